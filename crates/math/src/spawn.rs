//! Rays that leave surfaces without hitting them again.
//!
//! A hit point computed in floating point lies near the surface, not on
//! it: a ray spawned there may hit the surface it leaves. Instead of a
//! fixed epsilon, which fails at some scale, the origin moves off the
//! surface along the geometric normal by a conservative bound on the hit
//! point's rounding error, then one more float away (pbrt-v4, section
//! 6.8.6, `OffsetRayOrigin`). The offset is a few ulps of the coordinates,
//! so it works at every scale and leaks almost no light through thin gaps.

use glam::Vec3;

use crate::float::{gamma, next_float_down, next_float_up};
use crate::ray::Ray;

/// A point on a triangle, with a per-coordinate bound on the absolute
/// error of its computed position and the triangle's geometric normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// The computed position on the triangle.
    pub position: Vec3,
    /// `|computed - exact| <= error` in each coordinate.
    pub error: Vec3,
    /// Unit geometric normal (either side).
    pub normal: Vec3,
}

impl SurfacePoint {
    /// The point with barycentric coordinates `(1 - beta - gamma, beta,
    /// gamma)` on the triangle `corners`, as a ray/triangle test reports
    /// it. The error bound `γ(7) Σ |b_i p_i|` covers the barycentrics' and
    /// the interpolation's rounding (pbrt-v4, section 6.8.5); a term of
    /// `16 ε` times the farthest corner's distance times the triangle's
    /// [`elongation`] (at most [`MAX_ELONGATION`]) covers the rounding of the
    /// ray/triangle test's distances, so that rays leaving the point never
    /// hit the triangle again.
    pub fn on_triangle(corners: &[Vec3; 3], beta: f32, gamma_: f32) -> Self {
        Self::on_triangle_with_shape(corners, beta, gamma_, TriangleShape::of(corners))
    }

    /// [`SurfacePoint::on_triangle`] for a triangle whose shape is already
    /// known (renderers keep them: the double-precision square roots and
    /// divisions of [`TriangleShape::of`] are a noticeable share of a path
    /// tracer's time).
    #[inline]
    pub fn on_triangle_with_shape(corners: &[Vec3; 3], beta: f32, gamma_: f32, shape: TriangleShape) -> Self {
        let alpha = 1.0 - beta - gamma_;
        let [p0, p1, p2] = corners;
        let position = alpha * *p0 + beta * *p1 + gamma_ * *p2;
        let rounding = gamma(7) * ((alpha * *p0).abs() + (beta * *p1).abs() + (gamma_ * *p2).abs());
        // A ray that leaves the point meets this triangle's plane again, in
        // the ray/triangle test, a tiny distance behind its origin; the test
        // must find that distance negative. The watertight test computes it
        // from the corners relative to the origin, as an average of their
        // distances along the ray weighted by rounded edge functions, so it
        // errs by a few ulps of the farthest corner's distance, and by more
        // for slivers, whose weights round by up to their elongation (longest
        // edge over altitude) times more. The origin starts farther off the
        // plane than 16 ε times that distance times the elongation, which is
        // capped at 64 so that needles do not open gaps that leak light;
        // needles more elongated than that may still be hit again.
        let extent = (*p0 - position).abs().max((*p1 - position).abs()).max((*p2 - position).abs()).max_element();
        let error = rounding + Vec3::splat(16.0 * f32::EPSILON * extent * shape.elongation.min(MAX_ELONGATION));
        Self { position, error, normal: shape.normal }
    }

    /// The origin for a ray leaving this point towards `direction`.
    #[inline]
    pub fn offset_origin(&self, direction: Vec3) -> Vec3 {
        offset_ray_origin(self.position, self.error, self.normal, direction)
    }

    /// A ray from this point towards `direction`, over `(0, ∞)`.
    #[inline]
    pub fn spawn_ray(&self, direction: Vec3) -> Ray {
        Ray::with_range(self.offset_origin(direction), direction, SPAWN_T_MIN, f32::INFINITY)
    }

    /// A ray from this point to `target`: both ends are moved off their
    /// surfaces by their error bounds, towards each other, and the ray runs
    /// over `[0, 1 - 16ε]` of the segment between them. (The parameter
    /// bound stops ties with the target's surface, whose computed distance
    /// may round to 1; it is relative, so the same at every scale.)
    ///
    /// The origin's side is chosen by the target's computed position, but
    /// the ray runs to the target moved off its own surface. When the target
    /// lies within rounding of this triangle's plane (on a neighbour across
    /// a shallow or right-angled edge, the two points tens of ulps apart),
    /// that move can put the end on the other side of the plane, and the
    /// segment crosses it, often inside the triangle it leaves: `rtgi
    /// experiment intersector` found 13 such self-hits in 1.4 million rays
    /// on solids 2^13 to 2^22 from the origin. So the origin moves to the
    /// side where the end is, and the end, if it still lies lower above
    /// this plane than the origin, is raised to the origin's height (a few
    /// ulps): like [`SurfacePoint::spawn_ray`]'s, the ray then never heads
    /// back towards the surface it leaves.
    #[inline]
    pub fn spawn_ray_to(&self, target: &SurfacePoint) -> Ray {
        let mut from = self.offset_origin(target.position - self.position);
        let mut to = target.offset_origin(from - target.position);
        if (to - from).dot(self.normal) * (from - self.position).dot(self.normal) < 0.0 {
            from = self.offset_origin(to - self.position);
            to = target.offset_origin(from - target.position);
        }
        let to = self.not_below(from, to);
        Ray::with_range(from, to - from, SPAWN_T_MIN, SHADOW_T_MAX)
    }

    /// A ray from this point to a point `target` that lies on no surface
    /// (a point light), over `[0, 1 - 16ε]`. A target within the origin's
    /// offset of this triangle's plane is raised to the origin's height, as
    /// in [`SurfacePoint::spawn_ray_to`].
    #[inline]
    pub fn spawn_ray_to_point(&self, target: Vec3) -> Ray {
        let from = self.offset_origin(target - self.position);
        let target = self.not_below(from, target);
        Ray::with_range(from, target - from, SPAWN_T_MIN, SHADOW_T_MAX)
    }

    /// `to`, or, if it lies less far than `from` (an origin offset from this
    /// point) on `from`'s side of this triangle's plane, `to` moved along
    /// the normal to `from`'s height and one float further: a segment from
    /// `from` to it then does not approach the plane, so it cannot cross it.
    // Inlined for the same reason as `offset_ray_origin`.
    #[inline(always)]
    fn not_below(&self, from: Vec3, to: Vec3) -> Vec3 {
        let side = if (from - self.position).dot(self.normal) < 0.0 { -self.normal } else { self.normal };
        let lift = (from - self.position).dot(side) - (to - self.position).dot(side);
        if lift > 0.0 { offset_ray_origin(to + lift * side, Vec3::ZERO, side, side) } else { to }
    }
}

/// What rays leaving a triangle need of it besides its corners: its unit
/// geometric normal and its [`elongation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleShape {
    /// Unit geometric normal (either side), or zero for a degenerate triangle.
    pub normal: Vec3,
    /// The triangle's [`elongation`]: how thin it is, which scales the error of points on it.
    pub elongation: f32,
}

impl TriangleShape {
    /// The normal and elongation of the triangle with these corners.
    pub fn of(corners: &[Vec3; 3]) -> Self {
        Self { normal: geometric_normal(corners), elongation: elongation(corners) }
    }
}

/// Elongations up to which rays spawned from a triangle are offset far
/// enough never to hit it again (see [`SurfacePoint::on_triangle`]).
pub const MAX_ELONGATION: f32 = 64.0;

/// How elongated a triangle is: its longest edge over its altitude onto
/// that edge (the square of the longest edge over twice the area); at
/// least about 1.15 (equilateral), infinite for a degenerate triangle.
pub fn elongation(corners: &[Vec3; 3]) -> f32 {
    let [a, b, c] = corners.map(|v| v.as_dvec3());
    let longest = (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    (longest / (b - a).cross(c - a).length()) as f32
}

/// The unit normal of a triangle by the right-hand rule, or zero for a
/// degenerate one. It is computed in double precision, where the edges of
/// single-precision corners are (nearly always) exact and their cross
/// product neither underflows nor overflows, so it is accurate even for
/// slivers: rays spawned from a sliver move off its true plane.
pub fn geometric_normal(corners: &[Vec3; 3]) -> Vec3 {
    let [a, b, c] = corners.map(|v| v.as_dvec3());
    let n = (b - a).cross(c - a).normalize_or_zero();
    if n.is_finite() { n.as_vec3() } else { Vec3::ZERO }
}

/// Spawned rays exclude `t = 0` (the smallest normal float is their
/// start): an origin moved off an exactly computed point on an exact plane
/// may be only a tiny distance away, and the products of a ray/triangle
/// test can round such a negative distance to -0. It is the smallest
/// *normal* float because subnormal operands make x86 processors compute
/// in slow microcode (see [`offset_ray_origin`]).
const SPAWN_T_MIN: f32 = f32::MIN_POSITIVE;

/// The end of shadow-ray segments: 1 less the rounding of a computed hit distance.
const SHADOW_T_MAX: f32 = 1.0 - 16.0 * f32::EPSILON;

/// Moves `p` off its surface to the side of `normal` that `direction`
/// points to, by the error bound `error` projected on the normal, and then
/// rounds each moved coordinate one float further to that side (pbrt-v4,
/// `OffsetRayOrigin`). The last step happens even where the error bound is
/// zero (a point computed exactly, on an axis-aligned surface), so the
/// origin always leaves the surface and a hit at `t = 0` cannot occur.
///
/// Subnormal numbers are kept out of ray origins: x86 processors compute
/// with them in slow microcode, and a point on the plane x = 0 moved by one
/// float would become one, slowing down every box and triangle test of its
/// rays (path tracing a box with walls through zero ran 1.8 times slower).
/// So the distance is at least the rounding error of the point's largest
/// coordinate, and a coordinate that would still be subnormal (the point
/// is the origin) becomes the smallest normal float on its side.
///
/// Always inlined: called, it took its vectors through memory, and loading
/// two of a caller's separately stored coordinates as one 8-byte word
/// cannot be forwarded from the stores, so each call waited for them (a
/// fifth of the samples of the function, which had 7.7% of a Cornell box
/// render's). Inlined into the spawning functions, the render takes 5% less
/// time, with the same bits.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, error: Vec3, normal: Vec3, direction: Vec3) -> Vec3 {
    let side = if direction.dot(normal) < 0.0 { -normal } else { normal };
    // At least the rounding error of one coordinate of this size: a point
    // computed exactly on an axis-aligned plane through zero would otherwise
    // move by a subnormal distance.
    let distance = side.abs().dot(error).max(gamma(1) * p.abs().max_element());
    let moved = p + distance * side;
    let away = |value: f32, towards: f32| {
        let normal_beyond = |v: f32, sign: f32| {
            if v.abs() < f32::MIN_POSITIVE { f32::MIN_POSITIVE.copysign(sign) } else { v }
        };
        if towards > 0.0 {
            normal_beyond(next_float_up(value), 1.0)
        } else if towards < 0.0 {
            normal_beyond(next_float_down(value), -1.0)
        } else {
            value
        }
    };
    Vec3::new(away(moved.x, side.x), away(moved.y, side.y), away(moved.z, side.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_is_on_the_side_of_the_direction_and_scales_with_the_point() {
        for scale in [1e-20f32, 1e-3, 1.0, 1e3, 1e7, 1e20] {
            let corners =
                [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)].map(|c| c * scale);
            let point = SurfacePoint::on_triangle(&corners, 0.25, 0.25);
            assert!(point.error.max_element() > 0.0 && point.error.max_element() < 1e-5 * scale);
            let up = point.offset_origin(Vec3::Z);
            let down = point.offset_origin(-Vec3::Z);
            assert!(up.z > point.position.z && down.z < point.position.z, "scale {scale}");
            // A few ulps, not a fixed distance.
            assert!((up.z - point.position.z) < 64.0 * f32::EPSILON * scale, "scale {scale}");
            assert_eq!((up.x, up.y), (point.position.x, point.position.y));
            // Exact points on exact planes still move off them.
            let exact = SurfacePoint { position: Vec3::new(0.0, 0.0, scale), error: Vec3::ZERO, normal: Vec3::Z };
            assert!(exact.offset_origin(-Vec3::Z).z < scale && exact.offset_origin(Vec3::Z).z > scale);
        }
    }

    #[test]
    fn segments_to_targets_within_rounding_of_the_plane_never_head_back_into_it() {
        // A point on the plane z = c, far from the origin, and targets a few
        // ulps either side of that plane on a perpendicular surface (across a
        // cube's edge), tens of ulps away: the segment must not approach the
        // plane it leaves, whichever side the origin went to.
        let c = 131072.0f32;
        let ulp = next_float_up(c) - c;
        let corners = [Vec3::new(c, c, c), Vec3::new(c + 64.0 * ulp, c, c), Vec3::new(c, c + 64.0 * ulp, c)];
        let point = SurfacePoint::on_triangle(&corners, 0.3, 0.3);
        for height in -4..=4 {
            let target = SurfacePoint {
                position: point.position + Vec3::new(20.0 * ulp, 0.0, height as f32 * ulp),
                error: Vec3::splat(4.0 * ulp),
                normal: Vec3::X,
            };
            for ray in [point.spawn_ray_to(&target), point.spawn_ray_to_point(target.position)] {
                let above = ray.origin.z - c;
                assert!(above != 0.0, "height {height}");
                assert!(ray.direction.z * above >= 0.0, "height {height}: {ray:?} heads back to the plane");
            }
        }
    }

    #[test]
    fn shadow_segment_ends_short_of_the_target() {
        let a = SurfacePoint { position: Vec3::ZERO, error: Vec3::splat(1e-7), normal: Vec3::Y };
        let b = SurfacePoint { position: Vec3::new(0.0, 10.0, 0.0), error: Vec3::splat(1e-6), normal: -Vec3::Y };
        let ray = a.spawn_ray_to(&b);
        assert!(ray.origin.y > 0.0);
        let end = ray.at(ray.t_max);
        assert!(end.y < 10.0 && end.y > 9.999);
    }
}
