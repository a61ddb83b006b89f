//! End-to-end tests of the commands that expose the acceleration
//! structures: `rtgi trace`, `rtgi bench`, `rtgi bvh-boxes`, `rtgi heatmap`.

use super::{RTGI, path_str, rtgi};
use rtgi_accel::{Accel, LinearScan};
use rtgi_math::{Ray, Rng, Vec3};
use rtgi_render::rays::{primary_rays, uniform_sphere};
use rtgi_scene::Scene;
use rtgi_tests::{Run, scratch_dir, workspace_root};

const BOX: &str = "scenes/cornell-box.toml";

/// Camera rays, random rays from inside the box, and a ray that must miss
/// without trouble (an empty range). Rays with a NaN or a zero direction are
/// refused by `rtgi trace` (`cli_hostile.rs`), so they are not here.
fn test_rays(scene: &Scene) -> Vec<Ray> {
    let mut rays = primary_rays(&scene.cameras[0], 24, 24);
    let mut rng = Rng::new(5, 0);
    for _ in 0..500 {
        let origin = Vec3::new(rng.next_f32() * 550.0, rng.next_f32() * 540.0, rng.next_f32() * 550.0);
        let t_max = if rng.next_f32() < 0.5 { f32::INFINITY } else { rng.next_f32() * 300.0 };
        rays.push(Ray::with_range(origin, uniform_sphere(rng.next_f32(), rng.next_f32()), 0.0, t_max));
    }
    rays.push(Ray::with_range(Vec3::splat(100.0), Vec3::Y, 5.0, 1.0));
    rays
}

fn encode(rays: &[Ray]) -> Vec<u8> {
    rays.iter()
        .flat_map(|r| {
            [r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y, r.direction.z, r.t_min, r.t_max]
                .map(f32::to_le_bytes)
        })
        .flatten()
        .collect()
}

fn decode_hits(bytes: &[u8]) -> Vec<(f32, u32, f32, f32)> {
    bytes
        .chunks_exact(16)
        .map(|c| {
            let word = |i: usize| [c[i], c[i + 1], c[i + 2], c[i + 3]];
            (
                f32::from_le_bytes(word(0)),
                u32::from_le_bytes(word(4)),
                f32::from_le_bytes(word(8)),
                f32::from_le_bytes(word(12)),
            )
        })
        .collect()
}

#[test]
fn trace_writes_the_hits_of_every_variant_identically() {
    let dir = scratch_dir("trace");
    let scene = Scene::load(&workspace_root().join(BOX)).unwrap();
    let rays = test_rays(&scene);
    let rays_path = dir.join("rays.bin");
    std::fs::write(&rays_path, encode(&rays)).unwrap();
    let reference = LinearScan::new(&scene.triangle_positions(), rtgi_accel::Intersector::default());

    // `--grid 24`: the camera rays are a grid 24 wide, traced in tiles;
    // `--single-ray`: ray by ray through the single-ray query. Neither may
    // change the answers.
    let modes: [(&str, &[&str]); 3] = [("", &[]), ("-grid", &["--grid", "24"]), ("-single", &["--single-ray"])];
    for (accel, (mode, mode_args)) in rtgi_accel::AccelKind::ALL.iter().flat_map(|a| modes.map(|m| (a, m))) {
        for any_hit in [false, true] {
            let out = dir.join(format!("{accel}-{any_hit}{mode}.bin"));
            let mut args =
                vec!["trace", BOX, "--rays", path_str(&rays_path), "--out", path_str(&out), "--accel", accel.name()];
            if any_hit {
                args.push("--any-hit");
            }
            args.extend(mode_args);
            let run = rtgi(&args);
            assert!(run.success, "{run:?}");
            assert!(run.stderr.contains("Mrays/s") && run.stderr.contains("build"), "{}", run.stderr);
            let hits = decode_hits(&std::fs::read(&out).unwrap());
            assert_eq!(hits.len(), rays.len());
            for (ray, &(t, triangle, beta, gamma)) in rays.iter().zip(&hits) {
                if any_hit {
                    let expected = if reference.occluded(ray) { 0 } else { u32::MAX };
                    assert_eq!(triangle, expected, "{accel} any-hit {ray:?}");
                } else {
                    match reference.intersect(ray) {
                        Some(h) => assert_eq!((t, triangle, beta, gamma), (h.t, h.triangle, h.beta, h.gamma)),
                        None => assert_eq!((t, triangle), (f32::INFINITY, u32::MAX), "{accel} {ray:?}"),
                    }
                }
            }
        }
    }
    // Camera rays into the box hit something (the corners of the view pass
    // outside the open box); the ray with an empty range at the end misses.
    let hits = decode_hits(&std::fs::read(dir.join("sah-false.bin")).unwrap());
    let central = (4..20).flat_map(|y| (4..20).map(move |x| y * 24 + x));
    assert!(central.into_iter().all(|i| hits[i].1 != u32::MAX));
    assert_eq!(hits[hits.len() - 1].1, u32::MAX);

    // --stats counts the work per ray: a BVH tests its root at least.
    let out = dir.join("stats.bin");
    let run =
        rtgi(&["trace", BOX, "--rays", path_str(&rays_path), "--out", path_str(&out), "--accel", "bvh8", "--stats"]);
    assert!(run.success, "{run:?}");
    let stats = run.stderr.lines().find(|l| l.starts_with("stats")).unwrap_or_else(|| panic!("{}", run.stderr));
    let nodes: f64 = stats.split_whitespace().nth(1).and_then(|n| n.parse().ok()).unwrap_or_else(|| panic!("{stats}"));
    assert!(nodes >= 1.0 && stats.contains("triangle tests per ray"), "{stats}");
}

#[test]
fn trace_refuses_a_truncated_ray_file() {
    let dir = scratch_dir("trace-bad");
    let rays = dir.join("short.bin");
    std::fs::write(&rays, [0u8; 33]).unwrap();
    let out = dir.join("hits.bin");
    let run = rtgi(&["trace", BOX, "--rays", path_str(&rays), "--out", path_str(&out)]);
    assert!(!run.success);
    assert_eq!(run.stderr.trim().lines().count(), 1, "{}", run.stderr);
    assert!(run.stderr.contains("short.bin") && run.stderr.contains("multiple of 32"), "{}", run.stderr);
    assert!(!out.exists());
    let missing = rtgi(&["trace", BOX, "--rays", path_str(&dir.join("none.bin")), "--out", path_str(&out)]);
    assert!(!missing.success && missing.stderr.contains("none.bin"), "{missing:?}");
}

#[test]
fn bench_measures_every_variant_and_writes_json() {
    let dir = scratch_dir("bench");
    let json = dir.join("bench.json");
    let run = rtgi(&[
        "bench",
        "--width",
        "16",
        "--height",
        "16",
        "--rays",
        "500",
        "--repeats",
        "1",
        "--json",
        path_str(&json),
    ]);
    assert!(run.success, "{run:?}");
    for kind in rtgi_accel::AccelKind::ALL {
        assert!(run.stdout.lines().any(|l| l.starts_with(kind.name())), "{kind} missing from\n{}", run.stdout);
    }
    let text = std::fs::read_to_string(&json).unwrap();
    // Each variant (and peer built in, with the embree feature) has one report.
    let variants = rtgi_accel::AccelKind::ALL.len() + rtgi_accel::AccelKind::PEERS.len();
    assert_eq!(text.matches("\"build_ms_all_threads\"").count(), variants, "{text}");
    for field in ["sah_cost", "mrays_1_thread", "nodes_visited_per_ray", "speedup_vs_linear"] {
        assert!(text.contains(field), "{field} missing");
    }
    // Every intersector with every traversal, beside their failure rates.
    let combinations = rtgi_accel::Intersector::ALL.len() * rtgi_accel::Traversal::ALL.len();
    assert_eq!(text.matches("\"closed_mesh_escapes\"").count(), combinations, "{text}");
    assert!(run.stdout.contains("What accuracy costs"), "{}", run.stdout);
    // The default, watertight and robust, lets nothing through.
    let default_row = run.stdout.lines().find(|l| l.starts_with("watertight       robust")).expect("default row");
    assert_eq!(default_row.matches("0 (0.0000%)").count(), 2, "{default_row}");
}

#[test]
fn bvh_boxes_are_written_as_obj_groups() {
    let dir = scratch_dir("boxes");
    let out = dir.join("boxes.obj");
    let run = rtgi(&["bvh-boxes", "-o", path_str(&out), "--levels", "0,1", "--accel", "sah"]);
    assert!(run.success, "{run:?}");
    let obj = std::fs::read_to_string(&out).unwrap();
    assert!(obj.contains("g level_0") && obj.contains("g level_1"));
    // The root and its two children: 3 boxes of 8 corners and 6 faces.
    assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), 24);
    assert_eq!(obj.lines().filter(|l| l.starts_with("f ")).count(), 18);
    // The file is a valid OBJ that the scene loader reads back: 12 triangles a box.
    let boxes = Scene::load(&out).unwrap();
    assert_eq!(boxes.triangles.len(), 36);
    // A wide BVH: one root box and, below it, up to eight children.
    let wide = dir.join("wide.obj");
    let run = rtgi(&["bvh-boxes", "-o", path_str(&wide), "--levels", "0,1", "--accel", "bvh8"]);
    assert!(run.success, "{run:?}");
    let obj = std::fs::read_to_string(&wide).unwrap();
    let level_1 = obj.split("g level_1").nth(1).expect("a level-1 group");
    let children = level_1.lines().filter(|l| l.starts_with("v ")).count() / 8;
    assert!((2..=8).contains(&children), "{children} children");
    let linear = rtgi(&["bvh-boxes", "-o", path_str(&dir.join("l.obj")), "--accel", "linear"]);
    assert!(!linear.success && linear.stderr.contains("linear"), "{linear:?}");
}

#[test]
fn heatmap_counts_nodes_per_pixel() {
    let dir = scratch_dir("heatmap");
    let exr = dir.join("cost.exr");
    let run = rtgi(&["heatmap", "-o", path_str(&exr), "--width", "20", "--height", "20"]);
    assert!(run.success, "{run:?}");
    let counts = rtgi_image::HdrImage::read_exr(&exr).unwrap();
    // Every ray tests at least the root's box; inside the closed box every camera ray hits.
    assert!(counts.pixels().iter().all(|p| p.x >= 1.0 && p.z == 1.0));
    let png = dir.join("cost.png");
    let run = rtgi(&["heatmap", "-o", path_str(&png), "--width", "20", "--height", "10", "--triangles"]);
    assert!(run.success, "{run:?}");
    assert_eq!(image::open(&png).unwrap().to_rgb8().dimensions(), (20, 10));
}

/// Without `-o`, the commands that write one file name it after their
/// input, in the current folder; `trace --out` is an alias of `-o`.
#[test]
fn outputs_default_to_names_after_the_input() {
    let dir = scratch_dir("output-defaults");
    let scene = workspace_root().join(BOX);
    let in_dir = |args: &[&str]| -> Run {
        std::process::Command::new(RTGI).args(args).current_dir(&dir).output().expect("rtgi runs").into()
    };
    for (args, written) in [
        (vec!["heatmap", path_str(&scene), "--width", "8", "--height", "8"], "cornell-box.heatmap.png"),
        (vec!["bvh-boxes", path_str(&scene), "--levels", "0"], "cornell-box.boxes.obj"),
        (vec!["rays", path_str(&scene), "--width", "4", "--height", "4"], "cornell-box.rays.bin"),
        (vec!["trace", path_str(&scene), "--rays", "cornell-box.rays.bin"], "cornell-box.rays.hits.bin"),
        (vec!["trace", path_str(&scene), "--rays", "cornell-box.rays.bin", "--out", "alias.bin"], "alias.bin"),
    ] {
        let run = in_dir(&args);
        assert!(run.success, "{args:?}: {run:?}");
        assert!(dir.join(written).is_file(), "{args:?}: no {written}");
    }
    assert_eq!(
        std::fs::read(dir.join("alias.bin")).unwrap(),
        std::fs::read(dir.join("cornell-box.rays.hits.bin")).unwrap()
    );
}

#[test]
fn info_describes_scenes_as_text_and_json() {
    let run = rtgi(&["info"]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("triangles   32") && run.stdout.contains("cameras     1"), "{}", run.stdout);
    let Some(lamp) = rtgi_tests::shared_scene("gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf") else { return };
    let run = rtgi(&["info", path_str(&lamp), "--json"]);
    assert!(run.success, "{run:?}");
    assert_eq!(run.stdout.matches("\"intensity\"").count(), 5, "{}", run.stdout);
    assert!(run.stdout.contains("\"extensions_used\"") && run.stdout.contains("KHR_lights_punctual"));
    let Some(transmission) = rtgi_tests::shared_scene("gltf/TransmissionTest/glTF/TransmissionTest.gltf") else {
        return;
    };
    let run = rtgi(&["info", path_str(&transmission)]);
    assert!(run.success, "{run:?}");
    // Metadata: listed, not warned about.
    assert!(!run.stderr.contains("KHR_xmp"), "{run:?}");
    assert!(run.stdout.lines().any(|l| l.contains("KHR_xmp") && l.contains("not visual")), "{}", run.stdout);
}

#[test]
fn verify_checks_the_built_in_adversarial_scenes_and_writes_json() {
    let dir = scratch_dir("verify");
    let json = dir.join("verify.json");
    let run = rtgi(&["verify", "--rays", "20000", "--json", path_str(&json)]);
    assert!(run.success, "{}", run.stderr);
    for kind in [
        "random",
        "vertex",
        "edge",
        "axis-parallel",
        "secondary",
        "silhouette",
        "camera",
        "behind-origin",
        "inside",
        "through-edge",
    ] {
        assert!(run.stdout.lines().any(|l| l.starts_with(kind)), "no row for {kind}:\n{}", run.stdout);
    }
    for structure in ["linear", "object-median", "spatial-median", "sah", "sah-sweep", "bvh4", "bvh8", "sbvh", "sbvh8"]
    {
        assert!(run.stdout.lines().any(|l| l.starts_with(structure)), "no row for {structure}:\n{}", run.stdout);
    }
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let structures = report["structures"].as_array().unwrap();
    // Ours (the wide BVHs twice: one ray at a time and in batches) and the
    // peers built in (Embree, with the embree feature), whose differences
    // are reported but are not failures.
    let all = rtgi_accel::AccelKind::ALL;
    let ours_expected = all.len() + all.iter().filter(|k| k.node_width().is_some_and(|w| w > 2)).count();
    assert_eq!(structures.len(), ours_expected + rtgi_accel::AccelKind::PEERS.len());
    assert!(
        structures
            .iter()
            .any(|s| s["structure"].as_str().is_some_and(|n| n.starts_with("bvh8") && n.ends_with("batch")))
    );
    let mut ours = structures.iter().filter(|s| s["peer"] == false);
    assert_eq!(ours.clone().count(), ours_expected);
    assert!(ours.all(|s| s["tally"]["closest_disagreements"] == 0 && s["tally"]["leaks"] == 0));
}

#[test]
fn verify_fails_when_a_structure_is_not_exact() {
    // The fast slab test drops boxes that rays graze, and the NaN of an
    // origin on a box plane can drop boxes too: on the adversarial scenes
    // it disagrees with the linear scan, and verify must say so.
    let run = rtgi(&["verify", "--rays", "20000", "--accel", "sah", "--traversal", "fast"]);
    assert!(!run.success, "{}", run.stdout);
    assert!(run.stderr.contains("do not all answer exactly"), "{}", run.stderr);
}

#[test]
fn verify_checks_a_scene_file() {
    let run = rtgi(&["verify", BOX, "--rays", "5000", "--exhaustive", "--accel", "sah"]);
    assert!(run.success, "{}", run.stderr);
    assert!(run.stdout.contains("sah (leaf 16, 16 bins, watertight)"), "{}", run.stdout);
    assert!(run.stdout.contains("moller-trumbore"), "{}", run.stdout);
}
