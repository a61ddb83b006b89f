//! Measuring, written once for the experiments, `rtgi bench` and the
//! benches: the only clock of the crate. Timing with warm-up and repeats
//! (median, min and max, every run kept), variants timed in alternation so
//! that drift hits them alike, timed renders, ray throughput on a thread
//! pool, evenly spaced ray subsets, and traversal counters summed over a
//! batch.

use std::time::Instant;

use rayon::prelude::*;
use rtgi_accel::{Accel, TraversalCounters};
use rtgi_math::Ray;

use rtgi_image::HdrImage;
use rtgi_render::RenderSettings;

use crate::Subject;
use crate::stats::Timing;

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
