use std::io::IsTerminal;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rtgi_accel::Accel;
use rtgi_image::{ToneMap, check_writable};
use rtgi_render::{PixelSampler, RenderSettings, frame_scene, render};
use rtgi_scene::{Camera, Scene};

use crate::cli::{CameraArgs, RenderArgs};
use crate::default_scene;

/// Field of view of the automatic framing when no camera is given.
const DEFAULT_FOV_DEGREES: f32 = 40.0;

pub(crate) fn run(args: &RenderArgs) -> Result<()> {
    // Refuse an unusable output before spending time on loading and rendering.
    check_writable(&args.output)?;

    let load_start = Instant::now();
    let (scene, scene_name) = match &args.scene {
        Some(path) => (Scene::load(path)?, path.display().to_string()),
        None => (default_scene::load()?, default_scene::NAME.to_owned()),
    };
    let load_ms = load_start.elapsed().as_secs_f64() * 1e3;
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }

    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        samples_per_pixel: args.spp,
        sampler: args.sampler.unwrap_or(if args.spp == 1 { PixelSampler::Center } else { PixelSampler::Uniform }),
        seed: args.seed,
        background: args.background,
    };

    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(threads) = args.threads {
        pool = pool.num_threads(threads as usize);
    }
    let pool = pool.build().context("cannot start worker threads")?;

    let accel = pool.install(|| args.accel.build(&scene));
    let camera = choose_camera(&scene, accel.as_ref(), &args.camera, args.width as f32 / args.height as f32)?;
    let (image, stats) = pool.install(|| {
        let bar = progress_bar(args.width as u64 * args.height as u64);
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

/// The scene's first camera, or an automatic framing, with any camera
/// options applied on top.
fn choose_camera(scene: &Scene, accel: &dyn Accel, options: &CameraArgs, aspect: f32) -> Result<Camera> {
    let fov = match options.fov {
        Some(degrees) if !(degrees > 0.0 && degrees < 180.0) => {
            bail!("--fov {degrees}: the field of view must be between 0 and 180 degrees")
        }
        Some(degrees) => degrees.to_radians(),
        None => scene.cameras.first().map_or(DEFAULT_FOV_DEGREES.to_radians(), |c| c.vertical_fov),
    };
    let mut camera = match scene.cameras.first() {
        Some(camera) => *camera,
        None => frame_scene(scene, accel, fov, aspect),
    };
    camera.vertical_fov = fov;
    if let Some(up) = options.up {
        camera.up = up;
    }
    if let Some(at) = options.at {
        camera.position = at;
        if options.look.is_none() {
            camera.direction = scene.bounds().centroid() - at;
        }
    }
    if let Some(look) = options.look {
        camera.direction = look - camera.position;
    }
    if !camera.is_valid() {
        bail!("the camera is degenerate: it must look somewhere other than its own position, and not along --up");
    }
    Ok(camera)
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
