//! A render as a typed request: what `rtgi render` does, once, for every
//! front end (the command line, the course's script language, the
//! gallery, the experiments, tests and your own programs).
//!
//! A [`RenderRequest`] holds everything a render can be asked: the scene,
//! the integrator and light, the camera, the structure, the samples (a
//! fixed count, a noise target or a time), the outputs, the tone map,
//! denoising, a split into parts, checkpoints and resumption. [`render`]
//! carries it out and returns a [`RenderOutcome`] (serialisable: the plan,
//! the camera chosen and why, the exposure, the times, the rays, the files
//! written, the warnings) with the image. Errors ([`JobError`]) name the
//! request's fields; a front end phrases them in its own terms.
//!
//! ```no_run
//! use rtgi_job::{CancelToken, RenderRequest, SceneSource, Unobserved, render};
//!
//! let mut request = RenderRequest::new(SceneSource::BuiltIn, "cornell-box.png");
//! request.sampling.samples_per_pixel = Some(64);
//! let rendered = render(&request, &Unobserved, &CancelToken::new())?;
//! println!("{} rays in {:.0} ms", rendered.outcome.render.rays, rendered.outcome.render.ms);
//! # Ok::<(), rtgi_job::JobError>(())
//! ```

#![warn(missing_docs)]

mod cancel;
mod description;
mod error;
mod files;
mod memory;
mod observer;
mod outcome;
mod passes;
mod request;
mod run;
mod scene_source;
mod split;

pub use cancel::CancelToken;
pub use description::{CameraInfo, ExtensionInfo, LightInfo, MaterialInfo, SceneDescription, TextureInfo, describe};
pub use error::{Field, JobError};
pub use files::{check_output_folder, same_file};
pub use memory::{bytes_per_pixel, check_memory};
pub use observer::{Observer, Unobserved};
pub use outcome::{
    AdaptiveSummary, BuildSummary, CameraSummary, ExposureSummary, LegibilitySummary, OutputSummary, PartSummary,
    PassesSummary, RenderOutcome, SceneSummary, Warning,
};
pub use passes::Ending;
pub use request::{
    ACCUMULATION_EXTENSION, ADAPTIVE_SPP, Checkpoints, DEFAULT_BACKGROUND, DEFAULT_IMAGE_SIDE, Denoise, ImageSize,
    MAX_IMAGE_SIDE, RenderRequest, Sampling, Split, Structure, Tone, default_lighting, is_accumulation, reshaped,
};
pub use run::{
    Given, PREVIEW_FILTER_GLOSSY, Rendered, aov_path, check_output, render, render_given, render_in_memory, thread_pool,
};
pub use scene_source::{BUILT_IN_NAME, LoadedScene, SceneSource, built_in};
pub use split::band;

// The README's examples are compiled as doc tests, so they cannot rot.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
