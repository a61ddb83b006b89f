//! Top-down construction, shared by every split method.
//!
//! The builder sees only one box (and centroid) per primitive: it never
//! looks at triangles or user primitives. It works on an array of
//! [`BuildRef`]s (a box, a centroid and the index of its primitive) that
//! split functions reorder in place, so every pass over
//! a node's primitives reads memory sequentially. A node over `n` primitives
//! owns `2n - 1` slots of a scratch array (enough for any subtree over them),
//! so the two subtrees of a node get disjoint halves of its slots and are
//! built in parallel without locks. A final pass (`tree.rs`, shared with
//! spatial splits) lays the used slots out compactly with siblings side by
//! side, and measures the tree. A subtree
//! too small to split between threads is built on one thread with its
//! nodes packed depth-first at the front of its slots, so that the layout
//! pass reads them in order instead of one cache miss a node.

use rtgi_math::Vec3A;

use rayon::prelude::*;

use super::split::{
    BuildRef, CentredPrimRef, Context, HEURISTIC_DEPTH_LIMIT, LeafTests, PrimRef, RangeBounds, Split, SplitMethod,
};
use super::tree::{Slot, Tree, layout};
use super::{median, sah, spatial};
use crate::BuildParams;
use crate::boxa::BoxA;

/// Subtrees over at least this many primitives are built in parallel;
/// smaller ones on one thread, their nodes side by side.
const PARALLEL_THRESHOLD: usize = 2048;

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
