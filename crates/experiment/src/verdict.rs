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

#[cfg(test)]
mod tests {
    use super::*;

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
