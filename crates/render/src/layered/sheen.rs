//! The sheen lobe of KHR_materials_sheen: the "Charlie" distribution of
//! fibre normals (Estevez and Kulla, "Production Friendly Microfacet Sheen
//! BRDF", SIGGRAPH 2017 course) with Smith's height-correlated
//! masking-shadowing, `V = 1 / ((1 + Λ(wo) + Λ(wi)) · 4 cos θo cos θi)`.
//!
//! Estevez and Kulla computed Λ of their distribution numerically and
//! fitted a curve to it; the glTF specification quotes the fit. The fit
//! stays finite as the direction becomes grazing, where the true Λ grows
//! as 1 / cos θ, and for smooth sheens it is 3.4 to 6 times too small at
//! every angle (roughness 0.07). The lobe's directional albedo then
//! exceeds 1 near grazing for roughnesses below about 0.2: 2.9 at
//! roughness 0.07 and cos θ = 0.001, 1.08 at cos θ = 0.05 (Ashikhmin's
//! visibility, the specification's cheaper alternative, reaches 5.7).
//! Albedo scaling needs an albedo of at most 1, so Λ is computed here from
//! its definition, Λ(w) = P(w) / cos θ − 1 with P the normals' area
//! projected onto `w`, tabulated once; the lobe is then an exact Smith
//! microfacet lobe, and reflects at most what it receives.

use std::f32::consts::PI;
use std::sync::LazyLock;

use rtgi_math::Vec3;

use super::quadrature::gauss_legendre;
use super::table::Table2;

/// The smallest sheen roughness evaluated: smoother sheens are evaluated
/// at this one. MaterialX's Imageworks sheen clamps the width r = roughness²
/// at 0.005 likewise; below it the distribution is a spike at the horizon
/// that no table or sampler resolves.
pub(super) const MIN_ROUGHNESS: f32 = 0.07;

/// The Charlie distribution of normals at cos θm = `cos_m` for width r =
/// `alpha`: (2 + 1/r) sin^(1/r) θm / 2π, normalised so that the normals'
/// projected area is 1.
pub(super) fn charlie_d(cos_m: f32, alpha: f32) -> f32 {
    let inverse = 1.0 / alpha;
    let sin2 = (1.0 - cos_m * cos_m).max(0.0);
    (2.0 + inverse) * sin2.powf(0.5 * inverse) / (2.0 * PI)
}

/// The sheen's BRDF for white `sheenColor`, both directions above the
/// surface: D(h) V(wo, wi).
pub(super) fn value(wo: Vec3, wi: Vec3, roughness: f32) -> f32 {
    let h = (wo + wi).normalize_or_zero();
    if h == Vec3::ZERO {
        return 0.0;
    }
    let roughness = clamped(roughness);
    let d = charlie_d(h.z, roughness * roughness);
    d / ((1.0 + lambda(wo.z, roughness) + lambda(wi.z, roughness)) * 4.0 * wo.z * wi.z)
}

/// `roughness` within the range the tables cover.
pub(super) fn clamped(roughness: f32) -> f32 {
    roughness.clamp(MIN_ROUGHNESS, 1.0)
}

/// Where a roughness in [`MIN_ROUGHNESS`], 1 lies on the tables' roughness
/// axis: by its logarithm, because the sheen's albedo and Λ change far
/// faster with roughness near its smallest values.
pub(super) fn roughness_coordinate(roughness: f32) -> f32 {
    1.0 - clamped(roughness).ln() / MIN_ROUGHNESS.ln()
}

/// The inverse of [`roughness_coordinate`].
pub(super) fn roughness_at(coordinate: f32) -> f32 {
    (MIN_ROUGHNESS.ln() * (1.0 - coordinate)).exp()
}

/// Smith's Λ of the Charlie distribution for a direction of cosine `cos`
/// (> 0), read from the table of projected areas.
pub(super) fn lambda(cos: f32, roughness: f32) -> f32 {
    let area = PROJECTED_AREA.lookup((1.0 - cos).max(0.0).sqrt(), roughness_coordinate(roughness));
    (area / cos - 1.0).max(0.0)
}

/// The normals' area projected onto directions, over cos θ (through
/// sqrt(1 − cos θ), which follows the rapid growth of the fibres' sides
/// as the view tilts from the normal) and roughness (by its logarithm).
/// 32 × 32 nodes; within 0.5% of the integral (the interpolation's error:
/// the nodes are within 10⁻⁴).
static PROJECTED_AREA: LazyLock<Table2<f32>> = LazyLock::new(|| {
    let rule = gauss_legendre(24);
    Table2::build(32, 32, |x, y| {
        let roughness = roughness_at(y);
        projected_area((1.0 - x * x).max(0.0), roughness * roughness, &rule)
    })
});

/// P(w) = ∫ max(0, w·m) D(m) dm for a direction of cosine `cos` and width
/// `alpha`, by the quadrature `rule` (on [0, 1]) over θm; the integral
/// over the normals' azimuth is done in closed form: for `a` = sin θ sin θm
/// and `b` = cos θ cos θm, ∫ max(0, a cos φ + b) dφ over the circle is
/// 2πb when b ≥ a and 2(a sin φc + b φc), φc = acos(−b/a), otherwise.
pub(super) fn projected_area(cos: f32, alpha: f32, rule: &[(f64, f64)]) -> f32 {
    let (cos, sin) = (cos as f64, (1.0 - cos as f64 * cos as f64).max(0.0).sqrt());
    let mut sum = 0.0f64;
    for &(t, weight) in rule {
        let theta_m = t * std::f64::consts::FRAC_PI_2;
        let (sin_m, cos_m) = theta_m.sin_cos();
        let (a, b) = (sin * sin_m, cos * cos_m);
        let around = if b >= a {
            2.0 * std::f64::consts::PI * b
        } else {
            let phi_c = (-b / a).acos();
            2.0 * (a * phi_c.sin() + b * phi_c)
        };
        sum += weight * charlie_d(cos_m as f32, alpha) as f64 * sin_m * around;
    }
    (sum * std::f64::consts::FRAC_PI_2) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Rng;

    /// Estevez and Kulla's fit of Λ, as KHR_materials_sheen quotes it.
    fn fitted_lambda(cos: f32, alpha: f32) -> f32 {
        let l = |x: f32| {
            let t = (1.0 - alpha) * (1.0 - alpha);
            let mix = |p: f32, q: f32| p + (q - p) * t;
            let (a, b, c) = (mix(21.5473, 25.3245), mix(3.82987, 3.32435), mix(0.19823, 0.16801));
            let (d, e) = (mix(-1.97760, -1.27393), mix(-4.32054, -4.85967));
            a / (1.0 + b * x.powf(c)) + d * x + e
        };
        if cos < 0.5 { l(cos).exp() } else { (2.0 * l(0.5) - l(1.0 - cos)).exp() }
    }

    #[test]
    fn the_distribution_is_normalised() {
        // ∫ D(m) cos θm dm = 1, and so the projected area at the normal is 1.
        for roughness in [MIN_ROUGHNESS, 0.3, 1.0] {
            let alpha = roughness * roughness;
            let n = 20_000;
            let integral: f64 = (0..n)
                .map(|k| {
                    let theta = (k as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                    let weight = 2.0 * std::f64::consts::PI * theta.sin() * theta.cos();
                    charlie_d(theta.cos() as f32, alpha) as f64 * weight
                })
                .sum::<f64>()
                * std::f64::consts::FRAC_PI_2
                / n as f64;
            assert!((integral - 1.0).abs() < 1e-3, "{roughness}: {integral}");
            assert!((projected_area(1.0, alpha, &gauss_legendre(24)) - 1.0).abs() < 1e-4);
        }
    }

    #[test]
    fn tabulated_lambda_matches_monte_carlo_and_the_published_fit_where_it_holds() {
        // Independently of the closed-form azimuth and the table: P(w) as
        // the mean of max(0, w·m) D(m) over uniform normals, 400k samples.
        let mut rng = Rng::new(21, 22);
        for (cos, roughness) in [(0.05f32, 0.1f32), (0.3, 0.23), (0.62, 0.55), (0.97, 0.8), (0.15, 1.0)] {
            let alpha = roughness * roughness;
            let w = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let n = 400_000;
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let z = rng.next_f32();
                let r = (1.0 - z * z).sqrt();
                let phi = 2.0 * PI * rng.next_f32();
                let m = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                let x = (w.dot(m).max(0.0) * charlie_d(z, alpha) * 2.0 * PI) as f64;
                sum += x;
                sum2 += x * x;
            }
            let mean = sum / n as f64;
            let sigma = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
            let area = (lambda(cos, roughness) + 1.0) * cos;
            let tolerance = 0.005 * mean + 4.0 * sigma;
            assert!(
                (area as f64 - mean).abs() < tolerance,
                "{cos}, {roughness}: table {area}, integral {mean} ± {sigma}"
            );
        }
        // The fit is within 3% of Λ for roughness 0.3 and 1 away from grazing…
        for roughness in [0.3f32, 1.0] {
            for cos in [0.05f32, 0.2, 0.5] {
                let (ours, fit) = (lambda(cos, roughness), fitted_lambda(cos, roughness * roughness));
                assert!((ours - fit).abs() < 0.03 * ours.max(0.1), "{cos}, {roughness}: {ours} vs fit {fit}");
            }
        }
        // …but far too small for smooth sheens, which is why Λ is not fitted here.
        assert!(lambda(0.2, MIN_ROUGHNESS) > 3.0 * fitted_lambda(0.2, MIN_ROUGHNESS * MIN_ROUGHNESS));
    }
}
