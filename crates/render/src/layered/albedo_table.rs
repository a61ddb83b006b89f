//! Directional albedos of the layered model's lobes, E(wo) = ∫ f(wo, wi)
//! cos θi dωi for white colours, tabulated once on first use: what albedo
//! scaling dims the layers beneath a lobe by (Kulla and Conty, "Revisiting
//! Physically Based Shading at Imageworks", SIGGRAPH 2017 course; the
//! scheme KHR_materials_sheen describes), and what the lobes are chosen by
//! when sampling.
//!
//! Each table is built by deterministic quadrature, chosen and sized so
//! that its nodes are within 0.001 of the integral, and read by bilinear
//! interpolation on 32 × 32 nodes. Interpolated, at 2000 random (cos θ,
//! roughness), the GGX table was within 0.003 of the integral at 99.3% of
//! them and within 0.008 at all; those beyond 0.003 were all near grazing
//! (cos θ < 0.08) with narrow lobes (α < 0.03), where the albedo of a
//! near-mirror falls to its grazing limit over cos θ ≈ α. The sheen table
//! was within 0.002 at 1000 random points. Both tables together take
//! about 25 ms to build unoptimised (the test profile's opt-level 1).
//!
//! The clearcoat's albedo is read from the GGX table too: Schlick's
//! Fresnel is linear in F0 and F90, so one table of the two parts serves
//! the coat, the dielectric's specular lobe of any F0, and the metal.

use std::f32::consts::PI;
use std::sync::LazyLock;

use rtgi_math::{Vec2, Vec3};

use super::anisotropic_ggx::AnisotropicGgx;
use super::quadrature::gauss_legendre;
use super::sheen;
use super::table::Table2;
use super::{COAT_F0, MIN_WIDTH};
use crate::bsdf::reflect;

/// The two parts of a white GGX lobe's albedo with Schlick's Fresnel,
/// `(A, B)` = (∫ (1 − w) ρ, ∫ w ρ) with w = (1 − wo·h)⁵ and ρ the lobe
/// without Fresnel times cos θi, so that a lobe of Fresnel
/// F0 + (F90 − F0) w reflects F0·A + F90·B (Karis, "Real Shading in Unreal
/// Engine 4", 2013: the split-sum table). `alpha` is the GGX width.
pub(super) fn ggx_albedo(cos: f32, alpha: f32) -> Vec2 {
    GGX_ALBEDO.lookup(cos.max(0.0).sqrt(), ggx_width_coordinate(alpha))
}

/// The albedo of the clearcoat's lobe: GGX of width `alpha` with the
/// Fresnel of index 1.5.
pub(super) fn coat_albedo(cos: f32, alpha: f32) -> f32 {
    let ab = ggx_albedo(cos, alpha);
    COAT_F0 * ab.x + ab.y
}

/// The albedo of the sheen lobe of white colour and this (perceptual) roughness.
pub(super) fn sheen_albedo(cos: f32, roughness: f32) -> f32 {
    SHEEN_ALBEDO.lookup(cos.max(0.0).sqrt(), sheen::roughness_coordinate(roughness))
}

/// Where a GGX width lies on the table's axis: by its square root, the
/// perceptual roughness, from the narrowest width to 1.
fn ggx_width_coordinate(alpha: f32) -> f32 {
    (alpha.sqrt() - MIN_WIDTH.sqrt()) / (1.0 - MIN_WIDTH.sqrt())
}

fn ggx_width_at(coordinate: f32) -> f32 {
    (MIN_WIDTH.sqrt() + (1.0 - MIN_WIDTH.sqrt()) * coordinate).powi(2)
}

/// The cosine of a node whose axis coordinate is `x` (the tables'
/// cosine axis is its square root, which puts nodes closer together
/// towards grazing, where albedos change fastest). Exactly grazing has no
/// albedo; the node is evaluated a hair above it.
fn cos_at(x: f32) -> f32 {
    (x * x).max(1e-4)
}

/// Cosine (by its square root) × GGX width (by its square root).
static GGX_ALBEDO: LazyLock<Table2<Vec2>> =
    LazyLock::new(|| Table2::build(32, 32, |x, y| ggx_albedo_by_quadrature(cos_at(x), ggx_width_at(y))));

/// Cosine (by its square root) × sheen roughness (by its logarithm).
static SHEEN_ALBEDO: LazyLock<Table2<f32>> = LazyLock::new(|| {
    let rule: Vec<(f32, f32)> = gauss_legendre(12).into_iter().map(|(x, w)| (x as f32, w as f32)).collect();
    Table2::build(32, 32, |x, y| sheen_albedo_by_quadrature(cos_at(x), sheen::roughness_at(y), &rule))
});

/// `(A, B)` of [`ggx_albedo`] by the midpoint rule over the numbers that
/// draw visible normals: the estimator F G2 / G1(wo) of visible-normal
/// sampling averaged over a grid instead of random numbers. 32 steps for
/// the disc's radius, bunched towards its rim (u = 1 − (1 − t)², where the
/// reflected directions cross the horizon and the integrand bends), times
/// 8 steps over half the azimuths (the other half mirrors them).
pub(super) fn ggx_albedo_by_quadrature(cos: f32, alpha: f32) -> Vec2 {
    let ggx = AnisotropicGgx::isotropic(alpha);
    let wo = Vec3::new((1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos);
    let lambda_o = ggx.lambda(wo);
    let (radii, azimuths) = (32, 8);
    let mut sum = Vec2::ZERO;
    for i in 0..radii {
        let t = (i as f32 + 0.5) / radii as f32;
        let (u0, jacobian) = (1.0 - (1.0 - t) * (1.0 - t), 2.0 * (1.0 - t));
        for j in 0..azimuths {
            let u1 = 0.25 + 0.5 * (j as f32 + 0.5) / azimuths as f32;
            let m = ggx.sample_visible_normal(wo, Vec2::new(u0, u1));
            let wi = reflect(wo, m);
            if wi.z <= 0.0 {
                continue;
            }
            let weight = jacobian * (1.0 + lambda_o) / (1.0 + lambda_o + ggx.lambda(wi));
            let w = (1.0 - wo.dot(m).clamp(0.0, 1.0)).powi(5);
            sum += weight * Vec2::new(1.0 - w, w);
        }
    }
    sum / (radii * azimuths) as f32
}

/// The sheen's albedo by Gauss–Legendre quadrature (`rule` on [0, 1]) over
/// cos θi = t² (more nodes towards grazing, where the fibres reflect) and
/// half the azimuths.
pub(super) fn sheen_albedo_by_quadrature(cos: f32, roughness: f32, rule: &[(f32, f32)]) -> f32 {
    let wo = Vec3::new((1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos);
    let mut sum = 0.0f64;
    for &(t, weight_t) in rule {
        let cos_i = t * t;
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        for &(s, weight_s) in rule {
            let phi = PI * s;
            let wi = Vec3::new(sin_i * phi.cos(), sin_i * phi.sin(), cos_i);
            // dω = d(cos θi) dφ = 2t dt · π ds, twice for the mirrored half.
            sum += (weight_t * weight_s * sheen::value(wo, wi, roughness) * cos_i * 2.0 * t * 2.0 * PI) as f64;
        }
    }
    sum as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Rng;

    /// Mean and standard error of `n` draws.
    fn estimate(n: usize, mut draw: impl FnMut() -> f64) -> (f64, f64) {
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let x = draw();
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / n as f64;
        (mean, ((sum2 / n as f64 - mean * mean) / n as f64).sqrt())
    }

    #[test]
    fn ggx_table_matches_monte_carlo_off_its_nodes() {
        // A different method from the table's: normals drawn from D cos θm
        // (not from the visible normals), random (not a grid), 200k each.
        // The coat's albedo (F0 0.04) and the white lobe's (A + B) both.
        let mut rng = Rng::new(31, 32);
        for (cos, alpha) in [(0.93f32, 0.0123f32), (0.61, 0.087), (0.33, 0.29), (0.12, 0.51), (0.77, 0.93), (0.05, 0.2)]
        {
            let ggx = AnisotropicGgx::isotropic(alpha);
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let mut draw = |f0: f32| {
                // cos θm by inverting the GGX CDF of D cos θm.
                let u = rng.next_f32();
                let cos_m = ((1.0 - u) / (1.0 + (alpha * alpha - 1.0) * u)).sqrt();
                let sin_m = (1.0 - cos_m * cos_m).max(0.0).sqrt();
                let phi = 2.0 * PI * rng.next_f32();
                let m = Vec3::new(sin_m * phi.cos(), sin_m * phi.sin(), cos_m);
                let wi = reflect(wo, m);
                let cos_om = wo.dot(m);
                if wi.z <= 0.0 || cos_om <= 0.0 {
                    return 0.0;
                }
                // f cos θi / pdf, pdf = D cos θm / (4 wo·m).
                let fresnel = f0 + (1.0 - f0) * (1.0 - cos_om).powi(5);
                (fresnel * ggx.g2(wo, wi) * cos_om / (wo.z * cos_m)) as f64
            };
            let (coat, coat_sigma) = estimate(200_000, || draw(COAT_F0));
            let (white, white_sigma) = estimate(200_000, || draw(1.0));
            let table = ggx_albedo(cos, alpha);
            let (table_coat, table_white) = (coat_albedo(cos, alpha) as f64, (table.x + table.y) as f64);
            assert!(
                (table_coat - coat).abs() < 0.005 + 3.0 * coat_sigma,
                "{cos}, {alpha}: coat {table_coat} vs {coat} ± {coat_sigma}"
            );
            assert!(
                (table_white - white).abs() < 0.005 + 3.0 * white_sigma,
                "{cos}, {alpha}: white {table_white} vs {white} ± {white_sigma}"
            );
        }
    }

    #[test]
    fn sheen_table_matches_monte_carlo_off_its_nodes() {
        // Uniform directions (the table used a Gauss–Legendre grid), 200k each.
        let mut rng = Rng::new(33, 34);
        for (cos, roughness) in
            [(0.95f32, 0.9f32), (0.52, 0.41), (0.23, 0.13), (0.08, 0.66), (0.37, 0.08), (0.015, 0.3)]
        {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let (mc, sigma) = estimate(200_000, || {
                let z = rng.next_f32();
                let r = (1.0 - z * z).sqrt();
                let phi = 2.0 * PI * rng.next_f32();
                let wi = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                if z <= 0.0 {
                    return 0.0;
                }
                (sheen::value(wo, wi, roughness) * z * 2.0 * PI) as f64
            });
            let table = sheen_albedo(cos, roughness) as f64;
            assert!((table - mc).abs() < 0.005 + 3.0 * sigma, "{cos}, {roughness}: table {table} vs {mc} ± {sigma}");
            assert!(table <= 1.0);
        }
    }
}
