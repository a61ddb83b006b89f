//! Splits by the surface area heuristic (Goldsmith and Salmon 1987;
//! MacDonald and Booth 1990): the expected cost of a split is
//! `C_trav + (A_L N_L + A_R N_R) / A` in units of one triangle test, where
//! `A` are surface areas and `N` primitive counts; a leaf costs `N`, or
//! for leaves tested in blocks the number of blocks
//! ([`LeafTests`](super::split::LeafTests)).

use rtgi_math::Vec3A;

use super::median::{by_centroid, object_median};
use super::split::{BuildRef, Context, RangeBounds, Split};
use crate::SahAxes;
use crate::boxa::BoxA;

/// Decides between the best split found (its summed `A · N` over both
/// sides, `f32::INFINITY` when there is none) and a leaf. `None` means leaf;
/// otherwise the caller performs its split. Ranges larger than the maximum
/// leaf size are always split.
fn split_pays(ctx: &Context, count: usize, range: &RangeBounds, best_area_count: f32) -> bool {
    let must_split = count > ctx.max_leaf_size;
    if !best_area_count.is_finite() {
        return must_split;
    }
    let node_area = range.bounds.half_area();
    let split_cost = if node_area > 0.0 {
        ctx.traversal_cost + best_area_count / node_area
    } else {
        ctx.traversal_cost + ctx.leaf_cost(count)
    };
    must_split || split_cost < ctx.leaf_cost(count)
}

/// Bins a node's primitives fall into, per axis.
#[derive(Clone, Copy)]
struct Bin {
    bounds: BoxA,
    count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin { bounds: BoxA::EMPTY, count: 0 };
}

/// Most bins kept on the stack (and binned in parallel); more use the heap.
const STACK_BINS: usize = 32;

/// Ranges at least this long are binned in parallel chunks.
const PARALLEL_BINNING: usize = 32 * 1024;

/// Ranges at least this long are binned into two sets of bins (see
/// `binned_core`); shorter ones would spend more on clearing the second set.
const PAIRED_BINNING: usize = 256;

/// Adds the counts and boxes of `from`'s bins to `into`'s, axis by axis
/// (as many bins as `into` has).
fn merge_bins(into: &mut [&mut [Bin]; 3], from: &[impl AsRef<[Bin]>; 3]) {
    for (into, from) in into.iter_mut().zip(from) {
        for (bin, other) in into.iter_mut().zip(from.as_ref()) {
            bin.bounds = bin.bounds.union(other.bounds);
            bin.count += other.count;
        }
    }
}

/// Maps centroids to bins along each axis.
#[derive(Clone, Copy)]
struct Binning {
    origin: Vec3A,
    scale: Vec3A,
    last: u32,
}

/// 1.5 · 2^23: added to a float in [-0.5, 2^22), it leaves the nearest
/// integer in the low mantissa bits, a float-to-integer conversion in one
/// addition (Hecker's trick) instead of Rust's saturating `as` casts.
const ROUNDING_MAGIC: f32 = 12_582_912.0;

impl Binning {
    /// The bins of a (doubled) centroid along the three axes. Bin `k` holds
    /// positions in `[k, k + 1)` of the scaled axis, up to ties at the
    /// borders, which both this and [`Binning::bin`] resolve alike.
    #[inline(always)]
    fn bins(&self, centroid: Vec3A) -> [u32; 3] {
        let shifted = (centroid - self.origin) * self.scale + Vec3A::splat(ROUNDING_MAGIC - 0.5);
        shifted.to_array().map(|f| (f.to_bits() - ROUNDING_MAGIC.to_bits()).min(self.last))
    }

    /// The bin along one axis; the same arithmetic as [`Binning::bins`], so
    /// that partitioning agrees with binning exactly.
    #[inline(always)]
    fn bin(&self, centroid: Vec3A, axis: usize) -> u32 {
        let shifted = (centroid - self.origin) * self.scale + Vec3A::splat(ROUNDING_MAGIC - 0.5);
        (shifted.to_array()[axis].to_bits() - ROUNDING_MAGIC.to_bits()).min(self.last)
    }
}

/// Binned SAH (Wald, "On fast Construction of SAH-based Bounding Volume
/// Hierarchies", 2007): centroids are sorted into `sah_bins` equal bins per
/// axis (fewer for ranges shorter than that), and splits are evaluated only
/// at bin borders. The children's bounds are gathered while partitioning,
/// so no extra pass measures them.
pub(crate) fn binned<R: BuildRef>(ctx: &Context, prims: &mut [R], range: &RangeBounds) -> Option<Split> {
    if prims.len() <= SMALL_RANGE && ctx.sah_axes == SahAxes::All {
        return small(ctx, prims, range);
    }
    let bins = ctx.sah_bins.min(prims.len()).max(2);
    // Bin arrays live on the stack, sized to a power of two at least the bin
    // count, so that short ranges do not initialise arrays they do not use.
    match bins.next_power_of_two() {
        2 => binned_on_stack::<R, 2>(ctx, prims, range, bins),
        4 => binned_on_stack::<R, 4>(ctx, prims, range, bins),
        8 => binned_on_stack::<R, 8>(ctx, prims, range, bins),
        16 => binned_on_stack::<R, 16>(ctx, prims, range, bins),
        32 => binned_on_stack::<R, 32>(ctx, prims, range, bins),
        _ => {
            let mut storage: Vec<Vec<Bin>> = vec![vec![Bin::EMPTY; bins]; 3];
            let [x, y, z] = &mut storage[..] else { unreachable!("three axes") };
            binned_core(ctx, prims, range, bins, [&mut x[..], &mut y[..], &mut z[..]])
        }
    }
}

fn binned_on_stack<R: BuildRef, const N: usize>(
    ctx: &Context,
    prims: &mut [R],
    range: &RangeBounds,
    bins: usize,
) -> Option<Split> {
    let mut storage = [[Bin::EMPTY; N]; 3];
    let [x, y, z] = &mut storage;
    binned_core(ctx, prims, range, bins, [&mut x[..bins], &mut y[..bins], &mut z[..bins]])
}

fn binned_core<R: BuildRef>(
    ctx: &Context,
    prims: &mut [R],
    range: &RangeBounds,
    bins: usize,
    mut per_axis: [&mut [Bin]; 3],
) -> Option<Split> {
    let count = prims.len();
    let origin = range.centroids.min;
    let extent = range.centroids.max - origin;
    // Slightly less than bins / extent, so that the largest centroid lands in the last bin.
    let mut usable = extent.cmpgt(Vec3A::ZERO) & extent.is_finite_mask();
    if ctx.sah_axes == SahAxes::Longest {
        let longest = Vec3A::select(usable, extent, Vec3A::ZERO).max_position();
        usable &= Vec3A::AXES[longest].cmpgt(Vec3A::ZERO);
    }
    let scale = Vec3A::select(usable, Vec3A::splat(bins as f32 * (1.0 - 1e-6)) / extent, Vec3A::ZERO);
    let binning = Binning { origin, scale, last: bins as u32 - 1 };

    // Sorted primitives (every range below the root's) often fall in the
    // bin of the one before, and then each bin update waits for the last
    // one's store. Long ranges alternate between two sets of bins, merged
    // after, so that two such chains run at once.
    let add = |per_axis: &mut [&mut [Bin]; 3], prim: &R| {
        let bounds = prim.bounds();
        let slots = binning.bins(prim.centroid2());
        for axis in 0..3 {
            let bin = &mut per_axis[axis][slots[axis] as usize];
            bin.bounds = bin.bounds.union(bounds);
            bin.count += 1;
        }
    };
    let fill = |chunk: &[R], per_axis: &mut [&mut [Bin]; 3]| {
        if chunk.len() < PAIRED_BINNING || bins > STACK_BINS {
            chunk.iter().for_each(|prim| add(per_axis, prim));
            return;
        }
        let mut odd_storage = [[Bin::EMPTY; STACK_BINS]; 3];
        let [x, y, z] = &mut odd_storage;
        let mut odd = [&mut x[..bins], &mut y[..bins], &mut z[..bins]];
        let pairs = chunk.chunks_exact(2);
        pairs.remainder().iter().for_each(|prim| add(per_axis, prim));
        for pair in pairs {
            add(per_axis, &pair[0]);
            add(&mut odd, &pair[1]);
        }
        merge_bins(per_axis, &odd);
    };
    if count >= PARALLEL_BINNING && bins <= STACK_BINS {
        use rayon::prelude::*;
        let partial = prims
            .par_chunks(PARALLEL_BINNING / 4)
            .map(|chunk| {
                let mut local = [[Bin::EMPTY; STACK_BINS]; 3];
                let [x, y, z] = &mut local;
                fill(chunk, &mut [&mut x[..bins], &mut y[..bins], &mut z[..bins]]);
                local
            })
            .collect::<Vec<_>>();
        for local in &partial {
            merge_bins(&mut per_axis, local);
        }
    } else {
        fill(prims, &mut per_axis);
    }

    // best = (sum of A·N over both sides, axis, last bin of the left side)
    let mut best = (f32::INFINITY, 0, 0);
    let mut right_cost = [0.0f32; STACK_BINS];
    let mut right_cost_heap = Vec::new();
    let right_cost: &mut [f32] = if bins <= STACK_BINS {
        &mut right_cost[..bins]
    } else {
        right_cost_heap.resize(bins, 0.0);
        &mut right_cost_heap
    };
    for axis in (0..3).filter(|&a| usable.test(a)) {
        let axis_bins = &per_axis[axis];
        let (mut acc, mut n) = (BoxA::EMPTY, 0u32);
        for k in (1..bins).rev() {
            acc = acc.union(axis_bins[k].bounds);
            n += axis_bins[k].count;
            right_cost[k] = acc.half_area() * ctx.leaf_cost(n as usize);
        }
        let (mut acc, mut n) = (BoxA::EMPTY, 0u32);
        for k in 0..bins - 1 {
            acc = acc.union(axis_bins[k].bounds);
            n += axis_bins[k].count;
            if n == 0 || n as usize == count {
                continue;
            }
            let cost = acc.half_area() * ctx.leaf_cost(n as usize) + right_cost[k + 1];
            if cost < best.0 {
                best = (cost, axis, k);
            }
        }
    }

    if !split_pays(ctx, count, range, best.0) {
        return None;
    }
    if !best.0.is_finite() {
        // All centroids coincide (or no border separates them): equal counts.
        return Some(object_median(prims, range));
    }
    let (_, axis, last_left_bin) = best;
    let last_left_bin = last_left_bin as u32;
    // Branch-free partition: which side a primitive goes to is as good as
    // random near the root, where a branch on it would mispredict half the time.
    let mut sides = [RangeBounds::EMPTY; 2];
    let mut left_count = 0;
    for i in 0..count {
        let prim = prims[i];
        let goes_left = binning.bin(prim.centroid2(), axis) <= last_left_bin;
        prims[i] = prims[left_count];
        prims[left_count] = prim;
        left_count += goes_left as usize;
        sides[goes_left as usize].add(&prim);
    }
    let [right, left] = sides;
    Some(Split { left_count, left, right })
}

/// Ranges this short are split by an exact sweep on the stack: cheaper
/// than binning them, and exact.
const SMALL_RANGE: usize = 8;

/// The best split of a range of `count` primitives, over the three axes:
/// `bounds(axis, k)` is the box of the `k`-th primitive of the range sorted
/// by centroid along `axis`, and `right_cost` is scratch space of `count`
/// entries. Returns the summed `A · N` of both sides (`N` priced by
/// [`Context::leaf_cost`]), the axis and the left count.
#[inline(always)]
fn best_sweep(
    ctx: &Context,
    count: usize,
    bounds: impl Fn(usize, usize) -> BoxA,
    right_cost: &mut [f32],
) -> (f32, usize, usize) {
    let mut best = (f32::INFINITY, 0, 0);
    for axis in 0..3 {
        let mut acc = BoxA::EMPTY;
        for k in (1..count).rev() {
            acc = acc.union(bounds(axis, k));
            right_cost[k] = acc.half_area() * ctx.leaf_cost(count - k);
        }
        let mut acc = BoxA::EMPTY;
        for k in 0..count - 1 {
            acc = acc.union(bounds(axis, k));
            let cost = acc.half_area() * ctx.leaf_cost(k + 1) + right_cost[k + 1];
            // Equal costs (coincident boxes) go to the most even split, so
            // that such ranges halve instead of peeling one primitive a level.
            let imbalance = |left: usize| left.abs_diff(count - left);
            if cost < best.0 || (cost == best.0 && imbalance(k + 1) < imbalance(best.2)) {
                best = (cost, axis, k + 1);
            }
        }
    }
    best
}

/// A key whose unsigned order is [`by_centroid`]'s order along `axis`:
/// the centroid's coordinate in [`f32::total_cmp`]'s order, then the index.
#[inline(always)]
fn centroid_key<R: BuildRef>(prim: &R, axis: usize) -> u64 {
    let bits = prim.centroid2()[axis].to_bits();
    // Negative floats order backwards as integers: flip their magnitude
    // bits, then the sign bit, so that all of them order as unsigned.
    let total_order = bits ^ ((((bits as i32) >> 31) as u32) >> 1) ^ 0x8000_0000;
    (u64::from(total_order) << 32) | u64::from(prim.index())
}

/// The full sweep of [`sweep`] for at most [`SMALL_RANGE`] primitives.
/// Most nodes of a tree are this small, so this keeps the per-node
/// overhead of binning (bin arrays to clear, three axes to evaluate) off
/// the bottom levels. Each axis's order is found by ranking integer keys,
/// all pairs compared without branches, instead of sorting the 32-byte
/// references three times with a comparison function.
fn small<R: BuildRef>(ctx: &Context, prims: &mut [R], range: &RangeBounds) -> Option<Split> {
    let count = prims.len();
    debug_assert!(count <= SMALL_RANGE);
    let mut sorted = [[0u8; SMALL_RANGE]; 3];
    for (axis, order) in sorted.iter_mut().enumerate() {
        let mut keys = [u64::MAX; SMALL_RANGE];
        for (key, prim) in keys.iter_mut().zip(prims.iter()) {
            *key = centroid_key(prim, axis);
        }
        for i in 0..count {
            // Equal keys (a primitive referenced twice) rank by position,
            // so that the ranks are a permutation.
            let rank = (0..count).filter(|&j| keys[j] < keys[i] || (keys[j] == keys[i] && j < i)).count();
            order[rank] = i as u8;
        }
    }
    let best = best_sweep(ctx, count, |axis, k| prims[sorted[axis][k] as usize].bounds(), &mut [0.0; SMALL_RANGE]);
    if !split_pays(ctx, count, range, best.0) {
        return None;
    }
    let (_, axis, left_count) = best;
    let mut unsorted = [prims[0]; SMALL_RANGE];
    unsorted[..count].copy_from_slice(prims);
    for (prim, &i) in prims.iter_mut().zip(&sorted[axis][..count]) {
        *prim = unsorted[i as usize];
    }
    Some(Split::measured(prims, left_count))
}

/// Full-sweep SAH: every split between neighbouring centroids on every axis
/// is evaluated exactly. Slow (three sorts per node), and the reference for
/// the quality of the binned build.
pub(crate) fn sweep<R: BuildRef>(ctx: &Context, prims: &mut [R], range: &RangeBounds) -> Option<Split> {
    let count = prims.len();
    let mut sorted: [Vec<R>; 3] = [prims.to_vec(), prims.to_vec(), prims.to_vec()];
    for (axis, order) in sorted.iter_mut().enumerate() {
        order.sort_unstable_by(by_centroid(axis));
    }
    let best = best_sweep(ctx, count, |axis, k| sorted[axis][k].bounds(), &mut vec![0.0; count]);
    if !split_pays(ctx, count, range, best.0) {
        return None;
    }
    let (_, axis, left_count) = best;
    prims.copy_from_slice(&sorted[axis]);
    Some(Split::measured(prims, left_count))
}

#[cfg(test)]
mod tests {
    use rtgi_math::{Vec3, Vec3A};

    use super::{binned, centroid_key, small, sweep};
    use crate::boxa::BoxA;
    use crate::bvh::median::by_centroid;
    use crate::bvh::split::{Context, LeafTests, PrimRef, RangeBounds};
    use crate::{BuildParams, Bvh, SahAxes, SplitMethod};

    /// Four unit squares' halves in a row, a tenth apart: priced one by
    /// one, a leaf costs 4 and two leaves of two cost 1 + 2 · 2 · 2.1/4.3
    /// ≈ 2.95, so every sweep splits them; priced in blocks of four, the
    /// leaf costs one block and the split 1 + 2 · 2.1/4.3 ≈ 1.98, so every
    /// sweep keeps them together. Five in a row take two blocks however
    /// they are split, so every sweep splits them into two leaves of one
    /// block each.
    #[test]
    fn leaves_priced_in_blocks_keep_a_block_of_four_together() {
        let row = |count: u32| -> Vec<PrimRef> {
            (0..count)
                .map(|i| {
                    let x = i as f32 * 1.1;
                    PrimRef::new(BoxA { min: Vec3A::new(x, 0.0, 0.0), max: Vec3A::new(x + 1.0, 1.0, 0.0) }, i)
                })
                .collect()
        };
        let params = BuildParams { max_leaf_size: 8, ..BuildParams::default() };
        let splits = |leaf_tests, count| {
            let ctx = Context::of(SplitMethod::BinnedSah, &params, leaf_tests);
            let mut prims = row(count);
            let range = RangeBounds::of(&prims);
            [
                binned(&ctx, &mut prims.clone(), &range).map(|split| split.left_count),
                small(&ctx, &mut prims.clone(), &range).map(|split| split.left_count),
                sweep(&ctx, &mut prims, &range).map(|split| split.left_count),
            ]
        };
        assert_eq!(splits(LeafTests::OneByOne, 4), [Some(2); 3], "one by one, four split in two");
        assert_eq!(splits(LeafTests::InBlocksOf(4), 4), [None; 3], "in blocks, four stay one leaf");
        for split in splits(LeafTests::InBlocksOf(4), 5) {
            assert!(matches!(split, Some(1..=4)), "in blocks, five split into two blocks: {split:?}");
        }
        assert_eq!(LeafTests::InBlocksOf(4).steps(5), 2);
        assert_eq!(LeafTests::OneByOne.steps(5), 5);
    }

    /// The small sweep ranks integer keys where every other sweep sorts by
    /// [`by_centroid`]; both must give one order, or the trees would differ
    /// with the range's length. Signed zeros, subnormals, infinities and
    /// equal centroids with different indices are where a key goes wrong.
    #[test]
    fn centroid_keys_order_as_by_centroid() {
        let values = [f32::NEG_INFINITY, -3e38, -1.0, -1e-40, -0.0, 0.0, 1e-40, 1.0, 3e38, f32::INFINITY];
        let mut prims = Vec::new();
        for (i, &x) in values.iter().enumerate() {
            for index in [0, i as u32 + 1, (1 << 30) - 1] {
                let corner = Vec3A::new(x, -x, x * 0.5);
                prims.push(PrimRef::new(BoxA { min: corner, max: corner }, index));
            }
        }
        for axis in 0..3 {
            let order = by_centroid(axis);
            for a in &prims {
                for b in &prims {
                    assert_eq!(
                        centroid_key(a, axis).cmp(&centroid_key(b, axis)),
                        order(a, b),
                        "axis {axis}: {a:?} against {b:?}"
                    );
                }
            }
        }
    }

    /// Two rows of small triangles, long along x and far apart along y:
    /// the SAH over all axes separates the rows (a split along y), the
    /// course's SAH may only cut the longest axis, x.
    #[test]
    fn longest_axis_only_splits_the_longest_axis() {
        let mut triangles = Vec::new();
        for row in [0.0f32, 6.0] {
            for i in 0..64 {
                let corner = Vec3::new(i as f32 * 0.25, row, 0.0);
                triangles.push([corner, corner + Vec3::new(0.1, 0.0, 0.0), corner + Vec3::new(0.0, 0.1, 0.0)]);
            }
        }
        let children = |sah_axes| {
            let params = BuildParams { sah_bins: 8, sah_axes, ..BuildParams::default() };
            let boxes = Bvh::new(&triangles, SplitMethod::BinnedSah, &params).boxes_at_depths(&[1]);
            assert_eq!(boxes.len(), 2);
            (boxes[0].1, boxes[1].1)
        };
        let apart = |(a, b): (rtgi_math::Aabb, rtgi_math::Aabb), axis: usize| {
            a.max[axis] < b.min[axis] || b.max[axis] < a.min[axis]
        };
        let all = children(SahAxes::All);
        assert!(apart(all, 1) && !apart(all, 0), "all axes: the rows are split apart ({all:?})");
        let longest = children(SahAxes::Longest);
        assert!(apart(longest, 0) && !apart(longest, 1), "longest axis: x is cut ({longest:?})");
    }
}
