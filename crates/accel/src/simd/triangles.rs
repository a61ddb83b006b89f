//! One ray against four triangles at once.
//!
//! A [`TriangleBlock`] stores four triangles structure-of-arrays, so that
//! each step of a triangle test runs on all four in one SIMD instruction.
//! The tests evaluate the expressions of [`arith`](super::arith), which the
//! scalar tests evaluate too: every lane computes the bits the scalar test
//! computes for its triangle. Lanes the scalar test would decide in double
//! precision (the watertight test's exact zeros) are handed back to it.

use rtgi_math::glam::BVec4A;
use rtgi_math::{Vec3A, Vec4};

use super::arith;
use crate::triangle_hit::LaneHits;

/// Four triangles, structure-of-arrays: `corners[c][axis]` holds the
/// coordinate along `axis` of corner `c` of the four triangles. Lanes
/// without a triangle hold NaN corners, which every test rejects, and the
/// id [`TriangleBlock::NO_TRIANGLE`].
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub(crate) struct TriangleBlock {
    pub(crate) corners: [[Vec4; 3]; 3],
    /// Input index of each lane's triangle.
    pub(crate) ids: [u32; 4],
}

impl TriangleBlock {
    pub(crate) const LANES: usize = 4;
    pub(crate) const NO_TRIANGLE: u32 = u32::MAX;

    /// A block of up to four triangles and their input indices.
    pub(crate) fn new(triangles: &[[Vec3A; 3]], ids: &[u32]) -> Self {
        assert!(triangles.len() <= Self::LANES && triangles.len() == ids.len());
        let mut corners = [[[f32::NAN; 4]; 3]; 3];
        let mut lane_ids = [Self::NO_TRIANGLE; 4];
        for (lane, (triangle, &id)) in triangles.iter().zip(ids).enumerate() {
            for (c, corner) in triangle.iter().enumerate() {
                let corner = corner.to_array();
                for axis in 0..3 {
                    corners[c][axis][lane] = corner[axis];
                }
            }
            lane_ids[lane] = id;
        }
        Self { corners: corners.map(|corner| corner.map(Vec4::from_array)), ids: lane_ids }
    }

    /// The corners of the triangle in `lane`, as arrays.
    #[inline(always)]
    pub(crate) fn corners(&self, lane: usize) -> [[f32; 3]; 3] {
        // Written out: an array map of a closure was left as a call (with
        // its register spills) in the packet traversal's inner loop.
        let corner = |k: usize| {
            let c = &self.corners[k];
            [c[0][lane], c[1][lane], c[2][lane]]
        };
        [corner(0), corner(1), corner(2)]
    }

    /// The corners of the triangle in `lane`.
    #[inline(always)]
    pub(crate) fn triangle(&self, lane: usize) -> [Vec3A; 3] {
        let [a, b, c] = self.corners(lane);
        [Vec3A::from_array(a), Vec3A::from_array(b), Vec3A::from_array(c)]
    }

    /// Lanes that hold a triangle.
    pub(crate) fn len(&self) -> u32 {
        self.ids.iter().filter(|&&id| id != Self::NO_TRIANGLE).count() as u32
    }
}

/// One ray against the four triangles of a block.
pub(crate) type BlockHits = LaneHits<Vec4>;

impl BlockHits {
    /// Every lane that holds a triangle left to the scalar test: for tests
    /// without a block kernel.
    #[inline(always)]
    pub(crate) fn scalar_only(block: &TriangleBlock) -> BlockHits {
        let rescan = block
            .ids
            .iter()
            .enumerate()
            .filter(|(_, id)| **id != TriangleBlock::NO_TRIANGLE)
            .fold(0, |m, (lane, _)| m | 1 << lane);
        BlockHits {
            exact: 0,
            rescan,
            t: Vec4::ZERO,
            beta_scaled: Vec4::ZERO,
            gamma_scaled: Vec4::ZERO,
            scale: Vec4::ONE,
        }
    }
}

#[inline(always)]
fn in_range(t: Vec4, t_min: f32, t_max: f32) -> BVec4A {
    t.cmpge(Vec4::splat(t_min)) & t.cmple(Vec4::splat(t_max)) & t.is_finite_mask()
}

/// [`crate::triangle::Watertight`] on four triangles.
#[inline(always)]
pub(crate) fn watertight_block(
    origin: [f32; 3],
    axes: [usize; 3],
    shear: [f32; 3],
    t_min: f32,
    t_max: f32,
    block: &TriangleBlock,
) -> BlockHits {
    // Written out: nested array maps of closures were left as calls (3.6%
    // of incoherent rays' time in perf).
    let [kx, ky, kz] = axes;
    let (ox, oy, oz) = (Vec4::splat(origin[kx]), Vec4::splat(origin[ky]), Vec4::splat(origin[kz]));
    let relative_to_origin = |corner: &[Vec4; 3]| [corner[kx] - ox, corner[ky] - oy, corner[kz] - oz];
    let [a, b, c] = &block.corners;
    let relative = [relative_to_origin(a), relative_to_origin(b), relative_to_origin(c)];
    let [xs, ys, zs] = arith::watertight_shear(relative, shear);
    let uvw = arith::watertight_edges(xs, ys);
    let zero = Vec4::ZERO;
    // Edges within rounding of the ray are decided exactly, by the scalar test.
    let bound = arith::watertight_edge_bound(xs, ys, relative.map(|r| r[2]), shear);
    let rescan = uvw[0].abs().cmple(bound) | uvw[1].abs().cmple(bound) | uvw[2].abs().cmple(bound);
    let negative = uvw[0].cmplt(zero) | uvw[1].cmplt(zero) | uvw[2].cmplt(zero);
    let positive = uvw[0].cmpgt(zero) | uvw[1].cmpgt(zero) | uvw[2].cmpgt(zero);
    let (det, t_scaled) = arith::watertight_det_and_scaled_t(uvw, zs);
    // So are distances lost to cancellation, for lanes whose edges say hit.
    let rescan = rescan | (!(negative & positive) & t_scaled.abs().cmple(arith::watertight_t_bound(det, zs, bound)));
    let t = t_scaled / det;
    let hit = !(negative & positive) & det.cmpne(zero) & det.is_finite_mask() & in_range(t, t_min, t_max);
    BlockHits {
        exact: (hit & !rescan).bitmask(),
        rescan: rescan.bitmask(),
        t,
        beta_scaled: uvw[1],
        gamma_scaled: uvw[2],
        scale: det,
    }
}

/// [`crate::triangle::MollerTrumbore`] on four triangles.
#[inline(always)]
pub(crate) fn moller_trumbore_block(
    origin: [f32; 3],
    direction: [f32; 3],
    t_min: f32,
    t_max: f32,
    block: &TriangleBlock,
) -> BlockHits {
    let [det, beta, gamma, t] =
        arith::moller_trumbore(origin.map(Vec4::splat), direction.map(Vec4::splat), block.corners);
    let (zero, one) = (Vec4::ZERO, Vec4::ONE);
    let inside = det.cmpne(zero)
        & det.is_finite_mask()
        & beta.cmpge(zero)
        & beta.cmple(one)
        & !gamma.cmplt(zero)
        & !(beta + gamma).cmpgt(one);
    BlockHits {
        exact: (inside & in_range(t, t_min, t_max)).bitmask(),
        rescan: 0,
        t,
        beta_scaled: beta,
        gamma_scaled: gamma,
        scale: one,
    }
}
