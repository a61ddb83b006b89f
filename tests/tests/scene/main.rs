//! Loading scenes: OBJ and MTL, glTF and GLB, TOML descriptions, the
//! loaders' corpus of hostile files, and the shared third-party scenes.
//!
//! One test binary for the theme, a module a file.

mod gltf;
mod gltf_extensions;
mod gltf_orientation;
mod gltf_references;
mod khronos_models;
mod loader_api;
mod loader_corpus;
mod loader_hardening;
mod loading_scale;
mod mtl_alpha;
mod shared_scenes;
