//! Measuring, written once for the experiments, `rtgi bench` and the
//! benches: the only clock of the crate. Timing with warm-up and repeats
//! (median, min and max, every run kept), variants timed in alternation so
//! that drift hits them alike, timed renders, ray throughput on a thread
//! pool, evenly spaced ray subsets, and traversal counters summed over a
//! batch.

use std::time::Instant;

use rayon::prelude::*;
use rtgi_accel::{Accel, AccelKind, BuildParams, TraversalCounters};
use rtgi_math::Ray;

use rtgi_image::HdrImage;
use rtgi_render::RenderSettings;

use crate::stats::Timing;
use crate::{ExperimentError, Subject};

/// Rays a thread takes at a time.
pub const CHUNK: usize = 1024;

/// Times `run` `repeats` times (at least once) after `warm_up` untimed runs,
/// in milliseconds. The first runs pay for cold caches and sleeping threads.
pub fn time(repeats: usize, warm_up: usize, mut run: impl FnMut()) -> Timing {
    for _ in 0..warm_up {
        run();
    }
    time_each(repeats, |_| run(), |()| {})
}

/// Runs `f` once; returns what it made and its time in milliseconds.
pub fn once<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let made = f();
    (made, start.elapsed().as_secs_f64() * 1e3)
}

/// Times `run(repeat)` for each of `repeats` repeats (at least one, no
/// warm-up) and hands what each run made to `keep`, outside the clock:
/// renders that are compared with a reference after each seed are timed
/// without the comparison, and need not all be held at once.
pub fn time_each<T>(repeats: usize, mut run: impl FnMut(usize) -> T, mut keep: impl FnMut(T)) -> Timing {
    let runs: Vec<f64> = (0..repeats.max(1))
        .map(|repeat| {
            let (made, ms) = once(|| run(repeat));
            keep(made);
            ms
        })
        .collect();
    Timing::of(&runs)
}

/// Times each of `variants` `rounds` times (at least once) after one
/// untimed warm-up round, taking them in turn within each round: on a
/// shared machine the speed drifts (other work, the clock's boost), and in
/// alternation the drift hits every variant alike instead of whichever ran
/// during it. Returns each variant's timing, in their order.
pub fn alternate(rounds: usize, variants: &mut [&mut dyn FnMut()]) -> Vec<Timing> {
    for run in variants.iter_mut() {
        run();
    }
    let mut runs = vec![Vec::new(); variants.len()];
    for _ in 0..rounds.max(1) {
        for (run, runs) in variants.iter_mut().zip(&mut runs) {
            runs.push(once(&mut **run).1);
        }
    }
    runs.iter().map(|r| Timing::of(r)).collect()
}

/// Times `subject` against `pace` in `rounds` rounds (at least one), each
/// one run of both, which of the two goes first alternating from round to
/// round; returns what `subject` made first and the fastest run of each,
/// in ms. Noise on a shared machine only ever adds time, and slow spells
/// of a second or more hit both alike when they alternate this closely,
/// so the fastest runs' ratio is the steadiest reading of what `subject`
/// costs against `pace`.
pub fn fastest_in_alternation<P, T>(
    rounds: usize,
    mut pace: impl FnMut() -> P,
    mut subject: impl FnMut() -> T,
) -> (T, f64, f64) {
    let (mut made, mut fastest, mut pace_fastest) = (None, f64::INFINITY, f64::INFINITY);
    for round in 0..rounds.max(1) {
        if round % 2 == 0 {
            pace_fastest = pace_fastest.min(once(&mut pace).1);
        }
        let (output, ms) = once(&mut subject);
        fastest = fastest.min(ms);
        made.get_or_insert(output);
        if round % 2 == 1 {
            pace_fastest = pace_fastest.min(once(&mut pace).1);
        }
    }
    (made.expect("at least one round"), fastest, pace_fastest)
}

/// Times `trace` over `rays` in chunks of [`CHUNK`] on the current thread
/// pool, `repeats` times after one warm-up; `trace` answers a chunk (one ray
/// at a time, or through a batch query) and returns its hits.
pub fn time_rays(rays: &[Ray], repeats: usize, trace: impl Fn(&[Ray]) -> usize + Sync) -> Timing {
    time(repeats, 1, || {
        let hits: usize = rays.par_chunks(CHUNK).map(&trace).sum();
        std::hint::black_box(hits);
    })
}

/// Million rays a second of `rays` traced in `timing`: (median, at the slowest run, at the fastest).
pub fn mrays(rays: usize, timing: &Timing) -> (f64, f64, f64) {
    let rate = |ms: f64| rays as f64 / (ms.max(1e-9) * 1e3);
    (rate(timing.median_ms), rate(timing.max_ms), rate(timing.min_ms))
}

/// At most about `budget` rays of `rays`, evenly spaced (camera rays come in
/// tiles, and the first ones may all be sky).
pub fn every_nth(rays: &[Ray], budget: usize) -> Vec<Ray> {
    let stride = rays.len().div_ceil(budget.max(1)).max(1);
    rays.iter().step_by(stride).copied().collect()
}

/// The traversal counters (nodes visited, triangles tested) summed over
/// `rays`, and the rays that hit, on the current thread pool.
pub fn count(accel: &dyn Accel, rays: &[Ray]) -> (TraversalCounters, u64) {
    rays.par_chunks(CHUNK)
        .map(|chunk| {
            let mut counters = TraversalCounters::default();
            let hits = chunk.iter().filter(|r| accel.intersect_counted(r, &mut counters).is_some()).count();
            (counters, hits as u64)
        })
        .reduce(
            || (TraversalCounters::default(), 0),
            |(mut a, h), (b, g)| {
                a += b;
                (a, h + g)
            },
        )
}

/// Builds `kind` over `triangles` `repeats` times (at least once) on the
/// current thread pool; returns the last structure and the timing.
///
/// # Errors
/// [`ExperimentError::Build`] where the structure cannot be built (a peer
/// whose library is missing, triangles it refuses).
pub fn build(
    triangles: &[[rtgi_math::Vec3; 3]],
    kind: AccelKind,
    params: &BuildParams,
    repeats: usize,
) -> Result<(Box<dyn Accel>, Timing), ExperimentError> {
    let mut built = Ok(None);
    let timing = time(repeats, 0, || {
        // After a failure the rest would fail alike: no need to build again.
        if built.is_ok() {
            built = kind.try_build(triangles, params).map(Some).map_err(|e| ExperimentError::Build(e.to_string()));
        }
    });
    Ok((built?.expect("at least one build"), timing))
}

/// What tracing a batch of rays costs on the current thread pool.
#[derive(Clone, Debug)]
pub struct TraceCost {
    /// One ray at a time ([`Accel::intersect`]).
    pub single: Timing,
    /// Through the batch API ([`Accel::intersect_batch`]) on chunks of
    /// [`CHUNK`] consecutive rays: packets where the structure has them.
    pub batched: Timing,
}

/// Times tracing `rays` through `accel`, one ray at a time and through the
/// batch API, `repeats` times each after a warm-up ([`time_rays`]): what
/// the accel knob and `rtgi bench` measure of every structure.
pub fn trace_cost(accel: &dyn Accel, rays: &[Ray], repeats: usize) -> TraceCost {
    let single = trace_time(accel, rays, repeats);
    let batched = time_rays(rays, repeats, |chunk| {
        let mut hits = vec![None; chunk.len()];
        accel.intersect_batch(chunk, &mut hits);
        hits.iter().filter(|h| h.is_some()).count()
    });
    TraceCost { single, batched }
}

/// Times tracing `rays` through `accel` one ray at a time ([`time_rays`]).
pub fn trace_time(accel: &dyn Accel, rays: &[Ray], repeats: usize) -> Timing {
    time_rays(rays, repeats, |chunk| chunk.iter().filter(|r| accel.intersect(r).is_some()).count())
}

/// Rays that fail on the robustness probes of `rtgi_render::probes`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProbeFailures {
    /// Rays exactly through the shared edge of two triangles.
    pub shared_edge_rays: usize,
    /// Of those, the rays that hit neither triangle.
    pub shared_edge_misses: usize,
    /// Rays from inside a closed mesh, half aimed at its vertices and edges.
    pub closed_mesh_rays: usize,
    /// Of those, the rays that hit nothing (escape).
    pub closed_mesh_escapes: usize,
}

/// Builds `kind` with `params` over the shared-edge probe and over a
/// closed mesh with `leak_rays` rays from inside it (seeded by `seed`),
/// and counts the rays that miss: on the current thread pool.
///
/// # Errors
/// [`ExperimentError::Build`] where the structure cannot be built.
pub fn probe_failures(
    kind: AccelKind,
    params: &BuildParams,
    leak_rays: usize,
    seed: u64,
) -> Result<ProbeFailures, ExperimentError> {
    let (edge_triangles, edge_rays) = rtgi_render::probes::shared_edge_probe();
    let (mesh_triangles, mesh_rays) = rtgi_render::probes::closed_mesh_probe(leak_rays, seed);
    let misses = |triangles: &[[rtgi_math::Vec3; 3]], rays: &[Ray]| -> Result<usize, ExperimentError> {
        let accel = kind.try_build(triangles, params).map_err(|e| ExperimentError::Build(e.to_string()))?;
        Ok(rays.par_iter().filter(|r| accel.intersect(r).is_none()).count())
    };
    Ok(ProbeFailures {
        shared_edge_rays: edge_rays.len(),
        shared_edge_misses: misses(&edge_triangles, &edge_rays)?,
        closed_mesh_rays: mesh_rays.len(),
        closed_mesh_escapes: misses(&mesh_triangles, &mesh_rays)?,
    })
}

/// One render of an effects plan's comparison: the plan as planned, or
/// one of its decisions reversed.
#[derive(Clone, Debug)]
pub struct EffectRender {
    /// `plan`, `+effect` (forced on) or `-effect` (forced off).
    pub label: String,
    /// Whether the plan simulates the reversed effect; `None` for the plan itself.
    pub planned: Option<bool>,
    /// The settings rendered.
    pub settings: RenderSettings,
    /// The render's time over the repeats.
    pub time: Timing,
    /// The last repeat's image (every repeat renders the same seed).
    pub image: HdrImage,
}

/// Renders `subject` with its effects plan for `settings`, then once per
/// decision of the plan reversed (`EffectPlan::reversals`), each timed
/// `repeats` times with the same seed, so that the images differ by the
/// effects alone: the plan first. One untimed render of a sample first
/// wakes the threads, which must not make the plan look slow. `progress`
/// receives each render's label before it is measured.
pub fn effect_renders(
    subject: &Subject,
    settings: &RenderSettings,
    repeats: usize,
    progress: &dyn Fn(&str),
) -> Vec<EffectRender> {
    let plan = rtgi_render::EffectPlan::new(&subject.scene, settings);
    render(subject, &RenderSettings { samples_per_pixel: 1, ..settings.clone() });
    let planned = ("plan".to_owned(), None, settings.clone());
    let reversals =
        plan.reversals(&subject.scene, settings).into_iter().map(|r| (r.label(), Some(r.planned), r.settings));
    std::iter::once(planned)
        .chain(reversals)
        .map(|(label, planned, settings)| {
            progress(&label);
            let mut image = None;
            let time = time_each(repeats, |_| render(subject, &settings), |made| image = Some(made));
            EffectRender { label, planned, settings, time, image: image.expect("at least one repeat") }
        })
        .collect()
}

/// Renders `subject` with `settings` on the subject's structure.
pub(crate) fn render(subject: &Subject, settings: &RenderSettings) -> HdrImage {
    rtgi_render::render(&subject.scene, subject.accel.as_ref(), &subject.camera, settings, &|_| {}).0
}

/// [`render`], timed: the image and the time in ms.
pub(crate) fn render_timed(subject: &Subject, settings: &RenderSettings) -> (HdrImage, f64) {
    once(|| render(subject, settings))
}

/// Renders `subject` with `settings` and denoises the image as `rtgi
/// render` does for PNG output (`rtgi_render::render_denoised`).
pub(crate) fn render_denoised(subject: &Subject, settings: &RenderSettings) -> HdrImage {
    let denoise = rtgi_render::DenoiseSettings::for_samples(settings.samples_per_pixel);
    rtgi_render::render_denoised(&subject.scene, subject.accel.as_ref(), &subject.camera, settings, &denoise).0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_every_repeat_after_the_warm_up() {
        let mut calls = 0;
        let timing = time(4, 2, || calls += 1);
        assert_eq!((calls, timing.runs), (6, 4));
        assert!(timing.min_ms <= timing.median_ms && timing.median_ms <= timing.max_ms);
    }

    #[test]
    fn alternation_times_every_variant_each_round_in_turn() {
        let order = std::cell::RefCell::new(Vec::new());
        let (mut a, mut b) = (|| order.borrow_mut().push('a'), || order.borrow_mut().push('b'));
        let timings = alternate(3, &mut [&mut a, &mut b]);
        assert_eq!(order.into_inner().iter().collect::<String>(), "abababab");
        assert!(timings.iter().all(|t| t.runs == 3 && t.runs_ms.len() == 3));
    }

    #[test]
    fn alternation_against_a_pace_swaps_the_order_each_round_and_keeps_the_first_output() {
        let order = std::cell::RefCell::new(String::new());
        let mut made = 0;
        let (first, fastest, pace) = fastest_in_alternation(
            4,
            || order.borrow_mut().push('p'),
            || {
                order.borrow_mut().push('s');
                made += 1;
                made
            },
        );
        assert_eq!(order.into_inner(), "pssppssp");
        assert_eq!(first, 1);
        assert!(fastest.is_finite() && pace.is_finite() && fastest >= 0.0 && pace >= 0.0);
    }

    #[test]
    fn each_run_is_kept_outside_the_clock() {
        let mut kept = Vec::new();
        let timing = time_each(3, |repeat| repeat * 10, |made| kept.push(made));
        assert_eq!((kept, timing.runs), (vec![0, 10, 20], 3));
    }

    #[test]
    fn subsets_are_evenly_spaced_and_bounded() {
        let rays: Vec<Ray> = (0..10).map(|i| Ray::new(rtgi_math::Vec3::splat(i as f32), rtgi_math::Vec3::X)).collect();
        let subset = every_nth(&rays, 3);
        assert_eq!(subset.iter().map(|r| r.origin.x).collect::<Vec<_>>(), vec![0.0, 4.0, 8.0]);
        assert_eq!(every_nth(&rays, 100).len(), 10);
        let (median, slow, fast) = mrays(
            2_000_000,
            &Timing { median_ms: 1000.0, min_ms: 500.0, max_ms: 2000.0, runs: 3, runs_ms: Vec::new() },
        );
        assert_eq!((median, slow, fast), (2.0, 1.0, 4.0));
    }
}
