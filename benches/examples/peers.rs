//! Our SAH BVH against obvhs' BVH2 on the same rays, in one run:
//! `cargo run --release -p rtgi-benches --example peers [-- SCENE.obj]`.
//!
//! Follows the method of `../shared/notes/peers.md`: 1024×1024 primary rays
//! framing the bounding sphere with a 40° field of view, and 1,000,000
//! incoherent rays from uniform points in the bounding box in uniform
//! directions; closest hit; median of 7 runs at 1 and 2 threads.

use std::time::{Duration, Instant};

use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use rtgi_accel::{AccelKind, BuildParams};
use rtgi_benches::{mrays_per_second, workspace_root};
use rtgi_math::glam::Vec3A;
use rtgi_render::rays::{bounding_sphere_camera, box_rays, primary_rays};
use rtgi_scene::Scene;

fn main() {
    let path = std::env::args()
        .nth(1)
        .map(Into::into)
        .unwrap_or_else(|| workspace_root().join("../shared/scenes/bunny/stanford-bunny.obj"));
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let triangles = scene.triangle_positions();
    let primary = primary_rays(&bounding_sphere_camera(&scene), 1024, 1024);
    let incoherent = box_rays(&scene, 1_000_000, 1);
    println!("{}: {} triangles", path.display(), triangles.len());

    let ours = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let start = Instant::now();
        let bvh = pool.install(|| AccelKind::Sah.build(&triangles, &BuildParams::default()));
        (bvh, start.elapsed())
    };
    let (bvh, build_1) = ours(1);
    let (_, build_2) = ours(2);

    let obvhs_triangles: Vec<obvhs::triangle::Triangle> = triangles
        .iter()
        .map(|t| obvhs::triangle::Triangle { v0: Vec3A::from(t[0]), v1: Vec3A::from(t[1]), v2: Vec3A::from(t[2]) })
        .collect();
    let peer = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let start = Instant::now();
        let bvh = pool.install(|| {
            build_bvh2_from_tris(&obvhs_triangles, BvhBuildParams::medium_build(), &mut Duration::default())
        });
        (bvh, start.elapsed())
    };
    let (peer_bvh, peer_build_1) = peer(1);
    let (_, peer_build_2) = peer(2);
    // Triangles in the peer's leaf order, as its documentation advises.
    let peer_triangles: Vec<_> = peer_bvh.primitive_indices.iter().map(|&i| obvhs_triangles[i as usize]).collect();
    let peer_trace = |ray: &rtgi_math::Ray| {
        let ray = obvhs::ray::Ray::new(ray.origin.into(), ray.direction.into(), ray.t_min, ray.t_max);
        let mut hit = obvhs::ray::RayHit::none();
        peer_bvh.ray_traverse(ray, &mut hit, |r, id| peer_triangles[id].intersect(r))
    };
    let our_trace = |ray: &rtgi_math::Ray| bvh.intersect(ray).is_some();

    println!(
        "{:<12} {:>12} {:>12} {:>16} {:>16}",
        "", "build 1T ms", "build 2T ms", "primary 1T/2T", "incoherent 1T/2T"
    );
    for (name, b1, b2, trace) in [
        ("rtgi sah", build_1, build_2, &our_trace as &(dyn Fn(&rtgi_math::Ray) -> bool + Sync)),
        ("obvhs bvh2", peer_build_1, peer_build_2, &peer_trace),
    ] {
        let p: Vec<f64> = [1, 2].iter().map(|&t| mrays_per_second(&primary, t, 7, trace)).collect();
        let i: Vec<f64> = [1, 2].iter().map(|&t| mrays_per_second(&incoherent, t, 7, trace)).collect();
        println!(
            "{name:<12} {:>12.1} {:>12.1} {:>7.1} / {:>6.1} {:>7.2} / {:>6.2}",
            b1.as_secs_f64() * 1e3,
            b2.as_secs_f64() * 1e3,
            p[0],
            p[1],
            i[0],
            i[1]
        );
    }
    let hits_ours = primary.iter().filter(|r| our_trace(r)).count();
    let hits_peer = primary.iter().filter(|r| peer_trace(r)).count();
    println!("primary hits: ours {hits_ours}, obvhs {hits_peer} of {}", primary.len());
}
