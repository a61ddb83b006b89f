//! From a glTF material and its textures at a hit to the layered BSDF
//! ([`PbrLayers`]) in the hit's shading frame: the extensions' factors
//! times their textures (each in the channel its specification names), the
//! frame turned to the direction of anisotropy, and the coat's own normal.
//! Layers the plan leaves out are dropped here, so they cost nothing later.

use rtgi_math::{Frame, Vec2, Vec3, Vec4};
use rtgi_scene::{Material, TextureId};

use crate::layered::{Clearcoat, Iridescence, PbrLayers, Sheen};

/// Which layers the plan simulates.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LayerSwitches {
    pub sheen: bool,
    pub clearcoat: bool,
    pub iridescence: bool,
    pub anisotropy: bool,
}

/// Whether `material` needs the layered model rather than the plain
/// metallic-roughness one: a layer the plan simulates, or a dielectric
/// Fresnel other than glTF's default (KHR_materials_specular, KHR_materials_ior).
pub(crate) fn needs_layers(material: &Material, on: LayerSwitches) -> bool {
    (on.sheen && material.sheen.is_some())
        || (on.clearcoat && material.clearcoat.is_some())
        || (on.iridescence && material.iridescence.is_some())
        || (on.anisotropy && material.anisotropy.is_some())
        || material.dielectric_specular != rtgi_scene::DielectricSpecular::default()
        || material.ior != 1.5
}

/// What a hit gives the layers besides the material.
pub(crate) struct LayerInputs<'a> {
    /// Looks up a texture at the hit (`None` where textures are off).
    pub texture: Option<&'a dyn Fn(TextureId) -> Vec4>,
    /// The base colour, metallic and perceptual roughness after their textures.
    pub base_color: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    /// The shading frame (the base's normal map applied).
    pub frame: Frame,
    /// The interpolated vertex normal, before any normal map: the coat's
    /// normal where it has no map of its own.
    pub geometry_normal: Vec3,
    /// The interpolated vertex tangent (w: the bitangent's sign).
    pub tangent: Vec4,
    /// Bends a normal by a normal-map texel (`perturb` of the integrator).
    pub perturb: fn(Vec3, Vec4, Vec3, f32) -> Vec3,
}

/// The smallest GGX width, as the plain models use.
const MIN_ALPHA: f32 = 1e-3;

/// The layered BSDF of `material` at a hit, and the frame it is expressed
/// in (turned about the normal towards the direction of anisotropy).
pub(crate) fn pbr_layers(material: &Material, on: LayerSwitches, hit: &LayerInputs<'_>) -> (PbrLayers, Frame) {
    let texture = |id: Option<TextureId>| -> Option<Vec4> { Some((hit.texture?)(id?)) };
    let alpha = (hit.roughness * hit.roughness).max(MIN_ALPHA);
    let mut frame = hit.frame;
    let (mut alpha_x, mut alpha_y) = (alpha, alpha);
    if on.anisotropy
        && let Some(anisotropy) = &material.anisotropy
    {
        // KHR_materials_anisotropy: a direction in tangent space (the
        // texture's red and green as a normal map stores them, else +u),
        // turned by the rotation; the width along it grows with strength².
        let (mut direction, mut strength) = (Vec2::X, anisotropy.strength);
        if let Some(t) = texture(anisotropy.texture) {
            direction = (Vec2::new(t.x, t.y) * 2.0 - Vec2::ONE).normalize_or(Vec2::X);
            strength *= t.z;
        }
        let direction = Vec2::from_angle(anisotropy.rotation).rotate(direction);
        let n = frame.z;
        let t = (hit.tangent.truncate() - n * n.dot(hit.tangent.truncate())).normalize_or_zero();
        if t != Vec3::ZERO {
            let b = n.cross(t) * if hit.tangent.w < 0.0 { -1.0 } else { 1.0 };
            frame = Frame::from_z_and_x(n, t * direction.x + b * direction.y);
            let strength = strength.clamp(0.0, 1.0);
            alpha_x = alpha + (1.0 - alpha) * strength * strength;
            alpha_y = alpha;
        }
    }
    let specular = &material.dielectric_specular;
    let specular_factor = specular.factor * texture(specular.factor_texture).map_or(1.0, |t| t.w);
    let specular_color = specular.color * texture(specular.color_texture).map_or(Vec3::ONE, |t| t.truncate());
    let iridescence = material.iridescence.as_ref().filter(|_| on.iridescence).map(|film| {
        let thickness = match texture(film.thickness_texture) {
            Some(t) => film.thickness_min + (film.thickness_max - film.thickness_min) * t.y,
            None => film.thickness_max,
        };
        Iridescence {
            factor: film.factor * texture(film.factor_texture).map_or(1.0, |t| t.x),
            ior: film.ior,
            thickness_nm: thickness,
        }
    });
    let sheen = material.sheen.as_ref().filter(|_| on.sheen).map(|sheen| Sheen {
        color: sheen.color * texture(sheen.color_texture).map_or(Vec3::ONE, |t| t.truncate()),
        roughness: sheen.roughness * texture(sheen.roughness_texture).map_or(1.0, |t| t.w),
    });
    let clearcoat = material.clearcoat.as_ref().filter(|_| on.clearcoat).map(|coat| {
        let roughness = coat.roughness * texture(coat.roughness_texture).map_or(1.0, |t| t.y);
        // The coat follows the geometry, not the base's normal map, unless it has a map of its own.
        let mut normal = hit.geometry_normal;
        if let (Some((id, scale)), Some(lookup)) = (coat.normal_texture, hit.texture) {
            normal = (hit.perturb)(normal, hit.tangent, lookup(id).truncate(), scale);
        }
        let local = frame.to_local(normal.normalize_or_zero());
        Clearcoat {
            factor: (coat.factor * texture(coat.factor_texture).map_or(1.0, |t| t.x)).clamp(0.0, 1.0),
            alpha: (roughness * roughness).max(MIN_ALPHA),
            normal: if local.z > 1e-3 && local.is_finite() { local.normalize() } else { Vec3::Z },
        }
    });
    let layers = PbrLayers {
        base_color: hit.base_color,
        metallic: hit.metallic.clamp(0.0, 1.0),
        alpha_x,
        alpha_y,
        ior: material.ior.max(1.0),
        specular_factor: specular_factor.max(0.0),
        specular_color: specular_color.max(Vec3::ZERO),
        iridescence: iridescence.filter(|i| i.factor > 0.0),
        sheen: sheen.filter(|s| s.color.max_element() > 0.0),
        clearcoat: clearcoat.filter(|c| c.factor > 0.0),
    };
    (layers, frame)
}
