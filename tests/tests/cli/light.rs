//! End-to-end tests of the light-transport options of `rtgi render`,
//! `rtgi info`, `rtgi compare` and `rtgi bench-effects`.

use super::{path_str, rtgi};
use rtgi_image::{HdrImage, ToneMap};
use rtgi_math::Vec3;
use rtgi_tests::scratch_dir;

#[test]
fn path_tracing_prints_its_plan_and_writes_aovs() {
    let dir = scratch_dir("path-aov");
    let out = dir.join("box.png");
    let args = ["render", "-o", path_str(&out), "--width", "40", "--height", "32", "--spp", "4"];
    let run = rtgi(&[&args[..], &["--sampler", "center", "--aov", "normal,depth,albedo,position,cost"]].concat());
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("plan: path integrator, up to 8 bounces"), "{}", run.stdout);
    assert!(run.stdout.contains("+ direct-light") && run.stdout.contains("- textures"), "{}", run.stdout);
    assert!(out.is_file());
    let normal = HdrImage::read_exr(&dir.join("box.normal.exr")).unwrap();
    let depth = HdrImage::read_exr(&dir.join("box.depth.exr")).unwrap();
    assert_eq!((normal.width(), normal.height()), (40, 32));
    // The camera looks into the open box: most pixels hit it (depth 0 is a
    // miss), and above the blocks the back wall faces the camera (normal
    // along -z), 800 + 559 mm away.
    let wall = normal.get(20, 8);
    assert!((wall.length() - 1.0).abs() < 1e-3 && wall.z < -0.99, "{wall}");
    let hits = depth.pixels().iter().filter(|d| d.x > 500.0).count();
    let misses = depth.pixels().iter().filter(|d| d.x == 0.0).count();
    assert!(hits > 32 * 40 * 3 / 4 && hits + misses == 32 * 40, "{hits} hits, {misses} misses");
    let distance = depth.get(20, 8).x;
    assert!((1359.0..1450.0).contains(&distance), "{distance}");
    for name in ["albedo", "position", "cost"] {
        assert!(dir.join(format!("box.{name}.exr")).is_file(), "{name}");
    }
}

#[test]
fn lights_and_environments_from_the_command_line() {
    let dir = scratch_dir("cli-lights");
    let sky = dir.join("sky.exr");
    let mut image = HdrImage::new(8, 4);
    for (i, p) in image.pixels_mut().iter_mut().enumerate() {
        *p = Vec3::new(0.2, 0.3, 0.5 + i as f32 * 0.01);
    }
    image.write(&sky, &ToneMap::default()).unwrap();
    let out = dir.join("lit.exr");
    let run = rtgi(&[
        "render",
        "-o",
        path_str(&out),
        "--width",
        "24",
        "--height",
        "24",
        "--spp",
        "2",
        "--light",
        "point:278,500,279:40000",
        "--light",
        "spot:278,540,279:0,-1,0:90000:20:30:1,0.9,0.8",
        "--light",
        "directional:0,-1,0.2:2",
        "--environment",
        path_str(&sky),
        "--integrator",
        "direct",
    ]);
    assert!(run.success, "{run:?}");
    assert!(
        run.stdout.contains("shadow rays towards 3 lights, 2 emissive triangles, the environment"),
        "{}",
        run.stdout
    );
    let lit = HdrImage::read_exr(&out).unwrap();
    assert!(lit.mean().max_element() > 0.0);

    // Bad input: clear errors, usage errors exit with 2, nothing written.
    let bad = dir.join("bad.png");
    for (option, value, message) in [
        ("--light", "point:1,2:5", "expected three finite numbers"),
        ("--light", "lamp:1,2,3:5", "expected point:"),
        ("--light", "spot:0,0,0:0,-1,0:5:40:30", "inner <= outer"),
        ("--light", "directional:0,0,0:1", "the direction is zero"),
        ("--environment", "sky.hdr", "an .exr or .floats file"),
        ("--effects", "+shiny", "unknown effect 'shiny'"),
        ("--effects", "glossy", "+effect"),
        (
            "--integrator",
            "photon-mapping",
            "invalid value 'photon-mapping' for '--integrator <INTEGRATOR>' (possible values: primary,",
        ),
    ] {
        let run = rtgi(&["render", "-o", path_str(&bad), &format!("{option}={value}")]);
        assert_eq!(run.code, Some(2), "{option} {value}: {run:?}");
        assert!(run.stderr.contains(message), "{option} {value}: {}", run.stderr);
    }
    let missing = dir.join("missing.exr");
    let run = rtgi(&["render", "-o", path_str(&bad), "--environment", path_str(&missing)]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("missing.exr"), "{}", run.stderr);
    let not_exr = dir.join("fake.exr");
    std::fs::write(&not_exr, b"not an image").unwrap();
    let run = rtgi(&["render", "-o", path_str(&bad), "--environment", path_str(&not_exr)]);
    assert_eq!(run.code, Some(1), "{run:?}");
    assert!(run.stderr.contains("fake.exr"), "{}", run.stderr);
    assert!(!bad.exists());
    let run = rtgi(&["render", "-o", path_str(&bad), "--aov", "path"]);
    assert!(!run.success && run.stderr.contains("invalid value 'path' for '--aov <AOV>'"), "{run:?}");
}

#[test]
fn info_prints_the_plan_and_compare_measures_errors() {
    let run = rtgi(&["info", "--effects=+glossy,-indirect"]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("plan: path integrator"), "{}", run.stdout);
    assert!(run.stdout.contains("+!glossy") && run.stdout.contains("-!indirect"), "{}", run.stdout);
    let run = rtgi(&["info", "--json", "--integrator", "primary"]);
    assert!(run.success && run.stdout.contains("\"integrator\": \"primary\""), "{}", run.stdout);

    let dir = scratch_dir("compare");
    let (a, b, small) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("small.exr"));
    let mut image = HdrImage::new(4, 4);
    image.write(&a, &ToneMap::default()).unwrap();
    image.set(1, 2, Vec3::new(2.0, 0.0, 0.0));
    image.write(&b, &ToneMap::default()).unwrap();
    HdrImage::new(2, 2).write(&small, &ToneMap::default()).unwrap();
    let run = rtgi(&["compare", path_str(&b), path_str(&a)]);
    assert!(run.success, "{run:?}");
    assert!(run.stdout.contains("max abs       2.000000 at pixel (1, 2)"), "{}", run.stdout);
    let run = rtgi(&["compare", path_str(&small), path_str(&a)]);
    assert_eq!(run.code, Some(1));
    assert!(run.stderr.contains("small.exr") && run.stderr.contains("2x2"), "{}", run.stderr);
}

#[test]
fn bench_effects_reports_every_reversed_decision() {
    let dir = scratch_dir("bench-effects");
    let json = dir.join("effects.json");
    let args = ["bench-effects", "--width", "24", "--height", "24", "--spp", "1", "--repeats", "1"];
    let run = rtgi(&[&args[..], &["--json", path_str(&json)]].concat());
    assert!(run.success, "{run:?}");
    for row in ["plan", "-emission", "-direct-light", "-indirect", "+glossy", "+textures", "+alpha"] {
        assert!(run.stdout.lines().any(|l| l.starts_with(row)), "no row {row}: {}", run.stdout);
    }
    // Omitted effects forced on leave the image exactly as planned.
    for line in run.stdout.lines().filter(|l| l.starts_with('+') && !l.contains(':')) {
        assert!(line.trim_end().ends_with("0.000e0      0.000e0"), "{line}");
    }
    let report = std::fs::read_to_string(&json).unwrap();
    assert!(report.contains("\"relative_time\""), "{report}");
}
