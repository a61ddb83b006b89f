//! [`RenderOutcome`]: what a render did, as data: the plan, the camera and
//! why it was chosen, the exposure, the times, the rays, the files written
//! and the warnings. It serialises to JSON (what `rtgi render --json`
//! prints), so scripts and tests read it by name instead of by phrase.

use rtgi_image::{Legibility, ToneMap};
use rtgi_render::EffectPlan;
use rtgi_render::recipe::{ChosenCamera, FileCameraChoice};
use serde::Serialize;

/// What one render did.
#[derive(Clone, Debug, Serialize)]
pub struct RenderOutcome {
    /// The scene's file, or the built-in scene's name.
    pub scene: SceneSummary,
    /// Which effects the render simulated, and why.
    pub plan: EffectPlan,
    /// The camera used, and how it was chosen.
    pub camera: CameraSummary,
    /// Where the lamp hangs that an enclosed, unlit view was given.
    pub room_light: Option<[f32; 3]>,
    /// The structure built.
    pub build: BuildSummary,
    /// The samples: size, count, rays and times.
    pub render: PassesSummary,
    /// Milliseconds the denoiser took, when the image was denoised.
    pub denoise_ms: Option<f64>,
    /// How the PNG was exposed and tone mapped (`None` for other outputs).
    pub exposure: Option<ExposureSummary>,
    /// The image looks almost black or almost white, as its warning says.
    pub legibility: Option<LegibilitySummary>,
    /// For a part of a split render: its rows and samples, each `[start, end)`.
    pub part: Option<PartSummary>,
    /// What stopped the render before its last sample (`None`: it completed).
    pub stopped_by: Option<String>,
    /// The files written, the image or accumulation first.
    pub outputs: Vec<OutputSummary>,
    /// What the render warns of, in the order it found them.
    pub warnings: Vec<Warning>,
}

/// Something a render warns of: it rendered, but the result may not be
/// what was meant. A front end phrases each with the options that help.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Warning {
    /// The loader passed over part of the scene file (its message).
    Scene {
        /// The loader's message.
        message: String,
    },
    /// A camera from the file or the request seems to be inside geometry:
    /// this fraction of its view's rays meet the back of a surface.
    CameraInsideGeometry {
        /// The fraction of the view's rays.
        fraction: f32,
    },
    /// The image came out almost black: this fraction of its pixels.
    AlmostBlack {
        /// The fraction of pixels.
        fraction: f32,
    },
    /// The image came out almost white: this fraction of its pixels.
    AlmostWhite {
        /// The fraction of pixels.
        fraction: f32,
    },
}

/// The scene rendered.
#[derive(Clone, Debug, Serialize)]
pub struct SceneSummary {
    /// The scene's file, or the built-in scene's name.
    pub name: String,
    /// Triangles.
    pub triangles: usize,
    /// Milliseconds the load took.
    pub load_ms: f64,
}

/// The camera used, and how it was chosen.
#[derive(Clone, Debug, Serialize)]
pub struct CameraSummary {
    /// `file` (one of the scene's cameras), `automatic` (the framing of the
    /// model) or `options` (placed by --at or --look).
    pub source: &'static str,
    /// The file camera's index, when one was used.
    pub index: Option<usize>,
    /// How many cameras the file has.
    pub file_cameras: usize,
    /// Why this camera among the file's, when none was named (as the note says).
    pub file_choice: Option<String>,
    /// Which automatic view, and why (as the note says).
    pub automatic_view: Option<String>,
    /// Position.
    pub position: [f32; 3],
    /// Direction.
    pub direction: [f32; 3],
    /// Up direction.
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub vertical_fov_degrees: f32,
    /// The scene's up axis (`+Y`, `+Z`, ...).
    pub up_axis: String,
    /// The share of the surface in the flat base that decided the up axis, when one did.
    pub up_axis_base_share: Option<f32>,
    /// The fraction of the view's rays that meet the back of a surface,
    /// when that suggests the camera is inside geometry.
    pub inside_geometry: Option<f32>,
}

impl CameraSummary {
    /// The summary of `chosen`, given which camera the options asked for
    /// and how many the file has.
    pub fn new(chosen: &ChosenCamera, asked_index: Option<usize>, placed: bool, file_cameras: usize) -> Self {
        let index = match chosen.file_choice {
            Some(FileCameraChoice::SeesMost { index, .. }) => Some(index),
            Some(FileCameraChoice::Automatic { .. }) => None,
            None if chosen.automatic_view.is_none() && file_cameras > 0 => Some(asked_index.unwrap_or(0)),
            None => None,
        };
        let source = if chosen.automatic_view.is_some() {
            "automatic"
        } else if placed || index.is_none() {
            "options"
        } else {
            "file"
        };
        let camera = &chosen.camera;
        CameraSummary {
            source,
            index: index.filter(|_| source == "file"),
            file_cameras,
            file_choice: chosen.file_choice.map(|c| c.to_string()),
            automatic_view: chosen.automatic_view.as_ref().map(ToString::to_string),
            position: camera.position.to_array(),
            direction: camera.direction.to_array(),
            up: camera.up.to_array(),
            vertical_fov_degrees: camera.vertical_fov.to_degrees(),
            up_axis: chosen.up.name(),
            up_axis_base_share: chosen.up.base_share,
            inside_geometry: chosen.blocked,
        }
    }
}

/// The acceleration structure built.
#[derive(Clone, Debug, Serialize)]
pub struct BuildSummary {
    /// The structure and its parameters.
    pub variant: String,
    /// Milliseconds.
    pub ms: f64,
}

/// The render's samples: the size, how many and how fast.
#[derive(Clone, Debug, Serialize)]
pub struct PassesSummary {
    /// Milliseconds.
    pub ms: f64,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel asked for (the most a pixel takes, when sampling adapts).
    pub samples_per_pixel: u32,
    /// Samples per pixel done: fewer when the render was stopped.
    pub samples_done: u32,
    /// The pixel sampler.
    pub sampler: String,
    /// Worker threads.
    pub threads: usize,
    /// Passes over the image (rounds, when sampling adapts).
    pub passes: u32,
    /// Rays traced.
    pub rays: u64,
    /// Millions of rays a second.
    pub mrays_per_second: f64,
    /// When sampling adapted: the fewest samples a pixel took and the mean.
    pub adaptive: Option<AdaptiveSummary>,
}

/// What adaptive sampling did.
#[derive(Clone, Debug, Serialize)]
pub struct AdaptiveSummary {
    /// The fewest samples a pixel took.
    pub fewest_samples: u32,
    /// The mean of the samples the pixels took.
    pub mean_samples: f64,
    /// The most samples a pixel took.
    pub samples_reached: u32,
    /// Pixel samples in all.
    pub total_samples: u64,
    /// Rounds of sampling.
    pub rounds: u32,
    /// Whether the time bound ended the rounds (else the noise target or the sample count did).
    pub stopped_by_time: bool,
}

/// How a PNG was exposed and tone mapped.
#[derive(Clone, Debug, Serialize)]
pub struct ExposureSummary {
    /// Stops of exposure applied before tone mapping.
    pub stops: f32,
    /// Whether the exposure was chosen from the image (no --exposure).
    pub automatic: bool,
    /// The tone map.
    pub tone_map: String,
}

impl ExposureSummary {
    /// The summary of `tone_map`; `automatic` when the exposure was chosen from the image.
    pub fn new(tone_map: &ToneMap, automatic: bool) -> Self {
        ExposureSummary { stops: tone_map.exposure, automatic, tone_map: tone_map.operator.to_string() }
    }
}

/// An image that came out almost black or almost white.
#[derive(Clone, Debug, Serialize)]
pub struct LegibilitySummary {
    /// `almost black` or `almost white`.
    pub looks: &'static str,
    /// The fraction of pixels that are so.
    pub fraction: f32,
}

impl LegibilitySummary {
    /// The summary of `legibility`.
    pub fn new(legibility: Legibility) -> Self {
        match legibility {
            Legibility::AlmostBlack(fraction) => LegibilitySummary { looks: "almost black", fraction },
            Legibility::AlmostWhite(fraction) => LegibilitySummary { looks: "almost white", fraction },
        }
    }
}

/// The share of a split render a job rendered.
#[derive(Clone, Debug, Serialize)]
pub struct PartSummary {
    /// Rows `[start, end)`.
    pub rows: [u32; 2],
    /// Samples of every pixel `[start, end)`.
    pub samples: [u32; 2],
}

/// A file a render wrote.
#[derive(Clone, Debug, Serialize)]
pub struct OutputSummary {
    /// The file.
    pub path: String,
    /// `image`, `accumulation`, `checkpoint` or the AOV's name.
    pub kind: String,
    /// Samples per pixel in the file.
    pub samples_per_pixel: u32,
}
