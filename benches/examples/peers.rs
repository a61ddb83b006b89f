//! Our SAH BVH against obvhs' BVH2 on the same rays, in one run:
//! `cargo run --release -p rtgi-benches --example peers [-- SCENE.obj]`.
//!
//! Follows the method of `../shared/notes/peers.md`: 1024×1024 primary rays
//! framing the bounding sphere with a 40° field of view, and 1,000,000
//! incoherent rays from uniform points in the bounding box in uniform
//! directions; closest hit. Timings on a shared machine drift, so the two
//! libraries' runs alternate and each figure is the median of 15 runs
//! (builds: 15 builds).

use std::time::{Duration, Instant};

use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use rayon::prelude::*;
use rtgi_accel::{AccelKind, BuildParams};
use rtgi_benches::workspace_root;
use rtgi_math::Ray;
use rtgi_math::glam::Vec3A;
use rtgi_render::rays::{bounding_sphere_camera, box_rays, primary_rays};
use rtgi_scene::Scene;

const RUNS: usize = 15;

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Seconds of each of `RUNS` alternating runs of `a` and `b`, as medians.
fn alternate(a: &mut dyn FnMut() -> f64, b: &mut dyn FnMut() -> f64) -> (f64, f64) {
    a();
    b();
    let (mut times_a, mut times_b) = (Vec::new(), Vec::new());
    for _ in 0..RUNS {
        times_a.push(a());
        times_b.push(b());
    }
    (median(times_a), median(times_b))
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .map(Into::into)
        .unwrap_or_else(|| workspace_root().join("../shared/scenes/bunny/stanford-bunny.obj"));
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let triangles = scene.triangle_positions();
    let primary = primary_rays(&bounding_sphere_camera(&scene), 1024, 1024);
    let incoherent = box_rays(&scene, 1_000_000, 1);
    let peer_triangles: Vec<obvhs::triangle::Triangle> = triangles
        .iter()
        .map(|t| obvhs::triangle::Triangle { v0: Vec3A::from(t[0]), v1: Vec3A::from(t[1]), v2: Vec3A::from(t[2]) })
        .collect();
    println!("{}: {} triangles; medians of {RUNS} alternating runs", path.display(), triangles.len());

    let pools: Vec<rayon::ThreadPool> =
        [1, 2].iter().map(|&n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap()).collect();
    let ours = AccelKind::Sah.build(&triangles, &BuildParams::default());
    let peer = build_bvh2_from_tris(&peer_triangles, BvhBuildParams::medium_build(), &mut Duration::default());
    // Triangles in the peer's leaf order, as its documentation advises.
    let peer_leaf_order: Vec<_> = peer.primitive_indices.iter().map(|&i| peer_triangles[i as usize]).collect();
    let our_trace = |ray: &Ray| ours.intersect(ray).is_some();
    let peer_trace = |ray: &Ray| {
        let ray = obvhs::ray::Ray::new(ray.origin.into(), ray.direction.into(), ray.t_min, ray.t_max);
        let mut hit = obvhs::ray::RayHit::none();
        peer.ray_traverse(ray, &mut hit, |r, id| peer_leaf_order[id].intersect(r))
    };
    let timed = |pool: &rayon::ThreadPool, work: &(dyn Fn() + Sync)| {
        let start = Instant::now();
        pool.install(work);
        start.elapsed().as_secs_f64()
    };

    println!(
        "{:<10} {:>14} {:>14} {:>14} {:>14} {:>14} {:>14}",
        "", "build ms", "", "primary", "Mrays/s", "incoherent", "Mrays/s"
    );
    println!(
        "{:<10} {:>14} {:>14} {:>14} {:>14} {:>14} {:>14}",
        "threads", "rtgi sah", "obvhs bvh2", "rtgi sah", "obvhs bvh2", "rtgi sah", "obvhs bvh2"
    );
    for pool in &pools {
        let (build_ours, build_peer) = alternate(
            &mut || timed(pool, &|| drop(AccelKind::Sah.build(&triangles, &BuildParams::default()))),
            &mut || {
                timed(pool, &|| {
                    drop(build_bvh2_from_tris(
                        &peer_triangles,
                        BvhBuildParams::medium_build(),
                        &mut Duration::default(),
                    ))
                })
            },
        );
        let throughput = |rays: &[Ray]| {
            let count = |trace: &(dyn Fn(&Ray) -> bool + Sync)| {
                rays.par_chunks(1024).map(|c| c.iter().filter(|r| trace(r)).count()).sum::<usize>()
            };
            let (a, b) = alternate(
                &mut || {
                    timed(pool, &|| {
                        std::hint::black_box(count(&our_trace));
                    })
                },
                &mut || {
                    timed(pool, &|| {
                        std::hint::black_box(count(&peer_trace));
                    })
                },
            );
            (rays.len() as f64 / a * 1e-6, rays.len() as f64 / b * 1e-6)
        };
        let (primary_ours, primary_peer) = throughput(&primary);
        let (incoherent_ours, incoherent_peer) = throughput(&incoherent);
        println!(
            "{:<10} {:>14.1} {:>14.1} {:>14.2} {:>14.2} {:>14.2} {:>14.2}",
            pool.current_num_threads(),
            build_ours * 1e3,
            build_peer * 1e3,
            primary_ours,
            primary_peer,
            incoherent_ours,
            incoherent_peer
        );
    }
    let hits_ours = primary.iter().filter(|r| our_trace(r)).count();
    let hits_peer = primary.iter().filter(|r| peer_trace(r)).count();
    println!("primary hits: rtgi {hits_ours}, obvhs {hits_peer} of {}", primary.len());
}
