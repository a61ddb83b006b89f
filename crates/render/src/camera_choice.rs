//! Which of a file's cameras to use: the one that sees most of the model.
//!
//! A file's first camera is often not its best view (a glTF with eight
//! cameras opened on an extreme close-up of a side window). Points spread
//! over the model's surface by area are projected into each view; a point
//! counts as seen when it lies inside the frame and nothing hides it from
//! the camera.

use rtgi_accel::Accel;
use rtgi_math::{Ray, Rng, Vec3};
use rtgi_scene::{Camera, Scene};

/// Points spread over the model to judge the views by.
const SURFACE_POINTS: usize = 1024;

/// What a view shows of the model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewScore {
    /// The fraction of the model's surface points inside the frame.
    pub in_frame: f32,
    /// The fraction inside the frame and hidden by nothing.
    pub seen: f32,
}

impl ViewScore {
    /// Whether the frame holds (nearly) all of the model.
    pub fn sees_it_whole(&self) -> bool {
        self.in_frame >= 0.95
    }
}

/// Points on the model's surface, by area, the same for every call.
pub fn surface_points(scene: &Scene) -> Vec<(u32, Vec3)> {
    let corners = |t: usize| scene.triangles[t].vertices.map(|v| scene.vertices[v as usize].position);
    let mut cumulative = Vec::with_capacity(scene.triangles.len());
    let mut total = 0.0f64;
    for t in 0..scene.triangles.len() {
        let [a, b, c] = corners(t);
        let area = 0.5 * (b - a).cross(c - a).length();
        if area.is_finite() {
            total += f64::from(area);
        }
        cumulative.push(total);
    }
    if total <= 0.0 {
        return Vec::new();
    }
    let mut rng = Rng::new(0x5eed, 0);
    (0..SURFACE_POINTS)
        .map(|_| {
            let target = f64::from(rng.next_f32()) * total;
            let t = cumulative.partition_point(|&c| c <= target).min(scene.triangles.len() - 1);
            let [a, b, c] = corners(t);
            let (u, v) = (rng.next_f32(), rng.next_f32());
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            (t as u32, a + (b - a) * u + (c - a) * v)
        })
        .collect()
}

/// What `camera` shows of `points`, for images of `aspect` (the camera's
/// own aspect, where it has one, wins).
pub fn score_view<A: Accel + ?Sized>(accel: &A, camera: &Camera, aspect: f32, points: &[(u32, Vec3)]) -> ViewScore {
    if points.is_empty() || !camera.is_valid() {
        return ViewScore::default();
    }
    let forward = camera.direction.normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let tan_vertical = (0.5 * camera.vertical_fov).tan();
    let tan_horizontal = tan_vertical * camera.aspect.unwrap_or(aspect);
    let (mut in_frame, mut seen) = (0usize, 0usize);
    for &(triangle, point) in points {
        let offset = point - camera.position;
        let depth = offset.dot(forward);
        if depth <= 0.0
            || depth.is_nan()
            || offset.dot(right).abs() > tan_horizontal * depth
            || offset.dot(up).abs() > tan_vertical * depth
        {
            continue;
        }
        in_frame += 1;
        // Hidden when something is hit clearly before the point (its own
        // triangle, or one at its distance, does not hide it).
        let hidden = accel
            .intersect(&Ray::new(camera.position, offset))
            .is_some_and(|hit| hit.triangle != triangle && hit.t < 0.999);
        seen += usize::from(!hidden);
    }
    let count = points.len() as f32;
    ViewScore { in_frame: in_frame as f32 / count, seen: seen as f32 / count }
}

/// The index of the file camera that sees most of the model's `points`
/// ([`surface_points`]), and its score; `None` for a scene without
/// cameras. Ties go to the earlier camera.
pub fn best_file_camera<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    aspect: f32,
    points: &[(u32, Vec3)],
) -> Option<(usize, ViewScore)> {
    let mut best: Option<(usize, ViewScore)> = None;
    for (index, camera) in scene.cameras.iter().enumerate() {
        let score = score_view(accel, camera, aspect, points);
        if best.is_none_or(|(_, most)| score.seen > most.seen) {
            best = Some((index, score));
        }
    }
    best
}
