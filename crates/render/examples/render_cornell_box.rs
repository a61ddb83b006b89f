//! Renders the project's Cornell box, path traced, to a PNG in the
//! temporary folder: load, build a BVH, take the scene's camera, render,
//! tone-map and write.
//!
//! `cargo run -p rtgi-render --example render_cornell_box --release`

use rtgi_accel::AccelKind;
use rtgi_image::ToneMap;
use rtgi_render::{RenderSettings, default_camera, render};
use rtgi_scene::Scene;

fn main() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-box.toml");
    let scene = Scene::load(path.as_ref()).expect("the project's Cornell box loads");
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &AccelKind::Sah.default_params());
    // Small and few samples, so that the example runs in a moment as a test;
    // the default settings are 512 x 512 at 16 stratified samples per pixel.
    let settings = RenderSettings { width: 48, height: 48, samples_per_pixel: 4, ..RenderSettings::default() };
    let camera = default_camera(&scene, accel.as_ref(), settings.width as f32 / settings.height as f32);
    let (image, stats) = render(&scene, accel.as_ref(), &camera, &settings, &|_| {});
    let output = std::env::temp_dir().join("rtgi-cornell-box.png");
    image.write(&output, &ToneMap::default()).expect("the temporary folder is writable");
    println!(
        "{} x {} at {} spp: {} rays in {:.1} ms, mean radiance {}; wrote {}",
        stats.width,
        stats.height,
        stats.samples_per_pixel,
        stats.rays,
        stats.render_ms,
        image.mean(),
        output.display()
    );
    assert!(image.mean().min_element() > 0.0, "the box is lit");
}

#[test]
fn runs() {
    main();
}
