//! A build that does nothing when nothing changed. The provenance build
//! script of `rtgi-experiment` once watched `.git/packed-refs`, which a
//! checkout may lack; Cargo takes a missing watched path as changed, so
//! every build compiled that crate again and relinked every binary above
//! it, minutes on two cores.

use std::path::{Path, PathBuf};
use std::process::Command;

use rtgi_tests::workspace_root;

/// The README's test command, building only: what `cargo test --workspace`
/// built before running this test.
const TEST_BUILD: &[&str] = &["test", "--workspace", "--locked", "--no-run", "--message-format=json"];

/// The targets that a build compiled rather than found fresh, from Cargo's
/// JSON messages.
fn compiled(messages: &str) -> Vec<String> {
    messages
        .lines()
        .filter(|line| line.contains(r#""reason":"compiler-artifact""#) && line.contains(r#""fresh":false"#))
        .map(|line| {
            let id = line.split(r#""package_id":""#).nth(1).and_then(|rest| rest.split('"').next());
            let target = line.split(r#""name":""#).nth(1).and_then(|rest| rest.split('"').next());
            format!("{} ({})", target.unwrap_or("?"), id.unwrap_or("?"))
        })
        .collect()
}

fn build() -> String {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(cargo).args(TEST_BUILD).current_dir(workspace_root()).output().expect("cannot run cargo");
    assert!(output.status.success(), "the build failed: {}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8_lossy(&output.stdout).into_owned()
}

#[test]
fn a_second_build_compiles_nothing() {
    // Run within `cargo test --workspace`, the first build finds everything
    // fresh; run on its own, it builds what the README's command builds.
    build();
    let again = compiled(&build());
    assert!(again.is_empty(), "a build with nothing changed compiled again: {again:#?}");
}

/// The folder Cargo builds in: `CARGO_TARGET_DIR`, else the folder above
/// this test binary's `deps/`.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    exe.parent().and_then(Path::parent).expect("target/PROFILE/deps/TEST").to_path_buf()
}

#[test]
fn our_build_scripts_watch_only_paths_that_exist() {
    let build = profile_dir().join("build");
    let mut watched = 0;
    for entry in std::fs::read_dir(&build).unwrap_or_else(|e| panic!("{}: {e}", build.display())) {
        let dir = entry.unwrap().path();
        let ours = dir.file_name().is_some_and(|n| n.to_string_lossy().starts_with("rtgi-"));
        let Ok(output) = std::fs::read_to_string(dir.join("output")) else { continue };
        if !ours {
            continue;
        }
        for line in output.lines() {
            let Some(path) =
                line.strip_prefix("cargo:rerun-if-changed=").or(line.strip_prefix("cargo::rerun-if-changed="))
            else {
                continue;
            };
            watched += 1;
            assert!(
                Path::new(path).exists(),
                "{}: watches {path}, which does not exist: Cargo rebuilds it on every build",
                dir.display()
            );
        }
    }
    assert!(watched > 0, "no build script of ours under {} watches anything", build.display());
}
