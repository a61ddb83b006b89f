//! glTF's layered material ("PBR next": the core metallic-roughness model
//! with KHR_materials_ior, _specular, _anisotropy, _iridescence, _sheen and
//! _clearcoat) as one reflection model, in the local shading frame of
//! [`crate::bsdf`]: +z the shading normal, +x the anisotropy direction,
//! `wo` towards the viewer, `wi` towards the light. Reflection only, and
//! two-sided: for `wo` below the surface both directions are mirrored
//! above it.
//!
//! From the top:
//! - **clearcoat**: GGX of width `alpha` about the coat's own normal, with
//!   Schlick's Fresnel of index 1.5 at the microfacet (wo·h), weighted by
//!   `factor`. A tilted coat normal takes the light by its own cosine, as
//!   the glTF sample viewer does (its value is multiplied by
//!   cos θi(coat) / cos θi(shading)), so that the coat reflects its own
//!   albedo whatever the tilt; that is not reciprocal, as no normal map
//!   is. (With the shading frame's cosines in its denominator instead, a
//!   coat tilted towards a grazing view reflected 1.07 of the light.)
//!   Below the coat everything is dimmed by
//!   `1 − factor · max(E_coat(wo), E_coat(wi))`, E_coat the coat lobe's
//!   directional albedo: the base gets what the coat does not reflect.
//!   The extension dims by `1 − factor · F(n·wo)`, the Fresnel of the
//!   macroscopic normal, which is never below E_coat(wo) by more than
//!   0.001 (a rough lobe loses more to masking than its tilted
//!   microfacets gain in Fresnel), so it does not create energy either,
//!   but it loses what the coat's masking keeps from both: under a coat of
//!   width 0.25 a white base seen at cos θ = 0.15 returns 0.68 of the
//!   light, and 0.58 under width 1.
//! - **sheen**: Charlie fibres with Smith's masking (`layered/sheen.rs`) times
//!   `sheenColor`; below it, `1 − max(sheenColor) · max(E_sheen(wo),
//!   E_sheen(wi))`, as the extension's albedo scaling with both directions
//!   (its `min` of two terms).
//! - **base**: `mix(dielectric, metal, metallic)`, both with the same
//!   anisotropic GGX lobe (`layered/anisotropic_ggx.rs`), D G2 / (4 cos θo cos θi).
//!   - The metal's Fresnel is Schlick's from `baseColor` to white.
//!   - The dielectric's is KHR_materials_specular's: F0 = min(F0(ior) ·
//!     specularColor, 1) · specular, F90 = specular, at wo·h. Its
//!     diffuse lobe, baseColor / π, is dimmed by `1 − max over channels
//!     and both directions of E_dielectric`, the specular lobe's albedo.
//!     The extension's `(1 − max(F(wo·h))) · diffuse` keeps the diffuse at
//!     ~96% at grazing views, where the specular lobe reflects most: a
//!     white dielectric of width 0.3 then reflects 1.04 of the light at
//!     75° and 1.08 at 83°.
//!   - KHR_materials_iridescence mixes both Fresnel terms towards the
//!     thin film's (`layered/iridescence.rs`) by `factor`, over `F0` of the
//!     dielectric and `baseColor` of the metal, as the extension's
//!     appendix does. The film's albedo, for dimming the diffuse, is
//!     approximated by its Fresnel at the lobe's effective angle times the
//!     lobe's white albedo (see `film_albedo`).
//!
//! Albedo scaling by both directions keeps every layering symmetric in
//! `wo` and `wi` (reciprocal, but for a tilted coat) and within what it
//! receives: the layers below get at most 1 − E(wo) of the light, and
//! E(wo) is what the layer reflects. Dimming by the larger of the two
//! albedos loses what a layer reflects of grazing light before it
//! reaches the layer below (a white base under a white sheen of roughness
//! 0.5 returns 0.87 at normal incidence, the sheen 0.03 of it); dimming
//! by E(wo) alone would keep it, but not reciprocity. The albedos come
//! from tables built on first use (`layered/albedo_table.rs`).
//!
//! Sampling is one-sample MIS over the lobes (cosine-weighted diffuse, the
//! base's and the coat's visible normals, uniform directions for the
//! sheen), chosen with probabilities from each lobe's albedo at `wo`,
//! never below 5% for a lobe that is there; absent lobes are
//! neither evaluated nor chosen.

mod albedo_table;
pub(crate) mod anisotropic_ggx;
#[cfg(test)]
mod chi_square;
mod iridescence;
mod quadrature;
mod sheen;
mod table;
#[cfg(test)]
mod tests;

use std::f32::consts::PI;

use rtgi_math::{Frame, Vec2, Vec3};

use crate::bsdf::{BsdfSample, cosine_hemisphere, reflect, to_upper, to_upper_with};
use albedo_table::{coat_albedo, ggx_albedo, sheen_albedo};
use anisotropic_ggx::AnisotropicGgx;

/// The narrowest GGX width evaluated: narrower lobes are widened to it, as
/// the integrator does, because their D overflows f32 before a mirror
/// direction can be hit anyway.
const MIN_WIDTH: f32 = 1e-3;

/// The clearcoat's reflectance at normal incidence (index 1.5).
const COAT_F0: f32 = 0.04;

/// The least probability with which a lobe that is present is sampled, so
/// that a lobe whose albedo at `wo` is small but whose peak is high (a
/// dim narrow highlight, a sheen at grazing light) is still found.
const LOBE_FLOOR: f32 = 0.05;

/// glTF's layered material in the local shading frame: +z the shading
/// normal, +x the anisotropy direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PbrLayers {
    /// Diffuse colour of the dielectric, Fresnel colour of the metal (linear RGB).
    pub base_color: Vec3,
    /// From 0 (dielectric) to 1 (metal).
    pub metallic: f32,
    /// GGX width along +x (after anisotropy), in [1e-3, 1] (narrower is widened to 1e-3).
    pub alpha_x: f32,
    /// GGX width along +y; equal to `alpha_x` when isotropic.
    pub alpha_y: f32,
    /// KHR_materials_ior (default 1.5): the dielectric's F0 is ((ior − 1) / (ior + 1))².
    pub ior: f32,
    /// KHR_materials_specular `specularFactor` (default 1), in [0, 1].
    pub specular_factor: f32,
    /// KHR_materials_specular `specularColorFactor` (default 1, 1, 1).
    pub specular_color: Vec3,
    /// KHR_materials_iridescence, if present.
    pub iridescence: Option<Iridescence>,
    /// KHR_materials_sheen, if present.
    pub sheen: Option<Sheen>,
    /// KHR_materials_clearcoat, if present.
    pub clearcoat: Option<Clearcoat>,
}

/// A thin film on the base (KHR_materials_iridescence).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iridescence {
    /// How much of the film's Fresnel replaces the base's, in [0, 1].
    pub factor: f32,
    /// The film's index of refraction (`iridescenceIor`, default 1.3).
    pub ior: f32,
    /// The film's thickness in nanometres; 0 is no film.
    pub thickness_nm: f32,
}

/// A layer of fibres over the base (KHR_materials_sheen).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sheen {
    /// `sheenColorFactor` (linear RGB); black is no sheen.
    pub color: Vec3,
    /// The perceptual sheen roughness, in [0, 1]; the distribution's width
    /// is its square, and roughnesses below 0.07 are evaluated at 0.07.
    pub roughness: f32,
}

/// A clear dielectric coat over everything else (KHR_materials_clearcoat).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearcoat {
    /// `clearcoatFactor`, in [0, 1]; 0 is no coat.
    pub factor: f32,
    /// The coat's GGX width, roughness²: in [1e-3, 1] (narrower is widened to 1e-3).
    pub alpha: f32,
    /// The coat's normal, unit, in the local frame (z > 0); `Vec3::Z`
    /// without a coat normal map.
    pub normal: Vec3,
}

/// The lobes, in the order of [`View::choice`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lobe {
    Diffuse,
    Specular,
    Sheen,
    Coat,
}

const LOBES: [Lobe; 4] = [Lobe::Diffuse, Lobe::Specular, Lobe::Sheen, Lobe::Coat];

/// What evaluating, sampling and the density share for one direction
/// `wo` above the shading horizon.
struct View {
    wo: Vec3,
    base: AnisotropicGgx,
    metallic: f32,
    has_diffuse: bool,
    /// Whether the dielectric has a specular lobe (specular > 0 or a film).
    has_dielectric_specular: bool,
    has_specular: bool,
    /// The largest channel of the dielectric's specular albedo at `wo`.
    dielectric_albedo_o: f32,
    /// The sheen, if it shows, with its white albedo at `wo`.
    sheen: Option<(Sheen, f32)>,
    coat: Option<CoatView>,
    /// The probability of sampling each lobe of [`LOBES`].
    choice: [f32; 4],
}

/// The clearcoat seen from `wo`.
struct CoatView {
    /// The frame about the coat's normal; `None` when that is the shading normal.
    frame: Option<Frame>,
    ggx: AnisotropicGgx,
    factor: f32,
    /// `wo` in the coat's frame.
    wo: Vec3,
    /// The coat lobe's albedo at `wo` (at grazing when `wo` is below the coat's horizon).
    albedo_o: f32,
}

impl CoatView {
    fn to_local(&self, w: Vec3) -> Vec3 {
        self.frame.map_or(w, |frame| frame.to_local(w))
    }

    fn to_shading(&self, w: Vec3) -> Vec3 {
        self.frame.map_or(w, |frame| frame.to_world(w))
    }

    /// The coat's BRDF for `wi` in its frame, without `factor`; zero unless
    /// both directions are above the coat.
    fn reflection(&self, wi: Vec3) -> f32 {
        if self.wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (self.wo + wi).normalize_or_zero();
        if h == Vec3::ZERO {
            return 0.0;
        }
        let fresnel = COAT_F0 + (1.0 - COAT_F0) * (1.0 - self.wo.dot(h).clamp(0.0, 1.0)).powi(5);
        fresnel * self.ggx.reflection(self.wo, wi, h)
    }
}

impl View {
    /// The lobe that `u` chooses and `u` stretched back to [0, 1) within its share.
    fn choose(&self, u: f32) -> Option<(Lobe, f32)> {
        let mut start = 0.0;
        let mut last = None;
        for (lobe, p) in LOBES.into_iter().zip(self.choice) {
            if p <= 0.0 {
                continue;
            }
            last = Some((lobe, start, p));
            if u < start + p {
                break;
            }
            start += p;
        }
        // Past the last share (rounding of the sum) is the last lobe's.
        last.map(|(lobe, start, p)| (lobe, ((u - start) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0)))
    }
}

impl PbrLayers {
    /// The core metallic-roughness material: index 1.5, white specular, no layers.
    pub fn isotropic(base_color: Vec3, metallic: f32, alpha: f32) -> PbrLayers {
        PbrLayers {
            base_color,
            metallic,
            alpha_x: alpha,
            alpha_y: alpha,
            ior: 1.5,
            specular_factor: 1.0,
            specular_color: Vec3::ONE,
            iridescence: None,
            sheen: None,
            clearcoat: None,
        }
    }

    /// The BRDF's value for the pair of directions (unit); zero where
    /// either is in the surface's plane or they are on opposite sides.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (wo, wi) = (to_upper(wo), to_upper_with(wi, wo));
        match self.view(wo) {
            Some(view) if above_surface(wi) => self.eval_in(&view, wi),
            _ => Vec3::ZERO,
        }
    }

    /// The density (per solid angle) with which [`Self::sample`] draws `wi`.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = (to_upper(wo), to_upper_with(wi, wo));
        match self.view(wo) {
            Some(view) if above_surface(wi) => self.pdf_in(&view, wi),
            _ => 0.0,
        }
    }

    /// Draws an incident direction for `wo` from two uniform numbers; `u.x`
    /// also chooses the lobe and is stretched back to [0, 1) for it. `None`
    /// when the drawn direction is below the surface (a microfacet
    /// reflected it there) or nothing reflects. The sample's value and
    /// density are [`Self::eval`] and [`Self::pdf`] of its direction.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        let upper = to_upper(wo);
        let view = self.view(upper)?;
        let (lobe, u0) = view.choose(u.x)?;
        let u = Vec2::new(u0, u.y);
        let wi = match lobe {
            Lobe::Diffuse => cosine_hemisphere(u),
            Lobe::Specular => reflect(upper, view.base.sample_visible_normal(upper, u)),
            Lobe::Sheen => uniform_hemisphere(u),
            Lobe::Coat => {
                let coat = view.coat.as_ref()?;
                coat.to_shading(reflect(coat.wo, coat.ggx.sample_visible_normal(coat.wo, u)))
            }
        };
        if !above_surface(wi) {
            return None;
        }
        let pdf = self.pdf_in(&view, wi);
        (pdf > 0.0).then(|| BsdfSample {
            wi: to_upper_with(wi, wo),
            value: self.eval_in(&view, wi),
            pdf,
            delta: false,
            eta: 1.0,
        })
    }

    /// The reflectance for light from straight above, a cheap measure of
    /// how much the material scatters (to choose between lobes elsewhere):
    /// each layer's albedo at normal incidence, layered as [`Self::eval`]
    /// layers them (by the view's albedo alone).
    pub fn nominal_albedo(&self) -> Vec3 {
        let Some(view) = self.view(Vec3::Z) else { return Vec3::ZERO };
        let mut albedo = Vec3::ZERO;
        if view.metallic < 1.0 {
            let specular =
                if view.has_dielectric_specular { self.dielectric_albedo(&view.base, Vec3::Z) } else { Vec3::ZERO };
            albedo += (specular + self.base_color * (1.0 - specular.max_element())) * (1.0 - view.metallic);
        }
        if view.metallic > 0.0 {
            albedo += self.metal_albedo(&view.base, Vec3::Z) * view.metallic;
        }
        if let Some((sheen, e)) = view.sheen {
            albedo = sheen.color * e + albedo * (1.0 - sheen.color.max_element() * e).max(0.0);
        }
        if let Some(coat) = &view.coat {
            albedo = Vec3::splat(coat.factor * coat.albedo_o) + albedo * (1.0 - coat.factor * coat.albedo_o);
        }
        albedo
    }

    /// The material with every GGX lobe (the base's along both axes, the
    /// coat's) at least `alpha` wide, for path regularisation; the sheen
    /// and the diffuse lobe are kept.
    pub fn regularised(self, alpha: f32) -> PbrLayers {
        PbrLayers {
            alpha_x: self.alpha_x.max(alpha),
            alpha_y: self.alpha_y.max(alpha),
            clearcoat: self.clearcoat.map(|coat| Clearcoat { alpha: coat.alpha.max(alpha), ..coat }),
            ..self
        }
    }

    /// What the lobes need to know of `wo` (above the surface), and the
    /// probabilities of sampling them; `None` for `wo` in the plane (or NaN).
    fn view(&self, wo: Vec3) -> Option<View> {
        if !above_surface(wo) {
            return None;
        }
        let base =
            AnisotropicGgx { alpha_x: self.alpha_x.clamp(MIN_WIDTH, 1.0), alpha_y: self.alpha_y.clamp(MIN_WIDTH, 1.0) };
        let metallic = self.metallic.clamp(0.0, 1.0);
        let has_diffuse = metallic < 1.0 && self.base_color.max_element() > 0.0;
        let has_dielectric_specular = self.specular_weight() > 0.0 || self.film().is_some();
        let has_specular = (metallic < 1.0 && has_dielectric_specular) || metallic > 0.0;
        let dielectric_albedo_o = if metallic < 1.0 && has_dielectric_specular {
            self.dielectric_albedo(&base, wo).max_element()
        } else {
            0.0
        };
        let sheen = self.sheen.filter(|sheen| sheen.color.max_element() > 0.0).map(|sheen| {
            let albedo = sheen_albedo(wo.z, sheen.roughness);
            (sheen, albedo)
        });
        let coat = self.clearcoat.filter(|coat| coat.factor > 0.0).map(|coat| {
            let normal = coat.normal.try_normalize().filter(|n| n.z > 0.0).unwrap_or(Vec3::Z);
            let frame = (normal != Vec3::Z).then(|| Frame::from_z(normal));
            let local_wo = frame.map_or(wo, |frame| frame.to_local(wo));
            let ggx = AnisotropicGgx::isotropic(coat.alpha.clamp(MIN_WIDTH, 1.0));
            let albedo_o = coat_albedo(local_wo.z.max(0.0), ggx.alpha_x);
            CoatView { frame, ggx, factor: coat.factor.min(1.0), wo: local_wo, albedo_o }
        });

        // Each lobe's share of the light reflected towards wo, roughly: its
        // albedo at wo, dimmed by the layers above (from wo alone).
        let coat_visible = coat.as_ref().is_some_and(|coat| coat.wo.z > 0.0);
        let coat_reflects = coat.as_ref().map_or(0.0, |coat| coat.factor * coat.albedo_o);
        let mut below = 1.0 - coat_reflects;
        let sheen_weight = sheen.map_or(0.0, |(sheen, e)| {
            let reflected = sheen.color.max_element() * e;
            let weight = below * reflected;
            below *= (1.0 - reflected).max(0.0);
            weight
        });
        let specular_weight = if has_specular {
            let metal = if metallic > 0.0 { self.metal_albedo(&base, wo).max_element() } else { 0.0 };
            below * ((1.0 - metallic) * dielectric_albedo_o + metallic * metal)
        } else {
            0.0
        };
        let diffuse_weight = below * (1.0 - metallic) * (1.0 - dielectric_albedo_o) * self.base_color.max_element();
        let choice = lobe_probabilities(
            [diffuse_weight, specular_weight, sheen_weight, if coat_visible { coat_reflects } else { 0.0 }],
            [has_diffuse, has_specular, sheen.is_some(), coat_visible],
        );
        Some(View {
            wo,
            base,
            metallic,
            has_diffuse,
            has_dielectric_specular,
            has_specular,
            dielectric_albedo_o,
            sheen,
            coat,
            choice,
        })
    }

    /// The value for `wi` above the surface.
    fn eval_in(&self, view: &View, wi: Vec3) -> Vec3 {
        let mut value = self.base_value(view, wi);
        if let Some((sheen, albedo_o)) = view.sheen {
            let albedo = albedo_o.max(sheen_albedo(wi.z, sheen.roughness));
            let below = (1.0 - sheen.color.max_element() * albedo).max(0.0);
            value = sheen.color * sheen::value(view.wo, wi, sheen.roughness) + value * below;
        }
        if let Some(coat) = &view.coat {
            let local_wi = coat.to_local(wi);
            let albedo = coat.albedo_o.max(coat_albedo(local_wi.z.max(0.0), coat.ggx.alpha_x));
            let mut reflection = coat.reflection(local_wi);
            if coat.frame.is_some() {
                // The renderer weighs the value by the shading normal's cosine;
                // the coat's light arrives by its own normal's.
                reflection *= local_wi.z / wi.z;
            }
            value = Vec3::splat(coat.factor * reflection) + value * (1.0 - coat.factor * albedo);
        }
        value
    }

    /// The base, `mix(dielectric, metal, metallic)`, for `wi` above the surface.
    fn base_value(&self, view: &View, wi: Vec3) -> Vec3 {
        let wo = view.wo;
        let h = (wo + wi).normalize_or_zero();
        let specular = if view.has_specular && h != Vec3::ZERO { view.base.reflection(wo, wi, h) } else { 0.0 };
        let cos_oh = wo.dot(h);
        let mut value = Vec3::ZERO;
        if view.metallic < 1.0 {
            let mut dielectric = Vec3::ZERO;
            if view.has_dielectric_specular {
                dielectric += self.dielectric_fresnel(cos_oh) * specular;
            }
            if view.has_diffuse {
                let albedo_i = if view.has_dielectric_specular {
                    self.dielectric_albedo(&view.base, wi).max_element()
                } else {
                    0.0
                };
                dielectric += self.base_color * ((1.0 - view.dielectric_albedo_o.max(albedo_i)) / PI);
            }
            value += dielectric * (1.0 - view.metallic);
        }
        if view.metallic > 0.0 {
            value += self.metal_fresnel(cos_oh) * (specular * view.metallic);
        }
        value
    }

    /// The density of the lobes' mixture for `wi` above the surface.
    fn pdf_in(&self, view: &View, wi: Vec3) -> f32 {
        let [diffuse, specular, sheen, coat] = view.choice;
        let mut pdf = 0.0;
        if diffuse > 0.0 {
            pdf += diffuse * wi.z / PI;
        }
        if specular > 0.0 {
            pdf += specular * view.base.reflection_pdf(view.wo, wi);
        }
        if sheen > 0.0 {
            pdf += sheen / (2.0 * PI);
        }
        if let Some(lobe) = view.coat.as_ref().filter(|_| coat > 0.0) {
            pdf += coat * lobe.ggx.reflection_pdf(lobe.wo, lobe.to_local(wi));
        }
        pdf
    }

    fn specular_weight(&self) -> f32 {
        self.specular_factor.clamp(0.0, 1.0)
    }

    /// The film, if it changes anything.
    fn film(&self) -> Option<Iridescence> {
        self.iridescence.filter(|film| film.factor > 0.0 && film.thickness_nm > 0.0)
    }

    /// KHR_materials_specular's F0 with KHR_materials_ior's index.
    fn dielectric_f0(&self) -> Vec3 {
        let f0 = ((self.ior - 1.0) / (self.ior + 1.0)).powi(2);
        (f0 * self.specular_color).min(Vec3::ONE) * self.specular_weight()
    }

    /// The dielectric's Fresnel at a microfacet seen at cos θ = `cos`.
    fn dielectric_fresnel(&self, cos: f32) -> Vec3 {
        let f0 = self.dielectric_f0();
        let plain = schlick(f0, Vec3::splat(self.specular_weight()), cos);
        match self.film() {
            Some(film) => plain.lerp(film.fresnel(cos, f0), film.factor.min(1.0)),
            None => plain,
        }
    }

    /// The metal's Fresnel at a microfacet seen at cos θ = `cos`.
    fn metal_fresnel(&self, cos: f32) -> Vec3 {
        let plain = schlick(self.base_color, Vec3::ONE, cos);
        match self.film() {
            Some(film) => plain.lerp(film.fresnel(cos, self.base_color), film.factor.min(1.0)),
            None => plain,
        }
    }

    /// The albedo, per channel, of the dielectric's specular lobe towards `w`.
    fn dielectric_albedo(&self, base: &AnisotropicGgx, w: Vec3) -> Vec3 {
        let f0 = self.dielectric_f0();
        let ab = ggx_albedo(w.z, width_towards(base, w));
        let plain = f0 * ab.x + Vec3::splat(self.specular_weight() * ab.y);
        match self.film() {
            Some(film) => plain.lerp(film_albedo(film, f0, ab), film.factor.min(1.0)),
            None => plain,
        }
    }

    /// The albedo, per channel, of the metal's lobe towards `w`.
    fn metal_albedo(&self, base: &AnisotropicGgx, w: Vec3) -> Vec3 {
        let ab = ggx_albedo(w.z, width_towards(base, w));
        let plain = self.base_color * ab.x + Vec3::splat(ab.y);
        match self.film() {
            Some(film) => plain.lerp(film_albedo(film, self.base_color, ab), film.factor.min(1.0)),
            None => plain,
        }
    }
}

impl Iridescence {
    fn fresnel(&self, cos: f32, base_f0: Vec3) -> Vec3 {
        iridescence::thin_film_fresnel(cos, self.ior, self.thickness_nm, base_f0)
    }
}

/// The probabilities of sampling the lobes: LOBE_FLOOR for each lobe
/// present, the rest in proportion to the weights (evenly if all are 0);
/// 0 for absent lobes.
fn lobe_probabilities(weights: [f32; 4], present: [bool; 4]) -> [f32; 4] {
    let count = present.iter().filter(|&&p| p).count();
    if count == 0 {
        return [0.0; 4];
    }
    let total: f32 = weights.iter().zip(present).filter(|(_, p)| *p).map(|(w, _)| w.max(0.0)).sum();
    let spread = 1.0 - count as f32 * LOBE_FLOOR;
    let mut choice = [0.0; 4];
    for i in 0..4 {
        if present[i] {
            let share = if total > 0.0 { weights[i].max(0.0) / total } else { 1.0 / count as f32 };
            choice[i] = LOBE_FLOOR + spread * share;
        }
    }
    choice
}

/// The albedo of a GGX lobe whose Fresnel is the film's, from the lobe's
/// split albedo `ab` ([`ggx_albedo`]): the film's Fresnel at the lobe's
/// effective cosine c̄, (1 − c̄)⁵ = B / (A + B), times the white lobe's
/// albedo A + B. For a Fresnel of Schlick's form that is exact (F0·A + B);
/// for the film it averages over the microfacets' angles as Schlick's
/// weight does. (The film's Fresnel at the macroscopic angle instead
/// overestimated it at grazing, dimming a white diffuse base to 0.56.)
/// Approximate still: over film indices 1.2 to 2.3, thicknesses of 60 to
/// 800 nm and widths of 0.02 to 0.6, a white iridescent dielectric
/// reflected at most 1.014 of the light (at grazing; 1.002 without the
/// film, the tables' error).
fn film_albedo(film: Iridescence, base_f0: Vec3, ab: Vec2) -> Vec3 {
    let white = ab.x + ab.y;
    if white <= 0.0 {
        return Vec3::ZERO;
    }
    let effective_cos = 1.0 - (ab.y / white).powf(0.2);
    film.fresnel(effective_cos, base_f0) * white
}

/// An isotropic width standing for the lobe seen from `w`, to read its
/// albedo from the isotropic table: the width projected onto `w`'s
/// azimuth, which gives Λ(w) exactly and decides the albedo at grazing,
/// blended towards the geometric mean as `w` rises to the normal, where
/// every azimuth counts. Equal widths give that width.
fn width_towards(ggx: &AnisotropicGgx, w: Vec3) -> f32 {
    let (ax, ay) = (ggx.alpha_x, ggx.alpha_y);
    if ax == ay {
        return ax;
    }
    ((ax * ax * w.x * w.x + ay * ay * w.y * w.y + ax * ay * w.z * w.z) / w.length_squared()).sqrt()
}

/// Whether `w` points above the surface (false in its plane and for NaN).
fn above_surface(w: Vec3) -> bool {
    w.z > 0.0
}

/// Schlick's Fresnel from `f0` at normal incidence to `f90` at grazing.
fn schlick(f0: Vec3, f90: Vec3, cos: f32) -> Vec3 {
    f0 + (f90 - f0) * (1.0 - cos.clamp(0.0, 1.0)).powi(5)
}

/// A direction uniformly distributed over the hemisphere above +z (never in its plane).
fn uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = 1.0 - u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}
