//! A binary bounding volume hierarchy over triangles.
//!
//! Built top-down ([`build`](self::build)) with one of four split methods
//! (object median, spatial median, binned SAH, full-sweep SAH), then laid out
//! as a flat array of 32-byte nodes in which the two children of a node are
//! neighbours, and traversed front to back with an explicit stack
//! ([`traverse`](self::traverse)). Triangles are copied into leaf order so
//! that a leaf's triangles are contiguous in memory.

mod build;
mod median;
mod primitives;
mod sah;
mod spatial;
mod split;
mod traverse;
mod tree;
mod validate;

pub use primitives::PrimitiveBvh;
pub(crate) use split::LeafTests;
pub use split::SplitMethod;
pub use traverse::Traversal;

use std::time::Instant;

use rayon::prelude::*;
use rtgi_math::{Aabb, Vec3, Vec3A, Vec4};

use crate::boxa::BoxA;
use crate::contract::{HitFilter, QueryKind, Structure, is_hittable};
use crate::{BuildParams, BuildStats, Counter, Hit, TriangleSource};

/// A node of the flattened tree: its box, and either the index of its first
/// child (the second follows it) or, for a leaf, the range of its triangles
/// in leaf order.
///
/// Stored as two 16-byte vectors (32 bytes a node, two to a cache line) so
/// that traversal loads each corner of the box with one instruction; the
/// fourth lanes carry the index and the triangle count. They are stored with
/// bit 30 set, which keeps the lanes normal floating-point numbers (never
/// subnormal), so the box arithmetic that also runs on them is never slowed
/// by subnormal operands.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct BvhNode {
    min_first: Vec4,
    max_count: Vec4,
}

/// Set in the packed index lanes; see [`BvhNode`].
const LANE_BIAS: u32 = 1 << 30;

impl BvhNode {
    /// The largest index or count a node can hold.
    pub const MAX_INDEX: u32 = LANE_BIAS - 1;

    /// A node with the given box; `count > 0` makes it a leaf over triangles
    /// `first..first + count`, `count == 0` an interior node whose children
    /// are `first` and `first + 1`.
    pub fn new(min: Vec3, max: Vec3, first: u32, count: u32) -> Self {
        assert!(first <= Self::MAX_INDEX && count <= Self::MAX_INDEX, "node index out of range");
        Self {
            min_first: min.extend(f32::from_bits(first | LANE_BIAS)),
            max_count: max.extend(f32::from_bits(count | LANE_BIAS)),
        }
    }

    /// First child (interior nodes) or first triangle in leaf order (leaves).
    #[inline(always)]
    pub fn first(&self) -> u32 {
        self.min_first.w.to_bits() & !LANE_BIAS
    }

    /// Number of triangles; 0 for interior nodes.
    #[inline(always)]
    pub fn count(&self) -> u32 {
        self.max_count.w.to_bits() & !LANE_BIAS
    }

    #[inline(always)]
    /// Whether the node is a leaf (holds triangles rather than children).
    pub fn is_leaf(&self) -> bool {
        self.count() > 0
    }

    /// The smallest corner of the node's box.
    pub fn min(&self) -> Vec3 {
        self.min_first.truncate()
    }

    /// The largest corner of the node's box.
    pub fn max(&self) -> Vec3 {
        self.max_count.truncate()
    }

    /// The node's box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.min(), self.max())
    }

    /// The box corners as SIMD vectors; their fourth lanes hold the packed fields.
    #[inline(always)]
    pub(crate) fn corners(&self) -> (Vec3A, Vec3A) {
        (Vec3A::from_vec4(self.min_first), Vec3A::from_vec4(self.max_count))
    }
}

/// The tree over a source's hittable triangles, before their corners are
/// copied anywhere: [`Bvh`] copies them into leaf order, the wide builds
/// straight into their blocks.
pub(crate) struct BinaryTree {
    pub(crate) tree: tree::Tree,
    /// For each position of the leaf order, the triangle's index in the source.
    pub(crate) triangle_ids: Vec<u32>,
    /// Triangles left out because no ray can hit them ([`is_hittable`]).
    pub(crate) excluded: usize,
}

impl BinaryTree {
    /// The tree over the hittable `triangles`, for a structure whose leaves
    /// are tested as `leaf_tests` says.
    pub(crate) fn new(
        triangles: &(impl TriangleSource + ?Sized),
        method: SplitMethod,
        params: &BuildParams,
        leaf_tests: LeafTests,
    ) -> Self {
        let count = triangles.len();
        let all_hittable = (0..count).into_par_iter().all(|i| is_hittable(&triangles.corners(i)));
        let (boxes, ids): (Vec<BoxA>, Vec<u32>) = if all_hittable {
            (
                (0..count).into_par_iter().map(|i| BoxA::from_triangle(&triangles.corners(i))).collect(),
                (0..count as u32).collect(),
            )
        } else {
            (0..count)
                .into_par_iter()
                .filter_map(|i| {
                    let corners = triangles.corners(i);
                    is_hittable(&corners).then(|| (BoxA::from_triangle(&corners), i as u32))
                })
                .unzip()
        };
        let tree = build::build(&boxes, method, params, leaf_tests);
        let triangle_ids = tree.order.par_iter().map(|&p| ids[p as usize]).collect();
        BinaryTree { tree, triangle_ids, excluded: count - ids.len() }
    }
}

/// A bounding volume hierarchy over triangles.
#[derive(Debug)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    /// Triangle corners in leaf order.
    triangles: Vec<[Vec3A; 3]>,
    /// For each triangle in leaf order, its index in the input.
    triangle_ids: Vec<u32>,
    stats: BuildStats,
    intersector: crate::Intersector,
    traversal: Traversal,
    /// Built with spatial splits: a triangle may be in several leaves,
    /// each holding the part of its box on the leaf's side of the cuts.
    spatial_splits: bool,
}

impl Bvh {
    /// Builds a hierarchy over `triangles` (a soup, an [`crate::IndexedMesh`]
    /// or any [`TriangleSource`]) with the given split method.
    ///
    /// Triangles that can never be hit ([`crate::is_hittable`]) are left
    /// out of the tree and counted in [`BuildStats::excluded_triangles`].
    pub fn new(triangles: &(impl TriangleSource + ?Sized), method: SplitMethod, params: &BuildParams) -> Self {
        let start = Instant::now();
        let count = triangles.len();
        let BinaryTree { tree, triangle_ids, excluded } =
            BinaryTree::new(triangles, method, params, LeafTests::OneByOne);
        let leaf_triangles = triangle_ids.par_iter().map(|&i| triangles.corners(i as usize).map(Vec3A::from)).collect();
        let leaf_bytes = (std::mem::size_of::<[Vec3A; 3]>() + std::mem::size_of::<u32>()) * triangle_ids.len();
        let stats = tree.stats(method.name().to_owned(), count, excluded, start, leaf_bytes);
        Self {
            nodes: tree.nodes,
            triangles: leaf_triangles,
            triangle_ids,
            stats,
            intersector: params.intersector,
            traversal: params.traversal,
            spatial_splits: method == SplitMethod::SpatialSah,
        }
    }

    /// The flattened nodes; the root is node 0 (absent for an empty tree).
    pub fn nodes(&self) -> &[BvhNode] {
        &self.nodes
    }

    /// The input indices of the triangles of a leaf.
    pub fn leaf_triangles(&self, leaf: &BvhNode) -> &[u32] {
        &self.triangle_ids[leaf.first() as usize..(leaf.first() + leaf.count()) as usize]
    }

    /// The boxes of all nodes at the given depths (the root is depth 0); a
    /// leaf shallower than a requested depth is not repeated below itself.
    pub fn boxes_at_depths(&self, depths: &[usize]) -> Vec<(usize, Aabb)> {
        let mut boxes = Vec::new();
        let mut stack = Vec::new();
        if !self.nodes.is_empty() {
            stack.push((0usize, 0usize));
        }
        while let Some((index, depth)) = stack.pop() {
            let node = &self.nodes[index];
            if depths.contains(&depth) {
                boxes.push((depth, node.bounds()));
            }
            if !node.is_leaf() {
                stack.push((node.first() as usize + 1, depth + 1));
                stack.push((node.first() as usize, depth + 1));
            }
        }
        boxes.sort_by_key(|(depth, _)| *depth);
        boxes
    }
}

impl Structure for Bvh {
    fn query<Q: QueryKind, C: Counter, F: HitFilter>(
        &self,
        ray: &rtgi_math::Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        self.traverse::<Q, C, F>(ray, counter, filter)
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Accel, AccelKind};
    use rtgi_math::{Ray, Rng};

    fn random_soup(count: usize, seed: u64) -> Vec<[Vec3; 3]> {
        let mut rng = Rng::new(seed, 0);
        let mut point = |scale: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
        (0..count)
            .map(|_| {
                let base = point(10.0);
                [base, base + point(1.0), base + point(1.0)]
            })
            .collect()
    }

    /// Every BVH configuration of the tests, with its largest leaf size.
    fn every_bvh(triangles: &[[Vec3; 3]]) -> Vec<(String, Bvh, usize)> {
        AccelKind::all_configurations()
            .into_iter()
            .filter(|(_, params)| params.intersector == crate::Intersector::default())
            .filter_map(|(kind, params)| {
                let method = kind.split_method()?;
                Some((format!("{kind} {params:?}"), Bvh::new(triangles, method, &params), params.max_leaf_size))
            })
            .collect()
    }

    #[test]
    fn trees_are_valid_and_agree_with_the_linear_scan() {
        let triangles = random_soup(3000, 1);
        let linear = crate::LinearScan::new(&triangles, crate::Intersector::default());
        let mut rng = Rng::new(2, 0);
        let rays: Vec<Ray> = (0..500)
            .map(|_| {
                let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 14.0 - 2.0;
                let d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
                Ray::new(o, d)
            })
            .collect();
        for (name, bvh, leaf_size) in every_bvh(&triangles) {
            bvh.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(bvh.stats.excluded_triangles, 0);
            let max_leaf = bvh.stats.leaf_size_histogram.len() - 1;
            assert!(max_leaf <= leaf_size, "{name}: leaf of {max_leaf}");
            for ray in &rays {
                assert_eq!(bvh.intersect(ray), linear.intersect(ray), "{name}");
                assert_eq!(bvh.occluded(ray), linear.occluded(ray), "{name}");
            }
        }
    }

    #[test]
    fn long_ranges_partitioned_in_parallel_give_valid_exact_trees() {
        // Ranges of at least 32k primitives are binned and partitioned on
        // all threads; the tree must still be valid and exact.
        let triangles = random_soup(100_000, 5);
        let linear = crate::LinearScan::new(&triangles, crate::Intersector::default());
        let bvh = Bvh::new(&triangles, SplitMethod::BinnedSah, &BuildParams::default());
        bvh.validate().unwrap();
        let mut rng = Rng::new(6, 0);
        for _ in 0..300 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 14.0 - 2.0;
            let d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            let ray = Ray::new(o, d);
            assert_eq!(bvh.intersect(&ray), linear.intersect(&ray));
        }
    }

    #[test]
    fn identical_centroids_build_shallow_trees_with_small_leaves() {
        // 70,000 copies of one triangle: no heuristic can separate them.
        let triangle = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let triangles = vec![triangle; 70_000];
        for (name, bvh, leaf_size) in every_bvh(&triangles) {
            bvh.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(bvh.stats.depth <= 20, "{name}: depth {}", bvh.stats.depth);
            assert!(bvh.stats.leaf_size_histogram.len() <= leaf_size + 1, "{name}");
            let hit = bvh.intersect(&Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z)).unwrap();
            assert_eq!((hit.t, hit.triangle), (1.0, 0), "{name}: the lowest index wins the tie");
        }
    }

    #[test]
    fn spatial_median_survives_one_sided_and_geometric_distributions() {
        // One huge triangle and a cluster of tiny ones at one end: the middle of
        // the node's box has every centroid on one side.
        let mut triangles = vec![[Vec3::ZERO, Vec3::new(1000.0, 0.0, 0.0), Vec3::new(0.0, 1000.0, 0.0)]];
        // Centroids at 2^-k: each middle split peels off one triangle.
        for k in 0..120 {
            let x = 2f32.powi(-k);
            triangles.push([Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1e-3, 0.0), Vec3::new(x, 0.0, 1e-3)]);
        }
        let bvh =
            Bvh::new(&triangles, SplitMethod::SpatialMedian, &BuildParams { max_leaf_size: 1, ..Default::default() });
        bvh.validate().unwrap();
        assert!(bvh.stats.depth < super::traverse::STACK_SIZE, "depth {}", bvh.stats.depth);
        assert_eq!(bvh.stats.leaves, triangles.len());
    }

    #[test]
    fn empty_single_and_unhittable_inputs() {
        let empty = Bvh::new(&[], SplitMethod::BinnedSah, &BuildParams::default());
        empty.validate().unwrap();
        assert!(empty.intersect(&Ray::new(Vec3::ZERO, Vec3::X)).is_none());
        let one = Bvh::new(&[[Vec3::ZERO, Vec3::X, Vec3::Y]], SplitMethod::BinnedSah, &BuildParams::default());
        one.validate().unwrap();
        assert_eq!(one.intersect(&Ray::new(Vec3::new(0.1, 0.1, -1.0), Vec3::Z)).map(|h| h.t), Some(1.0));
        let bad = [
            [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
            [Vec3::ZERO, Vec3::ZERO, Vec3::Y],
            [Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X, Vec3::Y],
            [Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::X, Vec3::Y],
            [Vec3::ZERO, Vec3::X, Vec3::Y],
        ];
        let bvh = Bvh::new(&bad, SplitMethod::BinnedSah, &BuildParams::default());
        bvh.validate().unwrap();
        assert_eq!(bvh.stats.excluded_triangles, 4);
        assert_eq!(bvh.intersect(&Ray::new(Vec3::new(0.1, 0.1, -1.0), Vec3::Z)).map(|h| h.triangle), Some(4));
    }
}
