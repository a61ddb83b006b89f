//! `rtgi experiment`: parses the options, prepares each subject as a render
//! would, and hands it to `rtgi-experiment`, which measures and writes.
//!
//! With a scene, every chosen knob runs on it. `rtgi experiment all`
//! without a scene runs the report: each knob on the shared scenes it is
//! meant for (found in `$RTGI_SCENES` or `../shared/scenes`; missing ones
//! are skipped with a message), and writes `index.md` beside the results.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use rtgi_experiment::plan::Run;
use rtgi_experiment::provenance::Build;
use rtgi_experiment::{KNOBS, Knob, Machine, Options, RunRecord, Subject};

use rtgi_job::MAX_IMAGE_SIDE;

use crate::common::{LoadedScene, load_scene, prepare_render, write_atomically};
use crate::options::{AccelArgs, CameraArgs, LightingArgs, ThreadArgs};
use crate::output::outln;

/// `rtgi experiment`: one knob measured as time against error.
#[derive(Debug, Args)]
pub(crate) struct ExperimentArgs {
    /// The knob to vary
    #[arg(value_parser = knob_parser())]
    pub(crate) knob: KnobChoice,

    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Folder for the results [default: experiments/KNOB]; with 'all', one folder per knob inside it
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,

    /// Timed runs per measurement; times are reported as median, min and max
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub(crate) repeats: u32,

    /// A reduced version that runs in seconds (small images, few points): for tests, not conclusions
    #[arg(long)]
    pub(crate) quick: bool,

    /// Samples per pixel of the converged references [default: 4096; 256 with --quick]
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=1_048_576))]
    pub(crate) reference_spp: Option<u32>,

    /// Where references are cached between runs [default: experiments/.references]
    #[arg(long)]
    pub(crate) cache: Option<PathBuf>,

    /// Render every reference again instead of reading the cache
    #[arg(long)]
    pub(crate) no_cache: bool,

    /// Image width of the measured renders [default: 128; 32 with --quick]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) width: Option<u32>,

    /// Image height of the measured renders [default: 128; 32 with --quick]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) height: Option<u32>,

    #[command(flatten)]
    pub(crate) lighting: LightingArgs,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,
}

/// One knob, or all of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum KnobChoice {
    One(&'static dyn Knob),
    All,
    Index,
}

/// The knobs' names (from the registry, [`rtgi_experiment::KNOBS`], each
/// with what it varies as its help), `all` and `index`.
fn knob_parser() -> impl TypedValueParser<Value = KnobChoice> {
    let all = PossibleValue::new("all").help("Every knob in turn, one folder each, and the index");
    let index = PossibleValue::new("index")
        .help("Measure nothing: remake index.md in --out from the reports' JSON there (refused if they are of different code)");
    let knobs = KNOBS.iter().map(|k| PossibleValue::new(k.name()).help(k.about().trim_end_matches('.')));
    PossibleValuesParser::new(knobs.chain([all, index])).map(|name| match name.as_str() {
        "all" => KnobChoice::All,
        "index" => KnobChoice::Index,
        name => KnobChoice::One(rtgi_experiment::knob(name).expect("one of the possible values")),
    })
}

pub(crate) fn run(args: &ExperimentArgs) -> Result<()> {
    let started = (Instant::now(), rtgi_experiment::provenance::utc_now());
    let knobs: Vec<&dyn Knob> = match args.knob {
        KnobChoice::One(knob) => vec![knob],
        KnobChoice::All => KNOBS.to_vec(),
        KnobChoice::Index => {
            let folder = args.out.clone().unwrap_or_else(|| PathBuf::from("experiments"));
            let path = rtgi_experiment::write_index(&folder)?;
            return outln!("wrote {}", path.display());
        }
    };
    let report_mode = args.knob == KnobChoice::All && args.scene.is_none() && !args.quick;
    let out_root = args.out.clone().unwrap_or_else(|| PathBuf::from("experiments"));
    // Folders that cannot be folders are refused now, not after the
    // minutes or hours of measuring whose results would go there.
    for (option, folder) in [("--out", Some(&out_root)), ("--cache", args.cache.as_ref())] {
        if let Some(folder) = folder.filter(|f| f.exists() && !f.is_dir()) {
            bail!("{option} {}: exists and is not a folder", folder.display());
        }
    }
    let pool = args.threads.pool()?;
    let options = Options {
        repeats: args.repeats as usize,
        quick: args.quick,
        // As typed, with the program's name rather than the path it ran from.
        command: std::iter::once("rtgi".to_owned()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" "),
        threads: pool.current_num_threads(),
        cache: (!args.no_cache).then(|| args.cache.clone().unwrap_or_else(|| out_root.join(".references"))),
        reference_spp: args.reference_spp,
    };
    let single_folder = match args.knob {
        KnobChoice::One(_) => args.out.as_deref(),
        _ => None,
    };
    let (runs, missing) =
        rtgi_experiment::plan::runs(&knobs, args.scene.as_deref(), &out_root, single_folder, report_mode);
    for (knob, path) in missing {
        eprintln!("skipping {knob} on {}: not found (set RTGI_SCENES to the shared scenes' folder)", path.display());
    }

    // Every experiment asked for runs and writes its files even when the
    // reader of standard output has gone (`| head`): the first failed write
    // is kept and returned at the end, and nothing more is printed after it.
    let mut printed = Ok(());
    for Run { knob, scene, name, folder } in runs {
        let mut subject = pool.install(|| prepare(args, scene.as_deref(), &pool))?;
        if let Some(name) = name {
            subject.name = name;
        }
        let on = if knob.uses_scene() { format!(" on {}", subject.name) } else { String::new() };
        eprintln!("experiment {knob}{on}: {}", knob.question());
        let report = pool.install(|| rtgi_experiment::run(knob, &subject, &options, &|line| eprintln!("  {line}")))?;
        let paths = report.write(&folder)?;
        printed = printed.and_then(|()| {
            for finding in &report.findings {
                outln!("{knob}: {finding}")?;
            }
            for path in &paths {
                outln!("wrote {}", path.display())?;
            }
            Ok(())
        });
    }
    if args.knob == KnobChoice::All {
        let record = RunRecord {
            command: options.command.clone(),
            features: RunRecord::features(),
            build: Build::this(),
            machine: Machine::this(options.threads),
            started: started.1,
            finished: rtgi_experiment::provenance::utc_now(),
            wall_seconds: started.0.elapsed().as_secs_f64(),
        };
        let path = out_root.join(rtgi_experiment::RUN_RECORD);
        write_atomically(&path, serde_json::to_string_pretty(&record)?.as_bytes())?;
        let path = rtgi_experiment::write_index(&out_root)?;
        printed = printed.and_then(|()| outln!("wrote {}", path.display()));
    }
    printed
}

/// Loads the scene (the built-in Cornell box when `None`) and prepares it
/// exactly as `rtgi render` does ([`prepare_render`]: lighting, structure,
/// camera, the lamp of an enclosed camera), at the experiment's size.
fn prepare(args: &ExperimentArgs, scene: Option<&Path>, pool: &rayon::ThreadPool) -> Result<Subject> {
    let LoadedScene { mut scene, name, .. } = load_scene(scene)?;
    let mut settings = Subject::base_settings(args.quick, args.width, args.height);
    let (accel, prepared) = prepare_render(&mut scene, &mut settings, &args.lighting, &args.camera, &args.accel, pool)?;
    if let Some(light) = &prepared.room_light {
        let p = light.position;
        eprintln!(
            "  note: the camera is enclosed and nothing emits light: a lamp hangs at {:.3},{:.3},{:.3}",
            p.x, p.y, p.z
        );
    }
    Ok(Subject { name, scene, camera: prepared.camera.camera, accel, settings })
}

#[cfg(test)]
mod tests {
    use crate::cli::{Command, parse};

    /// The experiment renders what `rtgi render` renders with the same
    /// options: the same bytes, on the built-in box and on a closed room
    /// that needs the lamp of an enclosed camera.
    #[test]
    fn the_experiment_renders_the_bytes_of_rtgi_render() {
        let room = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/scenes/closed-room.toml");
        for scene in [None, Some(room)] {
            let options = ["--width", "24", "--height", "16", "--threads", "2"];
            let dir = std::env::temp_dir().join(format!("rtgi-recipe-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            let output = dir.join("render.exr");
            let mut render_args: Vec<&str> =
                vec!["rtgi", "render", "-o", output.to_str().unwrap(), "--spp", "4", "--seed", "3"];
            let mut experiment_args: Vec<&str> = vec!["rtgi", "experiment", "spp"];
            render_args.extend(scene);
            experiment_args.extend(scene);
            render_args.extend(options);
            experiment_args.extend(options);
            let Command::Render(render) = parse(&render_args).unwrap().command else { unreachable!() };
            let Command::Experiment(experiment) = parse(&experiment_args).unwrap().command else { unreachable!() };
            let pool = experiment.threads.pool().unwrap();
            let subject = super::prepare(&experiment, scene.map(std::path::Path::new), &pool).unwrap();
            let settings = rtgi_render::RenderSettings { samples_per_pixel: 4, seed: 3, ..subject.settings.clone() };
            let ours = pool.install(|| rtgi_experiment::render(&subject, &settings));
            let request = render.request().unwrap();
            let rendered = rtgi_job::render(&request, &rtgi_job::Unobserved, &rtgi_job::CancelToken::new()).unwrap();
            let (rendered, _) = rendered.image.expect("an image");
            let _ = std::fs::remove_dir_all(&dir);
            assert!(ours.pixels() == rendered.pixels(), "{scene:?}: the experiment renders another image");
            if scene.is_some() {
                assert!(!subject.scene.lights.is_empty(), "the closed room gets its lamp in the experiment too");
            }
        }
    }
}
