//! Long renders and split ones: a render proceeds in passes of samples,
//! each added exactly to an [`Accumulation`], so it can stop at a time
//! limit or a signal with the samples done, save checkpoints and resume
//! them, or be one job of many (a range of samples, a band of rows) whose
//! parts `rtgi merge` puts together, all with the bits of a render in one go.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use clap::Args;
use rtgi_accel::Accel;
use rtgi_image::HdrImage;
use rtgi_render::{Accumulation, PassControl, RenderSettings, render_pass};
use rtgi_scene::{Camera, Scene};

use crate::interrupt;
use crate::progress::Progress;

/// Longest pass: a stop asked for mid-pass loses at most this much work.
const LONGEST_PASS: f64 = 10.0;

/// Options for long and split renders.
#[derive(Debug, Args)]
pub(crate) struct JobArgs {
    /// Stop once this many seconds have passed since the command started (a pass that would not
    /// finish in time is not started, or abandoned), and write the image of the samples done
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub(crate) time_limit: Option<f64>,

    /// Save the render's state to FILE every --checkpoint-every seconds and when it stops, so
    /// that --resume FILE can continue it [default with --resume: the resumed file]
    #[arg(long, value_name = "FILE")]
    pub(crate) checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0, value_parser = parse_seconds)]
    pub(crate) checkpoint_every: f64,

    /// Continue the render saved in FILE by --checkpoint; the scene and every option must be
    /// those it was started with (a file of another render, or of other --samples or --tile,
    /// is refused with exit status 3). The result has the bits of a render never interrupted
    #[arg(long, value_name = "FILE")]
    pub(crate) resume: Option<PathBuf>,

    /// Render only samples FROM..TO (FROM included, TO not, counted from 0) of every pixel, of
    /// the --spp in all: one job of a split render. Write it to an .accum file and put the
    /// parts together with 'rtgi merge'
    #[arg(long, value_name = "FROM..TO", value_parser = parse_sample_range)]
    pub(crate) samples: Option<Range<u32>>,

    /// Render only band I (counted from 0) of N bands of rows of equal height: one job of a
    /// split render, written to an .accum file for 'rtgi merge'
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    pub(crate) tile: Option<(u32, u32)>,
}

impl JobArgs {
    /// Whether this run renders a part of the image, for `rtgi merge`.
    pub(crate) fn is_part(&self) -> bool {
        self.samples.is_some() || self.tile.is_some()
    }

    /// The rows and samples this job renders, for an image of `height` rows and `spp` samples.
    pub(crate) fn share(&self, height: u32, spp: u32) -> Result<(Range<u32>, Range<u32>)> {
        let rows = match self.tile {
            None => 0..height,
            Some((_, count)) if count > height => {
                bail!("--tile {}/{count}: the image has only {height} rows", self.tile.unwrap_or_default().0)
            }
            Some((index, count)) => band(index, count, height),
        };
        let samples = match &self.samples {
            None => 0..spp,
            Some(range) if range.end > spp => {
                bail!("--samples {}..{}: the render has {spp} samples per pixel (--spp)", range.start, range.end)
            }
            Some(range) => range.clone(),
        };
        Ok((rows, samples))
    }

    /// Where checkpoints go: `--checkpoint`, else the file resumed.
    pub(crate) fn checkpoint_path(&self) -> Option<&Path> {
        self.checkpoint.as_deref().or(self.resume.as_deref())
    }
}

/// Rows of band `index` of `count` bands of an image `height` rows high.
fn band(index: u32, count: u32, height: u32) -> Range<u32> {
    let edge = |i: u32| (i as u64 * height as u64 / count as u64) as u32;
    edge(index)..edge(index + 1)
}

pub(crate) fn parse_seconds(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| format!("expected a positive number of seconds (got '{text}')"))
}

fn parse_sample_range(text: &str) -> Result<Range<u32>, String> {
    let error = || format!("expected FROM..TO with 0 <= FROM < TO, like 0..64 (got '{text}')");
    let (from, to) = text.split_once("..").ok_or_else(error)?;
    let (from, to) = (from.trim().parse::<u32>().map_err(|_| error())?, to.trim().parse::<u32>().map_err(|_| error())?);
    if from >= to {
        return Err(error());
    }
    Ok(from..to)
}

fn parse_tile(text: &str) -> Result<(u32, u32), String> {
    let error = || format!("expected I/N with 0 <= I < N, like 0/4 (got '{text}')");
    let (index, count) = text.split_once('/').ok_or_else(error)?;
    let (index, count) =
        (index.trim().parse::<u32>().map_err(|_| error())?, count.trim().parse::<u32>().map_err(|_| error())?);
    if index >= count {
        return Err(error());
    }
    Ok((index, count))
}

/// How a run of passes ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ending {
    /// Every sample of the job is in.
    Complete,
    /// The time limit came first.
    TimeLimit,
    /// A SIGINT or SIGTERM (the signal's number).
    Signal(i32),
}

/// What the passes of a run traced.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Totals {
    pub(crate) passes: u32,
    pub(crate) rays: u64,
    pub(crate) render_seconds: f64,
}

/// What a run of passes renders with.
pub(crate) struct Renderer<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) accel: &'a dyn Accel,
    pub(crate) camera: &'a Camera,
    pub(crate) settings: &'a RenderSettings,
}

/// Renders passes into `accumulation` until its samples reach `last`, the
/// time limit (counted from `started`) is reached or a signal arrives;
/// saves a checkpoint every `--checkpoint-every` seconds. With `halfway`,
/// a pass ends at that many samples and the image then is returned too
/// (the denoiser's estimate of each pixel's noise).
pub(crate) fn run_passes(
    renderer: &Renderer<'_>,
    args: &JobArgs,
    started: Instant,
    accumulation: &mut Accumulation,
    (last, halfway): (u32, Option<u32>),
    progress: &Progress,
) -> Result<(Ending, Totals, Option<HdrImage>)> {
    let mut half = None;
    let deadline = args.time_limit.map(|seconds| started + Duration::from_secs_f64(seconds));
    let checkpoint = args.checkpoint_path();
    let pixels = accumulation.rows().len() as u64 * renderer.settings.width as u64;
    let first = accumulation.samples_done();
    let mut seconds_per_sample: Option<f64> = None;
    let mut last_checkpoint = Instant::now();
    let mut totals = Totals::default();
    let stop_requested = || interrupt::requested() || deadline.is_some_and(|d| Instant::now() >= d);
    let ending = loop {
        let remaining = last - accumulation.samples().end;
        if remaining == 0 {
            break Ending::Complete;
        }
        if let Some(signal) = interrupt::signal() {
            break Ending::Signal(signal);
        }
        let now = Instant::now();
        let mut target = LONGEST_PASS;
        if checkpoint.is_some() {
            target = target.min(args.checkpoint_every);
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
        let control = PassControl { progress: &|done| progress.add(done), cancelled: &stop_requested };
        let Renderer { scene, accel, camera, settings } = *renderer;
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
                progress.set_done(pixels * (accumulation.samples_done() - first) as u64);
                continue;
            }
        }
        if let Some(path) = checkpoint
            && last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every
            && accumulation.samples().end < last
        {
            accumulation.write(path)?;
            last_checkpoint = Instant::now();
            progress.say(&format!("checkpoint {}: {} samples per pixel", path.display(), accumulation.samples().end));
        }
    };
    Ok((ending, totals, half))
}

/// A render stopped by a signal, after writing what it had: the command
/// ends with the signal's exit status (130 for SIGINT, 143 for SIGTERM).
#[derive(Debug)]
pub(crate) struct StoppedBySignal(pub(crate) i32);

impl std::fmt::Display for StoppedBySignal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "stopped by {}", interrupt::name(self.0))
    }
}

impl std::error::Error for StoppedBySignal {}

/// A `--resume` file of another render, or of another share of it: the
/// command ends with exit status [`ResumeOfAnotherRender::EXIT_STATUS`], so
/// that a job script can tell it from a failure that running again may cure.
#[derive(Debug)]
pub(crate) struct ResumeOfAnotherRender(pub(crate) String);

impl ResumeOfAnotherRender {
    /// The exit status.
    pub(crate) const EXIT_STATUS: u8 = 3;
}

impl std::fmt::Display for ResumeOfAnotherRender {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ResumeOfAnotherRender {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_the_rows_once() {
        for (count, height) in [(1, 7), (3, 7), (7, 7), (4, 1080)] {
            let bands: Vec<_> = (0..count).map(|i| band(i, count, height)).collect();
            assert_eq!(bands[0].start, 0);
            assert_eq!(bands[count as usize - 1].end, height);
            assert!(bands.windows(2).all(|w| w[0].end == w[1].start && !w[0].is_empty()));
        }
    }

    #[test]
    fn ranges_and_tiles_parse_strictly() {
        assert_eq!(parse_sample_range("16..32"), Ok(16..32));
        for bad in ["32..16", "5..5", "-1..3", "0..", "..4", "0-4", "a..b"] {
            assert!(parse_sample_range(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_tile("3/4"), Ok((3, 4)));
        for bad in ["4/4", "1/0", "-1/4", "1", "a/b"] {
            assert!(parse_tile(bad).is_err(), "{bad}");
        }
        for bad in ["0", "-5", "nan", "inf", "x"] {
            assert!(parse_seconds(bad).is_err(), "{bad}");
        }
    }
}
