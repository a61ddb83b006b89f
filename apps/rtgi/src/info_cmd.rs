//! `rtgi info`: what a scene contains, as text or JSON.

use std::path::Path;

use anyhow::{Context, Result, bail};
use rtgi_accel::AccelKind;
use rtgi_image::HdrImage;
use rtgi_render::{EffectPlan, RenderSettings};
use rtgi_scene::{AlphaMode, LightKind, gltf_extension_support};
use serde::Serialize;

use crate::cli::{CompareArgs, InfoArgs};
use crate::common::{LoadedScene, apply_lighting, load_scene};
use crate::output::{out, outln};

#[derive(Debug, Serialize)]
struct Info {
    scene: String,
    triangles: usize,
    vertices: usize,
    /// Distinct vertex positions: fewer than `vertices` where corners at one
    /// position were split because their normals or texture coordinates differ.
    positions: usize,
    materials: Vec<MaterialInfo>,
    textures: Vec<TextureInfo>,
    lights: Vec<LightInfo>,
    cameras: Vec<CameraInfo>,
    bounds: Option<[[f32; 3]; 2]>,
    extensions_used: Vec<String>,
    extensions_unsupported: Vec<String>,
    /// Each extension the file uses, with how rtgi renders it.
    extensions: Vec<ExtensionInfo>,
    /// The file's material variants (KHR_materials_variants), which `--variant` chooses from.
    material_variants: Vec<String>,
    warnings: Vec<String>,
    /// What `rtgi render` with the given options would simulate, and why.
    plan: EffectPlan,
}

#[derive(Debug, Serialize)]
struct MaterialInfo {
    name: String,
    triangles: usize,
    base_color: [f32; 3],
    textured: bool,
    metallic: f32,
    roughness: f32,
    emission: [f32; 3],
    transmission: f32,
    ior: f32,
    alpha: String,
    /// What glTF's material extensions add: unlit, specular, sheen, clearcoat, ...
    layers: Vec<String>,
}

#[derive(Debug, Serialize)]
struct ExtensionInfo {
    name: String,
    /// simulated, approximated, not visual or unsupported.
    support: &'static str,
    /// How it is approximated, or what the image lacks without it.
    detail: &'static str,
}

#[derive(Debug, Serialize)]
struct TextureInfo {
    name: String,
    width: u32,
    height: u32,
}

#[derive(Debug, Serialize)]
struct LightInfo {
    name: String,
    kind: String,
    position: [f32; 3],
    direction: [f32; 3],
    color: [f32; 3],
    intensity: f32,
}

#[derive(Debug, Serialize)]
struct CameraInfo {
    position: [f32; 3],
    direction: [f32; 3],
    up: [f32; 3],
    vertical_fov_degrees: f32,
    aspect: Option<f32>,
}

pub(crate) fn run(args: &InfoArgs) -> Result<()> {
    let LoadedScene { mut scene, name, .. } = load_scene(args.scene.as_deref())?;
    let mut settings = RenderSettings::default();
    apply_lighting(&args.lighting, &mut scene, &mut settings)?;
    let mut per_material = vec![0usize; scene.materials.len()];
    for t in &scene.triangles {
        per_material[t.material as usize] += 1;
    }
    let bounds = scene.bounds();
    let info = Info {
        scene: name,
        triangles: scene.triangles.len(),
        vertices: scene.vertices.len(),
        positions: scene
            .vertices
            .iter()
            .map(|v| v.position.to_array().map(f32::to_bits))
            .collect::<std::collections::HashSet<_>>()
            .len(),
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
    rtgi_render::recipe::prepare(&mut scene, accel.as_ref(), &mut settings, &args.camera.choice())
        .map_err(|e| crate::phrasing::recipe_error(e, crate::phrasing::Phrasing::Options))?;
    info.plan = EffectPlan::new(&scene, &settings);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&info)?)?;
    } else {
        print_text(&info)?;
    }
    Ok(())
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

fn print_text(info: &Info) -> Result<()> {
    let v = |a: [f32; 3]| format!("({}, {}, {})", a[0], a[1], a[2]);
    outln!("scene       {}", info.scene)?;
    outln!("triangles   {}", info.triangles)?;
    if info.positions < info.vertices {
        outln!(
            "vertices    {} ({} distinct positions: corners at one position are split where their normals or \
             texture coordinates differ)",
            info.vertices,
            info.positions
        )?;
    } else {
        outln!("vertices    {}", info.vertices)?;
    }
    if let Some([min, max]) = info.bounds {
        outln!("bounds      {} to {}", v(min), v(max))?;
    }
    outln!("materials   {}", info.materials.len())?;
    for m in &info.materials {
        outln!(
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
            outln!("  {:<24} {}", "", m.layers.join("; "))?;
        }
    }
    outln!("textures    {}", info.textures.len())?;
    for (index, t) in info.textures.iter().enumerate() {
        outln!("  [{index}] {} ({}x{})", t.name, t.width, t.height)?;
    }
    outln!("lights      {}", info.lights.len())?;
    for l in &info.lights {
        outln!("  {:<24} {} at {}, colour {}, intensity {}", l.name, l.kind, v(l.position), v(l.color), l.intensity)?;
    }
    outln!("cameras     {}", info.cameras.len())?;
    for (index, c) in info.cameras.iter().enumerate() {
        outln!(
            "  [{index}] at {} looking {}, up {}, vertical field of view {:.2}°{}",
            v(c.position),
            v(c.direction),
            v(c.up),
            c.vertical_fov_degrees,
            c.aspect.map_or(String::new(), |aspect| format!(", aspect {aspect}"))
        )?;
    }
    if !info.extensions.is_empty() {
        outln!("extensions  {}", info.extensions.len())?;
        for e in &info.extensions {
            let detail = if e.detail.is_empty() { String::new() } else { format!(": {}", e.detail) };
            outln!("  {:<36} {}{detail}", e.name, e.support)?;
        }
    }
    if !info.material_variants.is_empty() {
        outln!("variants    {} (--variant NAME renders one)", info.material_variants.join(", "))?;
    }
    out!("{}", info.plan)
}

/// `rtgi compare`: prints the error of one EXR image against another.
pub(crate) fn compare(args: &CompareArgs) -> Result<()> {
    let image = read_exr(&args.image)?;
    let reference = read_exr(&args.reference)?;
    let Some(d) = rtgi_image::compare(&image, &reference) else {
        bail!(
            "{}: {}x{} pixels, but the reference {} has {}x{}",
            args.image.display(),
            image.width(),
            image.height(),
            args.reference.display(),
            reference.width(),
            reference.height()
        );
    };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&d)?)?;
    } else {
        outln!("rmse          {:.6}", d.rmse)?;
        outln!("relative mse  {:.6}", d.relative_mse)?;
        outln!("max abs       {:.6} at pixel ({}, {})", d.max_abs, d.max_at.0, d.max_at.1)?;
        outln!("mean          {:.6} (reference {:.6})", d.mean, d.reference_mean)?;
    }
    Ok(())
}

/// Reads an EXR image from a regular file. Anything else is refused first:
/// a FIFO would block until some other program writes to it, and a
/// directory or a device is no image.
fn read_exr(path: &Path) -> Result<HdrImage> {
    let metadata = std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
    if !metadata.is_file() {
        bail!("{}: cannot read: not a file", path.display());
    }
    Ok(HdrImage::read_exr(path)?)
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
