//! `precision`: the watertight triangle test in single precision against
//! the same test in double precision (`watertight-f64`), with
//! Möller-Trumbore for context: the time of one triangle test, and how far
//! `t`, `beta` and `gamma` are from the exact answer ([`crate::exact`]) on
//! triangles where single precision struggles:
//! - **far**: triangles 16 units across at 2^0 … 2^24 from the origin,
//!   seen from near the origin (a camera looking at a distant object);
//! - **needle** and **sliver**: triangles of longest edge 1 near the origin
//!   whose elongation (longest edge over height) grows from 2^0 to 2^20,
//!   the third corner near an end of the longest edge or over its middle.
//!
//! Each ray is aimed at a random interior point of its triangle (every
//! barycentric at least 0.1); the reference is the exact intersection of
//! the ray and triangle as given in `f32`, so the errors are the test's
//! arithmetic alone, and a ray whose exact answer lies inside the triangle
//! but that the test reports as a miss is counted as a miss.

use rtgi_accel::{Accel, Intersector, LinearScan};
use rtgi_math::{Frame, Ray, Rng, Vec3, uniform_sphere};

use crate::exact::ExactHit;
use crate::plot::{Corner, Curve, Plot};
use crate::report::{Point, Report, Series, Table, format_number};
use crate::stats::Timing;
use crate::{ExperimentError, Options, Steps};

/// A family of triangles with one parameter that makes them harder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Family {
    Far,
    Needle,
    Sliver,
}

impl Family {
    const ALL: [Family; 3] = [Family::Far, Family::Needle, Family::Sliver];

    fn name(self) -> &'static str {
        match self {
            Family::Far => "far",
            Family::Needle => "needle",
            Family::Sliver => "sliver",
        }
    }

    /// The parameter's values: distances from the origin, or elongations.
    fn parameters(self, quick: bool) -> Vec<f32> {
        let exponents: Vec<i32> = match (self, quick) {
            (Family::Far, false) => (0..=24).collect(),
            (Family::Far, true) => vec![0, 12, 24],
            (_, false) => (0..=20).step_by(2).collect(),
            (_, true) => vec![0, 8, 16],
        };
        exponents.into_iter().map(|e| 2f32.powi(e)).collect()
    }

    fn parameter_name(self) -> &'static str {
        match self {
            Family::Far => "distance from the origin (world units)",
            Family::Needle | Family::Sliver => "elongation (ratio: longest edge / height)",
        }
    }

    /// A triangle of the family at `parameter` and a ray aimed at a random
    /// interior point of it, everything rounded to `f32` as a scene holds it.
    fn case(self, parameter: f32, rng: &mut Rng) -> ([Vec3; 3], Ray) {
        let random_frame = |rng: &mut Rng| Frame::from_z(uniform_sphere(rng.next_f32(), rng.next_f32()));
        let (triangle, origin_near) = match self {
            Family::Far => {
                // Within 16 units of a point 2^k away, along a direction
                // off every axis; seen from the unit cube around the origin.
                let centre = Vec3::new(1.0, 0.75, -0.5).normalize() * parameter;
                let frame = random_frame(rng);
                let corner = |rng: &mut Rng| {
                    centre + 8.0 * (frame.x * (2.0 * rng.next_f32() - 1.0) + frame.y * (2.0 * rng.next_f32() - 1.0))
                };
                let triangle = [corner(rng), corner(rng), corner(rng)];
                let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
                (triangle, Some(origin))
            }
            Family::Needle | Family::Sliver => {
                let height = 1.0 / parameter;
                let apex = if self == Family::Needle { 0.02 } else { 0.5 };
                let centre = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * 2.0;
                let frame = random_frame(rng);
                let at = |x: f32, y: f32| centre + frame.x * (x - 0.5) + frame.y * y;
                ([at(0.0, 0.0), at(1.0, 0.0), at(apex, height)], None)
            }
        };
        let (u, v) = loop {
            let (u, v) = (rng.next_f32(), rng.next_f32());
            if u.min(v).min(1.0 - u - v) >= 0.1 {
                break (u, v);
            }
        };
        let [a, b, c] = triangle;
        let target = a + u * (b - a) + v * (c - a);
        let origin = origin_near.unwrap_or_else(|| {
            // Two units away, clearly off the triangle's plane (|cos| ≥ 0.2).
            let normal = (b - a).cross(c - a).normalize_or_zero();
            loop {
                let direction = uniform_sphere(rng.next_f32(), rng.next_f32());
                if direction.dot(normal).abs() >= 0.2 {
                    break target + 2.0 * direction;
                }
            }
        });
        (triangle, Ray::new(origin, target - origin))
    }
}

/// What one intersector did on one batch of cases.
struct Errors {
    /// Per case where the test and the exact answer both hit.
    t_relative: Vec<f64>,
    barycentric_absolute: Vec<f64>,
    /// Exactly inside, reported as a miss.
    misses: usize,
}

/// Median and max of `values` (0 for none).
fn median_max(values: &mut [f64]) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 0.0);
    }
    values.sort_by(f64::total_cmp);
    (values[values.len() / 2], values[values.len() - 1])
}

fn measure_errors(intersector: Intersector, cases: &[([Vec3; 3], Ray)], exact: &[Option<ExactHit>]) -> Errors {
    let mut errors = Errors { t_relative: Vec::new(), barycentric_absolute: Vec::new(), misses: 0 };
    for ((triangle, ray), reference) in cases.iter().zip(exact) {
        let Some(reference) = reference.as_ref().filter(|r| r.inside()) else { continue };
        match intersector.intersect(ray.origin, ray.direction, ray.t_min, ray.t_max, triangle) {
            None => errors.misses += 1,
            Some(hit) => {
                errors.t_relative.push(reference.t_relative_error(hit.t));
                errors.barycentric_absolute.push(reference.beta_error(hit.beta).max(reference.gamma_error(hit.gamma)));
            }
        }
    }
    errors
}

/// Times one triangle test: every ray against every triangle of the batch
/// through the linear scan (the ray prepared once, then the structures'
/// hit rule per triangle), on this thread; ns per test, median, min and max.
fn time_tests(intersector: Intersector, cases: &[([Vec3; 3], Ray)], repeats: usize) -> Timing {
    let triangles: Vec<[Vec3; 3]> = cases.iter().map(|c| c.0).collect();
    let scan = LinearScan::new(&triangles, intersector);
    crate::measure::time(repeats, 1, || {
        let hits = cases.iter().filter(|(_, ray)| scan.intersect(ray).is_some()).count();
        std::hint::black_box(hits);
    })
}

/// Cases per point: each ray is tested against all of them when timed.
fn cases_per_point(quick: bool) -> usize {
    if quick { 96 } else { 1024 }
}

pub(super) fn run(options: &Options, mut report: Report, progress: &dyn Fn(&str)) -> Result<Report, ExperimentError> {
    let repeats = options.repeats.max(1);
    let count = cases_per_point(options.quick);
    let points: Vec<(Family, f32)> =
        Family::ALL.iter().flat_map(|&f| f.parameters(options.quick).into_iter().map(move |p| (f, p))).collect();
    let mut steps = Steps::new(points.len(), progress);
    let mut all_series: Vec<Series> = Family::ALL
        .iter()
        .flat_map(|f| {
            Intersector::ALL.iter().map(move |i| Series { name: format!("{i} {}", f.name()), points: Vec::new() })
        })
        .collect();
    let mut table = Table {
        title: format!(
            "{count} cases per row, rays aimed inside: relative error of t and largest absolute error of beta and \
             gamma (median, max) against the exact answer; misses: exactly inside, reported as no hit; ns per \
             triangle test (median, min–max) for every ray against every triangle of the row through the linear scan"
        ),
        header: [
            "family",
            "parameter",
            "intersector",
            "t rel. error (median, max)",
            "barycentric error (median, max)",
            "misses",
            "ns per test",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    for (index, &(family, parameter)) in points.iter().enumerate() {
        steps.next(&format!("{} at {}", family.name(), parameter));
        let mut rng = Rng::new(17 + index as u64, 0x9ec1);
        let cases: Vec<([Vec3; 3], Ray)> = (0..count).map(|_| family.case(parameter, &mut rng)).collect();
        let exact: Vec<Option<ExactHit>> =
            cases.iter().map(|(triangle, ray)| ExactHit::new(ray.origin, ray.direction, triangle)).collect();
        let inside = exact.iter().filter(|e| e.as_ref().is_some_and(ExactHit::inside)).count();
        for &intersector in Intersector::ALL {
            let mut errors = measure_errors(intersector, &cases, &exact);
            let timing = time_tests(intersector, &cases, repeats);
            let per_test = |ms: f64| ms * 1e6 / (count * count) as f64;
            let (t_median, t_max) = median_max(&mut errors.t_relative);
            let (b_median, b_max) = median_max(&mut errors.barycentric_absolute);
            let mut point =
                Point::new(parameter as f64, format!("{} {}", family.name(), format_number(parameter as f64)))
                    .with("t_relative_error_median", t_median)
                    .with("t_relative_error_max", t_max)
                    .with("barycentric_error_median", b_median)
                    .with("barycentric_error_max", b_max)
                    .with("misses", errors.misses as f64)
                    .with("exactly_inside", inside as f64)
                    .with("ns_per_test", per_test(timing.median_ms))
                    .with("ns_per_test_min", per_test(timing.min_ms))
                    .with("ns_per_test_max", per_test(timing.max_ms));
            point.time = Some(timing.clone());
            table.rows.push(vec![
                family.name().to_owned(),
                format_number(parameter as f64),
                intersector.name().to_owned(),
                format!("{}, {}", format_number(t_median), format_number(t_max)),
                format!("{}, {}", format_number(b_median), format_number(b_max)),
                format!("{} of {inside}", errors.misses),
                format!(
                    "{} ({}–{})",
                    format_number(per_test(timing.median_ms)),
                    format_number(per_test(timing.min_ms)),
                    format_number(per_test(timing.max_ms))
                ),
            ]);
            let name = format!("{intersector} {}", family.name());
            all_series
                .iter_mut()
                .find(|s| s.name == name)
                .expect("a series per family and intersector")
                .points
                .push(point);
        }
    }
    report.series = all_series;
    findings(&mut report);
    plots(&mut report);
    report.tables.push(table);
    Ok(report)
}

fn series(report: &Report, intersector: Intersector, family: Family) -> &[Point] {
    let name = format!("{intersector} {}", family.name());
    report.series.iter().find(|s| s.name == name).map_or(&[], |s| s.points.as_slice())
}

fn findings(report: &mut Report) {
    let mut findings = Vec::new();
    for family in Family::ALL {
        for &intersector in Intersector::ALL {
            let points = series(report, intersector, family);
            let (Some(first), Some(last)) = (points.first(), points.last()) else { continue };
            let worst = |value: &str| points.iter().map(|p| p.values[value]).fold(0.0, f64::max);
            let misses: f64 = points.iter().map(|p| p.values["misses"]).sum();
            let inside: f64 = points.iter().map(|p| p.values["exactly_inside"]).sum();
            let mut ns: Vec<f64> = points.iter().map(|p| p.values["ns_per_test"]).collect();
            findings.push(format!(
                "{} triangles, {intersector}: largest relative error of t {} at {} and {} at {}, largest \
                 barycentric error {} over the family; {misses} of {inside} rays aimed inside missed; {} ns per \
                 test (median over the family)",
                family.name(),
                format_number(first.values["t_relative_error_max"]),
                first.label,
                format_number(last.values["t_relative_error_max"]),
                last.label,
                format_number(worst("barycentric_error_max")),
                format_number(median_max(&mut ns).0),
            ));
        }
    }
    report.findings.extend(findings);
}

/// A curve of `value` over a family, one point per parameter, the median
/// with a bar to the max where `max` is given. Points of zero error are
/// left out: a log axis has no place for them (the table has them).
fn curve(label: String, points: &[Point], value: &str, max: Option<&str>) -> Curve {
    let kept: Vec<&Point> = points.iter().filter(|p| p.values[value] > 0.0).collect();
    let bars = kept.iter().map(|p| max.map(|m| (p.values[value], p.values[m]))).collect();
    Curve::new(label, kept.iter().map(|p| (p.x, p.values[value])).collect()).with_bars(bars)
}

fn plots(report: &mut Report) {
    let mut plots = Vec::new();
    for (family, file) in [(Family::Far, "far"), (Family::Sliver, "sliver"), (Family::Needle, "needle")] {
        for (value, max, what, y_label) in [
            (
                "t_relative_error_median",
                "t_relative_error_max",
                "t",
                "relative error of t (fraction of t; median, bar to max)",
            ),
            (
                "barycentric_error_median",
                "barycentric_error_max",
                "barycentrics",
                "absolute error of beta, gamma (barycentric units; median, bar to max)",
            ),
        ] {
            plots.push(Plot {
                file: format!("precision-{file}-{what}.svg"),
                title: format!("Error of {what} on {} triangles against the exact answer", family.name()),
                x_label: family.parameter_name().into(),
                y_label: y_label.into(),
                log_x: true,
                log_y: true,
                curves: Intersector::ALL
                    .iter()
                    .map(|&i| curve(i.name().to_owned(), series(report, i, family), value, Some(max)))
                    .collect(),
                legend: Corner::UpperLeft,
                y_range: None,
            });
        }
    }
    plots.push(Plot {
        file: "precision-time.svg".into(),
        title: "Time of one triangle test on the far triangles".into(),
        x_label: Family::Far.parameter_name().into(),
        y_label: "time per triangle test (ns; median, min and max)".into(),
        log_x: true,
        log_y: false,
        curves: Intersector::ALL
            .iter()
            .map(|&i| {
                let points = series(report, i, Family::Far);
                Curve::new(i.name(), points.iter().map(|p| (p.x, p.values["ns_per_test"])).collect()).with_bars(
                    points.iter().map(|p| Some((p.values["ns_per_test_min"], p.values["ns_per_test_max"]))).collect(),
                )
            })
            .collect(),
        legend: Corner::UpperRight,
        y_range: None,
    });
    // The trade-off on one plot: each test's largest error of t on each
    // family against its time per test (the median over the family, with
    // the family's fastest and slowest), log-log.
    plots.push(Plot {
        file: "precision-error-time.svg".into(),
        title: "Largest relative error of t against time per triangle test, per family of hard triangles".into(),
        x_label: "time per triangle test (ns, median over the family; bars min–max)".into(),
        y_label: "largest relative error of t (fraction of t)".into(),
        log_x: true,
        log_y: true,
        curves: Intersector::ALL
            .iter()
            .flat_map(|&i| Family::ALL.iter().map(move |&family| (i, family)))
            .filter_map(|(i, family)| {
                let points = series(report, i, family);
                let mut ns: Vec<f64> = points.iter().map(|p| p.values["ns_per_test"]).collect();
                let (fastest, slowest) =
                    (ns.iter().copied().fold(f64::INFINITY, f64::min), ns.iter().copied().fold(0.0, f64::max));
                let error = points.iter().map(|p| p.values["t_relative_error_max"]).fold(0.0, f64::max);
                (error > 0.0 && !ns.is_empty()).then(|| {
                    Curve::new(format!("{}, {}", i.name(), family.name()), vec![(median_max(&mut ns).0, error)])
                        .with_x_bars(vec![Some((fastest, slowest))])
                })
            })
            .collect(),
        legend: Corner::UpperRight,
        y_range: None,
    });
    report.plots.extend(plots);
}

/// The `precision` knob.
pub(super) static PRECISION: super::Described = super::Described {
    name: "precision",
    about: "The triangle test in single against double precision: time, and error against the exact answer on near-degenerate and far triangles.",
    question: "how far are t and the barycentrics from the exact answer in single and double precision, on \
            near-degenerate and far-from-origin triangles, and what does double precision cost?",
    scenes: super::Scenes::Own("generated triangles"),
    // It measures on scenes of its own, not the subject's.
    run: |_subject, options, report, progress| run(options, report, progress),
};
