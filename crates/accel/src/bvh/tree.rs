//! The flat tree that every builder hands back, the slots it is built in,
//! and their layout into it.
//!
//! `build.rs` (the top-down recursion) and `spatial.rs` (spatial splits)
//! both write slots and lay them out here; `build.rs` hands spatial splits
//! to `spatial.rs`, so these types live in neither, and the dependencies
//! point one way.

use rtgi_math::Vec3;

use super::BvhNode;
use super::split::Context;
use crate::boxa::BoxA;

/// What a build hands back: the flattened nodes and the primitive order.
pub(crate) struct Tree {
    pub(crate) nodes: Vec<BvhNode>,
    /// Primitive indices (into the builder's input) in leaf order.
    pub(crate) order: Vec<u32>,
    pub(crate) depth: usize,
    pub(crate) leaf_size_histogram: Vec<usize>,
    /// Each leaf's first position in `order` and its count, left to right
    /// (so in increasing order of position).
    pub(crate) leaf_ranges: Vec<(u32, u32)>,
    pub(crate) sah_cost: f32,
}

impl Tree {
    /// The tree over no primitives.
    pub(crate) fn empty() -> Tree {
        Tree {
            nodes: Vec::new(),
            order: Vec::new(),
            depth: 0,
            leaf_size_histogram: vec![],
            leaf_ranges: vec![],
            sah_cost: 0.0,
        }
    }

    /// The statistics of a build that made this tree: `variant` names it,
    /// `inputs` primitives were given and `excluded` left out, it began at
    /// `start`, and its leaves keep `leaf_bytes` beside the nodes.
    pub(crate) fn stats(
        &self,
        variant: String,
        inputs: usize,
        excluded: usize,
        start: std::time::Instant,
        leaf_bytes: usize,
    ) -> crate::BuildStats {
        crate::BuildStats {
            variant,
            triangles: inputs,
            excluded_triangles: excluded,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
            nodes: self.nodes.len(),
            leaves: self.leaf_ranges.len(),
            depth: self.depth,
            leaf_size_histogram: self.leaf_size_histogram.clone(),
            sah_cost: self.sah_cost,
            memory_bytes: std::mem::size_of_val(self.nodes.as_slice()) + leaf_bytes,
        }
    }
}

/// A node before layout, 32 bytes: leaves have `count > 0` and their
/// primitives start at `link`; an interior node's left child is in the next
/// slot and its right child in slot `link`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Slot {
    min: Vec3,
    pub(crate) link: u32,
    max: Vec3,
    pub(crate) count: u32,
}

impl Slot {
    pub(crate) fn new(bounds: BoxA, link: u32, count: u32) -> Self {
        Slot { min: bounds.min.into(), link, max: bounds.max.into(), count }
    }

    fn bounds(&self) -> BoxA {
        BoxA { min: self.min.into(), max: self.max.into() }
    }
}

/// Lays the used slots out depth-first with siblings adjacent, and measures
/// the tree: depth, leaves, leaf sizes and SAH cost (the build's leaf and
/// traversal costs, relative to the root's area).
pub(crate) fn layout(slots: &[Slot], order: Vec<u32>, ctx: &Context) -> Tree {
    let root_area = slots[0].bounds().half_area();
    // At most every slot is used; reserving that much only claims address
    // space, and saves the copies of a growing vector.
    let mut nodes = Vec::with_capacity(slots.len());
    nodes.push(BvhNode::default());
    let mut depth = 0;
    let mut histogram = Vec::new();
    let mut leaf_ranges = Vec::new();
    let mut cost = 0.0f64;
    let mut stack = Vec::with_capacity(2 * super::traverse::STACK_SIZE);
    stack.push((0u32, 0u32, 0usize));
    while let Some((slot_index, node_index, node_depth)) = stack.pop() {
        let slot = &slots[slot_index as usize];
        depth = depth.max(node_depth);
        let relative_area = if root_area > 0.0 { (slot.bounds().half_area() / root_area) as f64 } else { 1.0 };
        let (min, max) = (slot.min, slot.max);
        let node = if slot.count > 0 {
            if histogram.len() <= slot.count as usize {
                histogram.resize(slot.count as usize + 1, 0);
            }
            histogram[slot.count as usize] += 1;
            leaf_ranges.push((slot.link, slot.count));
            cost += relative_area * ctx.leaf_cost(slot.count as usize) as f64;
            BvhNode::new(min, max, slot.link, slot.count)
        } else {
            let children = nodes.len() as u32;
            nodes.push(BvhNode::default());
            nodes.push(BvhNode::default());
            cost += relative_area * ctx.traversal_cost as f64;
            stack.push((slot.link, children + 1, node_depth + 1));
            stack.push((slot_index + 1, children, node_depth + 1));
            BvhNode::new(min, max, children, 0)
        };
        nodes[node_index as usize] = node;
    }
    Tree { nodes, order, depth, leaf_size_histogram: histogram, leaf_ranges, sah_cost: cost as f32 }
}
