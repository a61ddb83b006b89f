//! Runs a script of the course's command language through the library,
//! without the command line: what `rtgi script FILE` does, with a front
//! end of a dozen lines that prints and renders quietly.
//!
//! `cargo run --release -p rtgi-script --example run_script -- SCRIPT.rtgi`;
//! without an argument, a script of its own on the project's Cornell box,
//! rendered to the temporary folder.

use rtgi_job::{CancelToken, Rendered, Unobserved, Warning, render_given};
use rtgi_script::{Flow, Frontend, FrontendError, Run, Session, SessionOptions};

/// Prints what the session says and renders without progress.
struct Quiet;

impl Frontend for Quiet {
    fn say(&mut self, line: &str) -> Result<(), FrontendError> {
        println!("{line}");
        Ok(())
    }
    fn note(&mut self, message: &str) {
        eprintln!("note: {message}");
    }
    fn warn(&mut self, warning: &Warning) {
        eprintln!("warning: {warning:?}");
    }
    fn render(&mut self, run: Run<'_>) -> Result<Rendered, FrontendError> {
        Ok(render_given(run.request, run.given, &Unobserved, &CancelToken::new())?)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let box_obj = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-box/cornell-box.obj");
    let output = std::env::temp_dir().join("run_script.png");
    let script = match std::env::args_os().nth(1) {
        Some(path) => std::fs::read_to_string(path)?,
        None => format!(
            "load {box_obj}\nat 278 273 -800\nlook 0 0 1\nraytracer bbvh sah 16\ncommit\n\
             algo direct/mis\nresolution 160 160\nsppx 16\noutfile {}\nrun\nstats print\n",
            output.display()
        ),
    };
    let mut session = Session::new(SessionOptions::default());
    for (number, line) in script.lines().enumerate() {
        match session.execute(line, &mut Quiet) {
            Ok(Flow::Quit) => break,
            Ok(Flow::Continue) => {}
            Err(e) => return Err(format!("line {}: '{line}': {e}", number + 1).into()),
        }
    }
    Ok(())
}

#[test]
fn runs() {
    main().expect("the example runs its script");
}
