//! Path regularisation (`rtgi render --filter-glossy`, Cycles' "filter
//! glossy"): after a diffuse bounce, mirrors, glass and narrow lobes are
//! widened so that light sampling finds the caustics they bring. It must
//! cut the variance of caustics, keep most of their light, leave a scene
//! without sharp lobes bit for bit as it was, and say in the plan when it
//! is on.

use rtgi_accel::{Accel, AccelKind, BuildParams};
use rtgi_image::HdrImage;
use rtgi_math::luminance;
use rtgi_render::{EffectPlan, FilterGlossy, RenderSettings, render};
use rtgi_scene::{Camera, Scene};
use rtgi_tests::workspace_root;

/// A project scene with its camera.
fn project_scene(name: &str) -> (Scene, Box<dyn Accel>, Camera) {
    let scene = Scene::load(&workspace_root().join("scenes").join(name)).expect("the project's scene loads");
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = scene.cameras[0];
    (scene, accel, camera)
}

fn settings(threshold: Option<f32>, seed: u64) -> RenderSettings {
    let filter_glossy = threshold.map(FilterGlossy::all_lobes);
    RenderSettings { width: 48, height: 48, samples_per_pixel: 16, seed, filter_glossy, ..RenderSettings::default() }
}

/// The mean image's brightness and the variance of a render about it
/// (per pixel, of luminance), over `seeds` renders.
fn brightness_and_variance(images: &[HdrImage]) -> (f64, f64) {
    let pixels = images[0].pixels().len();
    let n = images.len() as f64;
    let (mut brightness, mut variance) = (0.0, 0.0);
    for p in 0..pixels {
        let values: Vec<f64> = images.iter().map(|image| luminance(image.pixels()[p]) as f64).collect();
        let mean = values.iter().sum::<f64>() / n;
        brightness += mean;
        variance += values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    }
    (brightness / pixels as f64, variance / pixels as f64)
}

#[test]
fn widening_sharp_lobes_after_a_diffuse_bounce_cuts_the_caustics_variance_and_keeps_their_light() {
    let (scene, accel, camera) = project_scene("caustics.toml");
    let seeds = 0..8u64;
    let measure = |filter: Option<f32>| {
        let images: Vec<HdrImage> = seeds
            .clone()
            .map(|seed| render(&scene, accel.as_ref(), &camera, &settings(filter, seed), &|_| {}).0)
            .collect();
        brightness_and_variance(&images)
    };
    let (exact_brightness, exact_variance) = measure(None);
    let (brightness, variance) = measure(Some(1.0));
    eprintln!(
        "caustics box, 16 spp, 8 seeds: exact brightness {exact_brightness:.4}, variance {exact_variance:.5}; \
         --filter-glossy 1: {brightness:.4}, {variance:.5}"
    );
    assert!(variance < 0.5 * exact_variance, "variance {variance} regularised against {exact_variance} exact");
    let ratio = brightness / exact_brightness;
    assert!((0.9..=1.02).contains(&ratio), "the regularised image is {ratio:.3} times as bright as the exact one");
}

#[test]
fn a_scene_without_sharp_lobes_is_rendered_bit_for_bit_as_without_it_and_the_plan_says_when_it_is_on() {
    let (scene, accel, camera) = project_scene("cornell-box.toml");
    let exact = render(&scene, accel.as_ref(), &camera, &settings(None, 3), &|_| {}).0;
    let filtered = render(&scene, accel.as_ref(), &camera, &settings(Some(1.0), 3), &|_| {}).0;
    assert!(exact.pixels() == filtered.pixels(), "a diffuse box changed under --filter-glossy");
    assert_eq!(EffectPlan::new(&scene, &settings(Some(1.0), 0)).filter_glossy, None);

    let (caustics, _, _) = project_scene("caustics.toml");
    let plan = EffectPlan::new(&caustics, &settings(Some(1.0), 0));
    assert_eq!(plan.filter_glossy, Some(FilterGlossy::all_lobes(1.0)));
    assert!(plan.to_string().contains("filter-glossy"), "{plan}");
    assert_eq!(EffectPlan::new(&caustics, &settings(None, 0)).filter_glossy, None);
}

#[test]
fn denoised_previews_widen_mirrors_and_glass_and_exact_outputs_do_not() {
    const RTGI: &str = env!("CARGO_BIN_EXE_rtgi-under-test");
    let dir = rtgi_tests::scratch_dir("regularisation-cli");
    let scene = workspace_root().join("scenes/caustics.toml");
    let scene = scene.to_str().unwrap();
    let render = |output: &str, extra: &[&str]| {
        let out = dir.join(output);
        let mut args =
            vec!["render", scene, "-o", out.to_str().unwrap(), "--width", "24", "--height", "24", "--spp", "2"];
        args.extend_from_slice(extra);
        let run = rtgi_tests::run_cli(RTGI, &args);
        assert!(run.success, "{run:?}");
        run.stdout
    };
    let preview = render("a.png", &[]);
    assert!(preview.contains("filter-glossy") && preview.contains("mirrors and smooth glass are widened"), "{preview}");
    assert!(!render("a.exr", &[]).contains("are widened"), "EXR output stays exact");
    assert!(!render("b.png", &["--filter-glossy", "0"]).contains("are widened"));
    assert!(!render("c.png", &["--denoise", "off"]).contains("are widened"), "an undenoised PNG stays exact");
    let all = render("d.exr", &["--filter-glossy", "2"]);
    assert!(all.contains("below 2, mirrors, glass and sharp highlights are widened"), "{all}");
}
