//! Build time and single-thread throughput of every BVH variant on the
//! shared bunny, Sponza and conference scenes, beside obvhs' BVH2 built
//! from the same triangles and traced on the same rays.
//!
//! `cargo bench -p rtgi-benches --bench bvh`; scenes that are not found are
//! skipped with a message (set RTGI_SCENES to their folder).

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use rtgi_accel::AccelKind;
use rtgi_benches::shared_scene;
use rtgi_math::Ray;
use rtgi_math::glam::Vec3A;
use rtgi_render::rays::{bounding_sphere_camera, box_rays, primary_rays};

const SCENES: [(&str, &str); 3] = [
    ("bunny", "bunny/stanford-bunny.obj"),
    ("sponza", "sponza-dabrovic/sponza.obj"),
    ("conference", "conference/conference.obj"),
];

fn bvh(c: &mut Criterion) {
    for (name, path) in SCENES {
        let Some(scene) = shared_scene(path) else { continue };
        let triangles = scene.triangle_positions();
        let peer_triangles: Vec<obvhs::triangle::Triangle> = triangles
            .iter()
            .map(|t| obvhs::triangle::Triangle { v0: Vec3A::from(t[0]), v1: Vec3A::from(t[1]), v2: Vec3A::from(t[2]) })
            .collect();
        let variants: Vec<AccelKind> = AccelKind::ALL.iter().copied().filter(|k| k.split_method().is_some()).collect();

        let mut group = c.benchmark_group(format!("build/{name}"));
        group
            .sample_size(10)
            .measurement_time(Duration::from_secs(3))
            .throughput(Throughput::Elements(triangles.len() as u64));
        for &kind in &variants {
            group.bench_function(kind.name(), |b| b.iter(|| kind.build(&triangles, &kind.default_params())));
        }
        group.bench_function("obvhs-bvh2", |b| {
            b.iter(|| build_bvh2_from_tris(&peer_triangles, BvhBuildParams::medium_build(), &mut Duration::default()))
        });
        group.finish();

        let peer = build_bvh2_from_tris(&peer_triangles, BvhBuildParams::medium_build(), &mut Duration::default());
        let peer_leaf_order: Vec<_> = peer.primitive_indices.iter().map(|&i| peer_triangles[i as usize]).collect();
        let batches: [(&str, Vec<Ray>); 2] = [
            ("primary", primary_rays(&bounding_sphere_camera(&scene), 512, 512)),
            ("incoherent", box_rays(&scene, 100_000, 1)),
        ];
        for (batch, rays) in &batches {
            let mut group = c.benchmark_group(format!("trace-{batch}/{name}"));
            group
                .sample_size(10)
                .measurement_time(Duration::from_secs(3))
                .throughput(Throughput::Elements(rays.len() as u64));
            for &kind in &variants {
                let accel = kind.build(&triangles, &kind.default_params());
                group.bench_function(BenchmarkId::new("rtgi", kind.name()), |b| {
                    b.iter(|| rays.iter().filter(|r| accel.intersect(r).is_some()).count())
                });
                // The batch API: packets of 16 for the wide BVHs where rays are coherent.
                if kind.node_width().is_some_and(|width| width > 2) {
                    let mut hits = vec![None; rays.len()];
                    group.bench_function(BenchmarkId::new("rtgi-batch", kind.name()), |b| {
                        b.iter(|| {
                            accel.intersect_batch(rays, &mut hits);
                            hits.iter().filter(|h| h.is_some()).count()
                        })
                    });
                }
            }
            group.bench_function(BenchmarkId::new("obvhs", "bvh2"), |b| {
                b.iter(|| {
                    rays.iter()
                        .filter(|r| {
                            let ray = obvhs::ray::Ray::new(r.origin.into(), r.direction.into(), r.t_min, r.t_max);
                            let mut hit = obvhs::ray::RayHit::none();
                            peer.ray_traverse(ray, &mut hit, |r, id| peer_leaf_order[id].intersect(r))
                        })
                        .count()
                })
            });
            group.finish();
        }
    }
}

criterion_group!(benches, bvh);
criterion_main!(benches);
