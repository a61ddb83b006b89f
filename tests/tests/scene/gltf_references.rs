//! Renders of glTF sample models compared with small reference images kept
//! in `tests/references/`, with a tolerance: textures, emission and alpha
//! cut-outs must stay where they are.
//!
//! The references were rendered by rtgi and looked at; after an intended
//! change of the images, regenerate them with
//! `RTGI_BLESS=1 cargo test -p rtgi-tests --test scene gltf_references` and look
//! at them again before committing.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_image::ToneMap;
use rtgi_render::{Integrator, PixelSampler, RenderSettings, frame_scene, render};
use rtgi_scene::Scene;
use rtgi_tests::{shared_scene, workspace_root};

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

fn render_model(relative: &str) -> Option<Vec<u8>> {
    let path = shared_scene(relative)?;
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let camera = scene
        .cameras
        .first()
        .copied()
        .unwrap_or_else(|| frame_scene(&scene, accel.as_ref(), 40f32.to_radians(), aspect));
    let settings = RenderSettings {
        width: WIDTH,
        height: HEIGHT,
        samples_per_pixel: 8,
        sampler: PixelSampler::Uniform,
        seed: 1,
        integrator: Integrator::Primary,
        ..RenderSettings::default()
    };
    let (image, _) = render(&scene, accel.as_ref(), &camera, &settings, &|_| {});
    Some(image.to_srgb8(&ToneMap::default()))
}

fn compare(name: &str, relative: &str) {
    let Some(rendered) = render_model(relative) else { return };
    let reference_path = workspace_root().join("tests/references").join(format!("{name}.png"));
    if std::env::var_os("RTGI_BLESS").is_some() {
        image::save_buffer(&reference_path, &rendered, WIDTH, HEIGHT, image::ExtendedColorType::Rgb8).unwrap();
        eprintln!("wrote {}", reference_path.display());
        return;
    }
    let reference = image::open(&reference_path)
        .unwrap_or_else(|e| panic!("{}: {e} (regenerate with RTGI_BLESS=1)", reference_path.display()))
        .to_rgb8();
    assert_eq!(reference.dimensions(), (WIDTH, HEIGHT));
    let differences: Vec<u32> =
        rendered.iter().zip(reference.as_raw()).map(|(&a, &b)| (a as i32 - b as i32).unsigned_abs()).collect();
    let mean = differences.iter().sum::<u32>() as f64 / differences.len() as f64;
    let large = differences.iter().filter(|&&d| d > 24).count() as f64 / differences.len() as f64;
    // A mean within 2 of 255 and few channels off by more than 24: small
    // shading changes pass; a lost texture, emission or cut-out does not.
    assert!(
        mean < 2.0 && large < 0.02,
        "{name}: mean difference {mean:.2}, {:.2}% of channels off by > 24",
        large * 100.0
    );
}

#[test]
fn damaged_helmet_matches_its_reference() {
    compare("damaged-helmet", "gltf/DamagedHelmet/glTF/DamagedHelmet.gltf");
}

#[test]
fn box_textured_matches_its_reference() {
    compare("box-textured", "gltf/BoxTextured/glTF/BoxTextured.gltf");
}

#[test]
fn alpha_blend_mode_test_matches_its_reference() {
    compare("alpha-blend-mode-test", "gltf/AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf");
}

#[test]
fn alpha_masks_cut_holes_that_opaque_rendering_fills() {
    let Some(path) = shared_scene("gltf/AlphaBlendModeTest/glTF/AlphaBlendModeTest.gltf") else { return };
    let scene = Scene::load(&path).unwrap();
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = frame_scene(&scene, accel.as_ref(), 20f32.to_radians(), 2.0);
    let settings = RenderSettings {
        width: 200,
        height: 100,
        samples_per_pixel: 1,
        sampler: PixelSampler::Center,
        ..RenderSettings::default()
    };
    let (with_alpha, _) = render(&scene, accel.as_ref(), &camera, &settings, &|_| {});
    let mut opaque_scene = scene.clone();
    opaque_scene.materials.iter_mut().for_each(|m| m.alpha_mode = rtgi_scene::AlphaMode::Opaque);
    let (opaque, _) = render(&opaque_scene, accel.as_ref(), &camera, &settings, &|_| {});
    let changed = with_alpha.pixels().iter().zip(opaque.pixels()).filter(|(a, b)| (**a - **b).length() > 0.05).count();
    // The masked and blended panels show the wall behind them through their holes.
    assert!(changed > 400, "only {changed} pixels differ between masked and opaque renders");
}
