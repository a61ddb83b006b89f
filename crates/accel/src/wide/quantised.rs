//! Wide nodes with quantised child boxes (as in Ylitie, Karras and Laine,
//! "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
//! BVHs", 2017): each plane of a child box is one byte, a step on a grid
//! laid over the node's own box. An eight-wide node takes 128 bytes (two
//! cache lines) instead of 256, so that incoherent rays, which miss the
//! caches on most nodes they visit, wait for half as many lines.
//!
//! The grid of axis `a` has its origin at the node's minimum and a step of
//! a power of two, so that the plane of step `q` decodes to
//! `origin[a] + q · scale[a]`, one exact product and one rounded sum, the
//! same bits wherever it is computed. The build picks each child's steps
//! by decoding them: the greatest step whose plane is at or below the
//! child's minimum, the least at or above its maximum. Every decoded
//! box therefore holds its child's built box, rounding included, and the
//! robust slab test on it culls nothing the built box would keep
//! ([`super::node::NodeLayout`]).
//!
//! Measured (the `peers` example, 2 threads, AVX-512, against `bvh8` in
//! the same run), it does not pay on the machines we have: incoherent
//! rays 0.92× on the bunny and 0.87× on the conference room, camera rays
//! 0.82× and 0.83×. Traversal of incoherent rays waits on each node's
//! first cache line, not on the number of lines, and the decode and the
//! looser boxes (5.8 → 6.6 nodes a ray on the conference room) cost more
//! than the second line saves. The node memory halves, but the triangle
//! blocks hold most of a tree's memory (21.2 → 18.8 MiB there).

use rtgi_math::Vec4;

use super::node::{ChildRef, NodeLayout, WideNode};
use crate::simd::Isa;
use crate::simd::boxes::{PlaneRay, enter_planes, single_ray_distances};
use crate::simd::packet::IntervalRay;

/// Steps on the grid of a node's axis: planes are quantised to `0..=255`.
const STEPS: u32 = u8::MAX as u32;

/// A wide node whose child boxes are quantised to one byte a plane.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct QuantisedNode<const W: usize> {
    /// The node's own minimum: the grid's origin on each axis.
    origin: [f32; 3],
    /// The grid's step on each axis, a power of two (or zero on an axis
    /// where every child is flat at the origin).
    scale: [f32; 3],
    /// `planes[k][lane]`: the step of the child's minimum (k = 0, 1, 2) or
    /// maximum (k = 3, 4, 5) along axis `k % 3`.
    planes: [[u8; W]; 6],
    /// Bit `i` set where lane `i` holds a child.
    occupied: u32,
    children: [ChildRef; W],
}

impl<const W: usize> QuantisedNode<W> {
    /// The plane of step `step` on the grid of `axis`: the one expression
    /// the build checks and traversal decodes with.
    #[inline(always)]
    fn plane(origin: f32, scale: f32, step: u8) -> f32 {
        origin + step as f32 * scale
    }

    /// Lanes `first..first + 4` of row `k` of the decoded planes (as in
    /// [`crate::simd::boxes::WideBoxes::planes`]): the same product and
    /// sum as [`QuantisedNode::plane`], four lanes at a time.
    #[inline(always)]
    fn four_planes(&self, k: usize, first: usize) -> Vec4 {
        let steps = &self.planes[k][first..first + 4];
        let steps = Vec4::new(steps[0] as f32, steps[1] as f32, steps[2] as f32, steps[3] as f32);
        Vec4::splat(self.origin[k % 3]) + steps * Vec4::splat(self.scale[k % 3])
    }

    /// Where one ray enters each child's decoded box within `[t_min,
    /// t_max]`, or +∞, and the mask of the children entered: the robust
    /// slab test of [`crate::simd::boxes::WideBoxes::enter`] on the
    /// decoded planes. Empty lanes decode to some box, which this may
    /// enter: [`NodeLayout::enter`] masks them out.
    #[inline(always)]
    pub(crate) fn enter_portable(&self, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        enter_planes(
            |k, first| self.four_planes(k, first),
            ray.near,
            ray.t_min,
            t_max,
            |axis, near, far| single_ray_distances(ray, axis, near, far),
        )
    }

    /// The grid's origin on each axis.
    #[inline(always)]
    pub(crate) fn origin(&self) -> [f32; 3] {
        self.origin
    }

    /// The grid's step on each axis.
    #[inline(always)]
    pub(crate) fn scale(&self) -> [f32; 3] {
        self.scale
    }

    /// The steps of row `k` of the planes, lane by lane.
    #[inline(always)]
    pub(crate) fn steps(&self, k: usize) -> &[u8; W] {
        &self.planes[k]
    }

    /// The quantised node over the first `lanes` of `boxes`, its
    /// children named by their lanes: for tests of the kernels.
    #[cfg(test)]
    pub(crate) fn of_boxes(boxes: &crate::simd::boxes::WideBoxes<W>, lanes: usize) -> Self {
        let mut node = WideNode { boxes: *boxes, children: [ChildRef::NONE; W] };
        for lane in 0..lanes {
            node.children[lane] = ChildRef::node(lane);
        }
        Self::quantise(&node)
    }

    /// Quantises one built node.
    fn quantise(node: &WideNode<W>) -> Self {
        let mut quantised = QuantisedNode {
            origin: [0.0; 3],
            scale: [0.0; 3],
            planes: [[u8::MAX; W]; 6],
            occupied: 0,
            children: node.children,
        };
        let lanes = || (0..W).filter(|&lane| node.children[lane] != ChildRef::NONE);
        for lane in lanes() {
            quantised.occupied |= 1 << lane;
        }
        if quantised.occupied == 0 {
            return quantised;
        }
        for axis in 0..3 {
            let min = lanes().map(|lane| node.boxes.planes[axis][lane]).fold(f32::INFINITY, f32::min);
            let max = lanes().map(|lane| node.boxes.planes[axis + 3][lane]).fold(f32::NEG_INFINITY, f32::max);
            let scale = grid_step(min, max);
            quantised.origin[axis] = min;
            quantised.scale[axis] = scale;
            for lane in lanes() {
                let (low, high) = (node.boxes.planes[axis][lane], node.boxes.planes[axis + 3][lane]);
                let (below, above) = child_steps(min, scale, low, high);
                quantised.planes[axis][lane] = below as u8;
                quantised.planes[axis + 3][lane] = above as u8;
            }
        }
        quantised
    }
}

/// The steps of a child's planes `low` and `high` on the grid from
/// `origin` by `scale`: the last whose plane is at or below `low` and the
/// first at or above `high`, guessed in double precision and settled by
/// decoding. Step 0 is at or below every child's minimum (it is the
/// node's); the last step is at or above every maximum ([`grid_step`]).
fn child_steps(origin: f32, scale: f32, low: f32, high: f32) -> (u32, u32) {
    let decode = |step: u32| QuantisedNode::<1>::plane(origin, scale, step as u8);
    let guess = |value: f32| {
        if scale > 0.0 { ((value as f64 - origin as f64) / scale as f64).clamp(0.0, STEPS as f64) as u32 } else { 0 }
    };
    let mut below = guess(low);
    while below > 0 && decode(below) > low {
        below -= 1;
    }
    while below < STEPS && decode(below + 1) <= low {
        below += 1;
    }
    let mut above = guess(high).max(below);
    while above < STEPS && decode(above) < high {
        above += 1;
    }
    while above > below && decode(above - 1) >= high {
        above -= 1;
    }
    debug_assert!(decode(below) <= low && decode(above) >= high, "{origin} {scale} {low} {high}");
    (below, above)
}

/// The least power of two `s` (down to the least subnormal) for which
/// `min + 255 · s`, rounded, reaches `max`; 0 when `max` is `min`. The
/// largest step, 2^127, always reaches: its last plane overflows to +∞.
fn grid_step(min: f32, max: f32) -> f32 {
    debug_assert!(min.is_finite() && max.is_finite() && min <= max, "finite built boxes: {min} {max}");
    if max <= min {
        return 0.0;
    }
    let reaches = |exponent: i32| {
        let scale = power_of_two(exponent);
        QuantisedNode::<1>::plane(min, scale, u8::MAX) >= max
    };
    // A first guess from the extent, then the least exponent that reaches.
    let extent = (max as f64 - min as f64) / STEPS as f64;
    let mut exponent = (extent.log2().ceil() as i32).clamp(-149, 127);
    while exponent < 127 && !reaches(exponent) {
        exponent += 1;
    }
    while exponent > -149 && reaches(exponent - 1) {
        exponent -= 1;
    }
    power_of_two(exponent)
}

/// 2^exponent for exponents -149 (the least subnormal) to 127.
fn power_of_two(exponent: i32) -> f32 {
    debug_assert!((-149..=127).contains(&exponent));
    (2.0f64).powi(exponent) as f32
}

impl<const W: usize> NodeLayout<W> for QuantisedNode<W> {
    const NAME_SUFFIX: &'static str = "q";

    fn from_built(nodes: Vec<WideNode<W>>) -> Vec<Self> {
        use rayon::prelude::*;
        nodes.par_iter().map(Self::quantise).collect()
    }

    #[inline(always)]
    fn children(&self) -> &[ChildRef; W] {
        &self.children
    }

    #[inline(always)]
    fn enter<I: Isa>(&self, isa: I, ray: &PlaneRay, t_max: f32) -> (u32, [f32; W]) {
        let (entered, enter) = isa.enter_quantised(self, ray, t_max);
        (entered & self.occupied, enter)
    }

    #[inline(always)]
    fn enter_interval<I: Isa>(&self, _isa: I, ray: &IntervalRay, t_max: f32) -> (u32, [f32; W]) {
        let (entered, enter) = ray.enter_planes(|k, first| self.four_planes(k, first), t_max);
        (entered & self.occupied, enter)
    }

    #[inline(always)]
    fn child_box(&self, lane: usize) -> ([f32; 3], [f32; 3]) {
        let plane = |k: usize| Self::plane(self.origin[k % 3], self.scale[k % 3], self.planes[k][lane]);
        ([plane(0), plane(1), plane(2)], [plane(3), plane(4), plane(5)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtgi_math::Rng;

    /// Child boxes at offsets up to 2^100 and sizes down to a few ulps and
    /// up to the node: each decoded box holds its child's built box, and
    /// is no more than two steps wider on each side.
    #[test]
    fn decoded_boxes_hold_the_built_ones_and_stay_tight() {
        let mut rng = Rng::new(5, 8);
        let mut checked = 0;
        for round in 0..4000 {
            let offset = match round % 4 {
                0 => 0.0,
                1 => 2f32.powi((rng.next_u32() % 100) as i32),
                2 => -(2f32.powi((rng.next_u32() % 24) as i32)),
                _ => f32::MAX / 4.0,
            };
            let size = 2f32.powi((rng.next_u32() % 60) as i32 - 40);
            let mut node = WideNode::<8>::EMPTY;
            let children = 1 + rng.next_u32() as usize % 8;
            for lane in 0..children {
                let corner = |rng: &mut Rng| offset + (rng.next_f32() - 0.5) * size * if lane == 0 { 0.0 } else { 1.0 };
                let (a, b) = ([0; 3].map(|_| corner(&mut rng)), [0; 3].map(|_| corner(&mut rng)));
                let (min, max) = ([0, 1, 2].map(|i| a[i].min(b[i])), [0, 1, 2].map(|i| a[i].max(b[i])));
                node.boxes.set(lane, min, max);
                node.children[lane] = ChildRef::node(lane);
            }
            let quantised = QuantisedNode::quantise(&node);
            assert_eq!(quantised.occupied, (1 << children) - 1);
            for lane in 0..children {
                let (built_min, built_max) = node.boxes.lane(lane);
                let (min, max) = quantised.child_box(lane);
                for axis in 0..3 {
                    assert!(min[axis] <= built_min[axis] && max[axis] >= built_max[axis], "{node:?} lane {lane}");
                    let scale = quantised.scale[axis];
                    if scale > 0.0 && built_max[axis] - built_min[axis] < f32::MAX / 2.0 {
                        assert!(built_min[axis] - min[axis] <= 2.0 * scale + f32::EPSILON * built_min[axis].abs());
                        assert!(max[axis] - built_max[axis] <= 2.0 * scale + f32::EPSILON * built_max[axis].abs());
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 20_000, "{checked}");
    }

    /// The extremes of finite boxes: a node over the whole range of f32,
    /// and a node flat on an axis, still decode to boxes that hold them.
    #[test]
    fn the_whole_range_and_flat_nodes_quantise() {
        let mut node = WideNode::<8>::EMPTY;
        node.boxes.set(0, [-f32::MAX, 0.0, 1.0], [f32::MAX, 0.0, 1.0]);
        node.boxes.set(1, [-1.0, 0.0, 1.0], [1.0, 0.0, 1.0]);
        node.children[0] = ChildRef::node(1);
        node.children[1] = ChildRef::node(2);
        let quantised = QuantisedNode::quantise(&node);
        assert_eq!(quantised.scale[1], 0.0);
        for lane in 0..2 {
            let (built_min, built_max) = node.boxes.lane(lane);
            let (min, max) = quantised.child_box(lane);
            for axis in 0..3 {
                assert!(min[axis] <= built_min[axis] && max[axis] >= built_max[axis], "lane {lane} axis {axis}");
            }
        }
    }

    #[test]
    fn an_eight_wide_node_takes_two_cache_lines() {
        assert_eq!(std::mem::size_of::<QuantisedNode<8>>(), 128);
        assert_eq!(std::mem::size_of::<WideNode<8>>(), 256);
    }
}
