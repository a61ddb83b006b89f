//! glTF 2.0 import (`.gltf` with external or embedded buffers, and `.glb`).
//!
//! Buffers and images are read here rather than by the `gltf` crate's
//! importer, so that every URI is checked (relative to the scene file, no
//! network, nothing outside its folder: see `files.rs`). Before any data
//! is read, the JSON is checked for everything the `gltf` crate assumes
//! (`validate_document`: indices in range, images with a source, accessor
//! types the readers accept), the node hierarchy for cycles, and every
//! accessor's byte range against its buffer: a hostile file gives an error,
//! never a panic or a huge allocation.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use rayon::prelude::*;
use rtgi_math::{Mat3, Mat4, Vec2, Vec3, Vec4};

use crate::files::Files;
use crate::{
    AlphaMode, Camera, ColorEncoding, Light, LightKind, Material, MeshBuilder, Scene, SceneError, SurfaceModel,
    Texture, TextureId, Wrap,
};

/// Extensions this importer understands; others are reported by `rtgi info`.
pub const SUPPORTED_GLTF_EXTENSIONS: &[&str] =
    &["KHR_lights_punctual", "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"];

pub(crate) fn load(
    bytes: &[u8],
    path: &Path,
    files: &Files<'_>,
    sources: &mut Vec<PathBuf>,
) -> Result<Scene, SceneError> {
    let error = |message: String| SceneError::Gltf { path: path.to_owned(), message };
    // The gltf crate's own validation indexes the POSITION accessor without
    // a bounds check, so the file is parsed unvalidated, checked for that
    // first, then validated, then checked for everything else the crate
    // would unwrap or reach `unreachable!()` on, before any accessor is read.
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| error(e.to_string()))?;
    validate_document(gltf.document.as_json()).map_err(&error)?;
    let buffers = load_buffers(&gltf, files, sources).map_err(&error)?;
    validate_accessors(&gltf.document, &buffers).map_err(&error)?;
    check_node_hierarchy(gltf.document.as_json()).map_err(&error)?;

    let mut scene = Scene {
        extensions_used: gltf.document.extensions_used().map(str::to_owned).collect(),
        // glTF 2.0, section 3.4 ("Coordinate System and Units"): +Y is up.
        up: Some(Vec3::Y),
        ..Scene::default()
    };
    let textures = TextureTable::new(&gltf.document, files, &buffers, &mut scene, sources);
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
    // A node is placed once, below the first parent that reaches it: the
    // specification gives each node at most one parent, and a file that
    // gives some several would otherwise instance them exponentially often.
    let mut placed = vec![false; gltf.document.nodes().len()];
    let mut reached_again = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut placed[node.index()], true) {
            reached_again.push(node.index());
            continue;
        }
        let transform = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            add_mesh(&mesh, &transform, &buffers, default_material, &mut scene, &mut skipped_primitives)
                .map_err(&error)?;
            if scene.triangles.len() > files.options.max_triangles {
                return Err(error(format!(
                    "more than {} triangles (the limit of LoadOptions::max_triangles)",
                    files.options.max_triangles
                )));
            }
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
    if let Some(first) = reached_again.first() {
        scene.warnings.push(format!(
            "{}: {} nodes have more than one parent (the first is node {first}); each is placed once, below its first parent",
            path.display(),
            reached_again.len()
        ));
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
/// inside the scene's folder.
fn load_buffers(gltf: &gltf::Gltf, files: &Files<'_>, sources: &mut Vec<PathBuf>) -> Result<Vec<Vec<u8>>, String> {
    gltf.document
        .buffers()
        .map(|buffer| {
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => gltf
                    .blob
                    .clone()
                    .ok_or_else(|| format!("buffer {} refers to a missing binary chunk", buffer.index()))?,
                gltf::buffer::Source::Uri(uri) => {
                    read_uri(uri, files, sources).map_err(|e| format!("buffer {}: {e}", buffer.index()))?
                }
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

/// Reads a URI of the file: a base64 data URI, or a relative path read
/// through `files` (inside the scene's folder unless allowed otherwise).
/// Remote URLs are refused.
fn read_uri(uri: &str, files: &Files<'_>, sources: &mut Vec<PathBuf>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, payload) =
            rest.split_once(";base64,").ok_or_else(|| format!("data URI without base64 payload: {}", short(uri)))?;
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("data URI is not valid base64 ({e})"));
    }
    if uri.contains("://") || uri.starts_with("file:") {
        return Err(format!("refusing to fetch '{}': only files beside the scene are read", short(uri)));
    }
    let file = files.read(&percent_decode(uri))?;
    sources.push(file.path);
    Ok(file.bytes)
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

/// Checks the JSON for what the `gltf` crate assumes without checking:
/// accessor indices of primitive attributes in range (its own validation
/// indexes with them), then its validation, then images with a source,
/// and accessors of the types the readers this importer calls accept.
fn validate_document(root: &gltf::json::Root) -> Result<(), String> {
    use gltf::json::accessor::{ComponentType, Type};
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::{Checked, Validate};
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let accessors = primitive.attributes.values().chain(&primitive.indices);
            if let Some(bad) = accessors.map(|a| a.value()).find(|&a| a >= root.accessors.len()) {
                return Err(format!(
                    "mesh {m} primitive {p} names accessor {bad}, but the file has {}",
                    root.accessors.len()
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| errors.push(format!("{}: {error}", path())));
    if !errors.is_empty() {
        let more = if errors.len() > 3 { format!(" (and {} more)", errors.len() - 3) } else { String::new() };
        return Err(format!("invalid glTF: {}{more}", errors[..errors.len().min(3)].join("; ")));
    }
    for (i, image) in root.images.iter().enumerate() {
        if image.buffer_view.is_none() && image.uri.is_none() {
            return Err(format!("image {i} has neither a uri nor a bufferView"));
        }
        if image.buffer_view.is_some() && image.mime_type.is_none() {
            return Err(format!("image {i} is in a bufferView but has no mimeType"));
        }
    }
    let accessor_kind = |index: usize| {
        let accessor = &root.accessors[index];
        match (&accessor.type_, &accessor.component_type) {
            (Checked::Valid(t), Checked::Valid(c)) => Some((*t, c.0)),
            _ => None,
        }
    };
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let what = |name: &str, index: usize| {
                format!("mesh {m} primitive {p}: {name} accessor {index} has a type its reader cannot read")
            };
            if let Some(indices) = &primitive.indices {
                let ok = matches!(
                    accessor_kind(indices.value()),
                    Some((Type::Scalar, ComponentType::U8 | ComponentType::U16 | ComponentType::U32))
                );
                if !ok {
                    return Err(what("index", indices.value()));
                }
            }
            for (semantic, accessor) in &primitive.attributes {
                let kind = accessor_kind(accessor.value());
                let ok = match semantic {
                    Checked::Valid(Semantic::Positions | Semantic::Normals) => {
                        kind == Some((Type::Vec3, ComponentType::F32))
                    }
                    Checked::Valid(Semantic::Tangents) => kind == Some((Type::Vec4, ComponentType::F32)),
                    Checked::Valid(Semantic::TexCoords(_)) => {
                        matches!(kind, Some((Type::Vec2, ComponentType::F32 | ComponentType::U8 | ComponentType::U16)))
                    }
                    _ => true,
                };
                if !ok {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "an invalid".to_owned(),
                    };
                    return Err(what(&name, accessor.value()));
                }
            }
        }
    }
    Ok(())
}

/// Refuses a node hierarchy with a cycle, naming a node on it: a
/// depth-first search over every node's children, iterative so that deep
/// hierarchies cannot overflow the stack.
fn check_node_hierarchy(root: &gltf::json::Root) -> Result<(), String> {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        New,
        OnPath,
        Done,
    }
    let children = |n: usize| root.nodes[n].children.as_deref().unwrap_or(&[]);
    let mut state = vec![State::New; root.nodes.len()];
    for start in 0..root.nodes.len() {
        if state[start] != State::New {
            continue;
        }
        // (node, how many of its children have been entered)
        let mut path: Vec<(usize, usize)> = vec![(start, 0)];
        state[start] = State::OnPath;
        while let Some((node, next)) = path.last_mut() {
            let node = *node;
            let Some(child) = children(node).get(*next).map(|c| c.value()) else {
                state[node] = State::Done;
                path.pop();
                continue;
            };
            *next += 1;
            match state[child] {
                State::OnPath => {
                    let name = root.nodes[child].name.as_deref().map_or(String::new(), |n| format!(" ('{n}')"));
                    return Err(format!(
                        "the node hierarchy has a cycle: node {child}{name} is its own descendant (through node {node})"
                    ));
                }
                State::New => {
                    state[child] = State::OnPath;
                    path.push((child, 0));
                }
                State::Done => {}
            }
        }
    }
    Ok(())
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
    fn new(
        document: &gltf::Document,
        files: &Files<'_>,
        buffers: &[Vec<u8>],
        scene: &mut Scene,
        sources: &mut Vec<PathBuf>,
    ) -> Self {
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
        // Files are read in order (for `sources`), then decoded in parallel.
        let mut read: HashMap<usize, Result<Vec<u8>, String>> = HashMap::new();
        for &(index, ..) in &wanted {
            read.entry(index).or_insert_with(|| match images[index].source() {
                gltf::image::Source::View { view, .. } => {
                    let buffer = &buffers[view.buffer().index()];
                    match view.offset().checked_add(view.length()) {
                        Some(end) if end <= buffer.len() => Ok(buffer[view.offset()..end].to_vec()),
                        _ => Err(format!("image {index} lies outside its buffer")),
                    }
                }
                gltf::image::Source::Uri { uri, .. } => {
                    read_uri(uri, files, sources).map_err(|e| format!("image {index}: {e}"))
                }
            });
        }
        let decoded: Vec<Result<Texture, String>> = wanted
            .par_iter()
            .map(|&(index, srgb, wrap_u, wrap_v)| {
                let encoding = if srgb { ColorEncoding::Srgb } else { ColorEncoding::Linear };
                let bytes = read[&index].as_ref().map_err(Clone::clone)?;
                // The image's name where it has one, and where its pixels are,
                // for `rtgi info` and messages.
                let source = match images[index].source() {
                    gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => "a data URI".to_owned(),
                    gltf::image::Source::Uri { uri, .. } => format!("'{uri}'"),
                    gltf::image::Source::View { view, .. } => format!("buffer view {}", view.index()),
                };
                let name = match images[index].name() {
                    Some(name) => format!("image {index} '{name}' from {source}"),
                    None => format!("image {index} from {source}"),
                };
                Texture::decode(bytes, &name, encoding).map(|t| t.with_wrap(wrap_u, wrap_v))
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
        alpha_texture: None,
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
