//! Steps that several commands share: loading a scene with its warnings
//! printed, the worker threads, checks on the files a command writes, and
//! a scene made ready to trace as `rtgi render` makes it.

use std::path::Path;

use anyhow::{Context, Result, bail};
use rtgi_accel::Accel;
use rtgi_job::SceneSource;
use rtgi_render::RenderSettings;
use rtgi_render::recipe::{self, Prepared};
use rtgi_scene::Camera;

pub(crate) use rtgi_job::{LoadedScene, same_file};

use crate::options::{AccelArgs, CameraArgs, LightingArgs, load_options};
use crate::phrasing::{Phrasing, recipe_error, report_camera, warn};

/// Loads a scene file (or the built-in Cornell box) and prints its warnings.
/// References outside the scene's folder are refused unless `--allow-outside-scene`.
pub(crate) fn load_scene(path: Option<&Path>) -> Result<LoadedScene> {
    let source = match path {
        Some(path) => SceneSource::File { path: path.to_owned(), options: load_options() },
        None => SceneSource::BuiltIn,
    };
    let loaded = source.load()?;
    for message in &loaded.scene.warnings {
        warn(&rtgi_job::Warning::Scene { message: message.clone() }, Phrasing::Options, false);
    }
    Ok(loaded)
}

/// Sizes rayon's global pool to `threads` worker threads (one per core
/// when `None`); called once, before any parallel work.
pub(crate) fn size_global_pool(threads: Option<u32>) -> Result<()> {
    let builder = rayon::ThreadPoolBuilder::new();
    let builder = match threads {
        Some(threads) => builder.num_threads(threads as usize),
        None => builder,
    };
    builder.build_global().context("cannot start worker threads")
}

/// Writes `bytes` to `path` atomically ([`rtgi_image::write_atomically`]):
/// a failure never leaves a partial file or destroys an earlier one, and a
/// FIFO or device is written in place.
pub(crate) fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    rtgi_image::write_atomically(path, bytes).with_context(|| format!("{}: cannot write", path.display()))
}

/// Checks that `path` can be created, before long work whose result goes there.
pub(crate) fn check_output_folder(path: &Path) -> Result<()> {
    Ok(rtgi_job::check_output_folder(path, rtgi_job::Field::Output)?)
}

/// Refuses to write over a file the command reads: an output named like
/// the scene or the rays file would destroy it.
pub(crate) fn refuse_inputs_as_outputs(outputs: &[(&str, &Path)], inputs: &[(&str, &Path)]) -> Result<()> {
    for (option, output) in outputs {
        if let Some((what, _)) = inputs.iter().find(|(_, input)| same_file(output, input)) {
            bail!("{option} {}: is {what}, which the command reads; write to another file", output.display());
        }
    }
    Ok(())
}

/// The scene's first camera, or an automatic framing, with any camera
/// options applied on top ([`rtgi_render::recipe::choose_camera`]); warns
/// when a given camera seems buried.
pub(crate) fn choose_camera(
    scene: &rtgi_scene::Scene,
    accel: &dyn Accel,
    options: &CameraArgs,
    aspect: f32,
) -> Result<Camera> {
    let chosen = recipe::choose_camera(scene, accel, &options.choice(), aspect)
        .map_err(|e| recipe_error(e, Phrasing::Options))?;
    report_camera(&chosen, Phrasing::Options);
    if let Some(fraction) = chosen.blocked {
        warn(&rtgi_job::Warning::CameraInsideGeometry { fraction }, Phrasing::Options, false);
    }
    Ok(chosen.camera)
}

/// Applies the lighting options ([`rtgi_render::recipe::apply_lighting`]).
pub(crate) fn apply_lighting(
    args: &LightingArgs,
    scene: &mut rtgi_scene::Scene,
    settings: &mut RenderSettings,
) -> Result<()> {
    recipe::apply_lighting(&args.lighting(), scene, settings).map_err(|e| recipe_error(e, Phrasing::Options))
}

/// Everything from loaded options to a scene ready to render, as `rtgi
/// render` prepares it: lighting applied, structure built (in `pool`),
/// camera chosen and the lamp of an enclosed camera added. `settings` holds
/// the size, samples, sampler and seed; the lighting options are applied to it.
pub(crate) fn prepare_render(
    scene: &mut rtgi_scene::Scene,
    settings: &mut RenderSettings,
    lighting: &LightingArgs,
    camera: &CameraArgs,
    accel: &AccelArgs,
    pool: &rayon::ThreadPool,
) -> Result<(Box<dyn Accel>, Prepared)> {
    apply_lighting(lighting, scene, settings)?;
    let built = pool.install(|| accel.build(scene))?;
    let prepared = recipe::prepare(scene, built.as_ref(), settings, &camera.choice())
        .map_err(|e| recipe_error(e, Phrasing::Options))?;
    report_camera(&prepared.camera, Phrasing::Options);
    if let Some(fraction) = prepared.camera.blocked {
        warn(&rtgi_job::Warning::CameraInsideGeometry { fraction }, Phrasing::Options, false);
    }
    Ok((built, prepared))
}
