//! Reflectance models, in the local frame of a surface where the shading
//! normal is +z: `wo` points to the viewer, `wi` to the light, both unit.
//! Each model evaluates, samples and gives the density of its samples,
//! consistently (the tests check each against the others). Reflection is
//! two-sided: directions are mirrored to the side of `wo`. The dielectric
//! is the exception, as it has to know which side is inside: +z is outside.

use std::f32::consts::PI;

use rtgi_math::{Vec2, Vec3};

use crate::layered::PbrLayers;

/// A direction drawn from a BSDF, with the BSDF's value there and the
/// density it was drawn with (solid angle). `delta` marks perfectly specular
/// directions, whose value and density are both Dirac deltas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled incident direction, unit length, in the shading frame.
    pub wi: Vec3,
    /// The BSDF's value for `wo` and `wi`, as [`Bsdf::eval`] gives it (for a delta, the weight divided by the cosine).
    pub value: Vec3,
    /// The density `wi` was drawn with, per unit solid angle (meaningless when `delta`).
    pub pdf: f32,
    /// Whether `wi` is a perfectly specular direction (mirror, smooth glass), which no other sampling strategy can find.
    pub delta: bool,
    /// The relative index of refraction crossed (n transmitted / n incident):
    /// radiance was scaled by 1/η² on the way. 1 where nothing refracted.
    pub eta: f32,
}

/// The reflectance models of the renderer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Ideal diffuse reflection.
    Lambert {
        /// Fraction of light reflected, per channel, in `[0, 1]`.
        albedo: Vec3,
    },
    /// Perfect mirror reflection.
    Mirror {
        /// Fraction of light reflected, per channel.
        reflectance: Vec3,
    },
    /// glTF's metallic-roughness model: a GGX (Trowbridge-Reitz) specular
    /// lobe with Schlick's Fresnel over a Lambertian base for dielectrics;
    /// `alpha` is the GGX width (perceptual roughness squared).
    MetallicRoughness {
        /// Diffuse colour of dielectrics, specular colour of metals (linear RGB).
        base_color: Vec3,
        /// From 0 (dielectric) to 1 (metal).
        metallic: f32,
        /// GGX width, in `(0, 1]`.
        alpha: f32,
    },
    /// A GGX specular lobe of constant reflectance (MTL's `Ks`, whose
    /// Fresnel behaviour the format does not describe).
    Glossy {
        /// Specular reflectance (linear RGB).
        reflectance: Vec3,
        /// GGX width, in `(0, 1]`.
        alpha: f32,
    },
    /// MTL's diffuse and glossy layers together: a Lambertian lobe of
    /// albedo `Kd` plus a GGX lobe of constant reflectance `Ks`. Evaluated
    /// as the sum of both and sampled from their mixture, chosen by
    /// luminance, so that light sampling sees both lobes at every hit
    /// (choosing one lobe per hit instead made directly lit walls noisy).
    DiffuseGlossy {
        /// Diffuse albedo (linear RGB).
        albedo: Vec3,
        /// Specular reflectance (linear RGB).
        reflectance: Vec3,
        /// GGX width, in `(0, 1]`.
        alpha: f32,
    },
    /// A smooth boundary between air (+z side) and a medium of index `ior`
    /// that reflects and refracts by Fresnel's equations; refracted light is
    /// tinted by `tint` (glTF's base colour for transmission).
    Dielectric {
        /// Index of refraction of the medium on the -z side.
        ior: f32,
        /// Colour multiplying refracted light.
        tint: Vec3,
    },
    /// A thin sheet of a dielectric (glTF's transmission without a volume):
    /// light reflects by Fresnel's equations, summed over the reflections
    /// inside the sheet, or passes straight through, tinted.
    ThinDielectric {
        /// Index of refraction of the sheet.
        ior: f32,
        /// Colour multiplying transmitted light.
        tint: Vec3,
    },
    /// A rough thin sheet (glTF's transmission with roughness): GGX
    /// microfacets of width `alpha` reflect as [`Bsdf::ThinDielectric`]
    /// does, and transmit into the mirror image of the reflected lobe
    /// below the sheet, so what lies behind is seen blurred. Not a delta.
    RoughThinDielectric {
        /// Index of refraction of the sheet.
        ior: f32,
        /// Colour multiplying transmitted light.
        tint: Vec3,
        /// GGX width of the microfacets, in `(0, 1]`.
        alpha: f32,
    },
    /// A rough boundary between air (+z side) and a medium of index `ior`:
    /// GGX microfacets of width `alpha`, each reflecting and refracting as
    /// [`Bsdf::Dielectric`] does (Walter et al., "Microfacet Models for
    /// Refraction through Rough Surfaces", EGSR 2007; pbrt-v4's
    /// `DielectricBxDF`). Not a delta, so light sampling works through it:
    /// path regularisation turns smooth glass into this after a diffuse
    /// bounce ([`Bsdf::regularised`]).
    RoughDielectric {
        /// Index of refraction of the medium on the -z side.
        ior: f32,
        /// Colour multiplying refracted light.
        tint: Vec3,
        /// GGX width of the microfacets, in `(0, 1]`.
        alpha: f32,
    },
    /// glTF's layered material: the metallic-roughness base with the
    /// Fresnel of KHR_materials_ior and _specular, anisotropy and
    /// iridescence, under sheen and clearcoat ([`PbrLayers`]). Used where a
    /// material has any of these; the others keep [`Bsdf::MetallicRoughness`].
    Layered(PbrLayers),
}

impl Bsdf {
    /// The BSDF's value for the pair of directions (zero for specular models).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if let Bsdf::Layered(layers) = self {
            return layers.eval(wo, wi);
        }
        if let Bsdf::RoughDielectric { ior, tint, alpha } = *self {
            return rough_dielectric(wo, wi, ior, alpha)
                .map_or(Vec3::ZERO, |lobe| if lobe.transmitted { tint * lobe.value } else { Vec3::splat(lobe.value) });
        }
        if let Bsdf::RoughThinDielectric { ior, tint, alpha } = *self {
            return rough_thin(wo, wi, ior, alpha).map_or(Vec3::ZERO, |lobe| {
                let f = lobe.fresnel_weight * lobe.microfacet_value;
                if lobe.transmitted { tint * f } else { Vec3::splat(f) }
            });
        }
        let (wo, wi) = (to_upper(wo), to_upper_with(wi, wo));
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Vec3::ZERO;
        }
        match *self {
            Bsdf::Lambert { albedo } => albedo / PI,
            Bsdf::Mirror { .. }
            | Bsdf::Dielectric { .. }
            | Bsdf::ThinDielectric { .. }
            | Bsdf::RoughDielectric { .. }
            | Bsdf::RoughThinDielectric { .. }
            | Bsdf::Layered(_) => Vec3::ZERO,
            Bsdf::Glossy { reflectance, alpha } => {
                let wm = (wo + wi).normalize_or_zero();
                if wm == Vec3::ZERO {
                    return Vec3::ZERO;
                }
                reflectance * (ggx_d(wm, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z))
            }
            Bsdf::DiffuseGlossy { albedo, reflectance, alpha } => {
                let glossy = Bsdf::Glossy { reflectance, alpha }.eval(wo, wi);
                albedo / PI + glossy
            }
            Bsdf::MetallicRoughness { base_color, metallic, alpha } => {
                let wm = (wo + wi).normalize_or_zero();
                if wm == Vec3::ZERO {
                    return Vec3::ZERO;
                }
                let f0 = Vec3::splat(0.04).lerp(base_color, metallic);
                let fresnel = schlick(f0, wi.dot(wm));
                let specular = fresnel * (ggx_d(wm, alpha) * ggx_g2(wo, wi, alpha) / (4.0 * wo.z * wi.z));
                let diffuse = (Vec3::ONE - fresnel) * (1.0 - metallic) * base_color / PI;
                specular + diffuse
            }
        }
    }

    /// The density with which [`Bsdf::sample`] draws `wi` (zero for specular models).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if let Bsdf::Layered(layers) = self {
            return layers.pdf(wo, wi);
        }
        if let Bsdf::RoughDielectric { ior, alpha, .. } = *self {
            return rough_dielectric(wo, wi, ior, alpha).map_or(0.0, |lobe| lobe.pdf);
        }
        if let Bsdf::RoughThinDielectric { ior, alpha, .. } = *self {
            return rough_thin(wo, wi, ior, alpha).map_or(0.0, |lobe| lobe.choice * lobe.reflection_pdf);
        }
        let (wo, wi) = (to_upper(wo), to_upper_with(wi, wo));
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        match *self {
            Bsdf::Lambert { .. } => wi.z / PI,
            Bsdf::Mirror { .. }
            | Bsdf::Dielectric { .. }
            | Bsdf::ThinDielectric { .. }
            | Bsdf::RoughDielectric { .. }
            | Bsdf::RoughThinDielectric { .. }
            | Bsdf::Layered(_) => 0.0,
            Bsdf::Glossy { alpha, .. } => ggx_reflection_pdf(wo, wi, alpha),
            Bsdf::DiffuseGlossy { albedo, reflectance, alpha } => {
                let p_glossy = glossy_probability(albedo, reflectance);
                p_glossy * ggx_reflection_pdf(wo, wi, alpha) + (1.0 - p_glossy) * wi.z / PI
            }
            Bsdf::MetallicRoughness { metallic, alpha, .. } => {
                let p_specular = specular_probability(metallic);
                p_specular * ggx_reflection_pdf(wo, wi, alpha) + (1.0 - p_specular) * wi.z / PI
            }
        }
    }

    /// Draws an incident direction for `wo` from two uniform numbers.
    ///
    /// `u.x` also chooses between the lobes of layered models; it is
    /// stretched back to [0, 1) for the chosen lobe.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        match *self {
            Bsdf::Layered(layers) => return layers.sample(wo, u),
            Bsdf::Dielectric { ior, tint } => return Some(sample_dielectric(wo, ior, tint, u.x)),
            Bsdf::ThinDielectric { ior, tint } => return Some(sample_thin_dielectric(wo, ior, tint, u.x)),
            Bsdf::RoughDielectric { ior, alpha, .. } => {
                // Reflect or refract with the reflectance at the macroscopic
                // normal (clamped so neither is starved), then draw a normal
                // visible from `wo`'s side with the stretched number.
                let p_reflect = rough_dielectric_reflect_probability(wo, ior);
                let (refract, u0) = if u.x < p_reflect {
                    (false, u.x / p_reflect)
                } else {
                    (true, (u.x - p_reflect) / (1.0 - p_reflect))
                };
                // Normals visible from below are those visible from -wo.
                let view = if wo.z < 0.0 { -wo } else { wo };
                let wm = sample_ggx_visible_normal(view, alpha, Vec2::new(u0, u.y));
                let wi = if refract { refract_at(wo, wm, ior)? } else { reflect(wo, wm) };
                if (wi.z * wo.z > 0.0) == refract || wi.z == 0.0 {
                    return None;
                }
                let lobe = rough_dielectric(wo, wi, ior, alpha)?;
                let value = self.eval(wo, wi);
                return (lobe.pdf > 0.0).then_some(BsdfSample {
                    wi,
                    value,
                    pdf: lobe.pdf,
                    delta: false,
                    eta: lobe.eta,
                });
            }
            Bsdf::RoughThinDielectric { ior, alpha, .. } => {
                // Reflect or transmit with the sheet's reflectance at the
                // macroscopic normal (clamped so neither is starved), then
                // draw a visible microfacet normal with the stretched number.
                let upper = to_upper(wo);
                let p_reflect = thin_reflectance(upper.z, ior).clamp(0.02, 0.98);
                let (transmit, u0) = if u.x < p_reflect {
                    (false, u.x / p_reflect)
                } else {
                    (true, (u.x - p_reflect) / (1.0 - p_reflect))
                };
                let reflected = reflect(upper, sample_ggx_visible_normal(upper, alpha, Vec2::new(u0, u.y)));
                if reflected.z <= 0.0 {
                    return None;
                }
                let side = if transmit { -1.0 } else { 1.0 } * if wo.z < 0.0 { -1.0 } else { 1.0 };
                let wi = Vec3::new(reflected.x, reflected.y, reflected.z * side);
                let pdf = self.pdf(wo, wi);
                return (pdf > 0.0).then(|| BsdfSample { wi, value: self.eval(wo, wi), pdf, delta: false, eta: 1.0 });
            }
            _ => {}
        }
        let flip = wo.z < 0.0;
        let local_wo = to_upper(wo);
        let back = |w: Vec3| if flip { Vec3::new(w.x, w.y, -w.z) } else { w };
        let wi = match *self {
            Bsdf::Lambert { .. } => cosine_hemisphere(u),
            Bsdf::Glossy { alpha, .. } => reflect(local_wo, sample_ggx_visible_normal(local_wo, alpha, u)),
            Bsdf::Dielectric { .. }
            | Bsdf::ThinDielectric { .. }
            | Bsdf::RoughDielectric { .. }
            | Bsdf::RoughThinDielectric { .. }
            | Bsdf::Layered(_) => {
                unreachable!("sampled above")
            }
            Bsdf::Mirror { reflectance } => {
                let wi = Vec3::new(-local_wo.x, -local_wo.y, local_wo.z);
                return Some(BsdfSample { wi: back(wi), value: reflectance / wi.z, pdf: 1.0, delta: true, eta: 1.0 });
            }
            Bsdf::DiffuseGlossy { albedo, reflectance, alpha } => {
                let p_glossy = glossy_probability(albedo, reflectance);
                if u.x < p_glossy {
                    let u = Vec2::new(u.x / p_glossy, u.y);
                    reflect(local_wo, sample_ggx_visible_normal(local_wo, alpha, u))
                } else {
                    cosine_hemisphere(Vec2::new((u.x - p_glossy) / (1.0 - p_glossy), u.y))
                }
            }
            Bsdf::MetallicRoughness { metallic, alpha, .. } => {
                let p_specular = specular_probability(metallic);
                if u.x < p_specular {
                    // Reuse the first number, stretched back to [0, 1).
                    let u = Vec2::new(u.x / p_specular, u.y);
                    let wm = sample_ggx_visible_normal(local_wo, alpha, u);
                    reflect(local_wo, wm)
                } else {
                    cosine_hemisphere(Vec2::new((u.x - p_specular) / (1.0 - p_specular), u.y))
                }
            }
        };
        if wi.z <= 0.0 {
            return None;
        }
        let wi = back(wi);
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample { wi, value: self.eval(wo, wi), pdf, delta: false, eta: 1.0 })
    }

    /// Whether every direction the model scatters to is a Dirac delta, so
    /// that sampling lights from its surfaces is pointless.
    pub fn is_delta(&self) -> bool {
        matches!(self, Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } | Bsdf::ThinDielectric { .. })
    }

    /// Whether light may pass through the surface (the dielectrics); the
    /// other models only reflect.
    pub fn transmits(&self) -> bool {
        matches!(
            self,
            Bsdf::Dielectric { .. }
                | Bsdf::ThinDielectric { .. }
                | Bsdf::RoughDielectric { .. }
                | Bsdf::RoughThinDielectric { .. }
        )
    }
}

/// An MTL material's diffuse (`Kd`) and specular (`Ks`) colours, scaled
/// together, when their sum exceeds 1 in any channel, so that the surface
/// reflects at most the light it receives. MTL files often give such sums
/// (11 of the conference room's 35 materials, up to 1.5): taken as they
/// are, a room of them returns more light at each bounce than arrives, the
/// bounces' sum converges slowly if at all, and paths that stay among them
/// bring fireflies of any size (a 4096-sample reference of the room kept
/// pixels of 10⁴). Sums up to 1 are returned unchanged, bit for bit.
pub fn energy_conserving(diffuse: Vec3, specular: Vec3) -> (Vec3, Vec3) {
    let total = (diffuse + specular).max_element();
    if total > 1.0 { (diffuse / total, specular / total) } else { (diffuse, specular) }
}

/// Fresnel reflectance of unpolarised light at a smooth dielectric boundary;
/// `cos_i` ≥ 0 on the incident side, `eta` = n_transmitted / n_incident.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0; // total internal reflection
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Reflects or refracts at a smooth dielectric, choosing by the Fresnel
/// reflectance, so the estimator's weight is 1 for reflection and
/// tint / η² for refraction: radiance is compressed into the smaller solid
/// angle of the denser medium (Veach 1997, section 5.2), which is why a ray
/// that enters and leaves a slab carries its radiance unchanged.
fn sample_dielectric(wo: Vec3, ior: f32, tint: Vec3, u: f32) -> BsdfSample {
    let entering = wo.z > 0.0;
    let eta = if entering { ior } else { 1.0 / ior };
    let cos_i = wo.z.abs();
    let reflectance = fresnel_dielectric(cos_i, eta);
    if u < reflectance {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        return BsdfSample { wi, value: Vec3::splat(reflectance / cos_i), pdf: reflectance, delta: true, eta: 1.0 };
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let normal = if entering { Vec3::Z } else { Vec3::NEG_Z };
    let wi = (-wo / eta + (cos_i / eta - cos_t) * normal).normalize();
    let transmittance = 1.0 - reflectance;
    let value = tint * (transmittance / (eta * eta) / cos_t.max(1e-8));
    BsdfSample { wi, value, pdf: transmittance, delta: true, eta }
}

/// Reflects or passes straight through a thin dielectric sheet. The sheet
/// reflects R + T²R / (1 − R²) of the light, counting the reflections inside
/// it, with R the Fresnel reflectance and T = 1 − R (pbrt-v4's
/// `ThinDielectricBxDF`); the rest goes through, tinted, with no change of
/// direction and so no change of radiance.
fn sample_thin_dielectric(wo: Vec3, ior: f32, tint: Vec3, u: f32) -> BsdfSample {
    let cos_i = wo.z.abs();
    let reflectance = thin_reflectance(cos_i, ior);
    if u < reflectance {
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        return BsdfSample { wi, value: Vec3::splat(reflectance / cos_i), pdf: reflectance, delta: true, eta: 1.0 };
    }
    let transmittance = 1.0 - reflectance;
    BsdfSample { wi: -wo, value: tint * (transmittance / cos_i), pdf: transmittance, delta: true, eta: 1.0 }
}

/// Fresnel reflectance at a dielectric boundary for a direction on either
/// side: `cos` is its cosine with the normal of the +z side, `ior` the
/// index on the -z side.
fn fresnel_either_side(cos: f32, ior: f32) -> f32 {
    if cos >= 0.0 { fresnel_dielectric(cos, ior) } else { fresnel_dielectric(-cos, 1.0 / ior) }
}

/// The probability with which [`Bsdf::RoughDielectric`] samples reflection
/// from `wo`: the Fresnel reflectance at the macroscopic normal, kept away
/// from 0 and 1 (total internal reflection there need not hold at every
/// microfacet).
fn rough_dielectric_reflect_probability(wo: Vec3, ior: f32) -> f32 {
    fresnel_either_side(wo.z, ior).clamp(0.02, 0.98)
}

/// `w` refracted through a boundary of microfacet normal `wm` (on the +z
/// side) into the other medium; `None` under total internal reflection.
fn refract_at(w: Vec3, wm: Vec3, ior: f32) -> Option<Vec3> {
    let (mut n, mut eta, mut cos_i) = (wm, ior, wm.dot(w));
    if cos_i < 0.0 {
        (n, eta, cos_i) = (-wm, 1.0 / ior, -cos_i);
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-w / eta + (cos_i / eta - cos_t) * n).normalize())
}

/// The value, density and radiance scale of a rough dielectric for a pair
/// of directions.
struct RoughDielectricLobe {
    /// The BSDF's value, without the tint (radiance: refraction divides by η²).
    value: f32,
    /// The density with which [`Bsdf::sample`] draws the pair.
    pdf: f32,
    /// η of the refraction (1 for reflection), as [`BsdfSample::eta`].
    eta: f32,
    transmitted: bool,
}

/// pbrt-v4's rough `DielectricBxDF`: the generalised half vector of the
/// pair, its GGX density, masking and Fresnel; `None` where the pair has
/// no microfacet that joins them.
fn rough_dielectric(wo: Vec3, wi: Vec3, ior: f32, alpha: f32) -> Option<RoughDielectricLobe> {
    let (cos_o, cos_i) = (wo.z, wi.z);
    if cos_o == 0.0 || cos_i == 0.0 {
        return None;
    }
    let reflected = cos_o * cos_i > 0.0;
    let eta = if reflected {
        1.0
    } else if cos_o > 0.0 {
        ior
    } else {
        1.0 / ior
    };
    let wm = (wi * eta + wo).normalize_or_zero();
    if wm == Vec3::ZERO {
        return None;
    }
    let wm = if wm.z < 0.0 { -wm } else { wm };
    let (dot_o, dot_i) = (wm.dot(wo), wm.dot(wi));
    // Microfacets seen from behind join nothing.
    if dot_i * cos_i <= 0.0 || dot_o * cos_o <= 0.0 {
        return None;
    }
    let fresnel = fresnel_either_side(dot_o, ior);
    let d = ggx_d(wm, alpha);
    let g = ggx_g2(wo, wi, alpha);
    // The density of normals visible from wo.
    let visible = ggx_g1(wo, alpha) / cos_o.abs() * d * dot_o.abs();
    let p_reflect = rough_dielectric_reflect_probability(wo, ior);
    if reflected {
        let value = d * g * fresnel / (4.0 * cos_i * cos_o).abs();
        let pdf = p_reflect * visible / (4.0 * dot_o.abs());
        Some(RoughDielectricLobe { value, pdf, eta: 1.0, transmitted: false })
    } else {
        let denominator = (dot_i + dot_o / eta).powi(2);
        let dwm_dwi = dot_i.abs() / denominator;
        let value = d * (1.0 - fresnel) * g * (dot_i * dot_o / (denominator * cos_i * cos_o)).abs() / (eta * eta);
        let pdf = (1.0 - p_reflect) * visible * dwm_dwi;
        Some(RoughDielectricLobe { value, pdf, eta, transmitted: true })
    }
}

/// The reflectance of a thin dielectric sheet, counting the reflections
/// inside it: R + T²R / (1 − R²) with R the Fresnel reflectance, T = 1 − R.
fn thin_reflectance(cos_i: f32, ior: f32) -> f32 {
    let r = fresnel_dielectric(cos_i, ior);
    if r < 1.0 { r + (1.0 - r) * (1.0 - r) * r / (1.0 - r * r) } else { 1.0 }
}

/// The pieces of a rough thin sheet's value and density for a pair of
/// directions; `None` where the sheet sends nothing from `wi` to `wo`.
struct RoughThinLobe {
    transmitted: bool,
    /// GGX's D G2 / (4 cos cos) for the reflected direction.
    microfacet_value: f32,
    /// The share reflected (or transmitted) at the microfacet.
    fresnel_weight: f32,
    /// The probability that sampling chooses this side.
    choice: f32,
    reflection_pdf: f32,
}

fn rough_thin(wo: Vec3, wi: Vec3, ior: f32, alpha: f32) -> Option<RoughThinLobe> {
    let upper = to_upper(wo);
    let same_side = wi.z * wo.z > 0.0;
    // Transmitted directions mirror to the reflected ones above the sheet.
    let reflected = Vec3::new(wi.x, wi.y, wi.z.abs());
    if upper.z <= 0.0 || reflected.z <= 0.0 {
        return None;
    }
    let wm = (upper + reflected).normalize_or_zero();
    if wm == Vec3::ZERO {
        return None;
    }
    let reflectance = thin_reflectance(upper.dot(wm).clamp(0.0, 1.0), ior);
    let p_reflect = thin_reflectance(upper.z, ior).clamp(0.02, 0.98);
    Some(RoughThinLobe {
        transmitted: !same_side,
        microfacet_value: ggx_d(wm, alpha) * ggx_g2(upper, reflected, alpha) / (4.0 * upper.z * reflected.z),
        fresnel_weight: if same_side { reflectance } else { 1.0 - reflectance },
        choice: if same_side { p_reflect } else { 1.0 - p_reflect },
        reflection_pdf: ggx_reflection_pdf(upper, reflected, alpha),
    })
}

impl Bsdf {
    /// The model's reflectance for light from straight above, a cheap
    /// measure of how much it scatters (to choose between lobes).
    pub fn nominal_albedo(&self) -> Vec3 {
        match *self {
            Bsdf::Lambert { albedo } => albedo,
            Bsdf::Mirror { reflectance } | Bsdf::Glossy { reflectance, .. } => reflectance,
            Bsdf::MetallicRoughness { base_color, .. } => base_color,
            Bsdf::DiffuseGlossy { albedo, reflectance, .. } => albedo + reflectance,
            Bsdf::Dielectric { tint, .. }
            | Bsdf::ThinDielectric { tint, .. }
            | Bsdf::RoughDielectric { tint, .. }
            | Bsdf::RoughThinDielectric { tint, .. } => tint,
            Bsdf::Layered(layers) => layers.nominal_albedo(),
        }
    }

    /// The model with every lobe at least `alpha` wide, for path
    /// regularisation (Kaplanyan and Dachsbacher, "Path Space
    /// Regularization for Holistic and Robust Light Transport", 2013;
    /// Cycles' "filter glossy"): mirrors become glossy and smooth glass
    /// rough, so light sampling reaches through them; wider lobes and
    /// Lambert are kept as they are.
    pub fn regularised(self, alpha: f32) -> Bsdf {
        match self {
            Bsdf::Lambert { .. } => self,
            Bsdf::Mirror { reflectance } => Bsdf::Glossy { reflectance, alpha },
            Bsdf::MetallicRoughness { base_color, metallic, alpha: own } => {
                Bsdf::MetallicRoughness { base_color, metallic, alpha: own.max(alpha) }
            }
            Bsdf::Glossy { reflectance, alpha: own } => Bsdf::Glossy { reflectance, alpha: own.max(alpha) },
            Bsdf::DiffuseGlossy { albedo, reflectance, alpha: own } => {
                Bsdf::DiffuseGlossy { albedo, reflectance, alpha: own.max(alpha) }
            }
            Bsdf::Dielectric { ior, tint } => Bsdf::RoughDielectric { ior, tint, alpha },
            Bsdf::ThinDielectric { ior, tint } => Bsdf::RoughThinDielectric { ior, tint, alpha },
            Bsdf::RoughDielectric { ior, tint, alpha: own } => {
                Bsdf::RoughDielectric { ior, tint, alpha: own.max(alpha) }
            }
            Bsdf::RoughThinDielectric { ior, tint, alpha: own } => {
                Bsdf::RoughThinDielectric { ior, tint, alpha: own.max(alpha) }
            }
            Bsdf::Layered(layers) => Bsdf::Layered(layers.regularised(alpha)),
        }
    }
}

/// How often the metallic-roughness model samples its specular lobe.
fn specular_probability(metallic: f32) -> f32 {
    0.5 + 0.5 * metallic.clamp(0.0, 1.0)
}

/// How often the diffuse-and-glossy model samples its glossy lobe: in
/// proportion to the lobes' luminance, so the brighter lobe gets the
/// samples, but never below 10% for either lobe while it reflects at all,
/// so that a dim but narrow highlight is still found often enough.
fn glossy_probability(albedo: Vec3, reflectance: Vec3) -> f32 {
    let (diffuse, glossy) = (rtgi_math::luminance(albedo).max(0.0), rtgi_math::luminance(reflectance).max(0.0));
    if glossy <= 0.0 {
        return 0.0;
    }
    if diffuse <= 0.0 {
        return 1.0;
    }
    (glossy / (diffuse + glossy)).clamp(0.1, 0.9)
}

pub(crate) fn to_upper(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, w.z.abs())
}

/// `w` mirrored to the upper hemisphere when `wo` is in the lower one.
pub(crate) fn to_upper_with(w: Vec3, wo: Vec3) -> Vec3 {
    if wo.z < 0.0 { Vec3::new(w.x, w.y, -w.z) } else { w }
}

pub(crate) fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

/// A cosine-distributed direction about +z (Malley's method).
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
}

/// The GGX distribution of normals.
fn ggx_d(m: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = m.z * m.z * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// Smith's Λ for GGX.
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let tan2 = (1.0 - w.z * w.z).max(0.0) / (w.z * w.z);
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

/// Height-correlated masking-shadowing.
fn ggx_g2(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

/// Density of reflected directions sampled through visible normals.
fn ggx_reflection_pdf(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    let wm = (wo + wi).normalize_or_zero();
    let cos_om = wo.dot(wm);
    if wm == Vec3::ZERO || cos_om <= 0.0 {
        return 0.0;
    }
    let visible = ggx_g1(wo, alpha) * cos_om * ggx_d(wm, alpha) / wo.z;
    visible / (4.0 * cos_om)
}

/// A microfacet normal drawn from the normals visible from `wo` (Heitz,
/// "Sampling the GGX Distribution of Visible Normals", JCGT 2018).
fn sample_ggx_visible_normal(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    // The anisotropic sampler with equal widths does the same arithmetic.
    crate::layered::anisotropic_ggx::AnisotropicGgx::isotropic(alpha).sample_visible_normal(wo, u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Rng;

    fn models() -> Vec<Bsdf> {
        vec![
            Bsdf::Lambert { albedo: Vec3::new(0.8, 0.5, 0.2) },
            Bsdf::MetallicRoughness { base_color: Vec3::new(0.9, 0.6, 0.3), metallic: 1.0, alpha: 0.3 },
            Bsdf::MetallicRoughness { base_color: Vec3::new(0.9, 0.6, 0.3), metallic: 0.0, alpha: 0.5 },
            Bsdf::MetallicRoughness { base_color: Vec3::ONE, metallic: 0.5, alpha: 0.05 },
            Bsdf::Glossy { reflectance: Vec3::new(0.9, 0.9, 0.5), alpha: 0.2 },
            Bsdf::DiffuseGlossy { albedo: Vec3::new(0.6, 0.4, 0.2), reflectance: Vec3::splat(0.2), alpha: 0.1 },
            Bsdf::DiffuseGlossy { albedo: Vec3::splat(0.02), reflectance: Vec3::splat(0.5), alpha: 0.4 },
            Bsdf::RoughThinDielectric { ior: 1.5, tint: Vec3::new(0.9, 0.8, 0.7), alpha: 0.3 },
            Bsdf::RoughDielectric { ior: 1.5, tint: Vec3::new(0.9, 0.8, 0.7), alpha: 0.3 },
            Bsdf::RoughDielectric { ior: 2.4, tint: Vec3::ONE, alpha: 0.4 },
            Bsdf::Layered(crate::layered::PbrLayers {
                alpha_x: 0.4,
                alpha_y: 0.1,
                ior: 1.7,
                specular_factor: 0.8,
                specular_color: Vec3::new(1.0, 0.8, 0.6),
                iridescence: Some(crate::layered::Iridescence { factor: 0.7, ior: 1.3, thickness_nm: 350.0 }),
                sheen: Some(crate::layered::Sheen { color: Vec3::new(0.3, 0.2, 0.4), roughness: 0.5 }),
                clearcoat: Some(crate::layered::Clearcoat {
                    factor: 0.8,
                    alpha: 0.05,
                    normal: Vec3::new(0.2, 0.0, 1.0).normalize(),
                }),
                ..crate::layered::PbrLayers::isotropic(Vec3::new(0.8, 0.4, 0.2), 0.3, 0.3)
            }),
        ]
    }

    fn direction(theta: f32) -> Vec3 {
        Vec3::new(theta.sin(), 0.0, theta.cos())
    }

    #[test]
    fn mtl_colours_beyond_one_are_scaled_together_and_others_kept_bit_for_bit() {
        let (kd, ks) = (Vec3::new(1.0, 0.9, 0.6), Vec3::splat(0.5));
        let (diffuse, specular) = energy_conserving(kd, ks);
        assert!(((diffuse + specular).max_element() - 1.0).abs() < 1e-6, "{diffuse} + {specular}");
        assert!((diffuse * 1.5 - kd).abs().max_element() < 1e-6 && (specular * 1.5 - ks).abs().max_element() < 1e-6);
        for (kd, ks) in [
            (Vec3::new(0.6, 0.4, 0.2), Vec3::splat(0.2)),
            (Vec3::splat(0.7), Vec3::splat(0.3)),
            (Vec3::ZERO, Vec3::ONE),
        ] {
            assert_eq!(energy_conserving(kd, ks), (kd, ks));
        }
    }

    #[test]
    fn samples_agree_with_eval_and_pdf() {
        let mut rng = Rng::new(1, 2);
        for bsdf in models() {
            for theta in [0.1f32, 0.8, 1.4] {
                for side in [1.0f32, -1.0] {
                    let mut wo = direction(theta);
                    wo.z *= side;
                    for _ in 0..2000 {
                        let Some(s) = bsdf.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())) else { continue };
                        let transmits = bsdf.transmits();
                        assert!(transmits || s.wi.z * wo.z > 0.0, "{bsdf:?}: sampled through the surface");
                        assert!((s.pdf - bsdf.pdf(wo, s.wi)).abs() <= 1e-3 * s.pdf.max(1.0), "{bsdf:?}");
                        assert!(
                            (s.value - bsdf.eval(wo, s.wi)).abs().max_element()
                                <= 1e-3 * s.value.max_element().max(1.0)
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn densities_integrate_to_the_sampling_success_rate_and_energy_is_conserved() {
        // The density integrates to the share of samples that succeed: 1 for
        // Lambert, less for GGX, whose reflections of steep microfacets can
        // point below the surface (such samples are refused, not redrawn,
        // which keeps estimates unbiased). Integrals use uniform directions.
        let mut rng = Rng::new(3, 4);
        let n = 400_000;
        for bsdf in models() {
            for theta in [0.2f32, 1.0] {
                let wo = direction(theta);
                let (mut pdf_sum, mut albedo) = (0.0f64, rtgi_math::glam::DVec3::ZERO);
                for _ in 0..n {
                    let wi = crate::rays::uniform_sphere(rng.next_f32(), rng.next_f32());
                    pdf_sum += bsdf.pdf(wo, wi) as f64 * 4.0 * PI as f64;
                    albedo += (bsdf.eval(wo, wi) * wi.z.abs() * 4.0 * PI).as_dvec3();
                }
                let successes = (0..n)
                    .filter(|_| bsdf.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())).is_some())
                    .count() as f64
                    / n as f64;
                let pdf_integral = pdf_sum / n as f64;
                let albedo = albedo / n as f64;
                assert!(
                    (pdf_integral - successes).abs() < 0.02,
                    "{bsdf:?} at {theta}: pdf integrates to {pdf_integral}, {successes} of samples succeed"
                );
                if matches!(bsdf, Bsdf::Lambert { .. }) {
                    assert!((pdf_integral - 1.0).abs() < 0.01 && successes == 1.0);
                }
                assert!(albedo.max_element() <= 1.02, "{bsdf:?} at {theta}: albedo {albedo}");
            }
        }
    }

    #[test]
    fn furnace_albedos() {
        // Importance-sampled albedo: Lambert returns its albedo exactly; a
        // smooth white metal loses almost nothing; rough GGX loses the energy
        // of the single-scattering approximation, exactly as much as theory says.
        let mut rng = Rng::new(5, 6);
        let albedo = |bsdf: Bsdf, wo: Vec3, rng: &mut Rng| {
            let n = 100_000;
            let mut sum = rtgi_math::glam::DVec3::ZERO;
            for _ in 0..n {
                if let Some(s) = bsdf.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())) {
                    sum += (s.value * s.wi.z.abs() / s.pdf).as_dvec3();
                }
            }
            (sum / n as f64).as_vec3()
        };
        let lambert = albedo(Bsdf::Lambert { albedo: Vec3::splat(0.7) }, direction(0.5), &mut rng);
        assert!((lambert - Vec3::splat(0.7)).abs().max_element() < 1e-4, "{lambert}");
        let smooth = albedo(
            Bsdf::MetallicRoughness { base_color: Vec3::ONE, metallic: 1.0, alpha: 0.05 },
            direction(0.3),
            &mut rng,
        );
        assert!(smooth.min_element() > 0.97 && smooth.max_element() < 1.01, "{smooth}");
        // At alpha = 1 GGX is uniform (D = 1/π) and at normal incidence the
        // height-correlated G2 is G1(wi) = 2 cos / (1 + cos), so the
        // single-scattering albedo is ∫ cos/(1 + cos) dcos = 1 - ln 2.
        let rough =
            albedo(Bsdf::MetallicRoughness { base_color: Vec3::ONE, metallic: 1.0, alpha: 1.0 }, Vec3::Z, &mut rng);
        assert!((rough.x - (1.0 - 2f32.ln())).abs() < 0.01, "{rough}");
        let mirror = Bsdf::Mirror { reflectance: Vec3::splat(0.9) }.sample(direction(0.7), Vec2::ZERO).unwrap();
        assert!((mirror.value * mirror.wi.z / mirror.pdf - Vec3::splat(0.9)).abs().max_element() < 1e-6);
        assert!((mirror.wi - Vec3::new(-0.7f32.sin(), 0.0, 0.7f32.cos())).length() < 1e-6);
    }

    #[test]
    fn diffuse_glossy_reflects_what_its_two_lobes_reflect() {
        // The mixture's importance-sampled albedo must be the Lambertian
        // albedo plus the glossy lobe's own albedo, at every sample count
        // (a wrong mixture weight shows up as a constant offset).
        let (albedo, reflectance, alpha) = (Vec3::new(0.5, 0.3, 0.1), Vec3::splat(0.25), 0.15);
        let layered = Bsdf::DiffuseGlossy { albedo, reflectance, alpha };
        let glossy = Bsdf::Glossy { reflectance, alpha };
        let mut rng = Rng::new(7, 8);
        for theta in [0.2f32, 0.9, 1.3] {
            let wo = direction(theta);
            let estimate = |bsdf: Bsdf, n: usize, rng: &mut Rng| {
                let mut sum = rtgi_math::glam::DVec3::ZERO;
                for _ in 0..n {
                    if let Some(s) = bsdf.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())) {
                        sum += (s.value * s.wi.z.abs() / s.pdf).as_dvec3();
                    }
                }
                (sum / n as f64).as_vec3()
            };
            let expected = albedo + estimate(glossy, 400_000, &mut rng);
            for n in [1_000usize, 20_000, 400_000] {
                let got = estimate(layered, n, &mut rng);
                let tolerance = 3.0 / (n as f32).sqrt();
                assert!((got - expected).abs().max_element() < tolerance, "{theta} with {n}: {got} vs {expected}");
            }
        }
    }

    #[test]
    fn thin_dielectric_passes_light_straight_through_and_loses_none() {
        let sheet = Bsdf::ThinDielectric { ior: 1.5, tint: Vec3::ONE };
        for theta in [0.0f32, 0.7, 1.3] {
            let wo = direction(theta);
            let through = sheet.sample(wo, Vec2::new(0.999, 0.0)).unwrap();
            assert!((through.wi + wo).length() < 1e-6);
            let back = sheet.sample(wo, Vec2::ZERO).unwrap();
            let weight = |s: &BsdfSample| s.value.x * s.wi.z.abs() / s.pdf;
            assert!((weight(&through) - 1.0).abs() < 1e-5 && (weight(&back) - 1.0).abs() < 1e-5);
            // Two surfaces reflect more than one: 2R / (1 + R) at normal incidence.
            assert!(back.pdf >= fresnel_dielectric(theta.cos(), 1.5));
        }
        let normal = sheet.sample(Vec3::Z, Vec2::ZERO).unwrap();
        assert!((normal.pdf - 2.0 * 0.04 / 1.04).abs() < 1e-6);
    }

    #[test]
    fn dielectric_fresnel_and_refraction() {
        // Normal incidence: ((n - 1) / (n + 1))², from either side.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        // Total internal reflection beyond the critical angle inside glass.
        let critical = (1.0f32 / 1.5).asin();
        assert_eq!(fresnel_dielectric((critical + 0.01).cos(), 1.0 / 1.5), 1.0);
        assert!(fresnel_dielectric((critical - 0.01).cos(), 1.0 / 1.5) < 1.0);

        let glass = Bsdf::Dielectric { ior: 1.5, tint: Vec3::ONE };
        for theta in [0.0f32, 0.4, 1.0, 1.5] {
            let wo = direction(theta);
            // Refraction obeys Snell's law and leaves through the other side.
            let refracted = glass.sample(wo, Vec2::new(0.999, 0.0)).unwrap();
            assert!(refracted.wi.z < 0.0 && refracted.delta);
            let sin_t = (refracted.wi.x * refracted.wi.x + refracted.wi.y * refracted.wi.y).sqrt();
            assert!((theta.sin() - 1.5 * sin_t).abs() < 1e-5, "Snell at {theta}");
            // Reflection and refraction weights, with the 1/η² radiance
            // compression undone, sum to one: the boundary loses no energy.
            let reflectance = fresnel_dielectric(theta.cos(), 1.5);
            let weight = |s: &BsdfSample| s.value * s.wi.z.abs() / s.pdf;
            let reflected = glass.sample(wo, Vec2::new(0.0, 0.0)).unwrap();
            assert!((reflected.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
            let energy = reflectance * weight(&reflected).x + (1.0 - reflectance) * weight(&refracted).x * 1.5 * 1.5;
            assert!((energy - 1.0).abs() < 1e-5, "energy {energy} at {theta}");
            // Entering and leaving a parallel slab: the ray leaves parallel
            // to how it came in, with its radiance unchanged.
            // The slab's lower face has the outward normal -z: flip z into its frame and back.
            let flip = |w: Vec3| Vec3::new(w.x, w.y, -w.z);
            let out = glass.sample(flip(-refracted.wi), Vec2::new(0.999, 0.0)).unwrap();
            assert!((flip(out.wi) - (-wo)).length() < 1e-5, "{theta}: left along {}", flip(out.wi));
            let round_trip = weight(&refracted) * weight(&out);
            assert!((round_trip - Vec3::ONE).abs().max_element() < 1e-5, "{round_trip}");
        }
    }

    #[test]
    fn a_rough_dielectric_loses_little_energy_and_narrows_to_the_smooth_one() {
        // Importance-sampled, with refraction's 1/η² undone, the boundary
        // never returns more than it receives, from either side; it loses
        // what single scattering leaves out, which is next to nothing for
        // narrow lobes (and up to a fifth from inside at alpha 0.3, where
        // microfacets reflect totally into each other); and as alpha
        // shrinks, reflection takes the smooth boundary's Fresnel share.
        let mut rng = Rng::new(9, 10);
        let n = 200_000;
        for (alpha, loss) in [(0.01f32, 0.01f64), (0.3, 0.25)] {
            let rough = Bsdf::RoughDielectric { ior: 1.5, tint: Vec3::ONE, alpha };
            for theta in [0.2f32, 0.9] {
                for side in [1.0f32, -1.0] {
                    let mut wo = direction(theta);
                    wo.z *= side;
                    let (mut energy, mut reflected) = (0.0f64, 0.0f64);
                    for _ in 0..n {
                        let Some(s) = rough.sample(wo, Vec2::new(rng.next_f32(), rng.next_f32())) else { continue };
                        let weight = (s.value.x * s.wi.z.abs() / s.pdf) as f64;
                        energy += weight * (s.eta * s.eta) as f64;
                        if s.wi.z * wo.z > 0.0 {
                            reflected += weight;
                        }
                    }
                    let (energy, reflected) = (energy / n as f64, reflected / n as f64);
                    assert!(energy <= 1.005, "alpha {alpha}, {theta}, side {side}: energy {energy}");
                    assert!(energy >= 1.0 - loss, "alpha {alpha}, {theta}, side {side}: energy {energy}");
                    if alpha < 0.05 {
                        let eta = if side > 0.0 { 1.5 } else { 1.0 / 1.5 };
                        let smooth = fresnel_dielectric(theta.cos(), eta) as f64;
                        assert!((reflected - smooth).abs() < 0.01, "{theta}, side {side}: {reflected} vs {smooth}");
                    }
                }
            }
        }
    }
}
