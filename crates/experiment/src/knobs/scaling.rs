//! `scaling`: the naive O(n) search against the BVHs over triangle counts
//! from 10 to 10^6, time per ray on log-log axes with fitted exponents:
//! where the course's warning that naive timings mislead is checked
//! against measurement.
//!
//! The meshes are spheres tessellated ever finer (closed, every edge
//! shared by two triangles), and the rays run from random points around
//! the sphere to random points inside it, so every ray hits.

use rtgi_accel::AccelKind;
use rtgi_math::{Ray, Rng, Vec3, uniform_sphere};

use crate::plot::{BOUND_NOTE, Corner, Curve, Plot, is_bound, rate_or_bound};
use crate::report::{Point, Report, Series, Table, format_ms, format_number};
use crate::{ExperimentError, Options, Steps};

/// A unit sphere of about `count` triangles: `rows` bands of `2 rows`
/// quads, the poles' quads folded to single triangles.
fn sphere(count: usize) -> Vec<[Vec3; 3]> {
    // Triangles: 2 · columns · (rows − 1) with columns = 2 · rows.
    let rows = ((count as f64 / 4.0).sqrt().round() as usize).max(2);
    let columns = 2 * rows;
    let at = |row: usize, column: usize| {
        let theta = std::f32::consts::PI * row as f32 / rows as f32;
        let phi = std::f32::consts::TAU * (column % columns) as f32 / columns as f32;
        Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut triangles = Vec::with_capacity(2 * rows * columns);
    for row in 0..rows {
        for column in 0..columns {
            let (a, b, c, d) = (at(row, column), at(row, column + 1), at(row + 1, column), at(row + 1, column + 1));
            if row > 0 {
                triangles.push([a, c, b]);
            }
            if row + 1 < rows {
                triangles.push([b, c, d]);
            }
        }
    }
    triangles
}

/// Rays from random points on a sphere of radius 3 to random points in the unit sphere's inner half.
fn rays(count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed, 0);
    (0..count)
        .map(|_| {
            let origin = 3.0 * uniform_sphere(rng.next_f32(), rng.next_f32());
            let target = 0.5 * rng.next_f32().cbrt() * uniform_sphere(rng.next_f32(), rng.next_f32());
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// Meshes from this many triangles up are fitted: below, the per-ray
/// overheads (setting the ray up, the first node) dominate the time.
const LARGE: f64 = 500.0;

/// Bytes the linear scan reads per triangle: three 16-byte corners and a 4-byte index.
const TRIANGLE_BYTES: f64 = 52.0;

/// Triangle data up to this size stays in the caches of a typical server
/// core (a few MiB of L2 and a share of L3).
const CACHED_BYTES: f64 = 2.0 * 1024.0 * 1024.0;

/// Triangle tests the linear scan may spend per count.
const LINEAR_BUDGET: usize = 200_000_000;

pub(super) fn run(options: &Options, mut report: Report, progress: &dyn Fn(&str)) -> Result<Report, ExperimentError> {
    let counts: Vec<usize> = if options.quick {
        vec![10, 100, 1000, 10_000]
    } else {
        vec![10, 30, 100, 300, 1000, 3000, 10_000, 30_000, 100_000, 300_000, 1_000_000]
    };
    let ray_count = if options.quick { 2000 } else { 200_000 };
    let all_rays = rays(ray_count, 7);
    // Ours, then the peers built in (Embree with the `embree` feature), on the same rays.
    let kinds: Vec<AccelKind> = [AccelKind::Linear, AccelKind::Sah, AccelKind::Bvh8]
        .into_iter()
        .chain(AccelKind::PEERS.iter().copied())
        .collect();
    let mut steps = Steps::new(counts.len() * kinds.len(), progress);
    let mut series: Vec<Series> =
        kinds.iter().map(|k| Series { name: k.name().to_owned(), points: Vec::new() }).collect();
    let mut table = Table {
        title: "time per ray (ns, median with min and max) and build time".into(),
        header: ["triangles", "structure", "ns per ray", "build ms", "bytes per triangle", "rays timed"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    for &count in &counts {
        let triangles = sphere(count);
        // The linear scan's answers on the rays it traces: what the others are checked against.
        let mut expected: Vec<Option<rtgi_accel::Hit>> = Vec::new();
        for (kind, series) in kinds.iter().zip(&mut series) {
            steps.next(&format!("{kind} over {} triangles", triangles.len()));
            let params = kind.default_params();
            let (accel, build_ms) = crate::measure::once(|| kind.try_build(&triangles, &params));
            let accel = accel.map_err(|e| ExperimentError::Build(e.to_string()))?;
            let bytes_per_triangle = accel.build_stats().memory_bytes as f64 / triangles.len() as f64;
            let limit = if *kind == AccelKind::Linear {
                (LINEAR_BUDGET / triangles.len()).clamp(64, ray_count)
            } else {
                ray_count
            };
            let rays = &all_rays[..limit];
            let timing = crate::measure::time_rays(rays, options.repeats, |chunk| {
                chunk.iter().filter(|r| accel.intersect(r).is_some()).count()
            });
            // The linear scan's answers on its rays are what the others are checked against.
            let checked = if *kind == AccelKind::Linear { rays } else { &all_rays[..expected.len()] };
            let answers = super::accel::answers(accel.as_ref(), checked);
            let differing = if *kind == AccelKind::Linear {
                expected = answers;
                0
            } else {
                super::accel::disagreements(&answers, &expected)
            };
            let per_ray = |ms: f64| ms * 1e6 / rays.len() as f64;
            let mut point = Point::new(triangles.len() as f64, triangles.len().to_string())
                .with("differing", differing as f64)
                .with("checked", expected.len() as f64)
                .with("ns_per_ray", per_ray(timing.median_ms))
                .with("ns_per_ray_min", per_ray(timing.min_ms))
                .with("ns_per_ray_max", per_ray(timing.max_ms))
                .with("build_ms", build_ms)
                .with("bytes_per_triangle", bytes_per_triangle)
                .with("rays_timed", rays.len() as f64);
            point.time = Some(timing.clone());
            table.rows.push(vec![
                triangles.len().to_string(),
                kind.to_string(),
                format!(
                    "{} ({}–{})",
                    format_number(per_ray(timing.median_ms)),
                    format_number(per_ray(timing.min_ms)),
                    format_number(per_ray(timing.max_ms))
                ),
                format_ms(build_ms),
                format_number(bytes_per_triangle),
                rays.len().to_string(),
            ]);
            series.points.push(point);
        }
    }
    let (mut curves, mut error_curves) = (Vec::new(), Vec::new());
    for s in &series {
        let xy: Vec<(f64, f64)> = s.points.iter().map(|p| (p.x, p.values["ns_per_ray"])).collect();
        let large: Vec<(f64, f64)> = xy.iter().copied().filter(|p| p.0 >= LARGE).collect();
        let quantity = format!("time per ray against triangles (meshes of {LARGE} triangles or more)");
        let label = match report.fit(&s.name, &quantity, xy.len(), &large) {
            Some(fit) => {
                report.findings.push(format!(
                    "{}: time per ray ∝ n^{:.3} ± {:.3}, fitted over the {} meshes of {LARGE} triangles or more",
                    s.name, fit.law.exponent, fit.law.standard_error, fit.law.points
                ));
                format!("{} (n^{:.2})", s.name, fit.law.exponent)
            }
            None => s.name.clone(),
        };
        let bars = s.points.iter().map(|p| Some((p.values["ns_per_ray_min"], p.values["ns_per_ray_max"]))).collect();
        curves.push(Curve::new(label, xy).with_bars(bars));
        let against_time: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|p| (p.values["ns_per_ray"], rate_or_bound(p.values["differing"], p.values["checked"])))
            .collect();
        let x_bars = s.points.iter().map(|p| Some((p.values["ns_per_ray_min"], p.values["ns_per_ray_max"]))).collect();
        let bounds = s.points.iter().map(|p| is_bound(p.values["differing"])).collect();
        error_curves.push(Curve::new(s.name.clone(), against_time).with_x_bars(x_bars).with_bounds(bounds));
    }
    for s in series.iter().skip(1) {
        let sum = |key: &str| s.points.iter().map(|p| p.values[key]).sum::<f64>();
        let peer = AccelKind::PEERS.iter().any(|k| k.name() == s.name);
        report.findings.push(format!(
            "{}: {} of {} answers differ from the linear scan's in any bit, over all mesh sizes{}",
            s.name,
            sum("differing"),
            sum("checked"),
            if peer { " (a peer, outside the exactness contract)" } else { "" }
        ));
    }
    report.plots.push(Plot {
        file: "scaling-error-time.svg".into(),
        title: "Answers differing from the linear scan against time per ray, one point per mesh size".into(),
        x_label: "time per closest-hit ray (ns, median; bars min–max)".into(),
        y_label: format!("answers differing in any bit (fraction of those checked; {BOUND_NOTE})"),
        log_x: true,
        log_y: true,
        curves: error_curves,
        legend: Corner::UpperLeft,
        y_range: None,
    });
    // The naive search's cost per triangle: constant while the triangles
    // fit in the caches, higher once every ray streams them from memory,
    // which bends the fitted exponent above 1.
    if let Some(linear) = series.iter().find(|s| s.name == AccelKind::Linear.name()) {
        let per_triangle: Vec<String> =
            linear.points.iter().map(|p| format!("{:.1} ns at {}", p.values["ns_per_ray"] / p.x, p.label)).collect();
        report
            .findings
            .push(format!("linear: time per ray per triangle (wall time on all threads): {}", per_triangle.join(", ")));
        let cached: Vec<(f64, f64)> = linear
            .points
            .iter()
            .filter(|p| p.x >= LARGE && p.x * TRIANGLE_BYTES <= CACHED_BYTES)
            .map(|p| (p.x, p.values["ns_per_ray"]))
            .collect();
        let quantity = "time per ray against triangles, linear scan, triangles in cache";
        if let Some(fit) = report.fit("linear", quantity, linear.points.len(), &cached).map(|f| f.law) {
            report.findings.push(format!(
                "linear: time per ray ∝ n^{:.3} over the {} meshes from {LARGE} triangles up whose triangles take at most {} MiB",
                fit.exponent,
                fit.points,
                CACHED_BYTES / (1024.0 * 1024.0)
            ));
        }
    }
    report.series = series;
    report.plots.push(Plot {
        file: "scaling.svg".into(),
        title: "Time per ray against triangle count".into(),
        x_label: "mesh size (triangles)".into(),
        y_label: "time per closest-hit ray (ns)".into(),
        log_x: true,
        log_y: true,
        curves,
        legend: Corner::UpperLeft,
        y_range: None,
    });
    report.tables.push(table);
    Ok(report)
}

/// The `scaling` knob.
pub(super) static SCALING: super::Described = super::Described {
    name: "scaling",
    about: "The naive O(n) search against the BVH, over triangle counts.",
    question: "how does the time per ray grow with the triangle count, for the naive search and for the BVH?",
    scenes: super::Scenes::Own("generated meshes"),
    // It measures on scenes of its own, not the subject's.
    run: |_subject, options, report, progress| run(options, report, progress),
};
