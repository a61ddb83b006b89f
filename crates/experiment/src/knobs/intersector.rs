//! `intersector`: every ray/triangle test of `rtgi_accel::Intersector::ALL`
//! (watertight, Möller-Trumbore, watertight in double precision), each with
//! the subject's structure rebuilt for it: what it costs per ray on the
//! subject's scene, and how often it fails on the hard cases of `rtgi
//! verify`: rays exactly through shared edges and vertices of closed
//! meshes that escape (leaks), and secondary rays that hit the surface
//! they leave (self-hits) on closed solids ever farther from the origin.
//!
//! The hard cases come from `rtgi_accel::verify`, the generators `rtgi
//! verify` and the hard-case tests use: the two-triangle square whose
//! diagonal rays pass exactly through the shared edge, the closed solids
//! with rays from inside aimed at their vertices and edge midpoints, and,
//! for each distance, the `secondary` rays (spawned from surface points as
//! the renderer spawns them) of the placed solids and rays from inside
//! them aimed at their vertices and edge midpoints.

use rtgi_accel::verify::shapes::{quad, rays_through_diagonal};
use rtgi_accel::verify::{Answer, Expect, ProbeRay, RayKind, Tally, solids};
use rtgi_accel::{Accel, AccelKind, BuildParams, Intersector};
use rtgi_math::{Ray, Vec3};
use rtgi_render::rays::{primary_rays, surface_rays};

use crate::measure::time_rays;
use crate::plot::{BOUND_NOTE, Corner, Curve, Plot, is_bound, rate_or_bound};
use crate::report::{Point, Report, Series, Table, format_number};
use crate::stats::Timing;
use crate::{ExperimentError, Options, Steps, Subject};

/// The structure the subject was built with, to be rebuilt with each
/// intersector: a peer (Embree) has its own test and cannot be.
fn subject_kind(subject: &Subject) -> Result<AccelKind, ExperimentError> {
    let variant = &subject.accel.build_stats().variant;
    match variant.parse::<AccelKind>() {
        Ok(kind) if !kind.is_peer() => Ok(kind),
        _ => Err(ExperimentError::Unsuitable(format!(
            "the intersector experiment rebuilds the structure with each ray/triangle test; \
             '{variant}' has a test of its own: choose one of {}",
            AccelKind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// Squares whose shared diagonal the rays cross exactly, as in
/// `tests/tests/accel/hard_cases.rs`: at the origin, 2^20 and 2^24 away, and tiny;
/// `(size, offset, bits)` with the grid `size / 2^bits` no finer than the
/// coordinates' ulp, so that every ray's aim is exact.
const SHARED_EDGES: [(f32, f32, u32); 4] =
    [(1.0, 0.0, 20), (1024.0, 1048576.0, 13), (65536.0, 16777216.0, 15), (1.0 / 1024.0, 0.0, 20)];

/// The ulp of `x`: the gap between it and the next float up.
fn ulp(x: f32) -> f32 {
    rtgi_math::next_float_up(x.abs()) - x.abs()
}

/// Where the solids go: `2^exponent` along a direction off every axis,
/// scaled up from unit size where the coordinates' ulp would otherwise
/// flatten their shape (at least 64 ulps across).
fn placement(exponent: i32) -> (f32, Vec3) {
    let offset = Vec3::new(1.0, 0.75, -0.5) * 2f32.powi(exponent);
    (1f32.max(64.0 * ulp(offset.abs().max_element())), offset)
}

/// The hard cases at one distance from the origin: every solid placed
/// there, its secondary rays, and rays from inside it that must hit it.
struct Placed {
    triangles: Vec<Vec<[Vec3; 3]>>,
    secondary: Vec<Vec<ProbeRay>>,
    escaping: Vec<Vec<ProbeRay>>,
}

impl Placed {
    fn new(exponent: i32, rays: usize, seed: u64) -> Placed {
        let (scale, offset) = placement(exponent);
        let (mut triangles, mut secondary, mut escaping) = (Vec::new(), Vec::new(), Vec::new());
        for (_, solid) in solids() {
            let mesh = solid.mesh.placed(scale, offset);
            let inside = |rng: &mut rtgi_math::Rng| offset + (solid.inside)(rng) * scale;
            escaping.push(must_hit(mesh.leak_rays(inside, rays, seed)));
            triangles.push(mesh.triangles());
            secondary.push(RayKind::Secondary.rays(triangles.last().expect("just pushed"), rays, seed));
        }
        Placed { triangles, secondary, escaping }
    }
}

/// Rays that must hit something (they cross a closed surface or a shared edge).
fn must_hit(rays: Vec<Ray>) -> Vec<ProbeRay> {
    rays.into_iter().map(|ray| ProbeRay { ray, expect: Expect::HitBy(f32::INFINITY) }).collect()
}

/// Traces `probes` through `accel` (closest and any hit) and tallies leaks and self-hits.
fn tally(accel: &dyn Accel, probes: &[ProbeRay]) -> Tally {
    Tally::of(probes, &Answer::all(accel, probes), None)
}

fn percent(failures: usize, rays: usize) -> f64 {
    100.0 * failures as f64 / rays.max(1) as f64
}

fn format_rate(failures: usize, rays: usize) -> String {
    format!("{failures} of {rays} ({}%)", format_number(percent(failures, rays)))
}

/// Mrays/s of a timing over `rays` rays: the median and the range.
fn mrays(t: &Timing, rays: usize) -> (f64, f64, f64) {
    let rate = |ms: f64| rays as f64 / (ms * 1e3);
    (rate(t.median_ms), rate(t.max_ms), rate(t.min_ms))
}

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let kind = subject_kind(subject)?;
    let repeats = options.repeats.max(1);
    let scene_triangles = subject.scene.triangle_positions();
    let (side, incoherent_count, edge_rays, leak_rays, per_solid) =
        if options.quick { (64, 4096, 500, 500, 200) } else { (512, 500_000, 100_000, 100_000, 20_000) };
    let exponents: Vec<i32> = if options.quick { vec![0, 12, 23] } else { (0..=23).collect() };
    let batches = [
        ("camera", primary_rays(&subject.camera, side, side)),
        ("incoherent", surface_rays(&subject.scene, incoherent_count, 1)),
    ];
    // Rays exactly through shared edges: each must hit one of the two triangles.
    let edge_cases: Vec<(Vec<[Vec3; 3]>, Vec<ProbeRay>)> = SHARED_EDGES
        .iter()
        .enumerate()
        .map(|(i, &(size, offset, bits))| {
            let rays = rays_through_diagonal(size, Vec3::splat(offset), bits, edge_rays, 11 + i as u64);
            (quad(size, Vec3::splat(offset)), must_hit(rays))
        })
        .collect();
    // Rays from inside the closed solids, half aimed at their vertices and edge midpoints.
    let mesh_cases: Vec<(Vec<[Vec3; 3]>, Vec<ProbeRay>)> = solids()
        .iter()
        .enumerate()
        .map(|(i, (_, solid))| {
            (solid.mesh.triangles(), must_hit(solid.mesh.leak_rays(solid.inside, leak_rays, 5 + i as u64)))
        })
        .collect();
    let placed: Vec<Placed> = exponents.iter().map(|&e| Placed::new(e, per_solid, 3 + e as u64)).collect();

    let mut steps = Steps::new(Intersector::ALL.len() * 2, progress);
    let mut table = Table {
        title: format!(
            "{kind} rebuilt for each test over {} triangles: {side}² camera rays and {incoherent_count} incoherent \
             rays one at a time (Mrays/s, median with min and max); rays exactly through the shared diagonal of \
             squares at 0, 2^20 and 2^24 from the origin and of size 2^-10 ({} each), and rays from inside an \
             icosphere, a tessellated cube and a cylinder, half aimed at their vertices and edge midpoints ({} \
             each), that escape",
            scene_triangles.len(),
            edge_rays,
            leak_rays
        ),
        header: [
            "intersector",
            "camera Mrays/s",
            "incoherent Mrays/s",
            "lost through shared edges",
            "escaped from closed meshes",
            "self-hits (all distances)",
            "escaped (all distances)",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let mut distance_table = Table {
        title: format!(
            "Secondary rays spawned from surface points (as the renderer spawns them) that hit the triangle they \
             leave, and rays from inside aimed at vertices and edge midpoints (half) or anywhere (half) that \
             escape, on the three solids placed at 2^k · (1, 0.75, -0.5), of unit size or 64 ulps across where \
             that is larger; {per_solid} rays of each kind per solid"
        ),
        header: ["distance", "intersector", "self-hits", "escaped", "µs per ray (median)"].map(String::from).to_vec(),
        rows: Vec::new(),
    };
    for &intersector in Intersector::ALL {
        let params = BuildParams { intersector, ..kind.default_params() };
        steps.next(&format!("{intersector}: tracing the scene's rays through {kind}"));
        let accel = kind.try_build(&scene_triangles, &params).map_err(|e| ExperimentError::Build(e.to_string()))?;
        let mut scene_point = Point::new(0.0, intersector.name());
        let mut cells = vec![intersector.name().to_owned()];
        for (batch, rays) in &batches {
            let timing =
                time_rays(rays, repeats, |chunk| chunk.iter().filter(|r| accel.intersect(r).is_some()).count());
            let (median, low, high) = mrays(&timing, rays.len());
            scene_point = scene_point
                .with(&format!("{batch}_mrays"), median)
                .with(&format!("{batch}_mrays_min"), low)
                .with(&format!("{batch}_mrays_max"), high);
            if *batch == "camera" {
                scene_point.time = Some(timing.clone());
            }
            cells.push(format!("{:.2} ({:.2}–{:.2})", median, low, high));
        }
        steps.next(&format!("{intersector}: hard cases"));
        let build = |triangles: &[[Vec3; 3]]| {
            kind.try_build(triangles, &params).map_err(|e| ExperimentError::Build(e.to_string()))
        };
        let (mut edge_leaks, mut edge_total) = (0, 0);
        for (triangles, probes) in &edge_cases {
            let t = tally(build(triangles)?.as_ref(), probes);
            edge_leaks += t.leaks;
            edge_total += t.rays;
        }
        let (mut mesh_leaks, mut mesh_total) = (0, 0);
        for (triangles, probes) in &mesh_cases {
            let t = tally(build(triangles)?.as_ref(), probes);
            mesh_leaks += t.leaks;
            mesh_total += t.rays;
        }
        scene_point = scene_point
            .with("shared_edge_leaks", edge_leaks as f64)
            .with("shared_edge_rays", edge_total as f64)
            .with("shared_edge_leak_percent", percent(edge_leaks, edge_total))
            .with("closed_mesh_leaks", mesh_leaks as f64)
            .with("closed_mesh_rays", mesh_total as f64)
            .with("closed_mesh_leak_percent", percent(mesh_leaks, mesh_total));
        cells.push(format_rate(edge_leaks, edge_total));
        cells.push(format_rate(mesh_leaks, mesh_total));

        let mut distance_points = Vec::new();
        let (mut all_self_hits, mut all_secondary, mut all_leaks, mut all_escaping) = (0, 0, 0, 0);
        for (&exponent, at) in exponents.iter().zip(&placed) {
            let (mut self_hits, mut secondary, mut leaks, mut escaping) = (0, 0, 0, 0);
            let mut rays: Vec<Ray> = Vec::new();
            let mut accels = Vec::new();
            for ((triangles, spawned), aimed) in at.triangles.iter().zip(&at.secondary).zip(&at.escaping) {
                let accel = build(triangles)?;
                let s = tally(accel.as_ref(), spawned);
                self_hits += s.self_hits;
                secondary += spawned.iter().filter(|p| matches!(p.expect, Expect::NotTriangle(_))).count();
                let a = tally(accel.as_ref(), aimed);
                leaks += a.leaks;
                escaping += aimed.len();
                rays.extend(spawned.iter().chain(aimed).map(|p| p.ray));
                accels.push((accel, spawned.len() + aimed.len()));
            }
            // The time of these rays, solid by solid: how the test's cost
            // changes (or not) with the distance.
            let timing = crate::measure::time(repeats, 1, || {
                let mut offset = 0;
                for (accel, count) in &accels {
                    let chunk = &rays[offset..offset + count];
                    let hits = trace_closest(accel.as_ref(), chunk);
                    std::hint::black_box(hits);
                    offset += count;
                }
            });
            let distance = 2f64.powi(exponent);
            let mut point = Point::new(distance, format!("2^{exponent}"))
                .with("self_hits", self_hits as f64)
                .with("secondary_rays", secondary as f64)
                .with("self_hit_percent", percent(self_hits, secondary))
                .with("escaped", leaks as f64)
                .with("escaping_rays", escaping as f64)
                .with("escaped_percent", percent(leaks, escaping))
                .with("scale", placement(exponent).0 as f64);
            point.time = Some(timing.clone());
            distance_table.rows.push(vec![
                format!("2^{exponent}"),
                intersector.name().to_owned(),
                format_rate(self_hits, secondary),
                format_rate(leaks, escaping),
                format_number(timing.median_ms * 1e3 / rays.len().max(1) as f64),
            ]);
            distance_points.push(point);
            all_self_hits += self_hits;
            all_secondary += secondary;
            all_leaks += leaks;
            all_escaping += escaping;
        }
        cells.push(format_rate(all_self_hits, all_secondary));
        cells.push(format_rate(all_leaks, all_escaping));
        table.rows.push(cells);
        report.series.push(Series { name: intersector.name().to_owned(), points: vec![scene_point] });
        report.series.push(Series { name: format!("{intersector} by distance"), points: distance_points });
    }
    findings(&mut report, kind);
    plots(&mut report);
    report.tables.push(table);
    report.tables.push(distance_table);
    Ok(report)
}

/// Closest-hit answers for `rays`, one at a time on this thread: the timed work.
fn trace_closest(accel: &dyn Accel, rays: &[Ray]) -> usize {
    rays.iter().filter(|r| accel.intersect(r).is_some()).count()
}

/// The scene point and the distance points of each intersector.
fn measured(report: &Report) -> Vec<(String, &Point, &[Point])> {
    report.series.chunks(2).map(|pair| (pair[0].name.clone(), &pair[0].points[0], pair[1].points.as_slice())).collect()
}

fn findings(report: &mut Report, kind: AccelKind) {
    let mut findings = Vec::new();
    let rows = measured(report);
    let base = rows.iter().find(|(name, _, _)| name == Intersector::default().name()).map(|r| r.1);
    for (name, point, by_distance) in &rows {
        let v = &point.values;
        let speed = match base {
            Some(b) if b.values["incoherent_mrays"] > 0.0 && *name != Intersector::default().name() => {
                format!(" ({:.2}× the default's)", v["incoherent_mrays"] / b.values["incoherent_mrays"])
            }
            _ => String::new(),
        };
        let self_hits: f64 = by_distance.iter().map(|p| p.values["self_hits"]).sum();
        let secondary: f64 = by_distance.iter().map(|p| p.values["secondary_rays"]).sum();
        let escaped: f64 = by_distance.iter().map(|p| p.values["escaped"]).sum();
        let escaping: f64 = by_distance.iter().map(|p| p.values["escaping_rays"]).sum();
        let worst = by_distance
            .iter()
            .max_by(|a, b| a.values["self_hit_percent"].total_cmp(&b.values["self_hit_percent"]))
            .filter(|p| p.values["self_hits"] > 0.0)
            .map(|p| format!(", most at {} ({}%)", p.label, format_number(p.values["self_hit_percent"])))
            .unwrap_or_default();
        findings.push(format!(
            "{name} on {kind}: {:.2} Mrays/s camera, {:.2} Mrays/s incoherent{speed}; {} of {} rays through shared \
             edges lost ({}%), {} of {} rays from inside closed meshes escaped ({}%); {} self-hits of {} secondary \
             rays over distances 2^{}…2^{}{worst}; {escaped} of {escaping} rays from inside the solids there \
             escaped",
            v["camera_mrays"],
            v["incoherent_mrays"],
            v["shared_edge_leaks"],
            v["shared_edge_rays"],
            format_number(v["shared_edge_leak_percent"]),
            v["closed_mesh_leaks"],
            v["closed_mesh_rays"],
            format_number(v["closed_mesh_leak_percent"]),
            self_hits,
            secondary,
            by_distance.first().map_or(0.0, |p| p.x.log2()),
            by_distance.last().map_or(0.0, |p| p.x.log2()),
        ));
    }
    report.findings.extend(findings);
}

fn plots(report: &mut Report) {
    let rows = measured(report);
    // Error against time: rays lost at shared edges and from inside closed
    // meshes, against the time per incoherent ray.
    let speed: Vec<Curve> = rows
        .iter()
        .map(|(name, p, _)| {
            let v = &p.values;
            let lost = rate_or_bound(
                v["shared_edge_leaks"] + v["closed_mesh_leaks"],
                v["shared_edge_rays"] + v["closed_mesh_rays"],
            );
            let ns = |mrays: f64| 1e3 / mrays.max(1e-12);
            Curve::new(name.clone(), vec![(ns(v["incoherent_mrays"]), lost)])
                .with_x_bars(vec![Some((ns(v["incoherent_mrays_max"]), ns(v["incoherent_mrays_min"])))])
                .with_bounds(vec![is_bound(v["shared_edge_leaks"] + v["closed_mesh_leaks"])])
        })
        .collect();
    let by_distance = |count: &str, trials: &str| -> Vec<Curve> {
        rows.iter()
            .map(|(name, _, points)| {
                let rates = points.iter().map(|p| (p.x, 100.0 * rate_or_bound(p.values[count], p.values[trials])));
                Curve::new(name.clone(), rates.collect())
                    .with_bounds(points.iter().map(|p| is_bound(p.values[count])).collect())
            })
            .collect()
    };
    let (self_hits, leaks) = (by_distance("self_hits", "secondary_rays"), by_distance("escaped", "escaping_rays"));
    report.plots.push(Plot {
        file: "intersector-speed.svg".into(),
        title: "Rays lost at shared edges and vertices against time per incoherent ray".into(),
        x_label: "time per incoherent ray (ns, one at a time on all threads; bars min–max)".into(),
        y_label: format!(
            "rays that escape through shared edges and from inside closed meshes (fraction of those traced; {BOUND_NOTE})"
        ),
        log_x: true,
        log_y: true,
        curves: speed,
        legend: Corner::LowerRight,
        y_range: None,
    });
    report.plots.push(Plot {
        file: "intersector-self-hits.svg".into(),
        title: "Secondary rays that hit the surface they leave, by distance from the origin".into(),
        x_label: "distance of the solids from the origin (world units)".into(),
        y_label: format!("self-hits (% of secondary rays; {BOUND_NOTE})"),
        log_x: true,
        log_y: true,
        curves: self_hits,
        legend: Corner::UpperLeft,
        y_range: None,
    });
    report.plots.push(Plot {
        file: "intersector-leaks.svg".into(),
        title: "Rays from inside closed solids that escape, by distance from the origin".into(),
        x_label: "distance of the solids from the origin (world units)".into(),
        y_label: format!("escaped (% of rays from inside; {BOUND_NOTE})"),
        log_x: true,
        log_y: true,
        curves: leaks,
        // Möller-Trumbore's losses are highest near the origin.
        legend: Corner::UpperRight,
        y_range: None,
    });
}

/// The `intersector` knob.
pub(super) static INTERSECTORS: super::Described = super::Described {
    name: "intersector",
    about: "The ray/triangle tests: time, and failures on the hard cases of `rtgi verify`.",
    question: "what does each ray/triangle test cost, and how often do rays slip through shared edges or hit the \
            surface they leave?",
    scenes: super::Scenes::Subject(&[super::CORNELL]),
    run,
};
