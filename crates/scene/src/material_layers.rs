//! The parts of glTF's layered material ("PBR next") that its ratified
//! extensions add to the metallic-roughness base, each as the file gives
//! it: factors, and the textures that multiply them (the channel each
//! texture is read from is the extension's). Absent layers are `None`, so
//! a material without them costs nothing to shade.

use rtgi_math::Vec3;

use crate::TextureId;

/// KHR_materials_specular: the strength and colour of a dielectric's
/// specular reflection. The default (factor 1, white) is glTF's core model.
#[derive(Clone, Debug, PartialEq)]
pub struct DielectricSpecular {
    /// Scales the Fresnel reflectance at every angle (`specularFactor`).
    pub factor: f32,
    /// Multiplies `factor` by its alpha channel (linear).
    pub factor_texture: Option<TextureId>,
    /// Tints the reflectance at normal incidence (`specularColorFactor`, linear RGB).
    pub color: Vec3,
    /// Multiplies `color` by its RGB (sRGB).
    pub color_texture: Option<TextureId>,
}

impl Default for DielectricSpecular {
    fn default() -> Self {
        Self { factor: 1.0, factor_texture: None, color: Vec3::ONE, color_texture: None }
    }
}

/// KHR_materials_sheen: a fabric's retro-reflective sheen over the base.
#[derive(Clone, Debug, PartialEq)]
pub struct Sheen {
    /// `sheenColorFactor` (linear RGB); black means no sheen.
    pub color: Vec3,
    /// Multiplies `color` by its RGB (sRGB).
    pub color_texture: Option<TextureId>,
    /// `sheenRoughnessFactor`, perceptual.
    pub roughness: f32,
    /// Multiplies `roughness` by its alpha channel (linear).
    pub roughness_texture: Option<TextureId>,
}

/// KHR_materials_clearcoat: a clear dielectric coat (index 1.5) over the base.
#[derive(Clone, Debug, PartialEq)]
pub struct Clearcoat {
    /// `clearcoatFactor`: how much coat there is, 0 to 1.
    pub factor: f32,
    /// Multiplies `factor` by its red channel (linear).
    pub factor_texture: Option<TextureId>,
    /// `clearcoatRoughnessFactor`, perceptual.
    pub roughness: f32,
    /// Multiplies `roughness` by its green channel (linear).
    pub roughness_texture: Option<TextureId>,
    /// The coat's own tangent-space normal map and its scale; without one
    /// the coat follows the geometry's normal, not the base's normal map.
    pub normal_texture: Option<(TextureId, f32)>,
}

/// KHR_materials_iridescence: a thin film on the surface whose
/// interference colours the Fresnel reflection.
#[derive(Clone, Debug, PartialEq)]
pub struct Iridescence {
    /// `iridescenceFactor`, 0 to 1.
    pub factor: f32,
    /// Multiplies `factor` by its red channel (linear).
    pub factor_texture: Option<TextureId>,
    /// The film's index of refraction (`iridescenceIor`, default 1.3).
    pub ior: f32,
    /// The film's thickness in nanometres where the thickness texture is 0
    /// (`iridescenceThicknessMinimum`, default 100).
    pub thickness_min: f32,
    /// Where it is 1, or everywhere without a texture (`iridescenceThicknessMaximum`, default 400).
    pub thickness_max: f32,
    /// Interpolates between the thicknesses by its green channel (linear).
    pub thickness_texture: Option<TextureId>,
}

/// KHR_materials_anisotropy: microfacets stretched along a direction in the tangent plane.
#[derive(Clone, Debug, PartialEq)]
pub struct Anisotropy {
    /// `anisotropyStrength`, 0 (isotropic) to 1.
    pub strength: f32,
    /// `anisotropyRotation`: radians from the tangent towards the bitangent.
    pub rotation: f32,
    /// Red and green: a direction in tangent space (as a normal map stores
    /// it); blue: multiplies `strength` (linear).
    pub texture: Option<TextureId>,
}

/// KHR_materials_volume: the medium a transmitting mesh encloses.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// `thicknessFactor`, in the mesh's units; 0 makes the surface thin-walled.
    pub thickness: f32,
    /// Multiplies `thickness` by its green channel (linear).
    pub thickness_texture: Option<TextureId>,
    /// `attenuationDistance`: how far light travels in the medium before it
    /// is attenuated to `attenuation_color` (infinite: no attenuation).
    pub attenuation_distance: f32,
    /// `attenuationColor` (linear RGB).
    pub attenuation_color: Vec3,
}

impl Volume {
    /// The medium's absorption coefficient per unit length (Beer–Lambert:
    /// transmittance over a distance d is exp(−σ d)), from the colour light
    /// has after `attenuation_distance`: σ = −ln(colour) / distance.
    pub fn absorption(&self) -> Vec3 {
        if !self.attenuation_distance.is_finite() || self.attenuation_distance <= 0.0 {
            return Vec3::ZERO;
        }
        let color = self.attenuation_color.clamp(Vec3::splat(1e-6), Vec3::ONE);
        -Vec3::new(color.x.ln(), color.y.ln(), color.z.ln()) / self.attenuation_distance
    }
}
