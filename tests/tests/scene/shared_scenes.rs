//! The shared third-party scenes load with the triangle counts that
//! ../shared/scenes/INDEX.md gives, and their textures are found.

use rtgi_scene::Scene;
use rtgi_tests::shared_scene;

fn load(relative: &str) -> Option<Scene> {
    let path = shared_scene(relative)?;
    Some(Scene::load(&path).unwrap_or_else(|e| panic!("{e}")))
}

#[test]
fn obj_triangle_counts_match_the_index() {
    let expected = [
        ("bunny/stanford-bunny.obj", 69_451),
        ("dragon/dragon-100k.obj", 100_000),
        ("cornell-box/CornellBox-Original.obj", 36),
        ("cornell-box/CornellBox-Mirror.obj", 36),
        ("cornell-box/CornellBox-Empty-RG.obj", 12),
        ("sponza-dabrovic/sponza.obj", 66_450),
        ("conference/conference.obj", 331_179),
    ];
    for (file, triangles) in expected {
        let Some(scene) = load(file) else { continue };
        assert_eq!(scene.triangles.len(), triangles, "{file}");
        assert!(scene.vertices.iter().all(|v| (v.normal.length() - 1.0).abs() < 1e-4), "{file}: normals");
    }
}

#[test]
fn sponza_finds_textures_named_in_another_letter_case() {
    let Some(scene) = load("sponza-dabrovic/sponza.obj") else {
        return;
    };
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let textured = scene.materials.iter().filter(|m| m.base_color_texture.is_some()).count();
    assert!(textured >= 10, "only {textured} textured materials");
    // The MTL names 00_SKAP.JPG; the file on disk is 00_skap.JPG.
    assert!(scene.textures.iter().any(|t| t.name.ends_with("00_skap.JPG")));
}

#[test]
fn cornell_box_materials_come_from_the_mtl() {
    let Some(scene) = load("cornell-box/CornellBox-Original.obj") else {
        return;
    };
    let light = scene.materials.iter().find(|m| m.name == "light").expect("a light material");
    assert_eq!(light.emission.to_array(), [17.0, 12.0, 4.0]);
    let left = scene.materials.iter().find(|m| m.name == "leftWall").expect("leftWall");
    assert!(left.base_color.x > 0.5 && left.base_color.y < 0.1);
    let emissive = scene.triangles.iter().filter(|t| scene.materials[t.material as usize].is_emissive()).count();
    assert_eq!(emissive, 2);
}
