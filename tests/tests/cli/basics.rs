//! End-to-end tests of the `rtgi` command: run as a new user would.

use std::path::Path;

use super::{RTGI, path_str, rtgi};
use rtgi_tests::{scratch_dir, shared_scene};

fn is_red([r, g, b]: [u8; 3]) -> bool {
    r as i32 > g as i32 + 60 && r as i32 > b as i32 + 60
}

fn is_green([r, g, b]: [u8; 3]) -> bool {
    g as i32 > r as i32 + 30 && g as i32 > b as i32 + 30
}

#[test]
fn default_scene_renders_the_cornell_box() {
    let dir = scratch_dir("default");
    let out = dir.join("box.png");
    let run = rtgi(&["render", "-o", path_str(&out), "--width", "96", "--height", "96", "--integrator", "primary"]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("triangles   32"), "{}", run.stdout);
    let image = image::open(&out).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (96, 96));
    // The published camera sees the red wall on the left and the green wall on the right.
    let left = image.get_pixel(4, 48).0;
    let right = image.get_pixel(91, 48).0;
    assert!(is_red(left), "left wall {left:?}");
    assert!(is_green(right), "right wall {right:?}");
    // The light in the ceiling is the brightest thing in view.
    let light_pixels = (0..24).flat_map(|y| (36..60).map(move |x| (x, y)));
    let white = light_pixels.filter(|&(x, y)| image.get_pixel(x, y).0 == [255, 255, 255]).count();
    assert!(white >= 4, "{white} white pixels where the light should be");
}

#[test]
fn same_seed_gives_same_bytes_at_any_thread_count() {
    let dir = scratch_dir("threads");
    let mut outputs = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.join(format!("t{threads}.exr"));
        let args = ["render", "-o", path_str(&out), "--width", "48", "--height", "40", "--spp", "3", "--seed", "7"];
        let run = rtgi(&[&args[..], &["--threads", threads]].concat());
        assert!(run.success, "{run:?}");
        outputs.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(outputs[0], outputs[1]);
    // And a different seed gives a different image: random subpixel positions are in use.
    let out = dir.join("other.exr");
    let run = rtgi(&["render", "-o", path_str(&out), "--width", "48", "--height", "40", "--spp", "3", "--seed", "8"]);
    assert!(run.success, "{run:?}");
    assert_ne!(std::fs::read(&out).unwrap(), outputs[0]);
}

/// Runs a command that must fail: one line on stderr containing `expected`,
/// a non-zero exit, no panic, and `output` untouched.
fn assert_fails_cleanly(args: &[&str], expected: &str, output: &Path) {
    let before = std::fs::read(output).ok();
    let run = rtgi(args);
    assert!(!run.success, "{args:?} succeeded: {run:?}");
    assert!(run.code.is_some_and(|c| c != 0 && c != 101), "{args:?}: exit {:?} (101 is a panic)", run.code);
    let lines: Vec<&str> = run.stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{args:?}: expected one line, got {:?}", run.stderr);
    assert!(lines[0].contains(expected), "{args:?}: '{}' does not mention '{expected}'", lines[0]);
    assert_eq!(std::fs::read(output).ok(), before, "{args:?} changed {}", output.display());
    let leftovers: Vec<_> = std::fs::read_dir(output.parent().unwrap())
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "{args:?} left {leftovers:?}");
}

#[test]
fn bad_input_fails_with_one_line_and_leaves_no_file() {
    let dir = scratch_dir("bad-input");
    let out = dir.join("out.png");
    let o = path_str(&out);
    let malformed = dir.join("malformed.obj");
    std::fs::write(&malformed, "v 0 0 0\nv 1 0 0\nv 0 one 0\nf 1 2 3\n").unwrap();
    let dangling = dir.join("dangling.obj");
    std::fs::write(&dangling, "v 0 0 0\nf 1 2 3\n").unwrap();

    assert_fails_cleanly(&["render", "no/such/scene.obj", "-o", o], "no/such/scene.obj", &out);
    assert_fails_cleanly(&["render", path_str(&malformed), "-o", o], "malformed.obj", &out);
    assert_fails_cleanly(&["render", path_str(&dangling), "-o", o], "dangling.obj", &out);
    assert_fails_cleanly(&["render", "Cargo.toml", "-o", o], "Cargo.toml", &out);
    assert_fails_cleanly(&["render", "-o", "no/such/folder/out.png"], "no/such/folder/out.png", &out);
    assert_fails_cleanly(&["render", "-o", path_str(&dir.join("out.bmp"))], "out.bmp", &out);
    assert_fails_cleanly(&["render", "-o", o, "--width", "0"], "--width", &out);
    assert_fails_cleanly(&["render", "-o", o, "--height", "1000000"], "--height", &out);
    assert_fails_cleanly(&["render", "-o", o, "--accel", "octree"], "octree", &out);
    assert_fails_cleanly(&["render", "-o", o, "--at", "1,2"], "--at", &out);
    assert_fails_cleanly(&["render", "-o", o, "--fov", "180"], "--fov", &out);
    assert_fails_cleanly(&["render", "-o", o, "--camera", "1"], "--camera 1", &out);
    assert!(!out.exists());
}

#[test]
fn failed_run_keeps_an_earlier_good_output() {
    let dir = scratch_dir("keep");
    let out = dir.join("good.png");
    let run = rtgi(&["render", "-o", path_str(&out), "--width", "16", "--height", "16"]);
    assert!(run.success, "{run:?}");
    assert_fails_cleanly(&["render", "missing.obj", "-o", path_str(&out)], "missing.obj", &out);
    assert_fails_cleanly(&["render", "-o", path_str(&out), "--accel", "nope"], "nope", &out);
}

#[test]
fn shared_cornell_box_renders_with_its_colours() {
    let Some(scene) = shared_scene("cornell-box/CornellBox-Original.obj") else {
        return;
    };
    let dir = scratch_dir("shared-box");
    let out = dir.join("box.png");
    let args = ["render", path_str(&scene), "-o", path_str(&out), "--width", "64", "--height", "64"];
    let run = rtgi(&[&args[..], &["--integrator", "primary"]].concat());
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("triangles   36"), "{}", run.stdout);
    // Notes (which view the camera is) are welcome; nothing else is.
    let unexpected: Vec<&str> = run.stderr.lines().filter(|line| !line.starts_with("note: ")).collect();
    assert!(unexpected.is_empty(), "unexpected warnings: {}", run.stderr);
    let image = image::open(&out).unwrap().to_rgb8();
    let mut reddish = 0;
    let mut greenish = 0;
    for p in image.pixels() {
        reddish += is_red(p.0) as u32;
        greenish += is_green(p.0) as u32;
    }
    assert!(reddish > 100 && greenish > 100, "red {reddish}, green {greenish}");
}

#[test]
fn a_thread_count_from_the_environment_that_is_not_a_count_is_refused() {
    for command in [&["render", "--quick", "-o", "/nonexistent/x.png"][..], &["rays", "-o", "/nonexistent/r.bin"]] {
        let output = std::process::Command::new(RTGI)
            .args(command)
            .env("RTGI_THREADS", "many")
            .current_dir(rtgi_tests::workspace_root())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.code().is_some_and(|c| c != 0 && c != 101), "{command:?}: {stderr}");
        assert!(stderr.contains("RTGI_THREADS=many"), "{command:?}: {stderr}");
    }
}
