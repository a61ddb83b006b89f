//! Our binary SAH BVH and our wide BVHs, with and without spatial splits (one ray at a time, and through
//! the batch API, which traces coherent rays as packets of 16) against
//! peers on the same rays, in one run:
//! `cargo run --release -p rtgi-benches --example peers [-- SCENE.obj]`.
//! The peers are obvhs' BVH2 and, built with `--features embree`, Intel
//! Embree 3 through `rtcIntersect1` (one ray at a time, [`Accel::intersect`])
//! and `rtcIntersect16` (packets of 16, [`Accel::intersect_batch`]), and
//! `rtcIntersect1` once more on a scene built with Embree's robust flag,
//! whose traversal is the counterpart of our robust slab test.
//!
//! Follows the method of `../shared/notes/peers.md`: 1024×1024 primary rays
//! framing the bounding sphere with a 40° field of view, and 1,000,000
//! incoherent rays from uniform points in the bounding box in uniform
//! directions; closest hit. Each of our structures is built with its own
//! defaults (`AccelKind::default_params`). Timings on a shared machine drift, so the
//! contenders' runs alternate and each figure is the median of 15 runs
//! (builds: 15 builds).

use std::time::Duration;

use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use rayon::prelude::*;
use rtgi_accel::{Accel, AccelKind, Hit};
use rtgi_benches::workspace_root;
use rtgi_experiment::measure::alternate;
use rtgi_math::Ray;
use rtgi_math::glam::Vec3A;
use rtgi_render::rays::{bounding_sphere_camera, box_rays, primary_rays};
use rtgi_scene::Scene;

const RUNS: usize = 15;

/// Rays per parallel work item; a multiple of 16, so that packets stay full.
const CHUNK: usize = 1024;

/// Traces a chunk of rays and counts the hits.
type Trace<'a> = Box<dyn Fn(&[Ray]) -> usize + Sync + 'a>;

/// One structure under test: how to build it (and drop it, for build
/// timings), and how to trace a chunk of rays, counting the hits.
struct Contender<'a> {
    name: &'static str,
    build: Box<dyn Fn() + Sync + 'a>,
    trace: Trace<'a>,
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
    println!("{}: {} triangles; medians of {RUNS} alternating runs", path.display(), triangles.len());

    let ours: Vec<(AccelKind, Box<dyn Accel>)> =
        [AccelKind::Sah, AccelKind::Bvh4, AccelKind::Bvh8, AccelKind::Bvh8q, AccelKind::Sbvh8]
            .map(|kind| (kind, kind.build(&triangles, &kind.default_params())))
            .into();
    let peer_triangles: Vec<obvhs::triangle::Triangle> = triangles
        .iter()
        .map(|t| obvhs::triangle::Triangle { v0: Vec3A::from(t[0]), v1: Vec3A::from(t[1]), v2: Vec3A::from(t[2]) })
        .collect();
    let build_obvhs =
        || build_bvh2_from_tris(&peer_triangles, BvhBuildParams::medium_build(), &mut Duration::default());
    let obvhs = build_obvhs();
    // Triangles in the peer's leaf order, as its documentation advises.
    let obvhs_leaf_order: Vec<_> = obvhs.primitive_indices.iter().map(|&i| peer_triangles[i as usize]).collect();
    let one_at_a_time = |accel: &dyn Accel, rays: &[Ray]| rays.iter().filter(|r| accel.intersect(r).is_some()).count();

    #[cfg(feature = "embree")]
    let embree =
        AccelKind::Embree.try_build(&triangles, &AccelKind::Embree.default_params()).unwrap_or_else(|e| panic!("{e}"));
    // Embree's robust mode, whose traversal is the counterpart of ours:
    // how much of a gap is the price of robustness.
    #[cfg(feature = "embree")]
    let build_embree_robust =
        || rtgi_accel::EmbreeBackend::robust(triangles.as_slice()).unwrap_or_else(|e| panic!("{e}"));
    #[cfg(feature = "embree")]
    let embree_robust = build_embree_robust();
    #[cfg_attr(not(feature = "embree"), allow(unused_mut))]
    let batched = |accel: &dyn Accel, rays: &[Ray]| {
        let mut hits: Vec<Option<Hit>> = vec![None; rays.len()];
        accel.intersect_batch(rays, &mut hits);
        hits.iter().filter(|h| h.is_some()).count()
    };
    let mut contenders = Vec::new();
    let triangles_ref = &triangles;
    for (kind, accel) in &ours {
        let (kind, accel) = (*kind, accel.as_ref());
        let names: [&'static str; 2] = match kind {
            AccelKind::Bvh4 => ["rtgi bvh4", "rtgi bvh4 16"],
            AccelKind::Bvh8 => ["rtgi bvh8", "rtgi bvh8 16"],
            AccelKind::Bvh8q => ["rtgi bvh8q", "rtgi bvh8q 16"],
            AccelKind::Sbvh8 => ["rtgi sbvh8", "rtgi sbvh8 16"],
            _ => ["rtgi sah", ""],
        };
        contenders.push(Contender {
            name: names[0],
            build: Box::new(move || drop(kind.build(triangles_ref, &kind.default_params()))),
            trace: Box::new(move |rays| one_at_a_time(accel, rays)),
        });
        if !names[1].is_empty() {
            contenders.push(Contender {
                name: names[1],
                build: Box::new(move || drop(kind.build(triangles_ref, &kind.default_params()))),
                trace: Box::new(move |rays| batched(accel, rays)),
            });
        }
    }
    contenders.extend([Contender {
        name: "obvhs bvh2",
        build: Box::new(|| drop(build_obvhs())),
        trace: Box::new(|rays| {
            rays.iter()
                .filter(|ray| {
                    let ray = obvhs::ray::Ray::new(ray.origin.into(), ray.direction.into(), ray.t_min, ray.t_max);
                    let mut hit = obvhs::ray::RayHit::none();
                    obvhs.ray_traverse(ray, &mut hit, |r, id| obvhs_leaf_order[id].intersect(r))
                })
                .count()
        }),
    }]);
    #[cfg(feature = "embree")]
    {
        let build_embree = || {
            drop(
                AccelKind::Embree
                    .try_build(&triangles, &AccelKind::Embree.default_params())
                    .unwrap_or_else(|e| panic!("{e}")),
            )
        };
        contenders.push(Contender {
            name: "embree 1",
            build: Box::new(build_embree),
            trace: Box::new(|rays| one_at_a_time(embree.as_ref(), rays)),
        });
        contenders.push(Contender {
            name: "embree 16",
            build: Box::new(build_embree),
            trace: Box::new(|rays| batched(embree.as_ref(), rays)),
        });
        contenders.push(Contender {
            name: "embree robust 1",
            build: Box::new(|| drop(build_embree_robust())),
            trace: Box::new(|rays| one_at_a_time(&embree_robust, rays)),
        });
    }
    let names: Vec<&str> = contenders.iter().map(|c| c.name).collect();
    println!("'16': the batch API (Accel::intersect_batch) on consecutive rays, 4×4 tiles of the primary rays");
    if names.iter().any(|n| n.starts_with("embree")) {
        println!(
            "embree 1: rtcIntersect1 (Accel::intersect); embree 16: rtcIntersect16 packets; \
             embree robust 1: rtcIntersect1 on a scene with RTC_SCENE_FLAG_ROBUST"
        );
    }
    // The columns once more, unambiguous for scripts (benches/targets.sh):
    // in the tables, names wider than a column push the rest along.
    println!("columns: threads, {}", names.join(", "));

    let pools: Vec<rayon::ThreadPool> =
        [1, 2].iter().map(|&n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap()).collect();
    let header = |what: &str| {
        println!();
        println!("{what}");
        print!("{:<8}", "threads");
        names.iter().for_each(|n| print!(" {n:>12}"));
        println!();
    };
    let row = |threads: usize, values: &[f64], decimals: usize| {
        print!("{threads:<8}");
        values.iter().for_each(|v| print!(" {v:>12.decimals$}"));
        println!();
    };
    // The contenders' runs alternate (`measure::alternate`), after one warm-up round.
    let medians_ms = |work: &mut [Box<dyn FnMut() + '_>]| -> Vec<f64> {
        let mut runs: Vec<&mut dyn FnMut()> = work.iter_mut().map(|r| &mut **r as _).collect();
        alternate(RUNS, &mut runs).into_iter().map(|t| t.median_ms).collect()
    };
    let measure_builds = |pool: &rayon::ThreadPool| {
        let mut work: Vec<Box<dyn FnMut() + '_>> =
            contenders.iter().map(|c| Box::new(|| pool.install(&*c.build)) as Box<dyn FnMut()>).collect();
        medians_ms(&mut work)
    };
    let measure_rays = |pool: &rayon::ThreadPool, rays: &[Ray]| {
        let mut work: Vec<Box<dyn FnMut() + '_>> = contenders
            .iter()
            .map(|c| {
                Box::new(|| {
                    pool.install(|| {
                        std::hint::black_box(rays.par_chunks(CHUNK).map(|chunk| (c.trace)(chunk)).sum::<usize>());
                    })
                }) as Box<dyn FnMut()>
            })
            .collect();
        medians_ms(&mut work).into_iter().map(|ms| rays.len() as f64 / ms * 1e-3).collect::<Vec<_>>()
    };
    header("build ms");
    for pool in &pools {
        row(pool.current_num_threads(), &measure_builds(pool), 1);
    }
    for (what, rays) in [("primary Mrays/s", &primary), ("incoherent Mrays/s", &incoherent)] {
        header(what);
        for pool in &pools {
            row(pool.current_num_threads(), &measure_rays(pool, rays), 2);
        }
    }
    println!();
    print!("primary hits of {}:", primary.len());
    for contender in &contenders {
        print!(" {} {},", contender.name, primary.chunks(CHUNK).map(|c| (contender.trace)(c)).sum::<usize>());
    }
    println!();
}
