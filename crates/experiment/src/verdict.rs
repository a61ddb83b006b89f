//! Every comparative sentence of the reports is decided here: whether the
//! measurement tells two configurations apart at [`CONFIDENCE`], by a rank
//! test on the repeats (times of runs, errors of seeds), never by comparing
//! medians or ranges. A difference the test cannot resolve is written "not
//! resolved", never as a winner.
//!
//! Efficiency `1 / (MSE · time)` is a figure of unbiased estimators only:
//! the MSE of a biased one does not fall as 1/time, so its "efficiency"
//! changes with the sample count. [`efficiency`] refuses a configuration
//! whose bias is resolved, and [`describe_bias`] says what it is instead.

use crate::format::format_number;
use crate::report::{ImageError, Point};
use crate::stats::Timing;

/// `a` against `b` by the rank test of their repeats: "`a` has 1.93× the
/// `what` of `b` (Mann–Whitney p = 0.008, …)" where resolved, else "not resolved".
pub fn compare(what: &str, a_name: &str, a: &[f64], b_name: &str, b: &[f64]) -> String {
    RankComparison::of(a, b).sentence(what, a_name, b_name)
}

/// Two timings compared by the rank test of their runs.
pub fn compare_times(what: &str, a_name: &str, a: &Timing, b_name: &str, b: &Timing) -> String {
    compare(what, a_name, &a.samples(), b_name, &b.samples())
}

/// Whether the runs of `a` are resolved from those of `b` (either way).
pub fn times_resolved(a: &Timing, b: &Timing) -> bool {
    RankComparison::of(&a.samples(), &b.samples()).resolved()
}

/// Whether `a` is below `b` beyond the resolution, in a figure where lower
/// is better (a time, an error): resolved by the rank test, and lower.
pub fn resolved_lower(a: &[f64], b: &[f64]) -> bool {
    let test = RankComparison::of(a, b);
    test.resolved() && test.ratio < 1.0
}

/// Which error an efficiency divides by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorMeasure {
    /// Mean squared error of linear radiance: bright pixels dominate it.
    Mse,
    /// Relative MSE: every pixel counts alike, dark ones too; what a noise
    /// target (adaptive sampling) aims at.
    RelativeMse,
}

impl ErrorMeasure {
    /// Its name in sentences.
    pub fn name(self) -> &'static str {
        match self {
            ErrorMeasure::Mse => "efficiency 1/(MSE·time)",
            ErrorMeasure::RelativeMse => "efficiency 1/(relative MSE·time)",
        }
    }
}

/// The efficiency `1 / (MSE · seconds)` of each repeat of a measured
/// render (repeat `i` rendered seed `i`, so its time and its error pair
/// up), or, for a configuration whose bias is resolved, why it has none.
/// `None` for a point without both a time and an error.
pub fn efficiency(point: &Point) -> Option<Result<Vec<f64>, String>> {
    efficiency_by(point, ErrorMeasure::Mse)
}

/// [`efficiency`] with the error `measure` chooses.
pub fn efficiency_by(point: &Point, measure: ErrorMeasure) -> Option<Result<Vec<f64>, String>> {
    let (time, error) = (point.time.as_ref()?, point.error.as_ref()?);
    if error.bias_resolved() {
        return Some(Err(describe_bias(error)));
    }
    let (per_seed, overall) = match measure {
        ErrorMeasure::Mse => (&error.seed_mse, error.mse()),
        ErrorMeasure::RelativeMse => (&error.seed_relative_mse, error.relative_mse),
    };
    let times = time.samples();
    Some(Ok(if times.len() == per_seed.len() {
        times.iter().zip(per_seed).map(|(ms, e)| 1.0 / (e * ms * 1e-3).max(1e-300)).collect()
    } else {
        // A report older than the per-seed errors: its median alone.
        vec![1.0 / (overall * time.median_ms * 1e-3).max(1e-300)]
    }))
}

/// The point of `points` with the highest median efficiency among those
/// whose bias is not resolved, with its per-repeat efficiencies.
pub fn most_efficient(points: &[Point]) -> Option<(Vec<f64>, &Point)> {
    most_efficient_by(points, ErrorMeasure::Mse)
}

/// [`most_efficient`] with the error `measure` chooses.
pub fn most_efficient_by(points: &[Point], measure: ErrorMeasure) -> Option<(Vec<f64>, &Point)> {
    points
        .iter()
        .filter_map(|p| Some((efficiency_by(p, measure)?.ok()?, p)))
        .max_by(|a, b| median(&a.0).total_cmp(&median(&b.0)))
}

/// `a` against `b` by efficiency where neither has a resolved bias;
/// otherwise what the biased ones are: a biased estimator is judged by its
/// error at equal time and by its bias, never by 1/(MSE·time).
pub fn compare_efficiency(a_name: &str, a: &Point, b_name: &str, b: &Point) -> String {
    compare_efficiency_by(ErrorMeasure::Mse, a_name, a, b_name, b)
}

/// [`compare_efficiency`] with the error `measure` chooses.
pub fn compare_efficiency_by(measure: ErrorMeasure, a_name: &str, a: &Point, b_name: &str, b: &Point) -> String {
    match (efficiency_by(a, measure), efficiency_by(b, measure)) {
        (Some(Ok(x)), Some(Ok(y))) => compare(measure.name(), a_name, &x, b_name, &y),
        (Some(x), Some(y)) => {
            let biased: Vec<String> = [(a_name, x), (b_name, y)]
                .into_iter()
                .filter_map(|(name, result)| result.err().map(|bias| format!("{name} is {bias}")))
                .collect();
            format!(
                "{}: no efficiency is given for a biased estimator, whose error does not fall as 1/time; \
                 compare by error at equal time",
                biased.join("; ")
            )
        }
        _ => format!("{a_name} and {b_name}: not both measured with time and error"),
    }
}

/// "biased: bias² 0.0123 (73% of its MSE), energy −4.9%": what a
/// configuration with a resolved bias is, in place of an efficiency.
pub fn describe_bias(error: &ImageError) -> String {
    if error.bias2 > error.bias_resolution {
        format!(
            "biased: bias² {} ({:.0}% of its MSE), energy {:+.1}%",
            format_number(error.bias2),
            100.0 * error.bias2 / error.mse().max(1e-300),
            100.0 * error.energy_change()
        )
    } else {
        // Resolved by the seeds' mean energy alone: too small per pixel to
        // stand out of each pixel's noise.
        format!(
            "biased: energy {:+.1}%, resolved by the seeds' means (per pixel, bias² is within the noise)",
            100.0 * error.energy_change()
        )
    }
}

/// The confidence at which a difference between repeated measurements
/// counts as resolved: a two-sided test must reject "no difference" at
/// 1 − this level.
pub const CONFIDENCE: f64 = 0.95;

/// Two sets of repeated measurements of one figure (the times of a
/// command's runs, or a render's error over seeds), compared by the
/// Mann–Whitney rank test: whether values of one tend to be larger than
/// values of the other, whatever their distribution. Medians, ranges and
/// ratios alone cannot say that; overlapping ranges can still be told
/// apart by ranks, and separate ranges of two runs each cannot be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RankComparison {
    /// Median of `a` over median of `b`.
    pub ratio: f64,
    /// The two-sided p-value of "neither tends to be larger": exact for
    /// samples of up to 40 each (ties counted a half, which makes it a
    /// little conservative), a normal approximation beyond.
    pub p_value: f64,
    /// Measurements of each side.
    pub counts: (usize, usize),
}

impl RankComparison {
    /// Compares the measurements `a` against `b` (each at least one value).
    pub fn of(a: &[f64], b: &[f64]) -> RankComparison {
        let (n, m) = (a.len(), b.len());
        assert!(n > 0 && m > 0, "a comparison needs measurements on both sides");
        // U: the pairs in which a's value is larger, ties counting a half.
        let u: f64 = a
            .iter()
            .map(|x| {
                b.iter()
                    .map(|y| {
                        if x > y {
                            1.0
                        } else if x == y {
                            0.5
                        } else {
                            0.0
                        }
                    })
                    .sum::<f64>()
            })
            .sum();
        let p_value = if n <= 40 && m <= 40 { exact_p_value(u, n, m) } else { normal_p_value(u, n, m) };
        RankComparison { ratio: median(a) / median(b).max(1e-300), p_value, counts: (n, m) }
    }

    /// Whether the test tells the two apart at [`CONFIDENCE`].
    pub fn resolved(&self) -> bool {
        self.p_value < 1.0 - CONFIDENCE
    }

    /// One sentence: "`a` has 1.93× the `what` of `b` (Mann–Whitney p =
    /// 0.008, 5 and 5 runs)" where resolved, else that it is not resolved.
    pub fn sentence(&self, what: &str, a_name: &str, b_name: &str) -> String {
        let (ratio, p, (n, m)) = (self.ratio, self.p_value, self.counts);
        if self.resolved() {
            format!(
                "{a_name} has {}× the {what} of {b_name} (Mann–Whitney p = {p:.3}, {n} and {m} measurements)",
                format_ratio(ratio)
            )
        } else {
            format!(
                "{what} of {a_name} and {b_name}: not resolved (ratio {}, Mann–Whitney p = {p:.2} with {n} and \
                 {m} measurements; {:.0}% confidence asks for p below {:.2})",
                format_ratio(ratio),
                100.0 * CONFIDENCE,
                1.0 - CONFIDENCE
            )
        }
    }
}

/// A ratio with two decimals, or three significant digits below 0.1 (a
/// ratio of 0.004 is not "0.00×").
fn format_ratio(ratio: f64) -> String {
    if ratio >= 0.1 || ratio == 0.0 || !ratio.is_finite() { format!("{ratio:.2}") } else { format!("{ratio:.2e}") }
}

/// The median of `values` (the mean of the middle two for an even count).
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let middle = sorted.len() / 2;
    if sorted.len() % 2 == 1 { sorted[middle] } else { 0.5 * (sorted[middle - 1] + sorted[middle]) }
}

/// The exact two-sided p-value of U for samples of `n` and `m` without
/// ties: the share of the C(n + m, n) equally likely orderings whose U is
/// as far from its mean n·m/2, counted by the recurrence
/// N(n, m, u) = N(n − 1, m, u − m) + N(n, m − 1, u) (Mann and Whitney, 1947).
fn exact_p_value(u: f64, n: usize, m: usize) -> f64 {
    // counts[j][u]: orderings of i values of a and j of b with statistic u, for the current i.
    let cells = n * m + 1;
    let mut counts: Vec<Vec<f64>> = (0..=m).map(|_| vec![0.0; cells]).collect();
    for row in counts.iter_mut() {
        row[0] = 1.0; // i = 0: one ordering, U = 0
    }
    for _i in 1..=n {
        let mut next: Vec<Vec<f64>> = (0..=m).map(|_| vec![0.0; cells]).collect();
        next[0][0] = 1.0;
        for j in 1..=m {
            for k in 0..cells {
                // The largest value is a's (it beats all j of b's) or b's.
                let from_a = if k >= j { counts[j][k - j] } else { 0.0 };
                next[j][k] = from_a + next[j - 1][k];
            }
        }
        counts = next;
    }
    let distribution = &counts[m];
    let total: f64 = distribution.iter().sum();
    let mean = (n * m) as f64 / 2.0;
    let distance = (u - mean).abs();
    // Orderings at least as far from the mean, either way (a tolerance for the half-counted ties).
    let extreme: f64 = distribution
        .iter()
        .enumerate()
        .filter(|(k, _)| (*k as f64 - mean).abs() >= distance - 1e-9)
        .map(|(_, count)| count)
        .sum();
    (extreme / total).min(1.0)
}

/// The two-sided p-value of U from its normal approximation (mean n·m/2,
/// variance n·m·(n + m + 1)/12, with a continuity correction of ½).
fn normal_p_value(u: f64, n: usize, m: usize) -> f64 {
    let (n, m) = (n as f64, m as f64);
    let sigma = (n * m * (n + m + 1.0) / 12.0).sqrt();
    let z = (((u - n * m / 2.0).abs() - 0.5).max(0.0)) / sigma;
    (2.0 * 0.5 * erfc(z / std::f64::consts::SQRT_2)).min(1.0)
}

/// The complementary error function (Numerical Recipes' erfcc, relative
/// error below 1.2e-7: far finer than any p-value is read).
fn erfc(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.5 * x.abs());
    let poly = -x * x - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98 + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let value = t * poly.exp();
    if x >= 0.0 { value } else { 2.0 - value }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rank_test_tells_separated_samples_apart_and_not_overlapping_ones() {
        // Five runs each, wholly apart: the most extreme of C(10, 5) = 252
        // orderings either way, p = 2/252.
        let fast = [98.0, 101.0, 99.5, 100.2, 100.8];
        let slow = [110.0, 112.5, 109.8, 111.1, 110.4];
        let apart = RankComparison::of(&slow, &fast);
        assert!((apart.p_value - 2.0 / 252.0).abs() < 1e-12, "{apart:?}");
        assert!(apart.resolved());
        assert_eq!(
            apart.sentence("time", "slow", "fast"),
            "slow has 1.10× the time of fast (Mann–Whitney p = 0.008, 5 and 5 measurements)"
        );
        // Interleaved: medians differ by 1%, the ranks say nothing.
        let a = [100.0, 102.0, 104.0, 106.0, 108.0];
        let b = [101.0, 103.0, 105.0, 107.0, 109.0];
        let overlapping = RankComparison::of(&a, &b);
        assert!(!overlapping.resolved() && overlapping.p_value > 0.5, "{overlapping:?}");
        let sentence = overlapping.sentence("time", "a", "b");
        assert!(sentence.starts_with("time of a and b: not resolved (ratio 0.99, Mann–Whitney p = "), "{sentence}");
        // Two runs each can never resolve at 95%: the most extreme ordering has p = 2/6.
        let few = RankComparison::of(&[1.0, 1.1], &[5.0, 5.1]);
        assert!(!few.resolved() && (few.p_value - 1.0 / 3.0).abs() < 1e-12, "{few:?}");
    }

    #[test]
    fn the_exact_and_the_normal_p_values_agree_where_both_apply() {
        // Forty against forty, shifted by a little and by more: both ways of
        // computing p agree as far as the normal approximation's tail error
        // allows (about 6% at p = 0.008).
        for (shift, tolerance) in [(2.5, 0.03), (7.5, 0.1)] {
            let a: Vec<f64> = (0..40).map(|i| i as f64).collect();
            let b: Vec<f64> = (0..40).map(|i| i as f64 + shift).collect();
            let u: f64 = a.iter().map(|x| b.iter().filter(|y| x > *y).count() as f64).sum();
            let (exact, normal) = (exact_p_value(u, 40, 40), normal_p_value(u, 40, 40));
            assert!((exact - normal).abs() < tolerance * exact, "shift {shift}: exact {exact}, normal {normal}");
        }
        assert!((erfc(0.0) - 1.0).abs() < 1e-7 && (erfc(1.0) - 0.157_299_207).abs() < 1e-7);
    }

    /// A measured point: five runs of `ms` ± 1%, five seeds of MSE `mse` ±
    /// 1%, and a mean radiance `energy` times the reference's.
    fn point(ms: f64, mse: f64, energy: f64) -> Point {
        let jitter = [-1.0, -0.5, 0.0, 0.5, 1.0];
        let mut p = Point::new(16.0, "16");
        p.time = Some(Timing::of(&jitter.map(|j| ms * (1.0 + 0.01 * j))));
        let seed_mse: Vec<f64> = jitter.iter().map(|j| mse * (1.0 + 0.01 * j)).collect();
        let seed_means: Vec<f64> = jitter.iter().map(|j| energy * (1.0 + 1e-4 * j)).collect();
        p.error = Some(ImageError {
            rmse: mse.sqrt(),
            rmse_min: (0.99 * mse).sqrt(),
            rmse_max: (1.01 * mse).sqrt(),
            relative_mse: mse,
            mean: energy,
            reference_mean: 1.0,
            bias2: (energy - 1.0).powi(2),
            variance: mse,
            bias_resolution: 1e-3,
            seeds: 5,
            reference_mean_noise: 0.0,
            seed_mse,
            seed_relative_mse: jitter.iter().map(|j| mse * (1.0 + 0.01 * j)).collect(),
            seed_means,
        });
        p
    }

    #[test]
    fn efficiency_is_compared_only_between_unbiased_configurations() {
        // Half the MSE in the same time: resolved, twice the efficiency.
        let (good, plain) = (point(100.0, 0.5, 1.0), point(100.0, 1.0, 1.0));
        let sentence = compare_efficiency("good", &good, "plain", &plain);
        assert!(
            sentence.starts_with("good has 2.00× the efficiency 1/(MSE·time) of plain (Mann–Whitney"),
            "{sentence}"
        );
        // Within the noise of each other: not resolved.
        let close = point(100.5, 1.0, 1.0);
        let sentence = compare_efficiency("close", &close, "plain", &plain);
        assert!(sentence.contains(": not resolved (ratio"), "{sentence}");
        // 10% of the energy lost, resolved by the seeds' means: biased, no efficiency.
        let clamped = point(100.0, 0.3, 0.9);
        assert!(efficiency(&clamped).unwrap().is_err());
        let sentence = compare_efficiency("the clamp", &clamped, "no clamp", &plain);
        assert!(sentence.starts_with("the clamp is biased: bias² 0.01"), "{sentence}");
        assert!(sentence.contains("energy -10.0%") && !sentence.contains("× the efficiency"), "{sentence}");
        // A ratio far below one keeps its digits.
        assert!(
            RankComparison::of(&[1.0, 1.01, 1.02, 1.03, 1.04], &[500.0, 501.0, 502.0, 503.0, 504.0])
                .sentence("time", "a", "b")
                .starts_with("a has 2.03e-3× the time of b")
        );
        // The most efficient skips the biased one, however low its MSE.
        let points = [plain.clone(), clamped, good.clone()];
        assert_eq!(most_efficient(&points).map(|(_, p)| p.time.clone()), Some(good.time.clone()));
    }
}
