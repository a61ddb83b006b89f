//! A small TOML scene description: the meshes to merge and a camera.
//!
//! ```toml
//! # Paths are relative to this file, and must lie inside its folder.
//! [[mesh]]
//! file = "cornell-box/cornell-box.obj"
//!
//! [camera]
//! position = [278.0, 273.0, -800.0]
//! look_at = [278.0, 273.0, 0.0]      # or: direction = [0.0, 0.0, 1.0]
//! up = [0.0, 1.0, 0.0]
//! vertical_fov_degrees = 39.3
//! aspect = 1.0                       # optional: width / height
//! ```

use std::path::{Path, PathBuf};

use rtgi_math::Vec3;
use serde::Deserialize;

use crate::files::{Files, MAX_NESTING};
use crate::{Camera, Scene, SceneError};

/// The parsed contents of a scene description file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Description {
    #[serde(default)]
    /// The meshes the scene merges, in order (`[[mesh]]` tables).
    pub mesh: Vec<MeshEntry>,
    /// The camera (`[camera]`); without one the scene has none.
    pub camera: Option<CameraEntry>,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
/// A `[[mesh]]` entry: one mesh file to load and merge.
pub struct MeshEntry {
    /// A mesh file, relative to the description.
    pub file: String,
}

#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
/// The `[camera]` entry, in world coordinates.
pub struct CameraEntry {
    /// The pinhole's position.
    pub position: [f32; 3],
    /// A point to look at; exactly one of `look_at` and `direction` is given.
    pub look_at: Option<[f32; 3]>,
    /// The viewing direction; exactly one of `look_at` and `direction` is given.
    pub direction: Option<[f32; 3]>,
    #[serde(default = "default_up")]
    /// Which way is up in the image [default: +Y].
    pub up: [f32; 3],
    /// The vertical field of view, in degrees.
    pub vertical_fov_degrees: f32,
    /// Width over height the camera was set up for, if the file says.
    pub aspect: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

impl Description {
    /// Parses description text; `path` is only used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Self, SceneError> {
        let error = |message: String| SceneError::Description { path: path.to_owned(), message };
        let description: Description = toml::from_str(text).map_err(|e| error(e.message().to_owned()))?;
        if let Some(c) = &description.camera {
            c.to_camera().map_err(error)?;
        }
        Ok(description)
    }

    /// The camera, if the description has one.
    pub fn camera(&self) -> Option<Camera> {
        self.camera.as_ref().and_then(|c| c.to_camera().ok())
    }
}

impl CameraEntry {
    fn to_camera(&self) -> Result<Camera, String> {
        let position = Vec3::from(self.position);
        let direction = match (self.look_at, self.direction) {
            (Some(target), None) => Vec3::from(target) - position,
            (None, Some(direction)) => Vec3::from(direction),
            _ => return Err("camera needs exactly one of 'look_at' and 'direction'".into()),
        };
        let camera = Camera {
            position,
            direction,
            up: Vec3::from(self.up),
            vertical_fov: self.vertical_fov_degrees.to_radians(),
            aspect: self.aspect,
        };
        if !camera.is_valid() || self.aspect.is_some_and(|a| !(a > 0.0 && a.is_finite())) {
            return Err("camera is degenerate (zero direction, direction parallel to up, \
                        field of view outside (0, 180) degrees, or a non-positive aspect)"
                .into());
        }
        Ok(camera)
    }
}

/// Loads a description and every mesh it lists, merged in the listed order.
/// Meshes are read through `files`, so they too must lie inside the folder
/// of the scene file that was opened; descriptions may include one another
/// to a depth of 8.
pub(crate) fn load(
    bytes: &[u8],
    path: &Path,
    files: &Files<'_>,
    sources: &mut Vec<PathBuf>,
) -> Result<Scene, SceneError> {
    let error = |message: String| SceneError::Description { path: path.to_owned(), message };
    let text = std::str::from_utf8(bytes).map_err(|e| error(format!("not UTF-8 text ({e})")))?;
    let description = Description::parse(text, path)?;
    let mut scene = Scene::default();
    for mesh in &description.mesh {
        if files.depth >= MAX_NESTING {
            return Err(error(format!("mesh '{}': descriptions nested more than {MAX_NESTING} deep", mesh.file)));
        }
        let file = files.read(&mesh.file).map_err(|why| error(format!("mesh {why}")))?;
        let nested = files.nested(&file);
        let mesh_path = file.path.clone();
        if !matches!(
            mesh_path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
            Some("obj" | "gltf" | "glb" | "toml")
        ) {
            return Err(SceneError::UnsupportedFormat { path: mesh_path });
        }
        sources.push(mesh_path.clone());
        let mut mesh_sources = Vec::new();
        let mesh_scene = Scene::load_read(&file.bytes, &mesh_path, &nested, &mut mesh_sources)?;
        sources.extend(mesh_sources);
        scene.append(mesh_scene);
    }
    scene.cameras.splice(0..0, description.camera());
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_from_look_at_or_direction() {
        let text = "[camera]\nposition = [0, 1, 2]\nlook_at = [0, 1, 0]\nvertical_fov_degrees = 90\n";
        let d = Description::parse(text, Path::new("a.toml")).unwrap();
        let c = d.camera().unwrap();
        assert_eq!(c.direction, Vec3::new(0.0, 0.0, -2.0));
        assert_eq!(c.up, Vec3::Y);
        assert!((c.vertical_fov - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn bad_descriptions_name_the_file() {
        let both = "[camera]\nposition=[0,0,0]\nlook_at=[1,0,0]\ndirection=[1,0,0]\nvertical_fov_degrees=40\n";
        for text in ["[[mesh]]\nfile = 3\n", "colour = 1\n", both, "[camera]\nposition=[0,0,0]\n"] {
            let err = Description::parse(text, Path::new("bad.toml")).unwrap_err();
            assert!(err.to_string().starts_with("bad.toml: "), "{err}");
        }
        let parallel = "[camera]\nposition=[0,0,0]\ndirection=[0,2,0]\nvertical_fov_degrees=40\n";
        assert!(Description::parse(parallel, Path::new("p.toml")).is_err());
    }
}
