use rayon::prelude::*;
use rtgi_accel::{AccelKind, BuildParams};
use rtgi_benches::workspace_root;
use rtgi_math::Ray;
use rtgi_render::rays::{bounding_sphere_camera, box_rays, primary_rays};
use rtgi_scene::Scene;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[0], v[v.len() / 2], v[v.len() - 1])
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .map(Into::into)
        .unwrap_or_else(|| workspace_root().join("../shared/scenes/bunny/stanford-bunny.obj"));
    let kinds: Vec<AccelKind> =
        std::env::args().nth(2).unwrap_or("sah,bvh4,bvh8".into()).split(',').map(|s| s.parse().unwrap()).collect();
    let threads: usize = std::env::args().nth(3).map(|s| s.parse().unwrap()).unwrap_or(1);
    let scene = Scene::load(&path).unwrap();
    let triangles = scene.triangle_positions();
    let limit: usize = std::env::var("PROBE_RAYS").ok().map(|s| s.parse().unwrap()).unwrap_or(usize::MAX);
    let reps: usize = std::env::var("PROBE_REPEATS").ok().map(|s| s.parse().unwrap()).unwrap_or(7);
    let mut primary = primary_rays(&bounding_sphere_camera(&scene), 1024, 1024);
    primary.truncate(limit);
    let mut incoherent = box_rays(&scene, 1_000_000, 1);
    incoherent.truncate(limit);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    for kind in kinds {
        let mut builds = Vec::new();
        let mut accel = None;
        for _ in 0..reps {
            let s = Instant::now();
            let a = pool.install(|| kind.build(&triangles, &BuildParams::default()));
            builds.push(s.elapsed().as_secs_f64() * 1e3);
            accel = Some(a);
        }
        let accel = accel.unwrap();
        let time = |rays: &[Ray], batch: bool| {
            let mut t = Vec::new();
            for _ in 0..reps {
                let s = Instant::now();
                let hits: usize = pool.install(|| {
                    if batch {
                        rays.par_chunks(256)
                            .map(|c| {
                                let mut h = vec![None; c.len()];
                                accel.intersect_batch(c, &mut h);
                                h.iter().filter(|h| h.is_some()).count()
                            })
                            .sum()
                    } else {
                        rays.par_chunks(1024).map(|c| c.iter().filter(|r| accel.intersect(r).is_some()).count()).sum()
                    }
                });
                std::hint::black_box(hits);
                t.push(rays.len() as f64 / s.elapsed().as_secs_f64() * 1e-6);
            }
            median(t)
        };
        let (b0, b1, b2) = median(builds);
        let p = time(&primary, false);
        let pb = time(&primary, true);
        let i = time(&incoherent, false);
        println!(
            "{:8} build {:.1} ({:.1}-{:.1}) ms | primary {:.2} ({:.2}-{:.2}) | batch {:.2} | incoherent {:.2} ({:.2}-{:.2}) Mrays/s",
            kind.name(),
            b1,
            b0,
            b2,
            p.1,
            p.0,
            p.2,
            pb.1,
            i.1,
            i.0,
            i.2
        );
    }
}
