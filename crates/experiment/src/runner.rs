//! Renders and times them: what every knob that renders shares.

use rtgi_image::HdrImage;
use rtgi_render::RenderSettings;

use crate::panel::EQUAL_TIME_TOLERANCE;
use crate::reference::Reference;
use crate::report::Point;
use crate::stats::{SeedErrors, Timing};
use crate::{Options, Subject};

pub(crate) use crate::measure::{render, render_denoised};

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
/// Counts (or time bounds) an equal-time entry may try to meet the budget within the tolerance.
const EQUAL_TIME_ATTEMPTS: usize = 8;
/// Rounds an equal-time entry is timed in, each one run of the budget's
/// render and one of the entry's, in alternation. On the 2-core VM the
/// report is made on, two runs of one render back to back differ by 7%
/// (the standard deviation of their ratio), at 0.13 s as at 0.5 s, and
/// slow spells of a second or more add 30%. Over 180 runs of one render
/// (Cornell box, 128², 16 spp), the ratio of the fastest runs of 7 such
/// rounds was within ±3.5% of 1 in 96% of the 83 windows, the median of
/// 7 pairs' ratios in 81%; medians of 3 lone runs ranged over 47%.
const EQUAL_TIME_ROUNDS: usize = 7;

/// The samples per pixel of an equal-time panel's budget where a knob
/// measures at `sweep_spp`, a power of two: half as many again. Counts
/// just above a power of two cost up to a fifth more per sample than it
/// (the stratified and low-discrepancy samplers' permutations walk cycles
/// over the next power of two: 17 samples took 22% longer than 16 on the
/// Cornell box, 15 longer than 16), so a budget at 16 leaves configurations
/// a little cheaper per sample no count that fits; from 20 to 24 samples
/// each one more took 2.8–4.2% longer (fastest of 5 runs each).
pub(crate) fn budget_spp(sweep_spp: u32) -> u32 {
    sweep_spp + sweep_spp / 2
}

/// The render whose time is an equal-time panel's budget: timed in
/// alternation with each entry, so that the entry is held to the budget as
/// the machine ran at the time.
pub(crate) struct Budget {
    /// What it renders (its samples per pixel included).
    pub settings: RenderSettings,
    /// How its image is made: a render, or a render and a filter.
    pub make: MakeImage,
    /// Its time as measured before (the median of a sweep's runs): the
    /// start from which each entry's count is estimated.
    pub estimate_ms: f64,
}

impl Budget {
    /// The budget of a knob whose sweep rendered `settings` (at a
    /// power-of-two count) and measured it as `point`: the same render at
    /// [`budget_spp`] of that count, its time estimated in proportion.
    pub(crate) fn from_sweep(settings: RenderSettings, make: MakeImage, point: &Point) -> Budget {
        let sweep_spp = settings.samples_per_pixel;
        let panel_spp = budget_spp(sweep_spp);
        let estimate_ms = point.time.as_ref().expect("measured").median_ms * panel_spp as f64 / sweep_spp.max(1) as f64;
        Budget { settings: RenderSettings { samples_per_pixel: panel_spp, ..settings }, make, estimate_ms }
    }
}

/// A configuration of an equal-time panel: rendered with as many samples
/// per pixel (or, adaptive, for as long) as fit the budget.
pub(crate) struct Candidate {
    /// The configuration's name; the count it takes is appended.
    pub label: String,
    /// What it renders (its count is chosen).
    pub settings: RenderSettings,
    /// Its measured milliseconds per sample: the first count's estimate.
    pub ms_per_sample: f64,
    /// How its image is made.
    pub make: MakeImage,
}

impl Candidate {
    /// A configuration whose image is a plain render.
    pub(crate) fn render(label: impl Into<String>, settings: RenderSettings, ms_per_sample: f64) -> Candidate {
        Candidate { label: label.into(), settings, ms_per_sample, make: render }
    }
}

/// An entry's image and its time against the budget's, from
/// [`against_budget`]: (image, entry ms, budget ms).
type Timed = (HdrImage, f64, f64);

/// Times `entry` against the budget's render in [`EQUAL_TIME_ROUNDS`]
/// rounds ([`crate::measure::fastest_in_alternation`]).
fn against_budget(subject: &Subject, budget: &Budget, entry: impl FnMut() -> HdrImage) -> Timed {
    crate::measure::fastest_in_alternation(EQUAL_TIME_ROUNDS, || (budget.make)(subject, &budget.settings), entry)
}

/// Renders each configuration (seed 0) with as many samples per pixel as
/// fit the budget: the entries of an equal-time panel. Each count is timed
/// in alternation with the budget's render ([`against_budget`]), and the
/// entry's share of the budget is the ratio of their fastest runs. The
/// count starts from the configuration's measured milliseconds per sample
/// and is corrected from each measured share (fixed costs, caches and the
/// sampler's patterns make time not quite proportional to samples) until
/// the share is within [`EQUAL_TIME_TOLERANCE`] of 1 ([`calibrate`]);
/// where one sample more or less steps over that window, the count closest
/// to the budget is kept. Each entry records its time and the budget's
/// timed alongside it, so a miss is visible, never hidden.
pub(crate) fn equal_time(
    subject: &Subject,
    reference: &Reference,
    budget: &Budget,
    candidates: &[Candidate],
) -> Vec<crate::panel::Entry> {
    candidates
        .iter()
        .map(|candidate| {
            let entry = |(image, time_ms, budget_ms): Timed, label: String| {
                let rmse = rtgi_image::compare(&image, &reference.image).expect("same size").rmse;
                crate::panel::Entry { label, image, time_ms, budget_ms: Some(budget_ms), rmse }
            };
            let share = |timed: &Timed| timed.1 / timed.2.max(1e-9);
            // The first render after another configuration's pays for cold
            // caches and sleeping threads: the budget's, untimed, first.
            let _ = (budget.make)(subject, &budget.settings);
            if let Some(sampling) = candidate.settings.adaptive {
                // Adaptive sampling bounded by a time: the round that would
                // overrun is cut to what fits, as predicted from the rounds
                // so far, so the render can overrun by a little. The bound
                // is corrected from each measured share until the render
                // meets the budget. One that meets its noise target early
                // ends early, and says so by its time.
                let bounded = |seconds: f64| RenderSettings {
                    samples_per_pixel: MAX_PANEL_SPP as u32,
                    seed: 0,
                    adaptive: Some(rtgi_render::AdaptiveSampling { seconds: Some(seconds), ..sampling }),
                    ..candidate.settings.clone()
                };
                let off = |timed: &Timed| (share(timed) - 1.0).abs();
                let mut seconds = budget.estimate_ms * 1e-3;
                let mut best: Option<(Timed, f64)> = None;
                for _ in 0..EQUAL_TIME_ATTEMPTS {
                    let timed = against_budget(subject, budget, || (candidate.make)(subject, &bounded(seconds)));
                    let next = seconds / share(&timed).max(1e-9);
                    let in_window = off(&timed) <= EQUAL_TIME_TOLERANCE;
                    if best.as_ref().is_none_or(|b| off(&timed) < off(&b.0)) {
                        best = Some((timed, seconds));
                    }
                    if in_window {
                        break;
                    }
                    seconds = next;
                }
                let (timed, seconds) = best.expect("at least one attempt");
                return entry(timed, format!("{}, --time {seconds:.3} s", candidate.label));
            }
            let render_at = |spp: u32| {
                let settings = RenderSettings { samples_per_pixel: spp, seed: 0, ..candidate.settings.clone() };
                let timed = against_budget(subject, budget, || (candidate.make)(subject, &settings));
                let share = share(&timed);
                (timed, share)
            };
            let first = (budget.estimate_ms / candidate.ms_per_sample.max(1e-9)).round().clamp(1.0, MAX_PANEL_SPP);
            let (timed, _, spp) = calibrate(1.0, first as u32, EQUAL_TIME_ATTEMPTS, render_at);
            entry(timed, format!("{}, {spp} spp", candidate.label))
        })
        .collect()
}

/// Finds the count of samples whose run takes `budget` (a time, or a share
/// of one): runs `run` at `first`, then at the untried count nearest the
/// one the line through the runs so far predicts, until a run is within
/// [`EQUAL_TIME_TOLERANCE`] of the budget, `attempts` runs were made, or
/// no untried count is within [`SEARCH_REACH`] of the prediction. No
/// count is run twice. Time is not monotone in the count: the stratified
/// sampler's patterns cost more per sample where the count is not a power
/// of two (17 samples took 22% longer than 16 on the Cornell box, 15
/// longer than 16), so a count on either side of the window does not mean
/// that no count fits, and the search goes on past it. Returns the run
/// closest to the budget, its time and its count.
pub(crate) fn calibrate<T>(
    budget: f64,
    first: u32,
    attempts: usize,
    mut run: impl FnMut(u32) -> (T, f64),
) -> (T, f64, u32) {
    let off = |ms: f64| (ms / budget - 1.0).abs();
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
        let predicted = next_count(&tried, budget).clamp(1.0, MAX_PANEL_SPP);
        let reach = (SEARCH_REACH * predicted).max(2.0);
        let untried = |n: &u32| tried.iter().all(|t| t.0 != *n);
        let lowest = (predicted - reach).floor().max(1.0) as u32;
        let highest = (predicted + reach).ceil().min(MAX_PANEL_SPP) as u32;
        // The nearest untried count, the larger one of two as near.
        let nearest = (lowest..=highest)
            .filter(untried)
            .filter(|&n| (n as f64 - predicted).abs() <= reach)
            .min_by(|&a, &b| (a as f64 - predicted).abs().total_cmp(&(b as f64 - predicted).abs()).then(b.cmp(&a)));
        match nearest {
            Some(next) => count = next,
            None => break,
        }
    }
    best.expect("at least one run")
}

/// How far from the predicted count the search of [`calibrate`] looks for
/// an untried one, as a fraction of it (and at least 2 counts).
const SEARCH_REACH: f64 = 0.1;

/// The count the runs `tried` (count, time) say takes `budget`: from the
/// line through them (a render has a fixed cost beside its samples) where
/// they span two counts or more and it rises, else from the median time per
/// sample (a median, so that one slow run moves the estimate little).
fn next_count(tried: &[(u32, f64)], budget: f64) -> f64 {
    let n = tried.len() as f64;
    let (mean_x, mean_y) =
        (tried.iter().map(|t| t.0 as f64).sum::<f64>() / n, tried.iter().map(|t| t.1).sum::<f64>() / n);
    let sxx: f64 = tried.iter().map(|t| (t.0 as f64 - mean_x).powi(2)).sum();
    let sxy: f64 = tried.iter().map(|t| (t.0 as f64 - mean_x) * (t.1 - mean_y)).sum();
    if sxx > 0.0 && sxy > 0.0 {
        let slope = sxy / sxx;
        let fixed = mean_y - slope * mean_x;
        let count = (budget - fixed) / slope;
        if count.is_finite() && count > 0.0 {
            return count;
        }
    }
    let mut rates: Vec<f64> = tried.iter().map(|&(n, ms)| ms / n as f64).collect();
    rates.sort_by(f64::total_cmp);
    budget / rates[rates.len() / 2].max(1e-12)
}

/// Renders the candidates at equal time ([`equal_time`]) and adds their
/// panel to `report`, its caption among the findings. The panel's budget
/// is the median of the budget's times measured alongside the entries.
pub(crate) fn add_equal_time_panel(
    report: &mut crate::Report,
    subject: &Subject,
    reference: &Reference,
    file: String,
    what: &str,
    budget: &Budget,
    candidates: &[Candidate],
) {
    let entries = equal_time(subject, reference, budget, candidates);
    let mut budgets: Vec<f64> = entries.iter().filter_map(|e| e.budget_ms).collect();
    budgets.sort_by(f64::total_cmp);
    let budget_ms = budgets.get(budgets.len() / 2).copied().unwrap_or(budget.estimate_ms);
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
    fn no_count_is_run_twice_and_a_cheaper_power_of_two_does_not_trap_the_search() {
        // The stratified sampler's patterns cost more at counts that are
        // not powers of two: 15 samples take longer than 16 here.
        for budget in [100.0, 120.0, 135.0, 150.0] {
            let mut runs = Vec::new();
            let (_, ms, count) = calibrate(budget, 8, EQUAL_TIME_ATTEMPTS, |n| {
                runs.push(n);
                let per_sample = if n.is_power_of_two() { 7.9 } else { 8.9 };
                ((), per_sample * n as f64)
            });
            let mut distinct = runs.clone();
            distinct.sort_unstable();
            distinct.dedup();
            assert_eq!(distinct.len(), runs.len(), "budget {budget}: {runs:?}");
            // 15 and 16 both fit 135 and 120 within 5%; 17 · 8.9 = 151.3 fits 150.
            assert!((ms / budget - 1.0).abs() <= EQUAL_TIME_TOLERANCE, "budget {budget}: {count} took {ms}, {runs:?}");
        }
    }

    #[test]
    fn where_no_count_fits_the_closest_is_kept() {
        // 30 ms a sample: 3 samples take 90 ms, 4 take 120; neither is within 5% of 100.
        let mut runs = Vec::new();
        let (_, ms, count) = calibrate(100.0, 1, EQUAL_TIME_ATTEMPTS, |n| {
            runs.push(n);
            ((), 30.0 * n as f64)
        });
        assert_eq!((count, ms), (3, 90.0));
        assert!(runs.len() < EQUAL_TIME_ATTEMPTS, "the search gives up when no count near the line is left: {runs:?}");
    }

    #[test]
    fn a_count_past_one_that_overran_is_tried_where_time_is_not_monotone() {
        // The costs measured on the Cornell box (ms; 15 a little slower):
        // 14 and 15 samples fall on either side of a 130.5 ms budget's
        // window, and 16 fits.
        let cost = |n: u32| match n {
            12 => 104.2,
            13 => 112.2,
            14 => 119.4,
            15 => 137.7,
            16 => 130.5,
            17 => 158.7,
            n => 9.0 * n as f64,
        };
        let mut runs = Vec::new();
        let (_, ms, count) = calibrate(130.5, 15, EQUAL_TIME_ATTEMPTS, |n| {
            runs.push(n);
            ((), cost(n))
        });
        assert_eq!((count, ms, runs), (16, 130.5, vec![15, 14, 16]));
    }
}
