//! The statistics of the experiments: timings as median with min and max,
//! power laws fitted on log-log axes with their standard errors, and the
//! error of renders over several seeds split into bias and variance.

use rtgi_image::HdrImage;
use serde::{Deserialize, Serialize};

/// Repeated timings of one measurement, in milliseconds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Median of the runs, in milliseconds.
    pub median_ms: f64,
    /// Fastest run, in milliseconds.
    pub min_ms: f64,
    /// Slowest run, in milliseconds.
    pub max_ms: f64,
    /// Number of runs.
    pub runs: usize,
    /// Every run, in the order they were measured: what the rank test of
    /// [`crate::verdict`] compares (a render's run `i` used seed `i`).
    #[serde(default)]
    pub runs_ms: Vec<f64>,
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
            runs_ms: runs.to_vec(),
        }
    }

    /// The runs the rank test compares; a timing read from a report older
    /// than them has only its median.
    pub fn samples(&self) -> Vec<f64> {
        if self.runs_ms.is_empty() { vec![self.median_ms] } else { self.runs_ms.clone() }
    }
}

/// How far renders of one configuration are from the reference, over all
/// pixels and channels of linear radiance and over the seeds they were
/// rendered with.
///
/// The mean squared error of one render splits into the squared bias of its
/// estimator and its variance: per pixel, over seeds, `E[(X − R)²] = (E[X] −
/// R)² + Var X`. With `n` seeds, the variance is estimated by the seeds'
/// sample variance `s²`, and the squared bias by `(mean − R)² − s²/n −
/// σ_R²`, which removes what the mean's own noise (`s²/n`) and the
/// reference's noise (`σ_R²`) add to it; it can come out slightly negative
/// when there is no bias. A bias below [`ImageError::bias_resolution`] is not resolved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageError {
    /// Root mean square error: `sqrt` of the mean squared error over the
    /// seeds (each render with its own seed).
    pub rmse: f64,
    /// The smallest RMSE of one render.
    pub rmse_min: f64,
    /// The largest RMSE of one render.
    pub rmse_max: f64,
    /// Mean of `(test − reference)² / (reference² + 0.01)` over the renders:
    /// dark pixels count as much as bright ones.
    pub relative_mse: f64,
    /// Mean radiance of the renders, against the reference's: where they
    /// differ, energy is missing (or added), not only noise.
    pub mean: f64,
    /// Mean radiance of the reference.
    pub reference_mean: f64,
    /// Squared bias, averaged over pixels and channels (see the type's documentation).
    pub bias2: f64,
    /// Variance of one render, averaged over pixels and channels.
    pub variance: f64,
    /// How large `bias2` must be to be told apart from noise: the mean's
    /// variance and the reference's noise that were subtracted from it.
    pub bias_resolution: f64,
    /// Renders (seeds) behind these figures.
    pub seeds: usize,
    /// The standard error of the reference's mean radiance: its per-pixel
    /// noise over the square root of the pixel count.
    #[serde(default)]
    pub reference_mean_noise: f64,
    /// The MSE of each render, in seed order: what the rank test of
    /// [`crate::verdict`] compares.
    #[serde(default)]
    pub seed_mse: Vec<f64>,
    /// The relative MSE of each render, in seed order.
    #[serde(default)]
    pub seed_relative_mse: Vec<f64>,
    /// The mean radiance of each render, in seed order.
    #[serde(default)]
    pub seed_means: Vec<f64>,
}

impl ImageError {
    /// The mean squared error of one render.
    pub fn mse(&self) -> f64 {
        self.rmse * self.rmse
    }

    /// Whether the bias is told apart from the noise: its squared bias
    /// beyond [`ImageError::bias_resolution`], or its energy beyond the
    /// spread of the seeds' means ([`ImageError::energy_resolved`]).
    pub fn bias_resolved(&self) -> bool {
        self.seeds > 1 && (self.bias2 > self.bias_resolution || self.energy_resolved())
    }

    /// The energy the renders gain (positive) or lose (negative) against
    /// the reference, as a fraction of the reference's mean radiance.
    pub fn energy_change(&self) -> f64 {
        self.mean / self.reference_mean.max(1e-300) - 1.0
    }

    /// Whether the renders' mean radiance differs from the reference's
    /// beyond chance: by more than the 99% two-sided Student-t interval of
    /// the seeds' means (with the reference's noise on its mean added).
    /// A bias spread over the image shows here long before it shows per
    /// pixel, where each pixel's noise hides it.
    pub fn energy_resolved(&self) -> bool {
        let n = self.seed_means.len();
        if n < 2 {
            return false;
        }
        let mean = self.seed_means.iter().sum::<f64>() / n as f64;
        let variance = self.seed_means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let half_width = student_t_99(n - 1) * (variance / n as f64).sqrt();
        (mean - self.reference_mean).abs() > half_width + 3.0 * self.reference_mean_noise
    }

    /// Efficiency, `1 / (MSE · seconds)`: a configuration twice as
    /// efficient reaches the same error in half the time (for unbiased estimators).
    pub fn efficiency(&self, time_ms: f64) -> f64 {
        1.0 / (self.mse() * time_ms * 1e-3).max(1e-300)
    }
}

/// Renders of one configuration with different seeds, gathered pixel by
/// pixel against a reference, for [`ImageError`].
#[derive(Debug)]
pub struct SeedErrors<'a> {
    reference: &'a HdrImage,
    reference_noise_rmse: f64,
    sum: Vec<f64>,
    sum_squares: Vec<f64>,
    mse: Vec<f64>,
    relative_mse: Vec<f64>,
    mean: Vec<f64>,
}

impl<'a> SeedErrors<'a> {
    /// Gathers against `reference`, whose own RMSE against the truth is `reference_noise_rmse`.
    pub fn new(reference: &'a HdrImage, reference_noise_rmse: f64) -> SeedErrors<'a> {
        let n = reference.pixels().len() * 3;
        SeedErrors {
            reference,
            reference_noise_rmse,
            sum: vec![0.0; n],
            sum_squares: vec![0.0; n],
            mse: Vec::new(),
            relative_mse: Vec::new(),
            mean: Vec::new(),
        }
    }

    /// Adds one render; panics unless it has the reference's size.
    pub fn add(&mut self, image: &HdrImage) {
        let d = rtgi_image::compare(image, self.reference).expect("the render has the reference's size");
        self.mse.push(d.rmse * d.rmse);
        self.relative_mse.push(d.relative_mse);
        self.mean.push(d.mean);
        let values = image.pixels().iter().flat_map(|p| p.to_array());
        for ((sum, squares), value) in self.sum.iter_mut().zip(&mut self.sum_squares).zip(values) {
            *sum += value as f64;
            *squares += value as f64 * value as f64;
        }
    }

    /// The figures of the renders added so far; panics if there were none.
    pub fn error(&self) -> ImageError {
        let seeds = self.mse.len();
        assert!(seeds > 0, "at least one render");
        let n = seeds as f64;
        // Per pixel, the bias term (mean − R)² − s²/n and the variance,
        // summed over its channels.
        let mut terms = Vec::with_capacity(self.reference.pixels().len());
        let mut variance = 0.0;
        for (pixel, r) in self.reference.pixels().iter().enumerate() {
            let mut term = 0.0;
            for (channel, r) in r.to_array().into_iter().enumerate() {
                let i = pixel * 3 + channel;
                let mean = self.sum[i] / n;
                let sample_variance =
                    if seeds > 1 { ((self.sum_squares[i] - n * mean * mean) / (n - 1.0)).max(0.0) } else { 0.0 };
                variance += sample_variance;
                term += (mean - r as f64).powi(2) - sample_variance / n;
            }
            terms.push(term / 3.0);
        }
        let count = self.sum.len().max(1) as f64;
        let pixels = terms.len().max(1) as f64;
        let noise2 = self.reference_noise_rmse * self.reference_noise_rmse;
        let mean_term = terms.iter().sum::<f64>() / pixels;
        let (bias2, variance) = (mean_term - noise2, variance / count);
        // Under no bias the terms scatter about σ_R²; three standard errors
        // of their mean, estimated from the terms themselves (renders have
        // heavy tails, so no Gaussian rule of thumb), are what a bias must
        // exceed. The channels of a pixel are correlated, so pixels, not
        // channels, are the independent terms.
        let scatter = terms.iter().map(|t| (t - mean_term).powi(2)).sum::<f64>() / (pixels - 1.0).max(1.0);
        let reference_mean =
            self.reference.pixels().iter().flat_map(|p| p.to_array()).map(f64::from).sum::<f64>() / count;
        ImageError {
            rmse: (self.mse.iter().sum::<f64>() / n).sqrt(),
            rmse_min: self.mse.iter().copied().fold(f64::INFINITY, f64::min).sqrt(),
            rmse_max: self.mse.iter().copied().fold(0.0, f64::max).sqrt(),
            relative_mse: self.relative_mse.iter().sum::<f64>() / n,
            mean: self.mean.iter().sum::<f64>() / n,
            reference_mean,
            bias2,
            variance,
            bias_resolution: if seeds > 1 { 3.0 * (scatter / pixels).sqrt() } else { f64::MAX },
            seeds,
            reference_mean_noise: self.reference_noise_rmse / pixels.sqrt(),
            seed_mse: self.mse.clone(),
            seed_relative_mse: self.relative_mse.clone(),
            seed_means: self.mean.clone(),
        }
    }
}

/// The 99.5% quantile of Student's t with `degrees` degrees of freedom:
/// the half-width, in standard errors, of a 99% two-sided interval.
fn student_t_99(degrees: usize) -> f64 {
    const TABLE: [f64; 10] = [63.657, 9.925, 5.841, 4.604, 4.032, 3.707, 3.499, 3.355, 3.250, 3.169];
    match degrees {
        0 => f64::INFINITY,
        1..=10 => TABLE[degrees - 1],
        11..=30 => 3.169 - (degrees - 10) as f64 * (3.169 - 2.750) / 20.0,
        _ => 2.576,
    }
}

/// `y = a · x^exponent`, fitted by least squares to `(ln x, ln y)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PowerLaw {
    /// The fitted exponent: the slope on log-log axes.
    pub exponent: f64,
    /// The exponent's standard error from the fit's residuals (0 for two
    /// points, which any line passes through).
    pub standard_error: f64,
    /// `a` above: the fitted value at `x = 1`.
    pub scale: f64,
    /// Points the fit used (those with positive, finite `x` and `y`).
    pub points: usize,
    /// The smallest `x` fitted.
    pub x_min: f64,
    /// The largest `x` fitted.
    pub x_max: f64,
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
        let intercept = mean_y - exponent * mean_x;
        let residuals: f64 = logs.iter().map(|p| (p.1 - intercept - exponent * p.0).powi(2)).sum();
        let standard_error = if logs.len() > 2 { (residuals / (n - 2.0) / sxx).sqrt() } else { 0.0 };
        let used = points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite());
        let (x_min, x_max) = used.fold((f64::INFINITY, 0.0f64), |(lo, hi), (x, _)| (lo.min(*x), hi.max(*x)));
        Some(PowerLaw { exponent, standard_error, scale: intercept.exp(), points: logs.len(), x_min, x_max })
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
        assert!(fit.standard_error < 1e-12 && (fit.x_min, fit.x_max) == (1.0, 16.0), "{fit:?}");
        assert!(PowerLaw::fit(&[(2.0, 1.0), (2.0, 3.0)]).is_none());
    }

    #[test]
    fn the_standard_error_grows_with_the_scatter() {
        let scattered = [(1.0, 1.0), (2.0, 0.9), (4.0, 0.4), (8.0, 0.45), (16.0, 0.2)];
        let fit = PowerLaw::fit(&scattered).unwrap();
        // The same least squares in Python's floats: slope −0.5644, standard error 0.1165.
        assert!((fit.exponent + 0.5644).abs() < 1e-4 && (fit.standard_error - 0.1165).abs() < 1e-4, "{fit:?}");
    }

    fn image(values: &[f32]) -> HdrImage {
        let pixels = values.iter().map(|&v| rtgi_math::Vec3::splat(v)).collect();
        HdrImage::from_pixels(values.len() as u32, 1, pixels).unwrap()
    }

    #[test]
    fn splits_the_error_into_bias_and_variance() {
        // Seeds scattered ±1 around the truth + 0.5: bias² 0.25, variance 4/3 (the sample variance of ±1 over 4 seeds).
        let reference = image(&[2.0; 64]);
        let mut errors = SeedErrors::new(&reference, 0.0);
        for offset in [-1.0, 1.0, -1.0, 1.0] {
            errors.add(&image(&[2.5 + offset; 64]));
        }
        let e = errors.error();
        assert!((e.variance - 4.0 / 3.0).abs() < 1e-9 && (e.bias2 - (0.25 - 1.0 / 3.0)).abs() < 1e-9, "{e:?}");
        assert!((e.mse() - 1.25).abs() < 1e-9, "MSE = bias² + the seeds' mean square spread: {e:?}");
        // An unbiased estimator's bias² is within its resolution; a strongly biased one's is not.
        assert!(!e.bias_resolved());
        let mut biased = SeedErrors::new(&reference, 0.0);
        for offset in [-0.1, 0.1, -0.1, 0.1] {
            biased.add(&image(&[3.0 + offset; 64]));
        }
        assert!(biased.error().bias_resolved() && (biased.error().bias2 - 1.0).abs() < 0.01);
    }
}
