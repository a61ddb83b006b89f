//! Records which code an experiment binary was built from, so that every
//! report can name it: the git commit, whether the sources differed from it
//! (and a hash of the difference), the compiler, the profile and the flags.
//!
//! Cargo reruns this script when the commit moves or any source of the
//! workspace changes, so a dirty build is never labelled with a clean commit.
//! It watches only paths that exist: Cargo takes a watched path that is
//! missing as changed, so a checkout without (say) `.git/packed-refs` would
//! rebuild this crate, and relink every binary above it, on every build.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The folders and files whose changes make a different program (docs and
/// tests do not).
const SOURCES: &[&str] = &["crates", "apps", "scenes", "Cargo.toml", "Cargo.lock"];

fn git(root: &Path, args: &[&str]) -> Option<String> {
    // `--no-optional-locks`: `git status` would otherwise refresh the index
    // as it goes, a write that no build needs.
    let output = Command::new("git").arg("--no-optional-locks").arg("-C").arg(root).args(args).output().ok()?;
    output.status.success().then(|| String::from_utf8_lossy(&output.stdout).trim_end().to_owned())
}

/// `git rev-parse --git-path`: where git keeps `path` (worktrees keep refs
/// in the common folder), relative to the root when git says so.
fn git_path(root: &Path, path: &str) -> Option<PathBuf> {
    git(root, &["rev-parse", "--git-path", path]).map(|p| root.join(p))
}

/// FNV-1a, 64 bits: a stable hash of the uncommitted difference.
fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

fn watch(path: &Path) {
    if path.exists() {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let root = Path::new(&manifest).join("../..");
    for source in SOURCES {
        watch(&root.join(source));
    }
    // The commit moves when HEAD names another branch or commit, or when the
    // branch moves: its loose ref is rewritten or created (a folder is
    // watched through the files in it), or the packed refs change.
    for path in ["HEAD", "refs/heads", "packed-refs"] {
        if let Some(path) = git_path(&root, path) {
            watch(&path);
        }
    }
    println!("cargo:rerun-if-env-changed=RUSTFLAGS");
    println!("cargo:rerun-if-env-changed=CARGO_ENCODED_RUSTFLAGS");

    let commit = git(&root, &["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".to_owned());
    let mut status_args = vec!["status", "--porcelain", "--untracked-files=all", "--"];
    status_args.extend(SOURCES);
    let dirty = match git(&root, &status_args) {
        Some(status) if status.is_empty() => String::new(),
        Some(_) => {
            // What the sources hold, not how git sees them: the difference
            // to the commit (staged or not) and each new file's name and
            // bytes, so staging a change does not change its hash.
            let mut diff_args = vec!["diff", "HEAD", "--"];
            diff_args.extend(SOURCES);
            let mut hashed = git(&root, &diff_args).unwrap_or_default().into_bytes();
            let mut untracked_args = vec!["ls-files", "--others", "--exclude-standard", "--"];
            untracked_args.extend(SOURCES);
            for name in git(&root, &untracked_args).unwrap_or_default().lines() {
                hashed.extend_from_slice(name.as_bytes());
                hashed.extend(std::fs::read(root.join(name)).unwrap_or_default());
            }
            format!("{:016x}", fnv(&hashed))
        }
        None => String::new(),
    };
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".to_owned());
    let rustc_version = Command::new(rustc)
        .arg("-V")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_else(|| "unknown".to_owned());
    let flags = std::env::var("CARGO_ENCODED_RUSTFLAGS").unwrap_or_default().replace('\u{1f}', " ");
    let features = std::env::var("CARGO_CFG_TARGET_FEATURE").unwrap_or_default();
    println!("cargo:rustc-env=RTGI_BUILD_COMMIT={commit}");
    println!("cargo:rustc-env=RTGI_BUILD_DIRTY={dirty}");
    println!("cargo:rustc-env=RTGI_BUILD_RUSTC={rustc_version}");
    println!("cargo:rustc-env=RTGI_BUILD_PROFILE={}", std::env::var("PROFILE").unwrap_or_default());
    println!("cargo:rustc-env=RTGI_BUILD_OPT_LEVEL={}", std::env::var("OPT_LEVEL").unwrap_or_default());
    println!("cargo:rustc-env=RTGI_BUILD_RUSTFLAGS={flags}");
    println!("cargo:rustc-env=RTGI_BUILD_TARGET_FEATURES={features}");
}
