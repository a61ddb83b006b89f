//! Wavefront OBJ + MTL import, through `tobj`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use rtgi_math::{Vec2, Vec3};

use crate::{ColorEncoding, Material, MeshBuilder, Scene, SceneError, Texture, TextureId, resolve_case_insensitive};

const LOAD_OPTIONS: tobj::LoadOptions = tobj::LoadOptions {
    // Fan triangulation keeps file order: polygon (0 1 2 3) gives (0 1 2), (0 2 3).
    triangulate: true,
    single_index: false,
    ignore_points: true,
    ignore_lines: true,
};

/// Loads an OBJ file and the MTL files it names, relative to its folder.
pub(crate) fn load(path: &Path) -> Result<Scene, SceneError> {
    let file = std::fs::File::open(path).map_err(|source| SceneError::Io { path: path.to_owned(), source })?;
    let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut reader = std::io::BufReader::new(file);
    let mtl_errors = std::cell::RefCell::new(Vec::new());
    let (models, materials) = tobj::load_obj_buf(&mut reader, &LOAD_OPTIONS, |mtl_name| {
        let mtl_text = mtl_name.to_string_lossy();
        let Some(mtl_path) = resolve_case_insensitive(&folder, &mtl_text) else {
            mtl_errors.borrow_mut().push(format!("{}: material library '{mtl_text}' not found", path.display()));
            return Ok(Default::default());
        };
        let file = std::fs::File::open(&mtl_path).map_err(|_| tobj::LoadError::OpenFileFailed)?;
        tobj::load_mtl_buf(&mut std::io::BufReader::new(file)).inspect_err(|e| {
            mtl_errors.borrow_mut().push(format!("{}: cannot parse: {e}", mtl_path.display()));
        })
    })
    .map_err(|e| SceneError::Obj { path: path.to_owned(), message: e.to_string() })?;
    let materials = materials.unwrap_or_default();
    let mut scene = from_tobj(&models, &materials, &folder, path)?;
    scene.warnings.splice(0..0, mtl_errors.into_inner());
    Ok(scene)
}

/// Loads OBJ text whose MTL text is given too; for scenes built into programs.
pub fn load_from_text(obj: &str, mtl: &str, name: &str) -> Result<Scene, SceneError> {
    let path = PathBuf::from(name);
    let (models, materials) =
        tobj::load_obj_buf(&mut obj.as_bytes(), &LOAD_OPTIONS, |_| tobj::load_mtl_buf(&mut mtl.as_bytes()))
            .map_err(|e| SceneError::Obj { path: path.clone(), message: e.to_string() })?;
    let materials = materials.map_err(|e| SceneError::Obj { path: path.clone(), message: e.to_string() })?;
    from_tobj(&models, &materials, Path::new("."), &path)
}

fn from_tobj(
    models: &[tobj::Model],
    obj_materials: &[tobj::Material],
    folder: &Path,
    path: &Path,
) -> Result<Scene, SceneError> {
    let mut scene = Scene::default();
    let texture_paths = load_materials(&mut scene, obj_materials, folder, path);
    load_textures(&mut scene, texture_paths);

    // Faces without a material (none named, or a name the MTL does not
    // define) share one default material, added only if needed.
    let mut default_material: Option<u32> = None;
    for model in models {
        let mesh = &model.mesh;
        let material = match mesh.material_id {
            Some(id) if id < obj_materials.len() => id as u32,
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

/// Converts the MTL materials; returns the texture files to decode, by texture index.
fn load_materials(
    scene: &mut Scene,
    obj_materials: &[tobj::Material],
    folder: &Path,
    path: &Path,
) -> Vec<Result<PathBuf, String>> {
    let mut texture_index: HashMap<String, u32> = HashMap::new();
    let mut texture_paths = Vec::new();
    for m in obj_materials {
        let base_color_texture = m.diffuse_texture.as_deref().map(|name| {
            let id =
                *texture_index.entry(name.to_owned()).or_insert_with(|| {
                    texture_paths.push(find_texture(folder, name).ok_or_else(|| {
                        format!("{}: material '{}': texture '{name}' not found", path.display(), m.name)
                    }));
                    texture_paths.len() as u32 - 1
                });
            TextureId(id)
        });
        let shininess = m.shininess.unwrap_or(0.0);
        let defaults = Material::default();
        let illumination = m.illumination_model.unwrap_or(2);
        let mirror = matches!(illumination, 3 | 5);
        let refracts = matches!(illumination, 4 | 6 | 7 | 9);
        scene.materials.push(Material {
            name: m.name.clone(),
            base_color: m.diffuse.map_or(defaults.base_color, Vec3::from),
            base_color_texture,
            specular: m.specular.map_or(Vec3::ZERO, Vec3::from),
            shininess,
            roughness: if mirror { 0.0 } else { Material::roughness_from_shininess(shininess) },
            transmission: if refracts { 1.0 } else { 0.0 },
            emission: m.emissive.map_or(Vec3::ZERO, Vec3::from),
            ior: m.optical_density.filter(|n| *n > 0.0).unwrap_or(1.5),
            opacity: m.dissolve.unwrap_or(1.0).clamp(0.0, 1.0),
            ..defaults
        });
    }
    texture_paths
}

/// MTL map statements may carry options before the file name
/// (`map_Kd -bm 0.5 wall.jpg`); the name is then the last word.
fn find_texture(folder: &Path, statement: &str) -> Option<PathBuf> {
    resolve_case_insensitive(folder, statement.trim())
        .or_else(|| statement.split_whitespace().last().and_then(|name| resolve_case_insensitive(folder, name)))
}

/// Decodes the textures in parallel; those that fail become a visible
/// checkerboard and a warning.
fn load_textures(scene: &mut Scene, paths: Vec<Result<PathBuf, String>>) {
    let decoded: Vec<Result<Texture, String>> =
        paths.into_par_iter().map(|p| p.and_then(|path| Texture::load(&path, ColorEncoding::Srgb))).collect();
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
}
