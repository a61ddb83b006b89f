//! The command line: the commands (each command's options live in its own
//! file, the groups they share in `options.rs`) and one-line parse errors.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::options::threads_from_environment;

#[derive(Debug, Parser)]
#[command(name = "rtgi", version, about = "Ray tracing and global illumination toolkit")]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,

    /// Let a scene's references (OBJ mtllib and textures, glTF buffers and images, meshes of a
    /// TOML description) reach outside the scene file's folder: only for scenes you trust
    #[arg(long, global = true)]
    pub(crate) allow_outside_scene: bool,

    /// The material variant of a glTF scene to render (KHR_materials_variants; `rtgi info`
    /// lists a scene's variants); without it each primitive has its default material
    #[arg(long, global = true, value_name = "NAME")]
    pub(crate) variant: Option<String>,
}

/// Parses a command line, `rtgi` first: the one entry point, which the
/// process's arguments and the tests' words both go through.
pub(crate) fn parse<T: Into<std::ffi::OsString> + Clone>(
    words: impl IntoIterator<Item = T>,
) -> Result<Cli, clap::Error> {
    Cli::try_parse_from(words)
}

#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Render a scene to an image (.png or .exr)
    Render(crate::render_cmd::RenderArgs),
    /// Trace a batch of rays from a binary file and write their hits
    Trace(crate::trace_cmd::TraceArgs),
    /// Write a ray file for 'rtgi trace': camera rays of a scene's view, random rays in its
    /// bounds, or rays leaving its surfaces
    Rays(crate::rays_cmd::RaysArgs),
    /// Measure build time, tree quality and ray throughput of acceleration structures
    Bench(crate::bench_cmd::BenchArgs),
    /// Export the boxes of chosen BVH levels as an OBJ file, to look at the tree
    BvhBoxes(crate::debug_cmd::BvhBoxesArgs),
    /// Render the traversal cost (BVH nodes visited per pixel) as a heat map
    Heatmap(crate::debug_cmd::HeatmapArgs),
    /// Describe a scene: triangles, materials, textures, lights, cameras, bounds, extensions,
    /// and the effects a render of it simulates
    Info(crate::info_cmd::InfoArgs),
    /// Measure how far an EXR image is from a reference EXR image (RMSE, relative MSE, max)
    Compare(crate::info_cmd::CompareArgs),
    /// Measure what each effect costs: render time with effects forced on and off, and how the image changes
    BenchEffects(crate::effects_cmd::BenchEffectsArgs),
    /// Check that every acceleration structure answers hard rays exactly as the linear scan does,
    /// bit for bit, and that rays aimed inside closed surfaces never leak
    Verify(crate::verify_cmd::VerifyArgs),
    /// Put the parts of a split render (--samples, --tile) or a checkpoint together into one
    /// image or accumulation, bit-identical to the render in one go
    Merge(crate::merge_cmd::MergeArgs),
    /// A contact sheet of scenes, each rendered as 'rtgi render SCENE' renders it with no options
    Gallery(crate::gallery_cmd::GalleryArgs),
    /// What accuracy costs in time: vary one knob (or all) and write a table (KNOB.md), every
    /// measurement (KNOB.json) and SVG plots
    Experiment(crate::experiment_cmd::ExperimentArgs),
    /// Run scripts in the command language of the course framework (at, load, raytracer, algo,
    /// commit, run, ...); with no script, open a prompt
    Script(crate::script::ScriptArgs),
    /// Open a prompt that takes the course framework's commands (after running any scripts given)
    Repl(crate::script::ScriptArgs),
}

impl Command {
    /// The worker threads the command asks for: `--threads`, else
    /// `RTGI_THREADS` (which commands without `--threads` read too); `None`
    /// for one per core.
    pub(crate) fn threads(&self) -> anyhow::Result<Option<u32>> {
        let args = match self {
            Command::Render(args) => &args.threads,
            Command::Trace(args) => &args.threads,
            Command::Bench(args) => &args.threads,
            Command::Heatmap(args) => &args.threads,
            Command::BenchEffects(args) => &args.threads,
            Command::Verify(args) => &args.threads,
            Command::Experiment(args) => &args.threads,
            Command::Script(args) | Command::Repl(args) => &args.threads,
            Command::BvhBoxes(_)
            | Command::Info(_)
            | Command::Compare(_)
            | Command::Merge(_)
            | Command::Gallery(_)
            | Command::Rays(_) => return threads_from_environment(),
        };
        args.count()
    }
}

/// Prints a command-line error as one line (help and version as clap writes them).
pub(crate) fn report_parse_error(error: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(error.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion)
        || error.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    {
        let _ = error.print();
        return ExitCode::from(if error.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand { 2 } else { 0 });
    }
    eprintln!("error: {}", parse_error_line(&error));
    ExitCode::from(2)
}

/// One line for a parse error, made from clap's error kind, its context
/// (the argument, the value, the valid values, a suggestion) and, for a
/// value our parsers refused, their own message: not from clap's printed text.
fn parse_error_line(error: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let context = |kind: ContextKind| -> Option<String> {
        error.get(kind).map(|value| match value {
            ContextValue::String(s) => s.clone(),
            ContextValue::Strings(list) => list.join(", "),
            ContextValue::StyledStr(styled) => styled.to_string(),
            ContextValue::StyledStrs(list) => list.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", "),
            ContextValue::Number(n) => n.to_string(),
            other => other.to_string(),
        })
    };
    let argument = context(ContextKind::InvalidArg).unwrap_or_default();
    let value = context(ContextKind::InvalidValue).unwrap_or_default();
    let mut line = match error.kind() {
        ErrorKind::ValueValidation => {
            let why = std::error::Error::source(error).map(|e| e.to_string()).unwrap_or_default();
            format!("invalid value '{value}' for '{argument}': {why}")
        }
        ErrorKind::InvalidValue => format!("invalid value '{value}' for '{argument}'"),
        ErrorKind::UnknownArgument => format!("unexpected argument '{argument}'"),
        ErrorKind::InvalidSubcommand => {
            format!("unrecognized subcommand '{}'", context(ContextKind::InvalidSubcommand).unwrap_or_default())
        }
        ErrorKind::MissingRequiredArgument => format!("the following required arguments were not provided: {argument}"),
        ErrorKind::ArgumentConflict => {
            let other = context(ContextKind::PriorArg).unwrap_or_default();
            if other == argument {
                format!("the argument '{argument}' cannot be used multiple times")
            } else {
                format!("the argument '{argument}' cannot be used with '{other}'")
            }
        }
        ErrorKind::TooManyValues => format!("unexpected value '{value}' for '{argument}'"),
        ErrorKind::TooFewValues | ErrorKind::WrongNumberOfValues => {
            let expected = context(ContextKind::ExpectedNumValues).unwrap_or_default();
            format!("'{argument}' takes {expected} value(s)")
        }
        ErrorKind::NoEquals => format!("'{argument}' needs a value after '='"),
        kind if !argument.is_empty() => format!("{kind}: '{argument}'"),
        kind => kind.to_string(),
    };
    if let Some(valid) = context(ContextKind::ValidValue) {
        line.push_str(&format!(" (possible values: {valid})"));
    }
    let suggestion = [ContextKind::SuggestedArg, ContextKind::SuggestedSubcommand, ContextKind::SuggestedValue]
        .into_iter()
        .find_map(context);
    if let Some(suggestion) = suggestion {
        line.push_str(&format!("; did you mean '{suggestion}'?"));
    }
    line
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;
    use rtgi_accel::{AccelKind, Intersector, Traversal};
    use rtgi_image::ToneOperator;
    use rtgi_render::{DirectStrategy, Integrator, PixelSampler};

    use super::*;

    /// `ValueEnum` (what clap parses and lists) and `ALL`/`name()` (what
    /// the libraries list, print and parse) must name the same choices.
    #[test]
    fn value_enums_agree_with_the_named_choices() {
        fn agree<T: ValueEnum + PartialEq + std::fmt::Debug>(all: &[T], name: fn(&T) -> &'static str) {
            assert_eq!(T::value_variants(), all);
            for value in T::value_variants() {
                let possible = value.to_possible_value().expect("no variant is skipped");
                assert_eq!(possible.get_name(), name(value), "{value:?}");
            }
        }
        let accels: Vec<AccelKind> = AccelKind::ALL.iter().chain(AccelKind::PEERS).copied().collect();
        agree(&accels, |k| k.name());
        agree(Intersector::ALL, |i| i.name());
        agree(Traversal::ALL, |t| t.name());
        agree(rtgi_accel::simd::SimdLevel::ALL, |l| l.name());
        agree(ToneOperator::ALL, |t| t.name());
        agree(PixelSampler::ALL, |p| p.name());
        agree(rtgi_render::Effect::ALL, |e| e.name());
        agree(Integrator::ALL, |i| i.name());
        agree(DirectStrategy::ALL, |d| d.name());
        agree(rtgi_accel::SahAxes::ALL, |a| a.name());
        agree(rtgi_render::BounceSampling::ALL, |b| b.name());
        agree(rtgi_job::Denoise::ALL, |d| d.name());
    }

    #[test]
    fn command_line_is_well_formed() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
