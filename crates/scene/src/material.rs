use rtgi_math::Vec3;

use crate::TextureId;

/// A surface's appearance.
///
/// OBJ/MTL fields map as follows: `Kd` → [`base_color`](Self::base_color),
/// `map_Kd` → [`base_color_texture`](Self::base_color_texture), `Ks` →
/// [`specular`](Self::specular), `Ns` → [`shininess`](Self::shininess) (the
/// Phong exponent, also turned into a microfacet
/// [`roughness`](Self::roughness) = (2 / (Ns + 2))^¼, Walter et al. 2007), `Ke`
/// → [`emission`](Self::emission), `Ni` → [`ior`](Self::ior), `d` →
/// [`opacity`](Self::opacity). Absent fields keep the defaults of
/// [`Material::default`].
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Diffuse reflectance (linear RGB), multiplied by the texture where there is one.
    pub base_color: Vec3,
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
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: String::from("default"),
            base_color: Vec3::splat(0.8),
            base_color_texture: None,
            specular: Vec3::ZERO,
            shininess: 0.0,
            roughness: 1.0,
            emission: Vec3::ZERO,
            ior: 1.5,
            opacity: 1.0,
        }
    }
}

impl Material {
    /// Whether the surface emits light.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// Shifts texture references when scenes are merged.
    pub(crate) fn offset_textures(&mut self, base: u32) {
        if let Some(t) = &mut self.base_color_texture {
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
