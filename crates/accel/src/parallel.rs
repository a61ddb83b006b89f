//! Many rays through one structure on the current thread pool: the batch
//! queries ([`Accel::intersect_batch`], [`Accel::occluded_batch`]) on runs
//! of [`BATCH_RAYS`] consecutive rays, the runs in parallel. The wide BVHs
//! trace coherent runs (camera rays in tiles) as packets. What `rtgi
//! trace` and the Python package do with a file or an array of rays.

use rayon::prelude::*;

use crate::{Accel, Hit, Ray};

/// Rays given to one batch query: runs of this many consecutive rays.
pub const BATCH_RAYS: usize = 1024;

/// A filter of candidate hits (triangle, beta, gamma): cut-outs' holes.
pub type HitFilter<'a> = &'a (dyn Fn(u32, f32, f32) -> bool + Sync);

/// The closest hit of every ray, in their order, with `filter` if given.
pub fn intersect_all(accel: &dyn Accel, rays: &[Ray], filter: Option<HitFilter<'_>>) -> Vec<Option<Hit>> {
    let mut hits = vec![None; rays.len()];
    rays.par_chunks(BATCH_RAYS).zip(hits.par_chunks_mut(BATCH_RAYS)).for_each(|(batch, out)| match filter {
        Some(accept) => accel.intersect_batch_filtered(batch, out, accept),
        None => accel.intersect_batch(batch, out),
    });
    hits
}

/// Whether each ray is occluded, in their order, with `filter` if given.
pub fn occluded_all(accel: &dyn Accel, rays: &[Ray], filter: Option<HitFilter<'_>>) -> Vec<bool> {
    let mut occluded = vec![false; rays.len()];
    rays.par_chunks(BATCH_RAYS).zip(occluded.par_chunks_mut(BATCH_RAYS)).for_each(|(batch, out)| match filter {
        Some(accept) => accel.occluded_batch_filtered(batch, out, accept),
        None => accel.occluded_batch(batch, out),
    });
    occluded
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
}
