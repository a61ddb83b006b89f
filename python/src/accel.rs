//! `rtgi.Accel`: an acceleration structure over a scene's triangles, and
//! its ray queries on arrays. Tracing releases the GIL and runs on rayon's
//! threads, in runs of [`BATCH_RAYS`] rays given to the batch queries, as
//! `rtgi trace` and [`rtgi_accel::parallel::intersect_all`] trace;
//! each run's rays are made from the arrays, and its answers written to the
//! output arrays, by the thread that traces it.

use numpy::PyArray1;
use pyo3::prelude::*;
use rayon::prelude::*;
use rtgi_accel::parallel::BATCH_RAYS;
use rtgi_accel::{AccelKind, BuildParams, Hit, Ray, Vec3};
use rtgi_job::Structure;

use crate::arrays::{Bounds, PerRay, rows3_f32};
use crate::errors::{request, request_error, to_python};

/// The triangle index of a ray that hits nothing (as in `rtgi trace`'s hit files).
pub const MISS: u32 = u32::MAX;

/// An acceleration structure, built by `Scene.build`; immutable, and
/// shared between threads (several may trace at once).
#[pyclass(module = "rtgi", frozen)]
#[derive(Debug)]
pub struct Accel {
    accel: Box<dyn rtgi_accel::Accel>,
    kind: AccelKind,
    params: BuildParams,
}

impl Accel {
    /// Builds `structure` over `triangles` (without the GIL, on rayon's threads).
    pub fn build(py: Python<'_>, triangles: &[[Vec3; 3]], structure: &Structure) -> PyResult<Accel> {
        let params = structure.params();
        params.check().map_err(|e| request_error("build", e))?;
        let kind = structure.kind;
        let accel = py.detach(|| kind.try_build(triangles, &params)).map_err(request)?;
        Ok(Accel { accel, kind, params })
    }

    /// The structure, for the library's functions.
    pub fn inner(&self) -> &dyn rtgi_accel::Accel {
        self.accel.as_ref()
    }
}

/// `origins`, `directions`, `tmin` and `tmax` read as slices: the input of a query.
struct RayInput<'a> {
    origins: &'a [f32],
    directions: &'a [f32],
    t_min: Bounds<'a>,
    t_max: Bounds<'a>,
}

impl RayInput<'_> {
    /// Rays `start..start + len` into `rays` (cleared first).
    #[inline]
    fn batch(&self, start: usize, len: usize, rays: &mut Vec<Ray>) {
        rays.clear();
        rays.extend((start..start + len).map(|i| {
            let (o, d) = (&self.origins[3 * i..3 * i + 3], &self.directions[3 * i..3 * i + 3]);
            Ray::with_range(
                Vec3::new(o[0], o[1], o[2]),
                Vec3::new(d[0], d[1], d[2]),
                self.t_min.get(i),
                self.t_max.get(i),
            )
        }));
    }
}

/// Reads the query's arrays and runs `trace` on them without the GIL.
fn with_rays<'py, T: Send>(
    py: Python<'py>,
    origins: &Bound<'py, PyAny>,
    directions: &Bound<'py, PyAny>,
    tmin: Option<&Bound<'py, PyAny>>,
    tmax: Option<&Bound<'py, PyAny>>,
    trace: impl FnOnce(&RayInput<'_>, usize) -> T + Send,
) -> PyResult<T> {
    let origins = rows3_f32("origins", origins)?;
    let directions = rows3_f32("directions", directions)?;
    let count = origins.as_slice()?.len() / 3;
    if directions.as_slice()?.len() != origins.as_slice()?.len() {
        return Err(request_error(
            "directions",
            format!("{} rays, and origins has {count}", directions.as_slice()?.len() / 3),
        ));
    }
    let t_min = PerRay::read("tmin", tmin, 0.0, count)?;
    let t_max = PerRay::read("tmax", tmax, f32::INFINITY, count)?;
    let input = RayInput {
        origins: origins.as_slice()?,
        directions: directions.as_slice()?,
        t_min: t_min.view()?,
        t_max: t_max.view()?,
    };
    Ok(py.detach(|| trace(&input, count)))
}

/// Closest hits as arrays: t, triangle, beta, gamma.
type HitArrays<'py> =
    (Bound<'py, PyArray1<f32>>, Bound<'py, PyArray1<u32>>, Bound<'py, PyArray1<f32>>, Bound<'py, PyArray1<f32>>);

#[pymethods]
impl Accel {
    /// The closest hits of rays given as arrays.
    ///
    /// `origins` and `directions` are N×3 float32 arrays (read in place
    /// when C-contiguous; other float dtypes and layouts are converted once);
    /// `tmin` and `tmax` bound each ray's distance, as a number for all or
    /// an array of N (default 0 and infinity). Returns `rtgi.Hits(t,
    /// triangle, beta, gamma)`: float32, uint32, float32, float32 arrays of N; a ray
    /// that hits nothing has `t = inf`, `triangle = rtgi.MISS` and
    /// `beta = gamma = 0`. Every structure gives the linear scan's hits, bit
    /// for bit (Embree, a peer, excepted). Releases the GIL; traces on
    /// rtgi's worker threads.
    #[pyo3(signature = (origins, directions, tmin = None, tmax = None))]
    fn intersect<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let accel = self.accel.as_ref();
        let (t, triangle, beta, gamma) = with_rays(py, origins, directions, tmin, tmax, |input, count| {
            let (mut t, mut triangle) = (vec![0f32; count], vec![0u32; count]);
            let (mut beta, mut gamma) = (vec![0f32; count], vec![0f32; count]);
            (
                t.par_chunks_mut(BATCH_RAYS),
                triangle.par_chunks_mut(BATCH_RAYS),
                beta.par_chunks_mut(BATCH_RAYS),
                gamma.par_chunks_mut(BATCH_RAYS),
            )
                .into_par_iter()
                .enumerate()
                .for_each_init(
                    || (Vec::with_capacity(BATCH_RAYS), vec![None; BATCH_RAYS]),
                    |(rays, hits), (index, (t, triangle, beta, gamma))| {
                        input.batch(index * BATCH_RAYS, t.len(), rays);
                        let hits: &mut [Option<Hit>] = &mut hits[..t.len()];
                        accel.intersect_batch(rays, hits);
                        for (i, hit) in hits.iter().enumerate() {
                            let hit = hit.unwrap_or(Hit { t: f32::INFINITY, triangle: MISS, beta: 0.0, gamma: 0.0 });
                            (t[i], triangle[i], beta[i], gamma[i]) = (hit.t, hit.triangle, hit.beta, hit.gamma);
                        }
                    },
                );
            (t, triangle, beta, gamma)
        })?;
        let arrays: HitArrays<'py> = (
            PyArray1::from_vec(py, t),
            PyArray1::from_vec(py, triangle),
            PyArray1::from_vec(py, beta),
            PyArray1::from_vec(py, gamma),
        );
        // As the named tuple `rtgi.Hits` (rtgi/__init__.py).
        py.import("rtgi")?.getattr("Hits")?.call1(arrays)
    }

    /// Whether anything is hit by each ray (any hit; stops at the first
    /// found): a bool array of N, true exactly where `intersect` hits.
    /// Arguments as for `intersect`; releases the GIL.
    #[pyo3(signature = (origins, directions, tmin = None, tmax = None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: &Bound<'py, PyAny>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let accel = self.accel.as_ref();
        let occluded = with_rays(py, origins, directions, tmin, tmax, |input, count| {
            let mut occluded = vec![false; count];
            occluded.par_chunks_mut(BATCH_RAYS).enumerate().for_each_init(Vec::new, |rays, (index, out)| {
                input.batch(index * BATCH_RAYS, out.len(), rays);
                accel.occluded_batch(rays, out);
            });
            occluded
        })?;
        Ok(PyArray1::from_vec(py, occluded))
    }

    /// The structure's name (`bvh8`, `sah`, ...).
    #[getter]
    fn kind(&self) -> &'static str {
        self.kind.name()
    }

    /// Milliseconds the build took.
    #[getter]
    fn build_ms(&self) -> f64 {
        self.accel.build_stats().build_ms
    }

    /// The build's statistics as a dict: variant, triangles,
    /// excluded_triangles, build_ms, nodes, leaves, depth,
    /// leaf_size_histogram, sah_cost, memory_bytes.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, self.accel.build_stats())
    }

    /// The build parameters used, as a dict (leaf size, bins, axes,
    /// traversal cost, intersector, traversal).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
        let p = &self.params;
        let dict = pyo3::types::PyDict::new(py);
        dict.set_item("leaf_size", p.max_leaf_size)?;
        dict.set_item("sah_bins", p.sah_bins)?;
        dict.set_item("sah_axes", p.sah_axes.name())?;
        dict.set_item("traversal_cost", p.traversal_cost)?;
        dict.set_item("intersector", p.intersector.name())?;
        dict.set_item("traversal", p.traversal.name())?;
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        let stats = self.accel.build_stats();
        format!(
            "<rtgi.Accel {}: {} triangles, {} nodes, depth {}, built in {:.1} ms>",
            self.kind, stats.triangles, stats.nodes, stats.depth, stats.build_ms
        )
    }
}
