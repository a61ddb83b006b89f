use std::io::IsTerminal;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};

use anyhow::bail;
use rtgi_image::{ToneMap, check_writable};
use rtgi_render::{EffectPlan, Integrator, PixelSampler, RenderSettings, render};

use crate::cli::RenderArgs;
use crate::common::{LoadedScene, apply_lighting, choose_camera, load_scene, thread_pool};

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    // Refuse unusable outputs before spending time on loading and rendering.
    check_writable(&args.output)?;
    let aov_outputs: Vec<(Integrator, PathBuf)> =
        args.aov.iter().map(|&kind| Ok((kind, aov_path(&args.output, kind)?))).collect::<Result<_>>()?;
    for (_, path) in &aov_outputs {
        check_writable(path)?;
    }

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
    print!("{}", EffectPlan::new(&scene, &settings));

    let pool = thread_pool(args.threads)?;

    let accel = pool.install(|| args.accel.build(&scene))?;
    let camera = choose_camera(&scene, accel.as_ref(), &args.camera, args.size.aspect())?;
    let (image, stats) = pool.install(|| {
        let bar = progress_bar(args.size.width as u64 * args.size.height as u64);
        let (image, stats) = render(&scene, accel.as_ref(), &camera, &settings, &|done| bar.inc(done));
        bar.finish_and_clear();
        (image, stats)
    });

    let tone_map = ToneMap { exposure: args.exposure, operator: args.tonemap };
    image.write(&args.output, &tone_map)?;
    for (kind, path) in &aov_outputs {
        let aov_settings = RenderSettings { integrator: *kind, ..settings.clone() };
        let (aov, _) = pool.install(|| render(&scene, accel.as_ref(), &camera, &aov_settings, &|_| {}));
        aov.write(path, &tone_map)?;
    }

    let build = accel.build_stats();
    println!("scene       {scene_name}");
    println!("triangles   {}", scene.triangles.len());
    println!("load        {load_ms:.1} ms");
    println!("build       {:.1} ms ({})", build.build_ms, build.variant);
    println!(
        "render      {:.1} ms, {}x{} at {} spp, {} threads",
        stats.render_ms,
        stats.width,
        stats.height,
        stats.samples_per_pixel,
        pool.current_num_threads()
    );
    println!("rays        {} ({:.3} Mrays/s)", stats.rays, stats.rays_per_second() * 1e-6);
    println!("wrote       {}", args.output.display());
    for (_, path) in &aov_outputs {
        println!("wrote       {}", path.display());
    }
    Ok(())
}

/// Where an arbitrary output variable goes: beside the output, as `NAME.KIND.exr`.
fn aov_path(output: &Path, kind: Integrator) -> Result<PathBuf> {
    if !kind.is_aov() {
        bail!("--aov {kind}: not an output variable (use albedo, normal, depth, position or cost)");
    }
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(output.with_file_name(format!("{stem}.{kind}.exr")))
}

/// A progress bar on standard error, drawn only when that is a terminal.
fn progress_bar(pixels: u64) -> ProgressBar {
    let target =
        if std::io::stderr().is_terminal() { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
    let bar = ProgressBar::with_draw_target(Some(pixels), target);
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed_precise} (eta {eta})") {
        bar.set_style(style);
    }
    bar
}
