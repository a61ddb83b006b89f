//! Ray/box slab tests: the robust one that traversal and the hit rule
//! share, and the textbook one kept for comparison.
//!
//! The robust test is used twice, with the same arithmetic: by BVH
//! traversal on node boxes, and by the hit rule ([`crate::contract`]) on
//! each hit triangle's own box. Rounding is monotone, so a box that
//! contains another is never entered later nor left earlier than it, bit
//! for bit; that is what lets traversal cull boxes exactly.

use rtgi_math::{BVec3A, Ray, Vec3A};

// The robust slab test's exit factor and its use on either sign, shared
// with `rtgi_math::Aabb::intersect`: one definition of the rounding rule.
pub(crate) use rtgi_math::{ROBUST_FAR_SCALE, ROBUST_FAR_SHRINK, later_exit};

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxRay {
    pub(crate) origin: Vec3A,
    pub(crate) inv_direction: Vec3A,
    /// Lanes where the direction's sign bit is set (so -0 counts as negative):
    /// there the box's max plane is entered first.
    pub(crate) negative: BVec3A,
    pub(crate) t_min: f32,
}

impl BoxRay {
    #[inline(always)]
    pub(crate) fn new(ray: &Ray) -> Self {
        let direction = Vec3A::from(ray.direction);
        Self {
            origin: ray.origin.into(),
            inv_direction: Vec3A::ONE / direction,
            negative: BVec3A::new(
                direction.x.is_sign_negative(),
                direction.y.is_sign_negative(),
                direction.z.is_sign_negative(),
            ),
            t_min: ray.t_min,
        }
    }
}

/// A slab test: the distance at which the ray enters the box `[min, max]`
/// within `[t_min, t_max]`, or +∞ if it misses.
pub(crate) trait SlabTest {
    fn enter(ray: &BoxRay, min: Vec3A, max: Vec3A, t_max: f32) -> f32;
}

/// Conservative: exit distances moved later by the factor `1 + 2γ(3)`
/// whatever their sign ([`later_exit`]), near and far
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
        let t_min_planes = (min - ray.origin) * ray.inv_direction;
        let t_max_planes = (max - ray.origin) * ray.inv_direction;
        let near = Vec3A::select(ray.negative, t_max_planes, t_min_planes);
        let far = later_exit(Vec3A::select(ray.negative, t_min_planes, t_max_planes), Vec3A::max);
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
}
