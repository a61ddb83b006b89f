//! Wavefront OBJ import through `tobj`, with MTL libraries read by our own
//! parser (`mtl.rs`) and every referenced file read through the scene's
//! files, which keeps reads inside the scene's folder (`files.rs`).

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use rtgi_math::{Vec2, Vec3};

use crate::files::{Files, ReadFile};
use crate::mtl::{self, MtlMaterial};
use crate::{AlphaMode, ColorEncoding, LoadOptions, Material, MeshBuilder, Scene, SceneError, Texture, TextureId};

const LOAD_OPTIONS: tobj::LoadOptions = tobj::LoadOptions {
    // Fan triangulation keeps file order: polygon (0 1 2 3) gives (0 1 2), (0 2 3).
    triangulate: true,
    single_index: false,
    ignore_points: true,
    ignore_lines: true,
};

/// The most vertices one OBJ face (or line, or point statement) may name:
/// tobj builds each polygon in memory before triangulating it, so a face of
/// 10^8 references would take gigabytes; no real model comes near.
pub const MAX_FACE_VERTICES: usize = 65_536;

/// Loads OBJ text whose MTL libraries and textures are read through `files`.
pub(crate) fn load(
    bytes: &[u8],
    path: &Path,
    files: &Files<'_>,
    sources: &mut Vec<PathBuf>,
) -> Result<Scene, SceneError> {
    let error = |message: String| SceneError::Obj { path: path.to_owned(), message };
    let statements = scan_statements(bytes).map_err(error)?;
    // tobj's loader is a `Fn`: what it collects goes through cells.
    let warnings = RefCell::new(Vec::new());
    let materials: RefCell<Vec<MtlMaterial>> = RefCell::new(Vec::new());
    let libraries_read: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let read_sources = RefCell::new(Vec::new());
    let loader = |mtl_name: &Path| -> tobj::MTLLoadResult {
        let reference = mtl_name.to_string_lossy().into_owned();
        // A library named again adds nothing: tobj keeps the names it mapped.
        if libraries_read.borrow().contains(&reference) {
            return Ok(Default::default());
        }
        libraries_read.borrow_mut().push(reference.clone());
        let file = match files.read(&reference) {
            Ok(file) => file,
            Err(why) => {
                warnings.borrow_mut().push(format!("{}: material library {why}", path.display()));
                return Ok(Default::default());
            }
        };
        let library = mtl::parse(&String::from_utf8_lossy(&file.bytes), &file.path.display().to_string());
        read_sources.borrow_mut().push(file.path);
        warnings.borrow_mut().extend(library.warnings);
        let names = mtl::index_by_name(&library.materials);
        let placeholders =
            library.materials.iter().map(|m| tobj::Material { name: m.name.clone(), ..Default::default() }).collect();
        materials.borrow_mut().extend(library.materials);
        Ok((placeholders, names.into_iter().collect()))
    };
    if let Some(why) = binary_content(bytes) {
        return Err(error(why));
    }
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &LOAD_OPTIONS, loader).map_err(|e| error(e.to_string()))?;
    // Checked after tobj's parse, whose errors name what is malformed.
    if statements.faces == 0 {
        let why = statements.unknown_note().map_or(String::new(), |note| format!("; {note}"));
        return Err(error(format!("no faces (f statements), so nothing to render{why}")));
    }
    sources.extend(read_sources.into_inner());
    let mut scene = from_tobj(&models, &materials.into_inner(), files, path, sources)?;
    scene.warnings.splice(0..0, warnings.into_inner());
    if let Some(note) = statements.unknown_note() {
        scene.warnings.insert(0, format!("{}: {note}, ignored", path.display()));
    }
    Ok(scene)
}

/// What a cheap scan of an OBJ file's statements found.
#[derive(Default)]
struct Statements {
    /// Face statements (`f`).
    faces: usize,
    /// The first statement that OBJ does not define, with its line number,
    /// and how many such lines there are.
    unknown: Option<(usize, String)>,
    unknown_lines: usize,
}

/// The statements OBJ defines (free-form geometry and display attributes
/// included, which are read as nothing).
const OBJ_STATEMENTS: &[&[u8]] = &[
    b"v",
    b"vt",
    b"vn",
    b"vp",
    b"f",
    b"fo",
    b"l",
    b"p",
    b"o",
    b"g",
    b"s",
    b"mg",
    b"mtllib",
    b"usemtl",
    b"usemap",
    b"maplib",
    b"cstype",
    b"deg",
    b"bmat",
    b"step",
    b"curv",
    b"curv2",
    b"surf",
    b"parm",
    b"trim",
    b"hole",
    b"scrv",
    b"sp",
    b"end",
    b"con",
    b"lod",
    b"shadow_obj",
    b"trace_obj",
    b"ctech",
    b"stech",
    b"bevel",
    b"c_interp",
    b"d_interp",
    b"call",
    b"csh",
];

/// Scans the statements' first words: refuses faces with more than
/// [`MAX_FACE_VERTICES`] vertices before tobj allocates them, and counts
/// faces and lines OBJ does not define, for the messages about them.
fn scan_statements(bytes: &[u8]) -> Result<Statements, String> {
    let mut found = Statements::default();
    for (number, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let mut words = line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty());
        let Some(first) = words.next() else { continue };
        if first.starts_with(b"#") {
            continue;
        }
        if !OBJ_STATEMENTS.contains(&first) {
            found.unknown_lines += 1;
            if found.unknown.is_none() {
                let shown: String = String::from_utf8_lossy(first).chars().take(40).collect();
                found.unknown = Some((number + 1, shown));
            }
            continue;
        }
        if first == b"f" {
            found.faces += 1;
        }
        if !matches!(first, b"f" | b"l" | b"p") {
            continue;
        }
        let count = words.count();
        if count > MAX_FACE_VERTICES {
            return Err(format!(
                "line {}: a face with {count} vertices (at most {MAX_FACE_VERTICES} are read)",
                number + 1
            ));
        }
    }
    Ok(found)
}

impl Statements {
    /// A note on the lines OBJ does not define, as a message's tail.
    fn unknown_note(&self) -> Option<String> {
        let (line, word) = self.unknown.as_ref()?;
        let more = match self.unknown_lines {
            1 => String::new(),
            n => format!(" ({} more such lines)", n - 1),
        };
        Some(format!("line {line}: '{word}' is not an OBJ statement{more}"))
    }
}

/// Loads OBJ text whose MTL text is given too; for scenes built into programs.
/// Every `mtllib` statement reads `mtl`; textures are not read.
pub fn load_from_text(obj: &str, mtl: &str, name: &str) -> Result<Scene, SceneError> {
    let read = |reference: &str| {
        Path::new(reference).extension().is_some_and(|e| e.eq_ignore_ascii_case("mtl")).then(|| mtl.as_bytes().to_vec())
    };
    let files = Files::memory(&read, &LoadOptions::default());
    load(obj.as_bytes(), Path::new(name), &files, &mut Vec::new())
}

fn from_tobj(
    models: &[tobj::Model],
    mtl_materials: &[MtlMaterial],
    files: &Files<'_>,
    path: &Path,
    sources: &mut Vec<PathBuf>,
) -> Result<Scene, SceneError> {
    let mut scene = Scene::default();
    let texture_files = load_materials(&mut scene, mtl_materials, files, path, sources);
    load_textures(&mut scene, texture_files);

    // Faces without a material (none named, or a name the MTL does not
    // define) share one default material, added only if needed.
    let mut default_material: Option<u32> = None;
    for model in models {
        let mesh = &model.mesh;
        let material = match mesh.material_id {
            Some(id) if id < mtl_materials.len() => id as u32,
            _ => *default_material.get_or_insert_with(|| {
                scene.materials.push(Material::default());
                scene.materials.len() as u32 - 1
            }),
        };
        let positions: Vec<Vec3> = mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        // OBJ puts v = 0 at the bottom of the image; the scene model at the top.
        let uvs: Vec<Vec2> = mesh.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])).collect();
        let normals: Vec<Vec3> = mesh.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2])).collect();
        let triangle_count = mesh.indices.len() / 3;
        let has_uvs = mesh.texcoord_indices.len() == mesh.indices.len() && !uvs.is_empty();
        let has_normals = mesh.normal_indices.len() == mesh.indices.len() && !normals.is_empty();
        let in_range = |indices: &[u32], len: usize| indices.iter().all(|&i| (i as usize) < len);
        if !in_range(&mesh.indices, positions.len())
            || (has_uvs && !in_range(&mesh.texcoord_indices, uvs.len()))
            || (has_normals && !in_range(&mesh.normal_indices, normals.len()))
        {
            return Err(SceneError::Obj {
                path: path.to_owned(),
                message: format!("object '{}' has a face index out of range", model.name),
            });
        }
        let mut builder = MeshBuilder::new(positions, uvs, normals);
        let corner = |indices: &[u32], t: usize| [indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]];
        for t in 0..triangle_count {
            builder.push(
                corner(&mesh.indices, t),
                has_uvs.then(|| corner(&mesh.texcoord_indices, t)),
                has_normals.then(|| corner(&mesh.normal_indices, t)),
                material,
            );
        }
        builder.finish_into(&mut scene);
    }
    Ok(scene)
}

/// Converts the MTL materials; returns each texture's file, read, by texture
/// index (or why it could not be read).
fn load_materials(
    scene: &mut Scene,
    mtl_materials: &[MtlMaterial],
    files: &Files<'_>,
    path: &Path,
    sources: &mut Vec<PathBuf>,
) -> Vec<Result<ReadFile, String>> {
    let mut texture_index: HashMap<String, u32> = HashMap::new();
    let mut texture_files = Vec::new();
    for m in mtl_materials {
        let mut texture = |name: &str| {
            let id = *texture_index.entry(name.to_owned()).or_insert_with(|| {
                let file =
                    files.read(name).map_err(|why| format!("{}: material '{}': texture {why}", path.display(), m.name));
                if let Ok(file) = &file {
                    sources.push(file.path.clone());
                }
                texture_files.push(file);
                texture_files.len() as u32 - 1
            });
            TextureId(id)
        };
        let base_color_texture = m.diffuse_texture.as_deref().map(&mut texture);
        let alpha_texture = m.dissolve_texture.as_deref().map(&mut texture);
        let shininess = m.shininess.unwrap_or(0.0);
        let defaults = Material::default();
        let illumination = m.illumination_model.unwrap_or(2);
        let mirror = matches!(illumination, 3 | 5);
        let refracts = matches!(illumination, 4 | 6 | 7 | 9);
        scene.materials.push(Material {
            name: m.name.clone(),
            base_color: m.diffuse.unwrap_or(defaults.base_color),
            base_color_texture,
            specular: m.specular.unwrap_or(Vec3::ZERO),
            shininess,
            roughness: if mirror { 0.0 } else { Material::roughness_from_shininess(shininess) },
            transmission: if refracts { 1.0 } else { 0.0 },
            emission: m.emissive.unwrap_or(Vec3::ZERO),
            ior: m.optical_density.filter(|n| *n > 0.0).unwrap_or(1.5),
            opacity: m.dissolve.unwrap_or(1.0).clamp(0.0, 1.0),
            // A map_d mask cuts holes (leaves, fences); a constant d below 1
            // lets light through in proportion (stochastic transparency).
            alpha_mode: if alpha_texture.is_some() {
                AlphaMode::Mask { cutoff: 0.5 }
            } else if m.dissolve.is_some_and(|d| d < 1.0) {
                AlphaMode::Blend
            } else {
                AlphaMode::Opaque
            },
            alpha_texture,
            ..defaults
        });
    }
    texture_files
}

/// Decodes the textures in parallel; those that fail become a visible
/// checkerboard and a warning.
fn load_textures(scene: &mut Scene, files: Vec<Result<ReadFile, String>>) {
    let decoded: Vec<Result<Texture, String>> = files
        .into_par_iter()
        .map(|f| f.and_then(|file| Texture::decode(&file.bytes, &file.path.display().to_string(), ColorEncoding::Srgb)))
        .collect();
    for texture in decoded {
        match texture {
            Ok(t) => scene.textures.push(t),
            Err(message) => {
                scene.textures.push(Texture::missing(message.clone()));
                scene.warnings.push(message);
            }
        }
    }
}

/// Why `bytes` cannot be an OBJ file's text, if they are binary: a NUL
/// byte or invalid UTF-8 in the first 64 KiB (tobj would only say "read
/// error"), with what the file looks like when its first bytes say.
fn binary_content(bytes: &[u8]) -> Option<String> {
    let head = &bytes[..bytes.len().min(1 << 16)];
    let at = match std::str::from_utf8(head) {
        // A character cut at the end of the window is no error.
        Err(e) if e.error_len().is_some() => e.valid_up_to(),
        _ => head.iter().position(|&b| b == 0)?,
    };
    let looks_like = if bytes.starts_with(b"ply") {
        "; it begins like a PLY file, which rtgi does not read (convert it to .obj)"
    } else if bytes.starts_with(b"glTF") {
        "; it begins like a binary glTF file: name it .glb"
    } else {
        ""
    };
    Some(format!("binary data at byte {at}, where an OBJ file is text{looks_like}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD_MTL: &str = "newmtl red\nKd 0.8 0.1 0.1\nKe 1 2 3\nNs 10\nNi 1.33\nd 0.5\nKs 0.2 0.2 0.2\n";

    #[test]
    fn quads_become_fans_in_file_order() {
        let obj = "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nusemtl red\nf 1 2 3 4\nf 1 2 5\n";
        let scene = load_from_text(obj, QUAD_MTL, "q.obj").unwrap();
        assert_eq!(scene.triangles.len(), 3);
        let corners: Vec<[Vec3; 3]> = scene.triangle_positions();
        assert_eq!(corners[0], [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)]);
        assert_eq!(corners[1], [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]);
        assert_eq!(corners[2], [Vec3::ZERO, Vec3::X, Vec3::Z]);
        let m = &scene.materials[scene.triangles[0].material as usize];
        assert_eq!(m.name, "red");
        assert_eq!(m.base_color, Vec3::new(0.8, 0.1, 0.1));
        assert_eq!(m.emission, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!((m.shininess, m.ior, m.opacity), (10.0, 1.33, 0.5));
        assert_eq!(m.specular, Vec3::splat(0.2));
    }

    #[test]
    fn missing_normals_are_computed_from_winding() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let scene = load_from_text(obj, "", "t.obj").unwrap();
        assert!(scene.vertices.iter().all(|v| v.normal == Vec3::Z));
        // Faces without a material get the default one.
        assert_eq!(scene.materials.len(), 1);
    }

    #[test]
    fn given_normals_and_flipped_uvs_are_kept() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 0.25\nvn 0 0 2\nf 1/1/1 2/2/1 3/3/1\n";
        let scene = load_from_text(obj, "", "t.obj").unwrap();
        let uvs: Vec<Vec2> = scene.vertices.iter().map(|v| v.uv).collect();
        assert_eq!(uvs, vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 0.75)]);
        assert!(scene.vertices.iter().all(|v| v.normal == Vec3::Z));
    }

    #[test]
    fn malformed_input_is_an_error_naming_the_file() {
        let err = load_from_text("v 0 0 zero\n", "", "bad.obj").unwrap_err();
        assert!(err.to_string().starts_with("bad.obj: "), "{err}");
        let err = load_from_text("v 0 0 0\nf 1 2 3\n", "", "range.obj").unwrap_err();
        assert!(err.to_string().starts_with("range.obj: "), "{err}");
    }

    #[test]
    fn a_binary_file_named_obj_is_an_error_saying_what_it_seems_to_be() {
        let ply = b"ply\nformat binary_little_endian 1.0\nend_header\n\x00\x01\xff\xfe";
        let err = load_from_bytes_for_test(ply, "igea.obj");
        assert!(err.starts_with("igea.obj: not a valid OBJ file: binary data at byte "), "{err}");
        assert!(err.contains("PLY"), "{err}");
        let err = load_from_bytes_for_test(b"v 0 0 0\n\x00", "nul.obj");
        assert!(err.contains("binary data at byte 8"), "{err}");
    }

    fn load_from_bytes_for_test(bytes: &[u8], name: &str) -> String {
        crate::Scene::load_from_bytes(name, bytes, &|_| None).unwrap_err().to_string()
    }

    #[test]
    fn a_file_without_faces_is_an_error_naming_what_it_holds() {
        let err = load_from_text("x\n", "", "x.obj").unwrap_err().to_string();
        assert_eq!(
            err,
            "x.obj: not a valid OBJ file: no faces (f statements), so nothing to render; line 1: 'x' is not an OBJ statement"
        );
        let err = load_from_text("# points only\nv 0 0 0\np 1\n", "", "points.obj").unwrap_err().to_string();
        assert_eq!(err, "points.obj: not a valid OBJ file: no faces (f statements), so nothing to render");
    }

    #[test]
    fn lines_obj_does_not_define_are_a_warning_naming_the_first() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvertex 1 2 3\nf 1 2 3\nface 1 2 3\n";
        let scene = load_from_text(obj, "", "t.obj").unwrap();
        assert_eq!(scene.triangles.len(), 1);
        assert_eq!(scene.warnings, ["t.obj: line 4: 'vertex' is not an OBJ statement (1 more such lines), ignored"]);
        // Free-form statements and comments are OBJ's own: no warning.
        let scene = load_from_text("cstype bspline\nv 0 0 0\nv 1 0 0\nv 0 1 0\n#x\nf 1 2 3\n", "", "t.obj").unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }
}
