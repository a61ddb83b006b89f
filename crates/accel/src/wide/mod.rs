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

mod collapse;
mod node;
pub(crate) mod packet;
mod traverse;

use std::time::Instant;

use rtgi_math::{Aabb, Vec3};

use crate::contract::{HitFilter, QueryKind, Structure};
use crate::simd::triangles::TriangleBlock;
use crate::{BuildParams, BuildStats, Bvh, Counter, Hit, Intersector, SplitMethod};
use node::{ChildRef, WideNode};

/// A BVH whose nodes have up to `W` children (4 and 8 are offered as
/// [`Bvh4`] and [`Bvh8`]).
#[derive(Debug)]
pub struct WideBvh<const W: usize> {
    nodes: Vec<WideNode<W>>,
    blocks: Vec<TriangleBlock>,
    stats: BuildStats,
    intersector: Intersector,
}

/// A BVH with four children a node.
pub type Bvh4 = WideBvh<4>;
/// A BVH with eight children a node.
pub type Bvh8 = WideBvh<8>;

impl<const W: usize> WideBvh<W> {
    /// Most triangles in a leaf: larger `max_leaf_size`s are lowered to this.
    pub const MAX_LEAF_SIZE: usize = ChildRef::MAX_LEAF_BLOCKS * TriangleBlock::LANES;

    /// Builds a binary hierarchy with `method` and collapses it to `W`
    /// children a node. Triangles that can never be hit are left out, as
    /// by every structure.
    pub fn new(triangles: &[[Vec3; 3]], method: SplitMethod, params: &BuildParams) -> Self {
        let start = Instant::now();
        let params = BuildParams { max_leaf_size: params.max_leaf_size.min(Self::MAX_LEAF_SIZE), ..params.clone() };
        let binary = Bvh::new(triangles, method, &params);
        let tree = collapse::collapse::<W>(&binary, params.traversal_cost);
        let build_ms = start.elapsed().as_secs_f64() * 1e3;
        let binary_stats = Structure::stats(&binary);
        let stats = BuildStats {
            variant: match method {
                SplitMethod::BinnedSah => format!("bvh{W}"),
                _ => format!("{}-bvh{W}", method.name()),
            },
            triangles: triangles.len(),
            excluded_triangles: binary_stats.excluded_triangles,
            build_ms,
            nodes: tree.nodes.len(),
            leaves: tree.leaves,
            depth: tree.depth,
            leaf_size_histogram: binary_stats.leaf_size_histogram.clone(),
            sah_cost: tree.sah_cost,
            memory_bytes: std::mem::size_of_val(tree.nodes.as_slice()) + std::mem::size_of_val(tree.blocks.as_slice()),
        };
        Self { nodes: tree.nodes, blocks: tree.blocks, stats, intersector: params.intersector }
    }
}

impl<const W: usize> WideBvh<W> {
    /// The boxes of all nodes and leaves at the given depths (the root, the
    /// union of its children's boxes, is depth 0); a leaf shallower than a
    /// requested depth is not repeated below itself.
    pub fn boxes_at_depths(&self, depths: &[usize]) -> Vec<(usize, Aabb)> {
        let mut boxes = Vec::new();
        let Some(root) = self.nodes.first() else {
            return boxes;
        };
        let children = |node: &WideNode<W>| -> Vec<(ChildRef, Aabb)> {
            (0..W)
                .filter(|&lane| node.children[lane] != ChildRef::NONE)
                .map(|lane| {
                    let p = &node.boxes.planes;
                    let min = Vec3::new(p[0][lane], p[1][lane], p[2][lane]);
                    let max = Vec3::new(p[3][lane], p[4][lane], p[5][lane]);
                    (node.children[lane], Aabb::new(min, max))
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

impl<const W: usize> Structure for WideBvh<W> {
    fn query<Q: QueryKind, C: Counter, F: HitFilter>(
        &self,
        ray: &rtgi_math::Ray,
        counter: &mut C,
        filter: &F,
    ) -> Option<Hit> {
        self.query_dispatched::<Q, C, F>(ray, counter, filter)
    }

    fn query_batch<Q: QueryKind>(&self, rays: &[rtgi_math::Ray], answer: &mut dyn FnMut(usize, Option<Hit>)) {
        self.query_batch_dispatched::<Q>(rays, answer)
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }
}
