//! Measuring, written once for the experiments and `rtgi bench`: timing
//! with warm-up and repeats (median, min and max), timed renders, ray throughput on a
//! thread pool, evenly spaced ray subsets, and traversal counters summed
//! over a batch.

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
    let runs: Vec<f64> = (0..repeats.max(1))
        .map(|_| {
            let start = Instant::now();
            run();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    Timing::of(&runs)
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

/// Renders `subject` with `settings` on the subject's structure; returns the image and the time in ms.
pub(crate) fn render_timed(subject: &Subject, settings: &RenderSettings) -> (HdrImage, f64) {
    let start = Instant::now();
    let (image, _) = rtgi_render::render(&subject.scene, subject.accel.as_ref(), &subject.camera, settings, &|_| {});
    (image, start.elapsed().as_secs_f64() * 1e3)
}

/// Renders `subject` with `settings` and denoises the image as `rtgi
/// render` does for PNG output (`rtgi_render::render_denoised`); returns
/// the image and the time of the render, its guides and the filter in ms.
pub(crate) fn render_denoised(subject: &Subject, settings: &RenderSettings) -> (HdrImage, f64) {
    let start = Instant::now();
    let denoise = rtgi_render::DenoiseSettings::for_samples(settings.samples_per_pixel);
    let (clean, _) =
        rtgi_render::render_denoised(&subject.scene, subject.accel.as_ref(), &subject.camera, settings, &denoise);
    (clean, start.elapsed().as_secs_f64() * 1e3)
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
