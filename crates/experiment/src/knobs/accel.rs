//! `accel`: every structure, leaf size and bin count: build time, trace
//! time for camera and incoherent rays (one ray at a time, and through the
//! batch API, which traces coherent rays of the wide BVHs as packets),
//! nodes visited and triangles tested per ray, and how many answers differ
//! from the linear scan's (zero for every structure of the contract: the
//! structures cost time, not accuracy).

use rayon::prelude::*;
use rtgi_accel::{Accel, AccelKind, BuildParams, Hit, TraversalCounters};
use rtgi_math::Ray;
use rtgi_render::rays::{primary_rays, surface_rays};

use crate::plot::{Corner, Curve, Plot};
use crate::report::{Point, Report, Series, Table, format_ms, format_number};
use crate::runner::{build_timed, time_rays};
use crate::stats::Timing;
use crate::{ExperimentError, Options, Steps, Subject};

/// Rays the linear scan answers, evenly spaced through each batch: the
/// scan costs a triangle test per triangle per ray.
const LINEAR_TRIANGLE_TESTS: usize = 200_000_000;

/// Rays whose nodes visited and triangles tested are counted, per batch.
const COUNTED_RAYS: usize = 100_000;

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
    list
}

fn answers(accel: &dyn Accel, rays: &[Ray]) -> Vec<Option<Hit>> {
    rays.par_iter().map(|r| accel.intersect(r)).collect()
}

/// Answers that differ in any bit (triangle, t, beta or gamma).
fn disagreements(a: &[Option<Hit>], b: &[Option<Hit>]) -> usize {
    let bits = |h: &Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.beta.to_bits(), h.gamma.to_bits()));
    a.iter().zip(b).filter(|(x, y)| bits(x) != bits(y)).count()
}

fn every_nth(rays: &[Ray], budget: usize) -> Vec<Ray> {
    let stride = rays.len().div_ceil(budget.max(1)).max(1);
    rays.iter().step_by(stride).copied().collect()
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
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    let repeats = options.repeats.max(1);
    for (index, (name, kind, params)) in configurations.iter().enumerate() {
        steps.next(name);
        let (accel, build) = build_timed(&triangles, *kind, params, repeats)?;
        let mut point = Point::new(index as f64, name.clone());
        point.time = Some(build);
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
            let single =
                time_rays(rays, repeats, |chunk| chunk.iter().filter(|r| accel.intersect(r).is_some()).count());
            let batched = time_rays(rays, repeats, |chunk| {
                let mut hits = vec![None; chunk.len()];
                accel.intersect_batch(chunk, &mut hits);
                hits.iter().filter(|h| h.is_some()).count()
            });
            let mrays = |t: &Timing| rays.len() as f64 / (t.median_ms * 1e3);
            // Evenly spaced: camera rays come in tiles, and the first ones may all be sky.
            let counted_rays = &every_nth(rays, COUNTED_RAYS);
            let counters = counted_rays
                .par_chunks(1024)
                .map(|chunk| {
                    let mut counters = TraversalCounters::default();
                    for ray in chunk {
                        accel.intersect_counted(ray, &mut counters);
                    }
                    counters
                })
                .reduce(TraversalCounters::default, |mut a, b| {
                    a += b;
                    a
                });
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
        table.rows.push(cells);
        report.series.push(Series { name: name.clone(), points: vec![point] });
    }
    let total_wrong: f64 = report
        .series
        .iter()
        .flat_map(|s| &s.points)
        .map(|p| p.values["camera_disagreements"] + p.values["incoherent_disagreements"])
        .sum();
    report.findings.push(format!(
        "{} configurations; {} answers (single-ray and batch) differ from the linear scan's in any bit",
        report.series.len(),
        total_wrong
    ));
    if let Some(fastest) = report
        .series
        .iter()
        .flat_map(|s| &s.points)
        .max_by(|a, b| a.values["incoherent_mrays"].total_cmp(&b.values["incoherent_mrays"]))
    {
        report.findings.push(format!(
            "fastest on incoherent rays: {} ({:.2} Mrays/s, build {} ms)",
            fastest.label,
            fastest.values["incoherent_mrays"],
            format_ms(fastest.time.expect("measured").median_ms)
        ));
    }
    let defaults: Vec<&Series> = report.series.iter().take(AccelKind::ALL.len()).collect();
    let per_batch = |batch: &str| -> Vec<Curve> {
        let label = |s: &&Series| s.name.clone();
        defaults
            .iter()
            .map(|s| {
                let p = &s.points[0];
                Curve::new(label(s), vec![(p.time.expect("measured").median_ms, p.values[&format!("{batch}_mrays")])])
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
            title: format!("Build time against {batch} ray throughput"),
            x_label: "build time (ms, median)".into(),
            y_label: format!("{batch} rays (Mrays/s, median with min and max)"),
            log_x: true,
            log_y: true,
            curves: per_batch(batch),
            legend: Corner::LowerRight,
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
        x_label: "most triangles per leaf".into(),
        y_label: "incoherent rays (Mrays/s)".into(),
        log_x: true,
        log_y: false,
        curves: vec![leaf("sah"), leaf("bvh8")],
        legend: Corner::LowerRight,
    });
    report.tables.push(table);
    Ok(report)
}
