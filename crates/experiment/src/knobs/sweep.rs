//! What the knobs that vary one render setting share: each configuration
//! measured at the same sample counts against one converged reference,
//! drawn as error against time, and compared with the default
//! configuration by the verdict module (efficiency where neither is biased).

use rtgi_render::RenderSettings;

use crate::plot::{Curve, Plot};
use crate::reference::Reference;
use crate::report::{Report, Series, Table, measurement_cells, measurement_header};
use crate::runner::{measure, time_and_error};
use crate::verdict::compare_efficiency;
use crate::{Options, Steps, Subject};

/// One setting of the knob: its name and the settings it renders with.
pub(super) struct Setting {
    pub(super) label: String,
    pub(super) settings: RenderSettings,
}

/// Measures every setting at every count of `counts` against `reference`;
/// `default` (an index into `settings`) is what the others are compared
/// with, at the count `compared_at`. Adds a table, the series, an
/// error-against-time plot named `file` and the comparisons.
#[allow(clippy::too_many_arguments)]
pub(super) fn measure_settings(
    subject: &Subject,
    options: &Options,
    report: &mut Report,
    steps: &mut Steps,
    reference: &Reference,
    settings: &[Setting],
    default: usize,
    counts: &[u32],
    compared_at: u32,
    file: &str,
    what: &str,
) {
    let mut table = Table {
        title: format!(
            "{what} (reference {} spp, noise RMSE ≈ {})",
            reference.info.samples_per_pixel,
            crate::report::format_number(reference.info.noise_rmse)
        ),
        header: measurement_header(&[what, "spp"]),
        rows: Vec::new(),
    };
    let mut curves = Vec::new();
    let first_series = report.series.len();
    for setting in settings {
        let mut series = Series { name: setting.label.clone(), points: Vec::new() };
        for &spp in counts {
            steps.next(&format!("{} at {spp} spp", setting.label));
            let render = RenderSettings { samples_per_pixel: spp, ..setting.settings.clone() };
            let point = measure(subject, &render, options, reference);
            let mut row = vec![setting.label.clone(), spp.to_string()];
            row.extend(measurement_cells(&point));
            table.rows.push(row);
            series.points.push(point);
        }
        curves.push(Curve::error_against_time(setting.label.clone(), &time_and_error(&series)));
        report.series.push(series);
    }
    let at = |index: usize| report.series[first_series + index].points.iter().find(|p| p.x == compared_at as f64);
    if let Some(baseline) = at(default) {
        let mut findings = Vec::new();
        for (index, setting) in settings.iter().enumerate().filter(|(i, _)| *i != default) {
            if let Some(point) = at(index) {
                findings.push(format!(
                    "at {compared_at} spp: {}",
                    compare_efficiency(&setting.label, point, &settings[default].label, baseline)
                ));
            }
        }
        report.findings.extend(findings);
    }
    report.plots.push(Plot::error_against_time(file, format!("RMSE against render time, by {what}"), curves));
    report.tables.push(table);
}
