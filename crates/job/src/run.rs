//! Carrying out a [`RenderRequest`]: every check before long work, the
//! scene and its structure, the view, the passes (or adaptive rounds),
//! checkpoints, denoising, the tone map, the files, and the outcome.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rtgi_accel::Accel;
use rtgi_image::{HdrImage, Legibility, OutputFormat, ToneMap, check_writable, legibility};
use rtgi_render::adaptive::AdaptiveOutcome;
use rtgi_render::recipe::{self, Prepared};
use rtgi_render::{
    Accumulation, DenoiseSettings, EffectPlan, EnvironmentSpec, FilterGlossy, Guides, Integrator, PixelSampler,
    RenderIdentity, RenderSettings, denoise, render_adaptive,
};

use crate::cancel::CancelToken;
use crate::error::{Field, JobError};
use crate::files::{check_output_folder, refuse_inputs_as_outputs};
use crate::memory::check_memory;
use crate::observer::Observer;
use crate::outcome::{
    AdaptiveSummary, BuildSummary, CameraSummary, ExposureSummary, LegibilitySummary, OutputSummary, PartSummary,
    PassesSummary, RenderOutcome, SceneSummary, Warning,
};
use crate::passes::{Ending, Plan, Renderer, Totals, run_passes};
use crate::request::{Denoise, RenderRequest, is_accumulation, reshaped};
use crate::scene_source::LoadedScene;

/// Path regularisation of denoised previews unless the request says
/// otherwise: mirrors and smooth glass only, after diffuse bounces.
/// Measured by `rtgi experiment filter-glossy` (16 spp, denoised): 1.7x the
/// efficiency on the mirror Cornell box, where glossy lobes widened too
/// cost the conference room a quarter of its efficiency and 6% of its
/// light; deltas are the lobes light sampling cannot see through at all.
pub const PREVIEW_FILTER_GLOSSY: FilterGlossy = FilterGlossy { threshold: 1.0, deltas_only: true };

/// What a render made: its outcome, and the image it wrote with the tone
/// map of its PNG (`None` when no sample finished, or for an accumulation
/// that was never made an image).
#[derive(Debug)]
pub struct Rendered {
    /// What the render did.
    pub outcome: RenderOutcome,
    /// The image (denoised if it was) and the tone map of its PNG.
    pub image: Option<(HdrImage, ToneMap)>,
    /// The arbitrary output variables asked for ([`RenderRequest::aovs`]),
    /// in the order asked, when the render completed.
    pub aovs: Vec<(Integrator, HdrImage)>,
    /// How the passes ended.
    pub ending: Ending,
}

/// A scene loaded (and perhaps edited) by the front end, with a structure
/// already built over its triangles: rendered in place of the request's
/// scene and structure (a script's `commit`).
#[derive(Clone, Copy)]
pub struct Given<'a> {
    /// The scene.
    pub scene: &'a LoadedScene,
    /// A structure over `scene`'s triangles.
    pub accel: &'a dyn Accel,
}

impl std::fmt::Debug for Given<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Given").field("scene", &self.scene.name).finish_non_exhaustive()
    }
}

/// Carries out `request`: loads its scene, builds its structure, renders
/// and writes its files. `observer` hears it as it runs; `cancel` stops it
/// (it then writes what it has, and its outcome says why it stopped).
///
/// A render that stops early (time limit, cancelled) is `Ok` with the
/// samples it finished, unless it finished none under a time limit.
pub fn render(request: &RenderRequest, observer: &dyn Observer, cancel: &CancelToken) -> Result<Rendered, JobError> {
    render_with(request, None, observer, cancel, Destination::Files)
}

/// [`render`] of `given`'s scene and structure instead of the request's.
pub fn render_given(
    request: &RenderRequest,
    given: Given<'_>,
    observer: &dyn Observer,
    cancel: &CancelToken,
) -> Result<Rendered, JobError> {
    render_with(request, Some(given), observer, cancel, Destination::Files)
}

/// [`render`] that writes no file: the image and the AOVs asked for are
/// returned in [`Rendered`] only, and `request.output` is not used. The
/// image is made as for an EXR output (`Denoise::Auto` keeps the unbiased
/// mean); the fields that name files (a checkpoint, a file resumed) or
/// make a part of an image for a merge (a range of samples, a tile) are
/// refused ([`JobError::InMemory`]). With `given`, its scene and structure
/// are rendered instead of the request's, as in [`render_given`].
pub fn render_in_memory(
    request: &RenderRequest,
    given: Option<Given<'_>>,
    observer: &dyn Observer,
    cancel: &CancelToken,
) -> Result<Rendered, JobError> {
    let files = [
        (request.checkpoints.checkpoint.is_some(), Field::Checkpoint),
        (request.checkpoints.resume.is_some(), Field::Resume),
        (request.split.samples.is_some(), Field::Samples),
        (request.split.tile.is_some(), Field::Tile),
    ];
    if let Some((_, field)) = files.into_iter().find(|(asked, _)| *asked) {
        return Err(JobError::InMemory(field));
    }
    render_with(request, given, observer, cancel, Destination::Memory)
}

/// Where a render's image goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Destination {
    /// The request's output file, the AOVs beside it.
    Files,
    /// Nowhere but [`Rendered`].
    Memory,
}

/// Whether the image is denoised: `Auto` denoises PNG output of the
/// integrators that simulate light (EXR, accumulations and images kept in
/// memory, `output` `None`, keep the unbiased mean), `On` any image of those integrators.
fn denoises(choice: Denoise, simulates_light: bool, output: Option<&Path>) -> bool {
    let png = output.is_some_and(|output| OutputFormat::from_path(output).is_ok_and(|f| f == OutputFormat::Png));
    simulates_light
        && !output.is_some_and(is_accumulation)
        && match choice {
            Denoise::Auto => png,
            Denoise::On => true,
            Denoise::Off => false,
        }
}

/// Checks before long work that `path` can take an image (.png, .exr) or an accumulation (.accum).
pub fn check_output(path: &Path) -> Result<(), JobError> {
    if is_accumulation(path) {
        return check_output_folder(path, Field::Output);
    }
    check_writable(path).map(|_| ()).map_err(|e| match e {
        rtgi_image::ImageError::UnsupportedFormat { .. } => JobError::OutputFormat { path: path.to_owned() },
        other => other.into(),
    })
}

/// Refuses what cannot go with adaptive sampling: whether a pixel goes on
/// depends on all its samples so far, so the render cannot be split,
/// checkpointed or resumed.
fn refuse_split_adaptive(request: &RenderRequest) -> Result<(), JobError> {
    let (split, checkpoints) = (&request.split, &request.checkpoints);
    let field = if split.samples.is_some() {
        Some(Field::Samples)
    } else if split.tile.is_some() {
        Some(Field::Tile)
    } else if checkpoints.resume.is_some() {
        Some(Field::Resume)
    } else if checkpoints.checkpoint.is_some() {
        Some(Field::Checkpoint)
    } else if checkpoints.time_limit.is_some() {
        Some(Field::TimeLimit)
    } else if request.writes_accumulation() {
        Some(Field::Output)
    } else {
        None
    };
    field.map_or(Ok(()), |field| Err(JobError::AdaptiveSplit(field)))
}

/// Where an arbitrary output variable goes: beside the output, as `NAME.KIND.exr`.
pub fn aov_path(output: &Path, kind: Integrator) -> Result<PathBuf, JobError> {
    if !kind.is_aov() {
        let aovs: Vec<&str> = Integrator::ALL.iter().filter(|i| i.is_aov()).map(|i| i.name()).collect();
        return Err(JobError::NotAnAov { aov: kind, allowed: aovs.join(", ") });
    }
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(output.with_file_name(format!("{stem}.{kind}.exr")))
}

/// Every check that needs no scene: the outputs, the options that cannot
/// go together, the files that must not be overwritten. Returns the AOVs
/// with their files (with no files for a render in memory).
fn check_request(request: &RenderRequest, destination: Destination) -> Result<Vec<(Integrator, PathBuf)>, JobError> {
    let output = &request.output;
    if destination == Destination::Memory {
        for &kind in &request.aovs {
            aov_path(output, kind)?;
        }
        if request.denoise == Denoise::On && !request.lighting.integrator.simulates_light() {
            return Err(JobError::DenoiseNotLight(request.lighting.integrator));
        }
        return Ok(request.aovs.iter().map(|&kind| (kind, PathBuf::new())).collect());
    }
    check_output(output)?;
    if request.sampling.adaptive().is_some() {
        refuse_split_adaptive(request)?;
    }
    if request.is_part() && !request.writes_accumulation() {
        return Err(JobError::PartNotAccumulated);
    }
    if request.denoise == Denoise::On {
        if request.writes_accumulation() {
            return Err(JobError::DenoiseAccumulation { output: output.clone() });
        }
        if !request.lighting.integrator.simulates_light() {
            return Err(JobError::DenoiseNotLight(request.lighting.integrator));
        }
    }
    if request.is_part() && !request.aovs.is_empty() {
        return Err(JobError::AovOfPart);
    }
    let aovs: Vec<(Integrator, PathBuf)> =
        request.aovs.iter().map(|&kind| Ok((kind, aov_path(output, kind)?))).collect::<Result<_, JobError>>()?;
    for (_, path) in &aovs {
        check_writable(path)?;
    }
    if let Some(path) = &request.checkpoints.checkpoint {
        check_output_folder(path, Field::Checkpoint)?;
    }
    let mut inputs: Vec<(String, &Path)> =
        request.scene.path().map(|path| ("the scene".to_owned(), path)).into_iter().collect();
    if let Some(EnvironmentSpec::File(path)) = &request.lighting.environment {
        inputs.push((Field::Environment.name().to_owned(), path));
    }
    refuse_inputs_as_outputs(&outputs(request, &aovs), &inputs)?;
    Ok(aovs)
}

/// The files a render writes, by the field that names them.
fn outputs<'a>(request: &'a RenderRequest, aovs: &'a [(Integrator, PathBuf)]) -> Vec<(Field, &'a Path)> {
    [(Field::Output, request.output.as_path())]
        .into_iter()
        .chain(aovs.iter().map(|(_, path)| (Field::Aovs, path.as_path())))
        .chain(request.checkpoints.checkpoint.as_deref().map(|path| (Field::Checkpoint, path)))
        .collect()
}

/// How the samples were taken: passes over every pixel into an
/// accumulation (which can be checkpointed, split and merged), or rounds of
/// adaptive sampling.
enum Done {
    Progressive(Accumulation, Ending, Totals),
    Adapted(HdrImage, AdaptiveOutcome),
}

impl Done {
    fn ending_and_totals(&self) -> (Ending, Totals) {
        match self {
            Done::Progressive(_, ending, totals) => (ending.clone(), *totals),
            Done::Adapted(_, outcome) => (
                Ending::Complete,
                Totals { passes: outcome.rounds.len() as u32, rays: outcome.rays(), render_seconds: outcome.seconds() },
            ),
        }
    }

    /// Samples per pixel done: of every pixel, or of the pixels that took most.
    fn samples_done(&self) -> u32 {
        match self {
            Done::Progressive(accumulation, ..) => accumulation.samples_done(),
            Done::Adapted(_, outcome) => outcome.samples_reached,
        }
    }
}

fn render_with(
    request: &RenderRequest,
    given: Option<Given<'_>>,
    observer: &dyn Observer,
    cancel: &CancelToken,
    destination: Destination,
) -> Result<Rendered, JobError> {
    let started = Instant::now();
    let writes = destination == Destination::Files;
    let aov_outputs = check_request(request, destination)?;
    let resumed = request.checkpoints.resume.as_deref().map(Accumulation::read).transpose()?;
    let (width, height, spp) = (request.size.width(), request.size.height(), request.samples_per_pixel());
    check_memory(width, height)?;
    let pool = thread_pool(request.threads)?;

    let mut warnings = Vec::new();
    let mut warn = |warning: Warning| {
        observer.warning(&warning);
        warnings.push(warning);
    };
    let loaded;
    let (LoadedScene { scene, name: scene_name, load_ms }, committed) = match given {
        Some(Given { scene, accel }) => (scene, Some(accel)),
        None => {
            loaded = pool.install(|| request.scene.load())?;
            for message in &loaded.scene.warnings {
                warn(Warning::Scene { message: message.clone() });
            }
            (&loaded, None)
        }
    };
    let mut scene = scene.clone();
    // The files the scene read (textures, material libraries, buffers) are inputs too.
    let sources: Vec<(String, &Path)> = scene
        .sources
        .iter()
        .map(|path| (format!("a file of the scene ({})", path.display()), path.as_path()))
        .collect();
    if writes {
        refuse_inputs_as_outputs(&outputs(request, &aov_outputs), &sources)?;
    }

    let adaptive = request.sampling.adaptive();
    let mut settings = RenderSettings {
        width,
        height,
        samples_per_pixel: spp,
        // Rounds of adaptive sampling take the first samples of each pixel's sequence.
        sampler: request.sampling.sampler.unwrap_or(if adaptive.is_some() {
            PixelSampler::Sobol
        } else {
            recipe::default_sampler(spp)
        }),
        seed: request.sampling.seed,
        background: request.background,
        adaptive,
        ..RenderSettings::default()
    };
    if let Some(adaptive) = &adaptive {
        adaptive.check(&settings)?;
    }
    recipe::apply_lighting(&request.lighting, &mut scene, &mut settings)?;
    let built;
    let accel: &dyn Accel = match committed {
        Some(committed) => committed,
        None => {
            built = pool.install(|| {
                request.structure.kind.try_build(&scene.triangle_positions(), &request.structure.params())
            })?;
            built.as_ref()
        }
    };
    let Prepared { camera: chosen, room_light } = recipe::prepare(&mut scene, accel, &mut settings, &request.camera)?;
    if let Some(fraction) = chosen.blocked {
        warn(Warning::CameraInsideGeometry { fraction });
    }
    let placed = request.camera.at.is_some() || request.camera.look.is_some();
    let camera_summary = CameraSummary::new(&chosen, request.camera.index, placed, scene.cameras.len());
    let camera = chosen.camera;
    // A file camera's aspect ratio shapes the image unless its size was given.
    if let Some(aspect) = camera.aspect.filter(|&a| a.is_finite() && a > 0.0 && !request.size.given()) {
        (settings.width, settings.height) = reshaped(settings.width, settings.height, aspect);
        check_memory(settings.width, settings.height)?;
    }
    let (rows, samples) = request.split.share(settings.height, spp)?;

    let denoising =
        denoises(request.denoise, settings.integrator.simulates_light(), writes.then_some(request.output.as_path()));
    // No filter asked for: the preview's when denoised; a threshold of 0 turns it off.
    settings.filter_glossy = match request.lighting.filter_glossy {
        None if denoising => Some(PREVIEW_FILTER_GLOSSY),
        Some(filter) if filter.threshold > 0.0 => Some(filter),
        _ => None,
    };
    let plan = EffectPlan::new(&scene, &settings);
    observer.planned(&plan, &chosen, room_light.as_ref());

    let renderer = Renderer { scene: &scene, accel, camera: &camera, settings: &settings };
    // The denoiser learns each pixel's noise from the image at half its samples.
    let halfway = (denoising && !request.is_part() && spp >= 2).then_some(spp / 2);
    let mut half_image = None;
    let rendered = match adaptive {
        Some(_) => {
            let (image, outcome) = pool
                .install(|| render_adaptive(&scene, accel, &camera, &settings, &mut |round| observer.round(round)))?;
            Done::Adapted(image, outcome)
        }
        None => {
            let identity = RenderIdentity::new(&scene, &camera, &settings);
            let mut accumulation = match resumed {
                None => Accumulation::new(identity, rows.clone(), samples.start),
                Some(resumed) => {
                    let path = request.checkpoints.resume.clone().unwrap_or_default();
                    check_resumed(&identity, &resumed, path.clone(), &rows, &samples)?;
                    observer.resuming(&path, resumed.samples().end, samples.end);
                    resumed
                }
            };
            let plan = Plan { checkpoints: &request.checkpoints, started, last: samples.end, halfway, cancel };
            let pixels = rows.len() as u64 * settings.width as u64;
            observer.passes_started(pixels, accumulation.samples().end, samples.end);
            // In the pool: the passes' tiles run on its threads, however
            // many the process's global pool has.
            let (ending, totals, half) = pool.install(|| run_passes(renderer, &plan, &mut accumulation, observer))?;
            observer.passes_ended();
            half_image = half;
            Done::Progressive(accumulation, ending, totals)
        }
    };
    let (ending, totals) = rendered.ending_and_totals();
    let done = rendered.samples_done();
    let mut outputs = Vec::new();
    if let Done::Progressive(accumulation, ..) = &rendered
        && let Some(path) = request.checkpoints.path()
        && (ending != Ending::Complete || request.checkpoints.checkpoint.is_some())
    {
        accumulation.write(path)?;
        observer.checkpoint(path, accumulation.samples().end);
        outputs.push(OutputSummary {
            path: path.display().to_string(),
            kind: "checkpoint".into(),
            samples_per_pixel: accumulation.samples_done(),
        });
    }
    let simulates_light = settings.integrator.simulates_light();
    let image = match &rendered {
        Done::Progressive(accumulation, ..) => (done > 0).then(|| accumulation.image()),
        Done::Adapted(image, _) => Some(image.clone()),
    };
    let mut denoise_ms = None;
    let image = match image {
        Some(raw) if denoising => {
            let started = Instant::now();
            let guides = pool.install(|| Guides::render(&scene, accel, &camera, &settings));
            let denoise_settings = DenoiseSettings::for_samples(done);
            // The half image tells the noise only as the first of two equal
            // halves: a render stopped early (time limit, cancelled) has fewer.
            let half = half_image.as_ref().filter(|_| done == spp);
            let clean = pool.install(|| denoise(&raw, half, &guides, &denoise_settings))?;
            denoise_ms = Some(started.elapsed().as_secs_f64() * 1e3);
            Some(clean)
        }
        other => other,
    };
    let tone_map = match &image {
        Some(image) => recipe::tone_map(request.tone.exposure, request.tone.operator, simulates_light, image),
        None => ToneMap::default(),
    };
    let wrote_output = if !writes {
        false
    } else if let Done::Progressive(accumulation, ..) = &rendered
        && request.writes_accumulation()
    {
        accumulation.write(&request.output)?;
        true
    } else if let Some(image) = &image {
        image.write(&request.output, &tone_map)?;
        true
    } else {
        false
    };
    let (mut aovs_written, mut aovs) = (Vec::new(), Vec::new());
    if ending == Ending::Complete {
        for (kind, path) in &aov_outputs {
            let aov_settings = RenderSettings { integrator: *kind, ..settings.clone() };
            let (aov, _) = pool.install(|| rtgi_render::render(&scene, accel, &camera, &aov_settings, &|_| {}));
            if writes {
                aov.write(path, &tone_map)?;
                aovs_written.push(OutputSummary {
                    path: path.display().to_string(),
                    kind: kind.to_string(),
                    samples_per_pixel: aov_settings.samples_per_pixel,
                });
            }
            aovs.push((*kind, aov));
        }
    }
    let (mut exposure, mut looks) = (None, None);
    if wrote_output {
        let kind = if request.writes_accumulation() { "accumulation" } else { "image" };
        outputs.insert(
            0,
            OutputSummary { path: request.output.display().to_string(), kind: kind.into(), samples_per_pixel: done },
        );
        if OutputFormat::from_path(&request.output).is_ok_and(|f| f == OutputFormat::Png) {
            exposure = Some(ExposureSummary::new(&tone_map, request.tone.exposure.is_none()));
        }
    }
    // The image is kept: written, or returned from a render in memory.
    let kept = if writes { wrote_output } else { image.is_some() };
    if kept && let Some(image) = &image {
        looks = legibility(image, &tone_map);
        match looks {
            Some(Legibility::AlmostBlack(fraction)) => warn(Warning::AlmostBlack { fraction }),
            Some(Legibility::AlmostWhite(fraction)) => warn(Warning::AlmostWhite { fraction }),
            None => {}
        }
    }
    outputs.extend(aovs_written);
    if ending == Ending::TimeLimit && !kept {
        return Err(JobError::NoSampleInTime);
    }

    let adaptive = match &rendered {
        Done::Progressive(..) => None,
        Done::Adapted(_, outcome) => Some(AdaptiveSummary {
            fewest_samples: outcome.samples.iter().copied().min().unwrap_or(0),
            mean_samples: outcome.total_samples() as f64 / outcome.samples.len().max(1) as f64,
            samples_reached: outcome.samples_reached,
            total_samples: outcome.total_samples(),
            rounds: outcome.rounds.len() as u32,
            stopped_by_time: outcome.stopped_by_time,
        }),
    };
    let build = accel.build_stats();
    let stopped_by = match &ending {
        Ending::Complete => None,
        Ending::TimeLimit => Some(format!("the time limit ({} s)", request.checkpoints.time_limit.unwrap_or_default())),
        Ending::Cancelled(reason) => Some(reason.clone()),
    };
    let outcome = RenderOutcome {
        scene: SceneSummary { name: scene_name.clone(), triangles: scene.triangles.len(), load_ms: *load_ms },
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
            mrays_per_second: totals.rays as f64 / totals.render_seconds.max(1e-9) * 1e-6,
            adaptive,
        },
        denoise_ms,
        exposure,
        legibility: looks.map(LegibilitySummary::new),
        part: request
            .is_part()
            .then_some(PartSummary { rows: [rows.start, rows.end], samples: [samples.start, samples.end] }),
        stopped_by,
        outputs,
        warnings,
    };
    Ok(Rendered { outcome, image: image.map(|image| (image, tone_map)), aovs, ending })
}

/// Refuses an accumulation resumed that is of another render, or of
/// another share of it.
fn check_resumed(
    identity: &RenderIdentity,
    resumed: &Accumulation,
    path: PathBuf,
    rows: &std::ops::Range<u32>,
    samples: &std::ops::Range<u32>,
) -> Result<(), JobError> {
    let differences = identity.differences(resumed.identity());
    if !differences.is_empty() {
        let differences =
            differences.iter().map(|d| format!("{}: {} now, {} in the file", d.what, d.ours, d.theirs)).collect();
        return Err(JobError::ResumeOfAnotherRender { path, differences });
    }
    if resumed.rows() != *rows || resumed.samples().start != samples.start || resumed.samples().end > samples.end {
        return Err(JobError::ResumeOfAnotherShare {
            path,
            theirs_rows: resumed.rows(),
            theirs_samples: resumed.samples(),
            rows: rows.clone(),
            samples: samples.clone(),
        });
    }
    Ok(())
}

/// A pool of `threads` worker threads, or one per core.
pub fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool, JobError> {
    let builder = rayon::ThreadPoolBuilder::new();
    let builder = match threads {
        Some(threads) => builder.num_threads(threads as usize),
        None => builder,
    };
    Ok(builder.build()?)
}
