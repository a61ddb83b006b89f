//! `packets`: the batch queries, which trace coherent rays of the wide BVHs
//! (and Embree, with the `embree` feature) as packets of 16, against one ray
//! at a time: time on the scene's camera rays (coherent) and incoherent
//! rays, and whether any answer changes (it must not, for our structures).

use rtgi_accel::{AccelKind, BuildParams, Hit};
use rtgi_math::Ray;
use rtgi_render::rays::{primary_rays, surface_rays};

use crate::measure::{every_nth, time_rays};
use crate::plot::{BOUND_NOTE, Corner, Curve, Plot, is_bound, rate_or_bound};
use crate::report::{Point, Report, Series, Table, format_number, format_timing};
use crate::verdict::compare_times;
use crate::{ExperimentError, Options, Steps, Subject};

/// Rays the linear scan answers per batch, at most.
const LINEAR_TRIANGLE_TESTS: usize = 100_000_000;

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let triangles = subject.scene.triangle_positions();
    let (side, incoherent) = if options.quick { (64, 4096) } else { (1024, 1_000_000) };
    let batches = [
        ("camera", primary_rays(&subject.camera, side, side)),
        ("incoherent", surface_rays(&subject.scene, incoherent, 1)),
    ];
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
    let kinds: Vec<AccelKind> = [AccelKind::Bvh4, AccelKind::Bvh8, AccelKind::Sbvh8]
        .into_iter()
        .chain(AccelKind::PEERS.iter().copied())
        .collect();
    let mut steps = Steps::new(kinds.len(), progress);
    let mut table = Table {
        title: format!(
            "{} triangles; {side}² camera rays and {incoherent} incoherent rays; answers compared with the linear \
             scan's on {} and {} of them",
            triangles.len(),
            checked[0].0.len(),
            checked[1].0.len()
        ),
        header: ["structure", "rays", "one at a time ms", "batch ms", "batch / single", "differing answers"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    let mut curves = Vec::new();
    for &kind in &kinds {
        steps.next(kind.name());
        let accel =
            kind.try_build(&triangles, &kind.default_params()).map_err(|e| ExperimentError::Build(e.to_string()))?;
        for ((batch, rays), (subset, expected)) in batches.iter().zip(&checked) {
            let single =
                time_rays(rays, options.repeats, |chunk| chunk.iter().filter(|r| accel.intersect(r).is_some()).count());
            let batched = time_rays(rays, options.repeats, |chunk| {
                let mut hits = vec![None; chunk.len()];
                accel.intersect_batch(chunk, &mut hits);
                hits.iter().filter(|h| h.is_some()).count()
            });
            let bits = |h: &Option<Hit>| h.map(|h| (h.triangle, h.t.to_bits(), h.beta.to_bits(), h.gamma.to_bits()));
            let mut answers = vec![None; subset.len()];
            accel.intersect_batch(subset, &mut answers);
            let differ = answers.iter().zip(expected).filter(|(a, e)| bits(a) != bits(e)).count();
            let name = format!("{kind}, {batch} rays");
            let verdict = compare_times("trace time", "the batch", &batched, "one ray at a time", &single);
            report.findings.push(format!(
                "{name}: {verdict}; {differ} of {} batch answers differ from the linear scan's{}",
                subset.len(),
                if kind.is_peer() { " (a peer, outside the exactness contract)" } else { "" }
            ));
            table.rows.push(vec![
                kind.to_string(),
                batch.to_string(),
                format_timing(&single),
                format_timing(&batched),
                format_number(batched.median_ms / single.median_ms.max(1e-9)),
                format!("{differ} of {}", subset.len()),
            ]);
            let ns = |ms: f64| ms * 1e6 / rays.len() as f64;
            let fraction = rate_or_bound(differ as f64, subset.len() as f64);
            for (mode, timing) in [("single", single.clone()), ("batch", batched.clone())] {
                curves.push(
                    Curve::new(format!("{kind}, {batch}, {mode}"), vec![(ns(timing.median_ms), fraction)])
                        .with_x_bars(vec![Some((ns(timing.min_ms), ns(timing.max_ms)))])
                        .with_bounds(vec![is_bound(differ as f64)]),
                );
            }
            let mut single_point = Point::new(0.0, "one at a time").with("differing", 0.0);
            single_point.time = Some(single);
            let mut batch_point =
                Point::new(1.0, "batch").with("differing", differ as f64).with("checked", subset.len() as f64);
            batch_point.time = Some(batched);
            report.series.push(Series { name, points: vec![single_point, batch_point] });
        }
    }
    report.plots.push(Plot {
        file: "packets.svg".into(),
        title: "Batch (packets) against one ray at a time: answers differing from the linear scan against time per ray"
            .into(),
        x_label: "time per ray (ns, all threads; bars min–max)".into(),
        y_label: format!(
            "batch answers differing from the linear scan's in any bit (fraction of the batch; {BOUND_NOTE})"
        ),
        log_x: true,
        log_y: true,
        curves,
        legend: Corner::UpperRight,
        y_range: None,
    });
    report.tables.push(table);
    Ok(report)
}

/// The `packets` knob.
pub(super) static PACKETS: super::Described = super::Described {
    name: "packets",
    about: "Batch queries (packets of 16 coherent rays) against one ray at a time.",
    question: "what do packets of coherent rays gain over one ray at a time, and do they change any answer?",
    scenes: super::Scenes::Subject(&[super::BUNNY]),
    run,
};
