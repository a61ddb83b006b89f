//! `rtgi script` and `rtgi repl`: the command language of the course
//! framework this toolkit comes from (`at`, `load`, `raytracer`, `algo`,
//! `commit`, `run`, ...), as scripts and at a prompt.
//!
//! - the language itself, each line parsed into a command and the course's
//!   BRDF names as our materials, is the `rtgi-script` library (pure code,
//!   fuzzed there);
//! - so is the interpreter, [`rtgi_script::Session`]: what the commands set
//!   up, and a `run` as the render request of `rtgi render`;
//! - this file is its front end: it reads scripts line by line and runs the
//!   prompt, prints what the session says, and renders a `run` through
//!   `rtgi render`'s own code (its progress, summary, warnings and signals),
//!   after printing the `rtgi render` command that writes the same bytes.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Result, bail};
use clap::Args;
use rtgi_job::{Rendered, Warning};
use rtgi_script::{Flow, Frontend, FrontendError, Run, Session, SessionError, SessionOptions};

use crate::command_line::{CommandLine, shell_words};
use crate::options::{SeedArgs, ThreadArgs, load_options};
use crate::output::outln;
use crate::phrasing::{Phrasing, warn};
use crate::render_cmd::{Printer, finish, render};

/// Options of `rtgi script` and `rtgi repl`.
#[derive(Debug, Args)]
pub(crate) struct ScriptArgs {
    /// Scripts to run, one after the other in one session; none opens the prompt
    pub(crate) scripts: Vec<PathBuf>,

    /// Where `run` writes until a script's `outfile` says otherwise (.png, or .exr for the
    /// linear floats)
    #[arg(short, long, default_value = "out.png")]
    pub(crate) output: PathBuf,

    /// A folder `load` also looks in, after the current folder and the script's (repeatable)
    #[arg(long = "modelpath", value_name = "DIR")]
    pub(crate) model_paths: Vec<PathBuf>,

    /// After the scripts, open the prompt in the session they set up
    #[arg(short = 'l', long)]
    pub(crate) interactive: bool,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,
}

/// `rtgi script`: runs the scripts, then the prompt if asked (or if there were none).
pub(crate) fn run(args: &ScriptArgs) -> Result<()> {
    let mut session = Session::new(SessionOptions {
        output: args.output.clone(),
        seed: args.seed.value,
        threads: args.threads.count()?,
        model_paths: args.model_paths.clone(),
        load: load_options(),
    });
    for script in &args.scripts {
        match run_file(&mut session, script) {
            Ok(Flow::Continue) => {}
            Ok(Flow::Quit) => return Ok(()),
            // With the prompt to come, a bad line is reported and the
            // prompt opens on the session as the script left it.
            Err(error) if args.interactive => {
                eprintln!("error: {}", crate::one_line(&error));
                break;
            }
            Err(error) => return Err(error),
        }
    }
    if args.scripts.is_empty() || args.interactive {
        prompt(&mut session)?;
    }
    Ok(())
}

/// Runs a script to its end or its `quit`; stops at the first bad line
/// with an error naming the file, the line and the command.
fn run_file(session: &mut Session, script: &std::path::Path) -> Result<Flow> {
    let text =
        std::fs::read_to_string(script).map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", script.display()))?;
    // Editors on some systems start a file with a byte-order mark.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    session
        .set_script_folder(script.parent().map(|p| if p.as_os_str().is_empty() { ".".into() } else { p.to_owned() }));
    // The `with` block being skipped, if any: its line, to name it when it never ends.
    let mut block = None;
    for (index, line) in text.lines().enumerate() {
        let skipping = session.in_skipped_block();
        match session.execute(line, &mut Terminal) {
            Ok(Flow::Continue) => {}
            Ok(Flow::Quit) => return Ok(Flow::Quit),
            Err(error) => {
                bail!("{}:{}: '{}': {}", script.display(), index + 1, line.trim(), one_line(error));
            }
        }
        if !skipping && session.in_skipped_block() {
            block = Some((index + 1, line.trim().to_owned()));
        }
    }
    if session.in_skipped_block()
        && let Some((number, line)) = block
    {
        bail!(
            "{}:{number}: '{line}': the block has no closing '}}' on a line of its own, so the rest of the script \
             was skipped",
            script.display()
        );
    }
    session.set_script_folder(None);
    Ok(Flow::Continue)
}

/// The prompt: line editing and history; a bad line is reported and the
/// session goes on.
fn prompt(session: &mut Session) -> Result<()> {
    let mut editor = rustyline::DefaultEditor::new()?;
    loop {
        match editor.readline("rtgi > ") {
            Ok(line) => {
                if !line.trim().is_empty() {
                    let _ = editor.add_history_entry(line.as_str());
                }
                match session.execute(&line, &mut Terminal) {
                    Ok(Flow::Continue) => {}
                    Ok(Flow::Quit) => return Ok(()),
                    Err(error) => eprintln!("error: '{}': {}", line.trim(), one_line(error)),
                }
                crate::output::flush()?;
            }
            Err(rustyline::error::ReadlineError::Interrupted | rustyline::error::ReadlineError::Eof) => return Ok(()),
            Err(error) => return Err(error.into()),
        }
    }
}

/// A session's error and its causes on one line, as every error of the app is said.
fn one_line(error: SessionError) -> String {
    crate::one_line(&error.into())
}

/// The terminal as a session's front end: what the session says on standard
/// output, notes and warnings on standard error, a `run` rendered as
/// `rtgi render` renders.
struct Terminal;

impl Frontend for Terminal {
    fn say(&mut self, line: &str) -> Result<(), FrontendError> {
        Ok(outln!("{line}")?)
    }

    fn note(&mut self, message: &str) {
        eprintln!("note: {message}");
    }

    fn warn(&mut self, warning: &Warning) {
        // A scene's warnings read the same wherever it is loaded.
        warn(warning, Phrasing::Options, false);
    }

    fn render(&mut self, run: Run<'_>) -> Result<Rendered, FrontendError> {
        Ok(render_run(run)?)
    }
}

/// Prints the `rtgi render` command that renders what `run` renders (or
/// its nearest, and what it lacks), renders with the script's phrasing
/// and says how long it took, as the course's framework does.
fn render_run(run: Run<'_>) -> Result<Rendered> {
    let words = run.request.to_command_line();
    if run.edits.is_empty() {
        outln!("the same as  rtgi {}", shell_words(&words))?;
    } else {
        outln!("like         rtgi {} (with {}, which no option expresses)", shell_words(&words), run.edits.join(", "))?;
    }
    let started = Instant::now();
    let printer = Printer::new(run.request, true, Phrasing::Script);
    let rendered = render(run.request, Some(run.given), &printer)?;
    finish(&rendered)?;
    eprintln!("Took {}", crate::progress::short_duration(started.elapsed().as_secs_f64()));
    Ok(rendered)
}
