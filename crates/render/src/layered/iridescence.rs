//! Thin-film interference on the Fresnel term (KHR_materials_iridescence):
//! Belcour and Barla, "A Practical Extension to Microfacet Theory for the
//! Modeling of Varying Iridescence", SIGGRAPH 2017, in the simplified form
//! the extension's appendix gives (Schlick's approximation at both
//! interfaces, phase shifts of 0 or π, no polarisation).
//!
//! The reflectance of the film is the Airy sum over the light's round trips
//! in it, R(ν) = C0 + 2 Σ_m C_m cos(m (2π·OPD·ν + φ)) for the wavenumber ν;
//! integrating it against the colour matching functions, each fitted by
//! Gaussians in ν, turns every term of the sum into a Gaussian's Fourier
//! transform, evaluated in closed form. The first two terms of the sum are
//! kept, as in the paper; the next one is below 10⁻⁵ over dielectric bases
//! and of the order of 10⁻⁴ over metals.

use std::f32::consts::PI;

use rtgi_math::Vec3;

/// The index of refraction outside the film (air).
const OUTSIDE_IOR: f32 = 1.0;

/// The Fresnel reflectance, linear Rec. 709 RGB, of a film of index
/// `film_ior` and `thickness_nm` over a base of normal-incidence
/// reflectance `base_f0`, for light arriving at cos θ = `cos`.
///
/// As the film thins to nothing, the result tends to the base's own
/// reflectance at normal incidence (within 0.004 for F0 0.04, 0.02 for F0
/// 0.5: the matching functions' white is not quite the Rec. 709 white,
/// and the difference grows with the base's reflectance), and above it at
/// oblique angles (0.154 instead of 0.115 at cos θ = 0.4 over F0 0.04),
/// because Schlick's approximation of the film's upper interface does not
/// vanish with it.
/// Belcour and Barla's code fades the film's index to the outside's over
/// the first 30 nm; with Schlick's approximation that makes it worse (0.35
/// there), so it is not done. A film of no thickness is no film: the
/// material does not call this for it. The result is clamped to [0, 1]:
/// the colour conversion can leave the gamut on either side, and a
/// reflectance above 1 would create energy.
pub(super) fn thin_film_fresnel(cos: f32, film_ior: f32, thickness_nm: f32, base_f0: Vec3) -> Vec3 {
    let cos1 = cos.clamp(0.0, 1.0);
    let sin2_t2 = (OUTSIDE_IOR / film_ior).powi(2) * (1.0 - cos1 * cos1);
    if sin2_t2 >= 1.0 {
        // Total internal reflection into the film (a film less dense than air).
        return Vec3::ONE;
    }
    let cos2 = (1.0 - sin2_t2).sqrt();

    // Outside to film, and back.
    let r12 = schlick(ior_to_f0(film_ior, OUTSIDE_IOR), cos1);
    let t121 = 1.0 - r12;
    let phi12 = if film_ior < OUTSIDE_IOR { PI } else { 0.0 };
    let phi21 = PI - phi12;

    // Film to base, per channel: the base's index from its F0 as if it
    // were a dielectric (for metals, an approximation with no extinction).
    let sqrt_f0 = base_f0.clamp(Vec3::ZERO, Vec3::splat(0.9999)).map(f32::sqrt);
    let base_ior = (Vec3::ONE + sqrt_f0) / (Vec3::ONE - sqrt_f0);
    let r23 = base_ior.map(|n| schlick(ior_to_f0(n, film_ior), cos2));
    let phi23 = base_ior.map(|n| if n < film_ior { PI } else { 0.0 });

    let opd = 2.0 * film_ior * thickness_nm * cos2;
    let phi = Vec3::splat(phi21) + phi23;
    // (The extension's code also clamps from below, at 10⁻⁵, which only
    // matters where a reflectance is 0: a film of the base's own index.)
    let r123 = (r12 * r23).clamp(Vec3::ZERO, Vec3::splat(0.9999));
    let rs = t121 * t121 * r23 / (Vec3::ONE - r123);
    let mut reflectance = Vec3::splat(r12) + rs;
    let mut cm = rs - Vec3::splat(t121);
    let amplitude = r123.map(f32::sqrt);
    for m in 1..=2 {
        cm *= amplitude;
        reflectance += cm * 2.0 * sensitivity(m as f32 * opd, m as f32 * phi);
    }
    reflectance.clamp(Vec3::ZERO, Vec3::ONE)
}

/// Schlick's approximation of a dielectric's reflectance.
fn schlick(f0: f32, cos: f32) -> f32 {
    f0 + (1.0 - f0) * (1.0 - cos).clamp(0.0, 1.0).powi(5)
}

/// The normal-incidence reflectance between media of these indices.
fn ior_to_f0(transmitted: f32, incident: f32) -> f32 {
    ((transmitted - incident) / (transmitted + incident)).powi(2)
}

/// The Gaussians, in wavenumber (1/m), fitted to the CIE 1931 colour
/// matching functions: x̄ (two lobes), ȳ and z̄. Each is
/// `height / √2 · exp(−(ν − centre)² / (4 variance))`; the Fourier
/// transform of that is `height · √(2π variance) · exp(−p² variance)`.
const MATCHING_GAUSSIANS: [(usize, f64, f64, f64); 4] = [
    // (channel, height, centre, variance)
    (0, 5.4856e-13, 1.6810e6, 4.3278e9),
    (1, 4.4201e-13, 1.7953e6, 9.3046e9),
    (2, 5.2481e-13, 2.2084e6, 6.6121e9),
    (0, 9.7470e-14, 2.2399e6, 4.5282e9),
];

/// ∫ ȳ(ν) dν, which makes Y of a unit reflectance 1.
const Y_INTEGRAL: f64 = 1.0685e-7;

/// CIE XYZ to linear Rec. 709 (sRGB primaries, D65 white), by rows.
const XYZ_TO_REC709: [[f64; 3]; 3] =
    [[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560], [0.0556434, -0.2040259, 1.0572252]];

/// `xyz` (relative to Y of a white reflector) in linear Rec. 709.
fn rec709(xyz: [f64; 3]) -> Vec3 {
    let row = |r: [f64; 3]| (r[0] * xyz[0] + r[1] * xyz[1] + r[2] * xyz[2]) as f32;
    Vec3::new(row(XYZ_TO_REC709[0]), row(XYZ_TO_REC709[1]), row(XYZ_TO_REC709[2]))
}

/// ∫ cmf(ν) cos(2π·OPD·ν + shift) dν / ∫ ȳ, converted to Rec. 709: the
/// colour of a cosine of the wavenumber with optical path difference
/// `opd_nm`, shifted per channel by `shift`.
fn sensitivity(opd_nm: f32, shift: Vec3) -> Vec3 {
    let p = 2.0 * std::f64::consts::PI * opd_nm as f64 * 1e-9;
    let mut xyz = [0.0f64; 3];
    for (channel, height, centre, variance) in MATCHING_GAUSSIANS {
        let phase = centre * p + shift[channel] as f64;
        xyz[channel] +=
            height * (2.0 * std::f64::consts::PI * variance).sqrt() * phase.cos() * (-p * p * variance).exp();
    }
    rec709(xyz.map(|c| c / Y_INTEGRAL))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rec. 709 colour of a spectral reflectance given per wavenumber, by
    /// direct integration against the fitted matching functions. Its mean
    /// over the phase is taken as white (as the closed form does: the
    /// constant term of the Airy sum is added to every channel), and only
    /// the oscillation around it is coloured.
    fn integrated_colour(reflectance: impl Fn(f64) -> f64, mean: f64) -> Vec3 {
        let (from, to, steps) = (0.6e6f64, 3.6e6f64, 60_000);
        let dv = (to - from) / steps as f64;
        let mut xyz = [0.0f64; 3];
        for k in 0..steps {
            let nu = from + (k as f64 + 0.5) * dv;
            let r = reflectance(nu) - mean;
            for (channel, height, centre, variance) in MATCHING_GAUSSIANS {
                let cmf = height / 2f64.sqrt() * (-(nu - centre).powi(2) / (4.0 * variance)).exp();
                xyz[channel] += r * cmf * dv;
            }
        }
        Vec3::splat(mean as f32) + rec709(xyz.map(|c| c / Y_INTEGRAL))
    }

    #[test]
    fn matches_the_airy_reflectance_integrated_over_the_spectrum() {
        // At normal incidence Schlick's approximation is exact, and the
        // film's reflectance per wavenumber is Airy's formula with the
        // amplitudes r = (n1 − n2) / (n1 + n2) of both interfaces:
        // R = |(r12 + r23 e^{iδ}) / (1 + r12 r23 e^{iδ})|², δ = 2π·2 n2 d·ν.
        for (film, base, thickness) in
            [(1.3f64, 1.5f64, 150.0f64), (1.3, 1.5, 300.0), (1.8, 1.5, 420.0), (1.3, 2.5, 250.0)]
        {
            let r12 = (1.0 - film) / (1.0 + film);
            let r23 = (film - base) / (film + base);
            let airy = |delta: f64| {
                let (c, s) = (delta.cos(), delta.sin());
                let (nr, ni) = (r12 + r23 * c, r23 * s);
                let (dr, di) = (1.0 + r12 * r23 * c, r12 * r23 * s);
                (nr * nr + ni * ni) / (dr * dr + di * di)
            };
            let opd = 2.0 * film * thickness * 1e-9;
            let mean = (0..10_000).map(|k| airy((k as f64 + 0.5) / 10_000.0 * 2.0 * std::f64::consts::PI)).sum::<f64>()
                / 10_000.0;
            let expected = integrated_colour(|nu| airy(2.0 * std::f64::consts::PI * opd * nu), mean);
            let base_f0 = ((base - 1.0) / (base + 1.0)).powi(2) as f32;
            let got = thin_film_fresnel(1.0, film as f32, thickness as f32, Vec3::splat(base_f0));
            assert!(
                (got - expected).abs().max_element() < 2e-4,
                "film {film} on {base}, {thickness} nm: {got} vs {expected}"
            );
        }
    }

    #[test]
    fn varies_with_thickness_within_zero_and_one() {
        let (mut lowest, mut highest) = (Vec3::ONE, Vec3::ZERO);
        for step in 0..=200 {
            let thickness = step as f32 * 5.0;
            for cos in [1.0f32, 0.6, 0.1] {
                for base in [Vec3::splat(0.04), Vec3::new(0.95, 0.64, 0.54)] {
                    let f = thin_film_fresnel(cos, 1.3, thickness, base);
                    assert!(f.min_element() >= 0.0 && f.max_element() <= 1.0, "{thickness} nm, {cos}: {f}");
                }
            }
            let f = thin_film_fresnel(1.0, 1.3, thickness, Vec3::splat(0.04));
            (lowest, highest) = (lowest.min(f), highest.max(f));
        }
        // A dielectric's 4% swings by several per cent and changes hue.
        assert!((highest - lowest).min_element() > 0.02, "{lowest} .. {highest}");
    }

    #[test]
    fn a_vanishing_film_or_one_of_the_bases_index_leaves_the_bare_base() {
        // At normal incidence, where Schlick's approximation is exact.
        for (f0, tolerance) in [(0.04f32, 0.005f32), (0.5, 0.02), (0.9, 0.02)] {
            let vanished = thin_film_fresnel(1.0, 1.3, 0.0, Vec3::splat(f0));
            assert!((vanished - Vec3::splat(f0)).abs().max_element() < tolerance, "{f0}: {vanished}");
        }
        // A film of index 1.5 on a base of index 1.5 (F0 = 0.04) has no lower
        // interface: whatever its thickness, only its upper one reflects.
        for thickness in [120.0f32, 300.0, 777.0] {
            let same = thin_film_fresnel(1.0, 1.5, thickness, Vec3::splat(0.04));
            assert!((same - Vec3::splat(0.04)).abs().max_element() < 1e-5, "{thickness}: {same}");
        }
    }
}
