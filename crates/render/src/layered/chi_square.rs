//! Pearson's χ² test of a direction sampler against the density it claims
//! (the test of Mitsuba's and pbrt-v4's BSDF suites): directions are
//! counted in bins of the hemisphere, the counts expected from the density
//! come from integrating it over each bin, and the statistic is compared
//! with the χ² distribution's quantile.

use std::f64::consts::PI;

use rtgi_math::{Rng, Vec2, Vec3};

/// Bins over θ ∈ [0, π/2] (equal angles, which spread a lobe near the
/// normal over more bins than equal cosines would) and over φ.
const THETA_BINS: usize = 10;
const PHI_BINS: usize = 20;

/// Bins expecting fewer samples than this are pooled into one, where the
/// χ² approximation of the statistic's distribution holds.
const MIN_EXPECTED: f64 = 5.0;

/// The outcome of one test.
#[derive(Debug)]
pub(super) struct ChiSquare {
    pub(super) statistic: f64,
    pub(super) degrees_of_freedom: usize,
    /// The statistic's quantile at the test's significance.
    pub(super) threshold: f64,
    /// Why the test failed outright: samples where the density is zero.
    pub(super) impossible: Option<String>,
}

impl ChiSquare {
    pub(super) fn passed(&self) -> bool {
        self.impossible.is_none() && self.statistic <= self.threshold
    }

    /// The outcome in words.
    pub(super) fn summary(&self) -> String {
        let verdict = if self.passed() { "passed" } else { "FAILED" };
        let impossible = self.impossible.as_deref().unwrap_or("");
        format!(
            "{verdict}: χ² = {:.1} with {} degrees of freedom, threshold {:.1} {impossible}",
            self.statistic, self.degrees_of_freedom, self.threshold
        )
    }
}

/// Draws `samples` directions with `sample` (from uniform numbers of
/// `rng`; `None` for a draw that failed, as BSDF samplers may) and tests
/// them against `pdf`, whose deficit from 1 is the expected share of
/// failed draws. Significance `alpha` (before any correction for the
/// number of tests). Directions are expected above the surface.
pub(super) fn chi_square_test(
    mut sample: impl FnMut(Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    samples: usize,
    rng: &mut Rng,
    alpha: f64,
) -> ChiSquare {
    let bins = THETA_BINS * PHI_BINS;
    // The last count is the failed draws.
    let mut observed = vec![0.0f64; bins + 1];
    let mut impossible = None;
    for _ in 0..samples {
        match sample(Vec2::new(rng.next_f32(), rng.next_f32())) {
            Some(w) if w.z > 0.0 => observed[bin_of(w)] += 1.0,
            Some(w) => impossible = Some(format!("sampled {w} below the surface")),
            None => observed[bins] += 1.0,
        }
    }
    let density = |theta: f64, phi: f64| {
        let (sin_t, cos_t) = theta.sin_cos();
        let w = Vec3::new((sin_t * phi.cos()) as f32, (sin_t * phi.sin()) as f32, cos_t as f32);
        pdf(w) as f64 * sin_t
    };
    let mut expected = vec![0.0f64; bins + 1];
    let (d_theta, d_phi) = (PI / 2.0 / THETA_BINS as f64, 2.0 * PI / PHI_BINS as f64);
    for t in 0..THETA_BINS {
        for p in 0..PHI_BINS {
            let cell = [t as f64 * d_theta, (t + 1) as f64 * d_theta, p as f64 * d_phi, (p + 1) as f64 * d_phi];
            expected[t * PHI_BINS + p] = integrate(&density, cell, 0) * samples as f64;
        }
    }
    let covered: f64 = expected[..bins].iter().sum();
    expected[bins] = (samples as f64 - covered).max(0.0);

    // Counts where nothing is expected are errors, not merely unlikely.
    for (i, (&o, &e)) in observed.iter().zip(&expected).enumerate() {
        if o > 0.0 && e < 1e-9 * samples as f64 {
            impossible = Some(format!("{o} samples in bin {i}, where the density integrates to {e}"));
        }
    }
    let (mut statistic, mut kept) = (0.0, 0usize);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(&expected) {
        if e < MIN_EXPECTED {
            pooled_observed += o;
            pooled_expected += e;
        } else {
            statistic += (o - e) * (o - e) / e;
            kept += 1;
        }
    }
    if pooled_expected > 0.0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        kept += 1;
    }
    let degrees_of_freedom = kept.saturating_sub(1).max(1);
    ChiSquare { statistic, degrees_of_freedom, threshold: chi_square_quantile(degrees_of_freedom, alpha), impossible }
}

fn bin_of(w: Vec3) -> usize {
    let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
    let phi = (w.y as f64).atan2(w.x as f64).rem_euclid(2.0 * PI);
    let t = ((theta / (PI / 2.0) * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let p = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    t * PHI_BINS + p
}

/// The 4-point Gauss–Legendre rule on [−1, 1].
const GAUSS_4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

fn gauss_4x4(f: &impl Fn(f64, f64) -> f64, [x0, x1, y0, y1]: [f64; 4]) -> f64 {
    let (cx, hx, cy, hy) = ((x0 + x1) / 2.0, (x1 - x0) / 2.0, (y0 + y1) / 2.0, (y1 - y0) / 2.0);
    let mut sum = 0.0;
    for (a, wa) in GAUSS_4 {
        for (b, wb) in GAUSS_4 {
            sum += wa * wb * f(cx + hx * a, cy + hy * b);
        }
    }
    sum * hx * hy
}

/// ∫ f over the cell, adaptively: a cell whose 4×4 Gauss–Legendre
/// estimate disagrees with its quarters' is split, down to 4⁷ pieces, so
/// that narrow lobes inside a bin are resolved.
fn integrate(f: &impl Fn(f64, f64) -> f64, cell: [f64; 4], depth: u32) -> f64 {
    let [x0, x1, y0, y1] = cell;
    let (xm, ym) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let quarters = [[x0, xm, y0, ym], [xm, x1, y0, ym], [x0, xm, ym, y1], [xm, x1, ym, y1]];
    let whole = gauss_4x4(f, cell);
    let parts: f64 = quarters.iter().map(|&q| gauss_4x4(f, q)).sum();
    if depth >= 7 || (whole - parts).abs() <= 1e-7 + 1e-5 * parts.abs() {
        return parts;
    }
    quarters.iter().map(|&q| integrate(f, q, depth + 1)).sum()
}

/// The χ² distribution's upper quantile for significance `alpha`: the
/// Wilson–Hilferty approximation k (1 − 2/9k + z √(2/9k))³, z the normal's.
fn chi_square_quantile(k: usize, alpha: f64) -> f64 {
    let k = k as f64;
    let z = normal_upper_quantile(alpha);
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

/// The z with P(Z > z) = `alpha` for a standard normal Z, by bisection on
/// the density's integral (Simpson's rule): slow and plain, and exact
/// enough for a threshold.
fn normal_upper_quantile(alpha: f64) -> f64 {
    let upper_tail = |z: f64| {
        let n = 2000;
        let h = z / n as f64;
        let phi = |t: f64| (-t * t / 2.0).exp() / (2.0 * PI).sqrt();
        let simpson: f64 = (0..=n)
            .map(|i| {
                let weight = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                weight * phi(i as f64 * h)
            })
            .sum::<f64>()
            * h
            / 3.0;
        0.5 - simpson
    };
    let (mut low, mut high) = (0.0, 10.0);
    for _ in 0..60 {
        let mid = (low + high) / 2.0;
        if upper_tail(mid) > alpha {
            low = mid;
        } else {
            high = mid;
        }
    }
    (low + high) / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_are_the_tabulated_ones() {
        assert!((normal_upper_quantile(0.01) - 2.326_348).abs() < 1e-5);
        assert!((normal_upper_quantile(0.001) - 3.090_232).abs() < 1e-5);
        // χ²(0.99; 10) = 23.209, χ²(0.99; 100) = 135.807 from tables.
        assert!((chi_square_quantile(10, 0.01) - 23.209).abs() < 0.1);
        assert!((chi_square_quantile(100, 0.01) - 135.807).abs() < 0.2);
    }
}
