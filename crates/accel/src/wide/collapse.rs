//! Collapsing a binary BVH into a `W`-wide one, as Embree, tinybvh and
//! obvhs do: each wide node takes the two children of a binary node and
//! keeps opening the child with the largest surface area until it has `W`
//! children or only leaves are left. Binary leaves become wide leaves whose
//! triangles are copied, in order, into blocks of four. The top levels'
//! subtrees are collapsed in parallel and appended in depth-first order.
//!
//! A leaf's blocks are placed before any node is made: the wide tree keeps
//! the binary leaves' left-to-right order, so each leaf's first block is the
//! count of blocks before it, and all blocks are filled at once, in
//! parallel, straight from the source's corners. Collapsing the top levels
//! in parallel used to grow a block array per subtree and copy it into the
//! whole; the blocks are most of a wide tree's memory.

use rayon::prelude::*;
use rtgi_math::Vec3A;

use super::node::{ChildRef, WideNode};
use crate::TriangleSource;
use crate::boxa::BoxA;
use crate::bvh::{BinaryTree, BvhNode};
use crate::simd::triangles::TriangleBlock;

/// The wide tree: nodes (the root first), triangle blocks in leaf order,
/// and what was measured on the way.
pub(crate) struct WideTree<const W: usize> {
    pub(crate) nodes: Vec<WideNode<W>>,
    pub(crate) blocks: Vec<TriangleBlock>,
    pub(crate) leaves: usize,
    /// Edges on the longest path from the root to a leaf.
    pub(crate) depth: usize,
    /// SAH cost in units of one test of a block of four triangles, each
    /// wide node costing `traversal_cost`, relative to the root's area.
    pub(crate) sah_cost: f32,
}

/// Wide nodes shallower than this collapse their children in parallel.
const PARALLEL_DEPTH: usize = 2;

impl<const W: usize> WideTree<W> {
    fn empty(nodes: usize) -> Self {
        Self { nodes: Vec::with_capacity(nodes), blocks: Vec::new(), leaves: 0, depth: 0, sah_cost: 0.0 }
    }

    /// Appends the nodes of `subtree` (its root at its index 0), moving its
    /// node references past this tree's nodes; returns its root's reference.
    fn append(&mut self, subtree: WideTree<W>) -> ChildRef {
        let node_offset = self.nodes.len();
        self.nodes.extend(subtree.nodes.into_iter().map(|mut node| {
            for child in &mut node.children {
                *child = child.relocated(node_offset);
            }
            node
        }));
        self.leaves += subtree.leaves;
        self.depth = self.depth.max(subtree.depth);
        ChildRef::node(node_offset)
    }
}

/// Collapses `binary`, built over `triangles`, into a `W`-wide tree.
pub(crate) fn collapse<const W: usize>(
    binary: &BinaryTree,
    triangles: &(impl TriangleSource + ?Sized),
    traversal_cost: f32,
) -> WideTree<W> {
    const { assert!(W >= 2 && W <= 32) };
    let nodes = binary.tree.nodes.as_slice();
    // Each wide node replaces at least one binary node.
    let mut tree = WideTree::empty(nodes.len().div_ceil(2));
    let Some(root) = nodes.first() else {
        return tree;
    };
    let BlockPlacement { first_blocks, spans } = place_blocks(&binary.tree.leaf_ranges);
    tree.blocks = fill_blocks(&spans, &binary.triangle_ids, triangles);
    let collapser = Collapser { binary: nodes, first_blocks, root_area: corners(root).half_area(), traversal_cost };
    let mut cost = 0.0f64;
    if root.is_leaf() {
        // A wide root over the one leaf, so that traversal always starts at a node.
        let mut node = WideNode::EMPTY;
        node.children[0] = collapser.leaf(root, &mut tree, &mut cost);
        node.boxes.set(0, root.min().to_array(), root.max().to_array());
        tree.nodes.push(node);
        cost += collapser.relative_area(root) * traversal_cost as f64;
        tree.depth = 1;
    } else {
        collapser.node(root, 0, &mut tree, &mut cost);
    }
    tree.sah_cost = cost as f32;
    tree
}

/// Where each binary leaf's blocks go.
struct BlockPlacement {
    /// Each leaf's first position in the leaf order and the index of its
    /// first block, in increasing order.
    first_blocks: Vec<(u32, u32)>,
    /// Each block's range of the leaf order: its first position and its
    /// number of triangles.
    spans: Vec<(u32, u32)>,
}

/// Places the blocks of the leaves given by their ranges of the leaf order,
/// left to right (as [`crate::bvh::BinaryTree`] lists them).
fn place_blocks(leaves: &[(u32, u32)]) -> BlockPlacement {
    debug_assert!(leaves.is_sorted());
    let lanes = TriangleBlock::LANES as u32;
    let mut first_blocks = Vec::with_capacity(leaves.len());
    let mut spans = Vec::with_capacity(leaves.iter().map(|&(_, count)| count.div_ceil(lanes) as usize).sum());
    for &(first, count) in leaves {
        first_blocks.push((first, spans.len() as u32));
        spans.extend((0..count).step_by(lanes as usize).map(|offset| (first + offset, (count - offset).min(lanes))));
    }
    BlockPlacement { first_blocks, spans }
}

/// The triangle blocks over the given spans of the leaf order, read from
/// the source (`ids` maps positions to its indices).
fn fill_blocks(spans: &[(u32, u32)], ids: &[u32], triangles: &(impl TriangleSource + ?Sized)) -> Vec<TriangleBlock> {
    spans
        .par_iter()
        .map(|&(first, count)| {
            let ids = &ids[first as usize..(first + count) as usize];
            let mut corners = [[Vec3A::ZERO; 3]; TriangleBlock::LANES];
            for (lane, &id) in ids.iter().enumerate() {
                corners[lane] = triangles.corners(id as usize).map(Vec3A::from);
            }
            TriangleBlock::new(&corners[..ids.len()], ids)
        })
        .collect()
}

fn corners(node: &BvhNode) -> BoxA {
    BoxA { min: node.min().into(), max: node.max().into() }
}

struct Collapser<'a> {
    binary: &'a [BvhNode],
    /// Each binary leaf's first position in the leaf order, and its first block, sorted.
    first_blocks: Vec<(u32, u32)>,
    root_area: f32,
    traversal_cost: f32,
}

impl Collapser<'_> {
    fn relative_area(&self, node: &BvhNode) -> f64 {
        if self.root_area > 0.0 { (corners(node).half_area() / self.root_area) as f64 } else { 1.0 }
    }

    fn children(&self, node: &BvhNode) -> [&BvhNode; 2] {
        let first = node.first() as usize;
        [&self.binary[first], &self.binary[first + 1]]
    }

    /// Emits the wide node for the binary interior node `node` and,
    /// depth first, its subtrees; returns its reference.
    fn node<const W: usize>(&self, node: &BvhNode, depth: usize, tree: &mut WideTree<W>, cost: &mut f64) -> ChildRef {
        debug_assert!(!node.is_leaf());
        let index = tree.nodes.len();
        tree.nodes.push(WideNode::EMPTY);
        tree.depth = tree.depth.max(depth + 1);
        *cost += self.relative_area(node) * self.traversal_cost as f64;
        // Children with the area that ranks them for opening (-1 for leaves).
        let openable = |child: &BvhNode| if child.is_leaf() { -1.0 } else { corners(child).half_area() };
        let [left, right] = self.children(node);
        let mut children = [(left, openable(left)); W];
        children[1] = (right, openable(right));
        let mut len = 2;
        while len < W {
            let mut largest = 0;
            for i in 1..len {
                if children[i].1 > children[largest].1 {
                    largest = i;
                }
            }
            if children[largest].1 < 0.0 {
                break;
            }
            let [left, right] = self.children(children[largest].0);
            children.copy_within(largest + 1..len, largest + 2);
            children[largest] = (left, openable(left));
            children[largest + 1] = (right, openable(right));
            len += 1;
        }
        let mut wide = WideNode::EMPTY;
        let children = &children[..len];
        if depth < PARALLEL_DEPTH {
            // Near the root, the children's subtrees are collapsed in
            // parallel into trees of their own, then appended in order.
            let subtrees: Vec<Option<(WideTree<W>, f64)>> = children
                .par_iter()
                .map(|&(child, _)| {
                    (!child.is_leaf()).then(|| {
                        let (mut subtree, mut subtree_cost) = (WideTree::empty(0), 0.0);
                        self.node(child, depth + 1, &mut subtree, &mut subtree_cost);
                        (subtree, subtree_cost)
                    })
                })
                .collect();
            for (lane, (&(child, _), subtree)) in children.iter().zip(subtrees).enumerate() {
                wide.boxes.set(lane, child.min().to_array(), child.max().to_array());
                wide.children[lane] = match subtree {
                    None => self.leaf(child, tree, cost),
                    Some((subtree, subtree_cost)) => {
                        *cost += subtree_cost;
                        tree.append(subtree)
                    }
                };
            }
        } else {
            for (lane, &(child, _)) in children.iter().enumerate() {
                wide.boxes.set(lane, child.min().to_array(), child.max().to_array());
                wide.children[lane] = if child.is_leaf() {
                    self.leaf(child, tree, cost)
                } else {
                    self.node(child, depth + 1, tree, cost)
                };
            }
        }
        tree.nodes[index] = wide;
        ChildRef::node(index)
    }

    /// The reference to the blocks of the binary leaf `leaf`, placed by [`place_blocks`].
    fn leaf<const W: usize>(&self, leaf: &BvhNode, tree: &mut WideTree<W>, cost: &mut f64) -> ChildRef {
        let at = self.first_blocks.partition_point(|&(first, _)| first < leaf.first());
        let (first, first_block) = self.first_blocks[at];
        debug_assert_eq!(first, leaf.first());
        tree.leaves += 1;
        let blocks = leaf.count().div_ceil(TriangleBlock::LANES as u32);
        *cost += self.relative_area(leaf) * blocks as f64;
        ChildRef::leaf(first_block as usize, blocks as usize)
    }
}
