//! One ray against the `W` child boxes of a wide node.
//!
//! The boxes are stored structure-of-arrays ([`WideBoxes`]), and each lane
//! runs the arithmetic of the robust slab test ([`crate::slab::RobustSlabs`])
//! on its box: the same subtractions, products and enlargement of the exit
//! distance, and the same treatment of NaN (an origin on a slab plane along
//! a zero direction component leaves that axis out). Only the order in
//! which the three axes' distances are combined differs, and maxima and
//! minima are exact, so each lane's entry distance is the bits the scalar
//! test computes: culling stays exact (see the crate's exactness contract).

use rtgi_math::Vec4;

use crate::slab::{BoxRay, later_exit};

/// The boxes of `W` children: `planes[k]` holds, for each child, the box's
/// minimum (k = 0, 1, 2) or maximum (k = 3, 4, 5) along axis `k % 3`.
/// Lanes without a child hold the empty box (minimum +∞, maximum -∞),
/// which no ray enters.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct WideBoxes<const W: usize> {
    pub(crate) planes: [[f32; W]; 6],
}

impl<const W: usize> WideBoxes<W> {
    pub(crate) const EMPTY: Self = Self {
        planes: [
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
            [f32::NEG_INFINITY; W],
        ],
    };

    /// Sets lane `lane` to the box `[min, max]`.
    pub(crate) fn set(&mut self, lane: usize, min: [f32; 3], max: [f32; 3]) {
        for axis in 0..3 {
            self.planes[axis][lane] = min[axis];
            self.planes[3 + axis][lane] = max[axis];
        }
    }

    /// The box in lane `lane`, as its minimum and maximum.
    #[inline(always)]
    pub(crate) fn lane(&self, lane: usize) -> ([f32; 3], [f32; 3]) {
        let p = &self.planes;
        ([p[0][lane], p[1][lane], p[2][lane]], [p[3][lane], p[4][lane], p[5][lane]])
    }

    /// The distance at which the ray enters each box within
    /// `[t_min, t_max]`, or +∞ for boxes it misses, and a mask of the
    /// boxes entered (bit `i` for lane `i`).
    ///
    /// Four lanes at a time, as `Vec4`s: SSE at the baseline, VEX- or
    /// EVEX-encoded when compiled for a wider level.
    #[inline(always)]
    pub(crate) fn enter(&self, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        self.enter_with(ray.near, ray.t_min, t_max, |axis, near, far| single_ray_distances(ray, axis, near, far))
    }

    /// The slab test's combination of distances, four boxes at a time:
    /// `distances(axis, near, far)` gives the distances along `axis` to
    /// four boxes' near and far planes (the far ones enlarged), where
    /// `near_planes[axis]` indexes the near planes in [`WideBoxes::planes`].
    /// Returns each box's entry distance within `[t_min, t_max]`, or +∞,
    /// and the mask of the boxes entered.
    #[inline(always)]
    pub(crate) fn enter_with(
        &self,
        near_planes: [usize; 3],
        t_min: f32,
        t_max: f32,
        distances: impl Fn(usize, Vec4, Vec4) -> (Vec4, Vec4),
    ) -> (u32, [f32; W]) {
        let plane = |k: usize, first: usize| Vec4::from_slice(&self.planes[k][first..first + 4]);
        enter_planes(plane, near_planes, t_min, t_max, distances)
    }
}

/// [`WideBoxes::enter_with`] on `W` boxes whose planes `plane(k, first)`
/// gives: row `k` of [`WideBoxes::planes`], lanes `first..first + 4`.
#[inline(always)]
pub(crate) fn enter_planes<const W: usize>(
    plane: impl Fn(usize, usize) -> Vec4,
    near_planes: [usize; 3],
    t_min: f32,
    t_max: f32,
    distances: impl Fn(usize, Vec4, Vec4) -> (Vec4, Vec4),
) -> (u32, [f32; W]) {
    const { assert!(W.is_multiple_of(4), "wide nodes have a multiple of four lanes") };
    let mut entries = [f32::INFINITY; W];
    let mut mask = 0;
    for chunk in 0..W / 4 {
        let first = chunk * 4;
        let mut enter = Vec4::splat(t_min);
        let mut exit = Vec4::splat(t_max);
        for (axis, flip) in FAR_OF_NEAR.into_iter().enumerate() {
            let near = plane(near_planes[axis], first);
            let far = plane(near_planes[axis] ^ flip, first);
            let (t_near, t_far) = distances(axis, near, far);
            // A NaN compares false and leaves the bound as it was.
            enter = Vec4::select(t_near.cmpgt(enter), t_near, enter);
            exit = Vec4::select(t_far.cmplt(exit), t_far, exit);
        }
        let entered = enter.cmple(exit) & enter.cmplt(Vec4::INFINITY);
        Vec4::select(entered, enter, Vec4::INFINITY).write_to_slice(&mut entries[first..first + 4]);
        mask |= entered.bitmask() << first;
    }
    (mask, entries)
}

/// The distances of [`WideBoxes::enter`] to four boxes' planes along
/// `axis`: near, and far enlarged.
#[inline(always)]
pub(crate) fn single_ray_distances(ray: &PlaneRay, axis: usize, near: Vec4, far: Vec4) -> (Vec4, Vec4) {
    let (origin, inv) = (Vec4::splat(ray.origin[axis]), Vec4::splat(ray.inv_direction[axis]));
    let (ahead, behind) = (Vec4::splat(ray.inv_exit[axis]), Vec4::splat(ray.inv_exit_behind[axis]));
    ((near - origin) * inv, later_exit(far - origin, ahead, behind, Vec4::max))
}

/// `near ^ FAR_OF_NEAR[axis]` turns the index of an axis's min plane into
/// its max plane's and back (`axis ^ (axis + 3)`).
pub(crate) const FAR_OF_NEAR: [usize; 3] = [3, 1 ^ 4, 2 ^ 5];

/// A ray prepared for [`WideBoxes::enter`]: per axis, which of the box's
/// planes it meets first (the maximum where the direction's sign bit is
/// set, so that -0 counts as negative, as in the scalar test).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PlaneRay {
    pub(crate) origin: [f32; 3],
    pub(crate) inv_direction: [f32; 3],
    /// The inverses for exit distances ahead of and behind the origin
    /// ([`crate::slab::exit_inverses`]).
    pub(crate) inv_exit: [f32; 3],
    pub(crate) inv_exit_behind: [f32; 3],
    /// Whether the range starts behind the origin: only then do the two
    /// exit inverses differ, and an exit needs both products.
    pub(crate) starts_behind: bool,
    pub(crate) near: [usize; 3],
    pub(crate) t_min: f32,
}

impl PlaneRay {
    #[inline(always)]
    pub(crate) fn new(ray: &BoxRay) -> Self {
        let negative = [ray.negative.test(0), ray.negative.test(1), ray.negative.test(2)];
        Self {
            origin: ray.origin.to_array(),
            inv_direction: ray.inv_direction.to_array(),
            inv_exit: ray.inv_exit.to_array(),
            inv_exit_behind: ray.inv_exit_behind.to_array(),
            starts_behind: ray.starts_behind,
            near: [0, 1, 2].map(|axis| if negative[axis] { axis + 3 } else { axis }),
            t_min: ray.t_min,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slab::{RobustSlabs, SlabTest};
    use rtgi_math::{Ray, Rng, Vec3, Vec3A};

    #[test]
    fn lanes_enter_exactly_where_the_scalar_test_does() {
        let mut rng = Rng::new(9, 2);
        let coordinate = |rng: &mut Rng| match rng.next_u32() % 8 {
            0 => 0.0,
            1 => 1.0,
            2 => -1.0,
            _ => rng.next_f32() * 8.0 - 4.0,
        };
        for _ in 0..20_000 {
            let mut boxes = WideBoxes::<8>::EMPTY;
            let mut scalar = Vec::new();
            for lane in 0..7 {
                let a = [0; 3].map(|_| coordinate(&mut rng));
                let b = [0; 3].map(|_| coordinate(&mut rng));
                let (min, max) = (Vec3::from(a).min(Vec3::from(b)), Vec3::from(a).max(Vec3::from(b)));
                boxes.set(lane, min.to_array(), max.to_array());
                scalar.push((min, max));
            }
            let origin = Vec3::from([0; 3].map(|_| coordinate(&mut rng)));
            let mut direction = Vec3::from([0; 3].map(|_| coordinate(&mut rng)));
            if direction == Vec3::ZERO {
                direction = Vec3::new(-0.0, 0.0, 1.0);
            }
            let ray = Ray::new(origin, direction);
            let box_ray = BoxRay::new(&ray);
            let t_max = if rng.next_u32().is_multiple_of(2) { f32::INFINITY } else { rng.next_f32() * 4.0 };
            let (mask, lanes) = boxes.enter(&PlaneRay::new(&box_ray), t_max);
            for (lane, (min, max)) in scalar.iter().enumerate() {
                let expected = RobustSlabs::enter(&box_ray, Vec3A::from(*min), Vec3A::from(*max), t_max);
                assert_eq!(lanes[lane].to_bits(), expected.to_bits(), "{ray:?} {min} {max} {t_max}");
            }
            assert_eq!(lanes[7], f32::INFINITY, "the empty lane is never entered");
            for (lane, distance) in lanes.iter().enumerate() {
                assert_eq!(mask >> lane & 1 == 1, *distance < f32::INFINITY);
            }
        }
    }
}
