//! Issue 15: no panic on any input, nothing read outside the scene. One test
//! per finding, each written against `Scene::load` alone so that it can be
//! run against the importers from before the fix (where each fails).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use rtgi_math::Vec3;
use rtgi_scene::{Scene, SceneError};
use rtgi_tests::scratch_dir;

/// Loads, turning a panic into a test failure that says which case panicked.
fn load(path: &Path) -> Result<Scene, SceneError> {
    catch_unwind(AssertUnwindSafe(|| Scene::load(path)))
        .unwrap_or_else(|_| panic!("loading {} panicked", path.display()))
}

/// Writes `files` (name, contents) into a fresh scratch folder and returns it.
fn folder(test: &str, files: &[(&str, &[u8])]) -> rtgi_tests::ScratchDir {
    let dir = scratch_dir(test);
    for (name, contents) in files {
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, contents).unwrap();
    }
    dir
}

const TRIANGLE_OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";

fn obj_using(materials: &[&str]) -> String {
    let mut obj = TRIANGLE_OBJ.to_owned();
    for m in materials {
        obj.push_str(&format!("usemtl {m}\nf 1/1 2/2 3/3\n"));
    }
    obj
}

#[test]
fn mtl_statements_with_too_few_numbers_do_not_panic() {
    // tobj indexed past the numbers it had; a one-number colour is grey by the MTL specification.
    let mtl = "newmtl grey\nKd 0.5\nnewmtl short\nKs 0.5 0.5\nKe 1\nTf 0.2\n";
    let dir =
        folder("mtl-few-numbers", &[("t.obj", obj_using(&["grey", "short"]).as_bytes()), ("m.mtl", mtl.as_bytes())]);
    let scene = load(&dir.join("t.obj")).unwrap();
    let grey = scene.materials.iter().find(|m| m.name == "grey").expect("grey");
    assert_eq!(grey.base_color, Vec3::splat(0.5));
    assert!(scene.warnings.iter().any(|w| w.contains("m.mtl:4") && w.contains("Ks 0.5 0.5")), "{:?}", scene.warnings);
}

#[test]
fn a_malformed_mtl_statement_is_a_warning_and_the_other_materials_load() {
    let mtl =
        "newmtl paint\nKd 0.8 0 0\nnewmtl glass\nKd 0.1 0.1 0.1\nNs twelve\nillum 7\nnewmtl chrome\nKs 0.9 0.9 0.9\n";
    let dir = folder(
        "mtl-typo",
        &[("t.obj", obj_using(&["paint", "glass", "chrome"]).as_bytes()), ("m.mtl", mtl.as_bytes())],
    );
    let scene = load(&dir.join("t.obj")).unwrap();
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["paint", "glass", "chrome"], "{:?}", scene.warnings);
    assert_eq!(scene.materials[0].base_color, Vec3::new(0.8, 0.0, 0.0));
    // The bad statement is dropped; the rest of its material is kept.
    assert_eq!(scene.materials[1].transmission, 1.0);
    let warning = scene.warnings.iter().find(|w| w.contains("m.mtl:5")).expect("a warning naming file and line");
    assert!(warning.contains("twelve"), "{warning}");
}

#[test]
fn an_obj_face_with_absurdly_many_vertices_is_refused_before_it_is_built() {
    let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    for i in 0..100_000 {
        obj.push_str([" 1", " 2", " 3"][i % 3]);
    }
    obj.push('\n');
    let dir = folder("obj-huge-face", &[("t.obj", obj.as_bytes())]);
    let err = load(&dir.join("t.obj")).unwrap_err().to_string();
    assert!(err.contains("t.obj") && err.contains("100000 vertices"), "{err}");
}

const TRIANGLE_BIN: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// A glTF document with one triangle from `tri.bin`, `extra` spliced into
/// its top-level object, and `primitive` as its primitive's JSON.
fn gltf(primitive: &str, nodes: &str, extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":{nodes},
        "meshes":[{{"primitives":[{primitive}]}}],
        "buffers":[{{"uri":"tri.bin","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}}]{extra}}}"#
    )
}

fn load_gltf(test: &str, text: &str) -> Result<Scene, SceneError> {
    let bin: Vec<u8> = TRIANGLE_BIN.iter().flat_map(|f| f.to_le_bytes()).collect();
    let dir = folder(test, &[("tri.bin", &bin), ("t.gltf", text.as_bytes())]);
    load(&dir.join("t.gltf"))
}

const POSITIONS: &str = r#"{"attributes":{"POSITION":0}}"#;

#[test]
fn gltf_accessor_numbers_out_of_range_are_errors() {
    for primitive in [
        r#"{"attributes":{"POSITION":7}}"#,
        r#"{"attributes":{"POSITION":0,"NORMAL":9}}"#,
        r#"{"attributes":{"POSITION":0},"indices":5}"#,
    ] {
        let err = load_gltf("gltf-accessor-range", &gltf(primitive, r#"[{"mesh":0}]"#, "")).unwrap_err();
        assert!(err.to_string().contains("t.gltf"), "{err}");
    }
}

#[test]
fn gltf_images_without_a_source_or_a_mime_type_are_errors() {
    let material =
        r#","textures":[{"source":0}],"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}]"#;
    let primitive = r#"{"attributes":{"POSITION":0},"material":0}"#;
    for image in [r#","images":[{"name":"nothing"}]"#, r#","images":[{"bufferView":0}]"#] {
        let text = gltf(primitive, r#"[{"mesh":0}]"#, &format!("{image}{material}"));
        let err = load_gltf("gltf-image-source", &text).unwrap_err().to_string();
        assert!(err.contains("image 0"), "{err}");
    }
}

#[test]
fn gltf_index_accessors_of_the_wrong_type_are_errors() {
    // A float index accessor, and a vector one, both reading the position data.
    for (component, kind) in [(5126, "SCALAR"), (5125, "VEC3"), (5126, "VEC3")] {
        let index_accessor = format!(r#"{{"bufferView":0,"componentType":{component},"count":3,"type":"{kind}"}}"#);
        let text = gltf(r#"{"attributes":{"POSITION":0},"indices":1}"#, r#"[{"mesh":0}]"#, "")
            .replace(r#""min":[0,0,0]}]"#, &format!(r#""min":[0,0,0]}},{index_accessor}]"#));
        let err = load_gltf("gltf-index-type", &text).unwrap_err().to_string();
        assert!(err.contains("index accessor 1"), "{component} {kind}: {err}");
    }
}

#[test]
fn a_gltf_node_cycle_is_an_error_naming_the_node_at_once() {
    let nodes = r#"[{"mesh":0,"children":[1]},{"name":"loop","mesh":0,"children":[2]},{"mesh":0,"children":[1]}]"#;
    let start = std::time::Instant::now();
    let err = load_gltf("gltf-cycle", &gltf(POSITIONS, nodes, "")).unwrap_err().to_string();
    assert!(err.contains("cycle") && err.contains("node 1 ('loop')"), "{err}");
    assert!(start.elapsed().as_secs_f64() < 1.0, "took {:?}", start.elapsed());
}

#[test]
fn gltf_nodes_with_two_parents_are_placed_once() {
    // Forty levels of two nodes, each parent of both nodes of the next
    // level: 2^40 paths to the last level if every path were instanced.
    let levels = 40;
    let mut nodes = Vec::new();
    for level in 0..levels {
        let children = if level + 1 < levels {
            format!(r#","children":[{},{}]"#, 2 * level + 2, 2 * level + 3)
        } else {
            String::new()
        };
        for _ in 0..2 {
            nodes.push(format!(r#"{{"mesh":0{children}}}"#));
        }
    }
    let text = gltf(POSITIONS, &format!("[{}]", nodes.join(",")), "").replace(r#""nodes":[0]"#, r#""nodes":[0,1]"#);
    let scene = load_gltf("gltf-two-parents", &text).unwrap();
    assert_eq!(scene.triangles.len(), 2 * levels);
    assert!(scene.warnings.iter().any(|w| w.contains("more than one parent")), "{:?}", scene.warnings);
}

/// A PNG declaring `width` × `height` grey texels, with a few bytes of pixels.
fn png_header(width: u32, height: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= b as u32;
            for _ in 0..8 {
                crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
            }
        }
        !crc
    }
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut header = width.to_be_bytes().to_vec();
    header.extend(height.to_be_bytes());
    header.extend([8, 0, 0, 0, 0]); // 8-bit greyscale, no interlace
    // An empty zlib stream: the decoder reads the header and meets the pixels' end.
    let empty_zlib = [0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01];
    for (kind, data) in [(b"IHDR", &header[..]), (b"IDAT", &empty_zlib[..]), (b"IEND", &[][..])] {
        let mut chunk = kind.to_vec();
        chunk.extend(data);
        png.extend((data.len() as u32).to_be_bytes());
        png.extend(&chunk);
        png.extend(crc32(&chunk).to_be_bytes());
    }
    png
}

#[test]
fn textures_of_absurd_declared_size_are_refused_from_their_header() {
    let dir = folder(
        "texture-huge",
        &[
            ("t.obj", obj_using(&["a"]).as_bytes()),
            ("m.mtl", b"newmtl a\nmap_Kd huge.png\n"),
            ("huge.png", &png_header(100_000, 100_000)),
        ],
    );
    let scene = load(&dir.join("t.obj")).unwrap();
    assert!(scene.warnings.iter().any(|w| w.contains("100000 x 100000")), "{:?}", scene.warnings);
}

/// A small valid PNG, to tell a texture that was read from one that was not.
fn small_png() -> Vec<u8> {
    let mut bytes = Vec::new();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([10, 200, 30, 255]))
        .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .unwrap();
    bytes
}

#[test]
fn obj_texture_and_mtl_references_outside_the_folder_are_refused() {
    let root = scratch_dir("contain-obj");
    std::fs::write(root.join("secret.png"), small_png()).unwrap();
    let dir = root.join("scene");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl up\nmap_Kd ../secret.png\nnewmtl abs\nmap_Kd /etc/passwd\n").unwrap();
    std::fs::write(dir.join("t.obj"), obj_using(&["up", "abs"])).unwrap();
    let scene = load(&dir.join("t.obj")).unwrap();
    for reference in ["../secret.png", "/etc/passwd"] {
        assert!(
            scene.warnings.iter().any(|w| w.contains(reference) && w.contains("refusing")),
            "{reference}: {:?}",
            scene.warnings
        );
    }
    // Both became the missing-texture checkerboard: nothing was decoded.
    assert!(scene.textures.iter().all(|t| t.width() == 8), "{:?}", scene.textures);
    // A material library outside the folder is refused too.
    std::fs::write(root.join("outside.mtl"), "newmtl up\nKd 1 0 0\n").unwrap();
    std::fs::write(dir.join("u.obj"), obj_using(&["up"]).replace("mtllib m.mtl", "mtllib ../outside.mtl")).unwrap();
    let scene = load(&dir.join("u.obj")).unwrap();
    assert!(scene.materials.iter().all(|m| m.name != "up"), "{:?}", scene.materials);
    assert!(
        scene.warnings.iter().any(|w| w.contains("../outside.mtl") && w.contains("refusing")),
        "{:?}",
        scene.warnings
    );
}

#[cfg(unix)]
#[test]
fn symbolic_links_out_of_the_folder_are_refused() {
    let root = scratch_dir("contain-symlink");
    let bin: Vec<u8> = TRIANGLE_BIN.iter().flat_map(|f| f.to_le_bytes()).collect();
    std::fs::write(root.join("outside.bin"), bin).unwrap();
    std::fs::write(root.join("outside.png"), small_png()).unwrap();
    let dir = root.join("scene");
    std::fs::create_dir_all(&dir).unwrap();
    std::os::unix::fs::symlink(root.join("outside.bin"), dir.join("tri.bin")).unwrap();
    std::os::unix::fs::symlink(root.join("outside.png"), dir.join("tex.png")).unwrap();
    std::fs::write(dir.join("t.gltf"), gltf(POSITIONS, r#"[{"mesh":0}]"#, "")).unwrap();
    let err = load(&dir.join("t.gltf")).unwrap_err().to_string();
    assert!(err.contains("t.gltf") && err.contains("tri.bin") && err.contains("leaves the scene's folder"), "{err}");
    std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd tex.png\n").unwrap();
    std::fs::write(dir.join("t.obj"), obj_using(&["a"])).unwrap();
    let scene = load(&dir.join("t.obj")).unwrap();
    assert!(scene.warnings.iter().any(|w| w.contains("tex.png") && w.contains("refusing")), "{:?}", scene.warnings);
}

#[test]
fn description_meshes_outside_the_folder_are_refused() {
    let root = scratch_dir("contain-toml");
    std::fs::write(root.join("mesh.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let dir = root.join("scene");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("s.toml"), "[[mesh]]\nfile = \"../mesh.obj\"\n").unwrap();
    let err = load(&dir.join("s.toml")).unwrap_err().to_string();
    assert!(err.contains("s.toml") && err.contains("../mesh.obj") && err.contains("refusing"), "{err}");
}

#[test]
fn a_description_that_includes_itself_is_an_error() {
    // Before the fix this recursed until the stack overflowed (an abort, not a panic).
    let dir = folder("toml-self", &[("s.toml", b"[[mesh]]\nfile = \"s.toml\"\n")]);
    let err = load(&dir.join("s.toml")).unwrap_err().to_string();
    assert!(err.contains("nested"), "{err}");
}
