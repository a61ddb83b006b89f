//! Comparisons that say whether the measurement tells two configurations
//! apart: a difference inside the spread is "not resolved", never a winner.

use crate::report::Point;
use crate::stats::Timing;

/// A measured figure with the range the repeats gave it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    /// The figure (a median, or the figure of all repeats together).
    pub value: f64,
    /// The smallest value the repeats allow.
    pub low: f64,
    /// The largest value the repeats allow.
    pub high: f64,
}

impl Spread {
    /// A time: median, min and max.
    pub fn time(timing: &Timing) -> Spread {
        Spread { value: timing.median_ms, low: timing.min_ms, high: timing.max_ms }
    }

    /// The efficiency `1 / (MSE · seconds)` of a measured render, from its
    /// RMSE over the seeds and median time; the range takes the worst seed
    /// with the slowest run and the best seed with the fastest.
    pub fn efficiency(point: &Point) -> Option<Spread> {
        let (time, error) = (point.time?, point.error?);
        let efficiency = |rmse: f64, ms: f64| 1.0 / (rmse * rmse * ms * 1e-3).max(1e-300);
        Some(Spread {
            value: error.efficiency(time.median_ms),
            low: efficiency(error.rmse_max, time.max_ms),
            high: efficiency(error.rmse_min, time.min_ms),
        })
    }

    /// The point of `points` with the highest [`Spread::efficiency`], and that efficiency.
    pub fn most_efficient(points: &[Point]) -> Option<(Spread, &Point)> {
        points.iter().filter_map(|p| Some((Spread::efficiency(p)?, p))).max_by(|a, b| a.0.value.total_cmp(&b.0.value))
    }

    /// Whether the two ranges do not overlap.
    pub fn resolved_from(&self, other: &Spread) -> bool {
        self.high < other.low || other.high < self.low
    }
}

/// `a` against `b` in one sentence: "`a` is 1.93× `b`'s efficiency" when
/// the ranges are apart, else that the difference is not resolved.
pub fn compare(what: &str, a_name: &str, a: &Spread, b_name: &str, b: &Spread) -> String {
    let ratio = a.value / b.value.max(1e-300);
    if a.resolved_from(b) {
        format!("{a_name} has {ratio:.2}× the {what} of {b_name}")
    } else {
        format!("{what} of {a_name} and {b_name}: not resolved (ratio {ratio:.2}, inside the spread of the repeats)")
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
                "{a_name} has {ratio:.2}× the {what} of {b_name} (Mann–Whitney p = {p:.3}, {n} and {m} measurements)"
            )
        } else {
            format!(
                "{what} of {a_name} and {b_name}: not resolved (ratio {ratio:.2}, Mann–Whitney p = {p:.2} with {n} and \
                 {m} measurements; {:.0}% confidence asks for p below {:.2})",
                100.0 * CONFIDENCE,
                1.0 - CONFIDENCE
            )
        }
    }
}

fn median(values: &[f64]) -> f64 {
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

    #[test]
    fn overlapping_ranges_are_not_resolved() {
        let a = Spread { value: 1.0, low: 0.9, high: 1.1 };
        let b = Spread { value: 1.09, low: 1.05, high: 1.2 };
        assert!(!a.resolved_from(&b));
        assert!(compare("time", "x", &b, "y", &a).contains("not resolved"));
        let c = Spread { value: 2.0, low: 1.8, high: 2.2 };
        assert!(c.resolved_from(&a));
        assert_eq!(compare("efficiency", "c", &c, "a", &a), "c has 2.00× the efficiency of a");
    }
}
