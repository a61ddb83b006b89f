use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use rtgi_image::{ToneMap, check_writable};
use rtgi_render::{Accumulation, EffectPlan, Integrator, PixelSampler, RenderIdentity, RenderSettings, render};

use crate::cli::EnvironmentArg;
use crate::cli::RenderArgs;
use crate::common::{
    LoadedScene, apply_lighting, check_output_folder, choose_camera, load_scene, refuse_inputs_as_outputs, thread_pool,
};
use crate::interrupt;
use crate::output::{out, outln};
use crate::progress::Progress;
use crate::render_job::{Ending, Renderer, StoppedBySignal, run_passes};

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
        check_writable(path).map(|_| ()).map_err(|e| {
            anyhow::anyhow!("{e}").context("the output is an image (.png, .exr) or a render's accumulation (.accum)")
        })
    }
}

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    let started = Instant::now();
    let job = &args.job;
    // Refuse unusable outputs and options before spending time on loading and rendering.
    check_output(&args.output)?;
    if job.is_part() && !is_accumulation(&args.output) {
        bail!(
            "--samples and --tile render a part of an image: write it to an .{ACCUMULATION_EXTENSION} file \
             (-o part.{ACCUMULATION_EXTENSION}) and put the parts together with 'rtgi merge'"
        );
    }
    if job.is_part() && !args.aov.is_empty() {
        bail!("--aov is for whole renders, not with --samples or --tile");
    }
    let aov_outputs: Vec<(Integrator, PathBuf)> =
        args.aov.iter().map(|&kind| Ok((kind, aov_path(&args.output, kind)?))).collect::<Result<_>>()?;
    for (_, path) in &aov_outputs {
        check_writable(path)?;
    }
    if let Some(path) = &job.checkpoint {
        check_output_folder(path)?;
    }
    let outputs: Vec<(&str, &Path)> = [("-o", args.output.as_path())]
        .into_iter()
        .chain(aov_outputs.iter().map(|(_, path)| ("--aov", path.as_path())))
        .chain(job.checkpoint.as_deref().map(|path| ("--checkpoint", path)))
        .collect();
    let mut inputs: Vec<(&str, &Path)> = args.scene.as_deref().map(|path| ("the scene", path)).into_iter().collect();
    if let Some(EnvironmentArg::File(path)) = &args.lighting.environment {
        inputs.push(("--environment", path));
    }
    refuse_inputs_as_outputs(&outputs, &inputs)?;
    let resumed = job.resume.as_deref().map(Accumulation::read).transpose()?;
    check_memory(args.size.width, args.size.height)?;

    let LoadedScene { mut scene, name: scene_name, load_ms } = load_scene(args.scene.as_deref())?;

    let spp = args.spp.unwrap_or(if args.lighting.integrator.simulates_light() { 16 } else { 1 });
    let mut settings = RenderSettings {
        width: args.size.width,
        height: args.size.height,
        samples_per_pixel: spp,
        sampler: args.sampler.unwrap_or(if spp == 1 { PixelSampler::Center } else { PixelSampler::Stratified }),
        seed: args.seed,
        background: args.background,
        ..RenderSettings::default()
    };
    apply_lighting(&args.lighting, &mut scene, &mut settings)?;
    let (rows, samples) = job.share(settings.height, spp)?;
    // What is printed goes on standard output; a reader that goes away
    // (`| head`) does not stop the render, and the first failed write is
    // returned once the outputs are written.
    let mut printed = out!("{}", EffectPlan::new(&scene, &settings));
    macro_rules! say {
        ($($arg:tt)*) => {
            printed = printed.and_then(|()| outln!($($arg)*))
        };
    }

    let pool = thread_pool(args.threads)?;

    let accel = pool.install(|| args.accel.build(&scene))?;
    let camera = choose_camera(&scene, accel.as_ref(), &args.camera, args.size.aspect())?;
    let identity = RenderIdentity::new(&scene, &camera, &settings);
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
                bail!(
                    "--resume {}: it is of another render ({}); resume it with the scene and options it was \
                     started with",
                    resume.display(),
                    differences.join("; ")
                );
            }
            if resumed.rows() != rows || resumed.samples().start != samples.start || resumed.samples().end > samples.end
            {
                bail!(
                    "--resume {}: it holds rows {:?} and samples {:?}, this job renders rows {rows:?} and \
                     samples {samples:?} (check --tile and --samples)",
                    resume.display(),
                    resumed.rows(),
                    resumed.samples()
                );
            }
            say!("resuming   {} at {} of {} samples per pixel", resume.display(), resumed.samples().end, samples.end);
            resumed
        }
    };

    interrupt::install()?;
    let before = accumulation.samples().end;
    let pixels = rows.len() as u64 * settings.width as u64;
    let progress = Progress::new(pixels, before, samples.end);
    let renderer = Renderer { scene: &scene, accel: accel.as_ref(), camera: &camera, settings: &settings };
    let (ending, totals) =
        pool.install(|| run_passes(&renderer, job, started, &mut accumulation, samples.end, &progress))?;
    progress.finish();

    // Write what there is, whatever stopped the render.
    let done = accumulation.samples_done();
    if let Some(path) = job.checkpoint_path()
        && (ending != Ending::Complete || job.checkpoint.is_some())
    {
        accumulation.write(path)?;
        say!("checkpoint  {} ({} of {} samples per pixel)", path.display(), accumulation.samples().end, samples.end);
    }
    let tone_map = ToneMap { exposure: args.exposure, operator: args.tonemap };
    let wrote_output = if is_accumulation(&args.output) {
        accumulation.write(&args.output)?;
        true
    } else if done > 0 {
        accumulation.image().write(&args.output, &tone_map)?;
        true
    } else {
        false
    };
    if ending == Ending::Complete {
        for (kind, path) in &aov_outputs {
            let aov_settings = RenderSettings { integrator: *kind, ..settings.clone() };
            let (aov, _) = pool.install(|| render(&scene, accel.as_ref(), &camera, &aov_settings, &|_| {}));
            aov.write(path, &tone_map)?;
        }
    }

    let build = accel.build_stats();
    say!("scene       {scene_name}");
    say!("triangles   {}", scene.triangles.len());
    say!("load        {load_ms:.1} ms");
    say!("build       {:.1} ms ({})", build.build_ms, build.variant);
    say!(
        "render      {:.1} ms, {}x{} at {} spp, {} threads, {} pass(es)",
        totals.render_seconds * 1e3,
        settings.width,
        settings.height,
        spp,
        pool.current_num_threads(),
        totals.passes
    );
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
        say!("stopped     by {reason} with {} of {} samples per pixel", accumulation.samples().end, samples.end);
    }
    if wrote_output {
        let partial = if done < samples.len() as u32 { format!(" ({done} samples per pixel)") } else { String::new() };
        say!("wrote       {}{partial}", args.output.display());
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
    match ending {
        Ending::Signal(signal) => Err(StoppedBySignal(signal).into()),
        Ending::TimeLimit if !wrote_output => bail!("no sample finished within the time limit"),
        _ => printed,
    }
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
        bail!("--aov {kind}: not an output variable (use albedo, normal, depth, position or cost)");
    }
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(output.with_file_name(format!("{stem}.{kind}.exr")))
}
