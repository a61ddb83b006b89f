//! What a first render says and chooses by itself: warnings for images
//! that show nothing, a light for an enclosed unlit view, the default
//! output name, and option errors that name the choices.

use std::path::Path;
use std::process::Command;

use super::{RTGI, path_str, rtgi};
use rtgi_tests::{Run, scratch_dir, workspace_root};

const ROOM: &str = "tests/scenes/closed-room.toml";

fn render_room(out: &Path, extra: &[&str]) -> Run {
    let mut args = vec!["render", ROOM, "-o", path_str(out), "--width", "32", "--height", "32", "--spp", "2"];
    args.extend(extra);
    rtgi(&args)
}

/// `rtgi ARGS --json`, which must succeed: its summary, and what it said on standard error.
fn summary(args: &[&str]) -> (serde_json::Value, String) {
    let run = rtgi(&[args, &["--json"]].concat());
    assert!(run.success, "{run:?}");
    let json = serde_json::from_str(&run.stdout).unwrap_or_else(|e| panic!("not JSON ({e}): {}", run.stdout));
    (json, run.stderr)
}

/// [`render_room`] with `--json`.
fn render_room_summary(out: &Path, extra: &[&str]) -> (serde_json::Value, String) {
    let mut args = vec!["render", ROOM, "-o", path_str(out), "--width", "32", "--height", "32", "--spp", "2"];
    args.extend(extra);
    summary(&args)
}

#[test]
fn a_room_lit_only_from_outside_is_said_to_be_almost_black() {
    let dir = scratch_dir("almost-black");
    let (json, stderr) = render_room_summary(&dir.join("black.png"), &["--light", "point:5,5,5:100"]);
    assert_eq!(json["legibility"]["looks"], "almost black", "{json}");
    assert_eq!(json["legibility"]["fraction"], 1.0, "{json}");
    // The outcome lists its warnings as data too (rtgi_job::Warning).
    let warnings = json["warnings"].as_array().expect("a list of warnings");
    assert!(warnings.iter().any(|w| w["kind"] == "almost_black" && w["fraction"] == 1.0), "{json}");
    // The warning says what to do, in the options' words.
    assert!(stderr.contains("warning: the image is almost black (100% of its pixels)"), "{stderr}");
    assert!(stderr.contains("--environment") && stderr.contains("--at"), "{stderr}");
}

#[test]
fn an_overexposed_image_is_said_to_be_almost_white() {
    let dir = scratch_dir("almost-white");
    let (json, stderr) =
        render_room_summary(&dir.join("white.png"), &["--light", "point:0,0.5,0:100", "--exposure", "12"]);
    assert_eq!(json["legibility"]["looks"], "almost white", "{json}");
    assert_eq!((json["exposure"]["stops"].as_f64(), &json["exposure"]["automatic"]), (Some(12.0), &false.into()));
    assert!(stderr.contains("warning: the image is almost white") && stderr.contains("lower --exposure"), "{stderr}");
    // Left to the automatic exposure, the same light gives an image that shows something.
    let (json, stderr) = render_room_summary(&dir.join("auto.png"), &["--light", "point:0,0.5,0:100"]);
    assert!(json["legibility"].is_null() && !stderr.contains("warning"), "{json} {stderr}");
    assert_eq!(json["warnings"], serde_json::json!([]), "{json}");
    assert_eq!((&json["exposure"]["automatic"], &json["exposure"]["tone_map"]), (&true.into(), &"aces".into()));
    // The text says the same as the JSON.
    let run = render_room(&dir.join("auto.png"), &["--light", "point:0,0.5,0:100"]);
    assert!(run.stdout.contains("(automatic; --exposure sets it), aces tone map"), "{run:?}");
}

#[test]
fn an_enclosed_unlit_view_gets_a_room_light_and_says_so() {
    let dir = scratch_dir("room-light");
    let (json, _) = render_room_summary(&dir.join("room.png"), &[]);
    let lamp: Vec<f64> = json["room_light"].as_array().expect("a room light").iter().flat_map(|c| c.as_f64()).collect();
    assert_eq!(lamp.len(), 3, "{json}");
    assert!(json["legibility"].is_null(), "{json}");
    let run = render_room(&dir.join("room.png"), &[]);
    assert!(run.stdout.contains("note: no sky reaches the camera or the surfaces it sees"), "{run:?}");
}

/// A cave in a large world (McGuire's lost_empire: a voxel world whose lava
/// is weak beside a sky over the whole world): the closed room with a small
/// glowing patch on its ceiling and a wall far away. The emitters are too
/// weak to light the world, so the plan keeps the default sky; but they
/// light the view, so the cave gets no lamp, and nothing says nothing emits.
#[test]
fn an_enclosed_view_lit_by_the_scenes_own_weak_emitters_gets_no_lamp() {
    let dir = scratch_dir("lit-cave");
    let room = std::fs::read_to_string(workspace_root().join("tests/scenes/closed-room.obj")).unwrap();
    let extra = "mtllib lava.mtl\nv -0.1 0.99 -0.1\nv 0.1 0.99 -0.1\nv 0.1 0.99 0.1\nv -0.1 0.99 0.1\n\
                 usemtl lava\nf 9 10 11 12\nv 100 -1 -100\nv 100 -1 100\nv 100 100 100\nusemtl rock\nf 13 14 15\n";
    std::fs::write(dir.join("cave.obj"), format!("{room}{extra}")).unwrap();
    std::fs::write(dir.join("lava.mtl"), "newmtl lava\nKd 0 0 0\nKe 50 20 5\nnewmtl rock\nKd 0.5 0.5 0.5\n").unwrap();
    let toml = "[[mesh]]\nfile = \"cave.obj\"\n[camera]\nposition = [0.0, 0.0, 0.0]\ndirection = [0.0, -0.3, -1.0]\nup = [0.0, 1.0, 0.0]\nvertical_fov_degrees = 60.0\n";
    std::fs::write(dir.join("cave.toml"), toml).unwrap();
    let (scene, out) = (dir.join("cave.toml"), dir.join("cave.png"));
    let args = ["render", path_str(&scene), "-o", path_str(&out), "--width", "32", "--height", "32", "--spp", "2"];
    let (json, _) = summary(&args);
    assert!(json["room_light"].is_null(), "{json}");
    let environment =
        json["plan"]["effects"].as_array().unwrap().iter().find(|e| e["effect"] == "environment").cloned();
    assert!(environment.is_some_and(|e| e["reason"].as_str().unwrap().contains("too little to light it")), "{json}");
    let run = rtgi(&args);
    assert!(!run.stdout.contains("nothing emits") && !run.stdout.contains("lamp"), "{run:?}");
}

#[test]
fn a_camera_that_sees_only_the_backs_of_faces_is_said_to_be_inside_geometry() {
    let dir = scratch_dir("buried-camera");
    let (json, stderr) = render_room_summary(&dir.join("outside.png"), &["--at", "0,0,1.5", "--look", "0,0,0"]);
    assert_eq!(json["camera"]["source"], "options", "{json}");
    assert!(json["camera"]["inside_geometry"].as_f64().is_some_and(|f| f > 0.5), "{json}");
    assert!(stderr.contains("warning: the camera seems to be inside geometry"), "{stderr}");
}

#[test]
fn without_o_the_image_is_named_after_the_scene_in_the_current_folder() {
    let dir = scratch_dir("default-output");
    let scene = workspace_root().join(ROOM);
    let run: Run = Command::new(RTGI)
        .args(["render", path_str(&scene), "--quick", "-t", "1", "--json"])
        .current_dir(&dir)
        .output()
        .unwrap()
        .into();
    assert!(run.success, "{run:?}");
    let json: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
    assert_eq!(json["outputs"][0]["path"], "closed-room.png", "{json}");
    let image = image::open(dir.join("closed-room.png")).expect("closed-room.png in the current folder");
    // --quick: a quarter of the default 512 x 512, and at most 4 samples per pixel.
    assert_eq!((image.width(), image.height()), (128, 128));
    let render = &json["render"];
    assert_eq!(
        (&render["width"], &render["height"], &render["samples_per_pixel"]),
        (&128.into(), &128.into(), &4.into())
    );
    assert_eq!(render["threads"], 1, "{json}");
}

#[test]
fn a_wrong_aov_name_lists_the_aovs() {
    let run = rtgi(&["render", "--aov", "normals", "-o", "x.png"]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert_eq!(
        run.stderr.trim(),
        "error: invalid value 'normals' for '--aov <AOV>' (possible values: albedo, normal, depth, position, emission, cost); \
         did you mean 'normal'?",
        "{run:?}"
    );
}

#[test]
fn the_readmes_trace_example_runs_on_rays_written_by_rtgi_rays() {
    let dir = scratch_dir("rays-then-trace");
    for (kind, expected) in [("camera", 24 * 16), ("random", 500), ("surface", 500)] {
        let (rays, hits) = (dir.join(format!("{kind}.bin")), dir.join(format!("{kind}.hits")));
        let run = rtgi(&[
            "rays",
            "scenes/cornell-box.toml",
            "--kind",
            kind,
            "--count",
            "500",
            "--width",
            "24",
            "--height",
            "16",
            "-o",
            path_str(&rays),
        ]);
        assert!(run.success, "{run:?}");
        assert_eq!(std::fs::metadata(&rays).unwrap().len(), expected * 32, "{kind}");
        let run = rtgi(&["trace", "scenes/cornell-box.toml", "--rays", path_str(&rays), "--out", path_str(&hits)]);
        assert!(run.success, "{run:?}");
        assert_eq!(std::fs::metadata(&hits).unwrap().len(), expected * 16, "{kind}");
        // Camera rays into the closed box all hit; surface rays mostly do.
        if kind == "camera" {
            assert!(run.stderr.contains(&format!("{expected} hits")), "{run:?}");
        }
    }
}

#[test]
fn parse_errors_are_one_line_made_from_clap_s_error_kinds() {
    for (args, expected) in [
        (&["rendr"][..], "error: unrecognized subcommand 'rendr'; did you mean 'render'?"),
        (
            &["render", "--seed", "1", "--seed", "2"][..],
            "error: the argument '--seed <SEED>' cannot be used multiple times",
        ),
        (&["render", "--frobnicate"][..], "error: unexpected argument '--frobnicate'"),
        (&["merge"][..], "error: the following required arguments were not provided: --output <OUTPUT>, <PARTS>..."),
    ] {
        let run = rtgi(args);
        assert_eq!(run.code, Some(2), "{run:?}");
        assert_eq!(run.stderr.trim(), expected, "{args:?}");
    }
}

#[test]
fn a_file_that_is_not_an_obj_is_refused_naming_its_first_line() {
    let dir = scratch_dir("not-obj");
    let scene = dir.join("x.obj");
    std::fs::write(&scene, "x\n").unwrap();
    let out = dir.join("x.png");
    let run = rtgi(&["render", path_str(&scene), "-o", path_str(&out), "--quick"]);
    assert!(!run.success && run.code == Some(1), "{run:?}");
    assert!(run.stderr.contains("x.obj: not a valid OBJ file: no faces"), "{run:?}");
    assert!(run.stderr.contains("line 1: 'x' is not an OBJ statement"), "{run:?}");
    assert!(!out.exists());
}

#[test]
fn an_output_folder_that_does_not_exist_is_named_as_such() {
    let dir = scratch_dir("missing-output-folder");
    let out = dir.join("no-such-folder").join("x.png");
    let run = rtgi(&["render", ROOM, "-o", path_str(&out), "--quick"]);
    assert!(!run.success, "{run:?}");
    assert!(run.stderr.contains("no-such-folder does not exist"), "{run:?}");
    // Not a complaint about the format: the name ends in .png.
    assert!(!run.stderr.contains(".exr"), "{run:?}");
}

/// `rtgi info` on the shared glTF samples: cameras and textures with their
/// index, textures with the file they came from, and an unsupported
/// extension warned about once.
#[test]
fn info_numbers_cameras_and_names_texture_files() {
    let (Some(helmet), Some(cameras), Some(transmission)) = (
        rtgi_tests::shared_scene("gltf/DamagedHelmet/glTF/DamagedHelmet.gltf"),
        rtgi_tests::shared_scene("gltf/Cameras/glTF/Cameras.gltf"),
        rtgi_tests::shared_scene("gltf/TransmissionTest/glTF/TransmissionTest.gltf"),
    ) else {
        return; // shared_scene said which is missing
    };
    let (json, _) = summary(&["info", path_str(&helmet)]);
    let texture = &json["textures"][0];
    assert_eq!(texture["name"], "image 0 from 'Default_albedo.jpg'", "{json}");
    assert_eq!((&texture["width"], &texture["height"]), (&2048.into(), &2048.into()));
    let (json, _) = summary(&["info", path_str(&cameras)]);
    assert_eq!(json["cameras"][0]["position"], serde_json::json!([0.5, 0.5, 3.0]), "{json}");
    // KHR_xmp is metadata: listed as nothing to render, with no warning.
    let (json, stderr) = summary(&["info", path_str(&transmission)]);
    assert_eq!(json["extensions_unsupported"], serde_json::json!([]), "{json}");
    let xmp = json["extensions"].as_array().unwrap().iter().find(|e| e["name"] == "KHR_xmp").cloned();
    assert_eq!(xmp.map(|e| e["support"].clone()), Some("not visual".into()), "{json}");
    assert!(!stderr.contains("KHR_xmp"), "{stderr}");
    let run = rtgi(&["info", path_str(&transmission)]);
    assert!(
        run.stdout.lines().any(|l| l.contains("KHR_materials_transmission") && l.contains("simulated")),
        "{}",
        run.stdout
    );
}

#[test]
fn info_says_why_it_counts_more_vertices_than_positions() {
    // Two triangles sharing an edge, each with its own normal: the shared
    // corners are split, 6 vertices at 4 positions.
    let dir = scratch_dir("info-vertices");
    let obj = dir.join("fold.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvn 0 0 1\nvn 0 1 0\nf 1//1 2//1 3//1\nf 2//2 4//2 3//2\n",
    )
    .unwrap();
    let (json, _) = summary(&["info", path_str(&obj)]);
    assert_eq!((&json["vertices"], &json["positions"]), (&6.into(), &4.into()), "{json}");
    let run = rtgi(&["info", path_str(&obj)]);
    assert!(
        run.stdout.contains("vertices    6 (4 distinct positions: corners at one position are split"),
        "{}",
        run.stdout
    );
}

/// A glTF triangle (0,0,0), (1,0,0), (0,1,0) with two perspective cameras
/// of aspect ratio 1.5 at z = 3: the first turned away, the second facing it.
fn two_camera_gltf(dir: &Path) -> std::path::PathBuf {
    use base64::Engine as _;
    let bytes: Vec<u8> =
        [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|f| f.to_le_bytes()).collect();
    let data = base64::engine::general_purpose::STANDARD.encode(bytes);
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1,2]}}],
        "nodes":[{{"mesh":0}},
                 {{"camera":0,"translation":[0.3,0.3,3],"rotation":[0,1,0,0]}},
                 {{"camera":0,"translation":[0.3,0.3,3]}}],
        "cameras":[{{"type":"perspective","perspective":{{"aspectRatio":1.5,"yfov":0.7,"znear":0.01}}}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}}]}}"#
    );
    let path = dir.join("two-cameras.gltf");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn of_two_file_cameras_the_one_that_sees_the_model_is_used_at_its_aspect_ratio() {
    let dir = scratch_dir("two-cameras");
    let scene = two_camera_gltf(&dir);
    let out = dir.join("two.png");
    let (json, stderr) = summary(&["render", path_str(&scene), "-o", path_str(&out), "--spp", "1"]);
    let camera = &json["camera"];
    // (The loader numbers the cameras in its own order of the nodes: the one facing the model is 0.)
    assert_eq!((&camera["source"], &camera["index"], &camera["file_cameras"]), (&"file".into(), &0.into(), &2.into()));
    assert!(camera["direction"][2].as_f64().is_some_and(|z| z < 0.0), "it looks at the model, along -Z: {json}");
    assert!(camera["file_choice"].as_str().is_some_and(|c| c.contains("the one that sees most")), "{json}");
    assert!(stderr.contains("of the file's 2 (0 to 1), the one that sees most of the model (100% of"), "{stderr}");
    // 512 wide, as tall as the camera's aspect ratio of 1.5 asks.
    assert_eq!((&json["render"]["width"], &json["render"]["height"]), (&512.into(), &341.into()));
    assert_eq!(image::image_dimensions(&out).unwrap(), (512, 341));
    // A size given wins; an index given needs no note.
    let (json, stderr) =
        summary(&["render", path_str(&scene), "-o", path_str(&out), "--spp", "1", "--camera", "0", "--width", "64"]);
    assert_eq!((&json["camera"]["index"], &json["camera"]["file_choice"]), (&0.into(), &serde_json::Value::Null));
    assert!(!stderr.contains("note: the view is"), "{stderr}");
    assert_eq!(image::image_dimensions(&out).unwrap(), (64, 512));
}

#[test]
fn the_automatic_view_says_which_view_it_took_and_a_given_one_does_not() {
    let dir = scratch_dir("automatic-view");
    // A model without a camera: a cube of one material, alike from every side.
    let model = dir.join("cube.obj");
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
    std::fs::write(&model, cube).unwrap();
    let render = |extra: &[&str]| {
        let out = dir.join("cube.png");
        let mut args = vec!["render", path_str(&model), "-o", path_str(&out), "--width", "24", "--height", "24"];
        args.extend(["--spp", "1"]);
        args.extend(extra);
        summary(&args)
    };
    let (json, stderr) = render(&[]);
    assert_eq!(json["camera"]["source"], "automatic", "{json}");
    let view = "a three-quarter shot of the model's front, from +Z and above";
    assert_eq!(json["camera"]["automatic_view"], view, "{json}");
    assert!(
        stderr.contains(&format!("note: the automatic view is {view}; --at (and --look) choose another")),
        "{stderr}"
    );
    // A field of view keeps the automatic view; a position or a target replaces it.
    let (json, _) = render(&["--fov", "30"]);
    assert_eq!((&json["camera"]["source"], &json["camera"]["automatic_view"]), (&"automatic".into(), &view.into()));
    assert!((json["camera"]["vertical_fov_degrees"].as_f64().unwrap() - 30.0).abs() < 1e-4, "{json}");
    for given in [&["--at", "2,2,2"][..], &["--look", "0,0.2,0"][..]] {
        let (json, stderr) = render(given);
        assert_eq!(json["camera"]["source"], "options", "{given:?}: {json}");
        assert!(json["camera"]["automatic_view"].is_null() && !stderr.contains("automatic view"), "{given:?}");
    }
}

/// A glTF file that requires an extension rtgi lacks is refused naming the
/// extension (not blamed on the file), and a material variant the file
/// does not have is refused listing its variants: both exit 2, as a usage
/// error does. The info of a file lists how each extension it uses is rendered.
#[test]
fn gltf_extensions_rtgi_lacks_and_unknown_variants_exit_2_naming_them() {
    let dir = scratch_dir("gltf-refusals");
    let unlit = workspace_root().join("tests/data/khronos/UnlitTest/glTF/UnlitTest.gltf");
    let text = std::fs::read_to_string(&unlit).unwrap().replacen(
        "\"extensionsRequired\"",
        "\"extensionsRequired\": [\"KHR_draco_mesh_compression\"], \"unusedRequired\"",
        1,
    );
    std::fs::copy(unlit.with_file_name("UnlitTest.bin"), dir.join("UnlitTest.bin")).unwrap();
    std::fs::write(dir.join("draco.gltf"), text).unwrap();
    let run = rtgi(&["info", path_str(&dir.join("draco.gltf"))]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("uses KHR_draco_mesh_compression, which rtgi does not support"), "{run:?}");
    assert!(!run.stderr.contains("not a valid glTF"), "{run:?}");
    let run = rtgi(&["info", path_str(&unlit), "--variant", "Dawn"]);
    assert_eq!(run.code, Some(2), "{run:?}");
    assert!(run.stderr.contains("has no material variant 'Dawn' (it has none)"), "{run:?}");
    let run = rtgi(&["info", path_str(&unlit)]);
    assert!(run.stdout.lines().any(|l| l.contains("KHR_materials_unlit") && l.contains("simulated")), "{run:?}");
    assert!(run.stdout.contains("unlit"), "{run:?}");
}
