//! Records which code an experiment binary was built from, so that every
//! report can name it: the git commit, whether the sources differed from it
//! (and a hash of the difference), the compiler, the profile and the flags.
//!
//! Cargo reruns this script when the commit moves or any source of the
//! workspace changes, so a dirty build is never labelled with a clean commit.

use std::path::Path;
use std::process::Command;

/// The folders and files whose changes make a different program (docs and
/// tests do not).
const SOURCES: &[&str] = &["crates", "apps", "scenes", "Cargo.toml", "Cargo.lock"];

fn git(root: &Path, args: &[&str]) -> Option<String> {
    let output = Command::new("git").arg("-C").arg(root).args(args).output().ok()?;
    output.status.success().then(|| String::from_utf8_lossy(&output.stdout).trim().to_owned())
}

/// FNV-1a, 64 bits: a stable hash of the uncommitted difference.
fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let root = Path::new(&manifest).join("../..");
    for source in SOURCES {
        println!("cargo:rerun-if-changed={}", root.join(source).display());
    }
    // The commit moves when HEAD, the branch it names or the index change.
    for path in ["HEAD", "index", "packed-refs"] {
        if let Some(path) = git(&root, &["rev-parse", "--git-path", path]) {
            println!("cargo:rerun-if-changed={}", root.join(path).display());
        }
    }
    if let Some(reference) = git(&root, &["symbolic-ref", "-q", "HEAD"])
        && let Some(path) = git(&root, &["rev-parse", "--git-path", &reference])
    {
        println!("cargo:rerun-if-changed={}", root.join(path).display());
    }
    println!("cargo:rerun-if-env-changed=RUSTFLAGS");
    println!("cargo:rerun-if-env-changed=CARGO_ENCODED_RUSTFLAGS");

    let commit = git(&root, &["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".to_owned());
    let mut status_args = vec!["status", "--porcelain", "--"];
    status_args.extend(SOURCES);
    let dirty = match git(&root, &status_args) {
        Some(status) if status.is_empty() => String::new(),
        Some(status) => {
            // The difference itself, and the names of new files, decide the hash.
            let mut diff_args = vec!["diff", "HEAD", "--"];
            diff_args.extend(SOURCES);
            let diff = git(&root, &diff_args).unwrap_or_default();
            format!("{:016x}", fnv(format!("{status}\n{diff}").as_bytes()))
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
