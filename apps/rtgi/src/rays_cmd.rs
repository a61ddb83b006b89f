//! `rtgi rays`: ray files for `rtgi trace`, from a scene.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};
use rtgi_accel::ray_file::{RAY_BYTES, RayWriter};
use rtgi_math::Ray;
use rtgi_render::rays::{box_rays, primary_rays, surface_rays};

use crate::common::{LoadedScene, choose_camera, load_scene, refuse_inputs_as_outputs, write_atomically};
use crate::options::{AccelArgs, CameraArgs, OutputArgs, SeedArgs};
use crate::output::outln;

/// Which rays `rtgi rays` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum RayKind {
    /// One ray through the centre of every pixel of the scene's view (as `rtgi render` frames
    /// it), in 4×4 blocks of pixels: coherent, as a renderer traces them
    Camera,
    /// Origins uniform in the scene's bounding box, directions uniform on the sphere
    Random,
    /// Origins on the surfaces (triangles chosen by area), lifted off them, directions uniform
    /// on the sphere: the secondary rays of path tracing
    Surface,
}

/// `rtgi rays`: writes a ray file in the format `rtgi trace` reads.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "The ray file: 8 little-endian f32 per ray (origin, direction, t_min, t_max) [default: SCENE.rays.bin, \
     in the current folder]"
)))]
pub(crate) struct RaysArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Which rays
    #[arg(long, value_enum, default_value_t = RayKind::Camera)]
    pub(crate) kind: RayKind,

    /// Rays to write (random and surface rays); camera rays are one per pixel
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
    pub(crate) count: u32,

    /// Image width and height of camera rays
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=rtgi_job::MAX_IMAGE_SIDE as i64))]
    pub(crate) width: u32,

    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=rtgi_job::MAX_IMAGE_SIDE as i64))]
    pub(crate) height: u32,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) output: OutputArgs,
}

pub(crate) fn run(args: &RaysArgs) -> Result<()> {
    let inputs: Vec<(&str, &std::path::Path)> = args.scene.iter().map(|s| ("the scene", s.as_path())).collect();
    let output = args.output.or_named_after(args.scene.as_deref(), ".rays.bin");
    refuse_inputs_as_outputs(&[("-o", &output)], &inputs)?;
    let LoadedScene { scene, .. } = load_scene(args.scene.as_deref())?;
    let rays: Vec<Ray> = match args.kind {
        RayKind::Camera => {
            // The view `rtgi render` would use (the automatic framing probes the scene).
            let accel = args.accel.build(&scene)?;
            let camera = choose_camera(&scene, accel.as_ref(), &args.camera, args.width as f32 / args.height as f32)?;
            primary_rays(&camera, args.width, args.height)
        }
        RayKind::Random => box_rays(&scene, args.count as usize, args.seed.value),
        RayKind::Surface => surface_rays(&scene, args.count as usize, args.seed.value),
    };
    let mut bytes = RayWriter::new(Vec::with_capacity(rays.len() * RAY_BYTES));
    bytes.write_rays(&rays)?;
    write_atomically(&output, &bytes.into_inner())?;
    outln!("wrote       {} ({} {:?} rays)", output.display(), rays.len(), args.kind)?;
    Ok(())
}
