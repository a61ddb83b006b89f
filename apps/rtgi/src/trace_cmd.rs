use std::fs::File;
use std::io::{BufWriter, ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use rayon::prelude::*;
use rtgi_accel::Accel;
use rtgi_math::{Ray, Vec3};
use rtgi_render::{AlphaTest, has_alpha};

use crate::cli::TraceArgs;
use crate::common::{LoadedScene, check_output_folder, load_scene, refuse_inputs_as_outputs};

/// Bytes of one ray in a ray file: 8 little-endian f32.
pub(crate) const RAY_BYTES: usize = 32;
/// Bytes of one hit in a hit file: t, triangle, beta, gamma.
pub(crate) const HIT_BYTES: usize = 16;
/// The triangle index of a miss.
pub(crate) const MISS: u32 = u32::MAX;
/// The uniform number a blended surface's alpha is compared with: a ray
/// file has no samples to average stochastic transparency over, so a
/// blended surface counts where its alpha exceeds one half.
const BLEND_THRESHOLD: f32 = 0.5;
/// Rays given to the batch queries at once: the wide BVHs trace coherent
/// runs of the file (camera rays in tiles) as packets.
const BATCH_RAYS: usize = 1024;
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
    let mut input = RayReader::open(&args.rays)?;
    let mut rays = Vec::with_capacity(CHUNK_RAYS);
    let mut more = input.next_chunk(&mut rays)?;
    let LoadedScene { scene, load_ms, .. } = load_scene(Some(&args.scene))?;

    let pool = args.threads.pool()?;
    let build_start = Instant::now();
    let accel = pool.install(|| args.accel.build(&scene))?;
    let build_ms = build_start.elapsed().as_secs_f64() * 1e3;

    let alpha_test = (has_alpha(&scene) && !args.no_alpha).then(|| AlphaTest::new(&scene));
    let accept =
        |triangle, beta, gamma| alpha_test.as_ref().is_none_or(|t| t.accepts(triangle, beta, gamma, BLEND_THRESHOLD));
    let filter: Option<&(dyn Fn(u32, f32, f32) -> bool + Sync)> = alpha_test.is_some().then_some(&accept);

    let mut output = PartialFile::create(&out)?;
    let mut hits = Vec::with_capacity(CHUNK_RAYS);
    let (mut ray_count, mut hit_count, mut trace_s) = (0usize, 0usize, 0.0);
    while more {
        let trace_start = Instant::now();
        pool.install(|| trace_chunk(accel.as_ref(), &rays, args.any_hit, filter, &mut hits));
        trace_s += trace_start.elapsed().as_secs_f64();
        ray_count += rays.len();
        hit_count += hits.iter().filter(|h| h[4..8] != MISS.to_le_bytes()).count();
        output.write_all(hits.as_flattened())?;
        more = input.next_chunk(&mut rays)?;
    }
    output.commit()?;

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

/// Traces `rays` through the batch queries, `BATCH_RAYS` at a time in
/// parallel, with the hit filter if there is one (cut-outs), and puts
/// their encoded hits in `hits`, in the same order.
fn trace_chunk(
    accel: &dyn Accel,
    rays: &[Ray],
    any_hit: bool,
    filter: Option<&(dyn Fn(u32, f32, f32) -> bool + Sync)>,
    hits: &mut Vec<[u8; HIT_BYTES]>,
) {
    hits.clear();
    hits.resize(rays.len(), [0; HIT_BYTES]);
    rays.par_chunks(BATCH_RAYS).zip(hits.par_chunks_mut(BATCH_RAYS)).for_each(|(batch, encoded)| {
        if any_hit {
            let mut occluded = vec![false; batch.len()];
            match filter {
                Some(accept) => accel.occluded_batch_filtered(batch, &mut occluded, accept),
                None => accel.occluded_batch(batch, &mut occluded),
            }
            for (out, &o) in encoded.iter_mut().zip(&occluded) {
                *out = encode_hit(0.0, if o { 0 } else { MISS }, 0.0, 0.0);
            }
        } else {
            let mut closest = vec![None; batch.len()];
            match filter {
                Some(accept) => accel.intersect_batch_filtered(batch, &mut closest, accept),
                None => accel.intersect_batch(batch, &mut closest),
            }
            for (out, hit) in encoded.iter_mut().zip(&closest) {
                *out = match hit {
                    Some(h) => encode_hit(h.t, h.triangle, h.beta, h.gamma),
                    None => encode_hit(f32::INFINITY, MISS, 0.0, 0.0),
                };
            }
        }
    });
}

/// Reads a ray file a chunk at a time, checking every record.
struct RayReader {
    path: PathBuf,
    file: File,
    /// Records read so far: the index of the next one.
    records: usize,
    buffer: Vec<u8>,
}

impl RayReader {
    /// Opens a ray file; a regular file whose size is no multiple of a
    /// record is refused here, before any work (a stream, at its end).
    fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
        let metadata = file.metadata().with_context(|| format!("{}: cannot read", path.display()))?;
        if metadata.is_dir() {
            bail!("{}: is a directory, not a ray file", path.display());
        }
        if metadata.is_file() {
            check_size(path, metadata.len())?;
        }
        Ok(RayReader { path: path.to_owned(), file, records: 0, buffer: vec![0; CHUNK_RAYS * RAY_BYTES] })
    }

    /// Replaces `rays` with the next chunk of the file; false at its end
    /// (and `rays` empty).
    fn next_chunk(&mut self, rays: &mut Vec<Ray>) -> Result<bool> {
        rays.clear();
        let mut filled = 0;
        while filled < self.buffer.len() {
            match self.file.read(&mut self.buffer[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e).with_context(|| format!("{}: cannot read", self.path.display())),
            }
        }
        if !filled.is_multiple_of(RAY_BYTES) {
            // Only at the end of the file: the buffer holds whole records.
            check_size(&self.path, (self.records * RAY_BYTES + filled) as u64)?;
        }
        for record in self.buffer[..filled].chunks_exact(RAY_BYTES) {
            let ray = decode_ray(record).with_context(|| {
                format!(
                    "{}: not a ray file: ray {} (bytes {} to {}) is not a valid ray",
                    self.path.display(),
                    self.records,
                    self.records * RAY_BYTES,
                    (self.records + 1) * RAY_BYTES - 1
                )
            })?;
            rays.push(ray);
            self.records += 1;
        }
        Ok(!rays.is_empty())
    }
}

fn check_size(path: &Path, bytes: u64) -> Result<()> {
    if !bytes.is_multiple_of(RAY_BYTES as u64) {
        bail!(
            "{}: not a ray file: its size, {bytes} bytes, is not a multiple of {RAY_BYTES} \
             (a ray is 8 little-endian f32: origin, direction, t_min, t_max)",
            path.display()
        );
    }
    Ok(())
}

/// The ray in one record: refused when it could only answer nonsense (a
/// NaN or infinite origin or direction, a zero direction, a NaN bound). An
/// empty range (`t_min > t_max`) is a ray that misses, and is kept.
fn decode_ray(record: &[u8]) -> Result<Ray> {
    let f: [f32; 8] = std::array::from_fn(|i| {
        f32::from_le_bytes([record[4 * i], record[4 * i + 1], record[4 * i + 2], record[4 * i + 3]])
    });
    let ray = Ray::with_range(Vec3::new(f[0], f[1], f[2]), Vec3::new(f[3], f[4], f[5]), f[6], f[7]);
    let v = |v: Vec3| format!("({}, {}, {})", v.x, v.y, v.z);
    if !ray.origin.is_finite() {
        bail!("its origin {} is not finite", v(ray.origin));
    }
    if !ray.direction.is_finite() {
        bail!("its direction {} is not finite", v(ray.direction));
    }
    if ray.direction == Vec3::ZERO {
        bail!("its direction is zero");
    }
    if ray.t_min.is_nan() || ray.t_max.is_nan() {
        bail!("its range [{}, {}] is not a number", ray.t_min, ray.t_max);
    }
    Ok(ray)
}

fn encode_hit(t: f32, triangle: u32, beta: f32, gamma: f32) -> [u8; HIT_BYTES] {
    let mut out = [0u8; HIT_BYTES];
    out[0..4].copy_from_slice(&t.to_le_bytes());
    out[4..8].copy_from_slice(&triangle.to_le_bytes());
    out[8..12].copy_from_slice(&beta.to_le_bytes());
    out[12..16].copy_from_slice(&gamma.to_le_bytes());
    out
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

    fn write_all(&mut self, bytes: &[u8]) -> Result<()> {
        let file = self.file.as_mut().expect("written only before commit");
        file.write_all(bytes).with_context(|| format!("{}: cannot write", self.path.display()))
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

impl Drop for PartialFile {
    /// Removes the temporary file unless it was committed (renamed away).
    fn drop(&mut self) {
        if let Some(temporary) = &self.temporary {
            let _ = std::fs::remove_file(temporary);
        }
    }
}
