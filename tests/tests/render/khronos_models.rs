//! Khronos' glTF test models (`tests/data/khronos/`) rendered, checked for
//! what their screenshots make checkable: unlit surfaces show their colour
//! unshaded, and each clear-coated sample differs from its uncoated twin.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_image::HdrImage;
use rtgi_math::Vec3;
use rtgi_render::{Effect, EffectOverrides, RenderSettings, render};
use rtgi_scene::{Camera, Scene};
use rtgi_tests::workspace_root;

fn khronos(name: &str) -> Scene {
    let path = workspace_root().join(format!("tests/data/khronos/{name}/glTF/{name}.gltf"));
    let scene = Scene::load(&path).unwrap();
    assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
    scene
}

fn render_view(scene: &Scene, camera: &Camera, settings: &RenderSettings) -> HdrImage {
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    render(scene, accel.as_ref(), camera, settings, &|_| {}).0
}

/// UnlitTest: an orange and a blue object, KHR_materials_unlit, lit by the
/// default sky and sun. Every pixel wholly on an object is its base colour,
/// exactly; shaded instead (the control: the same scene with `unlit`
/// cleared), none is.
#[test]
fn unlit_test_objects_show_their_base_colour_unshaded() {
    let scene = khronos("UnlitTest");
    let colours: Vec<Vec3> = scene.materials.iter().map(|m| m.base_color).collect();
    assert!(scene.materials.iter().all(|m| m.unlit), "{:?}", scene.materials);
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 6.0), Vec3::ZERO, Vec3::Y, 0.7);
    let settings = RenderSettings { width: 48, height: 32, samples_per_pixel: 4, ..RenderSettings::default() };
    let exact = |image: &HdrImage| {
        let on = |c: Vec3| image.pixels().iter().filter(|p| (**p - c).abs().max_element() < 1e-5).count();
        colours.iter().map(|&c| on(c)).collect::<Vec<_>>()
    };
    let unlit = exact(&render_view(&scene, &camera, &settings));
    // Each object covers a sixth of the view or so.
    assert!(unlit.iter().all(|&n| n > 48 * 32 / 20), "pixels of exactly each base colour: {unlit:?}");
    let mut shaded = scene.clone();
    for m in &mut shaded.materials {
        m.unlit = false;
    }
    let lit = exact(&render_view(&shaded, &camera, &settings));
    assert!(lit.iter().all(|&n| n == 0), "shaded, pixels of exactly each base colour: {lit:?}");
}

/// ClearCoatTest: rows of samples, each an uncoated base (left), the same
/// with a clear coat (middle), and the coat alone (right). The coated
/// sample of every row differs from its base (a smooth coat reflects the
/// sky; a textured, rough or normal-mapped one less or differently); with
/// the clearcoat effect left out of the plan, the two are the same image.
#[test]
fn clear_coat_test_coated_samples_differ_from_their_uncoated_twins() {
    let scene = khronos("ClearCoatTest");
    // (row, its height): simple, partial (a coat texture), roughness
    // variations (a roughness texture), coat normals, shared normals.
    let rows =
        [("simple", 5.25), ("partial", 3.15), ("roughness", 1.05), ("coat normals", -5.25), ("shared normals", -3.15)];
    let settings = RenderSettings { width: 24, height: 24, samples_per_pixel: 16, ..RenderSettings::default() };
    let without_coat = RenderSettings {
        effects: EffectOverrides { off: [Effect::Clearcoat].into_iter().collect(), ..EffectOverrides::default() },
        ..settings.clone()
    };
    // A camera in front of the sample at x, narrow enough to see it alone.
    let view = |x: f32, y: f32| Camera::look_at(Vec3::new(x, y, 8.0), Vec3::new(x, y, 0.0), Vec3::Y, 0.22);
    let mean = |image: &HdrImage| image.pixels().iter().fold(Vec3::ZERO, |s, p| s + *p) / image.pixels().len() as f32;
    // Of the views' mean colours, relative: the per-pixel noise of 16
    // samples averages out over the view.
    let difference = |a: &HdrImage, b: &HdrImage| (mean(a) - mean(b)).abs().element_sum() / mean(b).element_sum();
    for (row, y) in rows {
        let (base, coated) = (view(-2.1, y), view(0.0, y));
        let with_coat = render_view(&scene, &coated, &settings);
        let coat_left_out = render_view(&scene, &coated, &without_coat);
        let uncoated_twin = render_view(&scene, &base, &settings);
        // The coat changes the coated sample: it reflects the sky (the
        // same sample, seen the same way, with and without its coat).
        let by_coat = difference(&with_coat, &coat_left_out);
        // Without its coat the sample looks like its uncoated twin (they
        // are separate meshes, so only alike, within 8% measured).
        let twins = difference(&coat_left_out, &uncoated_twin);
        println!("{row}: coat {by_coat}, twins {twins}, coated vs twin {}", difference(&with_coat, &uncoated_twin));
        assert!(by_coat > 0.1, "{row}: the coat changes the sample by only {by_coat}");
        assert!(twins < 0.1, "{row}: without its coat the sample differs from its twin by {twins}");
        assert!(difference(&with_coat, &uncoated_twin) > 0.1, "{row}: the coated sample looks like its uncoated twin");
    }
}
