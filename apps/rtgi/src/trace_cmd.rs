//! `rtgi trace`: rays from a file, through the chosen structure, hits to a
//! file (the format is `rtgi_accel::ray_file`'s).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use rtgi_accel::ray_file::{self, HitWriter, RayReader};
use rtgi_accel::{Accel, BATCH_RAYS, Hit, HitFilter, Ray, intersect_parallel, occluded_parallel};
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
/// worker threads 64 batches. A multiple of `BATCH_RAYS`, so that the
/// batches are the same runs of the file as if it were traced whole.
const CHUNK_RAYS: usize = 64 * BATCH_RAYS;

pub(crate) fn run(args: &TraceArgs) -> Result<()> {
    let out = args.output.or_named_after(Some(&args.rays), ".hits.bin");
    refuse_inputs_as_outputs(&[("-o", &out)], &[("--rays", &args.rays), ("the scene", &args.scene)])?;
    check_output_folder(&out)?;
    // The first chunk is read before the scene, so that a file that is no
    // ray file at all (`/dev/zero`, a picture) is refused at once.
    let mut input = open_rays(&args.rays)?;
    let read_error = || args.rays.display().to_string();
    let mut rays = Vec::with_capacity(CHUNK_RAYS);
    let mut more = input.next_chunk(&mut rays).with_context(read_error)?;
    let LoadedScene { scene, load_ms, .. } = load_scene(Some(&args.scene))?;

    let pool = args.threads.pool()?;
    let build_start = Instant::now();
    let accel = pool.install(|| args.accel.build(&scene))?;
    let build_ms = build_start.elapsed().as_secs_f64() * 1e3;

    let alpha_test = (has_alpha(&scene) && !args.no_alpha).then(|| AlphaTest::new(&scene));
    let accept =
        |triangle, beta, gamma| alpha_test.as_ref().is_none_or(|t| t.accepts(triangle, beta, gamma, BLEND_THRESHOLD));
    let filter: Option<HitFilter<'_>> = alpha_test.is_some().then_some(&accept);

    let mut output = HitWriter::new(PartialFile::create(&out)?);
    let write_error = || format!("{}: cannot write", out.display());
    let (mut ray_count, mut hit_count, mut trace_s) = (0usize, 0usize, 0.0);
    while more {
        let trace_start = Instant::now();
        let answers = pool.install(|| trace_chunk(accel.as_ref(), &rays, args.any_hit, filter));
        trace_s += trace_start.elapsed().as_secs_f64();
        ray_count += rays.len();
        hit_count += answers.hits();
        answers.write_to(&mut output).with_context(write_error)?;
        more = input.next_chunk(&mut rays).with_context(read_error)?;
    }
    output.into_inner().commit()?;

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
    Ok(())
}

/// The answers of one chunk of rays, in their order.
enum Answers {
    Closest(Vec<Option<Hit>>),
    Occluded(Vec<bool>),
}

impl Answers {
    /// Rays that hit something.
    fn hits(&self) -> usize {
        match self {
            Answers::Closest(hits) => hits.iter().filter(|h| h.is_some()).count(),
            Answers::Occluded(occluded) => occluded.iter().filter(|&&o| o).count(),
        }
    }

    fn write_to<W: Write>(&self, out: &mut HitWriter<W>) -> std::io::Result<()> {
        match self {
            Answers::Closest(hits) => out.write_closest(hits),
            Answers::Occluded(occluded) => out.write_occluded(occluded),
        }
    }
}

/// Traces `rays` through the batch queries, [`rtgi_accel::BATCH_RAYS`] at
/// a time in parallel, with the hit filter if there is one (cut-outs).
fn trace_chunk(accel: &dyn Accel, rays: &[Ray], any_hit: bool, filter: Option<HitFilter<'_>>) -> Answers {
    if any_hit {
        let mut occluded = vec![false; rays.len()];
        occluded_parallel(accel, rays, &mut occluded, filter);
        Answers::Occluded(occluded)
    } else {
        let mut closest = vec![None; rays.len()];
        intersect_parallel(accel, rays, &mut closest, filter);
        Answers::Closest(closest)
    }
}

/// Opens a ray file; a regular file whose size is no multiple of a record
/// is refused here, before any work (a stream, at its end).
fn open_rays(path: &Path) -> Result<RayReader<File>> {
    let file = File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let metadata = file.metadata().with_context(|| format!("{}: cannot read", path.display()))?;
    if metadata.is_dir() {
        bail!("{}: is a directory, not a ray file", path.display());
    }
    if metadata.is_file() {
        ray_file::ray_count(metadata.len()).with_context(|| path.display().to_string())?;
    }
    Ok(RayReader::new(file, CHUNK_RAYS))
}

/// An output file written as it is produced, through a temporary file
/// beside it that replaces it only when complete ([`PartialFile::commit`]):
/// a failure never leaves a partial file or destroys an earlier one. The
/// temporary file is named as `common::write_atomically` names its own.
///
/// A path that exists and is neither a regular file nor a folder (a FIFO,
/// `/dev/null`, `/dev/stdout`) is written directly: renaming a file over it
/// would replace the device or the pipe with a plain file (and for root,
/// `/dev/null` is in a writable folder).
struct PartialFile {
    path: PathBuf,
    /// The temporary file, renamed to `path` on commit; `None` when
    /// writing to `path` directly.
    temporary: Option<PathBuf>,
    file: Option<BufWriter<File>>,
}

impl PartialFile {
    fn create(path: &Path) -> Result<Self> {
        let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir());
        let temporary = (!special).then(|| {
            let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            path.with_file_name(format!(".{name}.{}.partial", std::process::id()))
        });
        let file = File::create(temporary.as_deref().unwrap_or(path))
            .with_context(|| format!("{}: cannot write", path.display()))?;
        Ok(PartialFile { path: path.to_owned(), temporary, file: Some(BufWriter::new(file)) })
    }

    /// Puts the complete file in place of `path`.
    fn commit(mut self) -> Result<()> {
        let file = self.file.take().expect("committed once");
        let file = file.into_inner().map_err(|e| e.into_error());
        match &self.temporary {
            Some(temporary) => file.and_then(|f| f.sync_all()).and_then(|()| std::fs::rename(temporary, &self.path)),
            None => file.map(drop),
        }
        .with_context(|| format!("{}: cannot write", self.path.display()))
    }
}

impl Write for PartialFile {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.file.as_mut().expect("written only before commit").write(bytes)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.as_mut().expect("written only before commit").flush()
    }
}

impl Drop for PartialFile {
    /// Removes the temporary file unless it was committed (renamed away).
    fn drop(&mut self) {
        if let Some(temporary) = &self.temporary {
            let _ = std::fs::remove_file(temporary);
        }
    }
}
