//! The anisotropic GGX (Trowbridge–Reitz) distribution of microfacet
//! normals, with Smith's height-correlated masking-shadowing and sampling
//! of the normals visible from a direction.
//!
//! Formulas: Heitz, "Understanding the Masking-Shadowing Function in
//! Microfacet-Based BRDFs", JCGT 2014 (D, Λ and G2, sections 5.3 and 6);
//! Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 2018
//! (the sampler). They are those of KHR_materials_anisotropy's
//! implementation section (`D_GGX_anisotropic`, `V_GGX_anisotropic`).
//! With equal widths every formula is, term for term, the isotropic one
//! of [`crate::bsdf`].

use std::f32::consts::PI;

use rtgi_math::{Vec2, Vec3};

/// GGX widths along the frame's x and y axes; +z is the macroscopic normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct AnisotropicGgx {
    pub(super) alpha_x: f32,
    pub(super) alpha_y: f32,
}

impl AnisotropicGgx {
    pub(crate) fn isotropic(alpha: f32) -> Self {
        Self { alpha_x: alpha, alpha_y: alpha }
    }

    /// The density of normals `m` (unit) per unit projected area.
    pub(super) fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let (x, y) = (m.x / self.alpha_x, m.y / self.alpha_y);
        let t = x * x + y * y + m.z * m.z;
        1.0 / (PI * self.alpha_x * self.alpha_y * t * t)
    }

    /// Smith's Λ for direction `w` (unit, above the surface): the width
    /// projected onto `w`'s azimuth, times tan θ, decides it.
    pub(super) fn lambda(&self, w: Vec3) -> f32 {
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        let tan2 = (x * x + y * y) / (w.z * w.z);
        0.5 * ((1.0 + tan2).sqrt() - 1.0)
    }

    /// The share of the normals facing `w` that `w` sees.
    pub(super) fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing of the pair.
    pub(super) fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The microfacet reflection D G2 / (4 cos θo cos θi), without Fresnel,
    /// for both directions above the surface and their half vector `h`.
    pub(super) fn reflection(&self, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        self.d(h) * self.g2(wo, wi) / (4.0 * wo.z * wi.z)
    }

    /// The density of `wi` when it is `wo` reflected about a normal drawn
    /// by [`Self::sample_visible_normal`]: the visible normals' density
    /// G1(wo) max(0, wo·h) D(h) / cos θo times the Jacobian 1 / (4 wo·h) of
    /// reflection. `wi` may lie below the surface (the sampler can reflect
    /// there); `wo` must not.
    pub(super) fn reflection_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        if h.z <= 0.0 || wo.dot(h) <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * self.d(h) / (4.0 * wo.z)
    }

    /// A normal drawn from those visible from `wo` (above the surface) with
    /// density G1(wo) max(0, wo·m) D(m) / cos θo: the stretched
    /// configuration's visible hemisphere, sampled as a disc warped onto
    /// it, and stretched back (Heitz 2018, listing 1).
    pub(crate) fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let vh = Vec3::new(self.alpha_x * wo.x, self.alpha_y * wo.y, wo.z).normalize();
        let length2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if length2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / length2.sqrt() } else { Vec3::X };
        let t2 = vh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(0.0)).normalize_or(Vec3::Z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;
    use crate::bsdf::reflect;
    use rtgi_math::Rng;
    use std::f32::consts::TAU;

    fn direction(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    fn close_within(a: f32, b: f32, relative: f32) -> bool {
        (a - b).abs() <= relative * a.abs().max(b.abs()).max(1.0)
    }

    fn close(a: f32, b: f32) -> bool {
        close_within(a, b, 2e-5)
    }

    #[test]
    fn equal_widths_are_the_isotropic_model() {
        // Against the isotropic GGX of `Bsdf::Glossy` (white): value, density
        // and the very direction drawn from the same numbers. Near the peak of
        // a narrow lobe the isotropic D, a² / π (cos²θ (a² − 1) + 1)², loses
        // digits to cancellation in f32 (1 − cos²θ beside a²), so agreement
        // is looser there, as 1/a².
        let mut rng = Rng::new(11, 12);
        for alpha in [0.001f32, 0.05, 0.3, 1.0] {
            let relative = (2e-5 / (alpha * alpha)).clamp(2e-5, 2e-2);
            let ggx = AnisotropicGgx::isotropic(alpha);
            let glossy = Bsdf::Glossy { reflectance: Vec3::ONE, alpha };
            for _ in 0..500 {
                let wo = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
                let wi = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
                let h = (wo + wi).normalize();
                let (value, pdf) = (ggx.reflection(wo, wi, h), ggx.reflection_pdf(wo, wi));
                assert!(close_within(value, glossy.eval(wo, wi).x, relative), "{alpha} {wo} {wi}: {value}");
                assert!(close_within(pdf, glossy.pdf(wo, wi), relative), "{alpha} {wo} {wi}: {pdf}");
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                if let Some(s) = glossy.sample(wo, u) {
                    let ours = reflect(wo, ggx.sample_visible_normal(wo, u));
                    assert!((ours - s.wi).length() < 1e-4, "{alpha}: {ours} vs {}", s.wi);
                }
            }
        }
    }

    #[test]
    fn swapping_the_widths_is_a_quarter_turn() {
        // D, Λ and the sampler of (αx, αy) at w are those of (αy, αx) at w
        // turned by 90° about z.
        let turn = |w: Vec3| Vec3::new(-w.y, w.x, w.z);
        let (a, b) = (AnisotropicGgx { alpha_x: 0.05, alpha_y: 0.5 }, AnisotropicGgx { alpha_x: 0.5, alpha_y: 0.05 });
        let mut rng = Rng::new(13, 14);
        for _ in 0..1000 {
            let wo = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
            let wi = direction(1.5 * rng.next_f32(), TAU * rng.next_f32());
            let h = (wo + wi).normalize();
            assert!(close(a.reflection(wo, wi, h), b.reflection(turn(wo), turn(wi), turn(h))));
            assert!(close(a.reflection_pdf(wo, wi), b.reflection_pdf(turn(wo), turn(wi))));
        }
    }

    #[test]
    fn visible_normals_project_to_the_view_and_shadowing_is_reciprocal() {
        // ∫ G1(wo) max(0, wo·m) D(m) dm = cos θo: the visible normals'
        // density integrates to one (uniform directions, 200k samples).
        let ggx = AnisotropicGgx { alpha_x: 0.2, alpha_y: 0.6 };
        let mut rng = Rng::new(15, 16);
        for wo in [direction(0.3, 0.4), direction(1.2, 2.0), direction(1.45, -1.0)] {
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let m = rtgi_math::uniform_sphere(rng.next_f32(), rng.next_f32());
                sum += (ggx.g1(wo) * wo.dot(m).max(0.0) * ggx.d(m) / wo.z * 4.0 * PI) as f64;
            }
            let integral = sum / n as f64;
            assert!((integral - 1.0).abs() < 0.03, "{wo}: {integral}");
            let wi = direction(0.9, 1.0);
            assert_eq!(ggx.g2(wo, wi), ggx.g2(wi, wo));
        }
    }
}
