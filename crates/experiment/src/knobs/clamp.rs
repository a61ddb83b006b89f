//! `clamp`: the indirect-light clamp (`--clamp`), which trades bias for
//! variance: light a path brings in after the first bounce is limited to a
//! maximum, so the rare bright paths that make fireflies are cut, and the
//! energy they carried is missing. Measured at one sample count against the
//! converged, unclamped reference, with the error split into squared bias
//! and variance over the seeds.

use rtgi_render::RenderSettings;

use crate::plot::{Corner, Curve, Plot};
use crate::reference::reference;
use crate::report::{Point, Report, Series, Table, format_number, measurement_cells, measurement_header};
use crate::runner::{Budget, Candidate, add_equal_time_panel, measure};
use crate::verdict::compare_efficiency;
use crate::{ExperimentError, Options, Steps, Subject};

/// Clamps, as multiples of the reference's mean radiance (its brightest
/// channel's), from harsh to barely touching.
const LIMITS: [f64; 8] = [0.25, 0.5, 1.0, 2.0, 4.0, 16.0, 64.0, 256.0];

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    super::require_light_transport(subject, "clamp")?;
    let limits: &[f64] = if options.quick { &[0.25, 1.0, 4.0] } else { &LIMITS };
    let spp = if options.quick { 4 } else { 16 };
    let base = RenderSettings { samples_per_pixel: spp, indirect_clamp: None, ..super::at_reference_depth(subject) };
    let mut steps = Steps::new(2 + limits.len(), progress);
    steps.next("reference, unclamped");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let mean = reference.mean_radiance();
    let mut table = Table {
        title: format!(
            "{spp} spp per render, clamps as multiples of the reference's mean radiance {}",
            format_number(mean)
        ),
        header: measurement_header(&["clamp", "limit"]),
        rows: Vec::new(),
    };
    steps.next("unclamped");
    let unclamped = measure(subject, &base, options, &reference);
    let mut points: Vec<(String, f64, Point)> = vec![("none".to_owned(), f64::INFINITY, unclamped)];
    for &factor in limits {
        let limit = (factor * mean) as f32;
        steps.next(&format!("clamp at {factor}× the mean ({limit})"));
        let settings = RenderSettings { indirect_clamp: Some(limit), ..base.clone() };
        points.push((format!("{factor}× mean"), limit as f64, measure(subject, &settings, options, &reference)));
    }
    let mut series = Series { name: "indirect clamp".to_owned(), points: Vec::new() };
    let (mut bias_curve, mut variance_curve, mut resolution_curve, mut tradeoff) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (label, limit, point) in &points {
        let mut row = vec![label.clone(), if limit.is_finite() { format_number(*limit) } else { "–".to_owned() }];
        row.extend(measurement_cells(point));
        table.rows.push(row);
        let (time, error) = (point.time.as_ref().expect("measured"), point.error.as_ref().expect("measured"));
        if limit.is_finite() {
            // A bias below what the seeds resolve is noise (it may be
            // negative): only resolved ones are drawn, above the resolution's line.
            if error.bias_resolved() {
                bias_curve.push((*limit, error.bias2));
            }
            // One seed resolves no bias at all (its resolution is the largest double).
            if error.seeds > 1 {
                resolution_curve.push((*limit, error.bias_resolution));
            }
            variance_curve.push((*limit, error.variance));
        }
        tradeoff.push((label.clone(), time, error));
        let mut point = point.clone();
        point.x = if limit.is_finite() { *limit } else { 0.0 };
        point.label = label.clone();
        series.points.push(point.with("limit", if limit.is_finite() { *limit } else { -1.0 }));
    }
    // The clamp with the least MSE against no clamp, in efficiency.
    let (none, clamped) = series.points.split_first().expect("the unclamped point");
    let series_best = 1
        + (0..clamped.len())
            .min_by(|&a, &b| {
                clamped[a]
                    .error
                    .as_ref()
                    .expect("measured")
                    .mse()
                    .total_cmp(&clamped[b].error.as_ref().expect("measured").mse())
            })
            .unwrap_or(0);
    let none_error = none.error.as_ref().expect("measured");
    // A clamp no sample reaches renders the very images of no clamp: the
    // same error for every seed. It is reported as identical, not as a finding.
    let identical = |p: &Point| {
        let e = p.error.as_ref().expect("measured");
        e.seed_mse == none_error.seed_mse && e.seed_means == none_error.seed_means
    };
    let untouched: Vec<&str> = clamped.iter().filter(|p| identical(p)).map(|p| p.label.as_str()).collect();
    if !untouched.is_empty() {
        report.findings.push(format!(
            "the clamp at {} changes no sample at {spp} spp: every seed's render is identical to no clamp's",
            untouched.join(", ")
        ));
    }
    if let Some(best) = clamped.get(series_best - 1).filter(|p| !identical(p)) {
        let e = best.error.as_ref().expect("measured");
        report.findings.push(format!(
            "at {spp} spp the clamp at {} has the least MSE: bias² {}, variance {} against the unclamped {} and {}; {}",
            best.label,
            crate::report::format_bias(e),
            format_number(e.variance),
            crate::report::format_bias(none_error),
            format_number(none_error.variance),
            compare_efficiency(&format!("the clamp at {}", best.label), best, "no clamp", none)
        ));
    }
    // The unclamped render is the baseline: a bias it shares (the reference's
    // own, or one of the settings) is not the clamp's.
    if none_error.bias_resolved() {
        report.findings.push(format!(
            "without a clamp the renders are already {} against the reference: a bias of the settings, not of the clamp",
            crate::verdict::describe_bias(none_error)
        ));
    } else if let Some(first) =
        clamped.iter().rev().find(|p| !identical(p) && p.error.as_ref().expect("measured").bias_resolved())
    {
        let e = first.error.as_ref().expect("measured");
        report.findings.push(format!(
            "the clamp's bias is resolved from {} down: there it is {}",
            first.label,
            crate::verdict::describe_bias(e)
        ));
    }
    report.series.push(series);
    report.plots.push(Plot {
        file: "clamp-bias-variance.svg".into(),
        title: format!("Squared bias and variance against the clamp, {spp} spp"),
        x_label: "clamp threshold (radiance, of the brightest channel)".into(),
        y_label: "squared bias and variance per pixel and channel (radiance²)".into(),
        log_x: true,
        log_y: true,
        curves: vec![
            Curve::new("bias² (where resolved)", bias_curve),
            Curve::new("variance", variance_curve),
            Curve::guide("smallest bias² the seeds resolve", resolution_curve),
        ],
        legend: Corner::LowerLeft,
        y_range: None,
    });
    let title = format!("RMSE against render time for each clamp, {spp} spp");
    let curves = tradeoff
        .iter()
        .map(|(label, time, error)| {
            Curve::error_against_time(label, &[((*time).clone(), error.rmse, error.rmse_min, error.rmse_max)])
        })
        .collect();
    report.plots.push(Plot::error_against_time("clamp-tradeoff.svg", title, curves));
    // The equal-time panel: no clamp, the harshest, the best and a mild one, in the time of the unclamped
    // render at half as many samples again (`budget_spp`).
    let budget = Budget::from_sweep(base.clone(), crate::runner::render, &points[0].2);
    let best = series_best;
    let mut chosen: Vec<usize> = vec![0, 1, best, points.len() - 1];
    chosen.dedup();
    chosen.sort_unstable();
    chosen.dedup();
    let candidates: Vec<Candidate> = chosen
        .iter()
        .map(|&i| {
            let (label, limit, point) = &points[i];
            let clamp = limit.is_finite().then_some(*limit as f32);
            let settings = RenderSettings { indirect_clamp: clamp, ..base.clone() };
            Candidate::render(format!("clamp {label}"), settings, crate::runner::ms_per_sample(point, spp))
        })
        .collect();
    let file = "clamp-equal-time.png".to_owned();
    add_equal_time_panel(&mut report, subject, &reference, file, "Clamps", &budget, &candidates);
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}

/// The `clamp` knob.
pub(super) static CLAMP: super::Described = super::Described {
    name: "clamp",
    about: "The indirect-light clamp: bias traded for variance.",
    question: "how much bias does clamping indirect light add for the variance it removes?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::ROOM, super::CONFERENCE]),
    run,
};
