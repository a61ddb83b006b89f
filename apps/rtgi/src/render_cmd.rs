//! `rtgi render`: its options, the [`RenderRequest`] they make, and the
//! lines it prints. The render itself is [`rtgi_job::render`].

use std::ops::Range;
use std::path::PathBuf;
use std::sync::OnceLock;

use anyhow::Result;
use clap::Args;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use rtgi_job::{
    Checkpoints, Denoise, Ending, ImageSize, Observer, RenderOutcome, RenderRequest, Sampling, SceneSource, Split,
    Tone, Warning,
};
use rtgi_math::Vec3;
use rtgi_render::adaptive::Round;
use rtgi_render::recipe::ChosenCamera;
use rtgi_render::{EffectPlan, GUIDE_SAMPLES, Integrator, PixelSampler};
use rtgi_scene::Light;

use crate::interrupt;
use crate::options::{
    AccelArgs, CameraArgs, ImageSizeArgs, LightingArgs, OutputArgs, SeedArgs, ThreadArgs, ToneArgs, parse_colour,
};
use crate::output::{out, outln};
use crate::phrasing::{Phrasing, job_error, report_camera, warn};
use crate::progress::Progress;

/// `rtgi render`: an image of a scene.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "Output image; the format follows the extension (.png or .exr), or .accum for the render's exact sums \
     (a part of a split render, for 'rtgi merge') [default: SCENE.png, in the current folder]"
)))]
pub(crate) struct RenderArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    #[command(flatten)]
    pub(crate) size: ImageSizeArgs,

    /// A quick look: a quarter of the width and height, and at most 4 samples per pixel
    #[arg(long)]
    pub(crate) quick: bool,

    /// Samples per pixel [default: 16 for the direct and path integrators, 1 otherwise]; with
    /// --noise or --time, the most a pixel takes [default: 1024]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub(crate) spp: Option<u32>,

    #[command(flatten)]
    pub(crate) adaptive: AdaptiveArgs,

    #[command(flatten)]
    pub(crate) lighting: LightingArgs,

    /// Also write arbitrary output variables beside the output, as OUTPUT.NAME.exr (names
    /// separated by commas)
    #[arg(long, value_delimiter = ',', value_parser = aov_parser())]
    pub(crate) aov: Vec<Integrator>,

    /// Where samples go in a pixel, and how the first bounce's light and direction samples are
    /// spread over them [default: center for 1 spp, stratified otherwise]
    #[arg(long, value_enum)]
    pub(crate) sampler: Option<PixelSampler>,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    #[command(flatten)]
    pub(crate) tone: ToneArgs,

    /// Smooth the noise of a PNG across surfaces, keeping edges (an albedo-, normal- and
    /// depth-guided filter): auto denoises PNG output of the direct and path integrators and
    /// never EXR or .accum files, which keep the unbiased estimate
    #[arg(long, value_enum, default_value_t = Denoise::Auto)]
    pub(crate) denoise: Denoise,

    /// Radiance of camera rays that hit nothing and see no environment, as R,G,B
    #[arg(long, value_parser = parse_colour, default_value = "0.05,0.05,0.06", allow_hyphen_values = true)]
    pub(crate) background: Vec3,

    #[command(flatten)]
    pub(crate) job: JobArgs,

    /// Print the outcome as JSON instead of text: the plan, the camera and how it was chosen, the
    /// exposure, the times, the rays, the files written and the warnings (rtgi_job::RenderOutcome);
    /// warnings and notes still go to standard error as well
    #[arg(long)]
    pub(crate) json: bool,
}

/// Adaptive sampling: rounds of 16, 32, 64, ... samples, each pixel
/// stopping when its noise is low enough ([`rtgi_render::adaptive`]).
#[derive(Args, Debug, Clone, Default)]
pub(crate) struct AdaptiveArgs {
    /// Sample each pixel until the standard error of its mean is at most this fraction of it
    /// (0.02 for 2%), checked after 16, 32, 64, ... samples; deterministic: the same seed and
    /// options give the same image on any machine. Not with --samples, --tile, --resume,
    /// --checkpoint, --time-limit or .accum output: a pixel's stop depends on all its samples
    #[arg(long, value_name = "FRACTION", value_parser = parse_noise)]
    pub(crate) noise: Option<f32>,

    /// Render in rounds of doubling samples until the next round is predicted to end after
    /// SECONDS (with --noise, whichever stops first); it then prints the --spp that renders the
    /// same image without a time bound
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub(crate) time: Option<f64>,
}

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

fn parse_noise(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|n| n.is_finite() && *n > 0.0 && *n < 1.0)
        .ok_or_else(|| format!("expected a fraction between 0 and 1, like 0.02 for 2% (got '{text}')"))
}

/// The arbitrary output variables: the integrators that compute a property
/// of the closest hit ([`Integrator::is_aov`]), named as `ValueEnum` names them.
fn aov_parser() -> impl TypedValueParser<Value = Integrator> {
    use clap::ValueEnum;
    let aovs = Integrator::value_variants().iter().filter(|i| i.is_aov()).filter_map(ValueEnum::to_possible_value);
    PossibleValuesParser::new(aovs).map(|name| ValueEnum::from_str(&name, false).expect("one of the possible values"))
}

impl RenderArgs {
    /// The request these options make (`--quick` applied).
    pub(crate) fn request(&self) -> Result<RenderRequest> {
        let scene = match &self.scene {
            None => SceneSource::BuiltIn,
            Some(path) => SceneSource::File { path: path.clone(), options: crate::options::load_options() },
        };
        let mut request = RenderRequest::new(scene, self.output.or_named_after(self.scene.as_deref(), ".png"));
        request.aovs = self.aov.clone();
        request.size = ImageSize { width: self.size.width, height: self.size.height };
        request.sampling = Sampling {
            samples_per_pixel: self.spp,
            sampler: self.sampler,
            seed: self.seed.value,
            noise: self.adaptive.noise,
            time: self.adaptive.time,
        };
        if self.quick {
            let spp = request.samples_per_pixel().min(4);
            request.size = ImageSize::exactly((request.size.width() / 4).max(16), (request.size.height() / 4).max(16));
            request.sampling.samples_per_pixel = Some(spp);
        }
        request.lighting = self.lighting.lighting();
        request.background = self.background;
        request.camera = self.camera.choice();
        request.structure = self.accel.structure();
        request.tone = Tone { exposure: self.tone.exposure, operator: self.tone.tonemap };
        request.denoise = self.denoise;
        request.split = Split { samples: self.job.samples.clone(), tile: self.job.tile };
        request.checkpoints = Checkpoints {
            time_limit: self.job.time_limit,
            checkpoint: self.job.checkpoint.clone(),
            every_seconds: self.job.checkpoint_every,
            resume: self.job.resume.clone(),
        };
        request.threads = self.threads.count()?;
        Ok(request)
    }
}

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    let request = args.request()?;
    let printer = Printer::new(&request, !args.json, Phrasing::Options);
    let rendered = render(&request, None, &printer)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&rendered.outcome)?)?;
    }
    finish(&rendered)
}

/// Renders `request` (or `given`'s scene and structure) with signals
/// connected to its cancellation, in the words of `printer`'s phrasing.
pub(crate) fn render(
    request: &RenderRequest,
    given: Option<rtgi_job::Given<'_>>,
    printer: &Printer<'_>,
) -> Result<rtgi_job::Rendered> {
    // From the start: a Ctrl-C while the scene loads then stops the render
    // before its first pass (a second one ends the process at once).
    let cancel = interrupt::install()?;
    let rendered = match given {
        None => rtgi_job::render(request, printer, &cancel),
        Some(given) => rtgi_job::render_given(request, given, printer, &cancel),
    }
    .map_err(|e| job_error(e, printer.phrasing))?;
    printer.summary(request, &rendered.outcome)?;
    Ok(rendered)
}

/// A render that ended by a signal is an error of its own (the exit status says which signal).
pub(crate) fn finish(rendered: &rtgi_job::Rendered) -> Result<()> {
    match (&rendered.ending, interrupt::signal()) {
        (Ending::Cancelled(_), Some(signal)) => Err(interrupt::StoppedBySignal(signal).into()),
        _ => Ok(()),
    }
}

/// Prints a render as it runs (the plan, rounds, checkpoints, progress on
/// standard error) and, when `prose`, its summary after.
pub(crate) struct Printer<'a> {
    request: &'a RenderRequest,
    prose: bool,
    pub(crate) phrasing: Phrasing,
    /// Say, once every pixel has its first sample, how long the render will take.
    forecast: bool,
    progress: OnceLock<Progress>,
    /// The first failed write to standard output, returned at the end.
    printed: std::sync::Mutex<Result<()>>,
}

impl<'a> Printer<'a> {
    pub(crate) fn new(request: &'a RenderRequest, prose: bool, phrasing: Phrasing) -> Self {
        Self {
            request,
            prose,
            phrasing,
            forecast: phrasing == Phrasing::Script,
            progress: OnceLock::new(),
            printed: std::sync::Mutex::new(Ok(())),
        }
    }

    /// Prints a line on standard output when printing prose; the first
    /// failure is kept (a reader that goes away does not stop the render).
    fn say(&self, line: std::fmt::Arguments<'_>) {
        if !self.prose {
            return;
        }
        let mut printed = self.printed.lock().unwrap_or_else(|p| p.into_inner());
        if printed.is_ok() {
            *printed = outln!("{line}");
        }
    }

    /// The summary after the render, in lines.
    fn summary(&self, request: &RenderRequest, o: &RenderOutcome) -> Result<()> {
        let r = &o.render;
        self.say(format_args!("scene       {}", o.scene.name));
        self.say(format_args!("triangles   {}", o.scene.triangles));
        self.say(format_args!("load        {:.1} ms", o.scene.load_ms));
        self.say(format_args!("build       {:.1} ms ({})", o.build.ms, o.build.variant));
        match &r.adaptive {
            None => self.say(format_args!(
                "render      {:.1} ms, {}x{} at {} spp, {} threads, {} pass(es)",
                r.ms, r.width, r.height, r.samples_per_pixel, r.threads, r.passes
            )),
            Some(adaptive) => {
                self.say(format_args!(
                    "render      {:.1} ms, {}x{} at {} to {} spp (mean {:.1}), {} threads, {} round(s)",
                    r.ms,
                    r.width,
                    r.height,
                    adaptive.fewest_samples,
                    adaptive.samples_reached,
                    adaptive.mean_samples,
                    r.threads,
                    r.passes
                ));
                self.say(format_args!("{}", adaptive_summary(request, adaptive, &r.sampler)));
            }
        }
        if let Some(ms) = o.denoise_ms {
            self.say(format_args!(
                "denoised    {ms:.1} ms (guided by albedo, normal, depth and emission at {GUIDE_SAMPLES} spp; --denoise \
                 off keeps the samples' mean)"
            ));
        }
        if let Some(part) = &o.part {
            let (rows, samples) = (part.rows[0]..part.rows[1], part.samples[0]..part.samples[1]);
            self.say(format_args!("part        rows {rows:?}, samples {samples:?} of every pixel"));
        }
        self.say(format_args!("rays        {} ({:.3} Mrays/s)", r.rays, r.mrays_per_second));
        let last = o.part.as_ref().map_or(r.samples_per_pixel, |part| part.samples[1]);
        if let Some(reason) = &o.stopped_by {
            self.say(format_args!("stopped     by {reason} with {} of {last} samples per pixel", r.samples_done));
        }
        let main_output = o.outputs.iter().find(|output| matches!(output.kind.as_str(), "image" | "accumulation"));
        match main_output {
            Some(output) => {
                let first = o.part.as_ref().map_or(0, |part| part.samples[0]);
                let partial = if r.adaptive.is_none() && r.samples_done < last - first {
                    format!(" ({} samples per pixel)", r.samples_done)
                } else {
                    String::new()
                };
                self.say(format_args!("wrote       {}{partial}", output.path));
            }
            None => self.say(format_args!("wrote       nothing: no sample finished")),
        }
        if let Some(exposure) = &o.exposure {
            let how = if exposure.automatic { "automatic; --exposure sets it" } else { "--exposure" };
            self.say(format_args!("exposure    {:+.1} stops ({how}), {} tone map", exposure.stops, exposure.tone_map));
        }
        let aovs: Vec<_> =
            o.outputs.iter().filter(|output| Integrator::ALL.iter().any(|i| i.name() == output.kind)).collect();
        if o.stopped_by.is_none() {
            for aov in aovs {
                self.say(format_args!("wrote       {}", aov.path));
            }
        } else if !request.aovs.is_empty() {
            self.say(format_args!("skipped     the AOVs (they are written when the render completes)"));
        }
        std::mem::replace(&mut *self.printed.lock().unwrap_or_else(|p| p.into_inner()), Ok(()))
    }
}

impl Observer for Printer<'_> {
    fn warning(&self, warning: &Warning) {
        warn(warning, self.phrasing, self.request.tone.exposure.is_some());
    }

    fn planned(&self, plan: &EffectPlan, camera: &ChosenCamera, room_light: Option<&Light>) {
        report_camera(camera, self.phrasing);
        if self.prose {
            let mut printed = self.printed.lock().unwrap_or_else(|p| p.into_inner());
            if printed.is_ok() {
                *printed = out!("{plan}");
            }
        }
        if let Some(light) = room_light {
            let p = light.position;
            self.say(format_args!(
                "  note: no sky reaches the camera or the surfaces it sees, and the scene's own lights leave them \
                 dark, so a lamp at {:.3},{:.3},{:.3} hangs over the room in view; --light or --environment chooses \
                 others",
                p.x, p.y, p.z
            ));
        }
    }

    fn resuming(&self, path: &std::path::Path, samples: u32, of: u32) {
        self.say(format_args!("resuming   {} at {samples} of {of} samples per pixel", path.display()));
    }

    fn passes_started(&self, pixels: u64, before: u32, samples: u32) {
        let progress = Progress::new(pixels, before, samples);
        let _ = self.progress.set(if self.forecast { progress.with_forecast() } else { progress });
    }

    fn progress(&self, pixel_samples: u64) {
        if let Some(progress) = self.progress.get() {
            progress.add(pixel_samples);
        }
    }

    fn progress_reset(&self, done: u64) {
        if let Some(progress) = self.progress.get() {
            progress.set_done(done);
        }
    }

    fn checkpoint(&self, path: &std::path::Path, samples: u32) {
        match self.progress.get() {
            // During the passes: beside the progress bar.
            Some(progress) if !progress.finished() => {
                progress.say(&format!("checkpoint {}: {samples} samples per pixel", path.display()))
            }
            _ => {
                let of = self.request.split.samples.as_ref().map_or(self.request.samples_per_pixel(), |s| s.end);
                self.say(format_args!("checkpoint  {} ({samples} of {of} samples per pixel)", path.display()))
            }
        }
    }

    fn passes_ended(&self) {
        if let Some(progress) = self.progress.get() {
            progress.finish();
        }
    }

    fn round(&self, round: &Round) {
        let pixels = self.request.size.width() as u64 * self.request.size.height() as u64;
        self.say(format_args!(
            "round       {} samples per pixel: {} pixels rendered, {} of {} within the noise target, {:.0} ms",
            round.samples_per_pixel,
            round.pixels,
            round.converged,
            pixels,
            round.seconds * 1e3
        ));
    }
}

/// What adaptive sampling did, and how to render the same image again.
fn adaptive_summary(request: &RenderRequest, adaptive: &rtgi_job::AdaptiveSummary, sampler: &str) -> String {
    let sampling = &request.sampling;
    let time = sampling.time.unwrap_or_default();
    let reached = adaptive.samples_reached;
    let spp = request.samples_per_pixel();
    let why = if adaptive.stopped_by_time {
        // The rounds of a fixed count are its passes: without a noise target they sum to a plain render.
        let sampler = if sampling.noise.is_none() { format!(" --sampler {sampler}") } else { String::new() };
        format!(
            "--time {time} ended it after {reached} samples per pixel; --spp {reached}{sampler} with the same options \
             and no --time renders the same image"
        )
    } else if sampling.noise.is_none() {
        format!("every pixel took --spp {spp} within --time {time}")
    } else if reached < spp {
        "every pixel reached the noise target".to_owned()
    } else {
        format!("pixels still above the noise target stopped at --spp {spp}")
    };
    format!("adaptive    {} pixel samples in {} rounds; {why}", adaptive.total_samples, adaptive.rounds)
}

#[cfg(test)]
mod tests {
    use super::*;

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
