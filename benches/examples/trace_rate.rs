//! The Rust side of the Python package's overhead benchmark
//! (`python/benchmarks/overhead.py`): the rays `Scene.box_rays(count,
//! seed)` makes, traced through `rtgi_accel::parallel::intersect_all` (what
//! `rtgi trace` uses) on rayon's global pool, timed `repeats` times after
//! one warm-up, each time into a new buffer of answers (as the Python call
//! returns new arrays) and, for comparison, into one buffer reused; and one
//! ray at a time through the same call, for the cost of a call. Prints one JSON object: the times in milliseconds, the hits
//! and a checksum of the answers, which the Python side compares with its own.
//!
//! `cargo run --release -p rtgi-benches --example trace_rate -- SCENE [COUNT] [SEED] [ACCEL] [REPEATS]`

use std::time::Instant;

use rayon::prelude::*;
use rtgi_accel::parallel::{BATCH_RAYS, intersect_all};
use rtgi_accel::{AccelKind, Hit};
use rtgi_render::rays::box_rays;
use rtgi_scene::Scene;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: trace_rate SCENE [COUNT] [SEED] [ACCEL] [REPEATS]";
    let scene_path = args.first().expect(usage);
    let count: usize = args.get(1).map_or(1_000_000, |a| a.parse().expect(usage));
    let seed: u64 = args.get(2).map_or(0, |a| a.parse().expect(usage));
    let kind: AccelKind = args.get(3).map_or("bvh8", String::as_str).parse().expect(usage);
    let repeats: usize = args.get(4).map_or(5, |a| a.parse().expect(usage));

    let scene = Scene::load(scene_path.as_ref()).unwrap_or_else(|e| panic!("{e}"));
    let accel = kind.build(&scene.triangle_positions(), &kind.default_params());
    let rays = box_rays(&scene, count, seed);
    // As a caller of the Rust API traces a new batch (and as `Accel.intersect`
    // must, returning new arrays): `intersect_all` returns a new vector of
    // answers. And, for comparison, the same runs of the batch query into
    // one buffer reused every time.
    let mut hits: Vec<Option<Hit>> = Vec::new();
    let mut reused: Vec<Option<Hit>> = vec![None; rays.len()];
    let (mut trace_ms, mut reused_ms) = (Vec::with_capacity(repeats), Vec::with_capacity(repeats));
    for run in 0..=repeats {
        let started = Instant::now();
        hits = intersect_all(accel.as_ref(), &rays, None);
        let allocated = started.elapsed().as_secs_f64() * 1e3;
        let started = Instant::now();
        rays.par_chunks(BATCH_RAYS)
            .zip(reused.par_chunks_mut(BATCH_RAYS))
            .for_each(|(batch, out)| accel.intersect_batch(batch, out));
        if run > 0 {
            trace_ms.push(allocated);
            reused_ms.push(started.elapsed().as_secs_f64() * 1e3);
        }
    }
    assert!(hits == reused, "the same rays answered differently");
    // The answers' bits, summed: the Python side sums its arrays' bits the same way.
    let checksum = hits.iter().fold(0u64, |sum, hit| {
        let (t, triangle) = hit.map_or((f32::INFINITY.to_bits(), u32::MAX), |h| (h.t.to_bits(), h.triangle));
        sum.wrapping_add(t as u64).wrapping_add(triangle as u64)
    });
    // One ray per call: the cost of a call of the Rust API.
    let one = &rays[..1];
    let calls = 20_000;
    let started = Instant::now();
    for _ in 0..calls {
        std::hint::black_box(intersect_all(accel.as_ref(), one, None));
    }
    let call_us = started.elapsed().as_secs_f64() * 1e6 / calls as f64;
    let hit_count = hits.iter().filter(|h| h.is_some()).count();
    let list = |ms: &[f64]| ms.iter().map(|m| format!("{m:.4}")).collect::<Vec<_>>().join(", ");
    println!(
        "{{\"rays\": {}, \"threads\": {}, \"trace_ms\": [{}], \"reused_ms\": [{}], \"hits\": {hit_count}, \
         \"checksum\": {checksum}, \"call_us\": {call_us:.3}}}",
        rays.len(),
        rayon::current_num_threads(),
        list(&trace_ms),
        list(&reused_ms)
    );
}
