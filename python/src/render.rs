//! `rtgi.render(scene, **request)`: a `rtgi_job::RenderRequest` from
//! keyword arguments, carried out by `rtgi_job` (in memory, or to files
//! when `output` is given), returning the image, the AOVs and the outcome.

use std::path::PathBuf;
use std::sync::Arc;

use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use rtgi_image::HdrImage;
use rtgi_job::{CancelToken, Given, LoadedScene, RenderRequest, SceneSource, Split, Unobserved};
use rtgi_render::{FilterGlossy, Integrator};

use crate::accel::Accel;
use crate::arrays::vec3;
use crate::errors::{job_error, request_error, to_python};
use crate::scene::{Scene, choice};

/// The keyword arguments `render` takes, in the order its documentation
/// lists them (the fields of `RenderRequest` and of its groups).
pub const RENDER_ARGUMENTS: &[&str] = &[
    "output",
    "aovs",
    "width",
    "height",
    "samples_per_pixel",
    "sampler",
    "seed",
    "noise",
    "time",
    "integrator",
    "max_depth",
    "roulette_start",
    "bounce_sampling",
    "direct_strategy",
    "indirect_clamp",
    "filter_glossy",
    "environment",
    "environment_scale",
    "lights",
    "effects",
    "no_default_lighting",
    "background",
    "camera",
    "at",
    "look",
    "up",
    "fov",
    "accel",
    "leaf_size",
    "sah_bins",
    "sah_axes",
    "traversal_cost",
    "intersector",
    "traversal",
    "exposure",
    "tonemap",
    "denoise",
    "samples",
    "tile",
    "time_limit",
    "checkpoint",
    "checkpoint_every",
    "resume",
    "threads",
];

/// The keyword arguments, taken one by one; what is left at the end is unknown.
struct Arguments<'py> {
    kwargs: Bound<'py, PyDict>,
}

impl<'py> Arguments<'py> {
    /// The argument `name`, converted, if given (and not `None`).
    fn take<T: FromPyObjectOwned<'py>>(&self, name: &str) -> PyResult<Option<T>> {
        let Some(value) = self.kwargs.get_item(name)? else { return Ok(None) };
        self.kwargs.del_item(name)?;
        if value.is_none() {
            return Ok(None);
        }
        value.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            let got = value.repr().map_or_else(|_| "?".into(), |r| r.to_string());
            request_error(name, format!("{} (got {got})", e.value(self.kwargs.py())))
        })
    }

    /// A named choice of the libraries, by its name.
    fn choice<T: rtgi_math::NamedChoice>(&self, name: &str) -> PyResult<Option<T>> {
        self.take::<String>(name)?.map(|text| choice::<T>(name, &text)).transpose()
    }

    /// A value that the library parses from text (lights, environments, effects).
    fn parsed<T: std::str::FromStr>(&self, name: &str) -> PyResult<Option<T>>
    where
        T::Err: std::fmt::Display,
    {
        self.take::<String>(name)?.map(|text| text.parse::<T>().map_err(|e| request_error(name, e))).transpose()
    }

    /// A number in `range` (`what` says the range in the error).
    fn number<T>(&self, name: &str, accept: impl Fn(T) -> bool, what: &str) -> PyResult<Option<T>>
    where
        T: FromPyObjectOwned<'py> + Copy + std::fmt::Display,
    {
        match self.take::<T>(name)? {
            Some(value) if !accept(value) => Err(request_error(name, format!("{value}: expected {what}"))),
            other => Ok(other),
        }
    }

    /// Refuses what is left: keywords `render` does not take.
    fn finish(self) -> PyResult<()> {
        if let Some((key, _)) = self.kwargs.iter().next() {
            return Err(request_error(
                &key.to_string(),
                format!("not an argument of render (it takes: {})", RENDER_ARGUMENTS.join(", ")),
            ));
        }
        Ok(())
    }
}

fn positive_f32(v: f32) -> bool {
    v.is_finite() && v > 0.0
}

fn positive_f64(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// The request the keyword arguments ask for, of `scene`.
fn request_from(scene: SceneSource, args: &Arguments<'_>) -> PyResult<(RenderRequest, bool)> {
    let output: Option<PathBuf> = args.take("output")?;
    let writes = output.is_some();
    let mut request = RenderRequest::new(scene, output.unwrap_or_default());
    if let Some(aovs) = args.take::<Vec<String>>("aovs")? {
        request.aovs = aovs.iter().map(|name| choice::<Integrator>("aovs", name)).collect::<PyResult<_>>()?;
    }
    let side = |v: u32| (1..=rtgi_job::MAX_IMAGE_SIDE).contains(&v);
    let sides = format!("1 to {}", rtgi_job::MAX_IMAGE_SIDE);
    request.size.width = args.number("width", side, &sides)?;
    request.size.height = args.number("height", side, &sides)?;
    let sampling = &mut request.sampling;
    sampling.samples_per_pixel = args.number("samples_per_pixel", |v: u32| v >= 1, "at least 1")?;
    sampling.sampler = args.choice("sampler")?;
    sampling.seed = args.take("seed")?.unwrap_or(0);
    sampling.noise = args.number("noise", |v: f32| v > 0.0 && v < 1.0, "a fraction between 0 and 1")?;
    sampling.time = args.number("time", positive_f64, "a positive number of seconds")?;
    let lighting = &mut request.lighting;
    if let Some(integrator) = args.choice("integrator")? {
        lighting.integrator = integrator;
    }
    if let Some(depth) = args.number("max_depth", |v: u32| v <= 1024, "0 to 1024")? {
        lighting.max_depth = depth;
    }
    if let Some(start) = args.take("roulette_start")? {
        lighting.roulette_start = start;
    }
    if let Some(sampling) = args.choice("bounce_sampling")? {
        lighting.bounce_sampling = sampling;
    }
    if let Some(strategy) = args.choice("direct_strategy")? {
        lighting.direct_strategy = strategy;
    }
    lighting.indirect_clamp = args.number("indirect_clamp", positive_f32, "a finite number greater than 0")?;
    lighting.filter_glossy = args
        .number("filter_glossy", |v: f32| v.is_finite() && v >= 0.0, "a finite number of at least 0")?
        .map(FilterGlossy::all_lobes);
    lighting.environment = args.parsed("environment")?;
    if let Some(scale) = args.number("environment_scale", positive_f32, "a finite number greater than 0")? {
        lighting.environment_scale = scale;
    }
    if let Some(lights) = args.take::<Vec<String>>("lights")? {
        lighting.lights =
            lights.iter().map(|l| l.parse().map_err(|e| request_error("lights", e))).collect::<PyResult<_>>()?;
    }
    if let Some(effects) = args.parsed("effects")? {
        lighting.effects = effects;
    }
    lighting.no_default_lighting = args.take("no_default_lighting")?.unwrap_or(false);
    if let Some(background) = args.take::<[f32; 3]>("background")? {
        if !background.iter().all(|c| c.is_finite() && *c >= 0.0) {
            return Err(request_error(
                "background",
                format!("{background:?}: expected three finite numbers of at least 0"),
            ));
        }
        request.background = rtgi_math::Vec3::from_array(background);
    }
    request.camera.index = args.take("camera")?;
    request.camera.at = vec3("at", args.take("at")?)?;
    request.camera.look = vec3("look", args.take("look")?)?;
    request.camera.up = vec3("up", args.take("up")?)?;
    request.camera.fov_degrees = args.take("fov")?;
    let structure = &mut request.structure;
    if let Some(kind) = args.take::<String>("accel")? {
        structure.kind = kind.parse().map_err(|e| request_error("accel", e))?;
    }
    structure.leaf_size = args.take("leaf_size")?;
    if let Some(bins) = args.take("sah_bins")? {
        structure.sah_bins = bins;
    }
    if let Some(axes) = args.choice("sah_axes")? {
        structure.sah_axes = axes;
    }
    structure.traversal_cost = args.take("traversal_cost")?;
    if let Some(intersector) = args.choice("intersector")? {
        structure.intersector = intersector;
    }
    if let Some(traversal) = args.choice("traversal")? {
        structure.traversal = traversal;
    }
    structure.params().check().map_err(|e| request_error("the structure", e))?;
    request.tone.exposure = args.number("exposure", |v: f32| (-64.0..=64.0).contains(&v), "-64 to 64 stops")?;
    request.tone.operator = args.choice("tonemap")?;
    if let Some(denoise) = args.choice("denoise")? {
        request.denoise = denoise;
    }
    let samples: Option<(u32, u32)> = args.take("samples")?;
    if let Some((from, to)) = samples.filter(|(from, to)| from >= to) {
        return Err(request_error("samples", format!("({from}, {to}): expected (FROM, TO) with FROM < TO")));
    }
    let tile: Option<(u32, u32)> = args.take("tile")?;
    if let Some((index, count)) = tile.filter(|(index, count)| index >= count) {
        return Err(request_error("tile", format!("({index}, {count}): expected (INDEX, COUNT) with INDEX < COUNT")));
    }
    request.split = Split { samples: samples.map(|(from, to)| from..to), tile };
    request.checkpoints.time_limit = args.number("time_limit", positive_f64, "a positive number of seconds")?;
    request.checkpoints.checkpoint = args.take("checkpoint")?;
    if let Some(every) = args.number("checkpoint_every", positive_f64, "a positive number of seconds")? {
        request.checkpoints.every_seconds = every;
    }
    request.checkpoints.resume = args.take("resume")?;
    request.threads = args.number("threads", |v: u32| (1..=1024).contains(&v), "1 to 1024")?;
    Ok((request, writes))
}

/// An image as an H×W×3 float32 array (linear RGB, row 0 at the top).
fn image_array<'py>(py: Python<'py>, image: &HdrImage) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let values: Vec<f32> = image.pixels().iter().flat_map(|p| p.to_array()).collect();
    PyArray1::from_vec(py, values).reshape([image.height() as usize, image.width() as usize, 3])
}

/// The image (if a sample finished), the AOVs by name, the outcome as a dict.
type RenderResult<'py> = (Option<Bound<'py, PyArray3<f32>>>, Bound<'py, PyDict>, Bound<'py, PyAny>);

/// Reads an OpenEXR image (as `rtgi render -o x.exr` writes them): an
/// H×W×3 float32 array of linear RGB, row 0 at the top.
#[pyfunction]
pub fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let image = py.detach(|| HdrImage::read_exr(&path)).map_err(|e| request_error("path", e))?;
    image_array(py, &image)
}

/// Renders a scene as `rtgi render` does.
///
/// `scene` is a `rtgi.Scene`, a path, or `None` for the built-in Cornell
/// box. The keyword arguments are the fields of `rtgi_job::RenderRequest`
/// (see `rtgi.names("render")`), with `rtgi render`'s defaults. Without
/// `output` nothing is written and the image is made as for an EXR (not
/// denoised unless `denoise="on"`); with it, the files are written as
/// `rtgi render -o OUTPUT` writes them. Returns `(image, aovs, outcome)`:
/// the linear H×W×3 float32 image (`None` if no sample finished), a dict
/// of the AOVs asked for (name: H×W×3 array), and the outcome as a dict
/// (what `rtgi render --json` prints). Releases the GIL while rendering.
#[pyfunction]
#[pyo3(signature = (scene = None, **request))]
pub fn render<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    request: Option<&Bound<'py, PyDict>>,
) -> PyResult<RenderResult<'py>> {
    // A Scene object is rendered as given (`render_given`); a path or None as the request's.
    let (source, held): (SceneSource, Option<Arc<LoadedScene>>) = match scene {
        None => (SceneSource::BuiltIn, None),
        Some(scene) if scene.is_none() => (SceneSource::BuiltIn, None),
        Some(scene) if scene.is_instance_of::<PyString>() || scene.hasattr("__fspath__")? => {
            (SceneSource::file(scene.extract::<PathBuf>()?), None)
        }
        Some(scene) => {
            let scene =
                scene.cast::<Scene>().map_err(|_| request_error("scene", "expected a rtgi.Scene, a path or None"))?;
            (SceneSource::BuiltIn, Some(scene.get().loaded.clone()))
        }
    };
    let given = held.as_deref();
    let args = Arguments { kwargs: request.map_or_else(|| PyDict::new(py), |r| r.copy().expect("a dict copies")) };
    let (request, writes) = request_from(source, &args)?;
    args.finish()?;
    let built = match given {
        Some(loaded) => Some(Accel::build(py, &loaded.scene.triangle_positions(), &request.structure)?),
        None => None,
    };
    let rendered = py
        .detach(|| {
            let given = given.zip(built.as_ref()).map(|(scene, accel)| Given { scene, accel: accel.inner() });
            let cancel = CancelToken::new();
            match (given, writes) {
                (Some(given), true) => rtgi_job::render_given(&request, given, &Unobserved, &cancel),
                (None, true) => rtgi_job::render(&request, &Unobserved, &cancel),
                (given, false) => rtgi_job::render_in_memory(&request, given, &Unobserved, &cancel),
            }
        })
        .map_err(job_error)?;
    let image = rendered.image.as_ref().map(|(image, _)| image_array(py, image)).transpose()?;
    let aovs = PyDict::new(py);
    for (kind, image) in &rendered.aovs {
        aovs.set_item(kind.name(), image_array(py, image)?)?;
    }
    Ok((image, aovs, to_python(py, &rendered.outcome)?))
}
