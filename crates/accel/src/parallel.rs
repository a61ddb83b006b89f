//! Many rays through one structure on the current thread pool: the batch
//! queries ([`Accel::intersect_batch`], [`Accel::occluded_batch`]) on runs
//! of [`BATCH_RAYS`] consecutive rays, the runs in parallel. The wide BVHs
//! trace coherent runs (camera rays in tiles) as packets. What `rtgi
//! trace` and the Python package do with a file or an array of rays.

use rayon::prelude::*;

use crate::{Accel, Hit, Ray, TraversalCounters};

/// Rays given to one batch query: runs of this many consecutive rays.
pub const BATCH_RAYS: usize = 1024;

/// A filter of candidate hits (triangle, beta, gamma): cut-outs' holes.
pub type HitFilter<'a> = &'a (dyn Fn(u32, f32, f32) -> bool + Sync);

/// The closest hit of every ray, in their order, with `filter` if given.
pub fn intersect_all(accel: &dyn Accel, rays: &[Ray], filter: Option<HitFilter<'_>>) -> Vec<Option<Hit>> {
    by_runs(rays, |batch, out| match filter {
        Some(accept) => accel.intersect_batch_filtered(batch, out, accept),
        None => accel.intersect_batch(batch, out),
    })
}

/// Whether each ray is occluded, in their order, with `filter` if given.
pub fn occluded_all(accel: &dyn Accel, rays: &[Ray], filter: Option<HitFilter<'_>>) -> Vec<bool> {
    by_runs(rays, |batch, out| match filter {
        Some(accept) => accel.occluded_batch_filtered(batch, out, accept),
        None => accel.occluded_batch(batch, out),
    })
}

/// [`intersect_all`] through the single-ray query ([`Accel::intersect`],
/// or [`Accel::intersect_filtered`] with `filter`), ray by ray: what a
/// renderer's secondary rays use, and for a peer the API to compare ours
/// with (Embree's `rtcIntersect1`, where the batch queries are its packets).
/// The answers are [`intersect_all`]'s.
pub fn intersect_each(accel: &dyn Accel, rays: &[Ray], filter: Option<HitFilter<'_>>) -> Vec<Option<Hit>> {
    by_runs(rays, |batch, out| {
        for (ray, hit) in batch.iter().zip(out) {
            *hit = match filter {
                Some(accept) => accel.intersect_filtered(ray, accept),
                None => accel.intersect(ray),
            };
        }
    })
}

/// [`occluded_all`] through the single-ray query, as [`intersect_each`].
pub fn occluded_each(accel: &dyn Accel, rays: &[Ray], filter: Option<HitFilter<'_>>) -> Vec<bool> {
    by_runs(rays, |batch, out| {
        for (ray, answer) in batch.iter().zip(out) {
            *answer = match filter {
                Some(accept) => accel.occluded_filtered(ray, accept),
                None => accel.occluded(ray),
            };
        }
    })
}

/// Answers `rays` in runs of [`BATCH_RAYS`] consecutive rays, the runs in
/// parallel, each by `query`; the answers in the rays' order.
fn by_runs<T: Clone + Default + Send>(rays: &[Ray], query: impl Fn(&[Ray], &mut [T]) + Sync) -> Vec<T> {
    let mut answers = vec![T::default(); rays.len()];
    rays.par_chunks(BATCH_RAYS).zip(answers.par_chunks_mut(BATCH_RAYS)).for_each(|(batch, out)| query(batch, out));
    answers
}

/// The work the single-ray queries of `rays` do: nodes whose boxes were
/// tested and ray/triangle tests, summed (a peer that reports neither, as
/// Embree, counts only the rays). Counted ray by ray, in parallel, for
/// statistics: a counted query is slower than the batch queries above and
/// sees no cut-outs (every triangle is solid).
pub fn count_work(accel: &dyn Accel, rays: &[Ray], any_hit: bool) -> TraversalCounters {
    rays.par_chunks(BATCH_RAYS)
        .map(|batch| {
            let mut counters = TraversalCounters::default();
            for ray in batch {
                if any_hit {
                    accel.occluded_counted(ray, &mut counters);
                } else {
                    accel.intersect_counted(ray, &mut counters);
                }
            }
            counters
        })
        .reduce(TraversalCounters::default, |mut a, b| {
            a += b;
            a
        })
}

/// Rows of a camera grid traced together: the side of the square tiles
/// that the batch queries take as packets of 16.
pub const GRID_TILE: usize = 4;

/// [`intersect_all`] for rays that are a camera grid `width` rays wide in
/// scanline order (row by row, as most programs write them): each band of
/// [`GRID_TILE`] rows is traced in 4×4 tiles, which the batch queries take
/// as packets, instead of runs of one row, which make poor packets. The
/// answers are [`intersect_all`]'s, in the rays' order; only the time differs.
pub fn intersect_grid(
    accel: &dyn Accel,
    rays: &[Ray],
    width: usize,
    filter: Option<HitFilter<'_>>,
) -> Vec<Option<Hit>> {
    let mut hits = vec![None; rays.len()];
    by_tiles(rays, width, &mut hits, |batch, out| match filter {
        Some(accept) => accel.intersect_batch_filtered(batch, out, accept),
        None => accel.intersect_batch(batch, out),
    });
    hits
}

/// [`occluded_all`] for a camera grid `width` rays wide, as [`intersect_grid`] traces it.
pub fn occluded_grid(accel: &dyn Accel, rays: &[Ray], width: usize, filter: Option<HitFilter<'_>>) -> Vec<bool> {
    let mut occluded = vec![false; rays.len()];
    by_tiles(rays, width, &mut occluded, |batch, out| match filter {
        Some(accept) => accel.occluded_batch_filtered(batch, out, accept),
        None => accel.occluded_batch(batch, out),
    });
    occluded
}

/// Answers `rays` band by band of [`GRID_TILE`] rows of `width`, in
/// parallel: in each band, runs of tiles ([`BATCH_RAYS`] rays) are gathered
/// in tile order into a buffer reused from run to run (a fresh buffer per
/// band cost more than the packets gained: page faults), answered by
/// `query`, and the answers put back in the rays' order.
fn by_tiles<T: Copy + Default + Send>(
    rays: &[Ray],
    width: usize,
    answers: &mut [T],
    query: impl Fn(&[Ray], &mut [T]) + Sync,
) {
    let width = width.max(1);
    let band = width * GRID_TILE;
    let columns_per_run = (BATCH_RAYS / (GRID_TILE * GRID_TILE)).max(1) * GRID_TILE;
    rays.par_chunks(band).zip(answers.par_chunks_mut(band)).for_each(|(rays, answers)| {
        let (mut gathered, mut answered, mut order) =
            (Vec::with_capacity(BATCH_RAYS), Vec::with_capacity(BATCH_RAYS), Vec::with_capacity(BATCH_RAYS));
        for first_column in (0..width).step_by(columns_per_run) {
            let end_column = (first_column + columns_per_run).min(width);
            order.clear();
            for x0 in (first_column..end_column).step_by(GRID_TILE) {
                for row in 0..GRID_TILE {
                    let start = row * width;
                    order.extend((start + x0..start + (x0 + GRID_TILE).min(end_column)).filter(|&i| i < rays.len()));
                }
            }
            gathered.clear();
            gathered.extend(order.iter().map(|&i| rays[i]));
            answered.clear();
            answered.resize(gathered.len(), T::default());
            query(&gathered, &mut answered);
            for (&i, &answer) in order.iter().zip(&answered) {
                answers[i] = answer;
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AccelKind, Vec3};

    /// The parallel runs answer as one ray at a time does, in order, across
    /// several batches and a ragged last one.
    #[test]
    fn runs_in_parallel_answer_as_single_rays() {
        let triangles: Vec<[Vec3; 3]> = (0..50)
            .map(|i| {
                let x = i as f32;
                [Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.9, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)]
            })
            .collect();
        let rays: Vec<Ray> = (0..2 * BATCH_RAYS + 37)
            .map(|i| Ray::new(Vec3::new(i as f32 * 0.025, 0.2, -1.0), Vec3::new(0.0, 0.0, 1.0)))
            .collect();
        let accel = AccelKind::Bvh8.build(&triangles, &AccelKind::Bvh8.default_params());
        let hits = intersect_all(accel.as_ref(), &rays, None);
        let occluded = occluded_all(accel.as_ref(), &rays, None);
        assert!(hits.iter().any(Option::is_some) && hits.iter().any(Option::is_none));
        for (i, ray) in rays.iter().enumerate() {
            let single = accel.intersect(ray);
            assert_eq!(
                hits[i].map(|h| (h.t.to_bits(), h.triangle)),
                single.map(|h| (h.t.to_bits(), h.triangle)),
                "ray {i}"
            );
            assert_eq!(occluded[i], single.is_some(), "ray {i}");
        }
        let odd = |triangle: u32, _: f32, _: f32| triangle % 2 == 1;
        let filtered = intersect_all(accel.as_ref(), &rays, Some(&odd));
        assert!(filtered.iter().flatten().all(|h| h.triangle % 2 == 1));
        assert!(filtered.iter().flatten().count() > 0);
    }

    /// A camera grid traced by tiles answers as the rays in their order,
    /// bit for bit, for widths that are and are not multiples of the tile,
    /// and for a last row cut short.
    #[test]
    fn a_grid_traced_by_tiles_answers_as_its_rays_in_order() {
        let triangles: Vec<[Vec3; 3]> = (0..40)
            .map(|i| {
                let (x, y) = ((i % 8) as f32, (i / 8) as f32);
                [Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y, 0.1), Vec3::new(x, y + 1.0, -0.1)]
            })
            .collect();
        let accel = AccelKind::Bvh8.build(&triangles, &AccelKind::Bvh8.default_params());
        for (width, height, cut) in [(64, 40, 0), (37, 21, 5), (3, 9, 1), (1, 17, 0)] {
            let rays: Vec<Ray> = (0..width * height - cut)
                .map(|i| {
                    let (x, y) = (((i % width) as f32 + 0.5) / width as f32, (i / width) as f32 / height as f32);
                    Ray::new(Vec3::new(4.0, 2.5, -6.0), Vec3::new(x * 10.0 - 5.0, y * 6.0 - 3.0, 6.0))
                })
                .collect();
            let key = |h: &Option<Hit>| h.map(|h| (h.t.to_bits(), h.triangle, h.beta.to_bits(), h.gamma.to_bits()));
            let grid: Vec<_> = intersect_grid(accel.as_ref(), &rays, width, None).iter().map(key).collect();
            let single: Vec<_> = rays.iter().map(|r| key(&accel.intersect(r))).collect();
            assert_eq!(grid, single, "{width}x{height}");
            assert!(grid.iter().any(Option::is_some) && grid.iter().any(Option::is_none), "{width}x{height}");
            let occluded: Vec<bool> = rays.iter().map(|r| accel.occluded(r)).collect();
            assert_eq!(occluded_grid(accel.as_ref(), &rays, width, None), occluded, "{width}x{height}");
        }
    }
}
