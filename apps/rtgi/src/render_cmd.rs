use std::io::IsTerminal;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rtgi_image::{ToneMap, check_writable};
use rtgi_render::{PixelSampler, RenderSettings, render};

use crate::cli::RenderArgs;
use crate::common::{LoadedScene, choose_camera, load_scene, thread_pool};

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    // Refuse an unusable output before spending time on loading and rendering.
    check_writable(&args.output)?;

    let LoadedScene { scene, name: scene_name, load_ms } = load_scene(args.scene.as_deref())?;

    let settings = RenderSettings {
        width: args.size.width,
        height: args.size.height,
        samples_per_pixel: args.spp,
        sampler: args.sampler.unwrap_or(if args.spp == 1 { PixelSampler::Center } else { PixelSampler::Stratified }),
        seed: args.seed,
        background: args.background,
    };

    let pool = thread_pool(args.threads)?;

    let accel = pool.install(|| args.accel.build(&scene));
    let camera = choose_camera(&scene, accel.as_ref(), &args.camera, args.size.aspect())?;
    let (image, stats) = pool.install(|| {
        let bar = progress_bar(args.size.width as u64 * args.size.height as u64);
        let (image, stats) = render(&scene, accel.as_ref(), &camera, &settings, &|done| bar.inc(done));
        bar.finish_and_clear();
        (image, stats)
    });

    let tone_map = ToneMap { exposure: args.exposure, operator: args.tonemap };
    image.write(&args.output, &tone_map)?;

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
    Ok(())
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
