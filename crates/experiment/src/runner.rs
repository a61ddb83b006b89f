//! Renders and times them: what every knob that renders shares.

use std::time::Instant;

use rtgi_accel::{Accel, AccelKind};
use rtgi_image::HdrImage;
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

/// Renders `options.repeats` times with seeds 0, 1, 2... and measures the
/// time and the error against `reference`: RMSE, relative MSE, the split
/// into squared bias and variance over the seeds, and (in the point's
/// values) the efficiency `1 / (MSE · seconds)`.
pub(crate) fn measure(subject: &Subject, settings: &RenderSettings, options: &Options, reference: &Reference) -> Point {
    measure_with(subject, settings, options, reference, render)
}

/// How a knob makes an image: [`render`], or [`render_denoised`]; returns
/// the image and its time in ms.
pub(crate) type MakeImage = fn(&Subject, &RenderSettings) -> (HdrImage, f64);

/// [`measure`], each image made by `make` (a render, or a render and a filter).
pub(crate) fn measure_with(
    subject: &Subject,
    settings: &RenderSettings,
    options: &Options,
    reference: &Reference,
    make: MakeImage,
) -> Point {
    let mut times = Vec::new();
    let mut errors = SeedErrors::new(&reference.image, reference.info.noise_rmse);
    for repeat in 0..options.repeats.max(1) {
        let (image, ms) = make(subject, &RenderSettings { seed: repeat as u64, ..settings.clone() });
        times.push(ms);
        errors.add(&image);
    }
    let mut point = Point::new(settings.samples_per_pixel as f64, settings.samples_per_pixel.to_string());
    let (time, error) = (Timing::of(&times), errors.error());
    let efficiency = error.efficiency(time.median_ms);
    let biased = error.bias_resolved();
    point.time = Some(time);
    point.error = Some(error);
    // A biased estimator has no efficiency (its MSE does not fall as 1/time).
    let point = point.with("biased", if biased { 1.0 } else { 0.0 });
    if biased { point } else { point.with("efficiency", efficiency) }
}

/// The most samples per pixel an equal-time entry renders.
const MAX_PANEL_SPP: f64 = 65_536.0;
/// How far an equal-time entry's time may be from the budget, as a fraction of it.
pub(crate) const EQUAL_TIME_TOLERANCE: f64 = 0.05;
/// Renders an equal-time entry may take to meet the budget within the tolerance.
const EQUAL_TIME_ATTEMPTS: usize = 8;

/// Renders each configuration once (seed 0) with as many samples per pixel
/// as fit `budget_ms`: the entries of an equal-time panel. The count starts
/// from the configuration's measured milliseconds per sample and is
/// corrected from each render's own time (fixed costs and caches make the
/// time per sample of a long render differ from a short one's) until the
/// render takes the budget within [`EQUAL_TIME_TOLERANCE`]; where one
/// sample more or less steps over that window, or the time was noise, the
/// count is rendered again, and the entry closest to the budget is kept.
/// Each entry records its time, so a miss is visible, never hidden.
pub(crate) fn equal_time(
    subject: &Subject,
    reference: &Reference,
    configurations: &[(String, RenderSettings, f64)],
    budget_ms: f64,
) -> Vec<crate::panel::Entry> {
    configurations
        .iter()
        .map(|(label, settings, ms_per_sample)| {
            let entry = |image: HdrImage, time_ms: f64, label: String| {
                let rmse = rtgi_image::compare(&image, &reference.image).expect("same size").rmse;
                crate::panel::Entry { label, image, time_ms, rmse }
            };
            let off = |time_ms: f64| (time_ms / budget_ms - 1.0).abs();
            if let Some(sampling) = settings.adaptive {
                // Adaptive sampling bounded by the budget itself: the round
                // that would overrun is cut to what fits. A render that meets
                // its noise target early ends early, and says so by its time.
                let bounded = RenderSettings {
                    samples_per_pixel: MAX_PANEL_SPP as u32,
                    seed: 0,
                    adaptive: Some(rtgi_render::AdaptiveSampling { seconds: Some(budget_ms * 1e-3), ..sampling }),
                    ..settings.clone()
                };
                let mut best = render(subject, &bounded);
                for _ in 1..EQUAL_TIME_ATTEMPTS {
                    if off(best.1) <= EQUAL_TIME_TOLERANCE || best.1 < budget_ms {
                        break;
                    }
                    let again = render(subject, &bounded);
                    if off(again.1) < off(best.1) {
                        best = again;
                    }
                }
                return entry(best.0, best.1, format!("{label}, --time {:.3} s", budget_ms * 1e-3));
            }
            let render_at =
                |spp: u32| render(subject, &RenderSettings { samples_per_pixel: spp, seed: 0, ..settings.clone() });
            let mut spp = (budget_ms / ms_per_sample.max(1e-9)).round().clamp(1.0, MAX_PANEL_SPP) as u32;
            // The first render after another configuration's pays for cold
            // caches and sleeping threads: one untimed, shorter, first.
            let _ = render_at((spp / 4).max(1));
            let (mut total_ms, mut total_spp) = (0.0, 0.0);
            let mut best: Option<(HdrImage, f64, u32)> = None;
            for _ in 0..EQUAL_TIME_ATTEMPTS {
                let (image, time_ms) = render_at(spp);
                (total_ms, total_spp) = (total_ms + time_ms, total_spp + spp as f64);
                if best.as_ref().is_none_or(|b| off(time_ms) < off(b.1)) {
                    best = Some((image, time_ms, spp));
                }
                if best.as_ref().is_some_and(|b| off(b.1) <= EQUAL_TIME_TOLERANCE) {
                    break;
                }
                // The time per sample pooled over every render so far, so
                // that one run's noise moves the next count less.
                spp = (budget_ms * total_spp / total_ms.max(1e-9)).round().clamp(1.0, MAX_PANEL_SPP) as u32;
            }
            let best = best.expect("at least one attempt");
            let (image, time_ms, spp) = best;
            entry(image, time_ms, format!("{label}, {spp} spp"))
        })
        .collect()
}

/// Renders the configurations at equal time ([`equal_time`]) and adds their
/// panel to `report`, its caption among the findings.
pub(crate) fn add_equal_time_panel(
    report: &mut crate::Report,
    subject: &Subject,
    reference: &Reference,
    file: String,
    what: &str,
    configurations: &[(String, RenderSettings, f64)],
    budget_ms: f64,
) {
    let entries = equal_time(subject, reference, configurations, budget_ms);
    let title = format!("{what} at equal time ({} ms)", crate::report::format_ms(budget_ms));
    let mut panel = crate::panel::Panel::new(file, title, reference.image.clone(), entries);
    panel.budget_ms = Some(budget_ms);
    report.findings.push(panel.caption());
    report.panels.push(panel);
}

/// A measured point's median milliseconds per sample per pixel.
pub(crate) fn ms_per_sample(point: &Point, samples_per_pixel: u32) -> f64 {
    point.time.as_ref().expect("measured").median_ms / samples_per_pixel.max(1) as f64
}

/// `(time, RMSE, RMSE min, RMSE max)` of each measured point of `series`, for error-against-time plots.
pub(crate) fn time_and_error(series: &crate::Series) -> Vec<(Timing, f64, f64, f64)> {
    series
        .points
        .iter()
        .filter_map(|p| Some((p.time.as_ref()?, p.error.as_ref()?)))
        .map(|(t, e)| (t.clone(), e.rmse, e.rmse_min, e.rmse_max))
        .collect()
}

/// Builds `kind` over the subject's triangles `repeats` times; returns the last structure and the timing.
pub(crate) fn build_timed(
    triangles: &[[rtgi_math::Vec3; 3]],
    kind: AccelKind,
    params: &rtgi_accel::BuildParams,
    repeats: usize,
) -> Result<(Box<dyn Accel>, Timing), crate::ExperimentError> {
    let mut built = Ok(None);
    let timing = crate::measure::time(repeats, 0, || {
        if built.is_ok() {
            built =
                kind.try_build(triangles, params).map(Some).map_err(|e| crate::ExperimentError::Build(e.to_string()));
        }
    });
    Ok((built?.expect("at least one build"), timing))
}

pub(crate) use crate::measure::time_rays;
