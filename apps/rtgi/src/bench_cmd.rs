//! `rtgi bench`: build time, tree quality and throughput of every
//! acceleration structure on one scene, as a table and as JSON: the quick
//! mode of the `accel` knob. The measuring is the experiment library's
//! (`rtgi_experiment::measure`: builds, trace costs, traversal counts,
//! failures on the robustness probes); this file parses and prints.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use clap::builder::TypedValueParser;
use rtgi_accel::{AccelKind, BuildParams, BuildStats, Intersector, Traversal};
use rtgi_experiment::measure::{self, TraceCost};
use rtgi_math::Ray;
use rtgi_render::rays::{primary_rays, surface_rays};
use serde::Serialize;

use rtgi_job::MAX_IMAGE_SIDE;

use crate::common::{LoadedScene, check_output_folder, choose_camera, load_scene, thread_pool};
use crate::options::{AccelList, AccelParser, BuildArgs, SeedArgs, ThreadArgs};
use crate::output::outln;

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

/// Everything one run of `rtgi bench` measured.
#[derive(Debug, Serialize)]
struct BenchReport {
    scene: String,
    triangles: usize,
    /// Threads of the multi-threaded measurements.
    threads: usize,
    repeats: u32,
    primary_rays: usize,
    incoherent_rays: usize,
    incoherent_seed: u64,
    variants: Vec<VariantReport>,
    /// Every intersector and traversal on one structure: speed beside failure rates.
    accuracy: Vec<AccuracyReport>,
}

#[derive(Debug, Serialize)]
struct AccuracyReport {
    variant: String,
    intersector: String,
    traversal: String,
    primary_mrays_all_threads: f64,
    incoherent_mrays_all_threads: f64,
    /// Rays exactly through the shared edge of two triangles that hit neither.
    shared_edge_rays: usize,
    shared_edge_misses: usize,
    /// Rays from inside a closed mesh (half aimed at vertices and edges) that hit nothing.
    closed_mesh_rays: usize,
    closed_mesh_escapes: usize,
}

#[derive(Debug, Serialize)]
struct ParamsReport {
    max_leaf_size: usize,
    sah_bins: usize,
    traversal_cost: f32,
}

#[derive(Debug, Serialize)]
struct VariantReport {
    variant: String,
    /// The build parameters: the variant's defaults with the options given.
    params: ParamsReport,
    /// A peer's backend (Embree): it reports no nodes or triangle tests,
    /// and is not held to the exactness contract.
    peer: bool,
    /// Median build time on one thread and on all threads.
    build_ms_1_thread: f64,
    build_ms_all_threads: f64,
    stats: BuildStats,
    primary: BatchReport,
    incoherent: BatchReport,
}

#[derive(Debug, Serialize)]
struct BatchReport {
    /// Rays timed and counted: the whole batch, or for the linear scan an
    /// evenly spaced subset of it.
    rays_timed: usize,
    mrays_1_thread: f64,
    mrays_all_threads: f64,
    hit_fraction: f64,
    /// Throughput through the batch API (`Accel::intersect_batch`, chunks
    /// of 1024 consecutive rays), which traces coherent rays as packets
    /// where the structure can; one ray at a time otherwise.
    batch_mrays_1_thread: f64,
    batch_mrays_all_threads: f64,
    nodes_visited_per_ray: f64,
    triangles_tested_per_ray: f64,
    /// Time per ray of the linear scan over time per ray of this variant, all threads.
    speedup_vs_linear: Option<f64>,
}

pub(crate) fn run(args: &BenchArgs) -> Result<()> {
    if let Some(json) = &args.json {
        check_output_folder(json)?;
    }
    let LoadedScene { scene, name, .. } = load_scene(args.scene.as_deref())?;
    let triangles = scene.triangle_positions();
    let pool = args.threads.pool()?;
    let single = thread_pool(Some(1))?;
    let repeats = args.repeats as usize;
    if args.accuracy_accel.is_peer() {
        bail!("--accuracy-accel {}: a peer's backend has no intersector or traversal to choose", args.accuracy_accel);
    }

    // The camera rtgi render would use, over the default image aspect of the batch.
    let framing = AccelKind::Bvh8.build(&triangles, &AccelKind::Bvh8.default_params());
    let camera = choose_camera(&scene, framing.as_ref(), &Default::default(), args.width as f32 / args.height as f32)?;
    drop(framing);
    let primary = primary_rays(&camera, args.width, args.height);
    let incoherent = surface_rays(&scene, args.rays as usize, args.seed.value);
    eprintln!(
        "{name}: {} triangles; {} primary rays ({}x{}), {} incoherent rays; {} threads, median of {repeats}",
        triangles.len(),
        primary.len(),
        args.width,
        args.height,
        incoherent.len(),
        pool.current_num_threads()
    );

    let mut variants = Vec::new();
    let mut linear: Option<(f64, f64)> = None;
    for &kind in &args.accel.0 {
        eprintln!("measuring {kind} ...");
        let params = args.build.params_for(kind);
        let report = measure_variant(kind, &triangles, &params, &primary, &incoherent, args, &pool, &single, linear)?;
        if kind == AccelKind::Linear {
            linear = Some((report.primary.mrays_all_threads, report.incoherent.mrays_all_threads));
        }
        variants.push(report);
    }
    // The linear scan may have been measured after others: fill in their speedups.
    if let Some((primary_linear, incoherent_linear)) = linear {
        for v in variants.iter_mut().filter(|v| v.variant != "linear") {
            v.primary.speedup_vs_linear = Some(v.primary.mrays_all_threads / primary_linear);
            v.incoherent.speedup_vs_linear = Some(v.incoherent.mrays_all_threads / incoherent_linear);
        }
    }

    let accuracy =
        measure_accuracy(args, &triangles, &args.build.params_for(args.accuracy_accel), &primary, &incoherent, &pool)?;

    let report = BenchReport {
        scene: name,
        triangles: triangles.len(),
        threads: pool.current_num_threads(),
        repeats: args.repeats,
        primary_rays: primary.len(),
        incoherent_rays: incoherent.len(),
        incoherent_seed: args.seed.value,
        variants,
        accuracy,
    };
    // The JSON asked for is written even when the reader of the table has
    // gone (`| head`).
    let printed = print_table(&report, args.linear_rays).and_then(|()| print_accuracy(&report.accuracy));
    if let Some(json) = &args.json {
        crate::common::write_atomically(json, serde_json::to_string_pretty(&report)?.as_bytes())?;
        eprintln!("wrote {}", json.display());
    }
    printed
}

/// One structure, measured as the accel knob measures it (`rtgi_experiment::measure`):
/// its builds, and each batch one ray at a time and through the batch API,
/// on one thread and on all.
#[allow(clippy::too_many_arguments)]
fn measure_variant(
    kind: AccelKind,
    triangles: &[[rtgi_math::Vec3; 3]],
    params: &BuildParams,
    primary: &[Ray],
    incoherent: &[Ray],
    args: &BenchArgs,
    pool: &rayon::ThreadPool,
    single: &rayon::ThreadPool,
    linear: Option<(f64, f64)>,
) -> Result<VariantReport> {
    let repeats = args.repeats as usize;
    let (_, build_1_thread) = single.install(|| measure::build(triangles, kind, params, repeats))?;
    let (accel, build_all_threads) = pool.install(|| measure::build(triangles, kind, params, repeats))?;

    // The linear scan is timed on an evenly spaced subset of each batch, at most 3 times.
    let (subset, timed_repeats) =
        if kind == AccelKind::Linear { (Some(args.linear_rays as usize), repeats.min(3)) } else { (None, repeats) };
    let batch = |rays: &[Ray], linear_mrays: Option<f64>| {
        let rays = subset.map_or_else(|| rays.to_vec(), |budget| measure::every_nth(rays, budget));
        let rate = |timing: &rtgi_experiment::stats::Timing| measure::mrays(rays.len(), timing).0;
        let one: TraceCost = single.install(|| measure::trace_cost(accel.as_ref(), &rays, timed_repeats));
        let all: TraceCost = pool.install(|| measure::trace_cost(accel.as_ref(), &rays, timed_repeats));
        let (counters, hits) = pool.install(|| measure::count(accel.as_ref(), &rays));
        let per_ray = |n: u64| n as f64 / rays.len().max(1) as f64;
        BatchReport {
            rays_timed: rays.len(),
            mrays_1_thread: rate(&one.single),
            mrays_all_threads: rate(&all.single),
            hit_fraction: hits as f64 / rays.len().max(1) as f64,
            batch_mrays_1_thread: rate(&one.batched),
            batch_mrays_all_threads: rate(&all.batched),
            nodes_visited_per_ray: per_ray(counters.nodes_visited),
            triangles_tested_per_ray: per_ray(counters.triangles_tested),
            speedup_vs_linear: linear_mrays.map(|l| rate(&all.single) / l),
        }
    };
    let primary = batch(primary, linear.map(|l| l.0));
    let incoherent = batch(incoherent, linear.map(|l| l.1));
    Ok(VariantReport {
        variant: kind.name().to_owned(),
        params: ParamsReport {
            max_leaf_size: params.max_leaf_size,
            sah_bins: params.sah_bins,
            traversal_cost: params.traversal_cost,
        },
        peer: kind.is_peer(),
        build_ms_1_thread: build_1_thread.median_ms,
        build_ms_all_threads: build_all_threads.median_ms,
        stats: accel.build_stats().clone(),
        primary,
        incoherent,
    })
}

fn print_table(report: &BenchReport, linear_rays: u32) -> Result<()> {
    outln!(
        "{} ({} triangles), {} threads; primary: {} rays, incoherent: {} rays; median of {}",
        report.scene,
        report.triangles,
        report.threads,
        report.primary_rays,
        report.incoherent_rays,
        report.repeats
    )?;
    outln!(
        "{:<15} {:>8} {:>8} {:>7} {:>8} {:>5} {:>8} | {:>15} {:>15} {:>13} {:>11} | {:>15} {:>13} {:>11}",
        "",
        "build ms",
        "build ms",
        "SAH",
        "nodes",
        "depth",
        "memory",
        "primary Mrays/s",
        "batch Mrays/s",
        "nodes, tris",
        "x linear",
        "incoh. Mrays/s",
        "nodes, tris",
        "x linear"
    )?;
    outln!(
        "{:<15} {:>8} {:>8} {:>7} {:>8} {:>5} {:>8} | {:>15} {:>15} {:>13} {:>11} | {:>15} {:>13} {:>11}",
        "variant",
        "1 thr",
        format!("{} thr", report.threads),
        "cost",
        "",
        "",
        "MiB",
        format!("1 / {} thr", report.threads),
        format!("1 / {} thr", report.threads),
        "per ray",
        "(all thr)",
        format!("1 / {} thr", report.threads),
        "per ray",
        "(all thr)"
    )?;
    let speedup = |s: Option<f64>| s.map_or("-".to_owned(), |s| format!("{s:.0}x"));
    for v in &report.variants {
        let batch = |b: &BatchReport| {
            (
                format!("{} / {}", significant(b.mrays_1_thread), significant(b.mrays_all_threads)),
                if v.peer {
                    "-".to_owned()
                } else {
                    format!("{:.1}, {:.1}", b.nodes_visited_per_ray, b.triangles_tested_per_ray)
                },
                speedup(b.speedup_vs_linear),
            )
        };
        let (p, pn, ps) = batch(&v.primary);
        let pb = format!(
            "{} / {}",
            significant(v.primary.batch_mrays_1_thread),
            significant(v.primary.batch_mrays_all_threads)
        );
        let (i, inn, is) = batch(&v.incoherent);
        outln!(
            "{:<15} {:>8.1} {:>8.1} {:>7.1} {:>8} {:>5} {:>8.2} | {:>15} {:>15} {:>13} {:>11} | {:>15} {:>13} {:>11}",
            v.variant,
            v.build_ms_1_thread,
            v.build_ms_all_threads,
            v.stats.sah_cost,
            v.stats.nodes,
            v.stats.depth,
            v.stats.memory_bytes as f64 / (1024.0 * 1024.0),
            p,
            pb,
            pn,
            ps,
            i,
            inn,
            is
        )?;
    }
    outln!(
        "batch: the batch API on chunks of 1024 consecutive rays (primary rays come in 4x4 pixel tiles); \
         the wide BVHs trace coherent rays as packets of 16, the others one ray at a time"
    )?;
    if report.variants.iter().any(|v| v.variant == "linear") {
        outln!("linear: timed on an evenly spaced subset of at most {linear_rays} rays of each batch")?;
    }
    if report.variants.iter().any(|v| v.peer) {
        outln!(
            "embree: Intel Embree 3, a peer (its own BVH, build quality medium; not held to the exactness contract); \
             it reports no nodes or triangle tests, and its SAH cost, nodes and depth are not ours to measure"
        )?;
    }
    Ok(())
}

/// A positive number with three significant digits (at least two decimals),
/// so that the linear scan's thousandths of a million rays per second show.
fn significant(x: f64) -> String {
    if x <= 0.0 || !x.is_finite() {
        return format!("{x:.2}");
    }
    let decimals = (2 - x.log10().floor() as i32).max(2) as usize;
    format!("{x:.decimals$}")
}

/// Every intersector with every traversal on one structure: throughput on
/// the scene's batches beside the failure rates on the robustness probes,
/// both measured by `rtgi_experiment::measure`.
fn measure_accuracy(
    args: &BenchArgs,
    triangles: &[[rtgi_math::Vec3; 3]],
    params: &BuildParams,
    primary: &[Ray],
    incoherent: &[Ray],
    pool: &rayon::ThreadPool,
) -> Result<Vec<AccuracyReport>> {
    let kind = args.accuracy_accel;
    let mut reports = Vec::new();
    for &intersector in Intersector::ALL {
        for &traversal in Traversal::ALL {
            eprintln!("measuring {kind} with {intersector} and {traversal} traversal ...");
            let params = BuildParams { intersector, traversal, ..params.clone() };
            let (accel, _) = pool.install(|| measure::build(triangles, kind, &params, 1))?;
            let rate = |rays: &[Ray]| {
                let timing = pool.install(|| measure::trace_time(accel.as_ref(), rays, args.repeats as usize));
                measure::mrays(rays.len(), &timing).0
            };
            let failures =
                pool.install(|| measure::probe_failures(kind, &params, args.leak_rays as usize, args.seed.value))?;
            reports.push(AccuracyReport {
                variant: kind.name().to_owned(),
                intersector: intersector.name().to_owned(),
                traversal: traversal.name().to_owned(),
                primary_mrays_all_threads: rate(primary),
                incoherent_mrays_all_threads: rate(incoherent),
                shared_edge_rays: failures.shared_edge_rays,
                shared_edge_misses: failures.shared_edge_misses,
                closed_mesh_rays: failures.closed_mesh_rays,
                closed_mesh_escapes: failures.closed_mesh_escapes,
            });
        }
    }
    Ok(reports)
}

fn print_accuracy(reports: &[AccuracyReport]) -> Result<()> {
    let Some(first) = reports.first() else { return Ok(()) };
    outln!()?;
    outln!(
        "What accuracy costs ({}): throughput on all threads beside failures on {} rays exactly through shared edges and {} rays from inside a closed mesh",
        first.variant,
        first.shared_edge_rays,
        first.closed_mesh_rays
    )?;
    outln!(
        "{:<16} {:<10} {:>15} {:>15} {:>20} {:>20}",
        "intersector",
        "traversal",
        "primary Mrays/s",
        "incoh. Mrays/s",
        "shared-edge misses",
        "closed-mesh escapes"
    )?;
    let rate = |n: usize, of: usize| format!("{n} ({:.4}%)", 100.0 * n as f64 / of.max(1) as f64);
    for r in reports {
        outln!(
            "{:<16} {:<10} {:>15.2} {:>15.2} {:>20} {:>20}",
            r.intersector,
            r.traversal,
            r.primary_mrays_all_threads,
            r.incoherent_mrays_all_threads,
            rate(r.shared_edge_misses, r.shared_edge_rays),
            rate(r.closed_mesh_escapes, r.closed_mesh_rays)
        )?;
    }
    Ok(())
}
