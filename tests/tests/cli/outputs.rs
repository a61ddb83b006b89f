//! Outputs that would destroy an input, or that cannot fit in memory, are
//! refused before anything is rendered.

use std::path::Path;

use super::{path_str, rtgi};
use rtgi_tests::scratch_dir;

#[test]
fn an_output_that_is_also_an_input_is_refused_and_left_alone() {
    let dir = scratch_dir("output-is-input");
    let sky = dir.join("sky.exr");
    let mut image = rtgi_image::HdrImage::new(8, 4);
    image.pixels_mut().fill(rtgi_math::Vec3::splat(0.5));
    image.write(&sky, &rtgi_image::ToneMap::default()).unwrap();
    let before = std::fs::read(&sky).unwrap();
    let small = ["render", "--width", "16", "--height", "16", "--environment", path_str(&sky)];
    // As the image, as an AOV and as the checkpoint, through another spelling of the same path.
    let other_spelling = dir.join(".").join("sky.exr");
    for extra in [
        vec!["-o", path_str(&sky)],
        vec!["-o", path_str(&other_spelling)],
        vec!["-o", "x.png", "--checkpoint", path_str(&sky)],
    ] {
        let args: Vec<&str> = small.iter().copied().chain(extra).collect();
        let run = rtgi(&args);
        assert_eq!(run.code, Some(1), "{run:?}");
        assert!(run.stderr.contains("is --environment, which the command reads"), "{run:?}");
    }
    let aov_source = dir.join("out.normal.exr");
    std::fs::copy(&sky, &aov_source).unwrap();
    let out = dir.join("out.png");
    let run = rtgi(&[
        "render",
        "--width",
        "16",
        "--height",
        "16",
        "--environment",
        path_str(&aov_source),
        "--aov",
        "normal",
        "-o",
        path_str(&out),
    ]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("--aov"), "{run:?}");
    assert_eq!(std::fs::read(&sky).unwrap(), before);
    assert!(!out.exists());
}

#[test]
fn an_image_too_large_for_memory_is_refused_before_anything_is_allocated() {
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|info| {
        info.lines().find(|l| l.starts_with("MemAvailable:"))?.split_whitespace().nth(1)?.parse::<u64>().ok()
    });
    match available {
        Some(kib) if kib * 1024 < 16384 * 16384 * 120 => {}
        _ => {
            eprintln!("skipped: this machine may have the memory for a 16384x16384 render");
            return;
        }
    }
    let dir = scratch_dir("too-large");
    let out = dir.join("huge.png");
    let start = std::time::Instant::now();
    let run = rtgi(&["render", "--width", "16384", "--height", "16384", "-o", path_str(&out)]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("GiB of memory") && run.stderr.contains("--tile"), "{run:?}");
    assert!(start.elapsed() < std::time::Duration::from_secs(5), "{:?}", start.elapsed());
    assert!(!out.exists());
}

#[test]
fn trace_refuses_to_write_its_hits_over_its_rays() {
    let dir = scratch_dir("trace-over-rays");
    let rays = dir.join("rays.bin");
    let ray: Vec<u8> =
        [0.0f32, 0.0, 5.0, 0.0, 0.0, -1.0, 0.0, f32::INFINITY].iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(&rays, &ray).unwrap();
    let run = rtgi(&["trace", "scenes/cornell-box.toml", "--rays", path_str(&rays), "--out", path_str(&rays)]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("is --rays, which the command reads"), "{run:?}");
    assert_eq!(std::fs::read(&rays).unwrap(), ray);
}

/// A one-triangle OBJ in `dir/scene/` whose material's texture is `texture`.
fn textured_triangle(dir: &Path, texture: &str) -> std::path::PathBuf {
    let scene = dir.join("scene");
    std::fs::create_dir_all(&scene).unwrap();
    std::fs::write(scene.join("t.mtl"), format!("newmtl textured\nKd 1 1 1\nmap_Kd {texture}\n")).unwrap();
    let obj = "mtllib t.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0.5 1\nusemtl textured\nf 1/1 2/2 3/3\n";
    std::fs::write(scene.join("t.obj"), obj).unwrap();
    scene.join("t.obj")
}

fn write_png(path: &Path) {
    let mut image = rtgi_image::HdrImage::new(4, 4);
    image.pixels_mut().fill(rtgi_math::Vec3::new(0.2, 0.4, 0.8));
    image.write(path, &rtgi_image::ToneMap::default()).unwrap();
}

#[test]
fn a_texture_is_not_overwritten_by_the_render_that_reads_it() {
    let dir = scratch_dir("output-is-texture");
    let obj = textured_triangle(&dir, "wood.png");
    let texture = dir.join("scene/wood.png");
    write_png(&texture);
    let before = std::fs::read(&texture).unwrap();
    let run = rtgi(&["render", path_str(&obj), "-o", path_str(&texture), "--width", "8", "--height", "8"]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("is a file of the scene"), "{run:?}");
    assert_eq!(std::fs::read(&texture).unwrap(), before);
}

#[test]
fn a_texture_outside_the_scene_folder_is_read_only_with_allow_outside_scene() {
    let dir = scratch_dir("outside-scene");
    write_png(&dir.join("outside.png"));
    let obj = textured_triangle(&dir, "../outside.png");
    let out = dir.join("out.png");
    let args = ["render", path_str(&obj), "-o", path_str(&out), "--width", "8", "--height", "8"];
    let run = rtgi(&args);
    assert!(run.success, "{run:?}");
    assert!(run.stderr.contains("../outside.png") && run.stderr.contains("refusing"), "{run:?}");
    let trusted: Vec<&str> = args.iter().copied().chain(["--allow-outside-scene"]).collect();
    let run = rtgi(&trusted);
    assert!(run.success, "{run:?}");
    assert!(!run.stderr.contains("refusing"), "{run:?}");
}
