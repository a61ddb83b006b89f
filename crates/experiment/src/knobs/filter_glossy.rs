//! `filter-glossy`: path regularisation (`--filter-glossy`, Cycles' "filter
//! glossy") against the indirect-light clamp (`--clamp`), the two known
//! ways of trading bias for the fireflies of caustics and of sharp
//! highlights seen through a diffuse bounce. Regularisation widens mirrors,
//! glass and narrow lobes after a rough bounce, so light sampling finds the
//! light they bring; the clamp cuts the bright paths off. Both are measured
//! at one sample count against the converged, exact reference, raw and
//! denoised (the PNG default), with the error split into squared bias and
//! variance over the seeds.

use rtgi_render::{FilterGlossy, RenderSettings};

use crate::plot::{Curve, Plot};
use crate::reference::reference;
use crate::report::{Point, Report, Series, Table, format_bias, format_number, measurement_cells, measurement_header};
use crate::runner::{
    Budget, Candidate, MakeImage, add_equal_time_panel, measure_with, ms_per_sample, render, render_denoised,
};
use crate::verdict::compare_efficiency;
use crate::{ExperimentError, Options, Steps, Subject};

/// Regularisation thresholds, from barely touching (only grazing diffuse
/// bounces, whose density is below 0.1) to every diffuse and rough bounce.
const THRESHOLDS: [f32; 4] = [0.1, 0.3, 1.0, 3.0];

/// The clamp compared, as a multiple of the reference's mean radiance: the
/// mildest that the clamp experiment finds with a resolved gain.
const CLAMP_FACTOR: f64 = 4.0;

/// One configuration measured: its label, settings and how its image is made.
struct Configuration {
    label: String,
    settings: RenderSettings,
    make: MakeImage,
}

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    super::require_light_transport(subject, "filter-glossy")?;
    let thresholds: &[f32] = if options.quick { &[0.3, 1.0] } else { &THRESHOLDS };
    let spp = if options.quick { 4 } else { 16 };
    let base = RenderSettings {
        samples_per_pixel: spp,
        indirect_clamp: None,
        filter_glossy: None,
        adaptive: None,
        ..super::at_reference_depth(subject)
    };
    let mut steps = Steps::new(1 + 2 * (thresholds.len() + 3), progress);
    steps.next("reference, exact");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let mean = reference.mean_radiance();
    let clamp = (CLAMP_FACTOR * mean) as f32;

    let mut configurations = Vec::new();
    for (kind, make) in [("", render as MakeImage), (", denoised", render_denoised)] {
        configurations.push(Configuration { label: format!("exact{kind}"), settings: base.clone(), make });
        for &threshold in thresholds {
            configurations.push(Configuration {
                label: format!("filter glossy {threshold}{kind}"),
                settings: RenderSettings { filter_glossy: Some(FilterGlossy::all_lobes(threshold)), ..base.clone() },
                make,
            });
        }
        configurations.push(Configuration {
            label: format!("filter mirrors and glass 1{kind}"),
            settings: RenderSettings {
                filter_glossy: Some(FilterGlossy { threshold: 1.0, deltas_only: true }),
                ..base.clone()
            },
            make,
        });
        configurations.push(Configuration {
            label: format!("clamp {CLAMP_FACTOR}× mean{kind}"),
            settings: RenderSettings { indirect_clamp: Some(clamp), ..base.clone() },
            make,
        });
    }
    let mut table = Table {
        title: format!(
            "{spp} spp per render; the clamp at {CLAMP_FACTOR}× the reference's mean radiance is {}",
            format_number(clamp as f64)
        ),
        header: measurement_header(&["configuration"]),
        rows: Vec::new(),
    };
    let mut points = Vec::new();
    for configuration in &configurations {
        steps.next(&configuration.label);
        let mut point = measure_with(subject, &configuration.settings, options, &reference, configuration.make);
        point.label = configuration.label.clone();
        let mut row = vec![configuration.label.clone()];
        row.extend(measurement_cells(&point));
        table.rows.push(row);
        points.push(point);
    }

    // The raw and the denoised halves: each configuration against the exact one of its half.
    let half = configurations.len() / 2;
    for (name, points) in [("raw", &points[..half]), ("denoised", &points[half..])] {
        let (exact, others) = points.split_first().expect("the exact point");
        // Regularisation and the clamp are biased by design: where their
        // bias is resolved they are judged by it and by their error at equal
        // time (the panel), and only unbiased ones by efficiency.
        let x = exact.error.as_ref().expect("measured");
        if x.bias_resolved() {
            report.findings.push(format!(
                "{name}: the render called exact is {} at these settings, so nothing is compared to it",
                crate::verdict::describe_bias(x)
            ));
        }
        let least_mse = others.iter().min_by(|a, b| {
            a.error.as_ref().expect("measured").mse().total_cmp(&b.error.as_ref().expect("measured").mse())
        });
        if let Some(best) = least_mse {
            let e = best.error.as_ref().expect("measured");
            report.findings.push(format!(
                "{name}, at {spp} spp: the least MSE is {}'s, bias² {} and variance {} against {} {} and {}; {}",
                best.label,
                format_bias(e),
                format_number(e.variance),
                exact.label,
                format_bias(x),
                format_number(x.variance),
                compare_efficiency(&best.label, best, &exact.label, exact)
            ));
        }
        for point in others {
            let e = point.error.as_ref().expect("measured");
            report.findings.push(format!(
                "{}: mean radiance {:.2}% of the reference's (the exact render's: {:.2}%)",
                point.label,
                100.0 * e.mean / e.reference_mean.max(1e-30),
                100.0 * x.mean / x.reference_mean.max(1e-30)
            ));
        }
        let series = Series { name: name.to_owned(), points: points.to_vec() };
        report.series.push(series);
    }

    // Bias and variance against the threshold, raw renders.
    let (mut bias_curve, mut variance_curve) = (Vec::new(), Vec::new());
    for (threshold, point) in thresholds.iter().zip(&points[1..]) {
        let e = point.error.as_ref().expect("measured");
        if e.bias_resolved() {
            bias_curve.push((*threshold as f64, e.bias2));
        }
        variance_curve.push((*threshold as f64, e.variance));
    }
    let exact = points[0].error.as_ref().expect("measured");
    report.plots.push(Plot {
        file: "filter-glossy-bias-variance.svg".into(),
        title: format!("Squared bias and variance against the filter-glossy threshold, {spp} spp, raw"),
        x_label: "filter-glossy threshold (bounce density)".into(),
        y_label: "squared bias and variance per pixel and channel (radiance²)".into(),
        log_x: true,
        log_y: true,
        curves: vec![
            Curve::new("bias² (where resolved)", bias_curve),
            Curve::new("variance", variance_curve),
            Curve::guide(
                "the exact render's variance",
                thresholds.iter().map(|&t| (t as f64, exact.variance)).collect(),
            ),
        ],
        legend: crate::plot::Corner::LowerLeft,
        y_range: None,
    });
    let curves = points
        .iter()
        .map(|p| {
            let (time, error) = (p.time.as_ref().expect("measured"), p.error.as_ref().expect("measured"));
            Curve::error_against_time(&p.label, &[(time.clone(), error.rmse, error.rmse_min, error.rmse_max)])
        })
        .collect();
    report.plots.push(Plot::error_against_time(
        "filter-glossy-tradeoff.svg",
        format!("RMSE against render time, {spp} spp: regularisation and the clamp, raw and denoised"),
        curves,
    ));

    // Equal time (raw renders): exact, the clamp, and the thresholds 0.3 and 1, in the time of the exact
    // render at half as many samples again (`budget_spp`).
    steps.next("equal-time panel");
    let exact = &configurations[0];
    let budget = Budget::from_sweep(exact.settings.clone(), exact.make, &points[0]);
    let chosen: Vec<&Point> = points[..half]
        .iter()
        .filter(|p| {
            p.label == "exact" || p.label.starts_with("clamp") || p.label.ends_with(" 1") || p.label.ends_with(" 0.3")
        })
        .collect();
    let candidates: Vec<Candidate> = chosen
        .iter()
        .map(|p| {
            let settings = configurations.iter().find(|c| c.label == p.label).expect("configured").settings.clone();
            Candidate::render(p.label.clone(), settings, ms_per_sample(p, spp))
        })
        .collect();
    add_equal_time_panel(
        &mut report,
        subject,
        &reference,
        "filter-glossy-equal-time.png".to_owned(),
        "Regularisation and the clamp",
        &budget,
        &candidates,
    );
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}

/// The `filter-glossy` knob.
pub(super) static FILTER_GLOSSY_KNOB: super::Described = super::Described {
    name: "filter-glossy",
    about: "Path regularisation (Cycles' \"filter glossy\") against the clamp.",
    question: "does widening mirrors, glass and sharp highlights after a diffuse bounce (path regularisation) \
            remove the fireflies of caustics at less bias than the clamp, raw and denoised?",
    scenes: super::Scenes::Subject(&[super::CAUSTICS, super::MIRROR, super::CONFERENCE]),
    run,
};
