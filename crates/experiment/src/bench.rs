//! The quick mode of the accel knob, as `rtgi bench` prints it: every
//! chosen structure's builds, tree quality and throughput on one scene's
//! camera and incoherent rays, and every intersector and traversal of one
//! structure beside its failures on the robustness probes. All measuring
//! is [`crate::measure`]'s; this module only arranges it and formats the
//! tables ([`BenchReport`]'s `Display`).

use std::fmt;

use rayon::ThreadPool;
use rtgi_accel::{Accel, AccelKind, BuildParams, BuildStats, Intersector, Traversal};
use rtgi_math::{Ray, Vec3};
use serde::Serialize;

use crate::ExperimentError;
use crate::measure::{self, TraceCost};
use crate::stats::Timing;

/// What to measure: the structures, their parameters, and how often.
#[derive(Debug)]
pub struct BenchPlan<'a> {
    /// The scene's name, as reported.
    pub scene: String,
    /// The scene's triangles.
    pub triangles: &'a [[Vec3; 3]],
    /// Camera rays (one per pixel, in the order the caller generated them).
    pub primary: &'a [Ray],
    /// Incoherent rays (from the surfaces in random directions).
    pub incoherent: &'a [Ray],
    /// The seed the incoherent rays (and the probes' rays) were drawn with.
    pub seed: u64,
    /// The structures to measure, each with its parameters.
    pub structures: Vec<(AccelKind, BuildParams)>,
    /// The structure on which every intersector and traversal is compared.
    pub accuracy: (AccelKind, BuildParams),
    /// Rays from inside a closed mesh for the escape rate.
    pub leak_rays: usize,
    /// Timed runs per measurement (the median is reported).
    pub repeats: usize,
    /// Rays of each batch the linear scan is timed on (an evenly spaced subset).
    pub linear_rays: usize,
}

/// Everything one run of the bench measured.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// The scene's name.
    pub scene: String,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Threads of the multi-threaded measurements.
    pub threads: usize,
    /// Timed runs per measurement.
    pub repeats: u32,
    /// Camera rays.
    pub primary_rays: usize,
    /// Incoherent rays.
    pub incoherent_rays: usize,
    /// The seed of the incoherent rays.
    pub incoherent_seed: u64,
    /// The linear scan's subset of each batch.
    pub linear_rays: usize,
    /// One row per structure.
    pub variants: Vec<VariantReport>,
    /// Every intersector and traversal on one structure: speed beside failure rates.
    pub accuracy: Vec<AccuracyReport>,
}

/// One intersector and traversal on the accuracy structure.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyReport {
    /// The structure.
    pub variant: String,
    /// The ray/triangle test.
    pub intersector: String,
    /// The slab test.
    pub traversal: String,
    /// Camera rays, all threads, one ray at a time.
    pub primary_mrays_all_threads: f64,
    /// Incoherent rays, all threads, one ray at a time.
    pub incoherent_mrays_all_threads: f64,
    /// Rays exactly through the shared edge of two triangles.
    pub shared_edge_rays: usize,
    /// Of those, the rays that hit neither.
    pub shared_edge_misses: usize,
    /// Rays from inside a closed mesh (half aimed at vertices and edges).
    pub closed_mesh_rays: usize,
    /// Of those, the rays that hit nothing.
    pub closed_mesh_escapes: usize,
}

/// The build parameters a structure was measured with.
#[derive(Clone, Debug, Serialize)]
pub struct ParamsReport {
    /// Most triangles in a leaf.
    pub max_leaf_size: usize,
    /// Bins per axis of the SAH build.
    pub sah_bins: usize,
    /// The SAH's traversal cost.
    pub traversal_cost: f32,
}

/// One structure's row.
#[derive(Clone, Debug, Serialize)]
pub struct VariantReport {
    /// The structure's name.
    pub variant: String,
    /// The build parameters: the variant's defaults with the options given.
    pub params: ParamsReport,
    /// A peer's backend (Embree): it reports no nodes or triangle tests,
    /// and is not held to the exactness contract.
    pub peer: bool,
    /// Median build time on one thread.
    pub build_ms_1_thread: f64,
    /// Median build time on all threads.
    pub build_ms_all_threads: f64,
    /// Tree statistics.
    pub stats: BuildStats,
    /// The camera rays.
    pub primary: BatchReport,
    /// The incoherent rays.
    pub incoherent: BatchReport,
}

/// One batch of rays through one structure.
#[derive(Clone, Debug, Serialize)]
pub struct BatchReport {
    /// Rays timed and counted: the whole batch, or for the linear scan an
    /// evenly spaced subset of it.
    pub rays_timed: usize,
    /// One ray at a time, one thread.
    pub mrays_1_thread: f64,
    /// One ray at a time, all threads.
    pub mrays_all_threads: f64,
    /// Rays that hit something.
    pub hit_fraction: f64,
    /// Throughput through the batch API (`Accel::intersect_batch`, chunks
    /// of 1024 consecutive rays), which traces coherent rays as packets
    /// where the structure can; one ray at a time otherwise. One thread.
    pub batch_mrays_1_thread: f64,
    /// The batch API on all threads.
    pub batch_mrays_all_threads: f64,
    /// Mean nodes visited per ray.
    pub nodes_visited_per_ray: f64,
    /// Mean triangle tests per ray.
    pub triangles_tested_per_ray: f64,
    /// Time per ray of the linear scan over time per ray of this variant, all threads.
    pub speedup_vs_linear: Option<f64>,
}

/// Measures `plan` on `pool` (and on one thread): `progress` hears what is
/// being measured before it is.
///
/// # Errors
/// [`ExperimentError::Build`] where a structure cannot be built.
pub fn bench(plan: &BenchPlan<'_>, pool: &ThreadPool, progress: &dyn Fn(&str)) -> Result<BenchReport, ExperimentError> {
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| ExperimentError::Build(format!("cannot start a worker thread: {e}")))?;
    let mut variants = Vec::new();
    for (kind, params) in &plan.structures {
        progress(&format!("measuring {kind} ..."));
        variants.push(measure_variant(plan, *kind, params, pool, &single)?);
    }
    // The linear scan may have been measured after others: every speedup is set at the end.
    let linear = variants
        .iter()
        .find(|v| v.variant == AccelKind::Linear.name())
        .map(|v| (v.primary.mrays_all_threads, v.incoherent.mrays_all_threads));
    if let Some((primary, incoherent)) = linear {
        for v in variants.iter_mut().filter(|v| v.variant != AccelKind::Linear.name()) {
            v.primary.speedup_vs_linear = Some(v.primary.mrays_all_threads / primary);
            v.incoherent.speedup_vs_linear = Some(v.incoherent.mrays_all_threads / incoherent);
        }
    }
    Ok(BenchReport {
        scene: plan.scene.clone(),
        triangles: plan.triangles.len(),
        threads: pool.current_num_threads(),
        repeats: plan.repeats as u32,
        primary_rays: plan.primary.len(),
        incoherent_rays: plan.incoherent.len(),
        incoherent_seed: plan.seed,
        linear_rays: plan.linear_rays,
        variants,
        accuracy: measure_accuracy(plan, pool, progress)?,
    })
}

/// One structure: its builds, and each batch one ray at a time and through
/// the batch API, on one thread and on all.
fn measure_variant(
    plan: &BenchPlan<'_>,
    kind: AccelKind,
    params: &BuildParams,
    pool: &ThreadPool,
    single: &ThreadPool,
) -> Result<VariantReport, ExperimentError> {
    let repeats = plan.repeats;
    let (_, build_1_thread) = single.install(|| measure::build(plan.triangles, kind, params, repeats))?;
    let (accel, build_all_threads) = pool.install(|| measure::build(plan.triangles, kind, params, repeats))?;
    // The linear scan is timed on an evenly spaced subset of each batch, at most 3 times.
    let linear = kind == AccelKind::Linear;
    let timed_repeats = if linear { repeats.min(3) } else { repeats };
    let batch = |rays: &[Ray]| {
        let rays = if linear { measure::every_nth(rays, plan.linear_rays) } else { rays.to_vec() };
        measure_batch(accel.as_ref(), &rays, timed_repeats, pool, single)
    };
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
        primary: batch(plan.primary),
        incoherent: batch(plan.incoherent),
    })
}

fn measure_batch(
    accel: &dyn Accel,
    rays: &[Ray],
    repeats: usize,
    pool: &ThreadPool,
    single: &ThreadPool,
) -> BatchReport {
    let rate = |timing: &Timing| measure::mrays(rays.len(), timing).0;
    let one: TraceCost = single.install(|| measure::trace_cost(accel, rays, repeats));
    let all: TraceCost = pool.install(|| measure::trace_cost(accel, rays, repeats));
    let (counters, hits) = pool.install(|| measure::count(accel, rays));
    let per_ray = |n: u64| n as f64 / rays.len().max(1) as f64;
    BatchReport {
        rays_timed: rays.len(),
        mrays_1_thread: rate(&one.single),
        mrays_all_threads: rate(&all.single),
        hit_fraction: per_ray(hits),
        batch_mrays_1_thread: rate(&one.batched),
        batch_mrays_all_threads: rate(&all.batched),
        nodes_visited_per_ray: per_ray(counters.nodes_visited),
        triangles_tested_per_ray: per_ray(counters.triangles_tested),
        speedup_vs_linear: None,
    }
}

/// Every intersector with every traversal on the accuracy structure:
/// throughput on the scene's batches beside the failure rates on the probes.
fn measure_accuracy(
    plan: &BenchPlan<'_>,
    pool: &ThreadPool,
    progress: &dyn Fn(&str),
) -> Result<Vec<AccuracyReport>, ExperimentError> {
    let (kind, params) = &plan.accuracy;
    let mut reports = Vec::new();
    for &intersector in Intersector::ALL {
        for &traversal in Traversal::ALL {
            progress(&format!("measuring {kind} with {intersector} and {traversal} traversal ..."));
            let params = BuildParams { intersector, traversal, ..params.clone() };
            let (accel, _) = pool.install(|| measure::build(plan.triangles, *kind, &params, 1))?;
            let rate = |rays: &[Ray]| {
                let timing = pool.install(|| measure::trace_time(accel.as_ref(), rays, plan.repeats));
                measure::mrays(rays.len(), &timing).0
            };
            let failures = pool.install(|| measure::probe_failures(*kind, &params, plan.leak_rays, plan.seed))?;
            reports.push(AccuracyReport {
                variant: kind.name().to_owned(),
                intersector: intersector.name().to_owned(),
                traversal: traversal.name().to_owned(),
                primary_mrays_all_threads: rate(plan.primary),
                incoherent_mrays_all_threads: rate(plan.incoherent),
                shared_edge_rays: failures.shared_edge_rays,
                shared_edge_misses: failures.shared_edge_misses,
                closed_mesh_rays: failures.closed_mesh_rays,
                closed_mesh_escapes: failures.closed_mesh_escapes,
            });
        }
    }
    Ok(reports)
}

/// The two tables: the structures, then what accuracy costs.
impl fmt::Display for BenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} ({} triangles), {} threads; primary: {} rays, incoherent: {} rays; median of {}",
            self.scene, self.triangles, self.threads, self.primary_rays, self.incoherent_rays, self.repeats
        )?;
        let threads = format!("1 / {} thr", self.threads);
        let row = |f: &mut fmt::Formatter<'_>, cells: [&str; 14]| {
            let [a, b, c, d, e, g, h, i, j, k, l, m, n, o] = cells;
            writeln!(
                f,
                "{a:<15} {b:>8} {c:>8} {d:>7} {e:>8} {g:>5} {h:>8} | {i:>15} {j:>15} {k:>13} {l:>11} | {m:>15} {n:>13} {o:>11}"
            )
        };
        row(
            f,
            [
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
                "x linear",
            ],
        )?;
        let all_threads = format!("{} thr", self.threads);
        row(
            f,
            [
                "variant",
                "1 thr",
                &all_threads,
                "cost",
                "",
                "",
                "MiB",
                &threads,
                &threads,
                "per ray",
                "(all thr)",
                &threads,
                "per ray",
                "(all thr)",
            ],
        )?;
        for v in &self.variants {
            let rates = |one: f64, all: f64| format!("{} / {}", significant(one), significant(all));
            let per_ray = |b: &BatchReport| {
                if v.peer {
                    "-".to_owned()
                } else {
                    format!("{:.1}, {:.1}", b.nodes_visited_per_ray, b.triangles_tested_per_ray)
                }
            };
            let speedup = |b: &BatchReport| b.speedup_vs_linear.map_or("-".to_owned(), |s| format!("{s:.0}x"));
            let (p, i) = (&v.primary, &v.incoherent);
            row(
                f,
                [
                    &v.variant,
                    &format!("{:.1}", v.build_ms_1_thread),
                    &format!("{:.1}", v.build_ms_all_threads),
                    &format!("{:.1}", v.stats.sah_cost),
                    &v.stats.nodes.to_string(),
                    &v.stats.depth.to_string(),
                    &format!("{:.2}", v.stats.memory_bytes as f64 / (1024.0 * 1024.0)),
                    &rates(p.mrays_1_thread, p.mrays_all_threads),
                    &rates(p.batch_mrays_1_thread, p.batch_mrays_all_threads),
                    &per_ray(p),
                    &speedup(p),
                    &rates(i.mrays_1_thread, i.mrays_all_threads),
                    &per_ray(i),
                    &speedup(i),
                ],
            )?;
        }
        writeln!(
            f,
            "batch: the batch API on chunks of 1024 consecutive rays (primary rays come in 4x4 pixel tiles); \
             the wide BVHs trace coherent rays as packets of 16, the others one ray at a time"
        )?;
        if self.variants.iter().any(|v| v.variant == AccelKind::Linear.name()) {
            writeln!(f, "linear: timed on an evenly spaced subset of at most {} rays of each batch", self.linear_rays)?;
        }
        if self.variants.iter().any(|v| v.peer) {
            writeln!(
                f,
                "embree: Intel Embree 3, a peer (its own BVH, build quality medium; not held to the exactness \
                 contract); it reports no nodes or triangle tests, and its SAH cost, nodes and depth are not ours \
                 to measure"
            )?;
        }
        let Some(first) = self.accuracy.first() else { return Ok(()) };
        writeln!(f)?;
        writeln!(
            f,
            "What accuracy costs ({}): throughput on all threads beside failures on {} rays exactly through shared \
             edges and {} rays from inside a closed mesh",
            first.variant, first.shared_edge_rays, first.closed_mesh_rays
        )?;
        writeln!(
            f,
            "{:<16} {:<10} {:>15} {:>15} {:>20} {:>20}",
            "intersector",
            "traversal",
            "primary Mrays/s",
            "incoh. Mrays/s",
            "shared-edge misses",
            "closed-mesh escapes"
        )?;
        let rate = |n: usize, of: usize| format!("{n} ({:.4}%)", 100.0 * n as f64 / of.max(1) as f64);
        for r in &self.accuracy {
            writeln!(
                f,
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
