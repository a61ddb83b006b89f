//! `adaptive`: adaptive sampling (`rtgi render --noise`) against the same
//! samples everywhere. Fixed counts are measured with the default
//! stratified sampler and with Sobol (the sampler adaptive rounds take
//! their samples from, so that the two differ only in where samples go);
//! noise targets from loose to tight. All are drawn as error against time,
//! compared in efficiency, and shown at equal time, where the adaptive
//! render is bounded by the budget itself (`--noise` with `--time`).

use rtgi_render::{AdaptiveSampling, PixelSampler, RenderSettings};

use crate::plot::{Curve, Plot};
use crate::reference::reference;
use crate::report::{Point, Report, Series, Table, measurement_cells, measurement_header};
use crate::runner::{Budget, Candidate, add_equal_time_panel, measure, ms_per_sample, time_and_error};
use crate::verdict::{ErrorMeasure, compare_efficiency_by, most_efficient_by};
use crate::{ExperimentError, Options, Steps, Subject};

/// The most samples a pixel takes under a noise target.
const MOST: u32 = 1024;

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    super::require_light_transport(subject, "adaptive")?;
    let (counts, targets, most): (&[u32], &[f32], u32) =
        if options.quick { (&[4, 16], &[0.3], 64) } else { (&[16, 64, 256], &[0.2, 0.1, 0.05, 0.03], MOST) };
    let samplers = [PixelSampler::Stratified, PixelSampler::Sobol];
    let base = RenderSettings { adaptive: None, ..super::at_reference_depth(subject) };
    let mut steps = Steps::new(2 + samplers.len() * counts.len() + targets.len(), progress);
    steps.next("reference");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let mut table = Table {
        title: format!(
            "fixed samples per pixel, and noise targets with at most {most} samples a pixel (Sobol sampler)"
        ),
        header: measurement_header(&["sampling", "spp"]),
        rows: Vec::new(),
    };
    let mut curves = Vec::new();
    for sampler in samplers {
        let mut series = Series { name: format!("{sampler}, every pixel alike"), points: Vec::new() };
        for &spp in counts {
            steps.next(&format!("{sampler} at {spp} spp"));
            let settings = RenderSettings { sampler, samples_per_pixel: spp, ..base.clone() };
            let point = measure(subject, &settings, options, &reference);
            let mut row = vec![format!("{sampler}"), spp.to_string()];
            row.extend(measurement_cells(&point));
            table.rows.push(row);
            series.points.push(point);
        }
        curves.push(Curve::error_against_time(format!("{sampler}, fixed spp"), &time_and_error(&series)));
        report.series.push(series);
    }
    let adaptive = |noise: f32| RenderSettings {
        sampler: PixelSampler::Sobol,
        samples_per_pixel: most,
        adaptive: Some(AdaptiveSampling { noise: Some(noise), seconds: None }),
        ..base.clone()
    };
    let mut series = Series { name: "noise target".to_owned(), points: Vec::new() };
    for &noise in targets {
        steps.next(&format!("noise target {noise}"));
        let mut point = measure(subject, &adaptive(noise), options, &reference);
        point.x = noise as f64;
        point.label = format!("noise {noise}");
        let mut row = vec![format!("noise {noise}"), format!("≤ {most}")];
        row.extend(measurement_cells(&point));
        table.rows.push(row);
        series.points.push(point.with("noise_target", noise as f64));
    }
    curves.push(Curve::error_against_time("noise target", &time_and_error(&series)));
    report.series.push(series);

    // A noise target stops each pixel on its own noise estimate, which
    // correlates with its value: the stopping rule can bias the image.
    for point in &report.series.last().expect("the noise targets").points {
        let error = point.error.as_ref().expect("measured");
        if error.bias_resolved() {
            report.findings.push(format!(
                "{}: the stopping rule is {}",
                point.label,
                crate::verdict::describe_bias(error)
            ));
        }
    }
    // The most efficient of each kind, compared by relative MSE (what a
    // noise target aims at) and by MSE; first against fixed counts on the
    // same sampler (Sobol, which adaptive rounds need), then against the
    // default stratified sampler, which differs in the sampler too.
    let series_of = |name: &str| report.series.iter().find(|s| s.name == name).map(|s| &s.points[..]).unwrap_or(&[]);
    let adaptive_points = series_of("noise target");
    let mut findings = Vec::new();
    for measure in [ErrorMeasure::RelativeMse, ErrorMeasure::Mse] {
        let Some((_, adaptive_best)) = most_efficient_by(adaptive_points, measure) else {
            findings.push(format!("{}: every noise target is biased", measure.name()));
            continue;
        };
        for (what, sampler) in
            [("the same sampler", PixelSampler::Sobol), ("the default sampler", PixelSampler::Stratified)]
        {
            let fixed = series_of(&format!("{sampler}, every pixel alike"));
            if let Some((_, fixed_best)) = most_efficient_by(fixed, measure) {
                findings.push(format!(
                    "against fixed counts on {what}: {}",
                    compare_efficiency_by(
                        measure,
                        &format!("the best noise target ({})", adaptive_best.label),
                        adaptive_best,
                        &format!("the best fixed count, {sampler} ({} spp)", fixed_best.label),
                        fixed_best,
                    )
                ));
            }
        }
    }
    report.findings.extend(findings);
    report.plots.push(Plot::error_against_time(
        "adaptive-tradeoff.svg",
        "RMSE against render time: fixed samples per pixel and noise targets".to_owned(),
        curves,
    ));

    // Equal time: the stratified sampler's middle count sets the budget;
    // the adaptive render is bounded by it (the rounds stop when the next
    // would overrun, so it takes at most the budget).
    let middle = counts[counts.len() / 2];
    let at = |name: &str| -> Option<&Point> {
        report.series.iter().find(|s| s.name == name)?.points.iter().find(|p| p.x == middle as f64)
    };
    let stratified_name = format!("{}, every pixel alike", PixelSampler::Stratified);
    let sobol_name = format!("{}, every pixel alike", PixelSampler::Sobol);
    if let (Some(stratified), Some(sobol)) = (at(&stratified_name), at(&sobol_name)) {
        let budget = Budget {
            settings: RenderSettings { sampler: PixelSampler::Stratified, samples_per_pixel: middle, ..base.clone() },
            make: crate::runner::render,
            estimate_ms: stratified.time.as_ref().expect("measured").median_ms,
        };
        let tightest = *targets.last().expect("targets");
        let candidates = vec![
            Candidate::render(
                "stratified",
                RenderSettings { sampler: PixelSampler::Stratified, ..base.clone() },
                ms_per_sample(stratified, middle),
            ),
            Candidate::render(
                "sobol",
                RenderSettings { sampler: PixelSampler::Sobol, ..base.clone() },
                ms_per_sample(sobol, middle),
            ),
            Candidate::render(format!("noise {tightest}"), adaptive(tightest), ms_per_sample(sobol, middle)),
        ];
        steps.next("equal-time panel");
        let file = "adaptive-equal-time.png".to_owned();
        add_equal_time_panel(
            &mut report,
            subject,
            &reference,
            file,
            "Fixed and adaptive sampling",
            &budget,
            &candidates,
        );
    }
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}

/// The `adaptive` knob.
pub(super) static ADAPTIVE: super::Described = super::Described {
    name: "adaptive",
    about: "Adaptive sampling (noise targets) against fixed samples per pixel.",
    question: "does sampling until each pixel meets a noise target beat the same samples everywhere, at equal time?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::ROOM]),
    run,
};
