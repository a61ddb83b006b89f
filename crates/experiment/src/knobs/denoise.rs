//! `denoise`: the edge-avoiding denoiser (`rtgi render --denoise`, on by
//! default for PNG output) against the samples' mean. Both are measured at
//! the same sample counts, the denoised renders' time including their
//! guides and the filter, and compared in error against time and at equal
//! time. The filter trades variance for bias (blur, and the fireflies it
//! takes out): the squared bias over the seeds shows how much.

use rtgi_render::RenderSettings;

use crate::plot::{Curve, Plot};
use crate::reference::reference;
use crate::report::{Report, Series, Table, measurement_cells, measurement_header};
use crate::runner::{
    Budget, Candidate, MakeImage, add_equal_time_panel, measure_with, ms_per_sample, render, render_denoised,
    time_and_error,
};
use crate::verdict::{compare_efficiency, most_efficient};
use crate::{ExperimentError, Options, Steps, Subject};

/// The sample count whose denoised render sets the equal-time budget.
const BUDGET_SPP: u32 = 16;

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    super::require_light_transport(subject, "denoise")?;
    let counts: &[u32] = if options.quick { &[1, 4] } else { &[1, 4, 16, 64] };
    let budget_spp = if options.quick { 4 } else { BUDGET_SPP };
    let base = RenderSettings { adaptive: None, ..super::at_reference_depth(subject) };
    let mut steps = Steps::new(2 + 2 * counts.len(), progress);
    steps.next("reference");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let mut table = Table {
        title: "the samples' mean and the denoised image, at each sample count (denoised times include the \
                guides and the filter)"
            .to_owned(),
        header: measurement_header(&["image", "spp"]),
        rows: Vec::new(),
    };
    let kinds: [(&str, MakeImage); 2] = [("mean of the samples", render), ("denoised", render_denoised)];
    let mut curves = Vec::new();
    for (name, make) in kinds {
        let mut series = Series { name: name.to_owned(), points: Vec::new() };
        for &spp in counts {
            steps.next(&format!("{name} at {spp} spp"));
            let settings = RenderSettings { samples_per_pixel: spp, ..base.clone() };
            let point = measure_with(subject, &settings, options, &reference, make);
            let mut row = vec![name.to_owned(), spp.to_string()];
            row.extend(measurement_cells(&point));
            table.rows.push(row);
            series.points.push(point);
        }
        curves.push(Curve::error_against_time(name, &time_and_error(&series)));
        report.series.push(series);
    }
    // The denoiser trades noise for bias: where its bias is resolved it is
    // judged by that bias and by its error at equal time, not by efficiency.
    for point in &report.series[1].points {
        let error = point.error.as_ref().expect("measured");
        if error.bias_resolved() {
            report.findings.push(format!("denoised at {} spp: {}", point.label, crate::verdict::describe_bias(error)));
        }
    }
    if let (Some((_, raw)), Some((_, clean))) =
        (most_efficient(&report.series[0].points), most_efficient(&report.series[1].points))
    {
        report.findings.push(compare_efficiency(
            &format!("the most efficient unbiased denoised render ({} spp)", clean.label),
            clean,
            &format!("the most efficient mean of the samples ({} spp)", raw.label),
            raw,
        ));
    }
    report.plots.push(Plot::error_against_time(
        "denoise-tradeoff.svg",
        "RMSE against render time: the samples' mean and the denoised image".to_owned(),
        curves,
    ));

    // Equal time: the denoised render at half as many samples again as the
    // budget's count (`budget_spp`) sets the time;
    // the mean of the samples gets as many samples as fit it.
    let at = |series: &Series| series.points.iter().find(|p| p.x == budget_spp as f64).cloned();
    if let (Some(raw), Some(clean)) = (at(&report.series[0]), at(&report.series[1])) {
        steps.next("equal-time panel");
        let settings = RenderSettings { samples_per_pixel: budget_spp, ..base.clone() };
        let budget = Budget::from_sweep(settings.clone(), render_denoised, &clean);
        let candidates = [
            Candidate::render("mean of the samples", settings.clone(), ms_per_sample(&raw, budget_spp)),
            Candidate {
                label: "denoised".to_owned(),
                settings,
                ms_per_sample: ms_per_sample(&clean, budget_spp),
                make: render_denoised,
            },
        ];
        let what = "The samples' mean and the denoised image";
        let file = "denoise-equal-time.png".to_owned();
        add_equal_time_panel(&mut report, subject, &reference, file, what, &budget, &candidates);
    }
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}

/// The `denoise` knob.
pub(super) static DENOISE: super::Described = super::Described {
    name: "denoise",
    about: "The edge-avoiding denoiser against the samples' mean.",
    question: "does the denoiser lower the error at equal time, and how much bias does it trade for the noise?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::SPONZA, super::CONFERENCE]),
    run,
};
