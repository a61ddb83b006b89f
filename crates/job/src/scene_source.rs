//! Where a render's scene comes from: a file, or the Cornell box built
//! into the library so that a render works from any folder.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rtgi_scene::description::Description;
use rtgi_scene::{LoadOptions, Scene, SceneError};

/// The scene of a [`crate::RenderRequest`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SceneSource {
    /// The Cornell box as measured at Cornell University
    /// (`scenes/cornell-box.toml`), compiled in.
    BuiltIn,
    /// A scene file (.obj, .gltf, .glb or .toml), loaded with these options.
    File {
        /// The file.
        path: PathBuf,
        /// How it is loaded (references outside its folder, glTF variant).
        options: LoadOptions,
    },
}

impl SceneSource {
    /// `path`, loaded with the safe defaults.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        SceneSource::File { path: path.into(), options: LoadOptions::default() }
    }

    /// The file, if the scene comes from one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            SceneSource::BuiltIn => None,
            SceneSource::File { path, .. } => Some(path),
        }
    }

    /// The file's path, or the built-in scene's name, for messages.
    pub fn name(&self) -> String {
        match self {
            SceneSource::BuiltIn => BUILT_IN_NAME.to_owned(),
            SceneSource::File { path, .. } => path.display().to_string(),
        }
    }

    /// Loads the scene.
    pub fn load(&self) -> Result<LoadedScene, SceneError> {
        let start = Instant::now();
        let scene = match self {
            SceneSource::BuiltIn => built_in()?,
            SceneSource::File { path, options } => Scene::load_with(path, options)?,
        };
        Ok(LoadedScene { scene, name: self.name(), load_ms: start.elapsed().as_secs_f64() * 1e3 })
    }
}

/// A scene loaded, with its name and how long it took.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene; its `warnings` say what the loader passed over.
    pub scene: Scene,
    /// The file's path, or the built-in scene's name.
    pub name: String,
    /// Milliseconds the load took.
    pub load_ms: f64,
}

/// The built-in scene's name in messages and summaries.
pub const BUILT_IN_NAME: &str = "built-in Cornell box (scenes/cornell-box.toml)";

const DESCRIPTION: &str = include_str!("../../../scenes/cornell-box.toml");
const OBJ: &str = include_str!("../../../scenes/cornell-box/cornell-box.obj");
const MTL: &str = include_str!("../../../scenes/cornell-box/cornell-box.mtl");

/// The built-in Cornell box, with the camera its description gives.
pub fn built_in() -> Result<Scene, SceneError> {
    let description = Description::parse(DESCRIPTION, Path::new("scenes/cornell-box.toml"))?;
    let mut scene = rtgi_scene::obj::load_from_text(OBJ, MTL, "scenes/cornell-box/cornell-box.obj")?;
    scene.cameras.extend(description.camera());
    Ok(scene)
}
