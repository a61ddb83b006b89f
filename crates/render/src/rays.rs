//! Batches of rays for benchmarks and experiments.

use rtgi_math::{Ray, Rng, Vec2, Vec3};
use rtgi_scene::{Camera, Scene};

use crate::CameraRays;

/// One ray through the centre of every pixel.
///
/// The rays come in 4×4 tiles of pixels (tiles row by row, pixels row by
/// row within a tile), as a renderer traces them: sixteen consecutive
/// rays are neighbours, which packet traversal
/// ([`rtgi_accel::Accel::intersect_batch`]) exploits.
pub fn primary_rays(camera: &Camera, width: u32, height: u32) -> Vec<Ray> {
    let rays = CameraRays::new(camera, width, height);
    tile_order(width, height).map(|(x, y)| rays.ray(x, y, Vec2::splat(0.5))).collect()
}

/// Side of the square tiles in which camera rays are traced.
pub const TILE: u32 = 4;

/// Every pixel of a `width × height` image once, in [`TILE`]×[`TILE`]
/// tiles: tiles row by row, pixels row by row within a tile (tiles at the
/// right and bottom edges are cut to the image).
pub fn tile_order(width: u32, height: u32) -> impl Iterator<Item = (u32, u32)> {
    (0..height.div_ceil(TILE)).flat_map(move |ty| {
        (0..width.div_ceil(TILE)).flat_map(move |tx| {
            (ty * TILE..((ty + 1) * TILE).min(height))
                .flat_map(move |y| (tx * TILE..((tx + 1) * TILE).min(width)).map(move |x| (x, y)))
        })
    })
}

/// Incoherent rays: origins uniformly distributed over the scene's surfaces
/// (triangles chosen in proportion to their area), directions uniform on the
/// sphere. The same seed gives the same rays. Each origin is lifted off its
/// surface along the geometric normal by a relative 1e-4 of the scene's
/// size, so that rays do not start inside the surface they leave (this batch
/// measures traversal, not self-intersection).
pub fn surface_rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray> {
    let triangles = scene.triangle_positions();
    let areas: Vec<f64> = triangles.iter().map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length() as f64).collect();
    let mut cumulative = Vec::with_capacity(areas.len());
    let mut total = 0.0;
    for a in &areas {
        total += if a.is_finite() { *a } else { 0.0 };
        cumulative.push(total);
    }
    if total <= 0.0 {
        return Vec::new();
    }
    let lift = 1e-4 * scene.bounds().extent().length();
    let mut rng = Rng::new(seed, 0x5eed);
    (0..count)
        .map(|_| {
            let pick = rng.next_f32() as f64 * total;
            let index = cumulative.partition_point(|&c| c <= pick).min(triangles.len() - 1);
            let [a, b, c] = triangles[index];
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let point = a + u * (b - a) + v * (c - a);
            let direction = uniform_sphere(rng.next_f32(), rng.next_f32());
            let normal = (b - a).cross(c - a).normalize_or_zero();
            let side = if normal.dot(direction) >= 0.0 { 1.0 } else { -1.0 };
            Ray::new(point + side * lift * normal, direction)
        })
        .collect()
}

/// Rays with origins uniform in the scene's bounding box and directions
/// uniform on the sphere: the incoherent batch of the peer measurements in
/// `../shared/notes/peers.md`.
pub fn box_rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray> {
    let bounds = scene.bounds();
    let mut rng = Rng::new(seed, 0xb0c5);
    (0..count)
        .map(|_| {
            let t = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let origin = bounds.min + t * bounds.extent();
            Ray::new(origin, uniform_sphere(rng.next_f32(), rng.next_f32()))
        })
        .collect()
}

pub use rtgi_math::uniform_sphere;

/// The camera of the peer measurements: looking at the bounding sphere's
/// centre along -Z with a 40 degree vertical field of view, at the distance
/// where the sphere just fills the view.
pub fn bounding_sphere_camera(scene: &Scene) -> Camera {
    Camera::framing(&scene.bounds(), 40f32.to_radians(), 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_order_visits_every_pixel_once_in_tiles() {
        for (width, height) in [(8, 8), (5, 7), (1, 1), (4, 9)] {
            let pixels: Vec<(u32, u32)> = tile_order(width, height).collect();
            let mut sorted = pixels.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), (width * height) as usize, "{width}×{height}");
            assert_eq!(pixels.len(), sorted.len());
        }
        // The first sixteen pixels of a large image form the top-left tile.
        let first: Vec<(u32, u32)> = tile_order(64, 64).take(16).collect();
        assert!(first.iter().all(|&(x, y)| x < TILE && y < TILE));
    }
}
