//! `rtgi.verify` (the exactness contract checked on a scene),
//! `rtgi.experiment` (a knob's measurement as Python objects) and
//! `rtgi.names` (the names every choice accepts, from the libraries' tables).

use std::sync::Arc;

use pyo3::prelude::*;
use rtgi_accel::verify::{self as verifier, VerifyReport, check_case};
use rtgi_accel::{AccelKind, Intersector, SahAxes, Traversal};
use rtgi_experiment::{KNOBS, Options, Subject};
use rtgi_image::ToneOperator;
use rtgi_job::{Denoise, LoadedScene, SceneSource, Structure};
use rtgi_math::NamedChoice;
use rtgi_render::recipe::{self, CameraChoice};
use rtgi_render::{BounceSampling, DirectStrategy, Integrator, PixelSampler};

use crate::errors::{job_error, request, request_error, scene_error, to_python};
use crate::render::RENDER_ARGUMENTS;
use crate::scene::Scene;

/// The scene an argument names: a `rtgi.Scene`, a path, or `None` for `default`.
fn scene_argument(
    py: Python<'_>,
    scene: Option<&Bound<'_, PyAny>>,
    default: SceneSource,
) -> PyResult<Option<Arc<LoadedScene>>> {
    let source = match scene {
        Some(scene) if !scene.is_none() => match scene.cast::<Scene>() {
            Ok(scene) => return Ok(Some(scene.get().loaded.clone())),
            Err(_) => SceneSource::file(
                scene
                    .extract::<std::path::PathBuf>()
                    .map_err(|_| request_error("scene", "expected a rtgi.Scene, a path or None"))?,
            ),
        },
        _ => default,
    };
    if source == SceneSource::BuiltIn && scene.is_none_or(|s| s.is_none()) {
        return Ok(None);
    }
    Ok(Some(Arc::new(py.detach(|| source.load()).map_err(scene_error)?)))
}

/// The names of the structures in `accel`: a name, a list of names, or "all".
fn structures(accel: &Bound<'_, PyAny>) -> PyResult<Vec<AccelKind>> {
    let names: Vec<String> = match accel.extract::<String>() {
        Ok(name) => vec![name],
        Err(_) => accel.extract().map_err(|_| request_error("accel", "expected a name, a list of names or \"all\""))?,
    };
    let mut kinds = Vec::new();
    for name in names {
        match name.as_str() {
            "all" => kinds.extend(AccelKind::ALL.iter().chain(AccelKind::PEERS)),
            name => kinds.push(name.parse().map_err(|e| request_error("accel", e))?),
        }
    }
    Ok(kinds)
}

/// Checks the exactness contract: every structure's answers against the
/// linear scan's, bit for bit, on rays of the kinds that expose inexact
/// structures (what `rtgi verify` does).
///
/// `scene` is a `rtgi.Scene`, a path, or `None` for the built-in
/// adversarial scenes. `accel` is "all", a name or a list of names;
/// `exhaustive` checks every leaf size, bin count and intersector as the
/// tests do. `rays` are shared among the ray kinds (and scenes). Returns
/// the report as a dict (`kinds`, `structures`, ...) with `failed`, true
/// when a structure held to the contract disagreed.
#[pyfunction]
#[pyo3(signature = (scene = None, *, rays = 100_000, accel = None, exhaustive = false, seed = 0, linear_budget = 2_000_000_000))]
pub fn verify<'py>(
    py: Python<'py>,
    scene: Option<&Bound<'py, PyAny>>,
    rays: usize,
    accel: Option<&Bound<'py, PyAny>>,
    exhaustive: bool,
    seed: u64,
    linear_budget: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let chosen = match accel {
        Some(accel) if !accel.is_none() => structures(accel)?,
        _ => AccelKind::ALL.iter().chain(AccelKind::PEERS).copied().collect(),
    };
    if rays == 0 {
        return Err(request_error("rays", "expected at least 1"));
    }
    let loaded = scene_argument(py, scene, SceneSource::BuiltIn)?;
    let report = py.detach(|| {
        let scene = loaded.as_ref().map(|loaded| (loaded.name.clone(), loaded.scene.triangle_positions()));
        let (name, cases) = verifier::cases(scene, rays, seed);
        let configurations = verifier::configurations(&chosen, exhaustive, |kind| kind.default_params());
        let intersectors = verifier::reference_intersectors(&configurations, Intersector::default());
        let mut report = VerifyReport::new(name, seed);
        for (case, per_kind) in &cases {
            let rays = case.rays(*per_kind, seed);
            let budget_rays = (linear_budget / case.triangles.len().max(1) as u64) as usize;
            check_case(&mut report, case, &rays, &configurations, &intersectors, budget_rays, &mut |_| {})?;
        }
        Ok::<_, rtgi_accel::BuildError>(report)
    });
    let report = report.map_err(request)?;
    let dict = to_python(py, &report)?;
    dict.set_item("failed", report.failed())?;
    Ok(dict)
}

/// Runs an experiment: the knob's measurement of time against error, as
/// `rtgi experiment KNOB` makes it, returned as Python objects (its JSON:
/// `knob`, `question`, `tables`, `series`, `findings`, provenance) instead
/// of files, so that a notebook can plot its own figures.
///
/// `knob` is one of `rtgi.names("knobs")`; `scene` a `rtgi.Scene`, a path
/// or `None` for the built-in Cornell box (knobs with scenes of their own
/// ignore it). `quick` runs the reduced version (seconds, small images);
/// `repeats` timed runs per measurement; `width` and `height` the renders'
/// size (32 quick, else 128). Releases the GIL.
#[pyfunction]
#[pyo3(signature = (knob, scene = None, *, quick = true, repeats = 5, width = None, height = None, accel = "bvh8", threads = None))]
#[allow(clippy::too_many_arguments)]
pub fn experiment<'py>(
    py: Python<'py>,
    knob: &str,
    scene: Option<&Bound<'py, PyAny>>,
    quick: bool,
    repeats: usize,
    width: Option<u32>,
    height: Option<u32>,
    accel: &str,
    threads: Option<u32>,
) -> PyResult<Bound<'py, PyAny>> {
    let Some(knob) = rtgi_experiment::knob(knob) else {
        let names: Vec<&str> = KNOBS.iter().map(|k| k.name()).collect();
        return Err(request_error("knob", format!("unknown knob '{knob}' (expected one of: {})", names.join(", "))));
    };
    if repeats == 0 {
        return Err(request_error("repeats", "expected at least 1"));
    }
    let base = Subject::base_settings(quick, width, height);
    for (argument, value) in [("width", base.width), ("height", base.height)] {
        if !(1..=rtgi_job::MAX_IMAGE_SIDE).contains(&value) {
            return Err(request_error(argument, format!("{value}: expected 1 to {}", rtgi_job::MAX_IMAGE_SIDE)));
        }
    }
    let structure = Structure::of(accel.parse().map_err(|e| request_error("accel", e))?);
    let loaded = match scene_argument(py, scene, SceneSource::BuiltIn)? {
        Some(loaded) => loaded,
        None => Arc::new(py.detach(|| SceneSource::BuiltIn.load()).map_err(scene_error)?),
    };
    let pool = rtgi_job::thread_pool(threads).map_err(job_error)?;
    let command = format!("rtgi.experiment({:?}, {:?}, quick={quick}, repeats={repeats})", knob.name(), loaded.name);
    let report = py.detach(|| {
        pool.install(|| {
            let mut scene = loaded.scene.clone();
            let mut settings = base;
            // As `rtgi experiment` prepares its subject: `rtgi render`'s lighting, structure and camera.
            recipe::apply_lighting(&rtgi_job::default_lighting(), &mut scene, &mut settings).map_err(request)?;
            let accel = structure.kind.try_build(&scene.triangle_positions(), &structure.params()).map_err(request)?;
            let prepared = recipe::prepare(&mut scene, accel.as_ref(), &mut settings, &CameraChoice::default())
                .map_err(request)?;
            let subject = Subject { name: loaded.name.clone(), scene, camera: prepared.camera.camera, accel, settings };
            let options = Options {
                repeats,
                quick,
                command,
                threads: rayon::current_num_threads(),
                cache: None,
                reference_spp: None,
            };
            rtgi_experiment::run(knob, &subject, &options, &|_| {}).map_err(request)
        })
    })?;
    to_python(py, &report)
}

fn names_of<T: NamedChoice>() -> Vec<String> {
    T::ALL.iter().map(|c| c.name().to_owned()).collect()
}

/// The names a choice accepts, from the libraries' own tables: `accel`,
/// `intersector`, `traversal`, `sah_axes`, `integrator`, `aovs`,
/// `sampler`, `bounce_sampling`, `direct_strategy`, `tonemap`, `denoise`,
/// `knobs`, or `render` (the keyword arguments of `rtgi.render`).
#[pyfunction]
pub fn names(what: &str) -> PyResult<Vec<String>> {
    Ok(match what {
        "accel" => AccelKind::ALL.iter().chain(AccelKind::PEERS).map(|k| k.name().to_owned()).collect(),
        "intersector" => names_of::<Intersector>(),
        "traversal" => names_of::<Traversal>(),
        "sah_axes" => names_of::<SahAxes>(),
        "integrator" => names_of::<Integrator>(),
        "aovs" => Integrator::ALL.iter().filter(|i| i.is_aov()).map(|i| i.name().to_owned()).collect(),
        "sampler" => names_of::<PixelSampler>(),
        "bounce_sampling" => names_of::<BounceSampling>(),
        "direct_strategy" => names_of::<DirectStrategy>(),
        "tonemap" => names_of::<ToneOperator>(),
        "denoise" => names_of::<Denoise>(),
        "knobs" => KNOBS.iter().map(|k| k.name().to_owned()).collect(),
        "render" => RENDER_ARGUMENTS.iter().map(|&a| a.to_owned()).collect(),
        other => {
            return Err(request_error(
                "what",
                format!(
                    "unknown '{other}' (expected one of: accel, intersector, traversal, sah_axes, integrator, aovs, \
                     sampler, bounce_sampling, direct_strategy, tonemap, denoise, knobs, render)"
                ),
            ));
        }
    })
}
