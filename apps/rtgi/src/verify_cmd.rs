//! `rtgi verify`: every chosen structure against the linear scan, bit for
//! bit, on rays of the kinds that expose inexact structures.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Result, bail};
use clap::Args;
use rtgi_accel::verify::{self, VerifyReport, check_case};

use crate::common::{check_output_folder, load_scene, write_atomically};
use crate::options::{AccelList, AccelParser, BuildArgs, SeedArgs, ThreadArgs};
use crate::output::out;

/// `rtgi verify`: the exactness contract, checked on a scene or on the built-in adversarial set.
#[derive(Debug, Args)]
pub(crate) struct VerifyArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in adversarial scenes when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Rays in all, shared evenly among the ray kinds (and scenes)
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u32).range(1..=1_000_000_000))]
    pub(crate) rays: u32,

    /// Structures to check against the linear scan: names separated by commas, or all
    #[arg(long, default_value = "all", value_parser = AccelParser { list: true })]
    pub(crate) accel: AccelList,

    /// Check every leaf size (1, 2, 4, 8, 16), bin count and intersector, as the tests do,
    /// instead of the build options below
    #[arg(long)]
    pub(crate) exhaustive: bool,

    #[command(flatten)]
    pub(crate) build: BuildArgs,

    /// Triangle tests the linear scan may spend per ray kind; on big scenes it answers only the
    /// first rays of each kind within this budget, and the others are compared with the first
    /// structure checked
    #[arg(long, default_value_t = 2_000_000_000, value_parser = clap::value_parser!(u64).range(1..))]
    pub(crate) linear_budget: u64,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,

    /// Also write the table as JSON to this file
    #[arg(long)]
    pub(crate) json: Option<PathBuf>,
}

pub(crate) fn run(args: &VerifyArgs) -> Result<()> {
    if let Some(json) = &args.json {
        check_output_folder(json)?;
    }
    // Rays are shared evenly among the scenes and, in each, among the kinds:
    // the generic ones and (for the built-in scenes) the scene's own.
    let scene = match &args.scene {
        Some(path) => {
            let loaded = load_scene(Some(path))?;
            Some((loaded.name, loaded.scene.triangle_positions()))
        }
        None => None,
    };
    let (scene_name, cases) = verify::cases(scene, args.rays as usize, args.seed.value);
    let configurations = verify::configurations(&args.accel.0, args.exhaustive, |kind| args.build.params_for(kind));
    let intersectors = verify::reference_intersectors(&configurations, args.build.intersector);
    let pool = args.threads.pool()?;
    let start = Instant::now();

    let mut report = VerifyReport::new(scene_name, args.seed.value);
    for (case, per_kind) in &cases {
        let rays = pool.install(|| case.rays(*per_kind, args.seed.value));
        let budget_rays = (args.linear_budget / case.triangles.len().max(1) as u64) as usize;
        let ray_count: usize = rays.iter().map(|(_, r)| r.len()).sum();
        if cases.len() == 1 {
            eprintln!(
                "{}: {} triangles, {ray_count} rays through {} structures, the linear scan's answers for up to \
                 {budget_rays} of each kind (--linear-budget)",
                case.name,
                case.triangles.len(),
                configurations.len()
            );
        }
        let mut heartbeat = Heartbeat { start, last: Instant::now() };
        pool.install(|| {
            check_case(&mut report, case, &rays, &configurations, &intersectors, budget_rays, &mut |what| {
                heartbeat.beat(what)
            })
        })?;
        eprintln!(
            "{}: {} triangles, {} rays per structure checked ({:.1} s)",
            case.name,
            case.triangles.len(),
            ray_count,
            start.elapsed().as_secs_f64()
        );
    }
    // A reader that stops early (`| head`) must change neither the JSON
    // written nor the exit status that says whether verification failed.
    let printed = out!("{report}");
    if let Some(json) = &args.json {
        write_atomically(json, serde_json::to_string_pretty(&report)?.as_bytes())?;
    }
    if report.failed() {
        bail!("the structures do not all answer exactly as the linear scan, or rays leaked (see the table)");
    }
    printed
}

/// A progress line on standard error when a check has been quiet for a
/// while: a large scene takes minutes, and a silent program looks hung.
struct Heartbeat {
    start: Instant,
    last: Instant,
}

impl Heartbeat {
    const QUIET: std::time::Duration = std::time::Duration::from_secs(5);

    fn beat(&mut self, what: &dyn Fn() -> String) {
        if self.last.elapsed() >= Self::QUIET {
            eprintln!("  {} ({:.1} s)", what(), self.start.elapsed().as_secs_f64());
            self.last = Instant::now();
        }
    }
}
