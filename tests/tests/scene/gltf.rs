//! glTF import: the shared sample models load with the counts of
//! ../shared/scenes/INDEX.md, cameras and lights carry the values of their
//! JSON, and malformed or hostile files give errors that name the file.

use rtgi_math::Vec3;
use rtgi_scene::{LightKind, Scene, SceneError};
use rtgi_tests::{scratch_dir, shared_scene};

#[test]
fn sample_models_load_with_their_triangle_counts() {
    let expected = [
        ("gltf/Box/glTF/Box.gltf", 12),
        ("gltf/Box/glTF-Binary/Box.glb", 12),
        ("gltf/BoxTextured/glTF/BoxTextured.gltf", 12),
        ("gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12),
        ("gltf/DamagedHelmet/glTF/DamagedHelmet.gltf", 15_452),
        ("gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", 6_000),
        ("gltf/TransmissionTest/glTF/TransmissionTest.gltf", 128_775),
        ("gltf/TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb", 77_792),
        ("gltf/AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf", 61),
        ("gltf/Cameras/glTF/Cameras.gltf", 2),
    ];
    for (file, triangles) in expected {
        let Some(path) = shared_scene(file) else { continue };
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.triangles.len(), triangles, "{file}");
        // glTF fixes +Y as up (section 3.4 of the specification): nothing to guess.
        assert_eq!(scene.up, Some(Vec3::Y), "{file}");
        // Every texture a material names was found and decoded.
        assert!(scene.warnings.iter().all(|w| !w.contains("image")), "{file}: {:?}", scene.warnings);
    }
}

#[test]
fn cameras_gltf_has_its_perspective_camera() {
    let Some(path) = shared_scene("gltf/Cameras/glTF/Cameras.gltf") else { return };
    let scene = Scene::load(&path).unwrap();
    // Camera 0: perspective, yfov 0.7, aspect 1, at node translation (0.5, 0.5, 3),
    // looking along -Z. Camera 1 is orthographic and skipped with a warning.
    assert_eq!(scene.cameras.len(), 1);
    let camera = scene.cameras[0];
    assert_eq!(camera.position, Vec3::new(0.5, 0.5, 3.0));
    assert_eq!(camera.vertical_fov, 0.7);
    assert_eq!(camera.aspect, Some(1.0));
    assert!((camera.direction - -Vec3::Z).length() < 1e-6);
    assert!((camera.up - Vec3::Y).length() < 1e-6);
    assert!(scene.warnings.iter().any(|w| w.contains("orthographic")));
}

#[test]
fn lights_punctual_lamp_has_its_five_lights() {
    let Some(path) = shared_scene("gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf") else { return };
    let scene = Scene::load(&path).unwrap();
    assert_eq!(scene.lights.len(), 5);
    // Every primitive names its material: no unused default is added.
    assert!(scene.materials.iter().all(|m| m.name != "glTF default"));
    let by_name = |name: &str| scene.lights.iter().find(|l| l.name == name).unwrap_or_else(|| panic!("{name}"));
    // Values from the file's KHR_lights_punctual block.
    let point = by_name("Point");
    assert_eq!(point.kind, LightKind::Point);
    assert_eq!(point.intensity, 15.0);
    assert_eq!(point.color, Vec3::new(1.0, 0.631_875, 0.239_099_76));
    assert_eq!(by_name("Point.002").color, Vec3::ONE);
    assert_eq!(by_name("Point.002").intensity, 1.5);
    assert_eq!(by_name("Point.001").intensity, 80.0);
    assert_eq!(by_name("Point.003").intensity, 80.0);
    assert_eq!(by_name("Point.004").intensity, 180.0);
    // Placed by their nodes: all distinct positions, near the lamp.
    for light in &scene.lights {
        assert!(light.position.length() < 5.0 && light.position != Vec3::ZERO, "{light:?}");
    }
}

/// A minimal glTF with one triangle whose buffer is given as `uri` and
/// whose position accessor has `count` elements.
fn triangle_gltf(uri: &str, count: u32) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "buffers":[{{"uri":"{uri}","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3","max":[1,1,0],"min":[0,0,0]}}]}}"#
    )
}

fn triangle_bytes() -> Vec<u8> {
    [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|f| f.to_le_bytes()).collect()
}

fn load_text(name: &str, text: &str) -> Result<Scene, SceneError> {
    let dir = scratch_dir(&format!("gltf-{name}"));
    std::fs::write(dir.join("tri.bin"), triangle_bytes()).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, text).unwrap();
    Scene::load(&path)
}

#[test]
fn embedded_and_external_buffers_load() {
    use base64::Engine as _;
    let data = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(triangle_bytes())
    );
    for (name, uri) in [("embedded", data.as_str()), ("external", "tri.bin"), ("escaped", "tr%69.bin")] {
        let scene = load_text(name, &triangle_gltf(uri, 3)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.triangles.len(), 1, "{name}");
        assert_eq!(scene.vertices[0].normal, Vec3::Z, "{name}: flat normal computed");
    }
}

#[test]
fn hostile_files_are_refused_with_the_file_named() {
    let cases = [
        ("notjson", "{ this is not json".to_owned(), "notjson.gltf"),
        ("overrun", triangle_gltf("tri.bin", 1_000_000), "does not fit"),
        ("remote", triangle_gltf("https://example.com/tri.bin", 3), "refusing to fetch"),
        ("escape", triangle_gltf("../../etc/passwd", 3), "leaves the scene's folder"),
        ("absolute", triangle_gltf("/etc/passwd", 3), "absolute"),
        ("missing", triangle_gltf("nothere.bin", 3), "nothere.bin"),
    ];
    for (name, text, expected) in cases {
        let error = load_text(name, &text).err().unwrap_or_else(|| panic!("{name} loaded"));
        let message = error.to_string();
        assert!(message.contains(&format!("{name}.gltf")), "{name}: {message}");
        assert!(message.contains(expected), "{name}: {message}");
    }
}

#[test]
fn normal_mapped_models_get_unit_tangents_perpendicular_to_their_normals() {
    let Some(path) = shared_scene("gltf/DamagedHelmet/glTF/DamagedHelmet.gltf") else { return };
    let scene = Scene::load(&path).unwrap();
    assert!(scene.materials.iter().any(|m| m.normal_texture.is_some()));
    for v in &scene.vertices {
        let t = v.tangent.truncate();
        assert!((t.length() - 1.0).abs() < 1e-3, "{v:?}");
        assert!(t.dot(v.normal).abs() < 1e-3, "{v:?}");
        assert!(v.tangent.w == 1.0 || v.tangent.w == -1.0, "{v:?}");
    }
}

#[test]
fn spot_and_directional_lights_are_placed_by_their_nodes() {
    // A spot light moved to (1, 2, 3) and turned to shine along -Y (a -90°
    // rotation about X takes the light's -Z to -Y), and a directional light.
    let text = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],
        "extensionsUsed":["KHR_lights_punctual"],
        "extensions":{"KHR_lights_punctual":{"lights":[
            {"type":"spot","name":"spot","intensity":20,"color":[1,0.5,0.25],"range":7,
             "spot":{"innerConeAngle":0.2,"outerConeAngle":0.4}},
            {"type":"directional","name":"sun","intensity":3}]}},
        "nodes":[
            {"translation":[1,2,3],"rotation":[-0.70710678,0,0,0.70710678],"extensions":{"KHR_lights_punctual":{"light":0}}},
            {"extensions":{"KHR_lights_punctual":{"light":1}}}]}"#;
    let scene = load_text("lights", text).unwrap();
    let spot = scene.lights.iter().find(|l| l.name == "spot").unwrap();
    assert_eq!(spot.kind, LightKind::Spot { inner_cone: 0.2, outer_cone: 0.4 });
    assert_eq!(spot.position, Vec3::new(1.0, 2.0, 3.0));
    assert!((spot.direction - -Vec3::Y).length() < 1e-5, "{}", spot.direction);
    assert_eq!((spot.intensity, spot.range, spot.color), (20.0, Some(7.0), Vec3::new(1.0, 0.5, 0.25)));
    let sun = scene.lights.iter().find(|l| l.name == "sun").unwrap();
    assert_eq!((sun.kind, sun.direction, sun.color), (LightKind::Directional, -Vec3::Z, Vec3::ONE));
}

#[test]
fn a_missing_texture_is_a_warning_and_a_visible_fallback() {
    let mut text = triangle_gltf("tri.bin", 3);
    text.pop(); // the closing brace
    text.push_str(
        r#","images":[{"uri":"no-such-image.png"}],"textures":[{"source":0}],
        "materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}]}"#,
    );
    let text = text.replace(r#""attributes":{"POSITION":0}"#, r#""attributes":{"POSITION":0},"material":0"#);
    let scene = load_text("missing-texture", &text).unwrap();
    assert!(scene.warnings.iter().any(|w| w.contains("no-such-image.png")), "{:?}", scene.warnings);
    let texture = scene.materials[0].base_color_texture.expect("the fallback stands in");
    // Magenta and black: impossible to mistake for content.
    let texel = scene.textures[texture.0 as usize].sample(rtgi_math::Vec2::splat(1.0 / 16.0));
    assert!(texel.x > 0.9 && texel.y < 0.1 && texel.z > 0.9, "{texel}");
}

#[test]
fn instanced_meshes_appear_once_per_node_and_mirrors_keep_their_winding() {
    // One triangle mesh used by three nodes: as is, moved, and mirrored in x.
    let text = triangle_gltf("tri.bin", 3).replace(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"mesh":0},{"mesh":0,"translation":[0,0,5]},{"mesh":0,"scale":[-1,1,1]}]"#,
    );
    let text = text.replace(r#""scenes":[{"nodes":[0]}]"#, r#""scenes":[{"nodes":[0,1,2]}]"#);
    let scene = load_text("instances", &text).unwrap();
    assert_eq!(scene.triangles.len(), 3);
    // The primitive names no material, so the default one is kept, once.
    assert_eq!(scene.materials.len(), 1);
    let corners = scene.triangle_positions();
    assert!(corners.iter().any(|t| t[0].z == 5.0), "the moved instance");
    // The mirrored triangle's corners were reordered, so its winding (and
    // computed normal) still faces +z like the others.
    for t in &corners {
        let normal = (t[1] - t[0]).cross(t[2] - t[0]);
        assert!(normal.z > 0.0, "{t:?}");
    }
    assert!(corners.iter().any(|t| t.iter().any(|p| p.x < 0.0)), "the mirrored instance");
}

#[test]
fn a_description_keeps_an_up_axis_only_where_its_meshes_agree() {
    let dir = scratch_dir("description-up");
    let Some(gltf) = shared_scene("gltf/Box/glTF/Box.gltf") else { return };
    std::fs::copy(&gltf, dir.join("Box.gltf")).unwrap();
    std::fs::copy(gltf.with_file_name("Box0.bin"), dir.join("Box0.bin")).unwrap();
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let load = |meshes: &[&str], name: &str| {
        let text: String = meshes.iter().map(|m| format!("[[mesh]]\nfile = \"{m}\"\n")).collect();
        std::fs::write(dir.join(name), text).unwrap();
        Scene::load(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"))
    };
    assert_eq!(load(&["Box.gltf"], "gltf.toml").up, Some(Vec3::Y));
    assert_eq!(load(&["tri.obj"], "obj.toml").up, None, "OBJ has no convention");
    assert_eq!(load(&["Box.gltf", "tri.obj"], "both.toml").up, None, "mixed: the renderer judges");
}
