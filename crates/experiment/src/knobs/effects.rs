//! `effects`: each decision of the effects planner reversed on the
//! subject's scene: an effect the plan leaves out, forced on, and one it
//! simulates, forced off. Each is measured in time and in error against the
//! one converged reference of the plan as planned.
//!
//! What the planner promises, and the experiment checks: an effect the
//! scene does not call for costs time when forced on but no accuracy (the
//! renders draw the same random numbers whatever the plan, so the error
//! must equal the planned render's within the reference's noise), and an
//! effect the scene calls for is missed when forced off (more error, often
//! missing energy).

use rtgi_render::{EffectPlan, RenderSettings};

use crate::plot::{Corner, Curve, Plot};
use crate::reference::reference;
use crate::report::{Point, Report, Series, Table, format_bias, format_ms, format_number, format_timing};
use crate::runner::measure;
use crate::{ExperimentError, Options, Steps, Subject};

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let spp = if options.quick { 4 } else { 64 };
    let base = RenderSettings { samples_per_pixel: spp, ..super::at_reference_depth(subject) };
    let plan = EffectPlan::new(&subject.scene, &base);
    let reversals = plan.reversals(&subject.scene, &base);
    if reversals.is_empty() {
        return Err(ExperimentError::Unsuitable(format!(
            "the effects experiment has no decision to reverse: every effect is forced on or off ({})",
            base.effects.on.union(base.effects.off)
        )));
    }
    let mut steps = Steps::new(2 + reversals.len(), progress);
    steps.next("reference of the plan as planned");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let noise = reference.info.noise_rmse;
    steps.next("the plan");
    // The first render also pays for waking the threads; it must not make the plan look slow.
    crate::runner::render(subject, &RenderSettings { samples_per_pixel: 1, ..base.clone() });
    let planned = measure(subject, &base, options, &reference);
    let (planned_time, planned_error) =
        (planned.time.as_ref().expect("measured"), planned.error.as_ref().expect("measured"));
    let energy = |p: &Point| {
        let e = p.error.as_ref().expect("measured");
        e.mean / e.reference_mean.max(1e-30)
    };

    let mut table = Table {
        title: format!(
            "{spp} spp per render; plan: {} (reference {} spp, noise RMSE ≈ {})",
            plan.enabled(),
            reference.info.samples_per_pixel,
            format_number(noise)
        ),
        header: [
            "render",
            "time ms",
            "× plan's time",
            "RMSE (min–max)",
            "× plan's RMSE",
            "relMSE",
            "bias²",
            "variance",
            "efficiency 1/(MSE·s)",
            "mean / reference",
            "verdict",
        ]
        .map(String::from)
        .to_vec(),
        rows: vec![vec![
            "plan".to_owned(),
            format_timing(planned_time),
            "1".to_owned(),
            format!(
                "{} ({}–{})",
                format_number(planned_error.rmse),
                format_number(planned_error.rmse_min),
                format_number(planned_error.rmse_max)
            ),
            "1".to_owned(),
            format_number(planned_error.relative_mse),
            format_bias(planned_error),
            format_number(planned_error.variance),
            crate::report::format_efficiency(planned_error, planned_time),
            format!("{:.4}", energy(&planned)),
            "as planned".to_owned(),
        ]],
    };
    let mut series = Series { name: "plan and its reversals".to_owned(), points: Vec::new() };
    let mut plan_point = planned.clone();
    plan_point.x = 0.0;
    plan_point.label = "plan".to_owned();
    series
        .points
        .push(plan_point.with("time_ratio", 1.0).with("rmse_ratio", 1.0).with("energy_ratio", energy(&planned)));

    let mut curves = Vec::new();
    let (mut free, mut costly, mut missed, mut unexpected) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (index, reversal) in reversals.iter().enumerate() {
        let label = reversal.label();
        steps.next(&label);
        let mut point = measure(subject, &reversal.settings, options, &reference);
        let (time, error) = (point.time.as_ref().expect("measured"), point.error.as_ref().expect("measured"));
        let time_ratio = time.median_ms / planned_time.median_ms.max(1e-9);
        // A time the rank test does not tell from the plan's is not resolved.
        let time_resolved = crate::verdict::times_resolved(time, planned_time);
        let time_cell =
            |ratio: f64| if time_resolved { format!("{ratio:.3}") } else { format!("{ratio:.3} (not resolved)") };
        let rmse_ratio = error.rmse / planned_error.rmse.max(1e-30);
        // The reference's noise is the finest difference in error the
        // experiment resolves; a change of the image's mean radiance is
        // resolved beyond three standard errors of the planned render's mean.
        let rmse_change = error.rmse - planned_error.rmse;
        let mean_standard_error = planned_error.rmse / ((base.width as f64) * (base.height as f64)).sqrt();
        let energy_change = (error.mean - planned_error.mean) / planned_error.reference_mean.max(1e-30);
        let resolved = rmse_change.abs() > noise || (error.mean - planned_error.mean).abs() > 3.0 * mean_standard_error;
        let verdict = match (reversal.planned, resolved) {
            (false, false) => {
                free.push((label.clone(), time_cell(time_ratio), rmse_change));
                "not needed: no accuracy gained".to_owned()
            }
            (false, true) => {
                unexpected.push(format!(
                    "{label} changes the RMSE by {} (the reference's noise is {}) and the mean radiance by {:+.2}%, \
                     although the plan left it out",
                    format_number(rmse_change),
                    format_number(noise),
                    energy_change * 100.0
                ));
                "changes the image: the plan was wrong to leave it out".to_owned()
            }
            (true, true) => {
                missed.push((label.clone(), time_cell(time_ratio), rmse_ratio, energy(&point)));
                format!("needed: RMSE ×{rmse_ratio:.2}, mean {:+.1}%", energy_change * 100.0)
            }
            (true, false) => {
                costly.push((label.clone(), time_cell(time_ratio)));
                "no change resolved at this spp".to_owned()
            }
        };
        table.rows.push(vec![
            label.clone(),
            format_timing(time),
            time_cell(time_ratio),
            format!(
                "{} ({}–{})",
                format_number(error.rmse),
                format_number(error.rmse_min),
                format_number(error.rmse_max)
            ),
            format!("{rmse_ratio:.4}"),
            format_number(error.relative_mse),
            format_bias(error),
            format_number(error.variance),
            crate::report::format_efficiency(error, time),
            format!("{:.4}", energy(&point)),
            verdict,
        ]);
        // From the plan to the reversal: where the decision moves the render in time and error.
        let scale = planned_error.rmse.max(1e-30);
        curves.push(
            Curve::new(&label, vec![(1.0, 1.0), (time_ratio, rmse_ratio)])
                .with_bars(vec![None, Some((error.rmse_min / scale, error.rmse_max / scale))]),
        );
        point.x = (index + 1) as f64;
        point.label = label;
        let energy_ratio = energy(&point);
        series.points.push(
            point
                .with("time_ratio", time_ratio)
                .with("rmse_ratio", rmse_ratio)
                .with("rmse_change", rmse_change)
                .with("energy_ratio", energy_ratio)
                .with("planned", if reversal.planned { 1.0 } else { 0.0 }),
        );
    }
    report.series.push(series);

    report.findings.push(format!(
        "the plan simulates {} and leaves out {}; {} decisions reversed, {spp} spp per render, \
         as planned {} ms and RMSE {}",
        plan.enabled(),
        plan.omitted(),
        reversals.len(),
        format_ms(planned_time.median_ms),
        format_number(planned_error.rmse)
    ));
    if !free.is_empty() {
        let times: Vec<String> = free.iter().map(|(l, t, _)| format!("{l} {t}×")).collect();
        let largest = free.iter().map(|(_, _, change)| change.abs()).fold(0.0, f64::max);
        let change = if largest == 0.0 {
            "the RMSE is the same to the last bit (the same paths are traced)".to_owned()
        } else {
            format!("the RMSE changes by at most {}", format_number(largest))
        };
        report.findings.push(format!(
            "forcing on what the scene does not call for takes {} the plan's time and buys no accuracy: \
             {change} (the reference's noise is {})",
            times.join(", "),
            format_number(noise)
        ));
    }
    for (label, time_ratio, rmse_ratio, energy_ratio) in &missed {
        report.findings.push(format!(
            "{label}: {time_ratio}× the time, {rmse_ratio:.2}× the RMSE, mean radiance {:.1}% of the reference's: \
             the scene calls for it",
            energy_ratio * 100.0
        ));
    }
    for (label, time_ratio) in &costly {
        report.findings.push(format!(
            "{label}: {time_ratio}× the time, and neither the RMSE nor the mean radiance changes beyond their \
             noise at {spp} spp"
        ));
    }
    report.findings.extend(unexpected);

    report.plots.push(Plot {
        file: "effects.svg".into(),
        title: format!("Each decision of the plan reversed, {spp} spp"),
        x_label: "render time relative to the plan's (ratio of medians)".into(),
        y_label: "RMSE relative to the plan's (ratio)".into(),
        // Log on both axes, so that twice and half the plan's are equally far from it.
        log_x: true,
        log_y: true,
        curves,
        legend: Corner::UpperRight,
        y_range: None,
    });
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}

/// The `effects` knob.
pub(super) static EFFECTS: super::Described = super::Described {
    name: "effects",
    about: "Each decision of the effects planner reversed.",
    question: "what does each effect cost, and does leaving out one the scene does not call for cost accuracy?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::HELMET]),
    run,
};
