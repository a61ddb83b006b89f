//! The libraries speak of their own fields, not of a front end's options:
//! no `#[error("…")]` message in `crates/` names a `--flag`. The app turns
//! the typed errors into its options' words (`common::recipe_error`), and
//! a script or a Rust caller gets the field's name.

use std::path::Path;

use rtgi_tests::workspace_root;

/// `(file, line)` of each `#[error(...)]` under `folder` whose message holds `--` before a letter.
fn flags_in_errors(folder: &Path) -> Vec<String> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(folder).expect("a source folder").flatten() {
        let path = entry.path();
        if path.is_dir() {
            found.extend(flags_in_errors(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            for (i, line) in lines.iter().enumerate() {
                if !line.trim_start().starts_with("#[error(") {
                    continue;
                }
                // The attribute, over as many lines as it takes.
                let attribute: String = lines[i..]
                    .iter()
                    .take_while(|l| !l.trim_end().ends_with(")]"))
                    .chain(lines[i..].iter().find(|l| l.trim_end().ends_with(")]")))
                    .copied()
                    .collect::<Vec<_>>()
                    .join(" ");
                let names_flag = attribute
                    .match_indices("--")
                    .any(|(at, _)| attribute[at + 2..].chars().next().is_some_and(|c| c.is_ascii_lowercase()));
                if names_flag {
                    found.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
                }
            }
        }
    }
    found
}

#[test]
fn no_library_error_names_a_command_line_option() {
    let found = flags_in_errors(&workspace_root().join("crates"));
    assert!(found.is_empty(), "library errors that name a front end's option:\n{}", found.join("\n"));
}

#[test]
fn an_error_naming_an_option_is_found() {
    let dir = rtgi_tests::scratch_dir("library-errors");
    std::fs::write(
        dir.join("a.rs"),
        "enum E {\n    #[error(\"--camera {0}: out of range\")]\n    A(usize),\n    #[error(\"a range -- of sorts\")]\n    B,\n}\n",
    )
    .unwrap();
    let found = flags_in_errors(&dir);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].ends_with(":2: #[error(\"--camera {0}: out of range\")]"), "{found:?}");
}
