//! What a scene contains, as data: its triangles, vertices, materials and
//! their layers, textures, lights, cameras, bounds, glTF extensions (and
//! how each is rendered), variants, the loader's warnings, and the plan of
//! effects a render with given lighting and camera would simulate (what
//! `rtgi info` prints).

use std::collections::HashSet;

use rtgi_accel::AccelKind;
use rtgi_render::recipe::{self, CameraChoice, Lighting};
use rtgi_render::{EffectPlan, RenderSettings};
use rtgi_scene::{AlphaMode, LightKind, gltf_extension_support};
use serde::Serialize;

use crate::JobError;
use crate::scene_source::LoadedScene;

/// What a scene contains.
#[derive(Clone, Debug, Serialize)]
pub struct SceneDescription {
    /// The scene's file, or the built-in scene's name.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Vertices (corners with their normals and texture coordinates).
    pub vertices: usize,
    /// Distinct vertex positions: fewer than `vertices` where corners at one
    /// position were split because their normals or texture coordinates differ.
    pub positions: usize,
    /// Every material, with the triangles that use it.
    pub materials: Vec<MaterialInfo>,
    /// Every texture.
    pub textures: Vec<TextureInfo>,
    /// Every light the scene brings.
    pub lights: Vec<LightInfo>,
    /// Every camera the scene brings.
    pub cameras: Vec<CameraInfo>,
    /// The smallest and largest corner of the scene's box (`None` for an empty scene).
    pub bounds: Option<[[f32; 3]; 2]>,
    /// The glTF extensions the file uses.
    pub extensions_used: Vec<String>,
    /// Of those, the extensions rtgi does not render.
    pub extensions_unsupported: Vec<String>,
    /// Each extension the file uses, with how rtgi renders it.
    pub extensions: Vec<ExtensionInfo>,
    /// The file's material variants (KHR_materials_variants).
    pub material_variants: Vec<String>,
    /// What the loader passed over.
    pub warnings: Vec<String>,
    /// What a render with the given lighting and camera would simulate, and why.
    pub plan: EffectPlan,
}

/// A material, as the renderer sees it.
#[derive(Clone, Debug, Serialize)]
pub struct MaterialInfo {
    /// Its name in the file.
    pub name: String,
    /// Triangles.
    pub triangles: usize,
    /// Base colour (linear RGB).
    pub base_color: [f32; 3],
    /// Whether a texture multiplies the base colour.
    pub textured: bool,
    /// Metalness, 0 to 1.
    pub metallic: f32,
    /// Perceptual roughness, 0 to 1.
    pub roughness: f32,
    /// Emitted radiance (linear RGB).
    pub emission: [f32; 3],
    /// Share of light transmitted through the surface.
    pub transmission: f32,
    /// Index of refraction.
    pub ior: f32,
    /// How light gets through it: opaque, cut-out, blend, transmission.
    pub alpha: String,
    /// What glTF's material extensions add: unlit, specular, sheen, clearcoat, ...
    pub layers: Vec<String>,
}

/// A glTF extension the file uses, and how rtgi renders it.
#[derive(Clone, Debug, Serialize)]
pub struct ExtensionInfo {
    /// Its name in the file.
    pub name: String,
    /// simulated, approximated, not visual or unsupported.
    pub support: &'static str,
    /// How it is approximated, or what the image lacks without it.
    pub detail: &'static str,
}

/// A texture.
#[derive(Clone, Debug, Serialize)]
pub struct TextureInfo {
    /// Its name in the file.
    pub name: String,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// A light of the scene.
#[derive(Clone, Debug, Serialize)]
pub struct LightInfo {
    /// Its name in the file.
    pub name: String,
    /// Point, directional or spot (with its cones).
    pub kind: String,
    /// Position.
    pub position: [f32; 3],
    /// Direction.
    pub direction: [f32; 3],
    /// Colour (linear RGB).
    pub color: [f32; 3],
    /// Intensity (candela for point and spot lights, lux for directional ones).
    pub intensity: f32,
}

/// A camera of the scene.
#[derive(Clone, Debug, Serialize)]
pub struct CameraInfo {
    /// Position.
    pub position: [f32; 3],
    /// Direction.
    pub direction: [f32; 3],
    /// Up direction.
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub vertical_fov_degrees: f32,
    /// Width over height, if the camera fixes it.
    pub aspect: Option<f32>,
}

/// Describes `loaded`, with the plan of a render that adds `lighting` and
/// looks through `camera` (the lights a render adds for its view count).
pub fn describe(
    loaded: &LoadedScene,
    lighting: &Lighting,
    camera: &CameraChoice,
) -> Result<SceneDescription, JobError> {
    let (mut scene, name) = (loaded.scene.clone(), &loaded.name);
    let mut settings = RenderSettings::default();
    recipe::apply_lighting(lighting, &mut scene, &mut settings)?;
    let mut per_material = vec![0usize; scene.materials.len()];
    for t in &scene.triangles {
        per_material[t.material as usize] += 1;
    }
    let bounds = scene.bounds();
    let info = SceneDescription {
        scene: name.clone(),
        triangles: scene.triangles.len(),
        vertices: scene.vertices.len(),
        positions: scene.vertices.iter().map(|v| v.position.to_array().map(f32::to_bits)).collect::<HashSet<_>>().len(),
        materials: scene
            .materials
            .iter()
            .zip(&per_material)
            .map(|(m, &triangles)| MaterialInfo {
                name: m.name.clone(),
                triangles,
                base_color: m.base_color.to_array(),
                textured: m.base_color_texture.is_some(),
                metallic: m.metallic,
                roughness: m.roughness,
                emission: m.emission.to_array(),
                transmission: m.transmission,
                ior: m.ior,
                alpha: see_through(m),
                layers: layers(m),
            })
            .collect(),
        textures: scene
            .textures
            .iter()
            .map(|t| TextureInfo { name: t.name.clone(), width: t.width(), height: t.height() })
            .collect(),
        lights: scene
            .lights
            .iter()
            .map(|l| LightInfo {
                name: l.name.clone(),
                kind: match l.kind {
                    LightKind::Point => "point".into(),
                    LightKind::Directional => "directional".into(),
                    LightKind::Spot { inner_cone, outer_cone } => {
                        format!("spot (cones {:.1}° / {:.1}°)", inner_cone.to_degrees(), outer_cone.to_degrees())
                    }
                },
                position: l.position.to_array(),
                direction: l.direction.to_array(),
                color: l.color.to_array(),
                intensity: l.intensity,
            })
            .collect(),
        cameras: scene
            .cameras
            .iter()
            .map(|c| CameraInfo {
                position: c.position.to_array(),
                direction: c.direction.to_array(),
                up: c.up.to_array(),
                vertical_fov_degrees: c.vertical_fov.to_degrees(),
                aspect: c.aspect,
            })
            .collect(),
        bounds: (!bounds.is_empty()).then(|| [bounds.min.to_array(), bounds.max.to_array()]),
        extensions_unsupported: scene
            .extensions_used
            .iter()
            .filter(|e| !gltf_extension_support(e).is_supported())
            .cloned()
            .collect(),
        extensions: scene
            .extensions_used
            .iter()
            .map(|name| {
                let support = gltf_extension_support(name);
                ExtensionInfo { name: name.clone(), support: support.label(), detail: support.detail() }
            })
            .collect(),
        material_variants: scene.material_variants.clone(),
        extensions_used: scene.extensions_used.clone(),
        warnings: scene.warnings.clone(),
        plan: EffectPlan::new(&scene, &settings),
    };
    // The plan of the render: the lights it adds for the view it takes
    // (a probe of the view, a lamp over an enclosed room) count, as `rtgi
    // render` prints them; the scene's own lights are listed above.
    let accel = AccelKind::Bvh8.build(&scene.triangle_positions(), &AccelKind::Bvh8.default_params());
    let mut info = info;
    recipe::prepare(&mut scene, accel.as_ref(), &mut settings, camera)?;
    info.plan = EffectPlan::new(&scene, &settings);
    Ok(info)
}

/// The layers glTF's material extensions give a material, each with its factors.
fn layers(m: &rtgi_scene::Material) -> Vec<String> {
    let v = |c: rtgi_math::Vec3| format!("({:.3}, {:.3}, {:.3})", c.x, c.y, c.z);
    let mut layers = Vec::new();
    if m.unlit {
        layers.push("unlit".to_owned());
    }
    let specular = &m.dielectric_specular;
    if *specular != rtgi_scene::DielectricSpecular::default() {
        layers.push(format!("specular {} colour {}", specular.factor, v(specular.color)));
    }
    if let Some(sheen) = &m.sheen {
        layers.push(format!("sheen {} roughness {}", v(sheen.color), sheen.roughness));
    }
    if let Some(coat) = &m.clearcoat {
        let normal = if coat.normal_texture.is_some() { " with its own normal map" } else { "" };
        layers.push(format!("clearcoat {} roughness {}{normal}", coat.factor, coat.roughness));
    }
    if let Some(film) = &m.iridescence {
        layers.push(format!(
            "iridescence {} (film index {}, {}-{} nm)",
            film.factor, film.ior, film.thickness_min, film.thickness_max
        ));
    }
    if let Some(anisotropy) = &m.anisotropy {
        layers.push(format!("anisotropy {} at {} rad", anisotropy.strength, anisotropy.rotation));
    }
    if let Some(volume) = &m.volume {
        layers.push(format!(
            "volume: thickness {}, attenuation {} over {}",
            volume.thickness,
            v(volume.attenuation_color),
            volume.attenuation_distance
        ));
    }
    if m.dispersion > 0.0 {
        layers.push(format!("dispersion {} (approximated: no colour fringes)", m.dispersion));
    }
    layers
}

/// How light gets through a material, as the renderer treats it: cut-out
/// holes (alpha mask), partial coverage (alpha blend), transmission
/// through the surface (glass, thin sheets), or none.
fn see_through(m: &rtgi_scene::Material) -> String {
    let mut parts = Vec::new();
    let mask = if m.alpha_texture.is_some() { ", from a mask texture" } else { "" };
    match m.alpha_mode {
        AlphaMode::Opaque => {}
        AlphaMode::Mask { cutoff } => parts.push(format!("cut-out (alpha mask, cutoff {cutoff}{mask})")),
        AlphaMode::Blend => parts.push(format!("alpha blend (opacity {}{mask})", m.opacity)),
    }
    if m.transmission > 0.0 || m.transmission_texture.is_some() {
        let texture = if m.transmission_texture.is_some() { " x texture" } else { "" };
        parts.push(format!("transmits {}{texture} (ior {})", m.transmission, m.ior));
    }
    if parts.is_empty() { "opaque".into() } else { parts.join(", ") }
}

/// The text `rtgi info` prints before the plan.
impl std::fmt::Display for SceneDescription {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = |a: [f32; 3]| format!("({}, {}, {})", a[0], a[1], a[2]);
        writeln!(f, "scene       {}", self.scene)?;
        writeln!(f, "triangles   {}", self.triangles)?;
        if self.positions < self.vertices {
            writeln!(
                f,
                "vertices    {} ({} distinct positions: corners at one position are split where their normals or \
             texture coordinates differ)",
                self.vertices, self.positions
            )?;
        } else {
            writeln!(f, "vertices    {}", self.vertices)?;
        }
        if let Some([min, max]) = self.bounds {
            writeln!(f, "bounds      {} to {}", v(min), v(max))?;
        }
        writeln!(f, "materials   {}", self.materials.len())?;
        for m in &self.materials {
            writeln!(
                f,
                "  {:<24} {:>8} triangles, base colour {}{}, metallic {}, roughness {:.3}, emission {}, {}",
                m.name,
                m.triangles,
                v(m.base_color),
                if m.textured { " x texture" } else { "" },
                m.metallic,
                m.roughness,
                v(m.emission),
                m.alpha
            )?;
            if !m.layers.is_empty() {
                writeln!(f, "  {:<24} {}", "", m.layers.join("; "))?;
            }
        }
        writeln!(f, "textures    {}", self.textures.len())?;
        for (index, t) in self.textures.iter().enumerate() {
            writeln!(f, "  [{index}] {} ({}x{})", t.name, t.width, t.height)?;
        }
        writeln!(f, "lights      {}", self.lights.len())?;
        for l in &self.lights {
            writeln!(
                f,
                "  {:<24} {} at {}, colour {}, intensity {}",
                l.name,
                l.kind,
                v(l.position),
                v(l.color),
                l.intensity
            )?;
        }
        writeln!(f, "cameras     {}", self.cameras.len())?;
        for (index, c) in self.cameras.iter().enumerate() {
            writeln!(
                f,
                "  [{index}] at {} looking {}, up {}, vertical field of view {:.2}°{}",
                v(c.position),
                v(c.direction),
                v(c.up),
                c.vertical_fov_degrees,
                c.aspect.map_or(String::new(), |aspect| format!(", aspect {aspect}"))
            )?;
        }
        if !self.extensions.is_empty() {
            writeln!(f, "extensions  {}", self.extensions.len())?;
            for e in &self.extensions {
                let detail = if e.detail.is_empty() { String::new() } else { format!(": {}", e.detail) };
                writeln!(f, "  {:<36} {}{detail}", e.name, e.support)?;
            }
        }
        if !self.material_variants.is_empty() {
            writeln!(f, "variants    {}", self.material_variants.join(", "))?;
        }
        Ok(())
    }
}
