//! The error of every pixel sampler against the shared Cornell box's
//! reference at doubling sample counts, shared by the convergence test
//! (`tests/render/sampler_convergence.rs`) and its steadier, slower form
//! (`tests/slow/`).

use rtgi_image::{HdrImage, compare};
use rtgi_render::PixelSampler;
use rtgi_scene::Scene;

use crate::{render_cornell_box, shared_scene, workspace_root};

/// The sample counts, doubling: squares and not, where stratification differs.
pub const COUNTS: [u32; 5] = [16, 32, 64, 128, 256];
/// Every pixel sampler.
pub const SAMPLERS: [PixelSampler; 4] =
    [PixelSampler::Uniform, PixelSampler::Stratified, PixelSampler::LowDiscrepancy, PixelSampler::Sobol];

/// The shared Cornell box and its 16,384-spp reference, or `None` after
/// saying why not ([`crate::shared_scene`]).
pub fn scene_and_reference() -> Option<(Scene, HdrImage)> {
    let path = shared_scene("cornell-box/CornellBox-Original.obj")?;
    let scene = Scene::load(&path).unwrap();
    let reference = HdrImage::read_exr(&workspace_root().join("tests/references/cornell-box-path.exr")).unwrap();
    Some((scene, reference))
}

/// Per sampler and count: the root of the mean over `seeds` renders of the
/// squared RMSE against the reference.
pub fn errors(scene: &Scene, reference: &HdrImage, seeds: u64) -> Vec<Vec<f64>> {
    SAMPLERS
        .iter()
        .enumerate()
        .map(|(s, &sampler)| {
            COUNTS
                .iter()
                .map(|&spp| {
                    let mse: f64 = (0..seeds)
                        .map(|k| {
                            let seed = 3000 + 1000 * s as u64 + spp as u64 + 100_000 * k;
                            let image = render_cornell_box(scene, spp, sampler, seed);
                            compare(&image, reference).expect("the reference has the render's size").rmse.powi(2)
                        })
                        .sum();
                    (mse / seeds as f64).sqrt()
                })
                .collect()
        })
        .collect()
}

/// Prints the errors as a Markdown table, a row per sampler.
pub fn print_table(errors: &[Vec<f64>]) {
    println!("| sampler | {} |", COUNTS.map(|n| format!("{n} spp")).join(" | "));
    println!("|---|{}", "---:|".repeat(COUNTS.len()));
    for (sampler, errors) in SAMPLERS.iter().zip(errors) {
        println!("| {sampler} | {} |", errors.iter().map(|e| format!("{e:.4}")).collect::<Vec<_>>().join(" | "));
    }
}
