//! `analytic`: each estimator's bias against an answer known in closed form
//! (white furnaces, [`crate::analytic`]), not against another estimator:
//! every spreading sampler with every direct-light strategy, Russian
//! roulette on and off, over several seeds; the mean over the image and the
//! seeds against the exact radiance, in standard errors. A control that is
//! biased on purpose (an indirect clamp) shows that the measurement sees a
//! bias where there is one.

use rtgi_accel::AccelKind;
use rtgi_render::{DirectStrategy, PixelSampler, RenderSettings};

use crate::plot::{Corner, Curve, Plot};
use crate::report::{Point, Report, Series, Table, format_number, format_timing};
use crate::stats::Timing;
use crate::{ExperimentError, Options, Steps, Subject};

/// A render's time and its error, with the error's range (here one value thrice).
type TimedError = (Timing, f64, f64, f64);

/// A bias beyond this many standard errors is reported as resolved.
pub(crate) const RESOLVED_SE: f64 = 4.0;

/// The relative rounding of f32 radiance summed over an image: the
/// resolution of a bias when the estimator has no variance.
const ROUNDING: f64 = 1e-6;

/// Paths this long bring back less than ρ^65 of the light (5·10⁻⁷ of it at ρ = 0.8).
const DEPTH: u32 = 64;

pub(super) fn run(options: &Options, mut report: Report, progress: &dyn Fn(&str)) -> Result<Report, ExperimentError> {
    let furnaces: &[(f32, f32)] = if options.quick { &[(0.5, 0.4)] } else { &[(0.5, 0.4), (0.8, 0.2)] };
    let (side, spp, seeds) = if options.quick { (16, 4, 12) } else { (32, 16, 12) };
    // Quick runs take MIS only: twelve seeds of heavy-tailed means are few
    // enough already.
    let strategies: &[DirectStrategy] = if options.quick { &[DirectStrategy::Mis] } else { DirectStrategy::ALL };
    let samplers = [PixelSampler::Uniform, PixelSampler::Stratified, PixelSampler::LowDiscrepancy, PixelSampler::Sobol];
    let mut estimators: Vec<(String, RenderSettings)> = Vec::new();
    for sampler in samplers {
        for &strategy in strategies {
            for roulette in [true, false] {
                let name = format!("{sampler}, {strategy}, roulette {}", if roulette { "on" } else { "off" });
                let settings = RenderSettings {
                    width: side,
                    height: side,
                    samples_per_pixel: spp,
                    sampler,
                    direct_strategy: strategy,
                    russian_roulette: roulette,
                    max_depth: DEPTH,
                    ..RenderSettings::default()
                };
                estimators.push((name, settings));
            }
        }
    }
    let control = RenderSettings { indirect_clamp: Some(0.05), ..estimators[0].1.clone() };
    estimators.push(("control: clamp 0.05 (biased on purpose)".into(), control));
    let mut steps = Steps::new(furnaces.len() * estimators.len(), progress);
    let mut table = Table {
        title: format!("{side}² pixels, {spp} spp, {seeds} seeds, paths to depth {DEPTH}; bias of the image's mean"),
        header: ["furnace", "estimator", "mean / exact", "bias", "standard error", "bias / SE", "time ms"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    let mut curves = Vec::new();
    for &(albedo, emitted) in furnaces {
        let (scene, camera, exact) = crate::analytic::white_furnace(albedo, emitted);
        let kind = AccelKind::Bvh8;
        let accel = kind
            .try_build(&scene.triangle_positions(), &kind.default_params())
            .map_err(|e| ExperimentError::Build(e.to_string()))?;
        let name = format!("furnace ρ = {albedo}, Le = {emitted}");
        let subject = Subject { name: name.clone(), scene, camera, accel, settings: RenderSettings::default() };
        let mut series = Series { name: name.clone(), points: Vec::new() };
        let mut resolved = Vec::new();
        let mut z_scores = Vec::new();
        let mut by_strategy: Vec<(String, Vec<TimedError>)> = Vec::new();
        for (index, (label, settings)) in estimators.iter().enumerate() {
            steps.next(&format!("{name}: {label}"));
            let mut means = Vec::new();
            let time = crate::measure::time_each(
                seeds as usize,
                |seed| crate::runner::render(&subject, &RenderSettings { seed: seed as u64, ..settings.clone() }),
                |image| {
                    means.push(
                        image.pixels().iter().map(|p| p.element_sum() as f64 / 3.0).sum::<f64>()
                            / image.pixels().len() as f64,
                    )
                },
            );
            let n = means.len() as f64;
            let mean = means.iter().sum::<f64>() / n;
            let spread = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let standard_error = spread / n.sqrt();
            let bias = mean - exact;
            // An estimator without variance (BSDF sampling in a diffuse
            // furnace: every path weighs ρ per bounce) has a standard error
            // of 0; its mean is then exact to the f32 rounding of the
            // radiance, about 10⁻⁶ of it, which stands in for the error.
            let z = bias / standard_error.max(ROUNDING * exact);
            if z.abs() > RESOLVED_SE {
                resolved.push(format!("{label} ({:+.4}, {:.1} SE)", bias / exact, z));
            }
            // The control stands hundreds of standard errors off; plotted,
            // it would flatten the estimators it vouches for into one line.
            if index + 1 < estimators.len() {
                z_scores.push((time.median_ms, z));
                // The error of one render's mean against the exact answer: bias and spread together.
                let error = (bias * bias + spread * spread).sqrt() / exact;
                let group = label.split_once(", ").map_or(label.as_str(), |(_, rest)| rest).to_owned();
                match by_strategy.iter_mut().find(|(g, _)| *g == group) {
                    Some((_, points)) => points.push((time.clone(), error, error, error)),
                    None => by_strategy.push((group, vec![(time.clone(), error, error, error)])),
                }
            }
            table.rows.push(vec![
                name.clone(),
                label.clone(),
                format!("{:.5}", mean / exact),
                format_number(bias),
                format_number(standard_error),
                format!("{z:+.2}"),
                format_timing(&time),
            ]);
            let mut point = Point::new(index as f64, label.clone())
                .with("mean", mean)
                .with("exact", exact)
                .with("bias", bias)
                .with("standard_error", standard_error)
                .with("bias_in_standard_errors", z);
            point.time = Some(time);
            series.points.push(point);
        }
        let unbiased = estimators.len() - 1;
        let quiet = series.points[..unbiased]
            .iter()
            .filter(|p| p.values["bias_in_standard_errors"].abs() <= RESOLVED_SE)
            .count();
        report.findings.push(format!(
            "{name}: exact radiance {}; {quiet} of {unbiased} estimators show no bias resolved (|bias| ≤ {RESOLVED_SE} standard \
             errors){}",
            format_number(exact),
            if resolved.is_empty() { String::new() } else { format!("; resolved: {}", resolved.join(", ")) }
        ));
        // Error against time: one curve per direct strategy and roulette
        // setting, a point per pixel sampler (the table names each).
        let error_curves = by_strategy
            .iter()
            .map(|(group, points)| Curve { markers_only: true, ..Curve::error_against_time(group.clone(), points) })
            .collect();
        report.plots.push(Plot {
            file: format!("analytic-error-time-{}.svg", report.plots.len() + 1),
            title: format!(
                "{name}: relative error of one render's mean against the exact answer, against render time;                  a point per pixel sampler"
            ),
            x_label: "render time (ms, median over the seeds; bars min–max)".into(),
            y_label: "RMS error of one render's mean (fraction of the exact answer)".into(),
            log_x: true,
            log_y: true,
            curves: error_curves,
            legend: Corner::UpperRight,
            y_range: None,
        });
        curves.push(Curve::new(name, z_scores));
        report.series.push(series);
    }
    let times = curves.iter().flat_map(|c| c.points.iter().map(|p| p.0));
    let (first, last) = times.fold((f64::INFINITY, 0.0f64), |(lo, hi), t| (lo.min(t), hi.max(t)));
    curves.push(Curve::guide(format!("+{RESOLVED_SE} SE"), vec![(first, RESOLVED_SE), (last, RESOLVED_SE)]));
    curves.push(Curve::guide(format!("−{RESOLVED_SE} SE"), vec![(first, -RESOLVED_SE), (last, -RESOLVED_SE)]));
    let zs = curves.iter().flat_map(|c| c.points.iter().map(|p| p.1));
    let (lo, hi) = zs.fold((-RESOLVED_SE, RESOLVED_SE), |(lo, hi), z| (lo.min(z), hi.max(z)));
    let z_range = (lo - 0.35 * (hi - lo), hi + 0.08 * (hi - lo));
    report.plots.push(Plot {
        file: "analytic.svg".into(),
        title: "Bias of each estimator against the exact answer, in standard errors (the biased control, hundreds of \
                standard errors off, is in the table)"
            .into(),
        x_label: "render time (ms, median over the seeds); each point an estimator of the table".into(),
        y_label: "bias (standard errors)".into(),
        log_x: true,
        log_y: false,
        curves: curves.into_iter().map(|c| Curve { markers_only: !c.guide, ..c }).collect(),
        legend: Corner::LowerLeft,
        // Room below the −4 SE line for the legend: the guides span the width.
        y_range: Some(z_range),
    });
    report.tables.push(table);
    Ok(report)
}

/// The `analytic` knob.
pub(super) static ANALYTIC: super::Described = super::Described {
    name: "analytic",
    about: "Each estimator's bias against answers known in closed form (white furnaces).",
    question: "is any estimator (sampler, direct-light strategy, roulette) biased against an answer known exactly?",
    scenes: super::Scenes::Own("white furnaces (built in: closed emitting spheres)"),
    // It measures on scenes of its own, not the subject's.
    run: |_subject, options, report, progress| run(options, report, progress),
};
