//! What the split methods share: the primitives they reorder
//! ([`BuildRef`]: [`PrimRef`] for triangles, [`CentredPrimRef`] for user
//! primitives with centroids of their own), the bounds of a range of them ([`RangeBounds`]), the
//! split they return ([`Split`]), the read-only inputs of a build
//! ([`Context`]), and the depth below which the chosen method splits
//! ([`HEURISTIC_DEPTH_LIMIT`]). `build.rs`, `spatial.rs`, `median.rs` and
//! `sah.rs` all import this file, and it imports none of them.

use rayon::prelude::*;
use rtgi_math::{Vec3A, Vec4};

use crate::boxa::BoxA;

/// Below this depth the chosen method splits; deeper, the object median
/// does, which halves the count at every level. Together these bound the
/// depth by 64 + 32, within the traversal's fixed stack of
/// `traverse::STACK_SIZE` entries.
pub(crate) const HEURISTIC_DEPTH_LIMIT: usize = 64;

/// How a node's primitives are divided between its two children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitMethod {
    /// Equal counts: sort by centroid along the longest axis, split at the median.
    ObjectMedian,
    /// Split the longest axis of the node's box at its middle.
    SpatialMedian,
    /// Surface area heuristic evaluated at the borders of `BuildParams::sah_bins` bins per axis.
    BinnedSah,
    /// Surface area heuristic evaluated between every pair of neighbouring centroids on all three axes.
    SweepSah,
    /// Binned SAH with spatial splits (SBVH): where children would overlap, a
    /// node may be cut by a plane and the triangles across it referenced on
    /// both sides, their boxes cut at the plane (at most 1.5 references a
    /// triangle). A [`crate::PrimitiveBvh`] builds with the binned SAH instead.
    SpatialSah,
}

impl SplitMethod {
    /// The variant's name on command lines and in reports (`object-median`, `spatial-median`, `sah`, `sah-sweep`, `sbvh`).
    pub fn name(self) -> &'static str {
        match self {
            SplitMethod::ObjectMedian => "object-median",
            SplitMethod::SpatialMedian => "spatial-median",
            SplitMethod::BinnedSah => "sah",
            SplitMethod::SweepSah => "sah-sweep",
            SplitMethod::SpatialSah => "sbvh",
        }
    }
}

/// A primitive as the builder sees it: its box, its centroid (doubled)
/// and its index in the builder's input. Split methods are generic over
/// it, so that triangles keep their compact 32-byte [`PrimRef`] and user
/// primitives bring their own centroids ([`CentredPrimRef`]).
pub(crate) trait BuildRef: Copy + Send + Sync + 'static {
    fn index(&self) -> u32;

    fn bounds(&self) -> BoxA;

    /// Twice the centroid: the builder compares centroids only with each
    /// other, so the halving is left out.
    fn centroid2(&self) -> Vec3A;
}

/// A primitive whose centroid is the centre of its box (triangles): the
/// box, with the primitive's index in the fourth lane of `min` (stored
/// with bit 30 set, so that the lane is a normal float and never slows the
/// box arithmetic that also runs on it).
#[derive(Clone, Copy, Debug)]
pub(crate) struct PrimRef {
    min_index: Vec4,
    max: Vec4,
}

const INDEX_BIAS: u32 = 1 << 30;

impl PrimRef {
    pub(crate) fn new(bounds: BoxA, index: u32) -> Self {
        Self { min_index: bounds.min.extend(f32::from_bits(index | INDEX_BIAS)), max: bounds.max.extend(0.0) }
    }
}

impl BuildRef for PrimRef {
    #[inline(always)]
    fn index(&self) -> u32 {
        self.min_index.w.to_bits() & !INDEX_BIAS
    }

    #[inline(always)]
    fn bounds(&self) -> BoxA {
        BoxA { min: Vec3A::from_vec4(self.min_index), max: Vec3A::from_vec4(self.max) }
    }

    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        Vec3A::from_vec4(self.min_index + self.max)
    }
}

/// A primitive with a centroid of its own ([`crate::Primitive::centroid`]),
/// which need not be the centre of its box: 48 bytes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CentredPrimRef {
    bounds: PrimRef,
    centroid2: Vec3A,
}

impl CentredPrimRef {
    pub(crate) fn new(bounds: BoxA, centroid: Vec3A, index: u32) -> Self {
        Self { bounds: PrimRef::new(bounds, index), centroid2: centroid * 2.0 }
    }
}

impl BuildRef for CentredPrimRef {
    #[inline(always)]
    fn index(&self) -> u32 {
        self.bounds.index()
    }

    #[inline(always)]
    fn bounds(&self) -> BoxA {
        self.bounds.bounds()
    }

    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        self.centroid2
    }
}

/// Read-only inputs of every recursion step.
pub(crate) struct Context {
    pub(crate) method: SplitMethod,
    pub(crate) max_leaf_size: usize,
    pub(crate) sah_bins: usize,
    pub(crate) sah_axes: crate::SahAxes,
    pub(crate) traversal_cost: f32,
    /// Primitives a leaf tests in one step (see [`LeafTests`]).
    leaf_tests: LeafTests,
}

impl Context {
    /// The inputs of a build with `method` and `params` for a structure
    /// whose leaves are tested as `leaf_tests` says, clamped to what the
    /// builders handle.
    pub(crate) fn of(method: SplitMethod, params: &crate::BuildParams, leaf_tests: LeafTests) -> Context {
        Context {
            method,
            max_leaf_size: params.max_leaf_size.max(1),
            sah_bins: params.sah_bins.clamp(2, 256),
            sah_axes: params.sah_axes,
            traversal_cost: params.traversal_cost.max(0.0),
            leaf_tests,
        }
    }

    /// What the SAH charges a leaf of `count` primitives: the steps its
    /// test takes.
    #[inline(always)]
    pub(crate) fn leaf_cost(&self, count: usize) -> f32 {
        self.leaf_tests.steps(count) as f32
    }
}

/// How a structure tests the primitives of a leaf: one at a time (the
/// binary BVHs), or in blocks tested in one step (the wide BVHs test a ray
/// against four triangles at once). The SAH prices a leaf by its steps, as
/// Embree's builders do: priced by triangles, a wide build split a leaf of
/// five into four and one and left a quarter of the conference room's
/// blocks holding a single triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LeafTests {
    OneByOne,
    InBlocksOf(usize),
}

impl LeafTests {
    /// Steps a leaf of `count` primitives takes.
    #[inline(always)]
    pub(crate) fn steps(self, count: usize) -> usize {
        match self {
            LeafTests::OneByOne => count,
            LeafTests::InBlocksOf(block) => count.div_ceil(block),
        }
    }
}

/// Bounds of a range of primitives and of their (doubled) centroids.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RangeBounds {
    pub(crate) bounds: BoxA,
    pub(crate) centroids: BoxA,
}

impl RangeBounds {
    pub(crate) const EMPTY: RangeBounds = RangeBounds { bounds: BoxA::EMPTY, centroids: BoxA::EMPTY };

    #[inline(always)]
    pub(crate) fn add(&mut self, prim: &impl BuildRef) {
        self.bounds = self.bounds.union(prim.bounds());
        self.centroids = self.centroids.grow(prim.centroid2());
    }

    fn union(self, other: RangeBounds) -> RangeBounds {
        RangeBounds { bounds: self.bounds.union(other.bounds), centroids: self.centroids.union(other.centroids) }
    }

    /// The bounds of a range of primitives; in parallel for long ranges.
    pub(crate) fn of<R: BuildRef>(prims: &[R]) -> Self {
        const CHUNK: usize = 16 * 1024;
        let of_chunk = |chunk: &[R]| {
            let mut r = RangeBounds::EMPTY;
            for prim in chunk {
                r.add(prim);
            }
            r
        };
        if prims.len() <= CHUNK {
            return of_chunk(prims);
        }
        prims.par_chunks(CHUNK).map(of_chunk).reduce(|| RangeBounds::EMPTY, RangeBounds::union)
    }
}

/// A split of a node's range: the first `left_count` primitives (after the
/// split function reordered them) go to the left child.
pub(crate) struct Split {
    pub(crate) left_count: usize,
    pub(crate) left: RangeBounds,
    pub(crate) right: RangeBounds,
}

impl Split {
    /// A split whose children's bounds are measured afresh.
    pub(crate) fn measured<R: BuildRef>(prims: &[R], left_count: usize) -> Split {
        let (left, right) = prims.split_at(left_count);
        Split { left_count, left: RangeBounds::of(left), right: RangeBounds::of(right) }
    }
}
