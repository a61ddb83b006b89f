//! The path tracer converges to a high-sample reference of the Cornell box
//! (../shared/scenes/cornell-box/CornellBox-Original.obj), compared with
//! statistical tolerances that follow from the renders' own noise.
//!
//! The reference (`tests/references/cornell-box-path.exr`, 64×64, 16,384
//! samples per pixel) is rendered by this file; after an intended change of
//! the light transport, regenerate it with
//!
//! ```text
//! RTGI_BLESS=1 cargo test --release -p rtgi-tests --test render cornell_reference
//! ```
//!
//! and look at it (and at a full-size render) before committing.
//!
//! The test renders 16 independent images of 16 samples per pixel (seeds
//! 1 to 16). Their spread gives each pixel's standard error, so the
//! tolerance is exact where the image is smooth and loose where it is
//! noisy, and it is stated in standard deviations: z-scores of pixels, of
//! 8×8 blocks and of the whole image. The seeds are fixed, so the test is
//! deterministic; the bounds are wide enough (about 5σ) that a legitimate
//! change of the random numbers will not trip them. With 256 samples per
//! pixel, 5σ is about 0.7% of the whole image's brightness and 6% of an
//! 8×8 block's: biases larger than that fail.

use rtgi_image::{HdrImage, ToneMap};
use rtgi_render::PixelSampler;
use rtgi_scene::Scene;
use rtgi_tests::{CORNELL_SIZE as SIZE, render_cornell_box, shared_scene, workspace_root};

const REFERENCE_SPP: u32 = 16_384;
const RUNS: u32 = 16;
const RUN_SPP: u32 = 16;

fn render_box(scene: &Scene, samples_per_pixel: u32, seed: u64) -> HdrImage {
    render_cornell_box(scene, samples_per_pixel, PixelSampler::Stratified, seed)
}

#[test]
fn path_traced_cornell_box_converges_to_its_reference() {
    let Some(path) = shared_scene("cornell-box/CornellBox-Original.obj") else { return };
    let scene = Scene::load(&path).unwrap();
    let reference_path = workspace_root().join("tests/references/cornell-box-path.exr");
    if std::env::var_os("RTGI_BLESS").is_some() {
        let reference = render_box(&scene, REFERENCE_SPP, 1000);
        reference.write(&reference_path, &ToneMap::default()).unwrap();
        reference.write(&reference_path.with_extension("png"), &ToneMap::default()).unwrap();
        eprintln!("wrote {} (and a .png to look at)", reference_path.display());
        return;
    }
    let reference = HdrImage::read_exr(&reference_path)
        .unwrap_or_else(|e| panic!("{e} (regenerate with RTGI_BLESS=1, see this file's header)"));
    assert_eq!((reference.width(), reference.height()), (SIZE, SIZE));

    let runs: Vec<HdrImage> = (1..=RUNS as u64).map(|seed| render_box(&scene, RUN_SPP, seed)).collect();
    let n = RUNS as f64;
    let pixels = (SIZE * SIZE) as usize;
    // Per pixel and channel: mean of the runs, and the variance of that mean.
    let mut mean = vec![[0.0f64; 3]; pixels];
    let mut variance = vec![[0.0f64; 3]; pixels];
    for i in 0..pixels {
        for c in 0..3 {
            let values: Vec<f64> = runs.iter().map(|r| r.pixels()[i][c] as f64).collect();
            let m = values.iter().sum::<f64>() / n;
            let sample_variance = values.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
            mean[i][c] = m;
            // The reference has its own noise, REFERENCE_SPP / (RUNS × RUN_SPP) times smaller.
            let reference_share = (RUNS * RUN_SPP) as f64 / REFERENCE_SPP as f64;
            variance[i][c] = sample_variance / n * (1.0 + reference_share);
        }
    }
    let reference_value = |i: usize, c: usize| reference.pixels()[i][c] as f64;

    // Pixels: z-scores of noisy pixels; pixels with no noise at all (the
    // light's interior) must match exactly.
    let mut z2 = Vec::new();
    for i in 0..pixels {
        for c in 0..3 {
            let difference = mean[i][c] - reference_value(i, c);
            if variance[i][c] > 0.0 {
                z2.push((difference * difference / variance[i][c]).min(1e12));
            } else {
                assert!(difference.abs() <= 1e-4 * reference_value(i, c).max(1.0), "pixel {i} differs by {difference}");
            }
        }
    }
    z2.sort_by(f64::total_cmp);
    let median_z2 = z2[z2.len() / 2];
    let mean_z2 = z2.iter().sum::<f64>() / z2.len() as f64;
    let outliers = z2.iter().filter(|&&v| v > 36.0).count();
    println!("pixels: z² median {median_z2:.3}, mean {mean_z2:.3} over {} values, {outliers} beyond 6σ", z2.len());
    // With 16 runs z follows a t distribution of 15 degrees of freedom:
    // median z² ≈ 0.49, mean 15/13. Path tracing's rare bright paths make
    // 16 runs underestimate some pixels' variance, which inflates the mean
    // and the tail; the median is robust to that, and a bias moves it.
    assert!(median_z2 < 0.75, "pixels disagree with the reference: median z² = {median_z2}");
    assert!(mean_z2 < 2.5, "pixels disagree with the reference: mean z² = {mean_z2}");
    assert!(outliers as f64 <= 0.005 * z2.len() as f64, "{outliers} values beyond 6σ");

    // Blocks of 8×8 pixels: a local bias (a missing shadow, wrong colour
    // bleeding) shows here long before single pixels notice.
    let block = 8;
    let mut worst_block: f64 = 0.0;
    for by in (0..SIZE).step_by(block) {
        for bx in (0..SIZE).step_by(block) {
            for c in 0..3 {
                let (mut difference, mut var) = (0.0, 0.0);
                for y in by..by + block as u32 {
                    for x in bx..bx + block as u32 {
                        let i = (y * SIZE + x) as usize;
                        difference += mean[i][c] - reference_value(i, c);
                        var += variance[i][c];
                    }
                }
                if var > 0.0 {
                    worst_block = worst_block.max((difference / var.sqrt()).abs());
                }
            }
        }
    }
    println!("blocks: largest |z| {worst_block:.2}");
    assert!(worst_block < 5.0, "an 8×8 block disagrees with the reference by {worst_block}σ");

    // The whole image, and a plain relative bound for readers of this test.
    let total = |f: &dyn Fn(usize, usize) -> f64| {
        (0..pixels).flat_map(|i| (0..3).map(move |c| (i, c))).map(|(i, c)| f(i, c)).sum::<f64>()
    };
    let difference = total(&|i, c| mean[i][c] - reference_value(i, c));
    let z = difference / total(&|i, c| variance[i][c]).sqrt();
    let relative = difference / total(&|i, c| reference_value(i, c));
    println!("image: z {z:.2}, relative difference {relative:.5}");
    assert!(z.abs() < 5.0 && relative.abs() < 0.01, "the image is off by {relative} ({z}σ)");
}
