//! Renders and times them: what every knob that renders shares.

use rtgi_image::HdrImage;
use rtgi_render::RenderSettings;

use crate::panel::EQUAL_TIME_TOLERANCE;
use crate::reference::Reference;
use crate::report::Point;
use crate::stats::{SeedErrors, Timing};
use crate::{Options, Subject};

pub(crate) use crate::measure::{render, render_denoised, render_timed};

/// Renders `options.repeats` times with seeds 0, 1, 2... and measures the
/// time and the error against `reference`: RMSE, relative MSE, the split
/// into squared bias and variance over the seeds, and (in the point's
/// values) the efficiency `1 / (MSE · seconds)`.
pub(crate) fn measure(subject: &Subject, settings: &RenderSettings, options: &Options, reference: &Reference) -> Point {
    measure_with(subject, settings, options, reference, render)
}

/// How a knob makes an image: [`render`], or [`render_denoised`] (the
/// render and its filter, timed together).
pub(crate) type MakeImage = fn(&Subject, &RenderSettings) -> HdrImage;

/// [`measure`], each image made by `make` (a render, or a render and a filter).
pub(crate) fn measure_with(
    subject: &Subject,
    settings: &RenderSettings,
    options: &Options,
    reference: &Reference,
    make: MakeImage,
) -> Point {
    let mut errors = SeedErrors::new(&reference.image, reference.info.noise_rmse);
    let time = crate::measure::time_each(
        options.repeats,
        |repeat| make(subject, &RenderSettings { seed: repeat as u64, ..settings.clone() }),
        |image| errors.add(&image),
    );
    let mut point = Point::new(settings.samples_per_pixel as f64, settings.samples_per_pixel.to_string());
    let error = errors.error();
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
/// Renders an equal-time entry may take to meet the budget within the tolerance.
const EQUAL_TIME_ATTEMPTS: usize = 8;
/// Runs a fixed count is timed over in an equal-time panel, the median
/// recorded: panels are renders of a tenth of a second and up, where one
/// run can be 10% off on a shared machine.
const EQUAL_TIME_RUNS: usize = 3;

/// Renders each configuration (seed 0) with as many samples per pixel as
/// fit `budget_ms`: the entries of an equal-time panel. A fixed count's
/// time is the median of [`EQUAL_TIME_RUNS`] runs. The count starts
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
                // Adaptive sampling bounded by a time: the round that would
                // overrun is cut to what fits, as predicted from the rounds
                // so far, so the render can overrun by a little. The bound
                // is corrected from each render's own time until the render
                // meets the budget. One that meets its noise target early
                // ends early, and says so by its time.
                let bounded = |seconds: f64| RenderSettings {
                    samples_per_pixel: MAX_PANEL_SPP as u32,
                    seed: 0,
                    adaptive: Some(rtgi_render::AdaptiveSampling { seconds: Some(seconds), ..sampling }),
                    ..settings.clone()
                };
                let mut seconds = budget_ms * 1e-3;
                let mut best: Option<(HdrImage, f64, f64)> = None;
                for _ in 0..EQUAL_TIME_ATTEMPTS {
                    let (image, time_ms) = render_timed(subject, &bounded(seconds));
                    let next = seconds * budget_ms / time_ms.max(1e-9);
                    if best.as_ref().is_none_or(|b| off(time_ms) < off(b.1)) {
                        best = Some((image, time_ms, seconds));
                    }
                    if best.as_ref().is_some_and(|b| off(b.1) <= EQUAL_TIME_TOLERANCE) {
                        break;
                    }
                    seconds = next;
                }
                let (image, time_ms, seconds) = best.expect("at least one attempt");
                return entry(image, time_ms, format!("{label}, --time {seconds:.3} s"));
            }
            // A count's time is the median of its runs (the image is the
            // same bits each time): one run slowed by the machine then
            // neither misses the window nor becomes the entry's time.
            let render_at = |spp: u32| {
                let settings = RenderSettings { samples_per_pixel: spp, seed: 0, ..settings.clone() };
                let mut image = None;
                let timing = crate::measure::time_each(
                    EQUAL_TIME_RUNS,
                    |_| render(subject, &settings),
                    |made| {
                        image.get_or_insert(made);
                    },
                );
                (image.expect("at least one run"), timing.median_ms)
            };
            let first = (budget_ms / ms_per_sample.max(1e-9)).round().clamp(1.0, MAX_PANEL_SPP) as u32;
            // The first render after another configuration's pays for cold
            // caches and sleeping threads: one untimed, shorter, first.
            let _ = render_at((first / 4).max(1));
            let (image, time_ms, spp) = calibrate(budget_ms, first, EQUAL_TIME_ATTEMPTS, render_at);
            entry(image, time_ms, format!("{label}, {spp} spp"))
        })
        .collect()
}

/// Finds the count of samples whose run takes `budget_ms`: runs `run` at
/// `first`, then at counts from the median time per sample of the runs so
/// far (a median, so that one slow run moves the estimate little), until a
/// run is within [`EQUAL_TIME_TOLERANCE`] of the budget or `attempts` runs
/// were made. A count already run twice outside the window is not run a
/// third time: the next count towards the budget is. Returns the run
/// closest to the budget, its time and its count.
pub(crate) fn calibrate<T>(
    budget_ms: f64,
    first: u32,
    attempts: usize,
    mut run: impl FnMut(u32) -> (T, f64),
) -> (T, f64, u32) {
    let off = |ms: f64| (ms / budget_ms - 1.0).abs();
    let mut tried: Vec<(u32, f64)> = Vec::new();
    let mut best: Option<(T, f64, u32)> = None;
    let mut count = first.clamp(1, MAX_PANEL_SPP as u32);
    for _ in 0..attempts.max(1) {
        let (result, ms) = run(count);
        tried.push((count, ms));
        if best.as_ref().is_none_or(|b| off(ms) < off(b.1)) {
            best = Some((result, ms, count));
        }
        if off(ms) <= EQUAL_TIME_TOLERANCE {
            break;
        }
        let mut next = (next_count(&tried, budget_ms)).round().clamp(1.0, MAX_PANEL_SPP) as u32;
        let runs_of = |n: u32| tried.iter().filter(|t| t.0 == n).map(|t| t.1).collect::<Vec<f64>>();
        let at_next = runs_of(next);
        if at_next.len() >= 2 {
            // Twice outside the window: step towards the budget instead.
            let mean = at_next.iter().sum::<f64>() / at_next.len() as f64;
            next = if mean < budget_ms { next + 1 } else { next.saturating_sub(1).max(1) };
        }
        count = next;
    }
    best.expect("at least one run")
}

/// The count the runs `tried` (count, ms) say takes `budget_ms`: from the
/// line through them (a render has a fixed cost beside its samples) where
/// they span two counts or more and it rises, else from the median time per
/// sample (a median, so that one slow run moves the estimate little).
fn next_count(tried: &[(u32, f64)], budget_ms: f64) -> f64 {
    let n = tried.len() as f64;
    let (mean_x, mean_y) =
        (tried.iter().map(|t| t.0 as f64).sum::<f64>() / n, tried.iter().map(|t| t.1).sum::<f64>() / n);
    let sxx: f64 = tried.iter().map(|t| (t.0 as f64 - mean_x).powi(2)).sum();
    let sxy: f64 = tried.iter().map(|t| (t.0 as f64 - mean_x) * (t.1 - mean_y)).sum();
    if sxx > 0.0 && sxy > 0.0 {
        let slope = sxy / sxx;
        let fixed = mean_y - slope * mean_x;
        let count = (budget_ms - fixed) / slope;
        if count.is_finite() && count > 0.0 {
            return count;
        }
    }
    let mut rates: Vec<f64> = tried.iter().map(|&(n, ms)| ms / n as f64).collect();
    rates.sort_by(f64::total_cmp);
    budget_ms / rates[rates.len() / 2].max(1e-12)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A clock of `fixed + per_sample · n` ms with a noise of ±`noise` and,
    /// every fifth run, a slow outlier of +25%.
    fn noisy_clock(fixed: f64, per_sample: f64, noise: f64) -> impl FnMut(u32) -> ((), f64) {
        let mut run = 0u32;
        move |n| {
            run += 1;
            let jitter = (run.wrapping_mul(2_654_435_761) % 1000) as f64 / 1000.0 * 2.0 - 1.0;
            let outlier = if run.is_multiple_of(5) { 1.25 } else { 1.0 };
            ((), (fixed + per_sample * n as f64) * (1.0 + noise * jitter) * outlier)
        }
    }

    #[test]
    fn calibration_meets_the_budget_through_noise_and_outliers() {
        for (fixed, per_sample, first) in [(0.0, 6.5, 20), (30.0, 4.0, 10), (5.0, 0.7, 400), (0.0, 7.0, 11)] {
            let (_, ms, count) = calibrate(100.0, first, EQUAL_TIME_ATTEMPTS, noisy_clock(fixed, per_sample, 0.03));
            assert!((ms / 100.0 - 1.0).abs() <= EQUAL_TIME_TOLERANCE, "{fixed} + {per_sample}·n: {count} took {ms}");
        }
    }

    #[test]
    fn where_no_count_fits_the_closest_is_kept() {
        // 30 ms a sample: 3 samples take 90 ms, 4 take 120; neither is within 5% of 100.
        let (_, ms, count) = calibrate(100.0, 1, EQUAL_TIME_ATTEMPTS, |n| ((), 30.0 * n as f64));
        assert_eq!((count, ms), (3, 90.0));
    }
}
