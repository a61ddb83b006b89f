//! Renders and times them: what every knob that renders shares.

use std::time::Instant;

use rayon::prelude::*;

use rtgi_accel::{Accel, AccelKind};
use rtgi_image::HdrImage;
use rtgi_math::Ray;
use rtgi_render::RenderSettings;

use crate::reference::Reference;
use crate::report::{ImageError, Point};
use crate::stats::Timing;
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
/// time and the error against `reference`.
pub(crate) fn measure(subject: &Subject, settings: &RenderSettings, options: &Options, reference: &Reference) -> Point {
    let mut times = Vec::new();
    let (mut mse, mut relative_mse, mut mean) = (0.0, 0.0, 0.0);
    let (mut rmse_min, mut rmse_max) = (f64::INFINITY, 0.0f64);
    let repeats = options.repeats.max(1);
    for repeat in 0..repeats {
        let (image, ms) = render(subject, &RenderSettings { seed: repeat as u64, ..settings.clone() });
        times.push(ms);
        let d = rtgi_image::compare(&image, &reference.image).expect("the reference has the render's size");
        mse += d.rmse * d.rmse;
        relative_mse += d.relative_mse;
        mean += d.mean;
        rmse_min = rmse_min.min(d.rmse);
        rmse_max = rmse_max.max(d.rmse);
    }
    let n = repeats as f64;
    let reference_mean = reference.image.pixels().iter().map(|p| p.to_array().iter().sum::<f32>() as f64).sum::<f64>()
        / (reference.image.pixels().len() * 3).max(1) as f64;
    let mut point = Point::new(settings.samples_per_pixel as f64, settings.samples_per_pixel.to_string());
    point.time = Some(Timing::of(&times));
    point.error = Some(ImageError {
        rmse: (mse / n).sqrt(),
        rmse_min,
        rmse_max,
        relative_mse: relative_mse / n,
        mean: mean / n,
        reference_mean,
    });
    point
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
