//! The O(n) linear scan on the project's Cornell box: the baseline every
//! acceleration structure is measured against.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rtgi_accel::{AccelKind, BuildParams};
use rtgi_benches::project_scene;
use rtgi_render::rays::primary_rays;

fn linear_scan(c: &mut Criterion) {
    let scene = project_scene("cornell-box.toml");
    let accel = AccelKind::Linear.build(&scene.triangle_positions(), &BuildParams::default());
    let rays = primary_rays(&scene.cameras[0], 64, 64);
    let mut group = c.benchmark_group("linear-scan/cornell-box");
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function(BenchmarkId::new("intersect", "primary"), |b| {
        b.iter(|| rays.iter().filter(|r| accel.intersect(r).is_some()).count())
    });
    group.bench_function(BenchmarkId::new("occluded", "primary"), |b| {
        b.iter(|| rays.iter().filter(|r| accel.occluded(r)).count())
    });
    group.finish();
}

criterion_group!(benches, linear_scan);
criterion_main!(benches);
