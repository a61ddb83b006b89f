//! `traversal`: the robust slab test of the binary BVHs' traversal against
//! the textbook one (`Traversal::Robust` and `Fast`): what the robust one
//! costs in time, and what the fast one costs in answers that differ from
//! the linear scan's, on the scene's camera and incoherent rays and on
//! `rtgi verify`'s hard rays for it (axis-parallel, through vertices and
//! edges, grazing silhouettes).

use rtgi_accel::verify::RayKind;
use rtgi_accel::{Accel, AccelKind, BuildParams, Hit, Traversal};
use rtgi_math::Ray;
use rtgi_render::rays::{primary_rays, surface_rays};

use crate::measure::{every_nth, mrays, time_rays};
use crate::plot::{BOUND_NOTE, Corner, Curve, Plot, is_bound, rate_or_bound};
use crate::report::{Point, Report, Series, Table, format_number, format_timing};
use crate::verdict::compare_times;
use crate::{ExperimentError, Options, Steps, Subject};

/// Rays the linear scan answers per batch, at most (it tests every triangle).
const LINEAR_TRIANGLE_TESTS: usize = 100_000_000;

/// The hard rays of `rtgi verify` that grazing boxes decide.
const HARD: [RayKind; 4] = [RayKind::AxisParallel, RayKind::Vertex, RayKind::Edge, RayKind::Silhouette];

/// Answers that differ in any bit.
pub(super) fn differing(accel: &dyn Accel, rays: &[Ray], expected: &[Option<Hit>]) -> usize {
    let bits = |h: Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.beta.to_bits(), h.gamma.to_bits()));
    rays.iter().zip(expected).filter(|(r, e)| bits(accel.intersect(r)) != bits(**e)).count()
}

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let triangles = subject.scene.triangle_positions();
    let (side, incoherent, hard) = if options.quick { (64, 4096, 500) } else { (512, 200_000, 20_000) };
    let mut batches: Vec<(String, Vec<Ray>)> = vec![
        ("camera".into(), primary_rays(&subject.camera, side, side)),
        ("incoherent".into(), surface_rays(&subject.scene, incoherent, 1)),
    ];
    for kind in HARD {
        batches.push((kind.name().into(), kind.rays(&triangles, hard, 3).iter().map(|p| p.ray).collect()));
    }
    let linear = AccelKind::Linear.build(&triangles, &BuildParams::default());
    let budget = (LINEAR_TRIANGLE_TESTS / triangles.len().max(1)).max(256);
    let checked: Vec<(Vec<Ray>, Vec<Option<Hit>>)> = batches
        .iter()
        .map(|(_, rays)| {
            let subset = every_nth(rays, budget);
            let expected = subset.iter().map(|r| linear.intersect(r)).collect();
            (subset, expected)
        })
        .collect();
    let configurations: Vec<(AccelKind, Traversal)> = [AccelKind::Sah, AccelKind::ObjectMedian]
        .into_iter()
        .flat_map(|kind| Traversal::ALL.iter().map(move |&t| (kind, t)))
        .collect();
    let mut steps = Steps::new(configurations.len(), progress);
    let mut table = Table {
        title: format!(
            "{} triangles; {side}² camera rays, {incoherent} incoherent rays (timed), and {hard} hard rays of each \
             kind; answers compared with the linear scan's on evenly spaced subsets of at most {budget} rays",
            triangles.len()
        ),
        header: ["structure", "traversal", "camera ms", "incoherent ms", "Mrays/s (incoherent)", "differing answers"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    let mut curves = Vec::new();
    for (index, &(kind, traversal)) in configurations.iter().enumerate() {
        let name = format!("{kind}, {traversal}");
        steps.next(&name);
        let params = BuildParams { traversal, ..kind.default_params() };
        let accel = kind.try_build(&triangles, &params).map_err(|e| ExperimentError::Build(e.to_string()))?;
        let trace = |chunk: &[Ray]| chunk.iter().filter(|r| accel.intersect(r).is_some()).count();
        let camera = time_rays(&batches[0].1, options.repeats, trace);
        let incoherent_time = time_rays(&batches[1].1, options.repeats, trace);
        let mut point = Point::new(index as f64, name.clone());
        point.time = Some(incoherent_time.clone());
        let (mut wrong, mut total) = (0, 0);
        let mut by_kind = Vec::new();
        for ((batch, _), (subset, expected)) in batches.iter().zip(&checked) {
            let differ = differing(accel.as_ref(), subset, expected);
            point = point
                .with(&format!("{batch}_differing"), differ as f64)
                .with(&format!("{batch}_checked"), subset.len() as f64);
            by_kind.push(format!("{batch} {differ}/{}", subset.len()));
            wrong += differ;
            total += subset.len();
        }
        let rate = mrays(batches[1].1.len(), &incoherent_time);
        point = point
            .with("differing", wrong as f64)
            .with("checked", total as f64)
            .with("incoherent_mrays", rate.0)
            .with("camera_ms", camera.median_ms);
        table.rows.push(vec![
            kind.to_string(),
            traversal.to_string(),
            format_timing(&camera),
            format_timing(&incoherent_time),
            format_number(rate.0),
            format!("{wrong} of {total} ({})", by_kind.join(", ")),
        ]);
        let ns = |ms: f64| ms * 1e6 / batches[1].1.len() as f64;
        curves.push(
            Curve::new(&name, vec![(ns(incoherent_time.median_ms), rate_or_bound(wrong as f64, total as f64))])
                .with_x_bars(vec![Some((ns(incoherent_time.min_ms), ns(incoherent_time.max_ms)))])
                .with_bounds(vec![is_bound(wrong as f64)]),
        );
        report.series.push(Series { name, points: vec![point] });
    }
    for kind in [AccelKind::Sah, AccelKind::ObjectMedian] {
        let find = |t: Traversal| report.series.iter().find(|s| s.name == format!("{kind}, {t}")).map(|s| &s.points[0]);
        if let (Some(robust), Some(fast)) = (find(Traversal::Robust), find(Traversal::Fast)) {
            let time = |p: &'_ Point| p.time.clone().expect("measured");
            report.findings.push(format!(
                "{kind}: {}; the fast slab test gives {} of {} answers that differ from the linear scan's, the robust one {}",
                compare_times("incoherent trace time", "robust", &time(robust), "fast", &time(fast)),
                fast.values["differing"],
                fast.values["checked"],
                robust.values["differing"]
            ));
        }
    }
    let exact = report.series.iter().filter(|s| s.points[0].values["differing"] == 0.0).count();
    report.plots.push(Plot {
        file: "traversal.svg".into(),
        title: format!(
            "Answers differing from the linear scan against time per ray, robust and fast slab tests: none for {exact} of {}",
            report.series.len()
        ),
        x_label: "time per incoherent ray (ns, all threads; bars min–max)".into(),
        y_label: format!("answers differing in any bit (fraction of those checked; {BOUND_NOTE})"),
        log_x: true,
        log_y: true,
        curves,
        legend: Corner::UpperRight,
        y_range: None,
    });
    report.tables.push(table);
    Ok(report)
}

/// The `traversal` knob.
pub(super) static TRAVERSAL_TEST: super::Described = super::Described {
    name: "traversal",
    about: "The robust slab test of traversal against the textbook one.",
    question: "what does the robust slab test cost, and how many answers does the textbook one change?",
    scenes: super::Scenes::Subject(&[super::BUNNY]),
    run,
};
