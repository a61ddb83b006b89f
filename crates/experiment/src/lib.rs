//! What accuracy costs in time: each knob of the renderer and of the
//! acceleration structures, measured as time against error.
//!
//! An experiment takes a [`Subject`] (a scene, a camera, a structure and
//! base render settings, prepared by the caller) and [`Options`], varies one
//! [`Knob`] (each a file of its own, all listed in [`KNOBS`]), and returns a [`Report`]: every measurement, the machine, the
//! command, tables, findings (fitted slopes...) and plots, which
//! [`Report::write`] turns into `KNOB.md`, `KNOB.json` and SVG files.
//!
//! What makes the numbers trustworthy:
//! - errors are RMSE and relative MSE of linear radiance over the image,
//!   against a converged reference rendered with seeds of its own and
//!   cached on disk ([`mod@reference`]), whose own noise is
//!   reported beside;
//! - every time is the median of [`Options::repeats`] runs with min and max;
//! - each repeat of a measured render uses another seed, and its error is
//!   averaged as mean squared error.

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

use std::path::PathBuf;

use rtgi_accel::Accel;
use rtgi_render::RenderSettings;
use rtgi_scene::{Camera, Scene};

pub mod analytic;
pub mod bench;
pub mod bench_effects;
pub mod exact;
pub mod format;
mod index;
mod knobs;
pub mod machine;
pub mod measure;
pub mod panel;
pub mod pareto;
pub mod plan;
pub mod plot;
pub mod provenance;
pub mod reference;
pub mod report;
mod runner;
pub mod stats;
pub mod verdict;

pub use index::{IndexedReport, RUN_RECORD, RunRecord, index_markdown, read_reports, write_index};
pub use knobs::{KNOBS, Knob, Scenes, knob};
pub use machine::Machine;
pub use report::{Point, Report, Series, Table};

/// What an experiment renders: the caller loads the scene, chooses the
/// camera and builds the structure, as it would for a render.
pub struct Subject {
    /// The scene's file, or the built-in scene's name.
    pub name: String,
    /// The scene, with any lights the caller added.
    pub scene: Scene,
    /// The camera every render of the experiment uses.
    pub camera: Camera,
    /// The structure renders use, unless the knob varies it.
    pub accel: Box<dyn Accel>,
    /// Everything the knob does not vary: size, integrator, depth, lighting...
    pub settings: RenderSettings,
}

impl std::fmt::Debug for Subject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Subject").field("name", &self.name).field("settings", &self.settings).finish_non_exhaustive()
    }
}

#[derive(Clone, Debug)]
/// How an experiment is run: repeats, size, threads, where references are cached.
pub struct Options {
    /// Timed runs per measurement (renders: each with its own seed).
    pub repeats: usize,
    /// A reduced version that runs in seconds, for tests.
    pub quick: bool,
    /// The command line, recorded in the report.
    pub command: String,
    /// Worker threads (the caller runs the experiment in a pool of this size).
    pub threads: usize,
    /// Where references are cached; `None` renders them every time.
    pub cache: Option<PathBuf>,
    /// Samples per pixel of the references [default: 4096; 256 quick].
    pub reference_spp: Option<u32>,
}

impl Options {
    pub(crate) fn reference_spp(&self) -> u32 {
        self.reference_spp.unwrap_or(if self.quick { 256 } else { 4096 })
    }
}

#[derive(Debug, thiserror::Error)]
/// Why an experiment could not run or write its report.
pub enum ExperimentError {
    /// A report, plot or cached reference could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// An image (a reference in the cache) could not be written or read.
    #[error("{path}: {message}")]
    Image {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A plot could not be drawn.
    #[error("plot {file}: {message}")]
    Plot {
        /// The plot's file name.
        file: String,
        /// The plotting library's message.
        message: String,
    },
    /// A report or record could not be read back.
    #[error("{path}: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What was wrong with it.
        message: String,
    },
    /// An index was asked to put together reports of different code.
    #[error(
        "the reports were measured by different code, so their figures cannot stand in one index (rerun them \
         all from one commit): {0}"
    )]
    MixedVersions(String),
    /// An acceleration structure the knob needs could not be built.
    #[error("cannot build the structure: {0}")]
    Build(String),
    /// The knob cannot be measured on this subject; the message says why.
    #[error("{0}")]
    Unsuitable(String),
}

/// Samples per pixel of a subject's base settings: those of a default
/// `rtgi render` of a light-transport integrator, which decide the sampler
/// (knobs that vary the samples keep it).
pub const BASE_SAMPLES: u32 = 16;

impl Subject {
    /// The render settings of a subject before its lighting and camera are
    /// applied: `width` × `height` (32 × 32 when `quick`, else 128 × 128,
    /// where not given), [`BASE_SAMPLES`] and their default sampler. Every
    /// front end (`rtgi experiment`, the Python package) starts from these.
    pub fn base_settings(quick: bool, width: Option<u32>, height: Option<u32>) -> RenderSettings {
        let side = if quick { 32 } else { 128 };
        RenderSettings {
            width: width.unwrap_or(side),
            height: height.unwrap_or(side),
            samples_per_pixel: BASE_SAMPLES,
            sampler: rtgi_render::recipe::default_sampler(BASE_SAMPLES),
            ..RenderSettings::default()
        }
    }
}

/// Runs `knob` on `subject`; `progress` receives a line per step, with the
/// time spent and an estimate of the time left.
pub fn run(
    knob: &dyn Knob,
    subject: &Subject,
    options: &Options,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    knobs::run(knob, subject, options, progress)
}

/// Renders `subject` with `settings` on its structure, as every experiment's
/// measured render does: the image `rtgi render` makes of the same options.
pub fn render(subject: &Subject, settings: &RenderSettings) -> rtgi_image::HdrImage {
    runner::render(subject, settings)
}

/// Counts the steps of an experiment and estimates the time left from the
/// mean time of the steps done.
pub(crate) struct Steps<'a> {
    total: usize,
    done: usize,
    start: std::time::Instant,
    progress: &'a dyn Fn(&str),
}

impl<'a> Steps<'a> {
    pub(crate) fn new(total: usize, progress: &'a dyn Fn(&str)) -> Self {
        Steps { total, done: 0, start: std::time::Instant::now(), progress }
    }

    /// Announces the next step.
    pub(crate) fn next(&mut self, what: &str) {
        let elapsed = self.start.elapsed().as_secs_f64();
        let left = if self.done > 0 {
            format!(", about {:.0} s left", elapsed / self.done as f64 * (self.total - self.done) as f64)
        } else {
            String::new()
        };
        (self.progress)(&format!("[{}/{}] {what} ({elapsed:.0} s{left})", self.done + 1, self.total));
        self.done += 1;
    }
}
