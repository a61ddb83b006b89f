//! Spatial splits (SBVH: Stich, Friedrich and Dietrich, "Spatial Splits in
//! Bounding Volume Hierarchies", HPG 2009). Where the best object split
//! leaves two children whose boxes overlap, a node may instead be cut by an
//! axis-aligned plane: primitives on one side go to that side, and a
//! primitive that straddles the plane goes to both, each time with its box
//! cut at the plane. Interiors with long walls and floors, whose boxes
//! overlap every node's, get tighter nodes at the price of references to
//! some primitives in several leaves.
//!
//! # Why boxes are cut, not triangles
//!
//! Stich et al. clip the triangle at the plane and keep the bounds of each
//! piece, which are smaller along the other two axes too. Here the two
//! pieces of a reference are its box on either side of the plane,
//! `box ∩ {x ≤ s}` and `box ∩ {x ≥ s}`, with the same `f32` plane `s` in
//! both. This is what keeps the exactness contract. A hit on a triangle is
//! reported no earlier than where the ray enters the triangle's own box
//! (the hit rule), and the ray enters one of the two pieces at exactly
//! that distance, computed with the same planes and the same arithmetic:
//! if the entry is through the plane's side of the box, the piece beyond
//! the plane is entered where the whole box is, and otherwise the piece
//! that holds the entry face is. By induction some leaf's piece, and every
//! node above it, is entered no later than the hit, so traversal reaches a
//! reference to the triangle, whatever rounding does to the hit's
//! distance. Pieces of clipped triangles lie inside the box pieces but need
//! not hold the point where the ray enters the box, so rounding could then
//! lose a hit that lies next to the plane.
//!
//! One step of this needs the piece on the entry side not to be left
//! before it is entered: its exit at the plane must not fall below the
//! entry, which lies before the plane. The robust test computes every
//! exit late enough, negative ones too where the ray's range starts behind
//! its origin (`slab::later_exit`), so this holds for those rays as well.
//!
//! The builder, like the others, sees only boxes.

use rayon::prelude::*;

use super::median::object_median;
use super::sah;
use super::split::{BuildRef, Context, HEURISTIC_DEPTH_LIMIT, PrimRef, RangeBounds, Split};
use super::tree::{Slot, Tree, layout};
use crate::boxa::BoxA;

/// Spatial splits are tried where the object split's children overlap by
/// more than this fraction of the root's surface area (Stich et al.'s α):
/// small enough to try them wherever overlap matters, large enough to
/// leave the many small nodes deep in the tree alone.
const OVERLAP_FRACTION: f32 = 1e-5;

/// Planes tried per axis.
const SPATIAL_BINS: usize = 32;

/// References beyond one a primitive the whole tree may add, as a fraction
/// of the primitives: at most 1.5 references a primitive.
const DUPLICATE_BUDGET: f32 = 0.5;

/// Subtrees over at least this many references are built in parallel.
const PARALLEL_THRESHOLD: usize = 4096;

/// Builds a tree over primitives given by their boxes, with spatial splits
/// where they pay. A primitive may be in several leaves (`Tree::order`
/// names it once for each).
pub(crate) fn build(boxes: &[BoxA], ctx: &Context) -> Tree {
    let refs: Vec<PrimRef> = boxes.par_iter().enumerate().map(|(i, b)| PrimRef::new(*b, i as u32)).collect();
    if refs.is_empty() {
        return Tree::empty();
    }
    let range = RangeBounds::of(&refs);
    let root_area = range.bounds.half_area();
    let budget = (refs.len() as f32 * DUPLICATE_BUDGET) as usize;
    let subtree = build_node(ctx, root_area, refs, range, 0, budget);
    layout(&subtree.slots, subtree.order, ctx)
}

/// A subtree before layout: its slots (links relative to its own first
/// slot, and leaves' to its own first reference) and its references in
/// leaf order.
struct Subtree {
    slots: Vec<Slot>,
    order: Vec<u32>,
}

impl Subtree {
    /// Appends `child`, whose links become relative to this subtree.
    fn append(&mut self, child: Subtree) {
        let (slot_base, order_base) = (self.slots.len() as u32, self.order.len() as u32);
        self.slots.extend(child.slots.into_iter().map(|mut slot| {
            slot.link += if slot.count > 0 { order_base } else { slot_base };
            slot
        }));
        self.order.extend(child.order);
    }
}

fn build_node(
    ctx: &Context,
    root_area: f32,
    mut refs: Vec<PrimRef>,
    range: RangeBounds,
    depth: usize,
    budget: usize,
) -> Subtree {
    let n = refs.len();
    let object = if n <= 1 {
        None
    } else if depth >= HEURISTIC_DEPTH_LIMIT {
        Some(object_median(&mut refs, &range))
    } else {
        sah::binned(ctx, &mut refs, &range)
    };
    // As in `build::build_node`: a split that leaves one side empty
    // becomes the object median, which always splits in two.
    let object = match object {
        Some(s) if s.left_count == 0 || s.left_count >= n => Some(object_median(&mut refs, &range)),
        split => split,
    };
    let Some(object) = object else {
        let slot = Slot::new(range.bounds, 0, n as u32);
        return Subtree { slots: vec![slot], order: refs.iter().map(BuildRef::index).collect() };
    };
    let spatial = (budget > 0 && depth < HEURISTIC_DEPTH_LIMIT && overlaps(&object, root_area))
        .then(|| spatial_split(&refs, &range, &object, budget))
        .flatten();
    let (left, right, left_range, right_range, budget) = match spatial {
        Some(split) => {
            let used = split.left.len() + split.right.len() - n;
            let (left_range, right_range) = (RangeBounds::of(&split.left), RangeBounds::of(&split.right));
            (split.left, split.right, left_range, right_range, budget - used)
        }
        None => {
            let right = refs.split_off(object.left_count);
            (refs, right, object.left, object.right, budget)
        }
    };
    // What is left of the budget is shared in proportion to the references.
    let left_budget = (budget as f64 * left.len() as f64 / (left.len() + right.len()) as f64) as usize;
    let right_budget = budget - left_budget;
    let build_left = || build_node(ctx, root_area, left, left_range, depth + 1, left_budget);
    let build_right = || build_node(ctx, root_area, right, right_range, depth + 1, right_budget);
    let (left, right) =
        if n >= PARALLEL_THRESHOLD { rayon::join(build_left, build_right) } else { (build_left(), build_right()) };
    // This slot, then the left subtree (in the next slot), then the right.
    let right_slot = 1 + left.slots.len() as u32;
    let mut tree = Subtree { slots: vec![Slot::new(range.bounds, right_slot, 0)], order: Vec::new() };
    tree.append(left);
    tree.append(right);
    tree
}

/// Whether the object split's children overlap enough for a spatial split
/// to be worth trying.
fn overlaps(split: &Split, root_area: f32) -> bool {
    let (a, b) = (split.left.bounds, split.right.bounds);
    let overlap = BoxA { min: a.min.max(b.min), max: a.max.min(b.max) };
    let inside = overlap.max.cmpge(overlap.min).all();
    inside && root_area > 0.0 && root_area.is_finite() && overlap.half_area() > OVERLAP_FRACTION * root_area
}

/// The references of a spatial split, each side's boxes cut at the plane.
struct SpatialSplit {
    left: Vec<PrimRef>,
    right: Vec<PrimRef>,
}

/// One plane's bin: the union of the references' pieces in it, and how
/// many references begin and end in it.
#[derive(Clone, Copy)]
struct SpatialBin {
    bounds: BoxA,
    entries: u32,
    exits: u32,
}

/// The best spatial split of `refs` if it costs less than the object split
/// (Stich et al.'s binning, then their reference unsplitting), using at
/// most `budget` new references; `None` if no plane pays or none makes
/// both sides smaller.
fn spatial_split(refs: &[PrimRef], range: &RangeBounds, object: &Split, budget: usize) -> Option<SpatialSplit> {
    let n = refs.len();
    let bounds = range.bounds;
    let object_cost = object.left.bounds.half_area() * object.left_count as f32
        + object.right.bounds.half_area() * (n - object.left_count) as f32;
    // best = (sum of A·N, axis, plane)
    let mut best = (object_cost, 0, f32::NAN);
    for axis in 0..3 {
        let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
        let extent = hi - lo;
        if !(extent > 0.0 && extent.is_finite()) {
            continue;
        }
        // Plane k (1 to SPATIAL_BINS - 1) bounds bin k - 1 above and bin k below.
        let plane = |k: usize| lo + extent * (k as f32 / SPATIAL_BINS as f32);
        let bin_of = |x: f32| (((x - lo) / extent * SPATIAL_BINS as f32) as usize).min(SPATIAL_BINS - 1);
        let mut bins = [SpatialBin { bounds: BoxA::EMPTY, entries: 0, exits: 0 }; SPATIAL_BINS];
        for r in refs {
            let b = r.bounds();
            let (first, last) = (bin_of(b.min[axis]), bin_of(b.max[axis]));
            bins[first].entries += 1;
            bins[last].exits += 1;
            for (k, bin) in bins.iter_mut().enumerate().take(last + 1).skip(first) {
                let mut piece = b;
                // Clamped: `bin_of` and `plane` round apart by an ulp or so.
                if k > first {
                    piece.min[axis] = plane(k).min(b.max[axis]);
                }
                if k < last {
                    piece.max[axis] = plane(k + 1).max(b.min[axis]);
                }
                bin.bounds = bin.bounds.union(piece);
            }
        }
        let mut right_cost = [0.0f32; SPATIAL_BINS];
        let (mut acc, mut count) = (BoxA::EMPTY, 0u32);
        for k in (1..SPATIAL_BINS).rev() {
            acc = acc.union(bins[k].bounds);
            count += bins[k].exits;
            right_cost[k] = if count as usize >= n { f32::INFINITY } else { acc.half_area() * count as f32 };
        }
        let (mut acc, mut count) = (BoxA::EMPTY, 0u32);
        for k in 0..SPATIAL_BINS - 1 {
            acc = acc.union(bins[k].bounds);
            count += bins[k].entries;
            if count == 0 || count as usize >= n {
                continue;
            }
            let cost = acc.half_area() * count as f32 + right_cost[k + 1];
            let s = plane(k + 1);
            if cost < best.0 && s > lo && s < hi {
                best = (cost, axis, s);
            }
        }
    }
    let (_, axis, s) = best;
    if s.is_nan() {
        return None;
    }
    partition(refs, axis, s, budget)
}

/// Divides `refs` at the plane `s` on `axis`. A reference that straddles
/// it goes to both sides, cut, unless putting it whole on one side costs
/// less (Stich et al.'s unsplitting) or the budget is spent.
fn partition(refs: &[PrimRef], axis: usize, s: f32, budget: usize) -> Option<SpatialSplit> {
    let (mut left, mut right, mut straddling) = (Vec::new(), Vec::new(), Vec::new());
    let (mut left_bounds, mut right_bounds) = (BoxA::EMPTY, BoxA::EMPTY);
    for &r in refs {
        let b = r.bounds();
        if b.max[axis] <= s {
            left_bounds = left_bounds.union(b);
            left.push(r);
        } else if b.min[axis] >= s {
            right_bounds = right_bounds.union(b);
            right.push(r);
        } else {
            straddling.push(r);
        }
    }
    let mut spare = budget;
    for r in straddling {
        let b = r.bounds();
        let (mut below, mut above) = (b, b);
        below.max[axis] = s;
        above.min[axis] = s;
        let (left_n, right_n) = (left.len() as f32, right.len() as f32);
        let split_cost = left_bounds.union(below).half_area() * (left_n + 1.0)
            + right_bounds.union(above).half_area() * (right_n + 1.0);
        let all_left = left_bounds.union(b).half_area() * (left_n + 1.0) + right_bounds.half_area() * right_n;
        let all_right = left_bounds.half_area() * left_n + right_bounds.union(b).half_area() * (right_n + 1.0);
        if spare > 0 && split_cost < all_left && split_cost < all_right {
            spare -= 1;
            left_bounds = left_bounds.union(below);
            right_bounds = right_bounds.union(above);
            left.push(PrimRef::new(below, r.index()));
            right.push(PrimRef::new(above, r.index()));
        } else if all_left <= all_right {
            left_bounds = left_bounds.union(b);
            left.push(r);
        } else {
            right_bounds = right_bounds.union(b);
            right.push(r);
        }
    }
    let progress = |side: &Vec<PrimRef>| !side.is_empty() && side.len() < refs.len();
    (progress(&left) && progress(&right)).then_some(SpatialSplit { left, right })
}

#[cfg(test)]
mod tests {
    use rtgi_math::Vec3;

    use crate::{Accel, BuildParams, Bvh, SplitMethod};

    /// A lattice of long planks, half along x and half along z, crossing
    /// each other: no object split separates them, and cuts do.
    #[test]
    fn crossing_planks_get_cut_and_the_tree_costs_less() {
        let mut triangles = Vec::new();
        let quad = |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [[a, b, c], [a, c, d]];
        for i in 0..24 {
            let (at, y) = (i as f32, (i % 3) as f32 * 0.5);
            triangles.extend(quad(
                Vec3::new(0.0, y, at),
                Vec3::new(24.0, y, at),
                Vec3::new(24.0, y, at + 0.2),
                Vec3::new(0.0, y, at + 0.2),
            ));
            triangles.extend(quad(
                Vec3::new(at, y + 0.25, 0.0),
                Vec3::new(at + 0.2, y + 0.25, 0.0),
                Vec3::new(at + 0.2, y + 0.25, 24.0),
                Vec3::new(at, y + 0.25, 24.0),
            ));
        }
        let params = BuildParams::default();
        let plain = Bvh::new(&triangles, SplitMethod::BinnedSah, &params);
        let spatial = Bvh::new(&triangles, SplitMethod::SpatialSah, &params);
        spatial.validate().unwrap();
        let (plain, spatial) = (plain.build_stats(), spatial.build_stats());
        let references: usize = spatial.leaf_size_histogram.iter().enumerate().map(|(k, n)| k * n).sum();
        assert!(references > triangles.len(), "no reference was duplicated");
        assert!(references <= triangles.len() * 3 / 2, "{references} references break the budget");
        // 11.6 against 12.9: the budget, spent by the first cuts, bounds the gain.
        assert!(spatial.sah_cost < 0.95 * plain.sah_cost, "SAH {} against {}", spatial.sah_cost, plain.sah_cost);
    }

    /// The exactness tests run every variant over the adversarial cases;
    /// they test the argument above only where cuts are made: in the
    /// crossing planks, built for it.
    #[test]
    fn the_adversarial_cases_get_cut() {
        let mut cut = Vec::new();
        for case in crate::verify::adversarial_cases(100, 1) {
            let bvh = Bvh::new(&case.triangles, SplitMethod::SpatialSah, &BuildParams::default());
            bvh.validate().unwrap_or_else(|e| panic!("{}: {e}", case.name));
            let references: usize = bvh.build_stats().leaf_size_histogram.iter().enumerate().map(|(k, n)| k * n).sum();
            if references > case.triangles.len() {
                cut.push(case.name);
            }
        }
        assert!(cut.iter().any(|name| name == "crossing-planks"), "cut: {cut:?}");
    }
}
