//! What a render reports while it runs, for a front end to show: the
//! plan before the first sample, progress from the worker threads, the
//! rounds of adaptive sampling, checkpoints as they are written.
//! Everything here is also in the [`crate::RenderOutcome`]; an observer
//! only hears it sooner.

use std::path::Path;

use rtgi_render::EffectPlan;
use rtgi_render::adaptive::Round;
use rtgi_render::recipe::ChosenCamera;
use rtgi_scene::Light;

use crate::outcome::Warning;

/// Hears a render as it runs; every method does nothing unless overridden.
pub trait Observer: Sync {
    /// A warning, as soon as it is known (the outcome lists it again).
    fn warning(&self, _warning: &Warning) {}

    /// The view is chosen and the plan made: rendering starts. `room_light`
    /// is the lamp hung over an enclosed, unlit view, if one was.
    fn planned(&self, _plan: &EffectPlan, _camera: &ChosenCamera, _room_light: Option<&Light>) {}

    /// A render continues from `path`, which holds `samples` of `of` samples per pixel.
    fn resuming(&self, _path: &Path, _samples: u32, _of: u32) {}

    /// Passes start: `pixels` pixels, from `before` to `samples` samples per pixel.
    fn passes_started(&self, _pixels: u64, _before: u32, _samples: u32) {}

    /// Pixel samples finished since the last call; called from the worker
    /// threads, so it must be cheap.
    fn progress(&self, _pixel_samples: u64) {}

    /// A pass was abandoned: the pixel samples finished in all are `done`.
    fn progress_reset(&self, _done: u64) {}

    /// A checkpoint was written, holding `samples` samples per pixel.
    fn checkpoint(&self, _path: &Path, _samples: u32) {}

    /// The passes ended.
    fn passes_ended(&self) {}

    /// A round of adaptive sampling finished.
    fn round(&self, _round: &Round) {}
}

/// An observer that hears nothing: for renders nobody watches.
#[derive(Clone, Copy, Debug, Default)]
pub struct Unobserved;

impl Observer for Unobserved {}
