//! Ray casting and shading: from a scene, an acceleration structure and a
//! camera to an HDR image.
//!
//! Rendering is parallel over square tiles with rayon. Every sample draws
//! its random numbers from a generator seeded by (seed, pixel, sample), and
//! each pixel sums its samples in sample order, so the image is
//! bit-identical whatever the number of threads.
//!
//! ```no_run
//! use rtgi_accel::{AccelKind, BuildParams};
//! use rtgi_render::{RenderSettings, render};
//! use rtgi_scene::{Camera, Scene};
//!
//! let scene = Scene::load("scenes/cornell-box.toml".as_ref())?;
//! let accel = AccelKind::Linear.build(&scene.triangle_positions(), &BuildParams::default());
//! let settings = RenderSettings { width: 256, height: 256, ..RenderSettings::default() };
//! let camera = scene.cameras[0];
//! let (image, stats) = render(&scene, accel.as_ref(), &camera, &settings, &|_| {});
//! println!("{} rays in {:.1} ms", stats.rays, stats.render_ms);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bsdf;
mod camera;
mod framing;
pub mod probes;
pub mod rays;
mod sampler;
mod shade;

pub use camera::CameraRays;
pub use framing::frame_scene;
pub use sampler::{PixelSample, PixelSampler};
pub use shade::{alpha_accepts, has_alpha, shade_primary, shading_normal};

use std::time::Instant;

use rayon::prelude::*;
use rtgi_accel::{Accel, TraversalCounters};
use rtgi_image::HdrImage;
use rtgi_math::{Rng, Vec2, Vec3};
use rtgi_scene::{Camera, Scene};
use serde::Serialize;

/// Side of the square tiles that threads take one at a time.
pub const TILE_SIZE: u32 = 16;

/// What to render and how.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel.
    pub samples_per_pixel: u32,
    pub sampler: PixelSampler,
    pub seed: u64,
    /// Radiance of rays that hit nothing.
    pub background: Vec3,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            width: 512,
            height: 512,
            samples_per_pixel: 1,
            sampler: PixelSampler::Center,
            seed: 0,
            background: Vec3::new(0.05, 0.05, 0.06),
        }
    }
}

/// What a render did and how long it took.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RenderStats {
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    /// Rays traced, of all kinds.
    pub rays: u64,
    pub render_ms: f64,
}

impl RenderStats {
    pub fn rays_per_second(&self) -> f64 {
        self.rays as f64 / (self.render_ms * 1e-3).max(1e-9)
    }
}

/// The rectangles that make up an image, in row-major order.
fn tiles(width: u32, height: u32) -> Vec<(u32, u32, u32, u32)> {
    let mut tiles = Vec::new();
    for y0 in (0..height).step_by(TILE_SIZE as usize) {
        for x0 in (0..width).step_by(TILE_SIZE as usize) {
            tiles.push((x0, y0, (x0 + TILE_SIZE).min(width), (y0 + TILE_SIZE).min(height)));
        }
    }
    tiles
}

/// Renders the primary-hit view: each pixel averages its samples' shaded
/// closest hits, or the background.
///
/// `progress` is called from the worker threads with the number of pixels
/// finished since its last call; it must be cheap.
pub fn render<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    camera: &Camera,
    settings: &RenderSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> (HdrImage, RenderStats) {
    let start = Instant::now();
    let (width, height) = (settings.width, settings.height);
    let rays = CameraRays::new(camera, width, height);
    let spp = settings.samples_per_pixel.max(1);
    let alpha = has_alpha(scene);
    let image = render_pixels(width, height, progress, |x, y| {
        let pixel_index = y as u64 * width as u64 + x as u64;
        // One more generator per pixel, past every sample's: its shift of the pixel's pattern.
        let mut shift = Rng::for_sample(settings.seed, pixel_index, u64::MAX);
        let pixel_shift = Vec2::new(shift.next_f32(), shift.next_f32());
        let mut sum = Vec3::ZERO;
        for sample in 0..spp {
            let mut rng = Rng::for_sample(settings.seed, pixel_index, sample as u64);
            let position = PixelSample { index: sample, count: spp, pixel_shift };
            let ray = rays.ray(x, y, settings.sampler.offset(&position, &mut rng));
            let hit = if alpha {
                let u = rng.next_f32();
                accel.intersect_filtered(&ray, &|t, b, g| alpha_accepts(scene, t, b, g, u))
            } else {
                accel.intersect(&ray)
            };
            sum += match hit {
                Some(hit) => shade_primary(scene, &ray, &hit),
                None => settings.background,
            };
        }
        sum / spp as f32
    });
    let stats = RenderStats {
        width,
        height,
        samples_per_pixel: spp,
        rays: width as u64 * height as u64 * spp as u64,
        render_ms: start.elapsed().as_secs_f64() * 1e3,
    };
    (image, stats)
}

/// Renders what tracing costs: per pixel, the boxes tested (red channel)
/// and ray/triangle tests (green channel) of the ray through the pixel's
/// centre, and 1 in blue where it hit something. Parallel and
/// deterministic like [`render`]; also returns the totals.
pub fn render_traversal_cost<A: Accel + ?Sized>(
    accel: &A,
    camera: &Camera,
    width: u32,
    height: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> (HdrImage, TraversalCounters) {
    let rays = CameraRays::new(camera, width, height);
    let image = render_pixels(width, height, progress, |x, y| {
        let mut counters = TraversalCounters::default();
        let hit = accel.intersect_counted(&rays.ray(x, y, Vec2::splat(0.5)), &mut counters);
        Vec3::new(counters.nodes_visited as f32, counters.triangles_tested as f32, hit.is_some() as u32 as f32)
    });
    let mut total = TraversalCounters { rays: width as u64 * height as u64, ..TraversalCounters::default() };
    for p in image.pixels() {
        total.nodes_visited += p.x as u64;
        total.triangles_tested += p.y as u64;
    }
    (image, total)
}

/// Computes every pixel with `pixel(x, y)`, tile by tile in parallel, and
/// reports finished pixels to `progress`. The value of a pixel depends only
/// on its coordinates, so the image is the same for any number of threads.
fn render_pixels(
    width: u32,
    height: u32,
    progress: &(dyn Fn(u64) + Sync),
    pixel: impl Fn(u32, u32) -> Vec3 + Sync,
) -> HdrImage {
    let tile_pixels: Vec<Vec<Vec3>> = tiles(width, height)
        .into_par_iter()
        .map(|(x0, y0, x1, y1)| {
            let pixels: Vec<Vec3> =
                (y0..y1).flat_map(|y| (x0..x1).map(move |x| (x, y))).map(|(x, y)| pixel(x, y)).collect();
            progress(pixels.len() as u64);
            pixels
        })
        .collect();
    let mut image = HdrImage::new(width, height);
    for ((x0, y0, x1, _), pixels) in tiles(width, height).into_iter().zip(tile_pixels) {
        let tile_width = (x1 - x0) as usize;
        for (i, value) in pixels.into_iter().enumerate() {
            image.set(x0 + (i % tile_width) as u32, y0 + (i / tile_width) as u32, value);
        }
    }
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        let mut covered = vec![0u8; 37 * 21];
        for (x0, y0, x1, y1) in tiles(37, 21) {
            for y in y0..y1 {
                for x in x0..x1 {
                    covered[(y * 37 + x) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
    }
}
