use rtgi_accel::Accel;
use rtgi_math::{Vec2, Vec3};
use rtgi_scene::{Camera, Scene};

use crate::CameraRays;

/// Probe rays per side of a candidate view.
const PROBE_RESOLUTION: u32 = 24;

/// A camera for a scene that has none: the best of a few candidate views.
///
/// The candidates are the bounding box seen from +Z (the classic view of a
/// Cornell box or a scanned object), seen from +Z and 35 degrees above
/// (looking into open courtyards), and from the box's centre looking along
/// its longer horizontal axis (for rooms closed on all sides). A grid of probe rays counts the
/// distinct materials each view shows; the view that shows the most wins, the
/// earlier candidate on ties, so objects keep the plain front view while
/// architecture is seen from where it has something to show.
pub fn frame_scene<A: Accel + ?Sized>(scene: &Scene, accel: &A, vertical_fov: f32, aspect: f32) -> Camera {
    let bounds = scene.bounds();
    let front = Camera::framing(&bounds, vertical_fov, aspect);
    let centre = front.position + front.direction;
    let distance = front.direction.length();
    let elevation = 35f32.to_radians();
    let above_direction = Vec3::new(0.0, elevation.sin(), elevation.cos());
    let above = Camera::look_at(centre + distance * above_direction, centre, Vec3::Y, vertical_fov);
    let extent = bounds.extent();
    let along_room = if extent.x > extent.z { -Vec3::X } else { -Vec3::Z };
    let inside = Camera::look_at(centre, centre + along_room, Vec3::Y, vertical_fov);

    let mut best = (front, 0usize);
    for candidate in [front, above, inside] {
        let shown = materials_shown(scene, accel, &candidate, aspect);
        if shown > best.1 {
            best = (candidate, shown);
        }
    }
    best.0
}

/// How many materials cover at least two of the probe rays' hits.
fn materials_shown<A: Accel + ?Sized>(scene: &Scene, accel: &A, camera: &Camera, aspect: f32) -> usize {
    let height = PROBE_RESOLUTION;
    let width = ((PROBE_RESOLUTION as f32 * aspect).round() as u32).clamp(1, 4 * PROBE_RESOLUTION);
    let rays = CameraRays::new(camera, width, height);
    let mut hits_per_material = vec![0u32; scene.materials.len()];
    for y in 0..height {
        for x in 0..width {
            if let Some(hit) = accel.intersect(&rays.ray(x, y, Vec2::splat(0.5))) {
                hits_per_material[scene.triangles[hit.triangle as usize].material as usize] += 1;
            }
        }
    }
    hits_per_material.iter().filter(|&&n| n >= 2).count()
}
