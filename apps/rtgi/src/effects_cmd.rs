//! `rtgi bench-effects`: what the effects planner's decisions are worth.
//!
//! The scene is rendered with its plan, then once per effect with that
//! effect's decision reversed: omitted effects forced on (the time that
//! specialising saves; the image must not change) and simulated effects
//! forced off (the time the effect costs, and how much the image changes
//! without it). Every render uses the same seed, so differences are the
//! effects', not noise. The quick mode of the `effects` knob: measured and
//! tabled by `rtgi_experiment::bench_effects`; this file parses and prints.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use rtgi_experiment::Subject;
use rtgi_experiment::bench_effects::bench_effects;
use rtgi_render::{EffectPlan, RenderSettings};

use crate::common::{LoadedScene, check_output_folder, load_scene, prepare_render, write_atomically};
use crate::options::{AccelArgs, CameraArgs, ImageSizeArgs, LightingArgs, ThreadArgs};
use crate::output::out;

/// `rtgi bench-effects`: the time each effect of the plan costs or saves.
#[derive(Debug, Args)]
pub(crate) struct BenchEffectsArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) size: ImageSizeArgs,

    /// Samples per pixel of each render
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub(crate) spp: u32,

    /// Timed renders per row; the median is reported
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub(crate) repeats: u32,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,

    #[command(flatten)]
    pub(crate) lighting: LightingArgs,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    /// Also write the results as JSON to this file
    #[arg(long)]
    pub(crate) json: Option<PathBuf>,
}

pub(crate) fn run(args: &BenchEffectsArgs) -> Result<()> {
    if let Some(json) = &args.json {
        check_output_folder(json)?;
    }
    let LoadedScene { mut scene, name, .. } = load_scene(args.scene.as_deref())?;
    let mut settings = RenderSettings {
        width: args.size.width(),
        height: args.size.height(),
        samples_per_pixel: args.spp,
        sampler: rtgi_render::recipe::default_sampler(args.spp),
        ..RenderSettings::default()
    };
    // Prepared as `rtgi render` prepares it, the lamp of an enclosed camera included.
    let pool = args.threads.pool()?;
    let (accel, prepared) =
        prepare_render(&mut scene, &mut settings, &args.lighting, &args.camera, &args.accel, &pool)?;
    // The measurements and the JSON asked for go on when the reader of
    // standard output has gone (`| head`): the first failed write is kept
    // and returned at the end, and nothing more is printed after it.
    let mut printed = out!("{}", EffectPlan::new(&scene, &settings));
    let subject = Subject { name, scene, camera: prepared.camera.camera, accel, settings };
    let report =
        pool.install(|| bench_effects(&subject, args.repeats as usize, &|label| eprintln!("measuring {label} ...")));
    printed = printed.and_then(|()| out!("{report}"));
    if let Some(json) = &args.json {
        write_atomically(json, serde_json::to_string_pretty(&report)?.as_bytes())?;
    }
    printed
}
