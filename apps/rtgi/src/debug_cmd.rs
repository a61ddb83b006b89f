//! Commands that let users see their BVH: its boxes, and what traversal costs.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use rtgi_accel::{Accel, AccelKind, BuildParams, Bvh, Bvh4, Bvh8};
use rtgi_image::{HdrImage, OutputFormat, ToneMap, check_writable, heat_colour};
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
    let (obj, count) = boxes_obj(kind, &scene.triangle_positions(), &args.accel.build.params_for(kind), &args.levels)?;
    write_atomically(&output, obj.as_bytes())?;
    outln!("wrote {count} boxes of levels {:?} to {}", args.levels, output.display())?;
    Ok(())
}

/// The boxes of a BVH's nodes at `levels` (the root is 0) as an OBJ file,
/// a group `level_N` for each level, and how many boxes it holds.
pub(crate) fn boxes_obj(
    kind: AccelKind,
    triangles: &[[rtgi_math::Vec3; 3]],
    params: &BuildParams,
    levels: &[usize],
) -> Result<(String, usize)> {
    let Some(method) = kind.split_method() else {
        bail!("{kind}: only BVH variants have boxes to export");
    };
    let (boxes, stats) = match kind.node_width() {
        Some(4) => {
            let bvh = Bvh4::new(triangles, method, params);
            (bvh.boxes_at_depths(levels), bvh.build_stats().clone())
        }
        Some(8) => {
            let bvh = Bvh8::new(triangles, method, params);
            (bvh.boxes_at_depths(levels), bvh.build_stats().clone())
        }
        _ => {
            let bvh = Bvh::new(triangles, method, params);
            (bvh.boxes_at_depths(levels), bvh.build_stats().clone())
        }
    };
    let mut obj = format!(
        "# BVH boxes of levels {:?}, {} ({} build, {} nodes, depth {}), written by rtgi\n",
        levels,
        kind,
        method.name(),
        stats.nodes,
        stats.depth
    );
    let mut current_level = None;
    for (index, (level, aabb)) in boxes.iter().enumerate() {
        if current_level != Some(*level) {
            let _ = writeln!(obj, "g level_{level}");
            current_level = Some(*level);
        }
        for corner in 0..8 {
            let pick = |bit: usize, axis: usize| if corner & bit == 0 { aabb.min[axis] } else { aabb.max[axis] };
            let _ = writeln!(obj, "v {} {} {}", pick(1, 0), pick(2, 1), pick(4, 2));
        }
        let base = 8 * index + 1;
        for face in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
            let _ = writeln!(obj, "f {} {} {} {}", base + face[0], base + face[1], base + face[2], base + face[3]);
        }
    }
    Ok((obj, boxes.len()))
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

    let channel = |p: rtgi_math::Vec3| if args.triangles { p.y } else { p.x };
    let maximum = counts.pixels().iter().map(|&p| channel(p)).fold(0.0f32, f32::max);
    let scale = args.scale.unwrap_or(maximum.max(1.0));
    let image = match format {
        OutputFormat::Exr => counts,
        OutputFormat::Png => {
            let pixels = counts.pixels().iter().map(|&p| heat_colour(channel(p) / scale)).collect();
            HdrImage::from_pixels(args.size.width(), args.size.height(), pixels).expect("one colour per pixel")
        }
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
