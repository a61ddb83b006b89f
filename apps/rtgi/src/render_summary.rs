//! What `rtgi render --json` prints: the render's summary as data, the same
//! facts as its lines of prose (the plan, the camera and why it was chosen,
//! the exposure, the times and the files written), for scripts and tests
//! to read by name instead of by phrase.

use rtgi_image::{Legibility, ToneMap};
use rtgi_render::EffectPlan;
use rtgi_render::recipe::{ChosenCamera, FileCameraChoice};
use serde::Serialize;

/// The whole summary of one `rtgi render`.
#[derive(Debug, Serialize)]
pub(crate) struct RenderSummary {
    pub(crate) scene: SceneSummary,
    /// Which effects the render simulated, and why.
    pub(crate) plan: EffectPlan,
    pub(crate) camera: CameraSummary,
    /// Where the lamp hangs that an enclosed, unlit view was given.
    pub(crate) room_light: Option<[f32; 3]>,
    pub(crate) build: BuildSummary,
    pub(crate) render: PassesSummary,
    /// Milliseconds the denoiser took, when the image was denoised.
    pub(crate) denoise_ms: Option<f64>,
    /// How the PNG was exposed and tone mapped (`None` for other outputs).
    pub(crate) exposure: Option<ExposureSummary>,
    /// The image looks almost black or almost white, as its warning says.
    pub(crate) legibility: Option<LegibilitySummary>,
    /// For a part of a split render: its rows and samples, each `[start, end)`.
    pub(crate) part: Option<PartSummary>,
    /// What stopped the render before its last sample (`None`: it completed).
    pub(crate) stopped_by: Option<String>,
    /// The files written, the image or accumulation first.
    pub(crate) outputs: Vec<OutputSummary>,
}

#[derive(Debug, Serialize)]
pub(crate) struct SceneSummary {
    /// The scene's file, or the built-in scene's name.
    pub(crate) name: String,
    pub(crate) triangles: usize,
    pub(crate) load_ms: f64,
}

/// The camera used, and how it was chosen.
#[derive(Debug, Serialize)]
pub(crate) struct CameraSummary {
    /// `file` (one of the scene's cameras), `automatic` (the framing of the
    /// model) or `options` (placed by --at or --look).
    pub(crate) source: &'static str,
    /// The file camera's index, when one was used.
    pub(crate) index: Option<usize>,
    /// How many cameras the file has.
    pub(crate) file_cameras: usize,
    /// Why this camera among the file's, when none was named (as the note says).
    pub(crate) file_choice: Option<String>,
    /// Which automatic view, and why (as the note says).
    pub(crate) automatic_view: Option<String>,
    pub(crate) position: [f32; 3],
    pub(crate) direction: [f32; 3],
    pub(crate) up: [f32; 3],
    pub(crate) vertical_fov_degrees: f32,
    /// The scene's up axis (`+Y`, `+Z`, ...).
    pub(crate) up_axis: String,
    /// The share of the surface in the flat base that decided the up axis, when one did.
    pub(crate) up_axis_base_share: Option<f32>,
    /// The fraction of the view's rays that meet the back of a surface,
    /// when that suggests the camera is inside geometry.
    pub(crate) inside_geometry: Option<f32>,
}

impl CameraSummary {
    /// The summary of `chosen`, given which camera the options asked for
    /// and how many the file has.
    pub(crate) fn new(chosen: &ChosenCamera, asked_index: Option<usize>, placed: bool, file_cameras: usize) -> Self {
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

#[derive(Debug, Serialize)]
pub(crate) struct BuildSummary {
    /// The structure and its parameters.
    pub(crate) variant: String,
    pub(crate) ms: f64,
}

/// The render's samples: the size, how many and how fast.
#[derive(Debug, Serialize)]
pub(crate) struct PassesSummary {
    pub(crate) ms: f64,
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// Samples per pixel asked for (the most a pixel takes, when sampling adapts).
    pub(crate) samples_per_pixel: u32,
    /// Samples per pixel done: fewer when the render was stopped.
    pub(crate) samples_done: u32,
    pub(crate) sampler: String,
    pub(crate) threads: usize,
    /// Passes over the image (rounds, when sampling adapts).
    pub(crate) passes: u32,
    pub(crate) rays: u64,
    pub(crate) mrays_per_second: f64,
    /// When sampling adapted: the fewest samples a pixel took and the mean.
    pub(crate) adaptive: Option<AdaptiveSummary>,
}

#[derive(Debug, Serialize)]
pub(crate) struct AdaptiveSummary {
    pub(crate) fewest_samples: u32,
    pub(crate) mean_samples: f64,
}

#[derive(Debug, Serialize)]
pub(crate) struct ExposureSummary {
    /// Stops of exposure applied before tone mapping.
    pub(crate) stops: f32,
    /// Whether the exposure was chosen from the image (no --exposure).
    pub(crate) automatic: bool,
    pub(crate) tone_map: String,
}

impl ExposureSummary {
    pub(crate) fn new(tone_map: &ToneMap, automatic: bool) -> Self {
        ExposureSummary { stops: tone_map.exposure, automatic, tone_map: tone_map.operator.to_string() }
    }
}

#[derive(Debug, Serialize)]
pub(crate) struct LegibilitySummary {
    /// `almost black` or `almost white`.
    pub(crate) looks: &'static str,
    /// The fraction of pixels that are so.
    pub(crate) fraction: f32,
}

impl LegibilitySummary {
    pub(crate) fn new(legibility: Legibility) -> Self {
        match legibility {
            Legibility::AlmostBlack(fraction) => LegibilitySummary { looks: "almost black", fraction },
            Legibility::AlmostWhite(fraction) => LegibilitySummary { looks: "almost white", fraction },
        }
    }
}

#[derive(Debug, Serialize)]
pub(crate) struct PartSummary {
    pub(crate) rows: [u32; 2],
    pub(crate) samples: [u32; 2],
}

#[derive(Debug, Serialize)]
pub(crate) struct OutputSummary {
    pub(crate) path: String,
    /// `image`, `accumulation`, `checkpoint` or the AOV's name.
    pub(crate) kind: String,
    /// Samples per pixel in the file.
    pub(crate) samples_per_pixel: u32,
}
