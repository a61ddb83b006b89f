//! Renders and times them: what every knob that renders shares.

use std::time::Instant;

use rayon::prelude::*;

use rtgi_accel::{Accel, AccelKind};
use rtgi_image::HdrImage;
use rtgi_math::Ray;
use rtgi_render::RenderSettings;

use crate::reference::Reference;
use crate::report::Point;
use crate::stats::{SeedErrors, Timing};
use crate::{Options, Subject};

/// Renders `subject` with `settings` on the subject's structure; returns the image and the time in ms.
pub(crate) fn render(subject: &Subject, settings: &RenderSettings) -> (HdrImage, f64) {
    render_with(subject, subject.accel.as_ref(), settings)
}

pub(crate) fn render_with(subject: &Subject, accel: &dyn Accel, settings: &RenderSettings) -> (HdrImage, f64) {
    let start = Instant::now();
    let (image, _) = rtgi_render::render(&subject.scene, accel, &subject.camera, settings, &|_| {});
    (image, start.elapsed().as_secs_f64() * 1e3)
}

/// Renders `options.repeats` times with seeds 0, 1, 2... and measures the
/// time and the error against `reference`: RMSE, relative MSE, the split
/// into squared bias and variance over the seeds, and (in the point's
/// values) the efficiency `1 / (MSE · seconds)`.
pub(crate) fn measure(subject: &Subject, settings: &RenderSettings, options: &Options, reference: &Reference) -> Point {
    let mut times = Vec::new();
    let mut errors = SeedErrors::new(&reference.image, reference.info.noise_rmse);
    for repeat in 0..options.repeats.max(1) {
        let (image, ms) = render(subject, &RenderSettings { seed: repeat as u64, ..settings.clone() });
        times.push(ms);
        errors.add(&image);
    }
    let mut point = Point::new(settings.samples_per_pixel as f64, settings.samples_per_pixel.to_string());
    let (time, error) = (Timing::of(&times), errors.error());
    point.time = Some(time);
    point.error = Some(error);
    point.with("efficiency", error.efficiency(time.median_ms))
}

/// Renders each configuration once (seed 0) with as many samples per pixel
/// as fit `budget_ms` at its measured milliseconds per sample: the entries
/// of an equal-time panel, with the time each actually took.
pub(crate) fn equal_time(
    subject: &Subject,
    reference: &Reference,
    configurations: &[(String, RenderSettings, f64)],
    budget_ms: f64,
) -> Vec<crate::panel::Entry> {
    configurations
        .iter()
        .map(|(label, settings, ms_per_sample)| {
            let spp = (budget_ms / ms_per_sample.max(1e-9)).round().clamp(1.0, 65_536.0) as u32;
            let (image, time_ms) =
                render(subject, &RenderSettings { samples_per_pixel: spp, seed: 0, ..settings.clone() });
            let rmse = rtgi_image::compare(&image, &reference.image).expect("same size").rmse;
            crate::panel::Entry { label: format!("{label}, {spp} spp"), image, time_ms, rmse }
        })
        .collect()
}

/// A measured point's median milliseconds per sample per pixel.
pub(crate) fn ms_per_sample(point: &Point, samples_per_pixel: u32) -> f64 {
    point.time.expect("measured").median_ms / samples_per_pixel.max(1) as f64
}

/// `(time, RMSE, RMSE min, RMSE max)` of each measured point of `series`, for error-against-time plots.
pub(crate) fn time_and_error(series: &crate::Series) -> Vec<(Timing, f64, f64, f64)> {
    series
        .points
        .iter()
        .filter_map(|p| Some((p.time?, p.error?)))
        .map(|(t, e)| (t, e.rmse, e.rmse_min, e.rmse_max))
        .collect()
}

/// Builds `kind` over the subject's triangles `repeats` times; returns the last structure and the timing.
pub(crate) fn build_timed(
    triangles: &[[rtgi_math::Vec3; 3]],
    kind: AccelKind,
    params: &rtgi_accel::BuildParams,
    repeats: usize,
) -> Result<(Box<dyn Accel>, Timing), crate::ExperimentError> {
    let mut times = Vec::new();
    let mut built = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let accel = kind.try_build(triangles, params).map_err(|e| crate::ExperimentError::Build(e.to_string()))?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        built = Some(accel);
    }
    Ok((built.expect("at least one build"), Timing::of(&times)))
}

/// Times `trace` over `rays` in chunks of 1024 on all threads, `repeats` times after a warm-up.
pub(crate) fn time_rays(rays: &[Ray], repeats: usize, trace: impl Fn(&[Ray]) -> usize + Sync) -> Timing {
    let run = || {
        let start = Instant::now();
        let hits: usize = rays.par_chunks(1024).map(&trace).sum();
        std::hint::black_box(hits);
        start.elapsed().as_secs_f64() * 1e3
    };
    run();
    Timing::of(&(0..repeats.max(1)).map(|_| run()).collect::<Vec<_>>())
}
