//! Commands that let users see their BVH: its boxes, and what traversal costs.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use rtgi_accel::boxes_obj;
use rtgi_image::{OutputFormat, ToneMap, check_writable, heat_map};
use rtgi_render::render_traversal_cost;

use crate::common::{LoadedScene, check_output_folder, choose_camera, load_scene, write_atomically};
use crate::options::{AccelArgs, CameraArgs, ImageSizeArgs, OutputArgs, ThreadArgs, parse_positive};
use crate::output::outln;

/// `rtgi bvh-boxes`: the boxes of some levels of a BVH as a wireframe-able mesh.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "OBJ file to write; each level becomes a group named level_N [default: SCENE.boxes.obj, in the current folder]"
)))]
pub(crate) struct BvhBoxesArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    /// Depths to export, separated by commas (the root is 0)
    #[arg(long, default_value = "0,1,2,3", value_delimiter = ',')]
    pub(crate) levels: Vec<usize>,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,
}

/// `rtgi heatmap`: nodes visited per pixel, in false colour.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "Output image: .png for the false-colour map, .exr for the raw counts [default: SCENE.heatmap.png, in the current folder]"
)))]
pub(crate) struct HeatmapArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    #[command(flatten)]
    pub(crate) size: ImageSizeArgs,

    /// Count that maps to the top of the colour scale [default: the image's maximum]
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    pub(crate) scale: Option<f32>,

    /// Count triangle tests instead of nodes visited
    #[arg(long)]
    pub(crate) triangles: bool,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,
}

/// Writes the boxes of the chosen levels as OBJ: eight corners and six
/// quads a box, one group per level, so that viewers can show or hide
/// levels and draw them as wireframes.
pub(crate) fn boxes(args: &BvhBoxesArgs) -> Result<()> {
    let output = args.output.or_named_after(args.scene.as_deref(), ".boxes.obj");
    check_output_folder(&output)?;
    if args.accel.accel.split_method().is_none() {
        bail!("--accel {}: only BVH variants have boxes to export", args.accel.accel);
    }
    let LoadedScene { scene, .. } = load_scene(args.scene.as_deref())?;
    let kind = args.accel.accel;
    let Some((obj, count)) =
        boxes_obj(kind, &scene.triangle_positions(), &args.accel.build.params_for(kind), &args.levels)
    else {
        bail!("{kind}: only BVH variants have boxes to export");
    };
    write_atomically(&output, obj.as_bytes())?;
    outln!("wrote {count} boxes of levels {:?} to {}", args.levels, output.display())?;
    Ok(())
}

/// Renders nodes visited (or triangles tested) per pixel in false colour.
pub(crate) fn heatmap(args: &HeatmapArgs) -> Result<()> {
    let output = args.output.or_named_after(args.scene.as_deref(), ".heatmap.png");
    let format = check_writable(&output)?;
    if args.scale.is_some_and(|s| !(s > 0.0 && s.is_finite())) {
        bail!("--scale must be a positive number");
    }
    if args.accel.accel.is_peer() {
        bail!(
            "--accel {}: a peer's backend does not report the nodes it visits or the triangles it tests",
            args.accel.accel
        );
    }
    let LoadedScene { scene, name, .. } = load_scene(args.scene.as_deref())?;
    let pool = args.threads.pool()?;
    let accel = pool.install(|| args.accel.build(&scene))?;
    let camera = choose_camera(&scene, accel.as_ref(), &args.camera, args.size.aspect())?;
    let (counts, total) =
        pool.install(|| render_traversal_cost(accel.as_ref(), &camera, args.size.width(), args.size.height(), &|_| {}));

    let channel = if args.triangles { 1 } else { 0 };
    let (map, scale, maximum) = heat_map(&counts, channel, args.scale);
    let image = match format {
        OutputFormat::Exr => counts,
        OutputFormat::Png => map,
    };
    image.write(&output, &ToneMap::default())?;
    let rays = total.rays.max(1) as f64;
    let what = if args.triangles { "triangle tests" } else { "nodes visited" };
    outln!("scene       {name}")?;
    outln!("accel       {}", accel.build_stats().variant)?;
    outln!(
        "per ray     {:.1} nodes visited, {:.1} triangle tests (mean); max {maximum} {what}",
        total.nodes_visited as f64 / rays,
        total.triangles_tested as f64 / rays
    )?;
    outln!("colour      0 (dark) to {scale} {what} (pale yellow)")?;
    outln!("wrote       {}", output.display())?;
    Ok(())
}
