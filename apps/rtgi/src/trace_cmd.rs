//! `rtgi trace`: rays from a file, through the chosen structure, hits to a
//! file (the format is `rtgi_accel::ray_file`'s).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use rtgi_accel::TraversalCounters;
use rtgi_accel::parallel::{
    BATCH_RAYS, GRID_TILE, HitFilter, count_work, intersect_all, intersect_each, intersect_grid, occluded_all,
    occluded_each, occluded_grid,
};
use rtgi_accel::ray_file::{self, HitWriter, RayReader};
use rtgi_image::write_atomically_with;
use rtgi_render::{AlphaTest, has_alpha};

use crate::common::{LoadedScene, check_output_folder, load_scene, refuse_inputs_as_outputs};
use crate::options::{AccelArgs, OutputArgs, ThreadArgs};

/// `rtgi trace`: rays in, hits out, for tests and comparisons with other ray tracers.
///
/// Files are little-endian without a header. A ray is 8 × f32: origin x y z,
/// direction x y z, t_min, t_max. A hit is 16 bytes: t (f32; +inf for a
/// miss), triangle (u32; 0xFFFFFFFF for a miss), beta (f32), gamma (f32).
/// With --any-hit, triangle is 0 when the ray is occluded and 0xFFFFFFFF when
/// not, and t, beta and gamma are 0. Triangles are numbered in file order
/// (an OBJ polygon becomes a fan of triangles, in order). The rays are read,
/// traced and written in chunks, so a file of any size (or a stream) fits
/// in memory; a ray with a NaN or infinite origin or direction, a zero
/// direction or a NaN bound is refused, naming its index.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.visible_alias("out").help(
    "Binary file of hits to write, 16 bytes each [default: RAYS.hits.bin, after the ray file, in the current folder]"
)))]
pub(crate) struct TraceArgs {
    /// Scene file (.obj, .gltf, .glb or .toml)
    pub(crate) scene: PathBuf,

    /// Binary file of rays (32 bytes each)
    #[arg(long)]
    pub(crate) rays: PathBuf,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    /// Answer whether each ray is occluded (any hit) instead of its closest hit
    #[arg(long)]
    pub(crate) any_hit: bool,

    /// Trace cut-outs (alpha-masked and blended materials) as solid surfaces; by default
    /// rays pass through their holes as in renders, and blended surfaces count where their
    /// alpha exceeds one half
    #[arg(long)]
    pub(crate) no_alpha: bool,

    /// The rays are a camera grid WIDTH rays wide in scanline order (row by row): they are traced in
    /// 4x4 tiles, which the wide BVHs take as packets of 16, instead of runs along a row; the hits are
    /// the same, in the file's order. Only for files in scanline order: `rtgi rays --kind camera`
    /// writes 4x4 blocks already, which this would scatter (the bunny's traced 2x slower)
    #[arg(long, value_name = "WIDTH", value_parser = clap::value_parser!(u32).range(1..=rtgi_job::MAX_IMAGE_SIDE as i64))]
    pub(crate) grid: Option<u32>,

    /// Trace ray by ray through the single-ray query instead of the batch queries (for Embree,
    /// rtcIntersect1 instead of its packets of 16); the hits are the same
    #[arg(long, conflicts_with = "grid")]
    pub(crate) single_ray: bool,

    /// Also count the work per ray (nodes whose boxes were tested, ray/triangle tests), in a
    /// second pass that is not timed; Embree reports neither
    #[arg(long)]
    pub(crate) stats: bool,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,
}

/// The uniform number a blended surface's alpha is compared with: a ray
/// file has no samples to average stochastic transparency over, so a
/// blended surface counts where its alpha exceeds one half.
const BLEND_THRESHOLD: f32 = 0.5;
/// Rays read, traced and written at a time (2 MiB of rays, 1 MiB of hits):
/// memory stays bounded whatever the file's size, and each chunk gives the
/// worker threads 64 batches. Rounded up to whole batches (or with
/// `--grid`, whole bands of tile rows), so that the batches are the same
/// runs of the file as if it were traced whole.
const CHUNK_RAYS: usize = 64 * BATCH_RAYS;

pub(crate) fn run(args: &TraceArgs) -> Result<()> {
    let out = args.output.or_named_after(Some(&args.rays), ".hits.bin");
    refuse_inputs_as_outputs(&[("-o", &out)], &[("--rays", &args.rays), ("the scene", &args.scene)])?;
    check_output_folder(&out)?;
    // The first chunk is read before the scene, so that a file that is no
    // ray file at all (`/dev/zero`, a picture) is refused at once.
    // A grid is read in whole bands of tile rows, so that no band is cut.
    let band = args.grid.map_or(BATCH_RAYS, |width| width as usize * GRID_TILE);
    let mut input = open_rays(&args.rays, CHUNK_RAYS.div_ceil(band) * band)?;
    let read_error = || args.rays.display().to_string();
    let mut rays = Vec::new();
    let mut more = input.next_chunk(&mut rays).with_context(read_error)?;
    let LoadedScene { scene, load_ms, .. } = load_scene(Some(&args.scene))?;

    let pool = args.threads.pool()?;
    let build_start = Instant::now();
    let accel = pool.install(|| args.accel.build(&scene))?;
    let build_ms = build_start.elapsed().as_secs_f64() * 1e3;

    let alpha_test = (has_alpha(&scene) && !args.no_alpha).then(|| AlphaTest::new(&scene));
    if args.stats && alpha_test.is_some() {
        bail!(
            "{}: --stats counts queries without cut-outs, and this scene has some: add --no-alpha to trace and count it solid",
            args.scene.display()
        );
    }
    let accept =
        |triangle, beta, gamma| alpha_test.as_ref().is_none_or(|t| t.accepts(triangle, beta, gamma, BLEND_THRESHOLD));
    let filter: Option<HitFilter<'_>> = alpha_test.is_some().then_some(&accept);

    // Written through a temporary file that replaces `out` only when
    // complete: a failure leaves no partial file and keeps an earlier one.
    let grid = args.grid.map(|width| width as usize);
    let (mut ray_count, mut hit_count, mut trace_s) = (0usize, 0usize, 0.0);
    // Counted for our structures only: a peer reports no work, so a pass
    // over its rays would count nothing.
    let count = args.stats && !args.accel.accel.is_peer();
    let mut work = TraversalCounters::default();
    let mut read_failure = None;
    let written = write_atomically_with(&out, |sink| {
        let mut output = HitWriter::new(sink);
        while more {
            let trace_start = Instant::now();
            let accel = accel.as_ref();
            if args.any_hit {
                let occluded = pool.install(|| match grid {
                    Some(width) => occluded_grid(accel, &rays, width, filter),
                    None if args.single_ray => occluded_each(accel, &rays, filter),
                    None => occluded_all(accel, &rays, filter),
                });
                trace_s += trace_start.elapsed().as_secs_f64();
                hit_count += occluded.iter().filter(|&&o| o).count();
                output.write_occluded(&occluded)?;
            } else {
                let hits = pool.install(|| match grid {
                    Some(width) => intersect_grid(accel, &rays, width, filter),
                    None if args.single_ray => intersect_each(accel, &rays, filter),
                    None => intersect_all(accel, &rays, filter),
                });
                trace_s += trace_start.elapsed().as_secs_f64();
                hit_count += hits.iter().flatten().count();
                output.write_closest(&hits)?;
            }
            if count {
                work += pool.install(|| count_work(accel, &rays, args.any_hit));
            }
            ray_count += rays.len();
            more = input.next_chunk(&mut rays).map_err(|e| {
                read_failure = Some(anyhow::Error::new(e).context(read_error()));
                std::io::Error::other("the ray file could not be read")
            })?;
        }
        Ok(())
    });
    if let Some(failure) = read_failure {
        return Err(failure);
    }
    written.with_context(|| format!("{}: cannot write", out.display()))?;

    eprintln!("load   {load_ms:.1} ms ({} triangles)", scene.triangles.len());
    eprintln!("build  {build_ms:.1} ms ({})", accel.build_stats().variant);
    if has_alpha(&scene) {
        let materials = scene.materials.iter().filter(|m| m.alpha_mode != rtgi_scene::AlphaMode::Opaque).count();
        eprintln!(
            "alpha  {materials} of {} materials have cut-outs: {}",
            scene.materials.len(),
            if alpha_test.is_some() {
                "rays pass through their holes (blended ones where alpha is at most 0.5); --no-alpha traces them solid"
            } else {
                "traced solid (--no-alpha)"
            }
        );
    }
    eprintln!(
        "trace  {:.1} ms: {} rays, {} {}, {:.2} Mrays/s on {} threads (file I/O excluded)",
        trace_s * 1e3,
        ray_count,
        hit_count,
        if args.any_hit { "occluded" } else { "hits" },
        ray_count as f64 / trace_s.max(1e-9) * 1e-6,
        pool.current_num_threads()
    );
    if args.stats {
        let per_ray = |total: u64| total as f64 / ray_count.max(1) as f64;
        if count {
            eprintln!(
                "stats  {:.2} nodes, {:.2} triangle tests per ray (counted in a second pass, not timed; {} kernels)",
                per_ray(work.nodes_visited),
                per_ray(work.triangles_tested),
                rtgi_accel::simd::active_simd_level()
            );
        } else {
            eprintln!("stats  {} reports no nodes or triangle tests", accel.build_stats().variant);
        }
    }
    Ok(())
}

/// Opens a ray file; a regular file whose size is no multiple of a record
/// is refused here, before any work (a stream, at its end).
fn open_rays(path: &Path, chunk_rays: usize) -> Result<RayReader<File>> {
    let file = File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let metadata = file.metadata().with_context(|| format!("{}: cannot read", path.display()))?;
    if metadata.is_dir() {
        bail!("{}: is a directory, not a ray file", path.display());
    }
    if metadata.is_file() {
        ray_file::ray_count(metadata.len()).with_context(|| path.display().to_string())?;
    }
    Ok(RayReader::new(file, chunk_rays))
}
