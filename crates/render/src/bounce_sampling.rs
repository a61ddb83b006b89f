//! How a path draws the direction of its next bounce (and of the BSDF
//! strategy's direct-light rays): from the BSDF, as it should, or from the
//! cosine or uniform hemisphere, as a course on path tracing compares them.
//! The estimators stay unbiased whichever is chosen: the direction's
//! density is the hemisphere's, and MIS weighs with that density. Only the
//! noise differs.

use std::f32::consts::PI;

use rtgi_math::{Vec2, Vec3};

use crate::bsdf::{Bsdf, BsdfSample, cosine_hemisphere};

/// Where bounce directions come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum BounceSampling {
    /// Importance sampling of the BSDF (the least noise).
    #[default]
    Bsdf,
    /// The cosine-weighted hemisphere about the shading normal: the BSDF
    /// sampling of a Lambertian surface, noisier on glossy ones.
    Cosine,
    /// The uniform hemisphere: noisier still, the textbook's first estimator.
    Uniform,
}

impl BounceSampling {
    /// Every choice, in the order help texts list them.
    pub const ALL: &'static [BounceSampling] = &[BounceSampling::Bsdf, BounceSampling::Cosine, BounceSampling::Uniform];

    /// The name on command lines and in reports (`bsdf`, `cosine`, `uniform`).
    pub fn name(self) -> &'static str {
        match self {
            BounceSampling::Bsdf => "bsdf",
            BounceSampling::Cosine => "cosine",
            BounceSampling::Uniform => "uniform",
        }
    }

    /// Whether `bsdf` is sampled from the hemisphere: it reflects only and
    /// has no delta lobe. A mirror's or glass's direction cannot be found
    /// by chance, and a hemisphere does not reach transmitted light, so
    /// those are always sampled from the BSDF.
    fn applies_to(self, bsdf: &Bsdf) -> bool {
        self != BounceSampling::Bsdf && !bsdf.is_delta() && !bsdf.transmits()
    }

    /// A direction for `wo` (shading frame) drawn with `u`, the BSDF's value
    /// there and its density; `None` where nothing can be drawn.
    pub fn sample(self, bsdf: &Bsdf, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if !self.applies_to(bsdf) {
            return bsdf.sample(wo, u);
        }
        let wi = match self {
            BounceSampling::Cosine => cosine_hemisphere(u),
            _ => uniform_hemisphere(u),
        };
        // Reflection is two-sided: the hemisphere is the one `wo` is in.
        let wi = if wo.z < 0.0 { Vec3::new(wi.x, wi.y, -wi.z) } else { wi };
        let pdf = self.pdf(bsdf, wo, wi);
        (pdf > 0.0).then(|| BsdfSample { wi, value: bsdf.eval(wo, wi), pdf, delta: false, eta: 1.0 })
    }

    /// The density with which [`BounceSampling::sample`] draws `wi` for `wo`.
    pub fn pdf(self, bsdf: &Bsdf, wo: Vec3, wi: Vec3) -> f32 {
        if !self.applies_to(bsdf) {
            return bsdf.pdf(wo, wi);
        }
        if wi.z * wo.z <= 0.0 {
            return 0.0;
        }
        match self {
            BounceSampling::Cosine => wi.z.abs() / PI,
            _ => 1.0 / (2.0 * PI),
        }
    }
}

impl rtgi_math::NamedChoice for BounceSampling {
    const KIND: &'static str = "bounce sampling";
    const ALL: &'static [Self] = BounceSampling::ALL;
    fn name(self) -> &'static str {
        BounceSampling::name(self)
    }
}

impl std::fmt::Display for BounceSampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A uniformly distributed direction in the hemisphere about +z.
fn uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each strategy's densities integrate to one over the sphere, and
    /// its samples carry the density `pdf` gives them.
    #[test]
    fn samples_agree_with_their_density() {
        let bsdf = Bsdf::DiffuseGlossy { albedo: Vec3::splat(0.5), reflectance: Vec3::splat(0.3), alpha: 0.3 };
        let wo = Vec3::new(0.3, -0.2, -0.9).normalize();
        for &sampling in BounceSampling::ALL {
            let n = 256;
            let mut integral = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    // Midpoint rule over the sphere, in (cos θ, φ).
                    let z = 2.0 * u - 1.0;
                    let r = (1.0 - z * z).sqrt();
                    let wi = Vec3::new(r * (2.0 * PI * v).cos(), r * (2.0 * PI * v).sin(), z);
                    integral += sampling.pdf(&bsdf, wo, wi) as f64 * 4.0 * PI as f64 / (n * n) as f64;
                    let Some(sample) = sampling.sample(&bsdf, wo, Vec2::new(u, v)) else { continue };
                    assert!(sample.wi.z < 0.0, "{sampling}: on the side of wo");
                    let pdf = sampling.pdf(&bsdf, wo, sample.wi);
                    assert!((sample.pdf - pdf).abs() <= 1e-4 * pdf.max(1.0), "{sampling}: {} vs {pdf}", sample.pdf);
                }
            }
            // GGX sampling draws some directions below the horizon and drops
            // them, so the BSDF's own density holds a little less than one.
            let lowest = if sampling == BounceSampling::Bsdf { 0.9 } else { 0.99 };
            assert!(integral > lowest && integral < 1.01, "{sampling}: the density integrates to {integral}");
        }
    }

    #[test]
    fn specular_and_transmitting_bsdfs_are_sampled_from_the_bsdf() {
        let mirror = Bsdf::Mirror { reflectance: Vec3::ONE };
        let wo = Vec3::new(0.1, 0.2, 0.9).normalize();
        let u = Vec2::new(0.3, 0.7);
        for &sampling in BounceSampling::ALL {
            assert_eq!(sampling.sample(&mirror, wo, u), mirror.sample(wo, u));
            let glass = Bsdf::RoughThinDielectric { ior: 1.5, tint: Vec3::ONE, alpha: 0.3 };
            assert_eq!(sampling.sample(&glass, wo, u), glass.sample(wo, u));
        }
    }
}
