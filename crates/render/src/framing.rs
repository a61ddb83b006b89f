//! Cameras for scenes that bring none, and a check that a camera is not
//! buried in geometry.

use rtgi_accel::Accel;
use rtgi_math::{Aabb, Vec2, Vec3};
use rtgi_scene::{Camera, Scene};

use crate::CameraRays;
use crate::automatic_view::{AutomaticView, ModelSide, SideReason};
use crate::up_axis::{detect_up, turned_up};

/// Probe rays per side of a candidate view.
const PROBE_RESOLUTION: u32 = 24;

/// The product shot: this far round from the front towards +X, and this
/// far above, in degrees.
const THREE_QUARTER_AZIMUTH: f32 = 35.0;
const THREE_QUARTER_ELEVATION: f32 = 25.0;

/// The corner views of a room: this far in from each wall (a fraction of
/// the bounds), at this fraction of its height, looking at a point this
/// high above the floor in the middle.
const ROOM_CORNER_INSET: f32 = 0.08;
const ROOM_CAMERA_HEIGHT: f32 = 0.6;
const ROOM_TARGET_HEIGHT: f32 = 0.2;

/// How much more surface detail another side of a one-material model must
/// show than its front to be the side shown (see [`frame_scene`]): scans
/// are roughly symmetric, and +Z is the usual front. Measured on scans: a
/// cow's and a bust's faces show 1.7 times their flanks' detail, the
/// teapot's handle side 1.46 times its classic front's.
const SIDE_DETAIL_MARGIN: f32 = 1.5;

/// A model whose bounds are at most this fraction of their size thick is
/// flat, and seen straight on ([`flat_view`]).
const FLAT_THICKNESS: f32 = 0.01;

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
///   degrees towards +X and raised 25 degrees, moved until the model's
///   vertices fill 90% of the frame, centred ([`framed_tightly`]); for a model
///   of several materials much longer along Z than along X (a vehicle facing
///   +X or -X), the same view taken from its long side;
/// - the bounds seen straight from +Z (the classic view into a Cornell box);
/// - from +Z and 35 degrees above (looking into open courtyards);
/// - from the bounds' centre, looking along its longer horizontal axis
///   (rooms closed on all sides);
/// - when no sky reaches the bounds' centre (a closed room), from each
///   upper corner of the bounds, a little inside, looking down across the
///   middle of the floor (a room as a photographer shows it).
///
/// The product shot is taken from the side of the model that shows the
/// most: its back or one of its sides instead of its front when that side
/// shows clearly more surface detail (1.5 times as much), for a model of
/// one material (a scan: a statue, an animal): its face, hands and folds
/// are the detail, and scans do not agree on which way they face. Models of
/// several materials are judged by the materials each side shows, like
/// every other candidate.
///
/// A flat model (a cut-out, thinner than a hundredth of its size) is seen
/// straight on instead, from +Z, or from above when it lies flat across Y.
///
/// These directions are for a model with +Y up. A model standing on a flat
/// base across another axis (a Z-up scan or CAD part, [`detect_up`]) gets
/// them turned with its up ([`frame_scene_up`]).
///
/// A grid of probe rays counts the distinct materials each view shows; a
/// view whose rays mostly hit back faces or start against a surface is
/// inside geometry ([`camera_blocked`]) and is passed over. The view that
/// shows the most wins, the earlier candidate on ties, so objects get the
/// product shot while boxes and architecture are seen from where they have
/// something to show.
pub fn frame_scene<A: Accel + ?Sized>(scene: &Scene, accel: &A, vertical_fov: f32, aspect: f32) -> Camera {
    frame_scene_up(scene, accel, vertical_fov, aspect, detect_up(scene).up)
}

/// [`frame_scene`] for a model whose up is `up` (not judged from its base):
/// every "above", "side" and "front" of the views turns with it, +Z up
/// putting the front at −Y ([`crate::up_axis::turned_up`]).
pub fn frame_scene_up<A: Accel + ?Sized>(scene: &Scene, accel: &A, vertical_fov: f32, aspect: f32, up: Vec3) -> Camera {
    frame_scene_explained(scene, accel, vertical_fov, aspect, up).0
}

/// [`frame_scene_up`], and which of its views it took and why (what `rtgi
/// render` says of an automatic view).
pub fn frame_scene_explained<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    vertical_fov: f32,
    aspect: f32,
    up: Vec3,
) -> (Camera, AutomaticView) {
    let axes = Axes::new(up);
    let bounds = scene.bounds();
    if let Some((view, from)) = flat_view(scene, accel, &bounds, vertical_fov, aspect) {
        return (view, AutomaticView::Flat { from });
    }
    let framing = Camera::framing(&bounds, vertical_fov, aspect);
    let centre = framing.position + framing.direction;
    let distance = framing.direction.length();
    // Built as `Camera::framing` builds its +Z view, so that a +Y-up model's is that view bit for bit.
    let front = Camera {
        position: centre + axes.front * distance,
        direction: Vec3::ZERO - axes.front * distance,
        up: axes.up,
        ..framing
    };
    let elevation = 35f32.to_radians();
    let above_direction = axes.up * elevation.sin() + axes.front * elevation.cos();
    let above = Camera::look_at(centre + distance * above_direction, centre, axes.up, vertical_fov);
    let extent = axes.extent(&bounds);
    let along_room = if extent.x > extent.z { -axes.side } else { -axes.front };
    let inside = Camera::look_at(centre, centre + along_room, axes.up, vertical_fov);
    // Vehicles are long and of many materials: their long side is their
    // face. A long scan of one material (a bust deep from front to back) is
    // judged by its detail from every side.
    let long_side_first = scene.materials.len() > 1;
    let product = framed_tightly(
        scene,
        &three_quarter_view_from(&bounds, vertical_fov, aspect, 0, &axes, long_side_first),
        aspect,
    );
    let (product, side, reason) = best_side(scene, accel, product, vertical_fov, aspect, &axes);
    let product_from = side_facing(&bounds, side.quarter(), &axes, long_side_first);
    // A room closed on all sides is seen from a corner; an open courtyard
    // keeps the views that show its sky.
    let enclosed = crate::sky_visibility(accel, centre) < crate::ENCLOSED;
    let corners = if enclosed { room_corner_views(&bounds, vertical_fov, &axes).to_vec() } else { Vec::new() };

    let product_view = AutomaticView::Product { from: product_from, side, reason };
    let candidates = [
        (product, product_view),
        (front, AutomaticView::StraightOn { from: axes.front }),
        (above, AutomaticView::FromAbove { from: axes.front }),
        (inside, AutomaticView::Inside { along: along_room }),
    ];
    let corners = corners.into_iter().map(|corner| (corner, AutomaticView::RoomCorner));
    let mut best: Option<(Camera, AutomaticView, usize)> = None;
    for (candidate, view) in candidates.into_iter().chain(corners) {
        if camera_blocked(scene, accel, &candidate, aspect).is_some() {
            continue;
        }
        let shown = materials_shown(scene, accel, &candidate, aspect);
        if best.is_none_or(|(_, _, most)| shown > most) {
            best = Some((candidate, view, shown));
        }
    }
    // Every view blocked (a scene that is one solid): the product shot, from outside the bounds.
    best.map_or((product, product_view), |(camera, view, _)| (camera, view))
}

/// A flat model (a cut-out, a drawing: its bounds at most
/// [`FLAT_THICKNESS`] of their size thick) seen straight on, framed
/// tightly: any view from the side shows it foreshortened to a sliver. Seen
/// from the side of the axis it is flat across that faces +Z or +Y (where a
/// flat model across Y, lying down, is seen from above with −Z up).
fn flat_view<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    bounds: &Aabb,
    vertical_fov: f32,
    aspect: f32,
) -> Option<(Camera, Vec3)> {
    if bounds.is_empty() {
        return None;
    }
    let extent = bounds.extent();
    let axis = (0..3).min_by(|&a, &b| extent[a].total_cmp(&extent[b]))?;
    if extent[axis] > FLAT_THICKNESS * extent.max_element() {
        return None;
    }
    let mut towards_camera = Vec3::ZERO;
    towards_camera[axis] = 1.0;
    let up = if axis == 1 { Vec3::NEG_Z } else { Vec3::Y };
    let distance = extent.length().max(1e-6);
    let centre = bounds.centroid();
    let straight = Camera::look_at(centre + towards_camera * distance, centre, up, vertical_fov);
    let view = framed_tightly(scene, &straight, aspect);
    camera_blocked(scene, accel, &view, aspect).is_none().then_some((view, towards_camera))
}

/// Views from inside the four upper corners of `bounds`, each looking
/// across to the middle of the floor on the far side of the centre: how a
/// photographer shows a room (the whole floor, furniture and the far walls),
/// where a view from the centre sees one wall.
fn room_corner_views(bounds: &Aabb, vertical_fov: f32, axes: &Axes) -> [Camera; 4] {
    let target = axes.point(bounds, Vec3::new(0.5, ROOM_TARGET_HEIGHT, 0.5));
    [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(x, z)| {
        let inset = |side: f32| ROOM_CORNER_INSET + side * (1.0 - 2.0 * ROOM_CORNER_INSET);
        let position = axes.point(bounds, Vec3::new(inset(x), ROOM_CAMERA_HEIGHT, inset(z)));
        Camera::look_at(position, target, axes.up, vertical_fov)
    })
}

/// The three-quarter view of `bounds` (see [`frame_scene`]), +Y up.
pub fn three_quarter_view(bounds: &Aabb, vertical_fov: f32, aspect: f32) -> Camera {
    three_quarter_view_from(bounds, vertical_fov, aspect, 0, &Axes::new(Vec3::Y), true)
}

/// The directions the automatic views are taken in: up, the front the
/// product shot looks from, and the side to the front's right (+Y, +Z and
/// +X for a +Y-up model), turned together to the model's up.
struct Axes {
    up: Vec3,
    front: Vec3,
    side: Vec3,
}

impl Axes {
    fn new(up: Vec3) -> Self {
        let turn = turned_up(up);
        Self { up: turn * Vec3::Y, front: turn * Vec3::Z, side: turn * Vec3::X }
    }

    /// The size of `bounds` along (side, up, front).
    fn extent(&self, bounds: &Aabb) -> Vec3 {
        let extent = bounds.extent();
        Vec3::new(self.side.abs().dot(extent), self.up.abs().dot(extent), self.front.abs().dot(extent))
    }

    /// The point of `bounds` at `fractions` of its size along (side, up,
    /// front), from its lowest along each (for +Y up, `min + extent *
    /// fractions`, bit for bit).
    fn point(&self, bounds: &Aabb, fractions: Vec3) -> Vec3 {
        let extent = self.extent(bounds);
        let lowest = Vec3::select((self.side + self.up + self.front).cmplt(Vec3::ZERO), bounds.max, bounds.min);
        lowest
            + self.side * (extent.x * fractions.x)
            + self.up * (extent.y * fractions.y)
            + self.front * (extent.z * fractions.z)
    }
}

/// The product shot of a model `scene` from the side that shows the most:
/// its front, its back or either side (the view turned about the vertical
/// through the model's centre in quarter turns), by the materials in view,
/// and for a model of one material by its surface detail (a bust facing
/// along X is seen from the side its face is on). Ties keep the front, then
/// the back.
fn best_side<A: Accel + ?Sized>(
    scene: &Scene,
    accel: &A,
    front: Camera,
    vertical_fov: f32,
    aspect: f32,
    axes: &Axes,
) -> (Camera, ModelSide, SideReason) {
    let bounds = scene.bounds();
    let others: Vec<(Camera, ModelSide)> = [ModelSide::Back, ModelSide::Side, ModelSide::OtherSide]
        .into_iter()
        .map(|side| {
            let view =
                three_quarter_view_from(&bounds, vertical_fov, aspect, side.quarter(), axes, scene.materials.len() > 1);
            (framed_tightly(scene, &view, aspect), side)
        })
        .filter(|(view, _)| camera_blocked(scene, accel, view, aspect).is_none())
        .collect();
    let front_materials = materials_shown(scene, accel, &front, aspect);
    let materials: Vec<usize> = others.iter().map(|(view, _)| materials_shown(scene, accel, view, aspect)).collect();
    if scene.materials.len() > 1 || materials.iter().any(|&m| m != front_materials) {
        let mut best = (front, ModelSide::Front, front_materials);
        for ((view, side), shown) in others.into_iter().zip(materials) {
            if shown > best.2 {
                best = (view, side, shown);
            }
        }
        let (view, side, shown) = best;
        let reason = if side == ModelSide::Front {
            SideReason::Front
        } else {
            SideReason::Materials { shown, front: front_materials }
        };
        return (view, side, reason);
    }
    let front_detail = detail_shown(scene, accel, &front, aspect);
    let mut best = (front, ModelSide::Front, SIDE_DETAIL_MARGIN * front_detail);
    for (view, side) in others {
        let detail = detail_shown(scene, accel, &view, aspect);
        if detail > best.2 {
            best = (view, side, detail);
        }
    }
    let (view, side, detail) = best;
    let reason =
        if side == ModelSide::Front { SideReason::Front } else { SideReason::Detail { ratio: detail / front_detail } };
    (view, side, reason)
}

/// The horizontal direction from the model towards its side turned
/// `quarter` quarter turns from its front (see [`three_quarter_view_from`]).
fn side_facing(bounds: &Aabb, quarter: u32, axes: &Axes, long_side_first: bool) -> Vec3 {
    // Long from front to back: its side is its face (a vehicle).
    let along = axes.extent(bounds);
    let facing = if long_side_first && along.z > 1.5 * along.x { axes.side } else { axes.front };
    let turned = axes.up.cross(facing);
    match quarter % 4 {
        0 => facing,
        1 => turned,
        2 => -facing,
        _ => -turned,
    }
}

/// [`three_quarter_view`] from the model's front turned `quarter` quarter
/// turns about its up: 0 the front, 2 the back, 1 and 3 the two sides.
fn three_quarter_view_from(
    bounds: &Aabb,
    vertical_fov: f32,
    aspect: f32,
    quarter: u32,
    axes: &Axes,
    long_side_first: bool,
) -> Camera {
    let (centre, extent) = if bounds.is_empty() {
        (Vec3::ZERO, Vec3::ONE)
    } else {
        (bounds.centroid(), bounds.extent().max(Vec3::splat(1e-6)))
    };
    let (azimuth, elevation) = (THREE_QUARTER_AZIMUTH.to_radians(), THREE_QUARTER_ELEVATION.to_radians());
    let front = side_facing(bounds, quarter, axes, long_side_first);
    let side = axes.up.cross(front);
    let horizontal = front * azimuth.cos() + side * azimuth.sin();
    let towards_camera = horizontal * elevation.cos() + axes.up * elevation.sin();
    let forward = -towards_camera;
    let right = forward.cross(axes.up).normalize();
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
    Camera::look_at(centre + towards_camera * distance, centre, axes.up, vertical_fov)
}

/// `camera` moved along its own axes, its direction kept, to the closest
/// position from which every vertex of the scene's triangles lies within
/// 90% of the frame, centred: the model's silhouette, not its bounding
/// box, fills the view (a box's corners, seen three-quarter on, leave a
/// round model a fifth of the frame). Every vertex stays in front of the
/// camera. A scene without vertices keeps the camera as it is.
pub fn framed_tightly(scene: &Scene, camera: &Camera, aspect: f32) -> Camera {
    let forward = camera.direction.normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    if !(forward.is_finite() && right.is_finite()) {
        return *camera;
    }
    let tan_vertical = FILL * (0.5 * camera.vertical_fov).tan();
    let tan_horizontal = tan_vertical * aspect;
    // In the camera's axes, a point p is in frame from position c when
    // |p_r - c_r| <= T (p_f - c_f) on each side: c_r - T c_f >= max(p_r - T p_f)
    // and c_r + T c_f <= min(p_r + T p_f). The largest c_f (the closest
    // camera) meets both with c_r half-way between.
    let (mut low_r, mut high_r, mut low_u, mut high_u) =
        (f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY);
    let mut used = vec![false; scene.vertices.len()];
    for triangle in &scene.triangles {
        for &v in &triangle.vertices {
            used[v as usize] = true;
        }
    }
    for (vertex, _) in scene.vertices.iter().zip(&used).filter(|(v, used)| **used && v.position.is_finite()) {
        let p = vertex.position;
        let (pr, pu, pf) = (p.dot(right), p.dot(up), p.dot(forward));
        low_r = low_r.max(pr - tan_horizontal * pf);
        high_r = high_r.min(pr + tan_horizontal * pf);
        low_u = low_u.max(pu - tan_vertical * pf);
        high_u = high_u.min(pu + tan_vertical * pf);
    }
    if !(low_r.is_finite() && high_r.is_finite() && low_u.is_finite() && high_u.is_finite()) {
        return *camera;
    }
    let along = ((high_r - low_r) / (2.0 * tan_horizontal)).min((high_u - low_u) / (2.0 * tan_vertical));
    let across = 0.5 * (low_r + high_r);
    let height = 0.5 * (low_u + high_u);
    let position = right * across + up * height + forward * along;
    // As long as the way to the model's centre, so that position + direction is the point looked at.
    let depth = (scene.bounds().centroid() - position).dot(forward);
    let direction = forward * if depth > 0.0 { depth } else { camera.direction.length() };
    let moved = Camera { position, direction, ..*camera };
    if moved.is_valid() && position.is_finite() { moved } else { *camera }
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

/// The surface detail a view shows: over the pairs of neighbouring probe
/// rays that both hit, how much their surfaces' normals differ (1 − |cos|
/// of their angle, summed). Smooth backs and flat walls show little; faces,
/// hands and folds much.
fn detail_shown<A: Accel + ?Sized>(scene: &Scene, accel: &A, camera: &Camera, aspect: f32) -> f32 {
    let (width, height) = probe_grid(aspect);
    let normals: Vec<Option<Vec3>> = probe_rays(camera, aspect)
        .iter()
        .map(|ray| {
            let hit = accel.intersect(ray)?;
            let triangle = &scene.triangles[hit.triangle as usize];
            let normal = rtgi_math::geometric_normal(&triangle.vertices.map(|v| scene.vertices[v as usize].position));
            (normal != Vec3::ZERO).then_some(normal)
        })
        .collect();
    let at = |x: u32, y: u32| normals[(y * width + x) as usize];
    let mut detail = 0.0;
    for y in 0..height {
        for x in 0..width {
            let Some(n) = at(x, y) else { continue };
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if let Some(m) = (nx < width && ny < height).then(|| at(nx, ny)).flatten() {
                    detail += 1.0 - n.dot(m).abs();
                }
            }
        }
    }
    detail
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
    let (width, height) = probe_grid(aspect);
    let rays = CameraRays::new(camera, width, height);
    (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| rays.ray(x, y, Vec2::splat(0.5))).collect()
}

/// The probe grid's width and height for an image of `aspect`.
fn probe_grid(aspect: f32) -> (u32, u32) {
    let width = ((PROBE_RESOLUTION as f32 * aspect).round() as u32).clamp(1, 4 * PROBE_RESOLUTION);
    (width, PROBE_RESOLUTION)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tight framing puts every vertex inside the frame's fill and
    /// touches its edge on both sides of the limiting axis: the model's
    /// silhouette, not its box, decides. A lopsided model (a long thin
    /// arm off a small block) is framed by what it has, not by its corners.
    #[test]
    fn tight_framing_fills_the_frame_with_the_model() {
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 4 3 0.2\nv 4.1 3 0.2\nv 4 3.1 0.2\n\
                   f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 5 6\nf 3 7 5\n";
        let scene = Scene::load_from_bytes("lopsided.obj", obj.as_bytes(), &|_| None).unwrap();
        for aspect in [1.0, 16.0 / 9.0, 0.5] {
            let fov = 40f32.to_radians();
            let loose = three_quarter_view(&scene.bounds(), fov, aspect);
            let camera = framed_tightly(&scene, &loose, aspect);
            let forward = camera.direction.normalize();
            let right = forward.cross(camera.up).normalize();
            let up = right.cross(forward);
            let (tan_v, tan_h) = (FILL * (0.5 * fov).tan(), FILL * (0.5 * fov).tan() * aspect);
            let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
            for v in &scene.vertices {
                let offset = v.position - camera.position;
                let depth = offset.dot(forward);
                assert!(depth > 0.0, "every vertex in front of the camera");
                let p = Vec2::new(offset.dot(right) / (depth * tan_h), offset.dot(up) / (depth * tan_v));
                (lo, hi) = (lo.min(p), hi.max(p));
            }
            assert!(lo.min_element() >= -1.0 - 1e-4 && hi.max_element() <= 1.0 + 1e-4, "{aspect}: {lo} {hi}");
            // Centred on the limiting axis, and touching the fill there.
            let limiting = if hi.x - lo.x > hi.y - lo.y { 0 } else { 1 };
            assert!((lo[limiting] + 1.0).abs() < 1e-3 && (hi[limiting] - 1.0).abs() < 1e-3, "{aspect}: {lo} {hi}");
            // Closer than the box's framing, looking the same way.
            assert!(
                camera.position.distance(scene.bounds().centroid())
                    < loose.position.distance(scene.bounds().centroid())
            );
            assert!(forward.dot(loose.direction.normalize()) > 0.99999);
        }
    }

    /// A room 10 x 3 x 8 with its faces wound inwards, a table in the
    /// middle, chairs along it and a picture on one wall, each its own
    /// material; without its ceiling (`open`) it is a courtyard.
    fn furnished_room(open: bool) -> Scene {
        let mut obj = String::from("mtllib room.mtl\n");
        let mut vertices = 0;
        let mut cuboid = |obj: &mut String, material: &str, min: Vec3, max: Vec3, inward: bool, skip_top: bool| {
            obj.push_str(&format!("usemtl {material}\n"));
            for i in 0..8 {
                let pick = |bit: u32, lo: f32, hi: f32| if i & bit == 0 { lo } else { hi };
                obj.push_str(&format!(
                    "v {} {} {}\n",
                    pick(1, min.x, max.x),
                    pick(2, min.y, max.y),
                    pick(4, min.z, max.z)
                ));
            }
            // Outward-facing quads of the cube's corners 1..8 (bit 1: x, bit 2: y, bit 4: z).
            let faces = [[1, 5, 7, 3], [2, 4, 8, 6], [1, 2, 6, 5], [3, 7, 8, 4], [1, 3, 4, 2], [5, 6, 8, 7]];
            for (index, face) in faces.iter().enumerate() {
                if skip_top && index == 3 {
                    continue;
                }
                let mut face = face.map(|v| v + vertices);
                if inward {
                    face.reverse();
                }
                obj.push_str(&format!("f {} {} {} {}\n", face[0], face[1], face[2], face[3]));
            }
            vertices += 8;
        };
        cuboid(&mut obj, "walls", Vec3::new(-5.0, 0.0, -4.0), Vec3::new(5.0, 3.0, 4.0), true, open);
        cuboid(&mut obj, "table", Vec3::new(-2.5, 0.7, -1.0), Vec3::new(2.5, 0.8, 1.0), false, false);
        for x in [-2.0f32, -1.0, 0.0, 1.0, 2.0] {
            for z in [-1.5f32, 1.5] {
                let min = Vec3::new(x - 0.25, 0.0, z - 0.25);
                cuboid(&mut obj, "chairs", min, min + Vec3::new(0.5, 0.9, 0.5), false, false);
            }
        }
        cuboid(&mut obj, "picture", Vec3::new(-1.0, 1.2, 3.9), Vec3::new(1.0, 2.2, 3.95), false, false);
        cuboid(&mut obj, "carpet", Vec3::new(-4.0, 0.0, -3.0), Vec3::new(4.0, 0.01, 3.0), false, false);
        let mtl = "newmtl walls\nKd 0.8 0.8 0.8\nnewmtl table\nKd 0.6 0.4 0.2\nnewmtl chairs\nKd 0.8 0.1 0.1\n\
                   newmtl picture\nKd 0.1 0.3 0.8\nnewmtl carpet\nKd 0.2 0.5 0.2\n";
        let read = |name: &str| (name == "room.mtl").then(|| mtl.as_bytes().to_vec());
        Scene::load_from_bytes("room.obj", obj.as_bytes(), &read).expect("the room loads")
    }

    #[test]
    fn a_closed_room_is_seen_from_an_upper_corner_and_a_courtyard_keeps_its_sky() {
        use rtgi_accel::{AccelKind, BuildParams};
        let fov = DEFAULT_VERTICAL_FOV_DEGREES.to_radians();
        for open in [false, true] {
            let scene = furnished_room(open);
            assert_eq!(scene.materials.len(), 5);
            let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
            let camera = frame_scene(&scene, accel.as_ref(), fov, 1.0);
            let bounds = scene.bounds();
            let (min, max) = (bounds.min, bounds.max);
            let near_a_corner = [min.x, max.x].iter().any(|x| (camera.position.x - x).abs() < 0.1 * 10.0)
                && [min.z, max.z].iter().any(|z| (camera.position.z - z).abs() < 0.1 * 8.0);
            if open {
                // Sky reaches the middle of a courtyard: no corner view from inside.
                assert!(!near_a_corner || camera.position.y > max.y, "{camera:?}");
            } else {
                assert!(near_a_corner && (camera.position.y - 1.8).abs() < 1e-3, "{camera:?}");
                assert!(camera.direction.y < 0.0, "looks down across the room: {camera:?}");
                assert!(materials_shown(&scene, accel.as_ref(), &camera, 1.0) == 5, "{camera:?}");
                // The room light hangs inside the room, between the floor in view and the ceiling.
                let lamp = crate::room_light(&scene, accel.as_ref(), &camera, Vec3::Y).position;
                assert!(bounds.contains_point(lamp) && lamp.y > 1.0 && lamp.y < 3.0, "{lamp}");
            }
        }
    }

    /// A "statue" of one material, 2 × 3 × 1, facing −Z: the box's back
    /// (+Z) is flat, its front (`detailed`) covered in small pyramids, as a
    /// face, hands and folds cover a scan's front.
    fn statue(detailed: bool) -> Scene {
        let mut obj = String::new();
        let (min, max) = (Vec3::new(-1.0, 0.0, -0.5), Vec3::new(1.0, 3.0, 0.5));
        for i in 0..8 {
            let pick = |bit: u32, lo: f32, hi: f32| if i & bit == 0 { lo } else { hi };
            obj.push_str(&format!("v {} {} {}\n", pick(1, min.x, max.x), pick(2, min.y, max.y), pick(4, min.z, max.z)));
        }
        let faces = [[1, 5, 7, 3], [2, 4, 8, 6], [1, 2, 6, 5], [3, 7, 8, 4], [1, 3, 4, 2], [5, 6, 8, 7]];
        for (index, face) in faces.iter().enumerate() {
            if !(detailed && index == 4) {
                obj.push_str(&format!("f {} {} {} {}\n", face[0], face[1], face[2], face[3]));
            }
        }
        if detailed {
            let mut next = 9;
            let (columns, rows) = (8, 12);
            for column in 0..columns {
                for row in 0..rows {
                    let x = |k: u32| min.x + (max.x - min.x) * k as f32 / columns as f32;
                    let y = |k: u32| min.y + (max.y - min.y) * k as f32 / rows as f32;
                    let corners = [(column, row), (column, row + 1), (column + 1, row + 1), (column + 1, row)];
                    for (cx, cy) in corners {
                        obj.push_str(&format!("v {} {} {}\n", x(cx), y(cy), min.z));
                    }
                    let apex = Vec3::new(0.5 * (x(column) + x(column + 1)), 0.5 * (y(row) + y(row + 1)), min.z - 0.12);
                    obj.push_str(&format!("v {} {} {}\n", apex.x, apex.y, apex.z));
                    // Wound to face −Z, outwards.
                    for k in 0..4 {
                        obj.push_str(&format!("f {} {} {}\n", next + k, next + (k + 1) % 4, next + 4));
                    }
                    next += 5;
                }
            }
        }
        Scene::load_from_bytes("statue.obj", obj.as_bytes(), &|_| None).expect("the statue loads")
    }

    #[test]
    fn a_flat_cut_out_is_seen_straight_on() {
        use rtgi_accel::{AccelKind, BuildParams};
        // A zig-zag strip in the XY plane, and the same lying in XZ.
        let mut obj = String::new();
        for i in 0..12 {
            obj.push_str(&format!("v {} {} 0\nv {} {} 0\n", i as f32, (i % 2) as f32 * 0.5, i as f32, 1.0));
        }
        for i in 0..11 {
            let (a, b) = (2 * i + 1, 2 * i + 3);
            obj.push_str(&format!("f {a} {b} {} {}\n", b + 1, a + 1));
        }
        for (lying, towards) in [(false, Vec3::Z), (true, Vec3::Y)] {
            let mut scene = Scene::load_from_bytes("strip.obj", obj.as_bytes(), &|_| None).expect("the strip loads");
            if lying {
                for vertex in &mut scene.vertices {
                    vertex.position = Vec3::new(vertex.position.x, vertex.position.z, vertex.position.y);
                }
            }
            let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
            let (camera, view) = frame_scene_explained(&scene, accel.as_ref(), 40f32.to_radians(), 1.0, Vec3::Y);
            let from = (camera.position - scene.bounds().centroid()).normalize();
            assert!(from.dot(towards) > 0.999, "lying {lying}: seen from {from}");
            assert_eq!(view, AutomaticView::Flat { from: towards });
            assert!(view.to_string().contains("the model is flat"), "{view}");
        }
    }

    #[test]
    fn a_statue_on_a_base_across_z_is_seen_upright_from_its_front_at_minus_y() {
        use rtgi_accel::{AccelKind, BuildParams};
        for (axis, up) in [(2, Vec3::Z), (1, Vec3::Y)] {
            let scene = crate::up_axis::test_models::column(axis, true);
            let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
            let camera = frame_scene(&scene, accel.as_ref(), 40f32.to_radians(), 1.0);
            let centre = scene.bounds().centroid();
            assert!((camera.up.normalize() - up).length() < 1e-5, "{axis}: up {}", camera.up);
            // From above, in the product shot's direction turned with the model.
            let from = (camera.position - centre).normalize();
            assert!(from.dot(up) > 0.2, "{axis}: seen from {from}");
            let front = crate::up_axis::turned_up(up) * Vec3::Z;
            assert!(from.dot(front) > 0.5, "{axis}: seen from {from}, the front is {front}");
        }
    }

    #[test]
    fn a_scan_is_seen_from_the_side_with_its_detail_and_a_plain_one_from_the_front() {
        use rtgi_accel::{AccelKind, BuildParams};
        // Its back, or one of its sides.
        for detailed in [true, false] {
            let scene = statue(detailed);
            assert_eq!(scene.materials.len(), 1);
            let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
            let (camera, view) = frame_scene_explained(&scene, accel.as_ref(), 40f32.to_radians(), 1.0, Vec3::Y);
            let offset = camera.position - scene.bounds().centroid();
            assert!(offset.y > 0.0 && offset.x.abs() > 0.1, "a three-quarter view from above: {offset}");
            // What `rtgi render` says of the view names the side and why.
            let said = view.to_string();
            if detailed {
                assert!(offset.z < 0.0, "the detailed front faces -Z, the camera is at {offset}");
                let AutomaticView::Product { from, side: ModelSide::Back, reason: SideReason::Detail { ratio } } = view
                else {
                    panic!("{view:?}")
                };
                assert!(from == Vec3::NEG_Z && ratio >= SIDE_DETAIL_MARGIN, "{view:?}");
                assert!(said.starts_with("a three-quarter shot of the model's back, from -Z"), "{said}");
                assert!(said.contains(&format!("{ratio:.2} times the surface detail of its front")), "{said}");
            } else {
                assert!(offset.z > 0.0, "a plain block is seen from +Z, the camera is at {offset}");
                let expected =
                    AutomaticView::Product { from: Vec3::Z, side: ModelSide::Front, reason: SideReason::Front };
                assert_eq!(view, expected);
                assert_eq!(said, "a three-quarter shot of the model's front, from +Z and above");
            }
        }
        // Turned so that its detail faces +X: seen from that side (deeper than
        // wide, but of one material, so not taken for a vehicle).
        let mut turned = statue(true);
        for vertex in &mut turned.vertices {
            let p = vertex.position;
            vertex.position = Vec3::new(-p.z, p.y, p.x);
            vertex.normal = Vec3::new(-vertex.normal.z, vertex.normal.y, vertex.normal.x);
        }
        let accel = AccelKind::Sah.build(&turned.triangle_positions(), &BuildParams::default());
        let camera = frame_scene(&turned, accel.as_ref(), 40f32.to_radians(), 1.0);
        let offset = camera.position - turned.bounds().centroid();
        assert!(offset.x > offset.z.abs(), "the detail faces +X, the camera is at {offset}");
    }

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
