//! The two median splits of the course.

use std::cmp::Ordering;

use super::split::{BuildRef, RangeBounds, Split};

/// Orders primitives by centroid along `axis`, ties by index, so that
/// builds are deterministic.
#[inline]
pub(crate) fn by_centroid<R: BuildRef>(axis: usize) -> impl Fn(&R, &R) -> Ordering {
    move |a, b| a.centroid2()[axis].total_cmp(&b.centroid2()[axis]).then(a.index().cmp(&b.index()))
}

/// Equal counts: the lower half of the centroids along the longest axis of
/// the centroids' box goes left. Always splits a range of two or more.
pub(crate) fn object_median<R: BuildRef>(prims: &mut [R], range: &RangeBounds) -> Split {
    let axis = range.centroids.to_aabb().longest_axis();
    let half = prims.len() / 2;
    prims.select_nth_unstable_by(half, by_centroid(axis));
    Split::measured(prims, half)
}

/// Splits the longest axis of the node's box at its middle.
///
/// When every centroid falls on one side (a few large primitives spanning a
/// small cluster, say), the middle of the centroids' box is tried instead,
/// which always separates distinct centroids; when all centroids are equal,
/// or rounding makes the middle equal to an end, the object median splits.
/// Each fallback strictly shrinks both sides, so recursion ends.
pub(crate) fn spatial_median<R: BuildRef>(prims: &mut [R], range: &RangeBounds) -> Split {
    // Centroids are kept doubled, so the node's box is doubled to compare with them.
    let doubled_bounds = range.bounds.scaled(2.0);
    for bounds in [doubled_bounds, range.centroids] {
        let aabb = bounds.to_aabb();
        let axis = aabb.longest_axis();
        let middle = aabb.centroid()[axis];
        let left = partition(prims, |p| p.centroid2()[axis] < middle);
        if left > 0 && left < prims.len() {
            return Split::measured(prims, left);
        }
    }
    object_median(prims, range)
}

/// Moves the elements satisfying `goes_left` to the front; returns their count.
fn partition<R: BuildRef>(prims: &mut [R], goes_left: impl Fn(&R) -> bool) -> usize {
    let mut left = 0;
    for i in 0..prims.len() {
        if goes_left(&prims[i]) {
            prims.swap(left, i);
            left += 1;
        }
    }
    left
}
