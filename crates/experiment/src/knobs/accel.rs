//! `accel`: every structure, leaf size and bin count: build time, trace
//! time for camera and incoherent rays (one ray at a time, and through the
//! batch API, which traces coherent rays of the wide BVHs as packets),
//! nodes visited and triangles tested per ray, and how many answers differ
//! from the linear scan's (zero for every structure of the contract: the
//! structures cost time, not accuracy). The peers built in (Embree, with
//! the `embree` feature) are measured on the same rays, outside the
//! contract. Each structure reports its memory per triangle, build plus N
//! rays' trace time, and the ray count from which a structure that builds
//! slower but traces faster pays for its build.

use rayon::prelude::*;
use rtgi_accel::{Accel, AccelKind, BuildParams, Hit};
use rtgi_math::Ray;
use rtgi_render::rays::{primary_rays, surface_rays};

use crate::measure::{TraceCost, every_nth, trace_cost};
use crate::plot::{BOUND_NOTE, Corner, Curve, Plot, is_bound, rate_or_bound};
use crate::report::{Point, Report, Series, Table, format_ms, format_number};
use crate::stats::Timing;
use crate::verdict::{compare, resolved_lower};
use crate::{ExperimentError, Options, Steps, Subject};

/// Rays the linear scan answers, evenly spaced through each batch: the
/// scan costs a triangle test per triangle per ray.
const LINEAR_TRIANGLE_TESTS: usize = 200_000_000;

/// Rays whose nodes visited and triangles tested are counted, per batch.
const COUNTED_RAYS: usize = 100_000;

/// Ray counts of the build + trace totals.
const TOTAL_RAYS: [f64; 3] = [1e3, 1e6, 1e9];

/// The structures and parameters measured: each structure with its
/// defaults, then leaf sizes of the SAH and bvh8 builds, then SAH bin counts.
fn configurations(triangles: usize, quick: bool) -> Vec<(String, AccelKind, BuildParams)> {
    let mut list = Vec::new();
    for &kind in AccelKind::ALL {
        // The full-sweep SAH sorts three times per node: minutes on big scenes.
        if kind == AccelKind::SahSweep && triangles > 200_000 {
            continue;
        }
        list.push((kind.name().to_owned(), kind, kind.default_params()));
    }
    for &kind in AccelKind::PEERS {
        list.push((kind.name().to_owned(), kind, kind.default_params()));
    }
    let leaf_sizes: &[usize] = if quick { &[1, 16] } else { &[1, 2, 4, 8, 16] };
    for kind in [AccelKind::Sah, AccelKind::Bvh8] {
        for &max_leaf_size in leaf_sizes {
            let params = BuildParams { max_leaf_size, ..kind.default_params() };
            if params != kind.default_params() {
                list.push((format!("{kind} leaf {max_leaf_size}"), kind, params));
            }
        }
    }
    let bins: &[usize] = if quick { &[4] } else { &[4, 8, 32, 64] };
    for &sah_bins in bins {
        let params = BuildParams { sah_bins, ..AccelKind::Sah.default_params() };
        list.push((format!("sah bins {sah_bins}"), AccelKind::Sah, params));
    }
    // The course's SAH: the longest axis only, at the bin borders.
    for kind in [AccelKind::Sah, AccelKind::Bvh8] {
        let params = BuildParams { sah_axes: rtgi_accel::SahAxes::Longest, ..kind.default_params() };
        list.push((format!("{kind} sah axes longest"), kind, params));
    }
    // The SAH's traversal cost against a leaf test: low costs make deep
    // trees of small leaves, high costs shallow trees of large ones.
    // Each structure's own default is its base row (a quarter for bvh8), so
    // 1 appears only for the structures whose default it is not.
    let costs: &[f32] = if quick { &[4.0] } else { &[0.25, 0.5, 1.0, 2.0, 4.0] };
    for kind in [AccelKind::Sah, AccelKind::Bvh8] {
        for &traversal_cost in costs {
            let params = BuildParams { traversal_cost, ..kind.default_params() };
            if params != kind.default_params() {
                list.push((format!("{kind} traversal cost {traversal_cost}"), kind, params));
            }
        }
    }
    list
}

/// Each ray's closest hit, on all threads.
pub(super) fn answers(accel: &dyn Accel, rays: &[Ray]) -> Vec<Option<Hit>> {
    rays.par_iter().map(|r| accel.intersect(r)).collect()
}

/// Answers that differ in any bit (triangle, t, beta or gamma).
pub(super) fn disagreements(a: &[Option<Hit>], b: &[Option<Hit>]) -> usize {
    let bits = |h: &Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.beta.to_bits(), h.gamma.to_bits()));
    a.iter().zip(b).filter(|(x, y)| bits(x) != bits(y)).count()
}

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let triangles = subject.scene.triangle_positions();
    let (side, incoherent_count) = if options.quick { (64, 4096) } else { (1024, 1_000_000) };
    let batches = [
        ("camera", primary_rays(&subject.camera, side, side)),
        ("incoherent", surface_rays(&subject.scene, incoherent_count, 1)),
    ];
    // The reference answers: the linear scan on a subset of each batch.
    let linear = AccelKind::Linear.build(&triangles, &BuildParams::default());
    let budget = (LINEAR_TRIANGLE_TESTS / triangles.len().max(1)).max(256);
    let checked: Vec<(Vec<Ray>, Vec<Option<Hit>>)> = batches
        .iter()
        .map(|(_, rays)| {
            let subset = every_nth(rays, budget);
            let expected = answers(linear.as_ref(), &subset);
            (subset, expected)
        })
        .collect();
    let configurations = configurations(triangles.len(), options.quick);
    let mut steps = Steps::new(configurations.len(), progress);
    let mut table = Table {
        title: format!(
            "{} triangles; {}² camera rays and {} incoherent rays (from surface points in uniform directions); \
             answers compared with the linear scan's on {} and {} of them, which are also the rays the \
             linear scan itself is timed on",
            triangles.len(),
            side,
            incoherent_count,
            checked[0].0.len(),
            checked[1].0.len()
        ),
        header: [
            "structure",
            "build ms",
            "camera Mrays/s",
            "camera batch",
            "incoherent Mrays/s",
            "incoherent batch",
            "nodes/ray (camera, incoh.)",
            "triangles/ray (camera, incoh.)",
            "disagreements",
            "bytes/triangle",
            "build + 10⁶ incoherent rays ms",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let repeats = options.repeats.max(1);
    for (index, (name, kind, params)) in configurations.iter().enumerate() {
        steps.next(name);
        let (accel, build) = crate::measure::build(&triangles, *kind, params, repeats)?;
        let bytes_per_triangle = accel.build_stats().memory_bytes as f64 / triangles.len().max(1) as f64;
        let mut point = Point::new(index as f64, name.clone());
        point.time = Some(build.clone());
        let mut cells = vec![
            name.clone(),
            format!("{} ({}–{})", format_ms(build.median_ms), format_ms(build.min_ms), format_ms(build.max_ms)),
        ];
        let (mut nodes, mut tests) = (Vec::new(), Vec::new());
        let mut rates = Vec::new();
        for ((batch, all_rays), (subset, expected)) in batches.iter().zip(&checked) {
            // The linear scan is timed on the subset it answers for the
            // others: on the whole batch it would take hours.
            let rays: &[Ray] = if *kind == AccelKind::Linear { subset } else { all_rays };
            let TraceCost { single, batched } = trace_cost(accel.as_ref(), rays, repeats);
            let mrays = |t: &Timing| rays.len() as f64 / (t.median_ms * 1e3);
            // Evenly spaced: camera rays come in tiles, and the first ones may all be sky.
            let counted_rays = &every_nth(rays, COUNTED_RAYS);
            let (counters, _) = crate::measure::count(accel.as_ref(), counted_rays);
            let counted = counted_rays.len().max(1) as f64;
            let wrong = disagreements(&answers(accel.as_ref(), subset), expected);
            let mut batch_answers = vec![None; subset.len()];
            accel.intersect_batch(subset, &mut batch_answers);
            let wrong_batched = disagreements(&batch_answers, expected);
            point = point
                .with(&format!("{batch}_mrays"), mrays(&single))
                .with(&format!("{batch}_mrays_min"), rays.len() as f64 / (single.max_ms * 1e3))
                .with(&format!("{batch}_mrays_max"), rays.len() as f64 / (single.min_ms * 1e3))
                .with(&format!("{batch}_batch_mrays"), mrays(&batched))
                .with(&format!("{batch}_nodes_per_ray"), counters.nodes_visited as f64 / counted)
                .with(&format!("{batch}_triangles_per_ray"), counters.triangles_tested as f64 / counted)
                .with(&format!("{batch}_disagreements"), (wrong + wrong_batched) as f64)
                .with(&format!("{batch}_rays_checked"), subset.len() as f64)
                .with(&format!("{batch}_rays_timed"), rays.len() as f64);
            point.timings.insert(format!("{batch}_trace"), single.clone());
            point.timings.insert(format!("{batch}_batch_trace"), batched.clone());
            rates.push(format_number(mrays(&single)));
            rates.push(format_number(mrays(&batched)));
            nodes.push(format_number(counters.nodes_visited as f64 / counted));
            tests.push(format_number(counters.triangles_tested as f64 / counted));
        }
        cells.extend(rates);
        cells.push(nodes.join(", "));
        cells.push(tests.join(", "));
        let wrong = point.values["camera_disagreements"] + point.values["incoherent_disagreements"];
        cells.push(format!("{wrong}"));
        if kind.is_peer() {
            // A peer's backend counts no nodes or triangle tests.
            let len = cells.len();
            cells[len - 3] = "–".into();
            cells[len - 2] = "–".into();
        }
        // Build, then N incoherent rays one at a time on all threads.
        let ms_per_ray = 1.0 / (point.values["incoherent_mrays"] * 1e3);
        for n in TOTAL_RAYS {
            point = point.with(&format!("total_ms_{n:e}"), build.median_ms + n * ms_per_ray);
        }
        point = point.with("bytes_per_triangle", bytes_per_triangle).with("incoherent_ms_per_ray", ms_per_ray);
        if kind.is_peer() {
            point = point.with("peer", 1.0);
        }
        cells.push(format_number(bytes_per_triangle));
        cells.push(format_ms(build.median_ms + 1e6 * ms_per_ray));
        table.rows.push(cells);
        report.series.push(Series { name: name.clone(), points: vec![point] });
    }
    let ours = |s: &&Series| !s.points[0].values.contains_key("peer");
    let total_wrong: f64 = report
        .series
        .iter()
        .filter(ours)
        .flat_map(|s| &s.points)
        .map(|p| p.values["camera_disagreements"] + p.values["incoherent_disagreements"])
        .sum();
    report.findings.push(format!(
        "{} configurations of ours; {} answers (single-ray and batch) differ from the linear scan's in any bit",
        report.series.iter().filter(ours).count(),
        total_wrong
    ));
    for peer in report.series.iter().filter(|s| !ours(s)) {
        let p = &peer.points[0];
        let checked = p.values["camera_rays_checked"] + p.values["incoherent_rays_checked"];
        report.findings.push(format!(
            "{} (a peer, outside the exactness contract): {} of {} answers differ from the linear scan's in some bit",
            peer.name,
            p.values["camera_disagreements"] + p.values["incoherent_disagreements"],
            2.0 * checked
        ));
    }
    // The fastest on incoherent rays, and whether the runner-up is told apart from it.
    let mut by_speed: Vec<&Point> = report.series.iter().flat_map(|s| &s.points).collect();
    by_speed.sort_by(|a, b| b.values["incoherent_mrays"].total_cmp(&a.values["incoherent_mrays"]));
    let trace_runs = |p: &Point| p.timings.get("incoherent_trace").map(Timing::samples).unwrap_or_default();
    if let [fastest, second, ..] = &by_speed[..] {
        report.findings.push(format!(
            "incoherent rays, the two fastest: {}",
            compare("trace time", &second.label, &trace_runs(second), &fastest.label, &trace_runs(fastest))
        ));
    }
    // One configuration per structure with its defaults (and the peers), whatever was skipped.
    let defaults: Vec<&Series> = report
        .series
        .iter()
        .filter(|s| AccelKind::ALL.iter().chain(AccelKind::PEERS).any(|k| k.name() == s.name))
        .collect();
    // Build + N rays: where a structure that builds slower but traces
    // faster than the next cheaper one pays for its build.
    let mut by_build: Vec<&Point> = defaults.iter().map(|s| &s.points[0]).collect();
    by_build.sort_by(|a, b| {
        a.time.as_ref().expect("measured").median_ms.total_cmp(&b.time.as_ref().expect("measured").median_ms)
    });
    for pair in by_build.windows(2) {
        let (cheap, dear) = (pair[0], pair[1]);
        let (build_cheap, build_dear) = (cheap.time.as_ref().expect("measured"), dear.time.as_ref().expect("measured"));
        let (ray_cheap, ray_dear) = (cheap.values["incoherent_ms_per_ray"], dear.values["incoherent_ms_per_ray"]);
        if ray_dear >= ray_cheap {
            continue;
        }
        // A break-even is a finding only where both differences it rests on
        // are resolved: the builds' runs and the traces' runs.
        let builds_apart = resolved_lower(&build_cheap.samples(), &build_dear.samples());
        let traces_apart = resolved_lower(&trace_runs(dear), &trace_runs(cheap));
        if builds_apart && traces_apart {
            let rays = (build_dear.median_ms - build_cheap.median_ms) / (ray_cheap - ray_dear);
            report.findings.push(format!(
                "{} builds in {} ms more than {} and pays for it from {} incoherent rays on (both differences \
                 resolved at {:.0}% confidence)",
                dear.label,
                format_ms(build_dear.median_ms - build_cheap.median_ms),
                cheap.label,
                format_number(rays.max(0.0)),
                100.0 * crate::verdict::CONFIDENCE
            ));
        } else {
            let unresolved = match (builds_apart, traces_apart) {
                (false, false) => "neither their build times nor their trace times are",
                (false, true) => "their build times are not",
                _ => "their trace times are not",
            };
            report.findings.push(format!(
                "{} against {}: no break-even is claimed, as {unresolved} resolved at {:.0}% confidence",
                dear.label,
                cheap.label,
                100.0 * crate::verdict::CONFIDENCE
            ));
        }
    }
    let totals: Vec<Curve> = defaults
        .iter()
        .map(|s| {
            let p = &s.points[0];
            let build = p.time.as_ref().expect("measured").median_ms;
            let per_ray = p.values["incoherent_ms_per_ray"];
            let ns: Vec<f64> = (0..=18).map(|k| 10f64.powf(k as f64 * 0.5)).collect();
            Curve::guide(s.name.clone(), ns.iter().map(|&n| (n, build + n * per_ray)).collect())
        })
        .collect();
    report.plots.push(Plot {
        file: "accel-total.svg".into(),
        title: "Build plus trace time against the rays traced (incoherent, one at a time)".into(),
        x_label: "incoherent rays traced (count)".into(),
        y_label: "total time: build + rays × measured time per ray (ms)".into(),
        log_x: true,
        log_y: true,
        curves: totals,
        legend: Corner::UpperLeft,
        y_range: None,
    });
    // Error against time: the fraction of answers that differ from the
    // linear scan's in any bit, against the time per incoherent ray.
    let checked_of = |p: &Point| 2.0 * (p.values["camera_rays_checked"] + p.values["incoherent_rays_checked"]);
    let errors: Vec<Curve> = defaults
        .iter()
        .map(|s| {
            let p = &s.points[0];
            let wrong = p.values["camera_disagreements"] + p.values["incoherent_disagreements"];
            let ns = p.values["incoherent_ms_per_ray"] * 1e6;
            let spread = (1e3 / p.values["incoherent_mrays_max"], 1e3 / p.values["incoherent_mrays_min"]);
            Curve::new(s.name.clone(), vec![(ns, rate_or_bound(wrong, checked_of(p)))])
                .with_x_bars(vec![Some(spread)])
                .with_bounds(vec![is_bound(wrong)])
        })
        .collect();
    let exact = defaults.iter().filter(|s| {
        let p = &s.points[0];
        p.values["camera_disagreements"] + p.values["incoherent_disagreements"] == 0.0
    });
    let checked = defaults.first().map_or(0.0, |s| checked_of(&s.points[0]));
    report.plots.push(Plot {
        file: "accel-error-time.svg".into(),
        title: format!(
            "Answers differing from the linear scan against time per ray: none of {} for {} of {} structures",
            checked,
            exact.count(),
            defaults.len()
        ),
        x_label: "time per incoherent ray (ns, all threads; bars min–max)".into(),
        y_label: format!("answers differing in any bit (fraction of those checked; {BOUND_NOTE})"),
        log_x: true,
        log_y: true,
        curves: errors,
        legend: Corner::UpperRight,
        y_range: None,
    });

    let per_batch = |batch: &str| -> Vec<Curve> {
        let label = |s: &&Series| s.name.clone();
        defaults
            .iter()
            .map(|s| {
                let p = &s.points[0];
                Curve::new(
                    label(s),
                    vec![(p.time.as_ref().expect("measured").median_ms, p.values[&format!("{batch}_mrays")])],
                )
                .with_bars(vec![Some((
                    p.values[&format!("{batch}_mrays_min")],
                    p.values[&format!("{batch}_mrays_max")],
                ))])
            })
            .collect()
    };
    for batch in ["camera", "incoherent"] {
        report.plots.push(Plot {
            file: format!("accel-{batch}.svg"),
            title: format!(
                "{} ray throughput against build time",
                if batch == "camera" { "Camera" } else { "Incoherent" }
            ),
            x_label: "build time (ms, median)".into(),
            y_label: format!("{batch} rays (Mrays/s, median with min and max)"),
            log_x: true,
            log_y: true,
            curves: per_batch(batch),
            legend: Corner::LowerRight,
            y_range: None,
        });
    }
    let leaf = |kind: &str| -> Curve {
        let points: Vec<&Point> = report
            .series
            .iter()
            .filter(|s| s.name == kind || s.name.starts_with(&format!("{kind} leaf ")))
            .map(|s| &s.points[0])
            .collect();
        let mut xy: Vec<(f64, f64, f64, f64)> = points
            .iter()
            .map(|p| {
                let leaf = p
                    .label
                    .rsplit(' ')
                    .next()
                    .and_then(|n| n.parse::<f64>().ok())
                    .unwrap_or(kind.parse::<AccelKind>().map_or(4.0, |k| k.default_params().max_leaf_size as f64));
                (leaf, p.values["incoherent_mrays"], p.values["incoherent_mrays_min"], p.values["incoherent_mrays_max"])
            })
            .collect();
        xy.sort_by(|a, b| a.0.total_cmp(&b.0));
        Curve::new(kind, xy.iter().map(|p| (p.0, p.1)).collect())
            .with_bars(xy.iter().map(|p| Some((p.2, p.3))).collect())
    };
    report.plots.push(Plot {
        file: "accel-leaf-size.svg".into(),
        title: "Incoherent ray throughput against leaf size".into(),
        x_label: "leaf size limit (triangles)".into(),
        y_label: "incoherent rays (Mrays/s)".into(),
        log_x: true,
        log_y: false,
        curves: vec![leaf("sah"), leaf("bvh8")],
        legend: Corner::LowerRight,
        y_range: None,
    });
    report.tables.push(table);
    Ok(report)
}

/// The `accel` knob.
pub(super) static ACCEL_STRUCTURES: super::Described = super::Described {
    name: "accel",
    about: "The acceleration structures and their build parameters.",
    question: "what does each acceleration structure cost to build and to trace, and does it change any answer?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::BUNNY, super::SPONZA, super::CONFERENCE]),
    run,
};
