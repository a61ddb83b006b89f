//! `spp`: error against samples per pixel for each pixel sampler, on
//! log-log axes with the fitted slope beside the O(N^-1/2) line, and
//! error against time, so that samplers are compared at equal time.
//!
//! The spreading samplers place the camera ray in the pixel and spread the
//! first vertex's light and BSDF numbers; deeper vertices are independent.
//! So the experiment measures two integrands: the scene's own (light
//! transport) and the camera-ray integrand alone (the `primary`
//! integrator: edges and texture detail), and it is run on scenes of both
//! kinds: the Cornell box, whose error at high counts is mostly the
//! emitter's edge, and interiors and glossy scenes, where transport noise
//! dominates. Fits are of RMSE, relative MSE and variance; efficiency
//! `1/(MSE·time)` compares the samplers at 16 spp.

use rtgi_render::{Integrator, PixelSampler, RenderSettings};

use crate::plot::{Corner, Curve, Plot};
use crate::reference::reference;
use crate::report::{Report, Series, Table, format_number, measurement_cells, measurement_header};
use crate::runner::{Budget, Candidate, add_equal_time_panel, measure};
use crate::verdict::compare_efficiency;
use crate::{ExperimentError, Options, Steps, Subject};

/// The count at which the samplers are compared in efficiency.
const COMPARED_AT: f64 = 16.0;

const SAMPLERS: [PixelSampler; 4] =
    [PixelSampler::Uniform, PixelSampler::Stratified, PixelSampler::LowDiscrepancy, PixelSampler::Sobol];

/// Errors within this factor of the reference's own noise are left out of the fits.
const NOISE_MARGIN: f64 = 3.0;

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let counts: Vec<u32> = if options.quick { vec![1, 4, 16] } else { (0..=8).map(|k| 1 << k).collect() };
    let mut integrands = vec![("light transport", subject.settings.integrator, "")];
    if subject.settings.integrator != Integrator::Primary {
        integrands.push(("camera ray only", Integrator::Primary, "-pixel"));
    }
    let mut steps = Steps::new(1 + integrands.len() * (1 + SAMPLERS.len() * counts.len()), progress);
    for (integrand, integrator, suffix) in integrands {
        let base = RenderSettings { integrator, ..super::at_reference_depth(subject) };
        steps.next(&format!("{integrand}: reference"));
        let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
        let noise = reference.info.noise_rmse;
        let mut error_curves = Vec::new();
        let mut time_curves = Vec::new();
        let mut table = Table {
            title: format!(
                "{integrand} ({integrator} integrator; reference {} spp, noise RMSE ≈ {})",
                reference.info.samples_per_pixel,
                format_number(noise)
            ),
            header: measurement_header(&["sampler", "spp"]),
            rows: Vec::new(),
        };
        for sampler in SAMPLERS {
            let mut series = Series { name: format!("{sampler}, {integrand}"), points: Vec::new() };
            for &spp in &counts {
                steps.next(&format!("{integrand}: {sampler} at {spp} spp"));
                let settings = RenderSettings { sampler, samples_per_pixel: spp, ..base.clone() };
                let mut point = measure(subject, &settings, options, &reference);
                if integrator != subject.settings.integrator {
                    // Measured against the camera-ray integrand's own reference:
                    // not comparable with the scene's other configurations.
                    point = point.with(crate::report::OWN_REFERENCE, 1.0);
                }
                let mut row = vec![sampler.to_string(), spp.to_string()];
                row.extend(measurement_cells(&point));
                table.rows.push(row);
                series.points.push(point);
            }
            let rmse = |p: &crate::Point| p.error.as_ref().expect("measured").rmse;
            let resolved: Vec<(f64, f64)> =
                series.points.iter().filter(|p| rmse(p) > NOISE_MARGIN * noise).map(|p| (p.x, rmse(p))).collect();
            let offered = series.points.len();
            let quantity =
                format!("RMSE against spp (counts whose error is above {NOISE_MARGIN}× the reference's noise)");
            let label = match report.fit(&series.name, &quantity, offered, &resolved) {
                Some(fit) => format!(
                    "{sampler} (slope {})",
                    crate::plot::with_standard_error(fit.law.exponent, Some(fit.law.standard_error))
                ),
                None => {
                    report.findings.push(format!(
                        "{integrand}, {sampler}: too few counts above the reference's noise to fit a slope"
                    ));
                    sampler.to_string()
                }
            };
            // Relative MSE weighs dark pixels as much as bright ones, so it
            // shows whether a sampler helps the whole image or only the
            // bright edges that dominate RMSE; the variance is the part of
            // the error that samples reduce.
            let of = |f: fn(&crate::report::ImageError) -> f64| -> Vec<(f64, f64)> {
                series.points.iter().map(|p| (p.x, f(p.error.as_ref().expect("measured")))).collect()
            };
            report.fit(&series.name, "relative MSE against spp", offered, &of(|e| e.relative_mse));
            report.fit(&series.name, "variance against spp", offered, &of(|e| e.variance));
            let bars = series.points.iter().map(|p| p.error.as_ref().map(|e| (e.rmse_min, e.rmse_max))).collect();
            error_curves
                .push(Curve::new(&label, series.points.iter().map(|p| (p.x, rmse(p))).collect()).with_bars(bars));
            time_curves.push(Curve::error_against_time(sampler.to_string(), &crate::runner::time_and_error(&series)));
            report.series.push(series);
        }
        // Efficiency at equal samples against the uniform sampler, resolved or not.
        let at = |sampler: PixelSampler| {
            report
                .series
                .iter()
                .rev()
                .find(|s| s.name == format!("{sampler}, {integrand}"))
                .and_then(|s| s.points.iter().find(|p| p.x == COMPARED_AT))
        };
        if let Some(uniform) = at(PixelSampler::Uniform) {
            for &sampler in &SAMPLERS[1..] {
                if let Some(other) = at(sampler) {
                    report.findings.push(format!(
                        "{integrand}, at {COMPARED_AT} spp: {}",
                        compare_efficiency(&sampler.to_string(), other, "uniform", uniform)
                    ));
                }
            }
        }
        // The O(N^-1/2) law through the first uniform point, and the reference's noise floor.
        if let Some(&(x0, y0)) = error_curves.first().and_then(|c| c.points.first()) {
            let last = *counts.last().expect("counts") as f64;
            error_curves.push(Curve::guide("∝ spp^-1/2", vec![(x0, y0), (last, y0 * (last / x0).powf(-0.5))]));
            error_curves.push(Curve::guide("reference noise", vec![(x0, noise), (last, noise)]));
        }
        report.plots.push(Plot {
            file: format!("spp{suffix}-error.svg"),
            title: format!("RMSE against spp, {integrand}"),
            x_label: "samples per pixel (count)".into(),
            y_label: "RMSE of linear radiance (radiance)".into(),
            log_x: true,
            log_y: true,
            curves: error_curves,
            legend: Corner::LowerLeft,
            y_range: None,
        });
        report.plots.push(Plot::error_against_time(
            format!("spp{suffix}-time.svg"),
            format!("RMSE against render time, {integrand}"),
            time_curves,
        ));
        report.tables.push(table);
        if integrator == subject.settings.integrator {
            // Equal time: every sampler given the time stratified sampling takes at half as many samples
            // again as the compared count (`budget_spp`: clear of the step in cost past a power of two).
            let at_count = |sampler: PixelSampler| {
                report.series.iter().rev().find(|s| s.name == format!("{sampler}, {integrand}")).and_then(|s| {
                    s.points.iter().find(|p| p.x == COMPARED_AT.min(*counts.last().expect("counts") as f64))
                })
            };
            if let Some(stratified) = at_count(PixelSampler::Stratified) {
                let sweep = RenderSettings {
                    sampler: PixelSampler::Stratified,
                    samples_per_pixel: stratified.x as u32,
                    ..base.clone()
                };
                let budget = Budget::from_sweep(sweep, crate::runner::render, stratified);
                let candidates: Vec<Candidate> = SAMPLERS
                    .iter()
                    .filter_map(|&sampler| {
                        let point = at_count(sampler)?;
                        let settings = RenderSettings { sampler, ..base.clone() };
                        let ms_per_sample = crate::runner::ms_per_sample(point, point.x as u32);
                        Some(Candidate::render(sampler.to_string(), settings, ms_per_sample))
                    })
                    .collect();
                steps.next("equal-time panel");
                let file = "spp-equal-time.png".to_owned();
                add_equal_time_panel(&mut report, subject, &reference, file, "The samplers", &budget, &candidates);
            }
            report.reference = Some(reference.info);
        }
    }
    Ok(report)
}

/// The `spp` knob.
pub(super) static SPP: super::Described = super::Described {
    name: "spp",
    about: "Samples per pixel, for each pixel sampler.",
    question: "how fast does the error fall with samples per pixel, for each pixel sampler, and at equal time?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::BUNNY, super::ROOM, super::GLOSSY]),
    run,
};
