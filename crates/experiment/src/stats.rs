//! The statistics of the experiments: timings as median with min and max,
//! and power laws fitted on log-log axes.

use serde::Serialize;

/// Repeated timings of one measurement, in milliseconds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Timing {
    /// Median of the runs, in milliseconds.
    pub median_ms: f64,
    /// Fastest run, in milliseconds.
    pub min_ms: f64,
    /// Slowest run, in milliseconds.
    pub max_ms: f64,
    /// Number of runs.
    pub runs: usize,
}

impl Timing {
    /// The median, min and max of `runs` (at least one). For an even count
    /// the median is the upper of the two middle values, a time that was
    /// actually measured.
    pub fn of(runs: &[f64]) -> Timing {
        assert!(!runs.is_empty(), "a timing needs at least one run");
        let mut sorted = runs.to_vec();
        sorted.sort_by(f64::total_cmp);
        Timing {
            median_ms: sorted[sorted.len() / 2],
            min_ms: sorted[0],
            max_ms: sorted[sorted.len() - 1],
            runs: sorted.len(),
        }
    }
}

/// `y = a · x^exponent`, fitted by least squares to `(ln x, ln y)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PowerLaw {
    /// The fitted exponent: the slope on log-log axes.
    pub exponent: f64,
    /// `a` above: the fitted value at `x = 1`.
    pub scale: f64,
    /// Points the fit used (those with positive, finite `x` and `y`).
    pub points: usize,
}

impl PowerLaw {
    /// Fits the points with positive, finite coordinates; `None` if fewer
    /// than two remain or their `x` are all equal.
    pub fn fit(points: &[(f64, f64)]) -> Option<PowerLaw> {
        let logs: Vec<(f64, f64)> = points
            .iter()
            .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
            .map(|(x, y)| (x.ln(), y.ln()))
            .collect();
        let n = logs.len() as f64;
        if logs.len() < 2 {
            return None;
        }
        let mean_x = logs.iter().map(|p| p.0).sum::<f64>() / n;
        let mean_y = logs.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = logs.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
        let sxy: f64 = logs.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
        if sxx <= 0.0 {
            return None;
        }
        let exponent = sxy / sxx;
        Some(PowerLaw { exponent, scale: (mean_y - exponent * mean_x).exp(), points: logs.len() })
    }

    /// The fitted value `a · x^exponent` at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.scale * x.powf(self.exponent)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timing_reports_median_min_and_max() {
        let t = Timing::of(&[5.0, 1.0, 3.0, 9.0, 4.0]);
        assert_eq!((t.median_ms, t.min_ms, t.max_ms, t.runs), (4.0, 1.0, 9.0, 5));
    }

    #[test]
    fn fits_an_exact_power_law_and_skips_unusable_points() {
        let points: Vec<(f64, f64)> =
            [1.0, 2.0, 4.0, 8.0, 16.0].iter().map(|&x| (x, 3.0 * f64::powf(x, -0.5))).collect();
        let mut with_junk = points.clone();
        with_junk.push((0.0, 1.0));
        with_junk.push((4.0, f64::NAN));
        let fit = PowerLaw::fit(&with_junk).unwrap();
        assert!((fit.exponent + 0.5).abs() < 1e-12 && (fit.scale - 3.0).abs() < 1e-12, "{fit:?}");
        assert_eq!(fit.points, 5);
        assert!(PowerLaw::fit(&[(2.0, 1.0), (2.0, 3.0)]).is_none());
    }
}
