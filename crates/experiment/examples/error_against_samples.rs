//! The experiment `spp` in miniature: renders a small Cornell box at 1 to
//! 16 samples per pixel, measures each image's error against a reference of
//! many samples, and fits a power law to error against samples. Monte Carlo
//! error (MSE) falls as 1/spp with independent samples, and faster with the
//! default stratified ones, so the fitted exponent comes out at -1 or below.
//!
//! `cargo run -p rtgi-experiment --example error_against_samples --release`
//! (`rtgi experiment spp` is the full study, with timings, plots and a report.)

use rtgi_accel::AccelKind;
use rtgi_experiment::stats::PowerLaw;
use rtgi_image::compare;
use rtgi_render::{RenderSettings, default_camera, render};
use rtgi_scene::Scene;

fn main() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-box.toml");
    let scene = Scene::load(path.as_ref()).expect("the project's Cornell box loads");
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &AccelKind::Sah.default_params());
    let camera = default_camera(&scene, accel.as_ref(), 1.0);
    let base = RenderSettings { width: 16, height: 16, max_depth: 3, ..RenderSettings::default() };
    let image = |samples_per_pixel: u32, seed: u64| {
        let settings = RenderSettings { samples_per_pixel, seed, ..base.clone() };
        render(&scene, accel.as_ref(), &camera, &settings, &|_| {}).0
    };
    // The reference has a seed of its own, so that its noise is independent of the images'.
    let reference = image(256, 1_000);
    let mut points = Vec::new();
    for spp in [1, 2, 4, 8, 16] {
        // The mean squared error over four seeds, as the experiment averages its repeats.
        let seeds = 0..4u64;
        let mse = seeds
            .clone()
            .map(|seed| compare(&image(spp, seed), &reference).expect("same size").rmse.powi(2))
            .sum::<f64>()
            / seeds.count() as f64;
        println!("{spp:>3} spp: MSE {mse:.5}");
        points.push((f64::from(spp), mse));
    }
    let fit = PowerLaw::fit(&points).expect("five points with positive errors");
    println!("MSE ~ {:.4} * spp^{:.2} (independent samples: exponent -1)", fit.scale, fit.exponent);
    assert!(fit.exponent < -0.5, "error falls with samples");
}

#[test]
fn runs() {
    main();
}
