use glam::Vec3;

use crate::float::later_exit;
use crate::ray::RayWithInverse;

/// An axis-aligned bounding box, closed on all sides.
///
/// The empty box has `min = +∞` and `max = -∞`, so that growing it by any
/// point or box gives that point or box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The corner with the smallest coordinates (`+∞` in every axis when empty).
    pub min: Vec3,
    /// The corner with the largest coordinates (`-∞` in every axis when empty).
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The box holding nothing: the identity of [`Aabb::union`] and [`Aabb::grow`].
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    #[inline]
    /// The box from corner `min` to corner `max` (not checked: `min > max` on an axis is empty).
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// The smallest box containing all `points`.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grow(p))
    }

    #[inline]
    /// Whether the box holds no point (`min > max` on some axis).
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// This box grown to contain `point`.
    #[inline]
    #[must_use]
    pub fn grow(&self, point: Vec3) -> Self {
        Self { min: self.min.min(point), max: self.max.max(point) }
    }

    /// The smallest box containing both boxes.
    #[inline]
    #[must_use]
    pub fn union(&self, other: &Aabb) -> Self {
        Self { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// `max - min`; negative on every axis for the empty box.
    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    #[inline]
    /// The box's centre, halfway between its corners.
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Surface area, 0 for the empty box (the SAH weighs children by it).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Half the surface area: what SAH builders compare, one multiply cheaper.
    #[inline]
    pub fn half_area(&self) -> f32 {
        let e = self.extent().max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// The axis (0, 1 or 2) along which the box is longest; the lowest axis wins ties.
    #[inline]
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    #[inline]
    /// Whether `p` lies in the box, faces included.
    pub fn contains_point(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    #[inline]
    /// Whether `other` lies wholly inside this box, faces included (an empty `other` always does).
    pub fn contains_box(&self, other: &Aabb) -> bool {
        other.is_empty() || (other.min.cmpge(self.min).all() && other.max.cmple(self.max).all())
    }

    /// The slab test: the parameter interval `[t_enter, t_exit]` in which the
    /// ray is inside the box, clipped to the ray's `[t_min, t_max]`, or `None`.
    ///
    /// The cases for a direction component `d_c = 0` (either sign) follow from
    /// IEEE arithmetic with `1 / ±0 = ±∞`, without a branch:
    ///
    /// | origin `o_c`            | slab distances          | result               |
    /// |-------------------------|-------------------------|----------------------|
    /// | `min_c < o_c < max_c`   | `-∞` and `+∞`           | no constraint        |
    /// | `o_c < min_c` or `o_c > max_c` | both `+∞` or both `-∞` | miss          |
    /// | `o_c = min_c` or `o_c = max_c` | `0 · ∞ = NaN` on that face | NaN ignored: no constraint (the box is closed) |
    ///
    /// The near and far planes are chosen from the sign bit of `1 / d_c`, so
    /// -0 behaves as a negative direction, consistent with its reciprocal -∞.
    /// The exit distance is computed with the inverse enlarged by
    /// `1 + 2⁻²¹` (reduced by it where the exit lies behind the origin of a
    /// range that starts there, [`later_exit`]), which makes the test
    /// conservative: rounding can never drop a box the ray touches (Ize,
    /// "Robust BVH Ray Traversal", JCGT 2013; pbrt-v4 `Bounds3::IntersectP`),
    /// behind the origin too.
    #[inline]
    pub fn intersect(&self, ray: &RayWithInverse) -> Option<(f32, f32)> {
        let bounds = [self.min, self.max];
        let octant = ray.octant();
        let mut t_enter = ray.t_min;
        let mut t_exit = ray.t_max;
        for axis in 0..3 {
            let near_plane = bounds[octant[axis]][axis];
            let far_plane = bounds[1 - octant[axis]][axis];
            let t_near = (near_plane - ray.origin[axis]) * ray.inv_direction[axis];
            let (ahead, behind) = (ray.inv_exit.0[axis], ray.inv_exit.1[axis]);
            let t_far = later_exit(far_plane - ray.origin[axis], ahead, behind, f32::max);
            // Written as comparisons so that a NaN distance leaves the interval alone.
            if t_near > t_enter {
                t_enter = t_near;
            }
            if t_far < t_exit {
                t_exit = t_far;
            }
        }
        // An entry at +∞ only arises when the ray runs parallel to a slab outside of it.
        (t_enter <= t_exit && t_enter < f32::INFINITY).then_some((t_enter, t_exit))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Ray;

    fn unit_box() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    fn hits(b: &Aabb, origin: Vec3, direction: Vec3) -> bool {
        b.intersect(&Ray::new(origin, direction).with_inverse()).is_some()
    }

    #[test]
    fn empty_box_is_identity_of_union() {
        let b = unit_box();
        assert_eq!(Aabb::EMPTY.union(&b), b);
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.surface_area(), 0.0);
        assert_eq!(b.surface_area(), 6.0);
        assert_eq!(b.centroid(), Vec3::splat(0.5));
        assert!(Aabb::EMPTY.intersect(&Ray::new(Vec3::ZERO, Vec3::X).with_inverse()).is_none());
    }

    #[test]
    fn longest_axis_prefers_lowest_on_ties() {
        assert_eq!(unit_box().longest_axis(), 0);
        assert_eq!(Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 2.0)).longest_axis(), 1);
        assert_eq!(Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)).longest_axis(), 2);
    }

    #[test]
    fn zero_direction_components_of_both_signs() {
        let b = unit_box();
        for zero in [0.0f32, -0.0] {
            for sign in [1.0f32, -1.0] {
                let start_z = if sign > 0.0 { -1.0 } else { 2.0 };
                // Inside the x and y slabs: the zero components impose nothing.
                assert!(hits(&b, Vec3::new(0.5, 0.5, start_z), Vec3::new(zero, zero, sign)));
                // Outside the x slab on either side: parallel rays never enter.
                assert!(!hits(&b, Vec3::new(-0.5, 0.5, start_z), Vec3::new(zero, zero, sign)));
                assert!(!hits(&b, Vec3::new(1.5, 0.5, start_z), Vec3::new(zero, zero, sign)));
                // Exactly on a face (0 * ∞ = NaN): the closed box counts as hit.
                assert!(hits(&b, Vec3::new(0.0, 0.5, start_z), Vec3::new(zero, zero, sign)));
                assert!(hits(&b, Vec3::new(1.0, 1.0, start_z), Vec3::new(zero, zero, sign)));
            }
        }
    }

    #[test]
    fn a_flat_box_behind_the_origin_is_hit_by_a_range_that_starts_behind_it() {
        // The box of an axis-aligned triangle at x = -1: entered and left at
        // t = -1. Enlarging that exit's magnitude would move it before the entry.
        let wall = Aabb::new(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(-1.0, 1.0, 1.0));
        let ray = Ray::with_range(Vec3::ZERO, Vec3::X, -10.0, 10.0).with_inverse();
        let (enter, exit) = wall.intersect(&ray).expect("the wall behind the origin is in the ray's range");
        assert!(enter <= -1.0 && exit >= -1.0, "[{enter}, {exit}]");
        let ahead = Ray::with_range(Vec3::ZERO, -Vec3::X, 0.0, 10.0).with_inverse();
        assert!(wall.intersect(&ahead).is_some());
    }

    #[test]
    fn interval_is_clipped_to_ray_range() {
        let b = unit_box();
        let ray = Ray::with_range(Vec3::new(0.5, 0.5, -1.0), Vec3::Z, 0.0, 1.5).with_inverse();
        let (t0, t1) = b.intersect(&ray).unwrap();
        assert_eq!((t0, t1), (1.0, 1.5));
        let short = Ray::with_range(Vec3::new(0.5, 0.5, -1.0), Vec3::Z, 0.0, 0.5).with_inverse();
        assert!(b.intersect(&short).is_none());
        let behind = Ray::new(Vec3::new(0.5, 0.5, 3.0), Vec3::Z).with_inverse();
        assert!(b.intersect(&behind).is_none());
    }

    #[test]
    fn near_axis_directions_are_not_clamped() {
        // A "safe inverse" that clamps 2^-26 to some epsilon would miss this box
        // (robustness notes, section 2).
        let b = Aabb::new(Vec3::new(2f32.powi(-24), -1.0, 7.0), Vec3::new(2f32.powi(-22), 1.0, 9.0));
        assert!(hits(&b, Vec3::ZERO, Vec3::new(2f32.powi(-26), 0.0, 1.0)));
    }
}
