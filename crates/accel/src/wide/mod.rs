//! Wide bounding volume hierarchies: 4 or 8 children a node.
//!
//! Built by the binary builders ([`crate::Bvh`]) and collapsed
//! ([`collapse`](self::collapse)); a node stores its children's boxes
//! structure-of-arrays ([`node`](self::node)), so that one ray tests all of
//! them with a few SIMD instructions, and leaves store their triangles in
//! blocks of four for the block tests ([`crate::simd`]). Traversal
//! ([`traverse`](self::traverse)) visits children nearest first. The same
//! exactness contract as every structure holds: the box tests and block
//! tests compute, lane by lane, the bits of the scalar tests.

// The node layouts' trait is the crate's own: users pick a layout through
// the aliases below and never implement one, so the bounds of the generic
// impls may name a trait they cannot see.
#![allow(private_bounds)]

mod collapse;
mod node;
pub(crate) mod packet;
mod quantised;
mod traverse;

use std::time::Instant;

use rtgi_math::{Aabb, Vec3};

use crate::bvh::{BinaryTree, LeafTests};
use crate::contract::{HitFilter, QueryKind, Structure};
use crate::simd::triangles::TriangleBlock;
use crate::{BuildParams, BuildStats, Counter, Hit, Intersector, SplitMethod, TriangleSource};
pub use node::WideNode;
use node::{ChildRef, NodeLayout};
pub use quantised::QuantisedNode;

/// A BVH whose nodes have up to `W` children (4 and 8 are offered as
/// [`Bvh4`] and [`Bvh8`]), stored as `N`: [`WideNode`]s as built, or
/// [`QuantisedNode`]s, one byte a plane ([`Bvh8Quantised`]).
#[derive(Debug)]
pub struct WideBvh<const W: usize, N = WideNode<W>> {
    nodes: Vec<N>,
    blocks: Vec<TriangleBlock>,
    stats: BuildStats,
    intersector: Intersector,
}

/// A BVH with four children a node.
pub type Bvh4 = WideBvh<4>;
/// A BVH with eight children a node.
pub type Bvh8 = WideBvh<8>;
/// [`Bvh8`] with its child boxes quantised to one byte a plane: half the
/// node memory, for a few more instructions a node.
pub type Bvh8Quantised = WideBvh<8, QuantisedNode<8>>;

impl<const W: usize, N: NodeLayout<W>> WideBvh<W, N> {
    /// Most triangles in a leaf: larger `max_leaf_size`s are lowered to this.
    pub const MAX_LEAF_SIZE: usize = ChildRef::MAX_LEAF_BLOCKS * TriangleBlock::LANES;

    /// Builds a binary hierarchy over `triangles` (a soup, an
    /// [`crate::IndexedMesh`] or any [`TriangleSource`]) with `method` and
    /// collapses it to `W` children a node. Triangles that can never be hit
    /// are left out, as by every structure.
    pub fn new(triangles: &(impl TriangleSource + ?Sized), method: SplitMethod, params: &BuildParams) -> Self {
        let start = Instant::now();
        let params = BuildParams { max_leaf_size: params.max_leaf_size.min(Self::MAX_LEAF_SIZE), ..params.clone() };
        let binary = BinaryTree::new(triangles, method, &params, LeafTests::InBlocksOf(TriangleBlock::LANES));
        let tree = collapse::collapse::<W>(&binary, triangles, params.traversal_cost);
        let (node_count, memory_bytes) = (
            tree.nodes.len(),
            tree.nodes.len() * std::mem::size_of::<N>() + std::mem::size_of_val(tree.blocks.as_slice()),
        );
        let nodes = N::from_built(tree.nodes);
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        let stats = BuildStats {
            variant: match method {
                SplitMethod::BinnedSah => format!("bvh{W}{}", N::NAME_SUFFIX),
                SplitMethod::SpatialSah => format!("sbvh{W}{}", N::NAME_SUFFIX),
                _ => format!("{}-bvh{W}{}", method.name(), N::NAME_SUFFIX),
            },
            triangles: triangles.len(),
            excluded_triangles: binary.excluded,
            build_ms,
            nodes: node_count,
            leaves: tree.leaves,
            depth: tree.depth,
            leaf_size_histogram: binary.tree.leaf_size_histogram,
            sah_cost: tree.sah_cost,
            memory_bytes,
        };
        Self { nodes, blocks: tree.blocks, stats, intersector: params.intersector }
    }
}

/// Inserts `entry` among the first `count` entries of `sorted`, kept in
/// decreasing order of `enter` (far to near, so that the nearest is last).
#[inline(always)]
fn insert_far_to_near<T: Copy, K: PartialOrd>(sorted: &mut [T], count: usize, entry: T, enter: impl Fn(&T) -> K) {
    let mut at = count;
    while at > 0 && enter(&sorted[at - 1]) < enter(&entry) {
        sorted[at] = sorted[at - 1];
        at -= 1;
    }
    sorted[at] = entry;
}

impl<const W: usize, N: NodeLayout<W>> WideBvh<W, N> {
    /// The boxes of all nodes and leaves at the given depths (the root, the
    /// union of its children's boxes, is depth 0); a leaf shallower than a
    /// requested depth is not repeated below itself.
    pub fn boxes_at_depths(&self, depths: &[usize]) -> Vec<(usize, Aabb)> {
        let mut boxes = Vec::new();
        let Some(root) = self.nodes.first() else {
            return boxes;
        };
        let children = |node: &N| -> Vec<(ChildRef, Aabb)> {
            (0..W)
                .filter(|&lane| node.children()[lane] != ChildRef::NONE)
                .map(|lane| {
                    let (min, max) = node.child_box(lane);
                    (node.children()[lane], Aabb::new(Vec3::from(min), Vec3::from(max)))
                })
                .collect()
        };
        if depths.contains(&0) {
            let union = children(root).iter().fold(Aabb::EMPTY, |acc, (_, b)| acc.union(b));
            boxes.push((0, union));
        }
        let mut stack: Vec<(ChildRef, Aabb, usize)> =
            children(root).into_iter().map(|(child, bounds)| (child, bounds, 1)).collect();
        while let Some((child, bounds, depth)) = stack.pop() {
            if depths.contains(&depth) {
                boxes.push((depth, bounds));
            }
            if !child.is_leaf() {
                stack.extend(children(&self.nodes[child.node_index()]).into_iter().map(|(c, b)| (c, b, depth + 1)));
            }
        }
        boxes.sort_by_key(|(depth, _)| *depth);
        boxes
    }
}

impl<const W: usize, N: NodeLayout<W>> Structure for WideBvh<W, N> {
    fn query<Q: QueryKind, C: Counter, F: HitFilter>(
        &self,
        ray: &rtgi_math::Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        self.query_dispatched::<Q, C, F>(ray, counter, filter)
    }

    fn query_batch<Q: QueryKind, F: HitFilter>(
        &self,
        rays: &[rtgi_math::Ray],
        answer: &mut dyn FnMut(usize, Option<Hit>),
        filter: &F,
    ) {
        self.query_batch_dispatched::<Q, F>(rays, answer, filter)
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::triangles::TriangleBlock;
    use rtgi_math::Rng;

    /// Four triangles in a row, a tenth apart, are one block: the wide
    /// builds price a leaf by its blocks, so splitting the row in two
    /// (which pays when a leaf is priced by its triangles) would only add
    /// a block and a box test. Across many such rows, every block is full.
    #[test]
    fn wide_builds_fill_their_blocks() {
        let row = |y: f32| {
            (0..4).map(move |i| {
                let x = i as f32 * 1.1;
                [Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y, 0.0), Vec3::new(x, y + 1.0, 0.0)]
            })
        };
        let one_row: Vec<[Vec3; 3]> = row(0.0).collect();
        let params = crate::AccelKind::Bvh8.default_params();
        assert_eq!(Bvh8::new(&one_row, SplitMethod::BinnedSah, &params).blocks.len(), 1);
        assert_eq!(Bvh4::new(&one_row, SplitMethod::BinnedSah, &params).blocks.len(), 1);
        let rows: Vec<[Vec3; 3]> = (0..32).flat_map(|r| row(r as f32 * 10.0)).collect();
        let bvh = Bvh8::new(&rows, SplitMethod::BinnedSah, &params);
        assert_eq!(bvh.blocks.len(), 32, "32 rows of four in 32 blocks: {:?}", bvh.stats.leaf_size_histogram);
        check_tree(&bvh, &rows);
    }

    /// Every hittable triangle in exactly one block and inside every box
    /// on its path from the root, and references that stay inside the
    /// arrays: the invariants the parallel collapse must keep when it
    /// appends subtrees, and quantisation when it rounds boxes outward
    /// (a quantised box need not hold its children's, only what lies
    /// below it).
    fn check_tree<const W: usize, N: NodeLayout<W>>(bvh: &WideBvh<W, N>, triangles: &[[Vec3; 3]]) {
        let mut seen = vec![0u32; triangles.len()];
        let mut stack: Vec<(usize, Vec<(Vec3, Vec3)>)> = vec![(0, Vec::new())];
        let mut visited = 0;
        while let Some((index, path)) = stack.pop() {
            visited += 1;
            let node = &bvh.nodes[index];
            for lane in 0..W {
                let child = node.children()[lane];
                if child == ChildRef::NONE {
                    continue;
                }
                let (min, max) = node.child_box(lane);
                let mut path = path.clone();
                path.push((Vec3::from(min), Vec3::from(max)));
                let held =
                    |point: Vec3| path.iter().all(|&(min, max)| point.cmpge(min).all() && point.cmple(max).all());
                if child.is_leaf() {
                    for block in &bvh.blocks[child.blocks()] {
                        for lane in 0..TriangleBlock::LANES {
                            if block.ids[lane] == TriangleBlock::NO_TRIANGLE {
                                continue;
                            }
                            seen[block.ids[lane] as usize] += 1;
                            assert!(
                                block.triangle(lane).iter().all(|&c| held(c.into())),
                                "triangle outside a box on its path"
                            );
                        }
                    }
                } else {
                    stack.push((child.node_index(), path));
                }
            }
        }
        assert_eq!(visited, bvh.nodes.len(), "every node reachable once");
        for (index, triangle) in triangles.iter().enumerate() {
            assert_eq!(seen[index], crate::is_hittable(triangle) as u32, "triangle {index}");
        }
    }

    #[test]
    fn collapsed_trees_hold_every_triangle_once_inside_their_boxes() {
        let mut rng = Rng::new(17, 3);
        let mut point = |scale: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
        let mut triangles: Vec<[Vec3; 3]> = (0..20_000)
            .map(|_| {
                let base = point(100.0);
                [base, base + point(2.0), base + point(2.0)]
            })
            .collect();
        triangles.push([Vec3::ZERO, Vec3::X, 2.0 * Vec3::X]);
        for max_leaf_size in [1, 4, 8, 16] {
            let params = BuildParams { max_leaf_size, ..BuildParams::default() };
            check_tree(&Bvh4::new(&triangles, SplitMethod::BinnedSah, &params), &triangles);
            check_tree(&Bvh8::new(&triangles, SplitMethod::BinnedSah, &params), &triangles);
            check_tree(&Bvh8Quantised::new(&triangles, SplitMethod::BinnedSah, &params), &triangles);
        }
        check_tree(&Bvh8::new(&triangles[..1], SplitMethod::BinnedSah, &BuildParams::default()), &triangles[..1]);
    }
}
