//! The way from options to a ready render, written once: the lighting
//! options applied to the scene and settings, the sampler's default, the
//! camera (a file's, the automatic framing, or one placed by options), the
//! lamp an enclosed, unlit camera gets, and the tone map of the image.
//!
//! `rtgi render`, `rtgi experiment` and the other commands that render or
//! frame a scene all go through here, so that an experiment measures what a
//! render renders (a test renders both and compares their bytes).

use rtgi_accel::Accel;
use rtgi_image::{HdrImage, ToneMap, ToneOperator, auto_exposure};
use rtgi_math::Vec3;
use rtgi_scene::{Camera, Light, Scene};

use crate::camera_choice::{ViewScore, best_file_camera, score_view, surface_points};
use crate::effects::{materials_in_use, reflects_surroundings};
use crate::up_axis::{UpAxis, detect_up};
use crate::view_lighting::{REFLECTED_SHARE, UNLIT_VIEW, view_light};
use crate::{
    AutomaticView, BounceSampling, DEFAULT_VERTICAL_FOV_DEGREES, DefaultLighting, DirectStrategy, ENCLOSED,
    EffectOverrides, EffectPlan, EnvironmentSpec, Integrator, PixelSampler, RenderSettings, camera_blocked,
    frame_scene_explained, room_light, sky_visibility,
};

/// Why a render cannot be prepared; the messages name the field of
/// [`CameraChoice`] or of the settings (a front end names its own option
/// for it: `rtgi render` says `--camera`, `--fov`, `--up`).
#[derive(Debug, thiserror::Error)]
pub enum RecipeError {
    /// A file camera beyond the file's cameras.
    #[error("camera {index}: the scene has {count} camera(s), numbered from 0")]
    CameraIndex {
        /// The index asked for.
        index: usize,
        /// The cameras the scene has.
        count: usize,
    },
    /// A field of view outside (0°, 180°).
    #[error("field of view {0}: it must be between 0 and 180 degrees")]
    FieldOfView(f32),
    /// A camera that looks at its own position or along its up vector.
    #[error(
        "the camera is degenerate: it must look somewhere other than its own position, and not along its up direction"
    )]
    DegenerateCamera,
    /// The environment map could not be read.
    #[error(transparent)]
    Environment(#[from] rtgi_image::ImageError),
}

/// Which camera: one of the file's, else the automatic framing, with any
/// of its parts overridden.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraChoice {
    /// The file's camera of this index (default: its first, if any).
    pub index: Option<usize>,
    /// The camera's position; it then looks at the scene's centre unless `look` is given.
    pub at: Option<Vec3>,
    /// The point it looks at.
    pub look: Option<Vec3>,
    /// Its up direction.
    pub up: Option<Vec3>,
    /// Its vertical field of view, in degrees.
    pub fov_degrees: Option<f32>,
}

/// Which of several file cameras was taken, and why, for the user to read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FileCameraChoice {
    /// The file's camera that sees most of the model.
    SeesMost {
        /// Its index among the file's cameras.
        index: usize,
        /// How many cameras the file has.
        count: usize,
        /// What it sees.
        score: ViewScore,
    },
    /// None of the file's cameras holds the whole model in its frame, and
    /// the automatic view sees more of it than the best of them.
    Automatic {
        /// How many cameras the file has.
        count: usize,
        /// The file camera that sees most.
        best: usize,
        /// What that camera sees.
        best_score: ViewScore,
        /// What the automatic view sees.
        automatic: ViewScore,
    },
}

impl std::fmt::Display for FileCameraChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let percent = |x: f32| (100.0 * x).round();
        match *self {
            FileCameraChoice::SeesMost { index, count, score } => write!(
                f,
                "camera {index} of the file's {count} (0 to {}), the one that sees most of the model ({}% of its \
                 surface in view); --camera N picks another",
                count - 1,
                percent(score.seen)
            ),
            FileCameraChoice::Automatic { count, best, best_score, automatic } => write!(
                f,
                "the automatic view: none of the file's {count} cameras holds the whole model, and the best, camera \
                 {best}, sees {}% of its surface against the automatic view's {}%; --camera N picks one",
                percent(best_score.seen),
                percent(automatic.seen)
            ),
        }
    }
}

/// A chosen camera, and whether it seems to be inside geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct ChosenCamera {
    /// The camera.
    pub camera: Camera,
    /// How the camera was picked among several in the file, when no index was given.
    pub file_choice: Option<FileCameraChoice>,
    /// For a camera from the file or the options: the fraction of its rays
    /// that meet the back of a surface or start against one, when that
    /// suggests it is inside geometry (the automatic framing avoids such views).
    pub blocked: Option<f32>,
    /// Which way is up in the scene (for the default sky and sun): the
    /// options' `up`, else for the automatic view the model's, judged by
    /// its base ([`crate::up_axis::detect_up`]), else +Y.
    pub up: UpAxis,
    /// Which automatic view was taken and why, where the camera is one
    /// (neither the file's nor placed by the options).
    pub automatic_view: Option<AutomaticView>,
}

/// The scene's camera as `choice` says, for images of `aspect` (width / height).
pub fn choose_camera(
    scene: &Scene,
    accel: &dyn Accel,
    choice: &CameraChoice,
    aspect: f32,
) -> Result<ChosenCamera, RecipeError> {
    let (mut file_choice, mut automatic_view) = (None, None);
    // The model's up, judged once and only where the automatic view may be used.
    let given_up = choice.up.and_then(|up| up.try_normalize()).map(|up| UpAxis { up, base_share: None });
    let model_up = std::cell::OnceCell::new();
    let model_up = || *model_up.get_or_init(|| given_up.unwrap_or_else(|| detect_up(scene)));
    let chosen = match choice.index {
        Some(index) if index >= scene.cameras.len() => {
            return Err(RecipeError::CameraIndex { index, count: scene.cameras.len() });
        }
        Some(index) => scene.cameras.get(index),
        // Several cameras: the one that sees most of the model, or the
        // automatic view when none frames it whole and that view sees more.
        None if scene.cameras.len() > 1 => {
            let count = scene.cameras.len();
            let points = surface_points(scene);
            let (best, score) = best_file_camera(scene, accel, aspect, &points).expect("the scene has cameras");
            let automatic = (!score.sees_it_whole()).then(|| {
                let view = frame_scene_explained(
                    scene,
                    accel,
                    DEFAULT_VERTICAL_FOV_DEGREES.to_radians(),
                    aspect,
                    model_up().up,
                );
                let seen = score_view(accel, &view.0, aspect, &points);
                (view, seen)
            });
            match automatic {
                Some((view, automatic)) if automatic.seen > score.seen => {
                    file_choice = Some(FileCameraChoice::Automatic { count, best, best_score: score, automatic });
                    automatic_view = Some(view);
                    None
                }
                _ => {
                    file_choice = Some(FileCameraChoice::SeesMost { index: best, count, score });
                    scene.cameras.get(best)
                }
            }
        }
        None => scene.cameras.first(),
    };
    let fov = match choice.fov_degrees {
        Some(degrees) if !(degrees > 0.0 && degrees < 180.0) => return Err(RecipeError::FieldOfView(degrees)),
        Some(degrees) => degrees.to_radians(),
        None => chosen.map_or(DEFAULT_VERTICAL_FOV_DEGREES.to_radians(), |c| c.vertical_fov),
    };
    let automatic = chosen.is_none() && choice.at.is_none();
    let (mut camera, view) = match chosen {
        Some(camera) => (*camera, None),
        // No camera in the file, or none worth taking: the automatic view
        // (already framed, at the default field of view, when it was
        // compared with the file's).
        None => {
            let framed =
                automatic_view.filter(|_| choice.fov_degrees.is_none()).map(|(camera, view)| (camera, Some(view)));
            framed.unwrap_or_else(|| {
                // A position given replaces everything the automatic view would
                // choose but its up (+Y): its probe rays would cost seconds
                // through a slow structure (the linear scan) for nothing.
                if choice.at.is_some() {
                    (Camera::framing(&scene.bounds(), fov, aspect), None)
                } else {
                    let (camera, view) = frame_scene_explained(scene, accel, fov, aspect, model_up().up);
                    (camera, Some(view))
                }
            })
        }
    };
    // The view is the automatic one unless the options aim it elsewhere.
    let automatic_view = view.filter(|_| choice.look.is_none());
    camera.vertical_fov = fov;
    if let Some(up) = choice.up {
        camera.up = up;
    }
    if let Some(at) = choice.at {
        camera.position = at;
        if choice.look.is_none() {
            camera.direction = scene.bounds().centroid() - at;
        }
    }
    if let Some(look) = choice.look {
        camera.direction = look - camera.position;
    }
    if !camera.is_valid() {
        return Err(RecipeError::DegenerateCamera);
    }
    let blocked = if automatic { None } else { camera_blocked(scene, accel, &camera, aspect) };
    let up = if chosen.is_none() { model_up() } else { given_up.unwrap_or(UpAxis::Y) };
    Ok(ChosenCamera { camera, file_choice, blocked, up, automatic_view })
}

/// The lighting options: lights added to the scene, the integrator and its
/// settings, the environment and effect overrides.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// Lights added to the scene's own.
    pub lights: Vec<Light>,
    /// The integrator.
    pub integrator: Integrator,
    /// The most bounces a path takes.
    pub max_depth: u32,
    /// The bounce from which Russian roulette may end paths.
    pub roulette_start: u32,
    /// Where bounce directions come from.
    pub bounce_sampling: BounceSampling,
    /// How direct light is sampled.
    pub direct_strategy: DirectStrategy,
    /// The indirect-light clamp, if any.
    pub indirect_clamp: Option<f32>,
    /// Path regularisation ([`RenderSettings::filter_glossy`]), if any; a
    /// threshold of 0 is none.
    pub filter_glossy: Option<crate::FilterGlossy>,
    /// The environment (a colour or a map's file), if any.
    pub environment: Option<EnvironmentSpec>,
    /// Multiplies the environment's radiance.
    pub environment_scale: f32,
    /// Effects forced on or off.
    pub effects: EffectOverrides,
    /// Never add the default sky and sun, nor the lamp of an enclosed camera.
    pub no_default_lighting: bool,
}

/// Adds `lighting`'s lights to `scene` and sets its options in `settings` (reading an environment map).
pub fn apply_lighting(
    lighting: &Lighting,
    scene: &mut Scene,
    settings: &mut RenderSettings,
) -> Result<(), RecipeError> {
    scene.lights.extend(lighting.lights.iter().cloned());
    settings.integrator = lighting.integrator;
    settings.max_depth = lighting.max_depth;
    settings.roulette_start = lighting.roulette_start;
    settings.bounce_sampling = lighting.bounce_sampling;
    settings.direct_strategy = lighting.direct_strategy;
    settings.indirect_clamp = lighting.indirect_clamp;
    // A threshold of 0 widens nothing: it is no regularisation.
    settings.filter_glossy = lighting.filter_glossy.filter(|filter| filter.threshold > 0.0);
    settings.effects = lighting.effects.clone();
    settings.environment = lighting
        .environment
        .as_ref()
        .map(|spec| {
            spec.load()
                .map(|e| if lighting.environment_scale == 1.0 { e } else { e.scaled(lighting.environment_scale) })
        })
        .transpose()?;
    if lighting.no_default_lighting {
        settings.default_lighting = DefaultLighting::Off;
    }
    Ok(())
}

/// The sampler a render uses unless told otherwise: the pixel's centre for
/// one sample (no noise), the stratified sampler for more.
pub fn default_sampler(samples_per_pixel: u32) -> PixelSampler {
    if samples_per_pixel == 1 { PixelSampler::Center } else { PixelSampler::Stratified }
}

/// For a camera that no sky can reach (a closed room) in a scene that
/// would get the default sky and sun, adds a point light over the room in
/// view ([`room_light`]) and returns it: otherwise the image would be black.
///
/// Enclosure is judged by the surfaces in view, not the camera alone: a
/// camera in a pocket of an open world (a hollow in a voxel terrain) sees
/// surfaces the sky reaches, and a cave lit by its own lava sees surfaces
/// its emitters light, however weak they are beside a sky; neither gets a lamp.
pub fn light_enclosed_camera(
    scene: &mut Scene,
    accel: &dyn Accel,
    camera: &Camera,
    settings: &RenderSettings,
) -> Option<Light> {
    if !EffectPlan::new(scene, settings).default_environment || sky_visibility(accel, camera.position) >= ENCLOSED {
        return None;
    }
    let aspect = settings.width as f32 / settings.height.max(1) as f32;
    if let Some(view) = view_light(scene, accel, camera, aspect, settings.up)
        && (view.sky >= OPEN_VIEW_IRRADIANCE || view.own >= OPEN_VIEW_IRRADIANCE)
    {
        return None;
    }
    let light = room_light(scene, accel, camera, settings.up);
    scene.lights.push(light.clone());
    Some(light)
}

/// The mean irradiance on the surfaces in view (from the default sky and
/// sun, or from the scene's own lights) from which a view counts as lit
/// without a lamp: a fiftieth of the π that the room lamp brings to the
/// point the camera looks at.
const OPEN_VIEW_IRRADIANCE: f32 = UNLIT_VIEW * std::f32::consts::PI;

/// For a scene whose own lights would get no default sky, probes the view
/// ([`view_light`]): when they leave it dark, marks the settings so that
/// the plan adds the default sky and sun and says why; when they light it
/// but are all punctual and glossy or metal surfaces are in use, which
/// would reflect black, adds a dim grey environment for them to reflect.
pub fn judge_view_lighting(
    scene: &Scene,
    accel: &dyn Accel,
    camera: &Camera,
    aspect: f32,
    settings: &mut RenderSettings,
) {
    if settings.default_lighting != DefaultLighting::Auto
        || settings.environment.is_some()
        || !settings.integrator.simulates_light()
        || EffectPlan::new(scene, settings).default_environment
    {
        return;
    }
    let Some(view) = view_light(scene, accel, camera, aspect, settings.up) else { return };
    if let Some(fraction) = view.own_fraction()
        && fraction < UNLIT_VIEW
    {
        settings.default_lighting = DefaultLighting::ViewUnlit(fraction);
        return;
    }
    let in_use = materials_in_use(scene);
    // Emission through a texture is glowing detail, not light (as the plan judges it).
    let emits = in_use.iter().any(|m| m.is_emissive() && m.emission_texture.is_none());
    let glossy = in_use.iter().any(|m| reflects_surroundings(m));
    if !scene.lights.is_empty() && !emits && glossy && view.own > 0.0 {
        let radiance = REFLECTED_SHARE * view.own / std::f32::consts::PI;
        settings.environment = Some(crate::Environment::Uniform(Vec3::splat(radiance)));
        settings.default_lighting = DefaultLighting::Reflections(radiance);
    }
}

/// A scene made ready to render: its camera, and the lamp added for an enclosed camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Prepared {
    /// The camera chosen.
    pub camera: ChosenCamera,
    /// The lamp hung over the room in view, if the camera was enclosed and unlit.
    pub room_light: Option<Light>,
}

/// Chooses the camera and adds the lamp an enclosed camera needs, as every
/// render does, once the scene is loaded, its lighting applied and its
/// structure built.
pub fn prepare(
    scene: &mut Scene,
    accel: &dyn Accel,
    settings: &mut RenderSettings,
    choice: &CameraChoice,
) -> Result<Prepared, RecipeError> {
    let aspect = settings.width as f32 / settings.height.max(1) as f32;
    let camera = choose_camera(scene, accel, choice, aspect)?;
    settings.up = camera.up.up;
    // A flat model seen straight on is lit from the view's upper right.
    if let Some(AutomaticView::Flat { from }) = camera.automatic_view {
        settings.sun_towards = Some(crate::flat_view_sun(from, camera.camera.up));
    }
    judge_view_lighting(scene, accel, &camera.camera, aspect, settings);
    let room_light = light_enclosed_camera(scene, accel, &camera.camera, settings);
    Ok(Prepared { camera, room_light })
}

/// The tone map of an image's PNG: as given, else for light transport a
/// filmic curve at an exposure chosen from the image ([`auto_exposure`]),
/// for other integrators (albedo, normals, ...) the values as they are.
pub fn tone_map(
    exposure: Option<f32>,
    operator: Option<ToneOperator>,
    simulates_light: bool,
    image: &HdrImage,
) -> ToneMap {
    let operator = operator.unwrap_or(if simulates_light { ToneOperator::Aces } else { ToneOperator::Clamp });
    let exposure = match exposure {
        Some(stops) => stops,
        None if simulates_light => auto_exposure(image),
        None => 0.0,
    };
    ToneMap { exposure, operator }
}
