//! Cameras for scenes that bring none, and a check that a camera is not
//! buried in geometry.

use rtgi_accel::Accel;
use rtgi_math::{Aabb, Vec2, Vec3};
use rtgi_scene::{Camera, Scene};

use crate::CameraRays;

/// Probe rays per side of a candidate view.
const PROBE_RESOLUTION: u32 = 24;

/// The product shot: this far round from the front towards +X, and this
/// far above, in degrees.
const THREE_QUARTER_AZIMUTH: f32 = 35.0;
const THREE_QUARTER_ELEVATION: f32 = 25.0;

/// The part of the frame the model's bounds fill, across the narrower side.
const FILL: f32 = 0.9;

/// The vertical field of view, in degrees, of the camera [`default_camera`]
/// makes for a scene without one (the `rtgi` command's default too).
pub const DEFAULT_VERTICAL_FOV_DEGREES: f32 = 40.0;

/// A camera for any scene: the scene's first camera, or for a scene that
/// brings none (OBJ files, glTF files without cameras) the view
/// [`frame_scene`] picks with a vertical field of view of
/// [`DEFAULT_VERTICAL_FOV_DEGREES`]. `aspect` is the image's width over its
/// height.
///
/// ```no_run
/// use rtgi_accel::{AccelKind, BuildParams};
/// use rtgi_render::default_camera;
/// use rtgi_scene::Scene;
///
/// let scene = Scene::load("model.obj".as_ref())?;
/// let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
/// let camera = default_camera(&scene, accel.as_ref(), 16.0 / 9.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn default_camera<A: Accel + ?Sized>(scene: &Scene, accel: &A, aspect: f32) -> Camera {
    match scene.cameras.first() {
        Some(camera) => *camera,
        None => frame_scene(scene, accel, DEFAULT_VERTICAL_FOV_DEGREES.to_radians(), aspect),
    }
}

/// A camera for a scene that has none: the best of a few candidate views.
///
/// The candidates, in order of preference:
/// - a three-quarter view, like a product shot: from the front (+Z, the
///   side glTF models face and scanned models usually do) turned 35
///   degrees towards +X and raised 25 degrees, centred on the bounds and
///   close enough that they fill 90% of the frame; for a model much longer
///   along Z than along X (a vehicle facing +X or -X), the same view taken
///   from its long side;
/// - the bounds seen straight from +Z (the classic view into a Cornell box);
/// - from +Z and 35 degrees above (looking into open courtyards);
/// - from the bounds' centre, looking along its longer horizontal axis
///   (rooms closed on all sides).
///
/// A grid of probe rays counts the distinct materials each view shows; a
/// view whose rays mostly hit back faces or start against a surface is
/// inside geometry ([`camera_blocked`]) and is passed over. The view that
/// shows the most wins, the earlier candidate on ties, so objects get the
/// product shot while boxes and architecture are seen from where they have
/// something to show.
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
    let product = three_quarter_view(&bounds, vertical_fov, aspect);

    let mut best: Option<(Camera, usize)> = None;
    for candidate in [product, front, above, inside] {
        if camera_blocked(scene, accel, &candidate, aspect).is_some() {
            continue;
        }
        let shown = materials_shown(scene, accel, &candidate, aspect);
        if best.is_none_or(|(_, most)| shown > most) {
            best = Some((candidate, shown));
        }
    }
    // Every view blocked (a scene that is one solid): the product shot, from outside the bounds.
    best.map_or(product, |(camera, _)| camera)
}

/// The three-quarter view of `bounds` (see [`frame_scene`]).
pub fn three_quarter_view(bounds: &Aabb, vertical_fov: f32, aspect: f32) -> Camera {
    let (centre, extent) = if bounds.is_empty() {
        (Vec3::ZERO, Vec3::ONE)
    } else {
        (bounds.centroid(), bounds.extent().max(Vec3::splat(1e-6)))
    };
    let (azimuth, elevation) = (THREE_QUARTER_AZIMUTH.to_radians(), THREE_QUARTER_ELEVATION.to_radians());
    // Long along Z: its side is its face.
    let front = if extent.z > 1.5 * extent.x { Vec3::X } else { Vec3::Z };
    let side = Vec3::Y.cross(front);
    let horizontal = front * azimuth.cos() + side * azimuth.sin();
    let towards_camera = horizontal * elevation.cos() + Vec3::Y * elevation.sin();
    let forward = -towards_camera;
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    // The distance at which every corner of the box is inside FILL of the frame.
    let tan_vertical = FILL * (0.5 * vertical_fov).tan();
    let tan_horizontal = tan_vertical * aspect;
    let mut distance = 0.5 * extent.length();
    for corner in 0..8 {
        let offset = Vec3::new(
            if corner & 1 == 0 { -0.5 } else { 0.5 },
            if corner & 2 == 0 { -0.5 } else { 0.5 },
            if corner & 4 == 0 { -0.5 } else { 0.5 },
        ) * extent;
        let (x, y, z) = (offset.dot(right), offset.dot(up), offset.dot(forward));
        distance = distance.max(x.abs() / tan_horizontal - z).max(y.abs() / tan_vertical - z);
    }
    Camera::look_at(centre + towards_camera * distance, centre, Vec3::Y, vertical_fov)
}

/// Whether `camera` looks out from inside geometry: more than half of a
/// grid of rays through the view hit a surface from behind (a back face) or
/// within a ten-thousandth of the scene's size. Returns the fraction of
/// such rays, or `None` when the view is clear. A camera inside a solid
/// sees only the insides of its faces; one pressed against a wall sees the
/// wall at no distance.
pub fn camera_blocked<A: Accel + ?Sized>(scene: &Scene, accel: &A, camera: &Camera, aspect: f32) -> Option<f32> {
    let bounds = scene.bounds();
    let near = if bounds.is_empty() { 0.0 } else { 1e-4 * bounds.extent().length() };
    let mut blocked = 0u32;
    let probes = probe_rays(camera, aspect);
    for ray in &probes {
        let Some(hit) = accel.intersect(ray) else { continue };
        let triangle = &scene.triangles[hit.triangle as usize];
        let [a, b, c] = triangle.vertices.map(|v| scene.vertices[v as usize].position);
        // The winding decides, even for double-sided materials: a leaf
        // seen from behind is fine, a view made mostly of backs is not.
        let back_face = (b - a).cross(c - a).dot(ray.direction) > 0.0;
        if back_face || hit.t * ray.direction.length() < near {
            blocked += 1;
        }
    }
    let fraction = blocked as f32 / probes.len() as f32;
    (fraction > 0.5).then_some(fraction)
}

/// How many materials cover at least two of the probe rays' hits.
fn materials_shown<A: Accel + ?Sized>(scene: &Scene, accel: &A, camera: &Camera, aspect: f32) -> usize {
    let mut hits_per_material = vec![0u32; scene.materials.len()];
    for ray in probe_rays(camera, aspect) {
        if let Some(hit) = accel.intersect(&ray) {
            hits_per_material[scene.triangles[hit.triangle as usize].material as usize] += 1;
        }
    }
    hits_per_material.iter().filter(|&&n| n >= 2).count()
}

/// The probe rays of a view: one through the centre of each pixel of a
/// grid [`PROBE_RESOLUTION`] high, as wide as the aspect asks (up to four times).
fn probe_rays(camera: &Camera, aspect: f32) -> Vec<rtgi_math::Ray> {
    let height = PROBE_RESOLUTION;
    let width = ((PROBE_RESOLUTION as f32 * aspect).round() as u32).clamp(1, 4 * PROBE_RESOLUTION);
    let rays = CameraRays::new(camera, width, height);
    (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| rays.ray(x, y, Vec2::splat(0.5))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_product_shot_fills_the_frame_from_the_front_right_and_above() {
        let bounds = Aabb::new(Vec3::new(-1.0, 0.0, -0.5), Vec3::new(1.0, 3.0, 0.5));
        let fov = 40f32.to_radians();
        for aspect in [0.75, 1.0, 16.0 / 9.0] {
            let camera = three_quarter_view(&bounds, fov, aspect);
            assert!(camera.is_valid());
            let offset = camera.position - bounds.centroid();
            assert!(offset.z > 0.0 && offset.x > 0.0 && offset.y > 0.0, "{offset}");
            assert!((camera.position + camera.direction - bounds.centroid()).length() < 1e-4);
            // Every corner inside the frame, and the widest one near its edge.
            let forward = camera.direction.normalize();
            let right = forward.cross(Vec3::Y).normalize();
            let up = right.cross(forward);
            let tan_half = (0.5 * fov).tan();
            let mut widest: f32 = 0.0;
            for corner in 0..8 {
                let p = Vec3::new(
                    if corner & 1 == 0 { -1.0 } else { 1.0 },
                    if corner & 2 == 0 { 0.0 } else { 3.0 },
                    if corner & 4 == 0 { -0.5 } else { 0.5 },
                ) - camera.position;
                let depth = p.dot(forward);
                let (sx, sy) = (p.dot(right) / depth / (tan_half * aspect), p.dot(up) / depth / tan_half);
                assert!(sx.abs() <= FILL + 1e-4 && sy.abs() <= FILL + 1e-4, "corner {corner}: {sx} {sy}");
                widest = widest.max(sx.abs()).max(sy.abs());
            }
            assert!(widest > FILL - 1e-3, "{widest}");
        }
    }
}
