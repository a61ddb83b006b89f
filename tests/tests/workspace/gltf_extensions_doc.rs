//! The guide's table of glTF extensions (`docs/guide/rendering.md`, which
//! the README links to) says, in rtgi's column, what
//! `rtgi_scene::GLTF_EXTENSIONS` says: every extension the code knows is in
//! the table with its support (simulated, approximated, not visual,
//! unsupported), and the table names no other.

use rtgi_scene::GLTF_EXTENSIONS;
use rtgi_tests::workspace_root;

/// The page that holds the table.
const PAGE: &str = "docs/guide/rendering.md";

#[test]
fn the_guides_gltf_extension_table_matches_the_code() {
    let page = std::fs::read_to_string(workspace_root().join(PAGE)).unwrap_or_else(|e| panic!("{PAGE}: {e}"));
    let table = page
        .split("<!-- gltf-extensions: begin -->")
        .nth(1)
        .and_then(|rest| rest.split("<!-- gltf-extensions: end -->").next())
        .unwrap_or_else(|| panic!("{PAGE} has no gltf-extensions markers"));
    let rows: Vec<(String, String)> = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| Extension"))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            (cells[1].to_owned(), cells[2].to_owned())
        })
        .collect();
    for (name, support) in GLTF_EXTENSIONS {
        let row = rows.iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("{name} is not in {PAGE}'s table"));
        assert!(
            row.1.starts_with(support.label()),
            "{name}: {PAGE} says '{}', the code says '{}'",
            row.1,
            support.label()
        );
    }
    for (name, _) in &rows {
        assert!(GLTF_EXTENSIONS.iter().any(|(known, _)| known == name), "{name} is in {PAGE} but not in the code");
    }
}
