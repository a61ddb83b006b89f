use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use rtgi_image::{HdrImage, Legibility, OutputFormat, ToneMap, check_writable, legibility};
use rtgi_render::adaptive::AdaptiveOutcome;
use rtgi_render::{
    Accumulation, DenoiseSettings, EffectPlan, EnvironmentSpec, FilterGlossy, GUIDE_SAMPLES, Guides, Integrator,
    PixelSampler, RenderIdentity, RenderSettings, denoise, recipe, render, render_adaptive,
};

use crate::cli::ToneArgs;
use crate::cli::{Denoise, RenderArgs, reshaped};
use crate::common::{
    LoadedScene, Phrasing, Structure, apply_lighting, check_output_folder, load_scene, prepare_render, prepare_view,
    refuse_inputs_as_outputs,
};
use crate::interrupt;
use crate::output::{out, outln};
use crate::progress::Progress;
use crate::render_job::{Ending, Renderer, ResumeOfAnotherRender, StoppedBySignal, Totals, run_passes};
use crate::render_summary::{
    AdaptiveSummary, BuildSummary, CameraSummary, ExposureSummary, LegibilitySummary, OutputSummary, PartSummary,
    PassesSummary, RenderSummary, SceneSummary,
};

/// Extension of accumulation files: checkpoints and the parts of split renders.
pub(crate) const ACCUMULATION_EXTENSION: &str = "accum";

/// Whether `path` names an accumulation file rather than an image.
pub(crate) fn is_accumulation(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case(ACCUMULATION_EXTENSION))
}

/// Checks before long work that `path` can take an image (.png, .exr) or an accumulation (.accum).
pub(crate) fn check_output(path: &Path) -> Result<()> {
    if is_accumulation(path) {
        check_output_folder(path)
    } else {
        check_writable(path).map(|_| ()).map_err(|e| match e {
            rtgi_image::ImageError::UnsupportedFormat { .. } => anyhow::anyhow!("{e}")
                .context("the output is an image (.png, .exr) or a render's accumulation (.accum)"),
            other => anyhow::anyhow!("{other}"),
        })
    }
}

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    render_image(args).map(|_| ())
}

/// What `rtgi render` made: the image and how its PNG was tone-mapped
/// (`None` when no sample finished).
pub(crate) struct Rendered {
    pub(crate) image: Option<(HdrImage, ToneMap)>,
    /// Seconds spent rendering (not loading or building).
    pub(crate) seconds: f64,
    /// Rays traced.
    pub(crate) rays: u64,
}

/// A scene a script loaded and edited, with the structure its `commit`
/// built: rendered in place of the file `args.scene` names.
pub(crate) struct Given<'a> {
    pub(crate) scene: LoadedScene,
    pub(crate) accel: &'a dyn rtgi_accel::Accel,
}

/// Path regularisation of denoised previews unless `--filter-glossy` says
/// otherwise: mirrors and smooth glass only, after diffuse bounces.
/// Measured by `rtgi experiment filter-glossy` (16 spp, denoised): 1.7x the
/// efficiency on the mirror Cornell box, where glossy lobes widened too
/// cost the conference room a quarter of its efficiency and 6% of its
/// light; deltas are the lobes light sampling cannot see through at all.
const PREVIEW_FILTER_GLOSSY: FilterGlossy = FilterGlossy { threshold: 1.0, deltas_only: true };

/// Whether the image is denoised: `--denoise auto` denoises PNG output of
/// the integrators that simulate light (EXR and accumulations keep the
/// unbiased mean), `on` any image of those integrators.
fn denoises(choice: Denoise, simulates_light: bool, output: &Path) -> bool {
    let png = OutputFormat::from_path(output).is_ok_and(|f| f == OutputFormat::Png);
    simulates_light
        && !is_accumulation(output)
        && match choice {
            Denoise::Auto => png,
            Denoise::On => true,
            Denoise::Off => false,
        }
}

/// `rtgi render`, returning the image it wrote.
pub(crate) fn render_image(args: &RenderArgs) -> Result<Rendered> {
    render_given(args, None)
}

/// `rtgi render` of `given`'s scene and structure when there is one, else
/// of the file `args.scene` names; returns the image it wrote.
pub(crate) fn render_given(args: &RenderArgs, given: Option<Given<'_>>) -> Result<Rendered> {
    let started = Instant::now();
    // From the start: a Ctrl-C while the scene loads then stops the render
    // before its first pass (a second one ends the process at once).
    interrupt::install()?;
    let job = &args.job;
    let output = args.output();
    let (width, height, spp) = args.resolution();
    // Refuse unusable outputs and options before spending time on loading and rendering.
    check_output(&output)?;
    let adaptive = args.adaptive.sampling();
    if adaptive.is_some() {
        refuse_split_adaptive(args, &output)?;
    }
    if job.is_part() && !is_accumulation(&output) {
        bail!(
            "--samples and --tile render a part of an image: write it to an .{ACCUMULATION_EXTENSION} file \
             (-o part.{ACCUMULATION_EXTENSION}) and put the parts together with 'rtgi merge'"
        );
    }
    if args.denoise == Denoise::On {
        if is_accumulation(&output) {
            bail!(
                "--denoise on: {} keeps the samples' sums, which a filter cannot apply to; denoise the image \
                 (-o image.png or .exr) instead",
                output.display()
            );
        }
        if !args.lighting.integrator.simulates_light() {
            bail!(
                "--denoise on is for the direct and path integrators: the {} integrator's image is not noisy light",
                args.lighting.integrator
            );
        }
    }
    if job.is_part() && !args.aov.is_empty() {
        bail!("--aov is for whole renders, not with --samples or --tile");
    }
    let aov_outputs: Vec<(Integrator, PathBuf)> =
        args.aov.iter().map(|&kind| Ok((kind, aov_path(&output, kind)?))).collect::<Result<_>>()?;
    for (_, path) in &aov_outputs {
        check_writable(path)?;
    }
    if let Some(path) = &job.checkpoint {
        check_output_folder(path)?;
    }
    let outputs: Vec<(&str, &Path)> = [("-o", output.as_path())]
        .into_iter()
        .chain(aov_outputs.iter().map(|(_, path)| ("--aov", path.as_path())))
        .chain(job.checkpoint.as_deref().map(|path| ("--checkpoint", path)))
        .collect();
    let mut inputs: Vec<(&str, &Path)> = args.scene.as_deref().map(|path| ("the scene", path)).into_iter().collect();
    if let Some(EnvironmentSpec::File(path)) = &args.lighting.environment {
        inputs.push(("--environment", path));
    }
    refuse_inputs_as_outputs(&outputs, &inputs)?;
    let resumed = job.resume.as_deref().map(Accumulation::read).transpose()?;
    check_memory(width, height)?;

    let from_script = given.is_some();
    let (LoadedScene { mut scene, name: scene_name, load_ms }, committed) = match given {
        Some(Given { scene, accel }) => (scene, Some(accel)),
        None => (load_scene(args.scene.as_deref())?, None),
    };
    // The files the scene read (textures, material libraries, buffers) are inputs too.
    let sources: Vec<(String, &Path)> = scene
        .sources
        .iter()
        .map(|path| (format!("a file of the scene ({})", path.display()), path.as_path()))
        .collect();
    let sources: Vec<(&str, &Path)> = sources.iter().map(|(what, path)| (what.as_str(), *path)).collect();
    refuse_inputs_as_outputs(&outputs, &sources)?;

    let mut settings = RenderSettings {
        width,
        height,
        samples_per_pixel: spp,
        // Rounds of adaptive sampling take the first samples of each pixel's sequence.
        sampler: args.sampler.unwrap_or(if adaptive.is_some() {
            PixelSampler::Sobol
        } else {
            recipe::default_sampler(spp)
        }),
        seed: args.seed.value,
        background: args.background,
        adaptive,
        ..RenderSettings::default()
    };
    if let Some(adaptive) = &adaptive {
        adaptive.check(&settings)?;
    }
    let pool = args.threads.pool()?;
    let (accel, prepared) = match committed {
        None => {
            let (built, prepared) =
                prepare_render(&mut scene, &mut settings, &args.lighting, &args.camera, &args.accel, &pool)?;
            (Structure::Built(built), prepared)
        }
        Some(committed) => {
            apply_lighting(&args.lighting, &mut scene, &mut settings)?;
            let view = prepare_view(&mut scene, committed, &mut settings, &args.camera, Phrasing::Script)?;
            (Structure::Committed(committed), view)
        }
    };
    let camera_choice = args.camera.choice();
    let camera_summary = CameraSummary::new(
        &prepared.camera,
        camera_choice.index,
        camera_choice.at.is_some() || camera_choice.look.is_some(),
        scene.cameras.len(),
    );
    let (camera, room_light) = (prepared.camera.camera, prepared.room_light);
    // A file camera's aspect ratio shapes the image unless its size was given.
    if let Some(aspect) = camera.aspect.filter(|&a| a.is_finite() && a > 0.0 && !args.size.given()) {
        (settings.width, settings.height) = reshaped(settings.width, settings.height, aspect);
        check_memory(settings.width, settings.height)?;
    }
    let (rows, samples) = job.share(settings.height, spp)?;

    // What is printed goes on standard output; a reader that goes away
    // (`| head`) does not stop the render, and the first failed write is
    // returned once the outputs are written.
    // The denoiser learns each pixel's noise from the image at half its samples.
    let denoising = denoises(args.denoise, settings.integrator.simulates_light(), &output);
    if args.lighting.filter_glossy.is_none() && denoising {
        settings.filter_glossy = Some(PREVIEW_FILTER_GLOSSY);
    }
    // With --json the prose is left out and the summary printed at the end.
    let prose = !args.json;
    let plan = EffectPlan::new(&scene, &settings);
    let mut printed = if prose { out!("{plan}") } else { Ok(()) };
    macro_rules! say {
        ($($arg:tt)*) => {
            if prose {
                printed = printed.and_then(|()| outln!($($arg)*))
            }
        };
    }
    if let Some(light) = &room_light {
        let p = light.position;
        say!(
            "  note: no sky reaches the camera or the surfaces it sees, and the scene's own lights leave them \
             dark, so a lamp at {:.3},{:.3},{:.3} hangs over the room in view; --light or --environment chooses others",
            p.x,
            p.y,
            p.z
        );
    }
    let renderer = Renderer { scene: &scene, accel: accel.as_ref(), camera: &camera, settings: &settings };
    let halfway = (denoising && !job.is_part() && spp >= 2).then_some(spp / 2);
    let mut half_image = None;
    let rendered = match adaptive {
        Some(_) => {
            let mut rounds_printed = Ok(());
            let (image, outcome) = pool.install(|| {
                render_adaptive(&scene, accel.as_ref(), &camera, &settings, &mut |round| {
                    if prose && rounds_printed.is_ok() {
                        rounds_printed = outln!(
                            "round       {} samples per pixel: {} pixels rendered, {} of {} within the noise target, \
                             {:.0} ms",
                            round.samples_per_pixel,
                            round.pixels,
                            round.converged,
                            settings.width as u64 * settings.height as u64,
                            round.seconds * 1e3
                        );
                    }
                })
            })?;
            printed = printed.and(rounds_printed);
            Done::Adapted(image, outcome)
        }
        None => {
            // In the pool: the passes' tiles run on its threads, however
            // many the process's global pool has (a script's `one thread`).
            let (accumulation, half) = pool.install(|| {
                render_progressively(args, &renderer, started, from_script, resumed, halfway, &mut printed)
            })?;
            half_image = half;
            Done::Progressive(accumulation)
        }
    };
    let (ending, totals) = rendered.ending_and_totals();
    let mut outputs = Vec::new();
    let done = rendered.samples_done();
    if let Done::Progressive((accumulation, ..)) = &rendered
        && let Some(path) = job.checkpoint_path()
        && (ending != Ending::Complete || job.checkpoint.is_some())
    {
        accumulation.write(path)?;
        say!("checkpoint  {} ({} of {} samples per pixel)", path.display(), accumulation.samples().end, samples.end);
        outputs.push(OutputSummary {
            path: path.display().to_string(),
            kind: "checkpoint".into(),
            samples_per_pixel: accumulation.samples_done(),
        });
    }
    let simulates_light = settings.integrator.simulates_light();
    let image = match &rendered {
        Done::Progressive((accumulation, ..)) => (done > 0).then(|| accumulation.image()),
        Done::Adapted(image, _) => Some(image.clone()),
    };
    let mut denoise_ms = None;
    let image = match image {
        Some(raw) if denoising => {
            let started = Instant::now();
            let guides = pool.install(|| Guides::render(&scene, accel.as_ref(), &camera, &settings));
            let denoise_settings = DenoiseSettings::for_samples(done);
            // The half image tells the noise only as the first of two equal
            // halves: a render stopped early (time limit, signal) has fewer.
            let half = half_image.as_ref().filter(|_| done == spp);
            let clean = pool.install(|| denoise(&raw, half, &guides, &denoise_settings))?;
            denoise_ms = Some(started.elapsed().as_secs_f64() * 1e3);
            Some(clean)
        }
        other => other,
    };
    let tone_map = match &image {
        Some(image) => tone_map(&args.tone, simulates_light, image),
        None => ToneMap::default(),
    };
    let wrote_output = if let Done::Progressive((accumulation, ..)) = &rendered
        && is_accumulation(&output)
    {
        accumulation.write(&output)?;
        true
    } else if let Some(image) = &image {
        image.write(&output, &tone_map)?;
        true
    } else {
        false
    };
    if ending == Ending::Complete {
        for (kind, path) in &aov_outputs {
            let aov_settings = RenderSettings { integrator: *kind, ..settings.clone() };
            let (aov, _) = pool.install(|| render(&scene, accel.as_ref(), &camera, &aov_settings, &|_| {}));
            aov.write(path, &tone_map)?;
            outputs.push(OutputSummary {
                path: path.display().to_string(),
                kind: kind.to_string(),
                samples_per_pixel: aov_settings.samples_per_pixel,
            });
        }
    }

    let adaptive_samples = match &rendered {
        Done::Progressive(_) => None,
        Done::Adapted(_, outcome) => Some(AdaptiveSummary {
            fewest_samples: outcome.samples.iter().copied().min().unwrap_or(0),
            mean_samples: outcome.total_samples() as f64 / outcome.samples.len().max(1) as f64,
        }),
    };
    let build = accel.as_ref().build_stats();
    say!("scene       {scene_name}");
    say!("triangles   {}", scene.triangles.len());
    say!("load        {load_ms:.1} ms");
    say!("build       {:.1} ms ({})", build.build_ms, build.variant);
    match &rendered {
        Done::Progressive(_) => say!(
            "render      {:.1} ms, {}x{} at {} spp, {} threads, {} pass(es)",
            totals.render_seconds * 1e3,
            settings.width,
            settings.height,
            spp,
            pool.current_num_threads(),
            totals.passes
        ),
        Done::Adapted(_, outcome) => {
            let AdaptiveSummary { fewest_samples: fewest, mean_samples: mean } =
                adaptive_samples.as_ref().expect("an adaptive render has its figures");
            say!(
                "render      {:.1} ms, {}x{} at {fewest} to {} spp (mean {mean:.1}), {} threads, {} round(s)",
                totals.render_seconds * 1e3,
                settings.width,
                settings.height,
                outcome.samples_reached,
                pool.current_num_threads(),
                totals.passes
            );
            say!("{}", adaptive_summary(args, outcome, spp, settings.sampler));
        }
    }
    if let Some(ms) = denoise_ms {
        say!(
            "denoised    {ms:.1} ms (guided by albedo, normal, depth and emission at {GUIDE_SAMPLES} spp; --denoise off keeps \
             the samples' mean)"
        );
    }
    if job.is_part() {
        say!("part        rows {rows:?}, samples {samples:?} of every pixel");
    }
    let rays_per_second = totals.rays as f64 / totals.render_seconds.max(1e-9);
    say!("rays        {} ({:.3} Mrays/s)", totals.rays, rays_per_second * 1e-6);
    let stopped_by = match ending {
        Ending::Complete => None,
        Ending::TimeLimit => Some(format!("the time limit ({} s)", job.time_limit.unwrap_or_default())),
        Ending::Signal(signal) => Some(interrupt::name(signal).to_owned()),
    };
    if let Some(reason) = &stopped_by {
        say!("stopped     by {reason} with {done} of {} samples per pixel", samples.end);
    }
    let (mut exposure, mut looks) = (None, None);
    if wrote_output {
        let partial = if matches!(rendered, Done::Progressive(_)) && done < samples.len() as u32 {
            format!(" ({done} samples per pixel)")
        } else {
            String::new()
        };
        say!("wrote       {}{partial}", output.display());
        let kind = if is_accumulation(&output) { "accumulation" } else { "image" };
        outputs.insert(
            0,
            OutputSummary { path: output.display().to_string(), kind: kind.into(), samples_per_pixel: done },
        );
        if OutputFormat::from_path(&output).is_ok_and(|f| f == OutputFormat::Png) {
            let how = if args.tone.exposure.is_some() { "--exposure" } else { "automatic; --exposure sets it" };
            say!("exposure    {:+.1} stops ({how}), {} tone map", tone_map.exposure, tone_map.operator);
            exposure = Some(ExposureSummary::new(&tone_map, args.tone.exposure.is_none()));
        }
        if let Some(image) = &image {
            let phrasing = if from_script { Phrasing::Script } else { Phrasing::Options };
            looks = warn_if_illegible(image, &tone_map, args.tone.exposure.is_some(), phrasing);
        }
    } else {
        say!("wrote       nothing: no sample finished");
    }
    if ending == Ending::Complete {
        for (_, path) in &aov_outputs {
            say!("wrote       {}", path.display());
        }
    } else if !aov_outputs.is_empty() {
        say!("skipped     the AOVs (they are written when the render completes)");
    }
    if args.json {
        let summary = RenderSummary {
            scene: SceneSummary { name: scene_name.clone(), triangles: scene.triangles.len(), load_ms },
            plan,
            camera: camera_summary,
            room_light: room_light.as_ref().map(|light| light.position.to_array()),
            build: BuildSummary { variant: build.variant.to_string(), ms: build.build_ms },
            render: PassesSummary {
                ms: totals.render_seconds * 1e3,
                width: settings.width,
                height: settings.height,
                samples_per_pixel: spp,
                samples_done: done,
                sampler: settings.sampler.to_string(),
                threads: pool.current_num_threads(),
                passes: totals.passes,
                rays: totals.rays,
                mrays_per_second: rays_per_second * 1e-6,
                adaptive: adaptive_samples,
            },
            denoise_ms,
            exposure,
            legibility: looks.map(LegibilitySummary::new),
            part: job
                .is_part()
                .then_some(PartSummary { rows: [rows.start, rows.end], samples: [samples.start, samples.end] }),
            stopped_by,
            outputs,
        };
        printed = printed.and_then(|()| outln!("{}", serde_json::to_string_pretty(&summary)?));
    }
    match ending {
        Ending::Signal(signal) => Err(StoppedBySignal(signal).into()),
        Ending::TimeLimit if !wrote_output => bail!("no sample finished within the time limit"),
        _ => printed.map(|()| Rendered {
            image: image.map(|image| (image, tone_map)),
            seconds: totals.render_seconds,
            rays: totals.rays,
        }),
    }
}

/// How the samples were taken: passes over every pixel into an
/// accumulation (which can be checkpointed, split and merged), or rounds of
/// adaptive sampling.
enum Done {
    Progressive((Accumulation, Ending, Totals)),
    Adapted(HdrImage, AdaptiveOutcome),
}

impl Done {
    fn ending_and_totals(&self) -> (Ending, Totals) {
        match self {
            Done::Progressive((_, ending, totals)) => (*ending, *totals),
            Done::Adapted(_, outcome) => (
                Ending::Complete,
                Totals { passes: outcome.rounds.len() as u32, rays: outcome.rays(), render_seconds: outcome.seconds() },
            ),
        }
    }

    /// Samples per pixel done: of every pixel, or of the pixels that took most.
    fn samples_done(&self) -> u32 {
        match self {
            Done::Progressive((accumulation, ..)) => accumulation.samples_done(),
            Done::Adapted(_, outcome) => outcome.samples_reached,
        }
    }
}

/// The passes of a render that is not adaptive, from `resumed` if given:
/// the accumulation, why the passes ended, and what they took.
fn render_progressively(
    args: &RenderArgs,
    renderer: &Renderer<'_>,
    started: Instant,
    from_script: bool,
    resumed: Option<Accumulation>,
    halfway: Option<u32>,
    printed: &mut Result<()>,
) -> Result<((Accumulation, Ending, Totals), Option<HdrImage>)> {
    let job = &args.job;
    let settings = renderer.settings;
    let (rows, samples) = job.share(settings.height, settings.samples_per_pixel)?;
    let identity = RenderIdentity::new(renderer.scene, renderer.camera, settings);
    let mut accumulation = match resumed {
        None => Accumulation::new(identity, rows.clone(), samples.start),
        Some(resumed) => {
            let resume = job.resume.as_deref().unwrap_or(Path::new(""));
            let differences = identity.differences(resumed.identity());
            if !differences.is_empty() {
                let differences: Vec<String> = differences
                    .iter()
                    .map(|d| format!("{}: {} now, {} in the file", d.what, d.ours, d.theirs))
                    .collect();
                return Err(ResumeOfAnotherRender(format!(
                    "--resume {}: it is of another render ({}); resume it with the scene and options it was \
                     started with",
                    resume.display(),
                    differences.join("; ")
                ))
                .into());
            }
            if resumed.rows() != rows || resumed.samples().start != samples.start || resumed.samples().end > samples.end
            {
                return Err(ResumeOfAnotherRender(format!(
                    "--resume {}: it holds rows {:?} and samples {:?}, this job renders rows {rows:?} and \
                     samples {samples:?} (check --tile and --samples)",
                    resume.display(),
                    resumed.rows(),
                    resumed.samples()
                ))
                .into());
            }
            if !args.json && printed.is_ok() {
                *printed = outln!(
                    "resuming   {} at {} of {} samples per pixel",
                    resume.display(),
                    resumed.samples().end,
                    samples.end
                );
            }
            resumed
        }
    };
    let before = accumulation.samples().end;
    let pixels = rows.len() as u64 * settings.width as u64;
    let progress = Progress::new(pixels, before, samples.end);
    let progress = if from_script { progress.with_forecast() } else { progress };
    let (ending, totals, half) =
        run_passes(renderer, job, started, &mut accumulation, (samples.end, halfway), &progress)?;
    progress.finish();
    Ok(((accumulation, ending, totals), half))
}

/// Refuses what cannot go with adaptive sampling: whether a pixel goes on
/// depends on all its samples so far, so the render cannot be split,
/// checkpointed or resumed.
fn refuse_split_adaptive(args: &RenderArgs, output: &Path) -> Result<()> {
    let job = &args.job;
    let what = if job.samples.is_some() {
        Some("--samples")
    } else if job.tile.is_some() {
        Some("--tile")
    } else if job.resume.is_some() {
        Some("--resume")
    } else if job.checkpoint.is_some() {
        Some("--checkpoint")
    } else if job.time_limit.is_some() {
        Some("--time-limit (which stops to checkpoint; --time bounds an adaptive render)")
    } else if is_accumulation(output) {
        Some("an .accum output")
    } else {
        None
    };
    match what {
        Some(what) => bail!(
            "--noise and --time sample each pixel until its own samples say it is done, so the render cannot be \
             split, checkpointed or resumed: {what} cannot go with them; render in one go, or use --spp"
        ),
        None => Ok(()),
    }
}

/// What adaptive sampling did, and how to render the same image again.
fn adaptive_summary(args: &RenderArgs, outcome: &AdaptiveOutcome, spp: u32, sampler: PixelSampler) -> String {
    let why = if outcome.stopped_by_time {
        // The rounds of a fixed count are its passes: without a noise target they sum to a plain render.
        let sampler = if args.adaptive.noise.is_none() { format!(" --sampler {sampler}") } else { String::new() };
        format!(
            "--time {} ended it after {} samples per pixel; --spp {}{sampler} with the same options and no --time \
             renders the same image",
            args.adaptive.time.unwrap_or_default(),
            outcome.samples_reached,
            outcome.samples_reached
        )
    } else if args.adaptive.noise.is_none() {
        format!("every pixel took --spp {spp} within --time {}", args.adaptive.time.unwrap_or_default())
    } else if outcome.samples_reached < spp {
        "every pixel reached the noise target".to_owned()
    } else {
        format!("pixels still above the noise target stopped at --spp {spp}")
    };
    format!("adaptive    {} pixel samples in {} rounds; {why}", outcome.total_samples(), outcome.rounds.len())
}

/// Says so when the image came out almost black or almost white, with the
/// options that help; returns which.
fn warn_if_illegible(
    image: &HdrImage,
    tone_map: &ToneMap,
    exposure_given: bool,
    phrasing: Phrasing,
) -> Option<Legibility> {
    let looks = legibility(image, tone_map);
    match looks {
        Some(Legibility::AlmostBlack(fraction)) => {
            // A script's images are not exposed (as the course's are not).
            let exposure = if exposure_given && phrasing == Phrasing::Options { "raise --exposure, or " } else { "" };
            eprintln!(
                "warning: the image is almost black ({:.0}% of its pixels): the scene's lights may be too weak \
                 or hidden from the view, or the camera inside geometry; {exposure}add light ({}), or move the \
                 camera ({})",
                100.0 * fraction,
                phrasing.add_light(),
                phrasing.move_camera()
            );
        }
        Some(Legibility::AlmostWhite(fraction)) => {
            let what = match phrasing {
                Phrasing::Script => "the light is too strong for an image that is not exposed: dim the lights (pointlight col, skylight scale, material emissive)".to_owned(),
                Phrasing::Options if exposure_given => "lower --exposure or leave it out (automatic), or use --tonemap aces".to_owned(),
                Phrasing::Options => "lower --exposure, or use --tonemap aces".to_owned(),
            };
            eprintln!("warning: the image is almost white ({:.0}% of its pixels): {what}", 100.0 * fraction);
        }
        None => {}
    }
    looks
}

/// The exposure and tone map of an image's PNG ([`recipe::tone_map`]).
pub(crate) fn tone_map(args: &ToneArgs, simulates_light: bool, image: &HdrImage) -> ToneMap {
    recipe::tone_map(args.exposure, args.tonemap, simulates_light, image)
}

/// Refuses an image too large for this machine's memory before anything is
/// loaded or allocated: the render holds each pixel's exact sums (48 bytes),
/// a pass's sums beside them and the image of floats.
fn check_memory(width: u32, height: u32) -> Result<()> {
    const BYTES_PER_PIXEL: u64 = 48 + 48 + 12 + 12;
    let needed = width as u64 * height as u64 * BYTES_PER_PIXEL;
    if let Some(available) = available_memory()
        && needed > available
    {
        bail!(
            "--width {width} --height {height}: the render needs about {:.1} GiB of memory and {:.1} GiB are \
             available; render a smaller image, or split it with --tile and 'rtgi merge'",
            needed as f64 / (1u64 << 30) as f64,
            available as f64 / (1u64 << 30) as f64
        );
    }
    Ok(())
}

/// Memory available to new allocations (Linux's MemAvailable), if known.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Where an arbitrary output variable goes: beside the output, as `NAME.KIND.exr`.
fn aov_path(output: &Path, kind: Integrator) -> Result<PathBuf> {
    if !kind.is_aov() {
        let aovs: Vec<&str> = Integrator::ALL.iter().filter(|i| i.is_aov()).map(|i| i.name()).collect();
        bail!("--aov {kind}: not an output variable (use one of {})", aovs.join(", "));
    }
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(output.with_file_name(format!("{stem}.{kind}.exr")))
}
