//! Which way is up in a model that does not say: most files are +Y up (glTF
//! by its specification, most OBJ exports), but scans and CAD parts are
//! often +Z up (or −Z), and shown +Y up they lie on their side.
//!
//! The evidence is a flat base: the cut a bust or statue stands on, the
//! machined face a part rests on. It is the area of triangles that lie in
//! one face of the model's bounds and face along its axis. A model keeps
//! +Y unless a face across another axis holds a clear base, on one side
//! only, and the faces across Y hold next to none: measured on the shared
//! and sample scenes, the bunny (1.9% of its surface at −Y), the dragon
//! (0.8%), the teapot (7.8%) and every room and box (their floors) keep +Y,
//! and a Z-up bust (5.9% at −Z, none across Y) and a CAD part (24.5% at +Z)
//! turn.

use rtgi_math::Vec3;
use rtgi_math::glam::Quat;
use rtgi_scene::Scene;

/// The least share of the surface that makes a base.
const BASE_SHARE: f32 = 0.03;
/// A base across Y must be below this fraction of the other axis's for that
/// axis to win: a model standing on a floor keeps +Y.
const Y_BASE_FRACTION: f32 = 0.25;
/// The opposite face must hold less than this fraction of the base: a
/// base is on one side (a box is flat on all).
const OPPOSITE_FRACTION: f32 = 0.5;
/// Triangles within this fraction of the bounds' largest side from a face lie in it.
const FACE_TOLERANCE: f32 = 0.01;
/// And face along its axis within this angle, in degrees.
const FACE_ANGLE_DEGREES: f32 = 5.0;

/// The up direction of a model, and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpAxis {
    /// The unit up direction.
    pub up: Vec3,
    /// The share of the surface in the base that decided it, when one did
    /// (`None`: +Y, by convention).
    pub base_share: Option<f32>,
}

impl UpAxis {
    /// +Y, the convention of glTF and most files.
    pub const Y: UpAxis = UpAxis { up: Vec3::Y, base_share: None };

    /// The axis's name: `+Z`, `-X`, or the vector when it is no axis.
    pub fn name(&self) -> String {
        axis_name(self.up)
    }
}

/// `direction`'s name: `+Z`, `-X`, or its components when it is no axis.
pub fn axis_name(direction: Vec3) -> String {
    for (axis, name) in [(Vec3::X, "X"), (Vec3::Y, "Y"), (Vec3::Z, "Z")] {
        if direction == axis {
            return format!("+{name}");
        }
        if direction == -axis {
            return format!("-{name}");
        }
    }
    format!("({}, {}, {})", direction.x, direction.y, direction.z)
}

/// The rotation that takes the +Y-up conventions (the default sky, the
/// sun, the automatic views' sides, +Z their front) to `up`: the shortest
/// arc, so +Z up puts the front at −Y (as a Z-up modeller's front view
/// looks along +Y).
pub fn turned_up(up: Vec3) -> Quat {
    let up = up.try_normalize().unwrap_or(Vec3::Y);
    if up.dot(Vec3::Y) < -0.999_999 {
        // Upside down: half a turn about X (the sides stay where they were).
        Quat::from_rotation_x(std::f32::consts::PI)
    } else {
        Quat::from_rotation_arc(Vec3::Y, up)
    }
}

/// The model's up direction ([`UpAxis`]): the one its file's format fixes
/// ([`Scene::up`], +Y for glTF), else judged by its flat base.
pub fn detect_up(scene: &Scene) -> UpAxis {
    if let Some(up) = scene.up.and_then(|up| up.try_normalize()) {
        return UpAxis { up, base_share: None };
    }
    let bounds = scene.bounds();
    if bounds.is_empty() {
        return UpAxis::Y;
    }
    let extent = bounds.extent();
    let tolerance = FACE_TOLERANCE * extent.max_element();
    // A flat model (a cut-out) has no base: all of it lies in two faces.
    if extent.min_element() <= tolerance {
        return UpAxis::Y;
    }
    let cos_limit = FACE_ANGLE_DEGREES.to_radians().cos();
    // Area in each face of the bounds: [axis][low, high].
    let mut faces = [[0.0f64; 2]; 3];
    let mut total = 0.0f64;
    for triangle in &scene.triangles {
        let [a, b, c] = triangle.vertices.map(|v| scene.vertices[v as usize].position);
        let cross = (b - a).cross(c - a);
        let length = cross.length();
        if !(length > 0.0 && length.is_finite()) {
            continue;
        }
        total += f64::from(0.5 * length);
        for axis in 0..3 {
            if cross[axis].abs() < cos_limit * length {
                continue;
            }
            for (side, plane) in [bounds.min[axis], bounds.max[axis]].into_iter().enumerate() {
                if [a, b, c].iter().all(|p| (p[axis] - plane).abs() <= tolerance) {
                    faces[axis][side] += f64::from(0.5 * length);
                }
            }
        }
    }
    if total <= 0.0 {
        return UpAxis::Y;
    }
    let share = |axis: usize, side: usize| (faces[axis][side] / total) as f32;
    let across_y = share(1, 0) + share(1, 1);
    let mut best: Option<(usize, usize, f32)> = None;
    for axis in [0, 2] {
        for side in 0..2 {
            let base = share(axis, side);
            if base >= BASE_SHARE
                && share(axis, 1 - side) < OPPOSITE_FRACTION * base
                && across_y < Y_BASE_FRACTION * base
                && best.is_none_or(|(_, _, most)| base > most)
            {
                best = Some((axis, side, base));
            }
        }
    }
    match best {
        // A base in the low face (facing down along the axis) puts up along +axis.
        Some((axis, side, base)) => {
            let mut up = Vec3::ZERO;
            up[axis] = if side == 0 { 1.0 } else { -1.0 };
            UpAxis { up, base_share: Some(base) }
        }
        None => UpAxis::Y,
    }
}

/// Models for the tests of this module and of the framing.
#[cfg(test)]
pub(crate) mod test_models {
    use rtgi_math::{Vec2, Vec3, Vec4};
    use rtgi_scene::{Material, Scene, Triangle, Vertex};

    fn vertex(position: Vec3) -> Vertex {
        Vertex { position, normal: Vec3::Y, uv: Vec2::ZERO, uv1: Vec2::ZERO, color: Vec4::ONE, tangent: Vec4::ZERO }
    }

    /// A lumpy column along `axis` (a statue), closed at its low end by a
    /// flat round base when `base` is set.
    pub(crate) fn column(axis: usize, base: bool) -> Scene {
        let mut scene = Scene { materials: vec![Material::default()], ..Scene::default() };
        let (rings, sides) = (24usize, 16usize);
        let place = |along: f32, x: f32, y: f32| {
            // (x, y) across the axis, `along` the axis.
            let mut p = Vec3::ZERO;
            p[axis] = along;
            p[(axis + 1) % 3] = x;
            p[(axis + 2) % 3] = y;
            p
        };
        for ring in 0..=rings {
            let along = ring as f32 / rings as f32 * 4.0;
            // Lumpy, narrowing to a point at the top: no flat faces but the base.
            let radius = if ring == rings { 0.0 } else { 1.0 + 0.2 * (along * 3.0).sin() };
            for side in 0..sides {
                let angle = side as f32 / sides as f32 * std::f32::consts::TAU + 0.3 * ring as f32;
                scene.vertices.push(vertex(place(along, radius * angle.cos(), radius * angle.sin())));
            }
        }
        for ring in 0..rings {
            for side in 0..sides {
                let v = |r: usize, s: usize| (r * sides + s % sides) as u32;
                let (a, b, c, d) = (v(ring, side), v(ring, side + 1), v(ring + 1, side + 1), v(ring + 1, side));
                scene.triangles.push(Triangle { vertices: [a, b, c], material: 0 });
                scene.triangles.push(Triangle { vertices: [a, c, d], material: 0 });
            }
        }
        if base {
            // The bottom ring closed by a fan: flat, across the axis.
            let centre = scene.vertices.len() as u32;
            scene.vertices.push(vertex(place(0.0, 0.0, 0.0)));
            for side in 0..sides as u32 {
                scene.triangles.push(Triangle { vertices: [centre, (side + 1) % sides as u32, side], material: 0 });
            }
        }
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::test_models::column;
    use super::*;
    #[test]
    fn a_model_on_a_flat_base_across_z_is_z_up_and_one_on_y_keeps_y() {
        let z = detect_up(&column(2, true));
        assert_eq!(z.up, Vec3::Z, "{z:?}");
        assert!(z.base_share.is_some_and(|s| s > BASE_SHARE), "{z:?}");
        // Stood the other way (base at the high end): -Z.
        let mut flipped = column(2, true);
        for v in &mut flipped.vertices {
            v.position.z = -v.position.z;
        }
        assert_eq!(detect_up(&flipped).up, Vec3::NEG_Z);
        // On a base across Y, or with no base at all, +Y.
        assert_eq!(detect_up(&column(1, true)), UpAxis::Y);
        assert_eq!(detect_up(&column(2, false)), UpAxis::Y);
        assert_eq!(detect_up(&column(0, false)), UpAxis::Y);
    }

    #[test]
    fn a_format_that_fixes_up_is_not_second_guessed() {
        // A glTF statue on a base across Z is still +Y up, as its format says.
        let gltf = Scene { up: Some(Vec3::Y), ..column(2, true) };
        assert_eq!(detect_up(&gltf), UpAxis::Y);
    }

    #[test]
    fn turning_up_keeps_y_and_puts_z_up_models_front_at_minus_y() {
        assert!((turned_up(Vec3::Y) * Vec3::Z - Vec3::Z).length() < 1e-6);
        let z = turned_up(Vec3::Z);
        assert!((z * Vec3::Y - Vec3::Z).length() < 1e-6 && (z * Vec3::Z - Vec3::NEG_Y).length() < 1e-6);
        let down = turned_up(Vec3::NEG_Y);
        assert!((down * Vec3::Y - Vec3::NEG_Y).length() < 1e-6);
        assert_eq!(axis_name(Vec3::NEG_Z), "-Z");
    }
}
