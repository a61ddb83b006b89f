//! `rtgi bench-effects`: what the effects planner's decisions are worth.
//!
//! The scene is rendered with its plan, then once per effect with that
//! effect's decision reversed: omitted effects forced on (the time that
//! specialising saves; the image must not change) and simulated effects
//! forced off (the time the effect costs, and how much the image changes
//! without it). Every render uses the same seed, so differences are the
//! effects', not noise. The quick mode of the `effects` knob: the renders
//! are measured by `rtgi_experiment::measure::effect_renders`; this file
//! parses and prints.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use rtgi_experiment::Subject;
use rtgi_image::{Difference, compare};
use rtgi_render::{EffectPlan, RenderSettings};
use serde::Serialize;

use crate::common::{LoadedScene, check_output_folder, load_scene, prepare_render};
use crate::options::{AccelArgs, CameraArgs, ImageSizeArgs, LightingArgs, ThreadArgs};
use crate::output::{out, outln};

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

#[derive(Debug, Serialize)]
struct Row {
    /// `plan`, `+effect` or `-effect`.
    label: String,
    median_ms: f64,
    /// Median time over the plan's median time.
    relative_time: f64,
    /// Difference from the planned render (same seed); None for the plan itself.
    difference: Option<Difference>,
}

#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    width: u32,
    height: u32,
    samples_per_pixel: u32,
    threads: usize,
    repeats: u32,
    plan: EffectPlan,
    rows: Vec<Row>,
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
    let camera = prepared.camera.camera;
    let plan = EffectPlan::new(&scene, &settings);
    // The measurements and the JSON asked for go on when the reader of
    // standard output has gone (`| head`): the first failed write is kept
    // and returned at the end, and nothing more is printed after it.
    let mut printed = out!("{plan}");

    // Measured as the effects knob's renders are (`rtgi_experiment::measure`).
    let subject = Subject { name: name.clone(), scene, camera, accel, settings: settings.clone() };
    let renders = pool.install(|| {
        rtgi_experiment::measure::effect_renders(&subject, &settings, args.repeats as usize, &|label| {
            eprintln!("measuring {label} ...")
        })
    });
    let (planned, reversals) = renders.split_first().expect("the plan is rendered first");
    let planned_ms = planned.time.median_ms;
    let mut rows = vec![Row { label: "plan".into(), median_ms: planned_ms, relative_time: 1.0, difference: None }];
    // Effects the user forced stay as forced; every other decision is reversed once.
    for reversal in reversals {
        let ms = reversal.time.median_ms;
        rows.push(Row {
            label: reversal.label.clone(),
            median_ms: ms,
            relative_time: ms / planned_ms,
            difference: compare(&reversal.image, &planned.image),
        });
    }

    printed = printed.and_then(|()| {
        outln!(
            "{name}: {}x{} at {} spp, {} threads, median of {}",
            settings.width,
            settings.height,
            settings.samples_per_pixel,
            pool.current_num_threads(),
            args.repeats
        )?;
        outln!("{:<16} {:>10} {:>9} {:>12} {:>12}", "render", "ms", "x plan", "rmse", "max diff")?;
        for row in &rows {
            let (rmse, max) = row
                .difference
                .map_or(("-".into(), "-".into()), |d| (format!("{:.3e}", d.rmse), format!("{:.3e}", d.max_abs)));
            outln!("{:<16} {:>10.1} {:>9.2} {:>12} {:>12}", row.label, row.median_ms, row.relative_time, rmse, max)?;
        }
        outln!(
            "+effect: an effect the plan omits, forced on (its difference must be 0: specialising only saves time)"
        )?;
        outln!("-effect: an effect the plan simulates, forced off (what it costs, and what the image loses without it)")
    });

    if let Some(json) = &args.json {
        let report = Report {
            scene: name,
            width: settings.width,
            height: settings.height,
            samples_per_pixel: settings.samples_per_pixel,
            threads: pool.current_num_threads(),
            repeats: args.repeats,
            plan,
            rows,
        };
        crate::common::write_atomically(json, serde_json::to_string_pretty(&report)?.as_bytes())?;
    }
    printed
}
