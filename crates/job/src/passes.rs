//! Long renders in passes: samples are added pass by pass, exactly, to an
//! [`Accumulation`], so a render can stop at a time limit or when
//! cancelled with the samples done, save checkpoints and resume them, all
//! with the bits of a render in one go.

use std::path::Path;
use std::time::{Duration, Instant};

use rtgi_accel::Accel;
use rtgi_image::HdrImage;
use rtgi_render::{Accumulation, PassControl, RenderSettings, render_pass};
use rtgi_scene::{Camera, Scene};

use crate::JobError;
use crate::cancel::CancelToken;
use crate::observer::Observer;
use crate::request::Checkpoints;

/// Longest pass: a stop asked for mid-pass loses at most this much work.
const LONGEST_PASS: f64 = 10.0;

/// How a run of passes ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ending {
    /// Every sample of the job is in.
    Complete,
    /// The time limit came first.
    TimeLimit,
    /// The render was cancelled, for this reason.
    Cancelled(String),
}

/// What the passes of a run traced.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Totals {
    pub(crate) passes: u32,
    pub(crate) rays: u64,
    pub(crate) render_seconds: f64,
}

/// What a run of passes renders with.
#[derive(Clone, Copy)]
pub(crate) struct Renderer<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) accel: &'a dyn Accel,
    pub(crate) camera: &'a Camera,
    pub(crate) settings: &'a RenderSettings,
}

/// Where the passes stop and what they keep.
pub(crate) struct Plan<'a> {
    pub(crate) checkpoints: &'a Checkpoints,
    /// When the render started (the time limit counts from here).
    pub(crate) started: Instant,
    /// The last sample (exclusive) of every pixel.
    pub(crate) last: u32,
    /// A pass ends at this many samples, and the image then is returned
    /// too (the denoiser's estimate of each pixel's noise).
    pub(crate) halfway: Option<u32>,
    pub(crate) cancel: &'a CancelToken,
}

/// Renders passes into `accumulation` until its samples reach the plan's
/// last, the time limit is reached or the render is cancelled; saves a
/// checkpoint every `every_seconds`.
pub(crate) fn run_passes(
    renderer: Renderer<'_>,
    plan: &Plan<'_>,
    accumulation: &mut Accumulation,
    observer: &dyn Observer,
) -> Result<(Ending, Totals, Option<HdrImage>), JobError> {
    let Plan { checkpoints, started, last, halfway, cancel } = *plan;
    let mut half = None;
    let deadline = checkpoints.time_limit.map(|seconds| started + Duration::from_secs_f64(seconds));
    let checkpoint: Option<&Path> = checkpoints.path();
    let pixels = accumulation.rows().len() as u64 * renderer.settings.width as u64;
    let first = accumulation.samples_done();
    let mut seconds_per_sample: Option<f64> = None;
    let mut last_checkpoint = Instant::now();
    let mut totals = Totals::default();
    let stop_requested = || cancel.is_cancelled() || deadline.is_some_and(|d| Instant::now() >= d);
    let ending = loop {
        let remaining = last - accumulation.samples().end;
        if remaining == 0 {
            break Ending::Complete;
        }
        if let Some(reason) = cancel.reason() {
            break Ending::Cancelled(reason);
        }
        let now = Instant::now();
        let mut target = LONGEST_PASS;
        if checkpoint.is_some() {
            target = target.min(checkpoints.every_seconds);
        }
        if let Some(deadline) = deadline {
            let left = deadline.saturating_duration_since(now).as_secs_f64();
            if left <= 0.0 || seconds_per_sample.is_some_and(|t| t > left) {
                break Ending::TimeLimit;
            }
            target = target.min(left);
        }
        let mut count = match seconds_per_sample {
            None => 1,
            Some(t) => ((target / t).floor() as u32).clamp(1, remaining),
        };
        if let Some(halfway) = halfway.filter(|&h| h > accumulation.samples().end) {
            count = count.min(halfway - accumulation.samples().end);
        }
        let control = PassControl { progress: &|done| observer.progress(done), cancelled: &stop_requested };
        let Renderer { scene, accel, camera, settings } = renderer;
        let pass_start = Instant::now();
        match render_pass(scene, accel, camera, settings, accumulation, count, &control) {
            Ok(stats) => {
                totals.passes += 1;
                totals.rays += stats.rays;
                totals.render_seconds += stats.render_ms * 1e-3;
                seconds_per_sample = Some(pass_start.elapsed().as_secs_f64() / count as f64);
                if halfway == Some(accumulation.samples().end) {
                    half = Some(accumulation.image());
                }
            }
            Err(_cancelled) => {
                // The pass's samples are dropped; the loop's top says why it stopped.
                totals.render_seconds += pass_start.elapsed().as_secs_f64();
                observer.progress_reset(pixels * (accumulation.samples_done() - first) as u64);
                continue;
            }
        }
        if let Some(path) = checkpoint
            && last_checkpoint.elapsed().as_secs_f64() >= checkpoints.every_seconds
            && accumulation.samples().end < last
        {
            accumulation.write(path)?;
            last_checkpoint = Instant::now();
            observer.checkpoint(path, accumulation.samples().end);
        }
    };
    Ok((ending, totals, half))
}
