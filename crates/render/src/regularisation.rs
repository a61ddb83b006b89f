//! Path regularisation (Kaplanyan and Dachsbacher, "Path Space
//! Regularization for Holistic and Robust Light Transport", 2013; Cycles'
//! "filter glossy"): after a rough bounce, sharp lobes are widened, so that
//! light sampling finds the caustics they bring instead of rare BSDF
//! samples (fireflies). Biased: caustics come out blurred, and widened GGX
//! lobes lose the energy single scattering leaves out.

use serde::Serialize;

use crate::bsdf::Bsdf;

/// Which lobes path regularisation widens, and after which bounces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FilterGlossy {
    /// A bounce sampled with a density below this widens the lobes after
    /// it (diffuse bounces have densities of cos θ / π ≤ 0.32).
    pub threshold: f32,
    /// Only perfect mirrors and smooth glass (the deltas, which light
    /// sampling cannot see through at all), or every lobe narrower than the width.
    pub deltas_only: bool,
}

impl FilterGlossy {
    /// Every lobe, as Cycles' "filter glossy" (`--filter-glossy`).
    pub fn all_lobes(threshold: f32) -> Self {
        Self { threshold, deltas_only: false }
    }

    /// The GGX width lobes are widened to after bounces whose least
    /// density is `least_pdf`: Cycles' rule, 0.5·sqrt(1 − density /
    /// threshold) below the threshold. A diffuse bounce with the threshold
    /// 1 gives 0.41 to 0.5; a sharp glossy bounce (density in the tens)
    /// none, so a mirror seen in a mirror stays sharp. `None` before any
    /// bounce: what the camera sees directly is exact.
    pub fn width(&self, least_pdf: f32) -> Option<f32> {
        let blur = least_pdf / self.threshold;
        (blur < 1.0).then(|| 0.5 * (1.0 - blur).sqrt())
    }

    /// `bsdf` regularised after bounces of least density `least_pdf`.
    pub fn apply(&self, bsdf: Bsdf, least_pdf: f32) -> Bsdf {
        match self.width(least_pdf) {
            Some(width) if !self.deltas_only || bsdf.is_delta() => bsdf.regularised(width),
            _ => bsdf,
        }
    }

    /// What is widened, in words.
    pub fn lobes(&self) -> &'static str {
        if self.deltas_only { "mirrors and smooth glass" } else { "mirrors, glass and sharp highlights" }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Vec3;

    #[test]
    fn lobes_widen_after_rough_bounces_only_and_deltas_only_keeps_glossy_lobes() {
        let filter = FilterGlossy::all_lobes(1.0);
        assert_eq!(filter.width(f32::INFINITY), None);
        assert_eq!(filter.width(20.0), None);
        let width = filter.width(0.3).unwrap();
        assert!((width - 0.5 * 0.7f32.sqrt()).abs() < 1e-6);
        let mirror = Bsdf::Mirror { reflectance: Vec3::ONE };
        let glossy = Bsdf::Glossy { reflectance: Vec3::ONE, alpha: 0.05 };
        assert_eq!(filter.apply(mirror, 0.3), Bsdf::Glossy { reflectance: Vec3::ONE, alpha: width });
        assert_eq!(filter.apply(glossy, 0.3), Bsdf::Glossy { reflectance: Vec3::ONE, alpha: width });
        assert_eq!(filter.apply(glossy, 20.0), glossy);
        let deltas = FilterGlossy { threshold: 1.0, deltas_only: true };
        assert_eq!(deltas.apply(glossy, 0.3), glossy);
        assert_eq!(deltas.apply(mirror, 0.3), Bsdf::Glossy { reflectance: Vec3::ONE, alpha: width });
    }
}
