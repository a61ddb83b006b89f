//! Renders are bit-identical whatever the number of threads.

use rtgi_accel::{AccelKind, BuildParams};
use rtgi_render::{PixelSampler, RenderSettings, render};
use rtgi_scene::Scene;

#[test]
fn images_are_identical_at_one_two_and_three_threads() {
    let scene = Scene::load(&rtgi_tests::workspace_root().join("scenes/cornell-box.toml")).unwrap();
    let accel = AccelKind::Linear.build(&scene.triangle_positions(), &BuildParams::default());
    let settings = RenderSettings {
        width: 37,
        height: 23,
        samples_per_pixel: 5,
        sampler: PixelSampler::Uniform,
        seed: 99,
        ..RenderSettings::default()
    };
    let images: Vec<_> = [1, 2, 3]
        .into_iter()
        .map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| render(&scene, accel.as_ref(), &scene.cameras[0], &settings, &|_| {}).0)
        })
        .collect();
    let bits = |img: &rtgi_image::HdrImage| {
        img.pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
    };
    assert_eq!(bits(&images[0]), bits(&images[1]));
    assert_eq!(bits(&images[0]), bits(&images[2]));
}
