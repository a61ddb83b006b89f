//! Top-down construction, shared by every split method.
//!
//! The builder sees only one box (and centroid) per primitive: it never
//! looks at triangles or user primitives. It works on an array of
//! [`BuildRef`]s (a box, a centroid and the index of its primitive) that
//! split functions reorder in place, so every pass over
//! a node's primitives reads memory sequentially. A node over `n` primitives
//! owns `2n - 1` slots of a scratch array (enough for any subtree over them),
//! so the two subtrees of a node get disjoint halves of its slots and are
//! built in parallel without locks. A final pass lays the used slots out
//! compactly with siblings side by side, and measures the tree. A subtree
//! too small to split between threads is built on one thread with its
//! nodes packed depth-first at the front of its slots, so that the layout
//! pass reads them in order instead of one cache miss a node.

use rtgi_math::{Vec3, Vec3A};

use rayon::prelude::*;

use super::split::{BuildRef, CentredPrimRef, Context, LeafTests, PrimRef, RangeBounds, Split, SplitMethod};
use super::{BvhNode, median, sah, spatial};
use crate::BuildParams;
use crate::boxa::BoxA;

/// Below this depth the chosen method splits; deeper, the object median
/// does, which halves the count at every level. Together these bound the
/// depth by 64 + 32, within the traversal's fixed stack of
/// `traverse::STACK_SIZE` entries.
pub(crate) const HEURISTIC_DEPTH_LIMIT: usize = 64;

/// Subtrees over at least this many primitives are built in parallel;
/// smaller ones on one thread, their nodes side by side.
const PARALLEL_THRESHOLD: usize = 2048;

/// What [`build`] hands back: the flattened nodes and the primitive order.
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

/// Builds a tree over primitives given by their boxes, each centred in its
/// box (triangles). With spatial splits a primitive may be in several
/// leaves ([`spatial`]).
pub(crate) fn build(boxes: &[BoxA], method: SplitMethod, params: &BuildParams, leaf_tests: LeafTests) -> Tree {
    let ctx = Context::of(method, params, leaf_tests);
    if method == SplitMethod::SpatialSah {
        return spatial::build(boxes, &ctx);
    }
    let prims = boxes.par_iter().enumerate().map(|(i, b)| PrimRef::new(*b, i as u32)).collect();
    build_over(prims, &ctx)
}

/// Builds a tree over primitives given by their boxes and centroids.
pub(crate) fn build_with_centroids(primitives: &[(BoxA, Vec3A)], method: SplitMethod, params: &BuildParams) -> Tree {
    let prims = primitives
        .par_iter()
        .enumerate()
        .map(|(i, (bounds, centroid))| CentredPrimRef::new(*bounds, *centroid, i as u32))
        .collect();
    build_over(prims, &Context::of(method, params, LeafTests::OneByOne))
}

fn build_over<R: BuildRef>(mut prims: Vec<R>, ctx: &Context) -> Tree {
    let n = prims.len();
    if n == 0 {
        return Tree::empty();
    }
    let mut slots = vec![Slot::default(); 2 * n - 1];
    let root = RangeBounds::of(&prims);
    build_node(ctx, &mut prims, 0, &mut slots, 0, 0, root);
    let order = prims.iter().map(BuildRef::index).collect();
    layout(&slots, order, ctx)
}

/// Builds the subtree over `prims` (which start at position `first` of the
/// final order) into `slots`, whose first element is at `slot_base`.
/// Subtrees large enough to build in parallel split `slots` between their
/// children; smaller ones are built by [`build_dense`] at the front of their
/// share.
fn build_node<R: BuildRef>(
    ctx: &Context,
    prims: &mut [R],
    first: u32,
    slots: &mut [Slot],
    slot_base: u32,
    depth: usize,
    range: RangeBounds,
) {
    let n = prims.len();
    if n < PARALLEL_THRESHOLD {
        build_dense(ctx, prims, first, slots, slot_base, &mut 0, depth, range);
        return;
    }
    let split = choose_split(ctx, prims, depth, &range);
    let (this, rest) = slots.split_first_mut().expect("a subtree over n primitives has 2n - 1 slots");
    let Some(Split { left_count, left: left_range, right: right_range }) = split else {
        *this = Slot::new(range.bounds, first, n as u32);
        return;
    };
    let (left_slots, right_slots) = rest.split_at_mut(2 * left_count - 1);
    let right_slot = slot_base + 2 * left_count as u32;
    *this = Slot::new(range.bounds, right_slot, 0);
    let (left_prims, right_prims) = prims.split_at_mut(left_count);
    let right_first = first + left_count as u32;
    rayon::join(
        || build_node(ctx, left_prims, first, left_slots, slot_base + 1, depth + 1, left_range),
        || build_node(ctx, right_prims, right_first, right_slots, right_slot, depth + 1, right_range),
    );
}

/// Builds the subtree over `prims` on this thread into the slots from
/// `*used` on (of `slots`, whose first element is at `slot_base`), in
/// depth-first order with no gaps, and moves `*used` past them. Left
/// sparse, the used slots of a large tree lie about one in five in an
/// array too large for the caches, and the layout pass that reads them
/// back waited on a cache miss for almost every node.
#[allow(clippy::too_many_arguments)]
fn build_dense<R: BuildRef>(
    ctx: &Context,
    prims: &mut [R],
    first: u32,
    slots: &mut [Slot],
    slot_base: u32,
    used: &mut usize,
    depth: usize,
    range: RangeBounds,
) {
    let n = prims.len();
    let this = *used;
    *used += 1;
    let Some(Split { left_count, left: left_range, right: right_range }) = choose_split(ctx, prims, depth, &range)
    else {
        slots[this] = Slot::new(range.bounds, first, n as u32);
        return;
    };
    let (left_prims, right_prims) = prims.split_at_mut(left_count);
    build_dense(ctx, left_prims, first, slots, slot_base, used, depth + 1, left_range);
    let right_slot = slot_base + *used as u32;
    slots[this] = Slot::new(range.bounds, right_slot, 0);
    build_dense(ctx, right_prims, first + left_count as u32, slots, slot_base, used, depth + 1, right_range);
}

/// The split of a node over `prims` at `depth`, or `None` for a leaf.
fn choose_split<R: BuildRef>(ctx: &Context, prims: &mut [R], depth: usize, range: &RangeBounds) -> Option<Split> {
    let n = prims.len();
    let split = if n <= 1 {
        None
    } else if depth >= HEURISTIC_DEPTH_LIMIT {
        Some(median::object_median(prims, range))
    } else {
        match ctx.method {
            SplitMethod::ObjectMedian => (n > ctx.max_leaf_size).then(|| median::object_median(prims, range)),
            SplitMethod::SpatialMedian => (n > ctx.max_leaf_size).then(|| median::spatial_median(prims, range)),
            // User primitives are not split: their references stay whole.
            SplitMethod::BinnedSah | SplitMethod::SpatialSah => sah::binned(ctx, prims, range),
            SplitMethod::SweepSah => sah::sweep(ctx, prims, range),
        }
    };
    // A split method that puts every primitive on one side (found by
    // fuzzing: extreme finite coordinates, whose boxes overflow to
    // infinity) would index past the slots; the object median always
    // splits in two.
    let split = match split {
        Some(s) if s.left_count == 0 || s.left_count >= n => Some(median::object_median(prims, range)),
        split => split,
    };
    debug_assert!(split.as_ref().is_none_or(|s| s.left_count > 0 && s.left_count < n));
    split
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
