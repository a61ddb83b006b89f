//! Many rays at once on rayon's threads: the batch queries over runs of
//! [`BATCH_RAYS`] rays, in parallel, as `rtgi trace` and the Python package
//! trace a ray file or an array of rays.

use rayon::prelude::*;

use crate::{Accel, Hit, Ray};

/// Rays given to one batch query ([`Accel::intersect_batch`]) at a time:
/// the wide BVHs trace coherent runs (camera rays in tiles) as packets,
/// and a batch is the unit of work of a worker thread.
pub const BATCH_RAYS: usize = 1024;

/// A hit filter, as the `_filtered` queries take it: whether a candidate
/// hit on `(triangle, beta, gamma)` counts (cut-outs pass through their holes).
pub type HitFilter<'a> = &'a (dyn Fn(u32, f32, f32) -> bool + Sync);

/// `hits[i]` becomes the closest hit of `rays[i]` (accepted by `filter`,
/// if given), bit for bit as [`Accel::intersect`] answers it; runs of
/// [`BATCH_RAYS`] rays go to the batch queries on the current rayon pool.
///
/// # Panics
/// If the two slices differ in length.
pub fn intersect_parallel(accel: &dyn Accel, rays: &[Ray], hits: &mut [Option<Hit>], filter: Option<HitFilter<'_>>) {
    assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
    rays.par_chunks(BATCH_RAYS).zip(hits.par_chunks_mut(BATCH_RAYS)).for_each(|(batch, out)| match filter {
        Some(accept) => accel.intersect_batch_filtered(batch, out, accept),
        None => accel.intersect_batch(batch, out),
    });
}

/// `occluded[i]` becomes whether anything (accepted by `filter`, if given)
/// is hit by `rays[i]`, in runs of [`BATCH_RAYS`] on the current rayon pool.
///
/// # Panics
/// If the two slices differ in length.
pub fn occluded_parallel(accel: &dyn Accel, rays: &[Ray], occluded: &mut [bool], filter: Option<HitFilter<'_>>) {
    assert_eq!(rays.len(), occluded.len(), "one answer slot per ray");
    rays.par_chunks(BATCH_RAYS).zip(occluded.par_chunks_mut(BATCH_RAYS)).for_each(|(batch, out)| match filter {
        Some(accept) => accel.occluded_batch_filtered(batch, out, accept),
        None => accel.occluded_batch(batch, out),
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AccelKind, Vec3};

    /// The parallel queries answer as the one-ray queries do, over more
    /// than one batch and a batch cut short, with and without a filter.
    #[test]
    fn parallel_queries_answer_as_single_rays_do() {
        let grid = crate::verify::shapes::tessellated_cube(6).triangles();
        let rays: Vec<Ray> = (0..2 * BATCH_RAYS + 17)
            .map(|i| {
                let a = i as f32 * 0.37;
                // One ray in three points away from the cube, and misses.
                let towards = if i % 3 == 0 { -1.0 } else { 1.0 };
                Ray::new(Vec3::new(a.sin() * 0.3, a.cos() * 0.3, -3.0), Vec3::new(a.cos() * 0.1, 0.05, towards))
            })
            .collect();
        let accel = AccelKind::Bvh8.build(&grid, &AccelKind::Bvh8.default_params());
        let even = |triangle: u32, _: f32, _: f32| triangle.is_multiple_of(2);
        for filter in [None, Some(&even as HitFilter<'_>)] {
            let mut hits = vec![None; rays.len()];
            let mut occluded = vec![false; rays.len()];
            intersect_parallel(accel.as_ref(), &rays, &mut hits, filter);
            occluded_parallel(accel.as_ref(), &rays, &mut occluded, filter);
            for (i, ray) in rays.iter().enumerate() {
                let single = match filter {
                    Some(accept) => accel.intersect_filtered(ray, accept),
                    None => accel.intersect(ray),
                };
                assert_eq!(hits[i], single, "ray {i}");
                assert_eq!(occluded[i], single.is_some(), "ray {i}");
            }
            assert!(hits.iter().any(Option::is_some) && hits.iter().any(Option::is_none));
        }
    }
}
