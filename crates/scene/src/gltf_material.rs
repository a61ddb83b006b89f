//! glTF materials: the metallic-roughness core and the ratified material
//! extensions, read through the `gltf` crate where it has them (specular,
//! volume, unlit, transmission, ior, emissive strength, texture transform)
//! and from the extension's JSON where it does not (clearcoat, sheen,
//! iridescence, anisotropy, dispersion, and the texture transform of a
//! normal map). Every texture reference becomes a request for the image
//! decoded as colour or data, with its sampler's wrap modes and the
//! texture coordinates it reads ([`UvMap`]); requests alike share one texture.

use std::collections::HashMap;

use rtgi_math::{Vec2, Vec3};
use serde_json::Value;

use crate::{
    AlphaMode, Anisotropy, Clearcoat, DielectricSpecular, Iridescence, Material, Sheen, SurfaceModel, TextureId, UvMap,
    Volume, Wrap,
};

/// One texture a material asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TextureRequest {
    /// Index of the glTF image.
    pub image: usize,
    /// Whether the image holds colour (sRGB) or data (linear).
    pub srgb: bool,
    pub wrap: [Wrap; 2],
    pub uv_map: UvMap,
}

/// The textures the materials ask for, in the order first asked; a
/// request's [`TextureId`] is its place here (the scene's textures are
/// these, in this order).
#[derive(Default)]
pub(crate) struct TextureRequests {
    pub requests: Vec<TextureRequest>,
    /// Texture coordinate sets beyond the two a vertex keeps, by how often they were asked for.
    pub unsupported_sets: HashMap<u32, usize>,
}

impl TextureRequests {
    fn request(
        &mut self,
        texture: &gltf::Texture<'_>,
        srgb: bool,
        set: u32,
        transform: Option<Transform>,
    ) -> TextureId {
        use gltf::texture::WrappingMode;
        let wrap = |mode: WrappingMode| match mode {
            WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            WrappingMode::Repeat => Wrap::Repeat,
        };
        let sampler = texture.sampler();
        let transform = transform.unwrap_or_default();
        // KHR_texture_transform's texCoord overrides the reference's own.
        let set = transform.set.unwrap_or(set);
        if set > 1 {
            *self.unsupported_sets.entry(set).or_default() += 1;
        }
        let uv_map =
            UvMap::from_offset_rotation_scale(set.min(1) as u8, transform.offset, transform.rotation, transform.scale);
        let request = TextureRequest {
            image: texture.source().index(),
            srgb,
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
            uv_map,
        };
        let index = match self.requests.iter().position(|r| *r == request) {
            Some(index) => index,
            None => {
                self.requests.push(request);
                self.requests.len() - 1
            }
        };
        TextureId(index as u32)
    }

    /// A reference the `gltf` crate has read (`textureInfo`).
    fn info(&mut self, info: Option<gltf::texture::Info<'_>>, srgb: bool) -> Option<TextureId> {
        let info = info?;
        let transform = info.texture_transform().map(|t| Transform {
            offset: Vec2::from(t.offset()),
            rotation: t.rotation(),
            scale: Vec2::from(t.scale()),
            set: t.tex_coord(),
        });
        Some(self.request(&info.texture(), srgb, info.tex_coord(), transform))
    }

    /// A reference in an extension's JSON: `{"index", "texCoord", "extensions": {"KHR_texture_transform"}}`.
    fn raw(&mut self, document: &gltf::Document, value: Option<&Value>, srgb: bool) -> Option<TextureId> {
        let value = value?;
        let texture = document.textures().nth(value.get("index")?.as_u64()? as usize)?;
        let set = value.get("texCoord").and_then(Value::as_u64).unwrap_or(0) as u32;
        let transform = value.get("extensions").and_then(|e| e.get("KHR_texture_transform")).map(Transform::from_json);
        Some(self.request(&texture, srgb, set, transform))
    }
}

/// KHR_texture_transform's values.
#[derive(Clone, Copy, Debug)]
struct Transform {
    offset: Vec2,
    rotation: f32,
    scale: Vec2,
    set: Option<u32>,
}

impl Default for Transform {
    fn default() -> Self {
        Self { offset: Vec2::ZERO, rotation: 0.0, scale: Vec2::ONE, set: None }
    }
}

impl Transform {
    fn from_json(value: &Value) -> Transform {
        let pair = |key: &str, default: Vec2| {
            value.get(key).and_then(Value::as_array).filter(|a| a.len() == 2).map_or(default, |a| {
                Vec2::new(
                    a[0].as_f64().unwrap_or(default.x as f64) as f32,
                    a[1].as_f64().unwrap_or(default.y as f64) as f32,
                )
            })
        };
        Transform {
            offset: pair("offset", Vec2::ZERO),
            rotation: value.get("rotation").and_then(Value::as_f64).unwrap_or(0.0) as f32,
            scale: pair("scale", Vec2::ONE),
            set: value.get("texCoord").and_then(Value::as_u64).map(|s| s as u32),
        }
    }
}

/// A number of an extension's JSON, or its default.
fn number(extension: &Value, key: &str, default: f32) -> f32 {
    extension.get(key).and_then(Value::as_f64).map_or(default, |v| v as f32)
}

fn color(extension: &Value, key: &str, default: Vec3) -> Vec3 {
    extension
        .get(key)
        .and_then(Value::as_array)
        .filter(|a| a.len() == 3)
        .map_or(default, |a| Vec3::from_array(std::array::from_fn(|i| a[i].as_f64().unwrap_or(0.0) as f32)))
}

pub(crate) fn convert_material(
    m: &gltf::Material<'_>,
    document: &gltf::Document,
    textures: &mut TextureRequests,
) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
    // Requested in the order of the core material's slots, so that textures are numbered as the material lists them.
    let base_color_texture = textures.info(pbr.base_color_texture(), true);
    let metallic_roughness_texture = textures.info(pbr.metallic_roughness_texture(), false);
    let normal_texture = m.normal_texture().map(|n| {
        let transform = n.extension_value("KHR_texture_transform").map(Transform::from_json);
        (textures.request(&n.texture(), false, n.tex_coord(), transform), n.scale())
    });
    let extension = |name: &str| m.extension_value(name);
    let dielectric_specular = m.specular().map_or_else(DielectricSpecular::default, |s| DielectricSpecular {
        factor: s.specular_factor(),
        factor_texture: textures.info(s.specular_texture(), false),
        color: Vec3::from(s.specular_color_factor()),
        color_texture: textures.info(s.specular_color_texture(), true),
    });
    let sheen = extension("KHR_materials_sheen").map(|e| Sheen {
        color: color(e, "sheenColorFactor", Vec3::ZERO),
        color_texture: textures.raw(document, e.get("sheenColorTexture"), true),
        roughness: number(e, "sheenRoughnessFactor", 0.0),
        roughness_texture: textures.raw(document, e.get("sheenRoughnessTexture"), false),
    });
    let clearcoat = extension("KHR_materials_clearcoat").map(|e| Clearcoat {
        factor: number(e, "clearcoatFactor", 0.0),
        factor_texture: textures.raw(document, e.get("clearcoatTexture"), false),
        roughness: number(e, "clearcoatRoughnessFactor", 0.0),
        roughness_texture: textures.raw(document, e.get("clearcoatRoughnessTexture"), false),
        normal_texture: e.get("clearcoatNormalTexture").and_then(|n| {
            let id = textures.raw(document, Some(n), false)?;
            Some((id, number(n, "scale", 1.0)))
        }),
    });
    let iridescence = extension("KHR_materials_iridescence").map(|e| Iridescence {
        factor: number(e, "iridescenceFactor", 0.0),
        factor_texture: textures.raw(document, e.get("iridescenceTexture"), false),
        ior: number(e, "iridescenceIor", 1.3),
        thickness_min: number(e, "iridescenceThicknessMinimum", 100.0),
        thickness_max: number(e, "iridescenceThicknessMaximum", 400.0),
        thickness_texture: textures.raw(document, e.get("iridescenceThicknessTexture"), false),
    });
    let anisotropy = extension("KHR_materials_anisotropy").map(|e| Anisotropy {
        strength: number(e, "anisotropyStrength", 0.0),
        rotation: number(e, "anisotropyRotation", 0.0),
        texture: textures.raw(document, e.get("anisotropyTexture"), false),
    });
    let volume = m.volume().map(|v| Volume {
        thickness: v.thickness_factor(),
        thickness_texture: textures.info(v.thickness_texture(), false),
        attenuation_distance: v.attenuation_distance(),
        attenuation_color: Vec3::from(v.attenuation_color()),
    });
    Material {
        name: m.name().unwrap_or("unnamed").to_owned(),
        model: SurfaceModel::MetallicRoughness,
        base_color: Vec3::new(r, g, b),
        base_color_texture,
        specular: Vec3::ZERO,
        shininess: 0.0,
        roughness: pbr.roughness_factor(),
        emission,
        ior: m.ior().unwrap_or(1.5),
        opacity: a,
        metallic: pbr.metallic_factor(),
        metallic_roughness_texture,
        emission_texture: textures.info(m.emissive_texture(), true),
        normal_texture,
        transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
        transmission_texture: textures.info(m.transmission().and_then(|t| t.transmission_texture()), false),
        alpha_mode: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask { cutoff: m.alpha_cutoff().unwrap_or(0.5) },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        alpha_texture: None,
        double_sided: m.double_sided(),
        unlit: m.unlit(),
        dielectric_specular,
        // A layer whose factor is zero is no layer (files often carry the
        // extension with its defaults).
        sheen: sheen.filter(|s| s.color.max_element() > 0.0),
        clearcoat: clearcoat.filter(|c| c.factor > 0.0),
        iridescence: iridescence.filter(|i| i.factor > 0.0),
        anisotropy: anisotropy.filter(|a| a.strength > 0.0 || a.texture.is_some()),
        volume: volume.filter(|v| v.thickness > 0.0),
        dispersion: extension("KHR_materials_dispersion").map_or(0.0, |e| number(e, "dispersion", 0.0)),
    }
}
