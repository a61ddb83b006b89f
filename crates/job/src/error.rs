//! Why a render cannot be done. Messages name the fields of
//! [`crate::RenderRequest`] ([`Field`]); a front end that has options for
//! them phrases the errors in its own words (`rtgi render` names its
//! flags), matching on the variants.

use std::fmt;
use std::ops::Range;
use std::path::PathBuf;

use rtgi_render::Integrator;

/// A field of [`crate::RenderRequest`] that an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// [`crate::RenderRequest::output`].
    Output,
    /// [`crate::RenderRequest::aovs`].
    Aovs,
    /// [`crate::Checkpoints::checkpoint`].
    Checkpoint,
    /// [`crate::Checkpoints::resume`].
    Resume,
    /// [`crate::Checkpoints::time_limit`].
    TimeLimit,
    /// [`crate::Split::samples`].
    Samples,
    /// [`crate::Split::tile`].
    Tile,
    /// The environment map of [`rtgi_render::recipe::Lighting::environment`].
    Environment,
}

impl Field {
    /// The field's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Field::Output => "the output",
            Field::Aovs => "an AOV",
            Field::Checkpoint => "the checkpoint",
            Field::Resume => "the file resumed",
            Field::TimeLimit => "a time limit",
            Field::Samples => "a range of samples",
            Field::Tile => "a tile",
            Field::Environment => "the environment map",
        }
    }
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a render cannot be done, or could not be finished.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The scene could not be loaded.
    #[error(transparent)]
    Scene(#[from] rtgi_scene::SceneError),
    /// The structure could not be built.
    #[error(transparent)]
    Build(#[from] rtgi_accel::BuildError),
    /// The camera or the lighting could not be prepared.
    #[error(transparent)]
    Recipe(#[from] rtgi_render::recipe::RecipeError),
    /// An image could not be written.
    #[error(transparent)]
    Image(#[from] rtgi_image::ImageError),
    /// An accumulation could not be read or written.
    #[error(transparent)]
    Accumulation(#[from] rtgi_render::AccumulationFileError),
    /// The adaptive sampling asked for is not possible.
    #[error(transparent)]
    Adaptive(#[from] rtgi_render::adaptive::AdaptiveError),
    /// The denoiser refused its inputs.
    #[error(transparent)]
    Denoise(#[from] rtgi_render::DenoiseError),
    /// The worker threads could not be started.
    #[error("cannot start worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
    /// The output is neither an image nor an accumulation.
    #[error("{path}: the output is an image (.png, .exr) or a render's accumulation (.accum)")]
    OutputFormat {
        /// The output asked for.
        path: PathBuf,
    },
    /// A file cannot be written where it is asked for.
    #[error("{path}: cannot write: {why}")]
    Unwritable {
        /// Which field names the file.
        field: Field,
        /// The file.
        path: PathBuf,
        /// Why not.
        why: String,
    },
    /// A part of a split render must be written as an accumulation.
    #[error("a range of samples or a tile is a part of an image: write it to an .accum file and merge the parts")]
    PartNotAccumulated,
    /// Denoising asked for an accumulation, which keeps sums.
    #[error("denoising {output}: it keeps the samples' sums, which a filter cannot apply to; denoise an image instead")]
    DenoiseAccumulation {
        /// The output.
        output: PathBuf,
    },
    /// Denoising asked for an integrator whose image is not noisy light.
    #[error("denoising is for the direct and path integrators: the {0} integrator's image is not noisy light")]
    DenoiseNotLight(Integrator),
    /// AOVs asked for a part of a split render.
    #[error("AOVs are for whole renders, not for a range of samples or a tile")]
    AovOfPart,
    /// An AOV that is not an output variable.
    #[error("AOV {aov}: not an output variable (use one of {allowed})")]
    NotAnAov {
        /// The integrator asked for.
        aov: Integrator,
        /// The output variables, separated by commas.
        allowed: String,
    },
    /// An output is a file the render reads.
    #[error("{path}: is {what}, which the render reads; write to another file")]
    InputAsOutput {
        /// Which output.
        field: Field,
        /// The file.
        path: PathBuf,
        /// Which input it is.
        what: String,
    },
    /// The image would not fit in memory.
    #[error(
        "an image of {width}x{height} needs about {needed_gib:.1} GiB of memory and {available_gib:.1} GiB are \
         available; render a smaller image, or split it into tiles and merge them"
    )]
    Memory {
        /// The width asked for.
        width: u32,
        /// The height asked for.
        height: u32,
        /// What the render needs.
        needed_gib: f64,
        /// What is available.
        available_gib: f64,
    },
    /// Adaptive sampling with something that splits or suspends the render.
    #[error(
        "adaptive sampling samples each pixel until its own samples say it is done, so the render cannot be split, \
         checkpointed or resumed: {0} cannot go with it"
    )]
    AdaptiveSplit(Field),
    /// More bands than the image has rows.
    #[error("tile {index}/{count}: the image has only {height} rows")]
    TileTooFine {
        /// The band asked for.
        index: u32,
        /// Bands in all.
        count: u32,
        /// The image's rows.
        height: u32,
    },
    /// Samples beyond the render's count.
    #[error("samples {}..{}: the render has {spp} samples per pixel", range.start, range.end)]
    SamplesBeyond {
        /// The range asked for.
        range: Range<u32>,
        /// Samples per pixel of the whole render.
        spp: u32,
    },
    /// The file resumed is of another render.
    #[error(
        "{path}: the file resumed is of another render ({}); resume it with the scene and options it was started \
         with", differences.join("; ")
    )]
    ResumeOfAnotherRender {
        /// The file.
        path: PathBuf,
        /// What differs: `what: ours now, theirs in the file`.
        differences: Vec<String>,
    },
    /// The file resumed holds another share of the render.
    #[error(
        "{path}: the file resumed holds rows {theirs_rows:?} and samples {theirs_samples:?}, this job renders rows \
         {rows:?} and samples {samples:?}"
    )]
    ResumeOfAnotherShare {
        /// The file.
        path: PathBuf,
        /// Its rows.
        theirs_rows: Range<u32>,
        /// Its samples.
        theirs_samples: Range<u32>,
        /// This job's rows.
        rows: Range<u32>,
        /// This job's samples.
        samples: Range<u32>,
    },
    /// A render in memory ([`crate::render_in_memory`]) asked for a field
    /// that names a file or makes a part of an image for a merge.
    #[error("{0} is for renders written to files; a render in memory writes none")]
    InMemory(Field),
    /// The time limit came before the first sample.
    #[error("no sample finished within the time limit")]
    NoSampleInTime,
}

impl JobError {
    /// Whether the error is a file resumed that belongs to another render
    /// (or another share of it): running again will not cure it.
    pub fn is_resume_of_another_render(&self) -> bool {
        matches!(self, JobError::ResumeOfAnotherRender { .. } | JobError::ResumeOfAnotherShare { .. })
    }
}
