//! The `rtgi` command run as a process, as a new user runs it: first looks,
//! outputs, hostile input, long renders, lights, the structures (Embree with
//! the `embree` feature) and the course's scripts.
//!
//! One test binary for the theme, a module a file.

mod accel;
mod basics;
mod command_line;
mod embree;
mod first_look;
mod hostile;
mod light;
mod long_render;
mod outputs;
mod script;

use std::path::Path;

use rtgi_tests::{Run, run_cli};

/// The binary under test (the `rtgi` command, built for the tests).
const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");

/// Runs `rtgi ARGS` and collects what it did.
fn rtgi(args: &[&str]) -> Run {
    run_cli(RTGI, args)
}

/// A path as a command-line argument.
fn path_str(p: &Path) -> &str {
    p.to_str().expect("scratch paths are UTF-8")
}
