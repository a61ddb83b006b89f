//! What a first render says and chooses by itself: warnings for images
//! that show nothing, a light for an enclosed unlit view, the default
//! output name, and option errors that name the choices.

use std::path::Path;
use std::process::Command;

use rtgi_tests::{Run, run_cli, scratch_dir, workspace_root};

const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");
const ROOM: &str = "tests/scenes/closed-room.toml";

fn rtgi(args: &[&str]) -> Run {
    run_cli(RTGI, args)
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("scratch paths are UTF-8")
}

fn render_room(out: &Path, extra: &[&str]) -> Run {
    let mut args = vec!["render", ROOM, "-o", path_str(out), "--width", "32", "--height", "32", "--spp", "2"];
    args.extend(extra);
    rtgi(&args)
}

#[test]
fn a_room_lit_only_from_outside_is_said_to_be_almost_black() {
    let dir = scratch_dir("almost-black");
    let run = render_room(&dir.join("black.png"), &["--light", "point:5,5,5:100"]);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("warning: the image is almost black (100% of its pixels)"), "{run:?}");
    assert!(run.stderr.contains("--environment") && run.stderr.contains("--at"), "{run:?}");
}

#[test]
fn an_overexposed_image_is_said_to_be_almost_white() {
    let dir = scratch_dir("almost-white");
    let run = render_room(&dir.join("white.png"), &["--light", "point:0,0.5,0:100", "--exposure", "12"]);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("warning: the image is almost white"), "{run:?}");
    assert!(run.stderr.contains("lower --exposure"), "{run:?}");
    // Left to the automatic exposure, the same light gives an image that shows something.
    let run = render_room(&dir.join("auto.png"), &["--light", "point:0,0.5,0:100"]);
    assert!(run.success && !run.stderr.contains("warning"), "{run:?}");
    assert!(run.stdout.contains("(automatic; --exposure sets it), aces tone map"), "{run:?}");
}

#[test]
fn an_enclosed_unlit_view_gets_a_room_light_and_says_so() {
    let dir = scratch_dir("room-light");
    let run = render_room(&dir.join("room.png"), &[]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("note: the camera is enclosed by the scene"), "{run:?}");
    assert!(!run.stderr.contains("almost black"), "{run:?}");
}

#[test]
fn a_camera_that_sees_only_the_backs_of_faces_is_said_to_be_inside_geometry() {
    let dir = scratch_dir("buried-camera");
    let run = render_room(&dir.join("outside.png"), &["--at", "0,0,1.5", "--look", "0,0,0"]);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("warning: the camera seems to be inside geometry"), "{run:?}");
}

#[test]
fn without_o_the_image_is_named_after_the_scene_in_the_current_folder() {
    let dir = scratch_dir("default-output");
    let scene = workspace_root().join(ROOM);
    let run: Run = Command::new(RTGI)
        .args(["render", path_str(&scene), "--quick", "-t", "1"])
        .current_dir(&dir)
        .output()
        .unwrap()
        .into();
    assert!(run.success, "{run:?}");
    let image = image::open(dir.join("closed-room.png")).expect("closed-room.png in the current folder");
    // --quick: a quarter of the default 512 x 512.
    assert_eq!((image.width(), image.height()), (128, 128));
    assert!(run.stdout.contains("at 4 spp"), "{run:?}");
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
    let run = rtgi(&["info", path_str(&helmet)]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("  [0] image 0 from 'Default_albedo.jpg' (2048x2048)"), "{}", run.stdout);
    let run = rtgi(&["info", path_str(&cameras)]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("  [0] at (0.5, 0.5, 3)"), "{}", run.stdout);
    let run = rtgi(&["info", path_str(&transmission)]);
    assert!(run.success, "{run:?}");
    let said = format!("{}{}", run.stdout, run.stderr);
    assert_eq!(said.matches("KHR_xmp is not supported").count(), 1, "{said}");
    assert!(run.stdout.contains("KHR_xmp (ignored)"), "{}", run.stdout);
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
    let run = rtgi(&["info", path_str(&obj)]);
    assert!(run.success, "{run:?}");
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
    let run = rtgi(&["render", path_str(&scene), "-o", path_str(&out), "--spp", "1"]);
    assert!(run.success, "{run:?}");
    // (The loader numbers the cameras in its own order of the nodes.)
    assert!(run.stderr.contains("of the file's 2 (0 to 1), the one that sees most of the model (100% of"), "{run:?}");
    // 512 wide, as tall as the camera's aspect ratio of 1.5 asks.
    assert_eq!(image::image_dimensions(&out).unwrap(), (512, 341));
    // A size given wins; an index given needs no note.
    let run = rtgi(&["render", path_str(&scene), "-o", path_str(&out), "--spp", "1", "--camera", "0", "--width", "64"]);
    assert!(run.success && !run.stderr.contains("note: the view is"), "{run:?}");
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
        rtgi(&args)
    };
    let run = render(&[]);
    assert!(run.success, "{run:?}");
    let note = "note: the automatic view is a three-quarter shot of the model's front, from +Z and above; --at (and \
                --look) choose another";
    assert!(run.stderr.contains(note), "{run:?}");
    // A field of view keeps the automatic view; a position or a target replaces it.
    assert!(render(&["--fov", "30"]).stderr.contains(note));
    for given in [&["--at", "2,2,2"][..], &["--look", "0,0.2,0"][..]] {
        let run = render(given);
        assert!(run.success && !run.stderr.contains("automatic view"), "{given:?}: {run:?}");
    }
}
