//! glTF 2.0 import (`.gltf` with external or embedded buffers, and `.glb`).
//!
//! Buffers and images are read here rather than by the `gltf` crate's
//! importer, so that every URI is checked (relative to the scene file, no
//! network, no escaping its folder) and every accessor's byte range is
//! checked against its buffer before any data is read: a hostile file gives
//! an error, never a panic or a huge allocation.

use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};

use base64::Engine as _;
use rayon::prelude::*;
use rtgi_math::{Mat3, Mat4, Vec2, Vec3, Vec4};

use crate::{
    AlphaMode, Camera, ColorEncoding, Light, LightKind, Material, MeshBuilder, Scene, SceneError, SurfaceModel,
    Texture, TextureId, Wrap,
};

/// Extensions this importer understands; others are reported by `rtgi info`.
pub const SUPPORTED_GLTF_EXTENSIONS: &[&str] =
    &["KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"];

pub(crate) fn load(path: &Path) -> Result<Scene, SceneError> {
    let error = |message: String| SceneError::Gltf { path: path.to_owned(), message };
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
    let gltf = gltf::Gltf::from_slice(&bytes).map_err(|e| error(e.to_string()))?;
    let folder = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let buffers = load_buffers(&gltf, &folder).map_err(&error)?;
    validate_accessors(&gltf.document, &buffers).map_err(&error)?;

    let mut scene =
        Scene { extensions_used: gltf.document.extensions_used().map(str::to_owned).collect(), ..Scene::default() };
    let textures = TextureTable::new(&gltf.document, &folder, &buffers, &mut scene);
    for material in gltf.document.materials() {
        scene.materials.push(convert_material(&material, &textures));
    }
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material {
        name: "glTF default".into(),
        model: SurfaceModel::MetallicRoughness,
        base_color: Vec3::ONE,
        metallic: 1.0,
        roughness: 1.0,
        ..Material::default()
    });

    let Some(root) = gltf.document.default_scene().or_else(|| gltf.document.scenes().next()) else {
        scene.warnings.push(format!("{}: the file has no scene", path.display()));
        return Ok(scene);
    };
    let mut skipped_primitives: HashMap<String, usize> = HashMap::new();
    let mut stack: Vec<(gltf::Node<'_>, Mat4)> = root.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut visited = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > 1_000_000 {
            return Err(error("the node hierarchy is too large or cyclic".into()));
        }
        let transform = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            add_mesh(&mesh, &transform, &buffers, default_material, &mut scene, &mut skipped_primitives)
                .map_err(&error)?;
        }
        if let Some(camera) = node.camera() {
            match camera.projection() {
                gltf::camera::Projection::Perspective(p) => scene.cameras.push(Camera {
                    position: transform.transform_point3(Vec3::ZERO),
                    direction: transform.transform_vector3(-Vec3::Z).normalize_or(-Vec3::Z),
                    up: transform.transform_vector3(Vec3::Y).normalize_or(Vec3::Y),
                    vertical_fov: p.yfov(),
                    aspect: p.aspect_ratio(),
                }),
                gltf::camera::Projection::Orthographic(_) => {
                    scene.warnings.push(format!("{}: orthographic camera skipped", path.display()));
                }
            }
        }
        if let Some(light) = node.light() {
            scene.lights.push(convert_light(&light, &transform));
        }
        stack.extend(node.children().map(|child| (child, transform)));
    }
    // The default material exists for primitives that name none; drop it if none did.
    if !scene.triangles.iter().any(|t| t.material == default_material) {
        scene.materials.pop();
    }
    for (mode, count) in skipped_primitives {
        scene.warnings.push(format!(
            "{}: {count} primitives of mode {mode} skipped (only triangles are rendered)",
            path.display()
        ));
    }
    for extension in &scene.extensions_used {
        if !SUPPORTED_GLTF_EXTENSIONS.contains(&extension.as_str()) {
            scene.warnings.push(format!("{}: extension {extension} is not supported and is ignored", path.display()));
        }
    }
    Ok(scene)
}

/// The bytes of every buffer: the GLB binary chunk, a data URI, or a file
/// beside the scene.
fn load_buffers(gltf: &gltf::Gltf, folder: &Path) -> Result<Vec<Vec<u8>>, String> {
    gltf.document
        .buffers()
        .map(|buffer| {
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => gltf
                    .blob
                    .clone()
                    .ok_or_else(|| format!("buffer {} refers to a missing binary chunk", buffer.index()))?,
                gltf::buffer::Source::Uri(uri) => read_uri(uri, folder)?,
            };
            if data.len() < buffer.length() {
                return Err(format!(
                    "buffer {} has {} bytes but declares {}",
                    buffer.index(),
                    data.len(),
                    buffer.length()
                ));
            }
            Ok(data)
        })
        .collect()
}

/// Reads a URI of the file: a base64 data URI, or a relative path inside
/// the scene's folder. Remote URLs, absolute paths and paths that leave the
/// folder are refused.
fn read_uri(uri: &str, folder: &Path) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) =
            rest.split_once(";base64,").ok_or_else(|| format!("data URI without base64 payload: {}", short(uri)))?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("data URI is not valid base64 ({e})"));
    }
    let path = resolve_relative(uri, folder)?;
    std::fs::read(&path).map_err(|e| format!("{}: {e}", path.display()))
}

/// The file a relative URI names inside `folder`, after percent-decoding.
fn resolve_relative(uri: &str, folder: &Path) -> Result<PathBuf, String> {
    if uri.contains("://") || uri.starts_with("file:") {
        return Err(format!("refusing to fetch '{}': only files beside the scene are read", short(uri)));
    }
    let decoded = percent_decode(uri);
    let relative = Path::new(&decoded);
    if relative.has_root() || relative.components().any(|c| matches!(c, Component::Prefix(_))) {
        return Err(format!("refusing absolute path '{}'", short(uri)));
    }
    let mut depth = 0i32;
    for component in relative.components() {
        match component {
            Component::ParentDir => depth -= 1,
            Component::Normal(_) => depth += 1,
            _ => {}
        }
        if depth < 0 {
            return Err(format!("refusing '{}': it leaves the scene's folder", short(uri)));
        }
    }
    Ok(folder.join(relative))
}

fn percent_decode(text: &str) -> String {
    let bytes = text.as_bytes();
    let hex = |b: u8| (b as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(high), Some(low)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push(high * 16 + low);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A URI shortened for messages (data URIs can be megabytes long).
fn short(uri: &str) -> String {
    if uri.len() > 80 {
        format!("{}...", &uri[..uri.char_indices().nth(77).map_or(uri.len(), |(i, _)| i)])
    } else {
        uri.to_owned()
    }
}

/// Checks that every accessor's elements lie inside its buffer view and
/// every view inside its buffer, so that reading cannot go out of bounds.
fn validate_accessors(document: &gltf::Document, buffers: &[Vec<u8>]) -> Result<(), String> {
    for accessor in document.accessors() {
        if accessor.sparse().is_some() {
            return Err(format!("accessor {} is sparse, which is not supported", accessor.index()));
        }
        let Some(view) = accessor.view() else {
            return Err(format!("accessor {} has no buffer view", accessor.index()));
        };
        let buffer =
            buffers.get(view.buffer().index()).ok_or_else(|| format!("view {} has no buffer", view.index()))?;
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|end| end > buffer.len()) {
            return Err(format!("buffer view {} lies outside its buffer", view.index()));
        }
        let element = accessor.size();
        let stride = view.stride().unwrap_or(element);
        let needed = match accessor.count() {
            0 => Some(0),
            count => (count - 1)
                .checked_mul(stride)
                .and_then(|n| n.checked_add(element))
                .and_then(|n| n.checked_add(accessor.offset())),
        };
        if stride < element || needed.is_none_or(|n| n > view.length()) {
            return Err(format!(
                "accessor {} ({} elements of {element} bytes) does not fit in buffer view {} of {} bytes",
                accessor.index(),
                accessor.count(),
                view.index(),
                view.length()
            ));
        }
    }
    Ok(())
}

/// What distinguishes one decoded texture from another: the image, whether
/// it holds colour (sRGB) or data (linear), and the sampler's wrap modes.
type TextureKey = (usize, bool, Wrap, Wrap);

/// Decoded textures, one per [`TextureKey`] that materials use.
struct TextureTable {
    ids: HashMap<TextureKey, TextureId>,
}

fn texture_key(texture: &gltf::Texture<'_>, srgb: bool) -> TextureKey {
    use gltf::texture::WrappingMode;
    let wrap = |mode: WrappingMode| match mode {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let sampler = texture.sampler();
    (texture.source().index(), srgb, wrap(sampler.wrap_s()), wrap(sampler.wrap_t()))
}

impl TextureTable {
    fn new(document: &gltf::Document, folder: &Path, buffers: &[Vec<u8>], scene: &mut Scene) -> Self {
        // Which images are used as colour (sRGB) and which as data (linear).
        let mut wanted: Vec<TextureKey> = Vec::new();
        for m in document.materials() {
            let pbr = m.pbr_metallic_roughness();
            let mut want = |t: Option<gltf::Texture<'_>>, srgb: bool| {
                if let Some(t) = t {
                    let key = texture_key(&t, srgb);
                    if !wanted.contains(&key) {
                        wanted.push(key);
                    }
                }
            };
            want(pbr.base_color_texture().map(|i| i.texture()), true);
            want(m.emissive_texture().map(|i| i.texture()), true);
            want(pbr.metallic_roughness_texture().map(|i| i.texture()), false);
            want(m.normal_texture().map(|n| n.texture()), false);
            want(m.transmission().and_then(|t| t.transmission_texture()).map(|i| i.texture()), false);
        }
        let images: Vec<gltf::Image<'_>> = document.images().collect();
        let decoded: Vec<Result<Texture, String>> = wanted
            .par_iter()
            .map(|&(index, srgb, wrap_u, wrap_v)| {
                let image = &images[index];
                let encoding = if srgb { ColorEncoding::Srgb } else { ColorEncoding::Linear };
                let bytes = match image.source() {
                    gltf::image::Source::View { view, .. } => {
                        let buffer = &buffers[view.buffer().index()];
                        let end = view.offset() + view.length();
                        if end > buffer.len() {
                            return Err(format!("image {index} lies outside its buffer"));
                        }
                        buffer[view.offset()..end].to_vec()
                    }
                    gltf::image::Source::Uri { uri, .. } => {
                        read_uri(uri, folder).map_err(|e| format!("image {index}: {e}"))?
                    }
                };
                let name = image.name().map_or_else(|| format!("image {index}"), str::to_owned);
                Texture::decode(&bytes, &name, encoding).map(|t| t.with_wrap(wrap_u, wrap_v))
            })
            .collect();
        let mut ids = HashMap::new();
        for (key, texture) in wanted.into_iter().zip(decoded) {
            let texture = texture.unwrap_or_else(|message| {
                scene.warnings.push(message.clone());
                Texture::missing(message)
            });
            ids.insert(key, TextureId(scene.textures.len() as u32));
            scene.textures.push(texture);
        }
        Self { ids }
    }

    fn get(&self, texture: gltf::Texture<'_>, srgb: bool) -> Option<TextureId> {
        self.ids.get(&texture_key(&texture, srgb)).copied()
    }
}

fn convert_material(m: &gltf::Material<'_>, textures: &TextureTable) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
    Material {
        name: m.name().unwrap_or("unnamed").to_owned(),
        model: SurfaceModel::MetallicRoughness,
        base_color: Vec3::new(r, g, b),
        base_color_texture: pbr.base_color_texture().and_then(|i| textures.get(i.texture(), true)),
        specular: Vec3::ZERO,
        shininess: 0.0,
        roughness: pbr.roughness_factor(),
        emission,
        ior: m.ior().unwrap_or(1.5),
        opacity: a,
        metallic: pbr.metallic_factor(),
        metallic_roughness_texture: pbr.metallic_roughness_texture().and_then(|i| textures.get(i.texture(), false)),
        emission_texture: m.emissive_texture().and_then(|i| textures.get(i.texture(), true)),
        normal_texture: m.normal_texture().and_then(|n| textures.get(n.texture(), false).map(|t| (t, n.scale()))),
        transmission: m.transmission().map_or(0.0, |t| t.transmission_factor()),
        transmission_texture: m
            .transmission()
            .and_then(|t| t.transmission_texture())
            .and_then(|i| textures.get(i.texture(), false)),
        alpha_mode: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask { cutoff: m.alpha_cutoff().unwrap_or(0.5) },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided(),
    }
}

fn convert_light(light: &gltf::khr_lights_punctual::Light<'_>, transform: &Mat4) -> Light {
    use gltf::khr_lights_punctual::Kind;
    Light {
        name: light.name().unwrap_or("unnamed").to_owned(),
        kind: match light.kind() {
            Kind::Point => LightKind::Point,
            Kind::Directional => LightKind::Directional,
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                LightKind::Spot { inner_cone: inner_cone_angle, outer_cone: outer_cone_angle }
            }
        },
        position: transform.transform_point3(Vec3::ZERO),
        // Lights shine along their node's -Z.
        direction: transform.transform_vector3(-Vec3::Z).normalize_or(-Vec3::Z),
        color: Vec3::from(light.color()),
        intensity: light.intensity(),
        range: light.range(),
    }
}

/// Adds the triangles of one mesh instance, transformed to world space.
fn add_mesh(
    mesh: &gltf::Mesh<'_>,
    transform: &Mat4,
    buffers: &[Vec<u8>],
    default_material: u32,
    scene: &mut Scene,
    skipped: &mut HashMap<String, usize>,
) -> Result<(), String> {
    let normal_matrix = Mat3::from_mat4(*transform).inverse().transpose();
    // A mirroring transform turns counter-clockwise triangles clockwise.
    let flip = transform.determinant() < 0.0;
    for primitive in mesh.primitives() {
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            *skipped.entry(format!("{:?}", primitive.mode())).or_default() += 1;
            continue;
        }
        let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(Vec::as_slice));
        let Some(positions) = reader.read_positions() else {
            return Err(format!("mesh {} has a primitive without positions", mesh.index()));
        };
        let positions: Vec<Vec3> = positions.map(|p| transform.transform_point3(Vec3::from(p))).collect();
        let normals: Vec<Vec3> = reader
            .read_normals()
            .map(|n| n.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero()).collect())
            .unwrap_or_default();
        let tangents: Vec<Vec4> = reader
            .read_tangents()
            .map(|t| {
                t.map(|t| {
                    let direction = (Mat3::from_mat4(*transform) * Vec3::new(t[0], t[1], t[2])).normalize_or_zero();
                    // A mirroring transform also mirrors the bitangent.
                    direction.extend(if flip { -t[3] } else { t[3] })
                })
                .collect()
            })
            .unwrap_or_default();
        let uvs: Vec<Vec2> =
            reader.read_tex_coords(0).map(|t| t.into_f32().map(Vec2::from).collect()).unwrap_or_default();
        let indices: Vec<u32> = match reader.read_indices() {
            Some(indices) => indices.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(format!("mesh {} has index {bad} past its {} vertices", mesh.index(), positions.len()));
        }
        let has_normals = normals.len() == positions.len();
        let has_uvs = uvs.len() == positions.len();
        let material = primitive.material().index().map_or(default_material, |i| i as u32);
        // glTF asks for flat normals where a mesh has none.
        let tangents = if has_normals && tangents.len() == normals.len() { tangents } else { Vec::new() };
        let mut builder = MeshBuilder::new(positions, uvs, normals).with_flat_normals().with_tangents(tangents);
        for t in indices.chunks_exact(3) {
            let corners = if flip { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] };
            builder.push(corners, has_uvs.then_some(corners), has_normals.then_some(corners), material);
        }
        builder.finish_into(scene);
    }
    Ok(())
}
