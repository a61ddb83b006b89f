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
use crate::runner::{add_equal_time_panel, measure, ms_per_sample, time_and_error};
use crate::verdict::{Spread, compare};
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
    let base = RenderSettings { adaptive: None, ..subject.settings.clone() };
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

    // The most efficient of each kind, compared: does adaptive sampling win?
    let best = |name: &str| {
        report
            .series
            .iter()
            .find(|s| s.name == name)
            .and_then(|s| Spread::most_efficient(&s.points))
            .map(|(spread, p)| (spread, p.label.clone()))
    };
    let fixed = best(&format!("{}, every pixel alike", PixelSampler::Stratified));
    let sobol = best(&format!("{}, every pixel alike", PixelSampler::Sobol));
    if let Some((adaptive_best, label)) = best("noise target") {
        for (what, other) in [("stratified", fixed), ("sobol", sobol)] {
            if let Some((other_best, other_label)) = other {
                report.findings.push(compare(
                    "efficiency 1/(MSE·time)",
                    &format!("the most efficient noise target ({label})"),
                    &adaptive_best,
                    &format!("the most efficient fixed count, {what} ({other_label} spp)"),
                    &other_best,
                ));
            }
        }
    }
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
        let budget = stratified.time.expect("measured").median_ms;
        let tightest = *targets.last().expect("targets");
        let configurations = vec![
            (
                "stratified".to_owned(),
                RenderSettings { sampler: PixelSampler::Stratified, ..base.clone() },
                ms_per_sample(stratified, middle),
            ),
            (
                "sobol".to_owned(),
                RenderSettings { sampler: PixelSampler::Sobol, ..base.clone() },
                ms_per_sample(sobol, middle),
            ),
            (format!("noise {tightest}"), adaptive(tightest), ms_per_sample(sobol, middle)),
        ];
        steps.next("equal-time panel");
        let file = "adaptive-equal-time.png".to_owned();
        add_equal_time_panel(
            &mut report,
            subject,
            &reference,
            file,
            "Fixed and adaptive sampling",
            &configurations,
            budget,
        );
    }
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}
