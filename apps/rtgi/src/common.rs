//! Steps that several commands share.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use rtgi_accel::Accel;
use rtgi_render::RenderSettings;
use rtgi_render::recipe::{self, CameraChoice, ChosenCamera, Lighting, Prepared};
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

/// `--variant`, set once by `main` for every command.
pub(crate) static GLTF_VARIANT: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();

/// Loads a scene file (or the built-in Cornell box) and prints its warnings.
/// References outside the scene's folder are refused unless `--allow-outside-scene`.
pub(crate) fn load_scene(path: Option<&Path>) -> Result<LoadedScene> {
    let start = Instant::now();
    let (scene, name) = match path {
        Some(path) => {
            let options = LoadOptions {
                allow_outside_folder: ALLOW_OUTSIDE_SCENE.get() == Some(&true),
                gltf_variant: GLTF_VARIANT.get().cloned().flatten(),
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

/// Sizes rayon's global pool to `threads` worker threads (one per core
/// when `None`); called once, before any parallel work.
pub(crate) fn size_global_pool(threads: Option<u32>) -> Result<()> {
    pool_builder(threads).build_global().context("cannot start worker threads")
}

/// A pool of `threads` worker threads, or one per core.
pub(crate) fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool> {
    pool_builder(threads).build().context("cannot start worker threads")
}

/// A builder of `threads` worker threads; rayon's default (one per core) when `None`.
fn pool_builder(threads: Option<u32>) -> rayon::ThreadPoolBuilder {
    let builder = rayon::ThreadPoolBuilder::new();
    match threads {
        Some(threads) => builder.num_threads(threads as usize),
        None => builder,
    }
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
    if let Some(why) = rtgi_image::unusable_folder(path) {
        bail!("{}: cannot write: {why}", path.display());
    }
    let probe = beside(path, "probe");
    std::fs::File::create(&probe).with_context(|| format!("{}: cannot write", path.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

impl CameraArgs {
    /// The camera options as the recipe takes them.
    pub(crate) fn choice(&self) -> CameraChoice {
        CameraChoice { index: self.camera, at: self.at, look: self.look, up: self.up, fov_degrees: self.fov }
    }
}

impl LightingArgs {
    /// The lighting options as the recipe takes them.
    pub(crate) fn lighting(&self) -> Lighting {
        Lighting {
            lights: self.lights.clone(),
            integrator: self.integrator,
            max_depth: self.max_depth,
            roulette_start: self.roulette_start,
            bounce_sampling: self.bounce_sampling,
            direct_strategy: self.direct_strategy,
            indirect_clamp: self.clamp_indirect,
            filter_glossy: self.filter_glossy.filter(|&v| v > 0.0).map(rtgi_render::FilterGlossy::all_lobes),
            environment: self.environment.clone(),
            environment_scale: self.environment_scale,
            effects: self.effects.clone(),
            no_default_lighting: self.no_default_lighting,
        }
    }
}

/// Whose words the hints of warnings use: the command line's options, or
/// the commands of a script in the course framework's language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phrasing {
    Options,
    Script,
}

impl Phrasing {
    /// How to move the camera.
    pub(crate) fn move_camera(self) -> &'static str {
        match self {
            Phrasing::Options => "--at (and --look)",
            Phrasing::Script => "at (and look)",
        }
    }

    /// How to keep +Y up.
    pub(crate) fn up_y(self) -> &'static str {
        match self {
            Phrasing::Options => "--up 0,1,0",
            Phrasing::Script => "the camera's up (0 1 0)",
        }
    }

    /// How to add light.
    pub(crate) fn add_light(self) -> &'static str {
        match self {
            Phrasing::Options => "--environment 1,1,1 or --light",
            Phrasing::Script => "pointlight or skylight load",
        }
    }
}

/// A render that cannot be prepared, in the words of the command line:
/// the library names its fields, the app its options.
pub(crate) fn recipe_error(error: recipe::RecipeError, phrasing: Phrasing) -> anyhow::Error {
    use recipe::RecipeError;
    if phrasing == Phrasing::Script {
        return error.into();
    }
    match error {
        RecipeError::CameraIndex { index, count } => {
            anyhow::anyhow!("--camera {index}: the scene has {count} camera(s), numbered from 0")
        }
        RecipeError::FieldOfView(fov) => {
            anyhow::anyhow!("--fov {fov}: the field of view must be between 0 and 180 degrees")
        }
        RecipeError::DegenerateCamera => anyhow::anyhow!(
            "the camera is degenerate: it must look somewhere other than its own position (--at, --look), and not \
             along --up"
        ),
        other => other.into(),
    }
}

/// Says which of several file cameras was used, and warns that a camera
/// from the file or the options seems to be inside geometry.
pub(crate) fn report_camera(chosen: &ChosenCamera, phrasing: Phrasing) {
    if let Some(choice) = &chosen.file_choice {
        eprintln!("note: the view is {choice}");
    }
    if let Some(view) = &chosen.automatic_view {
        eprintln!("note: the automatic view is {view}; {} choose another", phrasing.move_camera());
    }
    if let Some(share) = chosen.up.base_share {
        eprintln!(
            "note: {} is up: the model stands on a flat base facing {} ({:.1}% of its surface) and has none across \
             Y, so the view, the default sky and the sun turn with it; {} keeps +Y",
            chosen.up.name(),
            rtgi_render::up_axis::axis_name(-chosen.up.up),
            100.0 * share,
            phrasing.up_y()
        );
    }
    if let Some(fraction) = chosen.blocked {
        eprintln!(
            "warning: the camera seems to be inside geometry: {:.0}% of the rays through its view hit the back of a \
             surface or start against one; move it with {}",
            100.0 * fraction,
            phrasing.move_camera()
        );
    }
}

/// The scene's first camera, or an automatic framing, with any camera
/// options applied on top ([`rtgi_render::recipe::choose_camera`]); warns
/// when a given camera seems buried.
pub(crate) fn choose_camera(scene: &Scene, accel: &dyn Accel, options: &CameraArgs, aspect: f32) -> Result<Camera> {
    let chosen = recipe::choose_camera(scene, accel, &options.choice(), aspect)
        .map_err(|e| recipe_error(e, Phrasing::Options))?;
    report_camera(&chosen, Phrasing::Options);
    Ok(chosen.camera)
}

/// Applies the lighting options ([`rtgi_render::recipe::apply_lighting`]).
pub(crate) fn apply_lighting(args: &LightingArgs, scene: &mut Scene, settings: &mut RenderSettings) -> Result<()> {
    recipe::apply_lighting(&args.lighting(), scene, settings).map_err(|e| recipe_error(e, Phrasing::Options))
}

/// The structure a render traces: built for it, or built before by a
/// script's `commit` over the same triangles.
pub(crate) enum Structure<'a> {
    Built(Box<dyn Accel>),
    Committed(&'a dyn Accel),
}

impl<'a> AsRef<dyn Accel + 'a> for Structure<'a> {
    fn as_ref(&self) -> &(dyn Accel + 'a) {
        match self {
            Structure::Built(built) => built.as_ref(),
            Structure::Committed(committed) => *committed,
        }
    }
}

/// Everything from loaded options to a scene ready to render, as `rtgi
/// render` prepares it: lighting applied, structure built (in `pool`),
/// camera chosen and the lamp of an enclosed camera added. `settings` holds
/// the size, samples, sampler and seed; the lighting options are applied to it.
pub(crate) fn prepare_render(
    scene: &mut Scene,
    settings: &mut RenderSettings,
    lighting: &LightingArgs,
    camera: &CameraArgs,
    accel: &crate::cli::AccelArgs,
    pool: &rayon::ThreadPool,
) -> Result<(Box<dyn Accel>, Prepared)> {
    apply_lighting(lighting, scene, settings)?;
    let built = pool.install(|| accel.build(scene))?;
    let prepared = prepare_view(scene, built.as_ref(), settings, camera, Phrasing::Options)?;
    Ok((built, prepared))
}

/// The camera chosen and the lamp of an enclosed camera added, once the
/// lighting options are applied and the structure is built.
pub(crate) fn prepare_view(
    scene: &mut Scene,
    accel: &dyn Accel,
    settings: &mut RenderSettings,
    camera: &CameraArgs,
    phrasing: Phrasing,
) -> Result<Prepared> {
    let prepared = recipe::prepare(scene, accel, settings, &camera.choice()).map_err(|e| recipe_error(e, phrasing))?;
    report_camera(&prepared.camera, phrasing);
    Ok(prepared)
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
