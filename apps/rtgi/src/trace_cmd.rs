use std::time::Instant;

use anyhow::{Context, Result, bail};
use rayon::prelude::*;
use rtgi_math::{Ray, Vec3};

use crate::cli::TraceArgs;
use crate::common::{LoadedScene, check_output_folder, load_scene, thread_pool, write_atomically};

/// Bytes of one ray in a ray file: 8 little-endian f32.
pub(crate) const RAY_BYTES: usize = 32;
/// Bytes of one hit in a hit file: t, triangle, beta, gamma.
pub(crate) const HIT_BYTES: usize = 16;
/// The triangle index of a miss.
pub(crate) const MISS: u32 = u32::MAX;

pub(crate) fn run(args: &TraceArgs) -> Result<()> {
    check_output_folder(&args.out)?;
    let LoadedScene { scene, load_ms, .. } = load_scene(Some(&args.scene))?;
    let bytes = std::fs::read(&args.rays).with_context(|| format!("{}: cannot read", args.rays.display()))?;
    let rays = decode_rays(&bytes).with_context(|| format!("{}: not a ray file", args.rays.display()))?;

    let pool = thread_pool(args.threads)?;
    let build_start = Instant::now();
    let accel = pool.install(|| args.accel.build(&scene))?;
    let build_ms = build_start.elapsed().as_secs_f64() * 1e3;

    let trace_start = Instant::now();
    // Through the batch queries, in chunks of consecutive rays: the wide
    // BVHs trace coherent runs of the file (camera rays in tiles) as packets.
    let hits: Vec<[u8; HIT_BYTES]> = pool.install(|| {
        rays.par_chunks(1024)
            .flat_map_iter(|chunk| {
                let encoded: Vec<[u8; HIT_BYTES]> = if args.any_hit {
                    let mut occluded = vec![false; chunk.len()];
                    accel.occluded_batch(chunk, &mut occluded);
                    occluded.iter().map(|&o| encode_hit(0.0, if o { 0 } else { MISS }, 0.0, 0.0)).collect()
                } else {
                    let mut closest = vec![None; chunk.len()];
                    accel.intersect_batch(chunk, &mut closest);
                    closest
                        .iter()
                        .map(|hit| match hit {
                            Some(h) => encode_hit(h.t, h.triangle, h.beta, h.gamma),
                            None => encode_hit(f32::INFINITY, MISS, 0.0, 0.0),
                        })
                        .collect()
                };
                encoded
            })
            .collect()
    });
    let trace_s = trace_start.elapsed().as_secs_f64();
    let hit_count = hits.iter().filter(|h| h[4..8] != MISS.to_le_bytes()).count();
    write_atomically(&args.out, hits.as_flattened())?;

    eprintln!("load   {load_ms:.1} ms ({} triangles)", scene.triangles.len());
    eprintln!("build  {build_ms:.1} ms ({})", accel.build_stats().variant);
    eprintln!(
        "trace  {:.1} ms: {} rays, {} {}, {:.2} Mrays/s on {} threads (file I/O excluded)",
        trace_s * 1e3,
        rays.len(),
        hit_count,
        if args.any_hit { "occluded" } else { "hits" },
        rays.len() as f64 / trace_s.max(1e-9) * 1e-6,
        pool.current_num_threads()
    );
    Ok(())
}

/// Rays from the bytes of a ray file.
pub(crate) fn decode_rays(bytes: &[u8]) -> Result<Vec<Ray>> {
    if !bytes.len().is_multiple_of(RAY_BYTES) {
        bail!("its size, {} bytes, is not a multiple of {RAY_BYTES} (8 little-endian f32 per ray)", bytes.len());
    }
    Ok(bytes
        .chunks_exact(RAY_BYTES)
        .map(|chunk| {
            let f: [f32; 8] =
                std::array::from_fn(|i| f32::from_le_bytes(chunk[4 * i..4 * i + 4].try_into().expect("four bytes")));
            Ray::with_range(Vec3::new(f[0], f[1], f[2]), Vec3::new(f[3], f[4], f[5]), f[6], f[7])
        })
        .collect())
}

fn encode_hit(t: f32, triangle: u32, beta: f32, gamma: f32) -> [u8; HIT_BYTES] {
    let mut out = [0u8; HIT_BYTES];
    out[0..4].copy_from_slice(&t.to_le_bytes());
    out[4..8].copy_from_slice(&triangle.to_le_bytes());
    out[8..12].copy_from_slice(&beta.to_le_bytes());
    out[12..16].copy_from_slice(&gamma.to_le_bytes());
    out
}
