//! The fixed corpus of mutated scene files (`tests/corpus/`) that
//! `tests/tests/scene/loader_corpus.rs` loads, and the files its scenes may reference.
//! The fuzz targets (`fuzz/`) give the same answers to references.

use std::path::PathBuf;

/// The formats of the corpus, one folder each: the file extension of the
/// scene files (`mtl` files are loaded through [`MTL_HOST_OBJ`]).
pub const FORMATS: &[&str] = &["obj", "mtl", "gltf", "glb", "toml"];

/// The folder of the corpus.
pub fn corpus_dir() -> PathBuf {
    crate::workspace_root().join("tests").join("corpus")
}

mod referenced_files;
pub use referenced_files::*;

/// Loads one input of a format from memory, as the fuzz targets do.
pub fn load_input(format: &str, bytes: &[u8]) -> Result<rtgi_scene::Scene, rtgi_scene::SceneError> {
    use rtgi_scene::Scene;
    match format {
        "mtl" => Scene::load_from_bytes("host.obj", MTL_HOST_OBJ.as_bytes(), &|name| referenced(name, bytes)),
        _ => Scene::load_from_bytes(&format!("input.{format}"), bytes, &|name| {
            referenced(name, REFERENCED_MTL.as_bytes())
        }),
    }
}
