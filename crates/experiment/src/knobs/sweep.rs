//! What the knobs that vary one render setting share: each configuration
//! measured at the same sample counts against one converged reference,
//! drawn as error against time, and compared with the default
//! configuration by the verdict module (efficiency where neither is biased).

use rtgi_render::RenderSettings;

use crate::plot::{Curve, Plot};
use crate::reference::reference;
use crate::report::{Report, Series, Table, measurement_cells, measurement_header};
use crate::runner::{measure, time_and_error};
use crate::verdict::compare_efficiency;
use crate::{ExperimentError, Options, Steps, Subject};

/// One setting of the knob: its name and the settings it renders with.
pub(super) struct Setting {
    pub(super) label: String,
    pub(super) settings: RenderSettings,
}

/// A knob that varies one render setting: its settings, which of them the
/// others are compared with, the counts and where they are compared.
pub(super) struct Sweep<'a> {
    /// What the reference renders: the settings the knob leaves alone.
    pub(super) base: RenderSettings,
    pub(super) settings: Vec<Setting>,
    /// The index into `settings` the others are compared with.
    pub(super) default: usize,
    pub(super) counts: &'a [u32],
    /// The count at which they are compared.
    pub(super) compared_at: u32,
    /// The error-against-time plot's file.
    pub(super) file: &'a str,
    /// What the knob varies, in the table and the plot.
    pub(super) what: &'a str,
}

/// Renders the reference of `sweep.base`, then measures every setting at
/// every count against it; adds a table, the series, an error-against-time
/// plot and each setting's comparison with the default at `compared_at`.
pub(super) fn measure_settings(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
    sweep: Sweep,
) -> Result<Report, ExperimentError> {
    let Sweep { base, settings, default, counts, compared_at, file, what } = sweep;
    let mut steps = Steps::new(1 + settings.len() * counts.len(), progress);
    steps.next("reference");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
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
    for setting in &settings {
        let mut series = Series { name: setting.label.clone(), points: Vec::new() };
        for &spp in counts {
            steps.next(&format!("{} at {spp} spp", setting.label));
            let render = RenderSettings { samples_per_pixel: spp, ..setting.settings.clone() };
            let point = measure(subject, &render, options, &reference);
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
    report.reference = Some(reference.info);
    Ok(report)
}
