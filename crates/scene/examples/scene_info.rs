//! Loads a scene (OBJ, glTF, or a TOML description; the project's Cornell
//! box when no path is given) and prints what it holds.
//!
//! `cargo run -p rtgi-scene --example scene_info -- path/to/scene.obj`

use std::path::PathBuf;

use rtgi_scene::Scene;

fn main() {
    let path = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-box.toml")));
    let scene = match Scene::load(&path) {
        Ok(scene) => scene,
        Err(error) => {
            eprintln!("{error}");
            std::process::exit(1);
        }
    };
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    let bounds = scene.bounds();
    println!("{}", path.display());
    println!("  {} vertices, {} triangles", scene.vertices.len(), scene.triangles.len());
    println!("  bounds {} to {}", bounds.min, bounds.max);
    println!("  {} materials, {} textures", scene.materials.len(), scene.textures.len());
    for (i, material) in scene.materials.iter().enumerate() {
        let emits = if material.is_emissive() { ", emits light" } else { "" };
        println!("    {i}: {}{emits}", material.name);
    }
    println!("  {} cameras, {} lights", scene.cameras.len(), scene.lights.len());
}

#[test]
fn runs() {
    main();
}
