//! `rtgi bench`: build time, tree quality and throughput of every
//! acceleration structure on one scene, as a table and as JSON: the quick
//! mode of the `accel` knob. The measuring and the tables are the
//! experiment library's (`rtgi_experiment::bench`); this file parses,
//! makes the rays and prints.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use clap::builder::TypedValueParser;
use rtgi_accel::AccelKind;
use rtgi_experiment::bench::{BenchPlan, bench};
use rtgi_render::rays::{primary_rays, surface_rays};

use rtgi_job::MAX_IMAGE_SIDE;

use crate::common::{LoadedScene, check_output_folder, choose_camera, load_scene, write_atomically};
use crate::options::{AccelList, AccelParser, BuildArgs, SeedArgs, ThreadArgs};
use crate::output::out;

/// `rtgi bench`: what each acceleration structure costs and gives, side by side.
#[derive(Debug, Args)]
pub(crate) struct BenchArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Structures to measure: names separated by commas, or all
    #[arg(long, default_value = "all", value_parser = AccelParser { list: true })]
    pub(crate) accel: AccelList,

    #[command(flatten)]
    pub(crate) build: BuildArgs,

    /// Width of the primary-ray batch (one ray per pixel of the scene's camera)
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) width: u32,

    /// Height of the primary-ray batch
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) height: u32,

    /// Incoherent rays: from random points on the surfaces in random directions
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
    pub(crate) rays: u32,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    /// Timed runs per measurement; the median is reported
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub(crate) repeats: u32,

    /// Rays per batch that the linear scan is timed on (an evenly spaced subset)
    #[arg(long, default_value_t = 2048, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
    pub(crate) linear_rays: u32,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,

    /// Also write the results as JSON to this file
    #[arg(long)]
    pub(crate) json: Option<PathBuf>,

    /// Structure on which every intersector and traversal is compared for speed and failure rates
    #[arg(long, default_value = "sah", value_parser = AccelParser { list: false }.map(|list| list.0[0]))]
    pub(crate) accuracy_accel: AccelKind,

    /// Rays from inside a closed mesh for the escape rate
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
    pub(crate) leak_rays: u32,
}

pub(crate) fn run(args: &BenchArgs) -> Result<()> {
    if let Some(json) = &args.json {
        check_output_folder(json)?;
    }
    if args.accuracy_accel.is_peer() {
        bail!("--accuracy-accel {}: a peer's backend has no intersector or traversal to choose", args.accuracy_accel);
    }
    let LoadedScene { scene, name, .. } = load_scene(args.scene.as_deref())?;
    let triangles = scene.triangle_positions();
    let pool = args.threads.pool()?;
    // The camera rtgi render would use, over the default image aspect of the batch.
    let framing = AccelKind::Bvh8.build(&triangles, &AccelKind::Bvh8.default_params());
    let camera = choose_camera(&scene, framing.as_ref(), &Default::default(), args.width as f32 / args.height as f32)?;
    drop(framing);
    let primary = primary_rays(&camera, args.width, args.height);
    let incoherent = surface_rays(&scene, args.rays as usize, args.seed.value);
    eprintln!(
        "{name}: {} triangles; {} primary rays ({}x{}), {} incoherent rays; {} threads, median of {}",
        triangles.len(),
        primary.len(),
        args.width,
        args.height,
        incoherent.len(),
        pool.current_num_threads(),
        args.repeats
    );
    let plan = BenchPlan {
        scene: name,
        triangles: &triangles,
        primary: &primary,
        incoherent: &incoherent,
        seed: args.seed.value,
        structures: args.accel.0.iter().map(|&kind| (kind, args.build.params_for(kind))).collect(),
        accuracy: (args.accuracy_accel, args.build.params_for(args.accuracy_accel)),
        leak_rays: args.leak_rays as usize,
        repeats: args.repeats as usize,
        linear_rays: args.linear_rays as usize,
    };
    let report = bench(&plan, &pool, &|what| eprintln!("{what}"))?;
    // The JSON asked for is written even when the reader of the table has gone (`| head`).
    let printed = out!("{report}");
    if let Some(json) = &args.json {
        write_atomically(json, serde_json::to_string_pretty(&report)?.as_bytes())?;
        eprintln!("wrote {}", json.display());
    }
    printed
}
