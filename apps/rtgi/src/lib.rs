//! `rtgi`: the command line of the rtgi ray tracer.
//!
//! The whole program lives in this library so that the end-to-end tests can
//! build the same command as a binary of their own and run it as a process.

mod bench_cmd;
mod cli;
mod command_line;
mod common;
mod debug_cmd;
mod effects_cmd;
mod experiment_cmd;
mod gallery_cmd;
mod info_cmd;
mod interrupt;
mod merge_cmd;
mod options;
mod output;
mod phrasing;
mod progress;
mod rays_cmd;
mod render_cmd;
mod script;
mod trace_cmd;
mod verify_cmd;

use std::process::ExitCode;

/// The command line's definitions (every command, option and help text),
/// for generators of its reference (`tests/tests/workspace/cli_reference.rs`).
pub fn command() -> clap::Command {
    <cli::Cli as clap::CommandFactory>::command()
}

/// The `rtgi render` command that makes `request`, as words after `rtgi`
/// (`render`, then only the options that differ from their defaults):
/// what a script prints beside its render, so that it can be run again,
/// split or put on a cluster.
pub fn render_command_line(request: &rtgi_job::RenderRequest) -> Vec<String> {
    command_line::CommandLine::to_command_line(request)
}

/// The request that `words` (after `rtgi`: `render`, the scene, options,
/// and the global options such as `--variant`) make, as `rtgi render`
/// would render it; `RTGI_THREADS` is read as `rtgi render` reads it.
///
/// # Errors
/// Words that are no render command line, with clap's message.
pub fn render_request<T: Into<std::ffi::OsString> + Clone>(
    words: impl IntoIterator<Item = T>,
) -> anyhow::Result<rtgi_job::RenderRequest> {
    let words = std::iter::once(std::ffi::OsString::from("rtgi")).chain(words.into_iter().map(Into::into));
    let cli = cli::parse(words).map_err(|e| anyhow::anyhow!("{}", e.to_string().trim_end()))?;
    let cli::Command::Render(args) = cli.command else { anyhow::bail!("not an `rtgi render` command line") };
    let mut request = args.request()?;
    // The global options, which `main` keeps in statics for every command.
    if let rtgi_job::SceneSource::File { options, .. } = &mut request.scene {
        options.allow_outside_folder = cli.allow_outside_scene;
        options.gltf_variant = cli.variant;
    }
    Ok(request)
}

/// Runs the command line with the process's arguments; returns the exit code.
pub fn main() -> ExitCode {
    let cli = match cli::parse(std::env::args_os()) {
        Ok(cli) => cli,
        Err(e) => return cli::report_parse_error(e),
    };
    let _ = options::ALLOW_OUTSIDE_SCENE.set(cli.allow_outside_scene);
    let _ = options::GLTF_VARIANT.set(cli.variant.clone());
    // Rayon's global pool runs whatever no command's own pool runs (loading
    // a scene, the passes of a render): it gets the same count, so that
    // `--threads N` bounds every thread that works, not only the pool's.
    if let Err(e) = cli.command.threads().and_then(common::size_global_pool) {
        eprintln!("error: {}", one_line(&e));
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        cli::Command::Render(args) => render_cmd::run(&args),
        cli::Command::Trace(args) => trace_cmd::run(&args),
        cli::Command::Bench(args) => bench_cmd::run(&args),
        cli::Command::BvhBoxes(args) => debug_cmd::boxes(&args),
        cli::Command::Heatmap(args) => debug_cmd::heatmap(&args),
        cli::Command::Info(args) => info_cmd::run(&args),
        cli::Command::Compare(args) => info_cmd::compare(&args),
        cli::Command::BenchEffects(args) => effects_cmd::run(&args),
        cli::Command::Verify(args) => verify_cmd::run(&args),
        cli::Command::Experiment(args) => experiment_cmd::run(&args),
        cli::Command::Merge(args) => merge_cmd::run(&args),
        cli::Command::Gallery(args) => gallery_cmd::run(&args),
        cli::Command::Rays(args) => rays_cmd::run(&args),
        cli::Command::Script(args) => script::run(&args),
        cli::Command::Repl(args) => script::run(&crate::script::ScriptArgs { interactive: true, ..args }),
    };
    // Whatever the command printed last may still sit in the buffer.
    let result = result.and_then(|()| output::flush());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output has gone (`rtgi info | head -1`):
        // it has all it wanted, so this is not a failure to report.
        Err(e) if output::is_closed(&e) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(interrupt::StoppedBySignal(signal)) = e.downcast_ref() {
                eprintln!("rtgi: {e}");
                return ExitCode::from(interrupt::exit_status(*signal));
            }
            // A file rtgi cannot render for want of an extension, or a
            // variant the file does not have, is a usage problem, as a bad
            // argument is: exit status 2.
            if e.chain().any(|cause| {
                matches!(
                    cause.downcast_ref(),
                    Some(
                        rtgi_scene::SceneError::UnsupportedGltfExtension { .. }
                            | rtgi_scene::SceneError::UnknownMaterialVariant { .. }
                    )
                )
            }) {
                eprintln!("error: {}", one_line(&e));
                return ExitCode::from(2);
            }
            if e.downcast_ref::<phrasing::ResumeOfAnotherRender>().is_some() {
                eprintln!("error: {}", one_line(&e));
                return ExitCode::from(phrasing::ResumeOfAnotherRender::EXIT_STATUS);
            }
            eprintln!("error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// An error and its causes on one line, leaving out causes that the
/// messages before them already quote (library errors name their cause).
pub(crate) fn one_line(error: &anyhow::Error) -> String {
    let mut line = error.to_string();
    for cause in error.chain().skip(1) {
        let cause = cause.to_string();
        if !line.contains(&cause) {
            line.push_str(": ");
            line.push_str(&cause);
        }
    }
    line.replace('\n', " ")
}
