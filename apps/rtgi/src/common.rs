//! Steps that several commands share.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use rtgi_accel::Accel;
use rtgi_render::{
    DEFAULT_VERTICAL_FOV_DEGREES, EnvironmentSpec, RenderSettings, camera_blocked, default_camera, frame_scene,
};
use rtgi_scene::{Camera, LoadOptions, Scene};

use crate::cli::{CameraArgs, LightingArgs};
use crate::default_scene;

pub(crate) struct LoadedScene {
    pub(crate) scene: Scene,
    /// The file's path, or the built-in scene's name.
    pub(crate) name: String,
    pub(crate) load_ms: f64,
}

/// `--allow-outside-scene`, set once by `main` for every command.
pub(crate) static ALLOW_OUTSIDE_SCENE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// Loads a scene file (or the built-in Cornell box) and prints its warnings.
/// References outside the scene's folder are refused unless `--allow-outside-scene`.
pub(crate) fn load_scene(path: Option<&Path>) -> Result<LoadedScene> {
    let start = Instant::now();
    let (scene, name) = match path {
        Some(path) => {
            let options = LoadOptions {
                allow_outside_folder: ALLOW_OUTSIDE_SCENE.get() == Some(&true),
                ..LoadOptions::default()
            };
            (Scene::load_with(path, &options)?, path.display().to_string())
        }
        None => (default_scene::load()?, default_scene::NAME.to_owned()),
    };
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    Ok(LoadedScene { scene, name, load_ms })
}

/// A pool of `threads` worker threads, or one per core.
pub(crate) fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = threads {
        pool = pool.num_threads(threads as usize);
    }
    pool.build().context("cannot start worker threads")
}

/// A name beside `path` for a temporary file of this process.
fn beside(path: &Path, suffix: &str) -> std::path::PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{suffix}", std::process::id()))
}

/// Writes `bytes` to `path` atomically ([`rtgi_image::write_atomically`]):
/// a failure never leaves a partial file or destroys an earlier one, and a
/// FIFO or device is written in place.
pub(crate) fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    rtgi_image::write_atomically(path, bytes).with_context(|| format!("{}: cannot write", path.display()))
}

/// Checks that `path` can be created, before long work whose result goes there.
pub(crate) fn check_output_folder(path: &Path) -> Result<()> {
    if path.is_dir() {
        bail!("{}: is a directory", path.display());
    }
    let probe = beside(path, "probe");
    std::fs::File::create(&probe).with_context(|| format!("{}: cannot write", path.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The scene's first camera, or an automatic framing, with any camera
/// options applied on top.
pub(crate) fn choose_camera(scene: &Scene, accel: &dyn Accel, options: &CameraArgs, aspect: f32) -> Result<Camera> {
    let chosen = match options.camera {
        Some(index) if index >= scene.cameras.len() => {
            bail!("--camera {index}: the scene has {} camera(s), numbered from 0", scene.cameras.len())
        }
        Some(index) => scene.cameras.get(index),
        None => scene.cameras.first(),
    };
    let fov = match options.fov {
        Some(degrees) if !(degrees > 0.0 && degrees < 180.0) => {
            bail!("--fov {degrees}: the field of view must be between 0 and 180 degrees")
        }
        Some(degrees) => degrees.to_radians(),
        None => chosen.map_or(DEFAULT_VERTICAL_FOV_DEGREES.to_radians(), |c| c.vertical_fov),
    };
    let automatic = chosen.is_none() && options.at.is_none();
    let mut camera = match chosen {
        Some(camera) => *camera,
        None if options.fov.is_none() => default_camera(scene, accel, aspect),
        None => frame_scene(scene, accel, fov, aspect),
    };
    camera.vertical_fov = fov;
    if let Some(up) = options.up {
        camera.up = up;
    }
    if let Some(at) = options.at {
        camera.position = at;
        if options.look.is_none() {
            camera.direction = scene.bounds().centroid() - at;
        }
    }
    if let Some(look) = options.look {
        camera.direction = look - camera.position;
    }
    if !camera.is_valid() {
        bail!("the camera is degenerate: it must look somewhere other than its own position, and not along --up");
    }
    // The automatic framing avoids such views itself; a camera from the file
    // or the options is kept, but said to be buried.
    if !automatic && let Some(fraction) = camera_blocked(scene, accel, &camera, aspect) {
        eprintln!(
            "warning: the camera seems to be inside geometry: {:.0}% of the rays through its view hit the back of a \
             surface or start against one; move it with --at (and --look)",
            100.0 * fraction
        );
    }
    Ok(camera)
}

/// Applies the lighting options: adds the `--light`s to the scene and sets
/// the integrator, depth, strategy, environment (reading its file) and
/// effect overrides of `settings`.
pub(crate) fn apply_lighting(args: &LightingArgs, scene: &mut Scene, settings: &mut RenderSettings) -> Result<()> {
    scene.lights.extend(args.lights.iter().cloned());
    settings.integrator = args.integrator;
    settings.max_depth = args.max_depth;
    settings.direct_strategy = args.direct_strategy;
    settings.indirect_clamp = args.clamp_indirect;
    settings.effects = args.effects.clone();
    settings.environment = args.environment.as_ref().map(EnvironmentSpec::load).transpose()?;
    Ok(())
}

/// Whether `a` and `b` name the same file, following links; a file that
/// does not exist yet is compared by its folder and name.
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    fn canonical(path: &Path) -> Option<std::path::PathBuf> {
        if let Ok(path) = path.canonicalize() {
            return Some(path);
        }
        let folder = match path.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent.canonicalize().ok()?,
            _ => std::env::current_dir().ok()?,
        };
        Some(folder.join(path.file_name()?))
    }
    match (canonical(a), canonical(b)) {
        (Some(a), Some(b)) => a == b,
        _ => a == b,
    }
}

/// Refuses to write over a file the command reads: an output named like
/// the scene, a texture, the environment map or the rays file would destroy it.
pub(crate) fn refuse_inputs_as_outputs(outputs: &[(&str, &Path)], inputs: &[(&str, &Path)]) -> Result<()> {
    for (option, output) in outputs {
        if let Some((what, _)) = inputs.iter().find(|(_, input)| same_file(output, input)) {
            bail!("{option} {}: is {what}, which the command reads; write to another file", output.display());
        }
    }
    Ok(())
}
