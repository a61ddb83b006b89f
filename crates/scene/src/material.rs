use rtgi_math::Vec3;

use crate::TextureId;
use crate::material_layers::{Anisotropy, Clearcoat, DielectricSpecular, Iridescence, Sheen, Volume};

/// A surface's appearance.
///
/// OBJ/MTL fields map as follows: `Kd` → [`base_color`](Self::base_color),
/// `map_Kd` → [`base_color_texture`](Self::base_color_texture), `Ks` →
/// [`specular`](Self::specular), `Ns` → [`shininess`](Self::shininess) (the
/// Phong exponent, also turned into a microfacet
/// [`roughness`](Self::roughness) = (2 / (Ns + 2))^¼, Walter et al. 2007), `Ke`
/// → [`emission`](Self::emission), `Ni` → [`ior`](Self::ior), `d` →
/// [`opacity`](Self::opacity). Absent fields keep the defaults of
/// [`Material::default`]; OBJ surfaces are non-metallic and two-sided. MTL's
/// illumination models 3 and 5 (ray-traced reflection) make the specular
/// lobe a perfect mirror (roughness 0); 4, 6, 7 and 9 (refraction) make the
/// surface transmit (transmission 1, refracting by `Ni`).
///
/// glTF 2.0 metallic-roughness materials map directly: base colour factor
/// and texture, metallic and roughness factors and texture, normal map and
/// scale, emissive factor (times KHR_materials_emissive_strength) and
/// texture, alpha mode and cutoff, double-sided, KHR_materials_transmission
/// (factor and texture) and KHR_materials_ior; `specular` and `shininess` stay zero.
/// The extensions of glTF's layered material fill the layer fields
/// ([`dielectric_specular`](Self::dielectric_specular), [`sheen`](Self::sheen),
/// [`clearcoat`](Self::clearcoat), [`iridescence`](Self::iridescence),
/// [`anisotropy`](Self::anisotropy), [`volume`](Self::volume)), and
/// KHR_materials_unlit sets [`unlit`](Self::unlit).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The name the file gives the material (`newmtl`, or glTF's `name`).
    pub name: String,
    /// Which reflectance model the fields describe.
    pub model: SurfaceModel,
    /// Diffuse reflectance (linear RGB), multiplied by the texture where there is one.
    pub base_color: Vec3,
    /// Multiplies `base_color` (and gives alpha), sampled at the hit's texture coordinates.
    pub base_color_texture: Option<TextureId>,
    /// Specular reflectance (linear RGB).
    pub specular: Vec3,
    /// Phong exponent of the specular lobe.
    pub shininess: f32,
    /// Microfacet roughness (perceptual, the square root of GGX's alpha).
    pub roughness: f32,
    /// Emitted radiance (linear RGB).
    pub emission: Vec3,
    /// Index of refraction.
    pub ior: f32,
    /// 1 is opaque, 0 fully transparent.
    pub opacity: f32,
    /// 0 for dielectrics, 1 for metals (glTF metallic-roughness).
    pub metallic: f32,
    /// Metallic in its blue channel, roughness in its green channel, multiplying the factors (linear).
    pub metallic_roughness_texture: Option<TextureId>,
    /// Emission multiplies this texture (sRGB) where there is one.
    pub emission_texture: Option<TextureId>,
    /// Tangent-space normal map (linear) and its scale.
    pub normal_texture: Option<(TextureId, f32)>,
    /// Fraction of light transmitted through the surface (KHR_materials_transmission).
    pub transmission: f32,
    /// Multiplies `transmission` by its red channel (linear).
    pub transmission_texture: Option<TextureId>,
    /// How the alpha of base colour and texture is used: ignored, a cutout mask, or blending.
    pub alpha_mode: AlphaMode,
    /// Multiplies alpha by its alpha channel, or by its red channel where it
    /// has none (an MTL `map_d` mask, often greyscale). Where it is the base
    /// colour texture and has alpha, that alpha is the base colour's, which
    /// counts once.
    pub alpha_texture: Option<TextureId>,
    /// Whether the back side is lit as the front (glTF); OBJ surfaces are two-sided.
    pub double_sided: bool,
    /// The camera sees the base colour as it is, unshaded, and the surface
    /// reflects no light (KHR_materials_unlit).
    pub unlit: bool,
    /// The strength and tint of a dielectric's specular reflection (KHR_materials_specular).
    pub dielectric_specular: DielectricSpecular,
    /// A fabric sheen over the base (KHR_materials_sheen).
    pub sheen: Option<Sheen>,
    /// A clear coat over everything else (KHR_materials_clearcoat).
    pub clearcoat: Option<Clearcoat>,
    /// Thin-film interference on the base's Fresnel reflection (KHR_materials_iridescence).
    pub iridescence: Option<Iridescence>,
    /// Stretched microfacets (KHR_materials_anisotropy).
    pub anisotropy: Option<Anisotropy>,
    /// The medium inside a transmitting mesh (KHR_materials_volume).
    pub volume: Option<Volume>,
    /// KHR_materials_dispersion's `dispersion` (20 / Abbe number); 0 is none.
    pub dispersion: f32,
}

/// The two ways the importers describe reflectance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceModel {
    /// MTL's sum of a diffuse lobe (`base_color`) and a specular lobe
    /// (`specular`, `roughness`); Fresnel effects are not modelled.
    DiffuseSpecular,
    /// glTF's metallic-roughness model (`base_color`, `metallic`, `roughness`),
    /// with Fresnel reflection; `transmission` and `ior` extend it.
    MetallicRoughness,
}

/// How a material's alpha (base colour alpha times `opacity`) is used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    Opaque,
    /// Surfaces with alpha below the cutoff are holes.
    Mask {
        /// Alpha below which a point is a hole, in `[0, 1]` (glTF's default 0.5).
        cutoff: f32,
    },
    /// Alpha blends the surface with what lies behind.
    Blend,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: String::from("default"),
            model: SurfaceModel::DiffuseSpecular,
            base_color: Vec3::splat(0.8),
            base_color_texture: None,
            specular: Vec3::ZERO,
            shininess: 0.0,
            roughness: 1.0,
            emission: Vec3::ZERO,
            ior: 1.5,
            opacity: 1.0,
            metallic: 0.0,
            metallic_roughness_texture: None,
            emission_texture: None,
            normal_texture: None,
            transmission: 0.0,
            transmission_texture: None,
            alpha_mode: AlphaMode::Opaque,
            alpha_texture: None,
            double_sided: true,
            unlit: false,
            dielectric_specular: DielectricSpecular::default(),
            sheen: None,
            clearcoat: None,
            iridescence: None,
            anisotropy: None,
            volume: None,
            dispersion: 0.0,
        }
    }
}

impl Material {
    /// Whether the surface emits light.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// Every texture the material refers to.
    pub fn textures(&self) -> Vec<TextureId> {
        // A copy, so that one list of the slots serves both directions.
        self.clone().texture_slots_mut().into_iter().map(|t| *t).collect()
    }

    fn texture_slots_mut(&mut self) -> Vec<&mut TextureId> {
        let mut slots: Vec<&mut Option<TextureId>> = vec![
            &mut self.base_color_texture,
            &mut self.metallic_roughness_texture,
            &mut self.emission_texture,
            &mut self.transmission_texture,
            &mut self.alpha_texture,
            &mut self.dielectric_specular.factor_texture,
            &mut self.dielectric_specular.color_texture,
        ];
        if let Some(sheen) = &mut self.sheen {
            slots.extend([&mut sheen.color_texture, &mut sheen.roughness_texture]);
        }
        let mut normal_maps: Vec<&mut Option<(TextureId, f32)>> = vec![&mut self.normal_texture];
        if let Some(coat) = &mut self.clearcoat {
            slots.extend([&mut coat.factor_texture, &mut coat.roughness_texture]);
            normal_maps.push(&mut coat.normal_texture);
        }
        if let Some(film) = &mut self.iridescence {
            slots.extend([&mut film.factor_texture, &mut film.thickness_texture]);
        }
        if let Some(anisotropy) = &mut self.anisotropy {
            slots.push(&mut anisotropy.texture);
        }
        if let Some(volume) = &mut self.volume {
            slots.push(&mut volume.thickness_texture);
        }
        let mut ids: Vec<&mut TextureId> = slots.into_iter().flatten().collect();
        ids.extend(normal_maps.into_iter().flatten().map(|(t, _)| t));
        ids
    }

    /// Shifts texture references when scenes are merged.
    pub(crate) fn offset_textures(&mut self, base: u32) {
        for t in self.texture_slots_mut() {
            t.0 += base;
        }
    }

    /// The roughness that matches a Phong exponent (Walter et al.,
    /// "Microfacet Models for Refraction through Rough Surfaces", 2007, eq. 33,
    /// with alpha = roughness²).
    pub fn roughness_from_shininess(shininess: f32) -> f32 {
        (2.0 / (shininess.max(0.0) + 2.0)).sqrt().sqrt()
    }
}
