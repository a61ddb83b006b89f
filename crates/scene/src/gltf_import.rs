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
use crate::gltf_accessor::read_floats;
use crate::gltf_extensions::{ExtensionSupport, gltf_extension_support};
use crate::gltf_material::{TextureRequest, TextureRequests, convert_material};
use crate::{Camera, ColorEncoding, Light, LightKind, Material, MeshBuilder, Scene, SceneError, SurfaceModel, Texture};

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
    // A required extension rtgi lacks is named as such, before the `gltf`
    // crate's validation blames the file for it.
    for extension in &gltf.document.as_json().extensions_required {
        if let ExtensionSupport::Unsupported(lacks) = gltf_extension_support(extension) {
            return Err(SceneError::UnsupportedGltfExtension {
                path: path.to_owned(),
                extension: extension.clone(),
                lacks,
            });
        }
    }
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
    let mut textures = TextureRequests::default();
    for material in gltf.document.materials() {
        scene.materials.push(convert_material(&material, &gltf.document, &mut textures));
    }
    decode_textures(&textures, &gltf.document, files, &buffers, &mut scene, sources);
    for (set, count) in &textures.unsupported_sets {
        scene.warnings.push(format!(
            "{}: {count} texture references read texture coordinate set {set}; only sets 0 and 1 are kept, so they read set 1",
            path.display()
        ));
    }
    scene.material_variants = gltf.document.variants().into_iter().flatten().map(|v| v.name().to_owned()).collect();
    let variant = match files.options.gltf_variant.as_deref() {
        None => None,
        Some(name) => match scene.material_variants.iter().position(|v| v == name) {
            Some(index) => Some(index as u32),
            None => {
                return Err(SceneError::UnknownMaterialVariant {
                    path: path.to_owned(),
                    variant: name.to_owned(),
                    variants: scene.material_variants.clone(),
                });
            }
        },
    };
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
            let materials = MaterialChoice { default: default_material, variant };
            add_mesh(&mesh, &transform, &buffers, materials, &mut scene, &mut skipped_primitives).map_err(&error)?;
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
        if let ExtensionSupport::Unsupported(lacks) = gltf_extension_support(extension) {
            scene.warnings.push(format!(
                "{}: uses {extension}, which rtgi does not support, so the image lacks it: {lacks}",
                path.display()
            ));
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
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path();
        // The crate refuses required extensions it has no feature for;
        // those rtgi reads itself (from their JSON) are checked above.
        if path.as_str().starts_with("extensionsRequired") {
            return;
        }
        errors.push(format!("{path}: {error}"));
    });
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
                // Floats, or the integers KHR_mesh_quantization allows.
                let ok = match (semantic, kind) {
                    (_, None) => false,
                    (Checked::Valid(Semantic::Positions | Semantic::Normals), Some((t, c))) => {
                        t == Type::Vec3 && c != ComponentType::U32
                    }
                    (Checked::Valid(Semantic::Tangents), Some((t, c))) => t == Type::Vec4 && c != ComponentType::U32,
                    (Checked::Valid(Semantic::TexCoords(_)), Some((t, c))) => {
                        t == Type::Vec2 && c != ComponentType::U32
                    }
                    (Checked::Valid(Semantic::Colors(_)), Some((t, c))) => {
                        matches!(t, Type::Vec3 | Type::Vec4) && c != ComponentType::U32
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

/// Decodes the images the materials asked for, once per image and
/// encoding, in parallel, and adds one texture per request (requests that
/// differ only in wrap modes or coordinates share the decoded texels).
fn decode_textures(
    textures: &TextureRequests,
    document: &gltf::Document,
    files: &Files<'_>,
    buffers: &[Vec<u8>],
    scene: &mut Scene,
    sources: &mut Vec<PathBuf>,
) {
    debug_assert!(scene.textures.is_empty(), "texture ids are the requests' places");
    let images: Vec<gltf::Image<'_>> = document.images().collect();
    let mut decodings: Vec<(usize, bool)> = Vec::new();
    for request in &textures.requests {
        if !decodings.contains(&(request.image, request.srgb)) {
            decodings.push((request.image, request.srgb));
        }
    }
    // Files are read in order (for `sources`), then decoded in parallel.
    let mut read: HashMap<usize, Result<Vec<u8>, String>> = HashMap::new();
    for &(index, _) in &decodings {
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
    let decoded: Vec<Result<Texture, String>> = decodings
        .par_iter()
        .map(|&(index, srgb)| {
            let encoding = if srgb { ColorEncoding::Srgb } else { ColorEncoding::Linear };
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
            let bytes = read[&index].as_ref().map_err(Clone::clone)?;
            Texture::decode(bytes, &name, encoding)
        })
        .collect();
    let mut decoded: Vec<Option<Texture>> = decoded
        .into_iter()
        .map(|texture| {
            Some(texture.unwrap_or_else(|message| {
                scene.warnings.push(message.clone());
                Texture::missing(message)
            }))
        })
        .collect();
    let decoding_of = |request: &TextureRequest| {
        decodings.iter().position(|d| *d == (request.image, request.srgb)).expect("every request is decoded")
    };
    let mut uses_left = vec![0usize; decodings.len()];
    for request in &textures.requests {
        uses_left[decoding_of(request)] += 1;
    }
    for request in &textures.requests {
        let at = decoding_of(request);
        uses_left[at] -= 1;
        // The last use takes the texels; earlier ones copy them.
        let texture = if uses_left[at] == 0 { decoded[at].take() } else { decoded[at].clone() };
        let [wrap_u, wrap_v] = request.wrap;
        let texture = texture.expect("taken only by its last use");
        scene.textures.push(texture.with_wrap(wrap_u, wrap_v).with_uv_map(request.uv_map));
    }
}

/// Which material a primitive gets: its variant's where one is chosen and
/// maps it, else its own, else the default.
#[derive(Clone, Copy)]
struct MaterialChoice {
    default: u32,
    variant: Option<u32>,
}

impl MaterialChoice {
    fn of(&self, primitive: &gltf::Primitive<'_>) -> u32 {
        let mapped = self.variant.and_then(|variant| {
            primitive.mappings().find(|m| m.variants().contains(&variant)).and_then(|m| m.material().index())
        });
        mapped.or(primitive.material().index()).map_or(self.default, |i| i as u32)
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
    materials: MaterialChoice,
    scene: &mut Scene,
    skipped: &mut HashMap<String, usize>,
) -> Result<(), String> {
    use gltf::mesh::Semantic;
    let normal_matrix = Mat3::from_mat4(*transform).inverse().transpose();
    // A mirroring transform turns counter-clockwise triangles clockwise.
    let flip = transform.determinant() < 0.0;
    for primitive in mesh.primitives() {
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            *skipped.entry(format!("{:?}", primitive.mode())).or_default() += 1;
            continue;
        }
        // Attributes are read as floats whatever their type (KHR_mesh_quantization).
        let attribute = |semantic: Semantic| primitive.get(&semantic);
        let Some(positions) = attribute(Semantic::Positions) else {
            return Err(format!("mesh {} has a primitive without positions", mesh.index()));
        };
        let positions: Vec<Vec3> = read_floats(&positions, buffers, [0.0; 3])
            .into_iter()
            .map(|p| transform.transform_point3(Vec3::from(p)))
            .collect();
        let normals: Vec<Vec3> = attribute(Semantic::Normals)
            .map(|a| {
                let normals = read_floats(&a, buffers, [0.0; 3]);
                normals.into_iter().map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero()).collect()
            })
            .unwrap_or_default();
        let tangents: Vec<Vec4> = attribute(Semantic::Tangents)
            .map(|a| {
                let tangents = read_floats(&a, buffers, [0.0, 0.0, 0.0, 1.0]);
                tangents
                    .into_iter()
                    .map(|t| {
                        let direction = (Mat3::from_mat4(*transform) * Vec3::new(t[0], t[1], t[2])).normalize_or_zero();
                        // A mirroring transform also mirrors the bitangent.
                        direction.extend(if flip { -t[3] } else { t[3] })
                    })
                    .collect()
            })
            .unwrap_or_default();
        let texture_coords = |set: u32| -> Vec<Vec2> {
            attribute(Semantic::TexCoords(set))
                .map(|a| read_floats(&a, buffers, [0.0; 2]).into_iter().map(Vec2::from).collect())
                .filter(|uvs: &Vec<Vec2>| uvs.len() == positions.len())
                .unwrap_or_default()
        };
        let (uvs, second_uvs) = (texture_coords(0), texture_coords(1));
        let colors: Vec<Vec4> = attribute(Semantic::Colors(0))
            .map(|a| read_floats(&a, buffers, [1.0; 4]).into_iter().map(Vec4::from).collect())
            .filter(|colors: &Vec<Vec4>| colors.len() == positions.len())
            .unwrap_or_default();
        let reader = primitive.reader(|buffer| buffers.get(buffer.index()).map(Vec::as_slice));
        let indices: Vec<u32> = match reader.read_indices() {
            Some(indices) => indices.into_u32().collect(),
            None => (0..positions.len() as u32).collect(),
        };
        if let Some(bad) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(format!("mesh {} has index {bad} past its {} vertices", mesh.index(), positions.len()));
        }
        let has_normals = normals.len() == positions.len();
        let has_uvs = !uvs.is_empty();
        let material = materials.of(&primitive);
        // glTF asks for flat normals where a mesh has none.
        let tangents = if has_normals && tangents.len() == normals.len() { tangents } else { Vec::new() };
        let mut builder = MeshBuilder::new(positions, uvs, normals)
            .with_flat_normals()
            .with_tangents(tangents)
            .with_per_position(second_uvs, colors);
        for t in indices.chunks_exact(3) {
            let corners = if flip { [t[0], t[2], t[1]] } else { [t[0], t[1], t[2]] };
            builder.push(corners, has_uvs.then_some(corners), has_normals.then_some(corners), material);
        }
        builder.finish_into(scene);
    }
    Ok(())
}
