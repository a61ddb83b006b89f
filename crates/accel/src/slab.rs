//! Ray/box slab tests: the robust one that traversal and the hit rule
//! share, and the textbook one kept for comparison.
//!
//! The robust test is used twice, with the same arithmetic: by BVH
//! traversal on node boxes, and by the hit rule ([`crate::contract`]) on
//! each hit triangle's own box. Rounding is monotone, so a box that
//! contains another is never entered later nor left earlier than it, bit
//! for bit; that is what lets traversal cull boxes exactly.

use rtgi_math::{BVec3A, Ray, Vec3A};

// The robust slab test's exit inverses and their use on either sign,
// shared with `rtgi_math::Aabb::intersect`: one definition of the
// rounding rule.
pub(crate) use rtgi_math::{EXIT_FOLD, exit_inverses, later_exit};

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxRay {
    pub(crate) origin: Vec3A,
    pub(crate) inv_direction: Vec3A,
    /// The inverse for exit distances ahead of the origin
    /// ([`rtgi_math::exit_inverses`]).
    pub(crate) inv_exit: Vec3A,
    /// The inverse for exit distances behind the origin: `inv_exit` itself
    /// unless the range starts behind the origin.
    pub(crate) inv_exit_behind: Vec3A,
    /// Whether the range starts behind the origin (`t_min < 0`, or NaN):
    /// only then do the two exit inverses differ.
    pub(crate) starts_behind: bool,
    /// Lanes where the direction's sign bit is set (so -0 counts as negative):
    /// there the box's max plane is entered first.
    pub(crate) negative: BVec3A,
    pub(crate) t_min: f32,
}

impl BoxRay {
    #[inline(always)]
    pub(crate) fn new(ray: &Ray) -> Self {
        let direction = Vec3A::from(ray.direction);
        let inv_direction = Vec3A::ONE / direction;
        let (inv_exit, inv_exit_behind) = exit_inverses(inv_direction, ray.t_min);
        Self {
            origin: ray.origin.into(),
            inv_direction,
            inv_exit,
            inv_exit_behind,
            starts_behind: Self::starts_behind(ray),
            negative: BVec3A::new(
                direction.x.is_sign_negative(),
                direction.y.is_sign_negative(),
                direction.z.is_sign_negative(),
            ),
            t_min: ray.t_min,
        }
    }
}

impl BoxRay {
    /// Whether the ray's range starts behind its origin (`t_min < 0`, or
    /// NaN): only such a ray has two different exit inverses.
    #[inline(always)]
    pub(crate) fn starts_behind(ray: &Ray) -> bool {
        rtgi_math::starts_behind(ray.t_min)
    }
}

/// A slab test: the distance at which the ray enters the box `[min, max]`
/// within `[t_min, t_max]`, or +∞ if it misses.
pub(crate) trait SlabTest {
    fn enter(ray: &BoxRay, min: Vec3A, max: Vec3A, t_max: f32) -> f32;
}

/// Conservative: exit distances computed with the inverse direction
/// enlarged by `1 + 2⁻²¹`, reduced for exits behind the origin of a range
/// that starts there ([`rtgi_math::exit_inverses`], [`later_exit`]), near and far
/// planes chosen by the direction's sign bit, and the NaN of `0 · ∞` (an
/// origin on a slab plane along a zero direction component) ignored.
///
/// Every step is monotone in the box's corners, so for boxes `A ⊆ B` the
/// computed entry of `B` is at most that of `A` and its exit at least
/// that of `A`: a ray that passes `A` passes `B`.
pub(crate) struct RobustSlabs;

impl SlabTest for RobustSlabs {
    #[inline(always)]
    fn enter(ray: &BoxRay, min: Vec3A, max: Vec3A, t_max: f32) -> f32 {
        let near = (Vec3A::select(ray.negative, max, min) - ray.origin) * ray.inv_direction;
        let to_far = Vec3A::select(ray.negative, min, max) - ray.origin;
        let far = later_exit(to_far, ray.inv_exit, ray.inv_exit_behind, Vec3A::max);
        let (enter, exit) = clip_nan_ignoring(near, far, Vec3A::splat(ray.t_min), Vec3A::splat(t_max));
        if enter <= exit && enter < f32::INFINITY { enter } else { f32::INFINITY }
    }
}

/// The common textbook slab test: `min`/`max` of the two plane distances,
/// no enlargement. Rounding can drop boxes that rays graze, and NaN can
/// drop boxes whose planes contain the origin.
pub(crate) struct FastSlabs;

impl SlabTest for FastSlabs {
    #[inline(always)]
    fn enter(ray: &BoxRay, min: Vec3A, max: Vec3A, t_max: f32) -> f32 {
        let t1 = (min - ray.origin) * ray.inv_direction;
        let t2 = (max - ray.origin) * ray.inv_direction;
        let enter = t1.min(t2).max(Vec3A::splat(ray.t_min)).max_element();
        let exit = t1.max(t2).min(Vec3A::splat(t_max)).min_element();
        if enter <= exit { enter } else { f32::INFINITY }
    }
}

/// `max(near, lower)` and `min(far, upper)` reduced over the three axes,
/// where a NaN in `near` or `far` yields the bound instead.
///
/// On x86, SSE's `maxps`/`minps` return their second operand when either is
/// NaN, and glam passes `self` first, so the plain methods already ignore
/// NaNs in `near` and `far`. Elsewhere (NEON propagates NaN) a
/// compare-and-select does the same. The unit tests of the slab test cover
/// origins on the planes with zero direction components on every platform.
#[inline(always)]
fn clip_nan_ignoring(near: Vec3A, far: Vec3A, lower: Vec3A, upper: Vec3A) -> (f32, f32) {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        (near.max(lower).max_element(), far.min(upper).min_element())
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        let enter = Vec3A::select(near.cmpgt(lower), near, lower).max_element();
        let exit = Vec3A::select(far.cmplt(upper), far, upper).min_element();
        (enter, exit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Vec3;

    fn enter(origin: Vec3, direction: Vec3, min: Vec3, max: Vec3) -> f32 {
        RobustSlabs::enter(&BoxRay::new(&Ray::new(origin, direction)), min.into(), max.into(), f32::INFINITY)
    }

    #[test]
    fn zero_components_and_origins_on_planes() {
        let (min, max) = (Vec3::ZERO, Vec3::ONE);
        for zero in [0.0f32, -0.0] {
            // Parallel to the x = 0 face, origin on its plane: inside the slab.
            assert_eq!(enter(Vec3::new(0.0, 0.5, -1.0), Vec3::new(zero, 0.0, 1.0), min, max), 1.0);
            // Parallel and outside the slab: a miss.
            assert_eq!(enter(Vec3::new(-0.5, 0.5, -1.0), Vec3::new(zero, 0.0, 1.0), min, max), f32::INFINITY);
            // Along an edge of the box (two planes through the origin).
            assert_eq!(enter(Vec3::new(1.0, 1.0, -1.0), Vec3::new(zero, zero, 1.0), min, max), 1.0);
        }
    }

    #[test]
    fn the_exit_inverses_are_those_of_the_rule() {
        for t_min in [0.0, -0.0, 1.0, -1.0, f32::NAN, f32::NEG_INFINITY] {
            let ray = Ray::with_range(Vec3::ONE, Vec3::new(0.3, -0.0, -7.0e-30), t_min, f32::INFINITY);
            let box_ray = BoxRay::new(&ray);
            for axis in 0..3 {
                let (ahead, behind) = exit_inverses(box_ray.inv_direction[axis], t_min);
                assert_eq!(box_ray.inv_exit[axis].to_bits(), ahead.to_bits());
                assert_eq!(box_ray.inv_exit_behind[axis].to_bits(), behind.to_bits());
            }
            assert_eq!(box_ray.starts_behind, box_ray.inv_exit.to_array() != box_ray.inv_exit_behind.to_array());
        }
    }

    #[test]
    fn containing_boxes_are_entered_no_later() {
        // Monotonicity, the property exact culling rests on: for nested
        // boxes, random rays enter the outer one no later than the inner one.
        let mut rng = rtgi_math::Rng::new(3, 1);
        let mut point = |s: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * s - s / 2.0;
        for _ in 0..20_000 {
            let (a, b) = (point(4.0), point(4.0));
            let (inner_min, inner_max) = (a.min(b), a.max(b));
            let (outer_min, outer_max) = (inner_min - point(1.0).abs(), inner_max + point(1.0).abs());
            let origin = point(16.0);
            let mut direction = point(2.0);
            if direction.x.abs() < 0.3 {
                direction.x = 0.0;
            }
            let inner = enter(origin, direction, inner_min, inner_max);
            let outer = enter(origin, direction, outer_min, outer_max);
            assert!(outer <= inner, "{outer} > {inner}");
        }
    }

    /// The case the exit factor exists for: a box flat along one axis (an
    /// axis-aligned triangle's) is entered and left at one exact distance,
    /// and rounding must not put the computed exit before the entry, for
    /// walls ahead of the origin and, for ranges that start behind it,
    /// behind it; at every scale the coordinates take.
    #[test]
    fn a_flat_box_the_ray_crosses_is_entered_ahead_of_and_behind_the_origin() {
        let mut rng = rtgi_math::Rng::new(17, 5);
        let mut uniform = |low: f32, high: f32| low + (high - low) * rng.next_f32();
        let mut crossed = 0;
        for case in 0..200_000 {
            let scale = 2f32.powi((case % 41) as i32 - 20);
            let origin = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)) * scale;
            let direction = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0));
            let axis = case % 3;
            let wall = origin[axis] + uniform(-4.0, 4.0) * scale;
            let t = (f64::from(wall) - f64::from(origin[axis])) / f64::from(direction[axis]);
            if !t.is_finite() {
                continue;
            }
            // The other axes' slabs hold the crossing point with room to spare.
            let (mut min, mut max) = (Vec3::splat(wall), Vec3::splat(wall));
            for other in (0..3).filter(|&other| other != axis) {
                let at = f64::from(origin[other]) + t * f64::from(direction[other]);
                let room = at.abs() * 1e-3 + f64::from(scale);
                min[other] = (at - room) as f32;
                max[other] = (at + room) as f32;
            }
            let t_min = if t < 0.0 { (t * 2.0 - 1.0) as f32 } else { 0.0 };
            let ray = Ray::with_range(origin, direction, t_min, f32::INFINITY);
            let enter = RobustSlabs::enter(&BoxRay::new(&ray), min.into(), max.into(), f32::INFINITY);
            assert!(enter < f32::INFINITY, "case {case}: {ray:?} misses the wall {axis} = {wall} at t = {t}");
            crossed += 1;
        }
        assert!(crossed > 190_000, "{crossed}");
    }

    /// The case the exit factor's size is set for: the exact ray grazes a
    /// box's edge, entering one axis's slab at the distance where it
    /// leaves another's, so entry and exit come from different inverses
    /// and each rounding may move them apart. The coordinates have short
    /// mantissas, so the touching point and its offsets from the origin
    /// are exact and only the inverses and products round. Ahead of the
    /// origin and, for ranges that start behind it, behind it.
    #[test]
    fn a_box_whose_edge_the_ray_grazes_is_entered() {
        let mut rng = rtgi_math::Rng::new(23, 9);
        let mut short = |bits: u32| {
            let odd = (rng.next_u32() % (1 << bits)) | 1;
            let sign = if rng.next_u32().is_multiple_of(2) { 1.0 } else { -1.0 };
            sign * odd as f32 / (1 << bits) as f32
        };
        let mut grazed = 0;
        for case in 0..200_000 {
            let scale = 2f32.powi(case % 31 - 15);
            let direction = Vec3::new(short(12), short(12), short(12));
            let origin = Vec3::new(short(6), short(6), short(6)) * 4.0 * scale;
            let t = short(8) * 4.0 * scale;
            let touch = [0, 1, 2].map(|axis| f64::from(origin[axis]) + f64::from(t) * f64::from(direction[axis]));
            if touch.iter().any(|&c| c as f32 as f64 != c) {
                continue;
            }
            let touch = Vec3::from(touch.map(|c| c as f32));
            // Leave the slab of `leave` and enter that of `enter` at `t`.
            let (leave, enter) = ((case % 3) as usize, (case / 3 % 3) as usize);
            if leave == enter {
                continue;
            }
            let room = Vec3::splat(scale);
            let (mut min, mut max) = (touch - room, touch + room);
            if direction[leave] > 0.0 {
                max[leave] = touch[leave]
            } else {
                min[leave] = touch[leave]
            }
            if direction[enter] > 0.0 {
                min[enter] = touch[enter]
            } else {
                max[enter] = touch[enter]
            }
            let t_min = if t < 0.0 { t * 2.0 } else { 0.0 };
            let ray = Ray::with_range(origin, direction, t_min, f32::INFINITY);
            let entry = RobustSlabs::enter(&BoxRay::new(&ray), min.into(), max.into(), f32::INFINITY);
            assert!(entry < f32::INFINITY, "case {case}: {ray:?} misses [{min}, {max}], grazed at t = {t}");
            grazed += 1;
        }
        assert!(grazed > 50_000, "{grazed}");
    }
}
