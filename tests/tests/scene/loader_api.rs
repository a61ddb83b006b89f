//! The loading API of issue 15: `Scene::sources`, `Scene::load_with` and
//! its `LoadOptions`, and `Scene::load_from_bytes`.

use rtgi_scene::{LoadOptions, Scene};
use rtgi_tests::corpus::REFERENCED_PNG;
use rtgi_tests::scratch_dir;

const OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n";

#[test]
fn sources_list_every_file_read_as_canonical_paths() {
    let dir = scratch_dir("api-sources");
    std::fs::create_dir_all(dir.join("tex")).unwrap();
    std::fs::write(dir.join("tex").join("a.png"), REFERENCED_PNG).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd tex/A.PNG\n").unwrap();
    std::fs::write(dir.join("t.obj"), OBJ).unwrap();
    std::fs::write(dir.join("s.toml"), "[[mesh]]\nfile = \"./t.obj\"\n").unwrap();
    let scene = Scene::load(&dir.join("s.toml")).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let dir = dir.canonicalize().unwrap();
    let expected = ["s.toml", "t.obj", "m.mtl", "tex/a.png"].map(|f| dir.join(f));
    assert_eq!(scene.sources, expected);
}

#[test]
fn allow_outside_folder_lets_a_trusted_scene_reach_out() {
    let root = scratch_dir("api-outside");
    std::fs::write(root.join("shared.png"), REFERENCED_PNG).unwrap();
    let dir = root.join("scene");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl a\nmap_Kd ../shared.png\n").unwrap();
    std::fs::write(dir.join("t.obj"), OBJ).unwrap();
    let safe = Scene::load(&dir.join("t.obj")).unwrap();
    assert!(safe.warnings.iter().any(|w| w.contains("refusing")), "{:?}", safe.warnings);
    assert!(!safe.sources.iter().any(|s| s.ends_with("shared.png")));
    let options = LoadOptions { allow_outside_folder: true, ..LoadOptions::default() };
    let trusted = Scene::load_with(&dir.join("t.obj"), &options).unwrap();
    assert!(trusted.warnings.is_empty(), "{:?}", trusted.warnings);
    assert_eq!(trusted.textures[0].width(), 2);
    assert!(trusted.sources.contains(&root.canonicalize().unwrap().join("shared.png")));
}

#[test]
fn scenes_load_from_memory_through_a_reader() {
    let read = |name: &str| match name {
        "m.mtl" => Some(b"newmtl a\nKd 1 0 0\nmap_Kd t.png\n".to_vec()),
        "t.png" => Some(REFERENCED_PNG.to_vec()),
        _ => None,
    };
    let scene = Scene::load_from_bytes("tri.obj", OBJ.as_bytes(), &read).unwrap();
    assert_eq!(scene.materials[0].name, "a");
    assert_eq!(scene.textures[0].width(), 2);
    let names: Vec<String> = scene.sources.iter().map(|s| s.display().to_string()).collect();
    assert_eq!(names, ["tri.obj", "m.mtl", "t.png"]);
    assert!(Scene::load_from_bytes("x.ply", b"", &read).is_err());
}
