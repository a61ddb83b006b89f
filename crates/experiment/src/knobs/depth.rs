//! `depth`: the most bounces a path may take, with Russian roulette on and
//! off: time, RMSE, and the energy missing against a converged reference
//! (the same scene at a depth no path of it reaches, 64 bounces).

use rtgi_render::{Integrator, RenderSettings};

use crate::plot::{Corner, Curve, Plot};
use crate::reference::reference;
use crate::report::{Report, Series, Table, format_bias, measurement_cells, measurement_header};
use crate::runner::{Budget, Candidate, add_equal_time_panel, measure};
use crate::verdict::{compare_efficiency, compare_times};
use crate::{ExperimentError, Options, Steps, Subject};

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    // The report's line on the renders says the depth is what varies.
    report.renders = Some(super::renders(&super::at_reference_depth(subject), Some("varied")));
    if !subject.settings.integrator.simulates_light() || subject.settings.integrator == Integrator::Direct {
        return Err(ExperimentError::Unsuitable(format!(
            "the depth experiment needs the path integrator (the subject uses '{}')",
            subject.settings.integrator
        )));
    }
    let depths: Vec<u32> = if options.quick { vec![1, 2, 4] } else { vec![1, 2, 3, 4, 6, 8, 12, 16, 32] };
    let spp = if options.quick { 4 } else { 64 };
    let base = RenderSettings { samples_per_pixel: spp, ..subject.settings.clone() };
    let mut steps = Steps::new(1 + 2 * depths.len(), progress);
    steps.next("reference");
    // The reference runs every path to CONVERGED_DEPTH whatever the base's depth.
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let mut table = Table {
        title: format!("{spp} spp per render"),
        header: {
            let mut header = measurement_header(&["Russian roulette", "max depth"]);
            header.push("energy missing".into());
            header
        },
        rows: Vec::new(),
    };
    let (mut energy, mut times, mut errors, mut tradeoff) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for roulette in [true, false] {
        let name = if roulette { "roulette on" } else { "roulette off" };
        let mut series = Series { name: name.to_owned(), points: Vec::new() };
        for &depth in &depths {
            steps.next(&format!("{name}, depth {depth}"));
            let settings = RenderSettings { max_depth: depth, russian_roulette: roulette, ..base.clone() };
            let mut point = measure(subject, &settings, options, &reference);
            let error = point.error.as_ref().expect("measured");
            let missing = 1.0 - error.mean / error.reference_mean.max(1e-30);
            point.x = depth as f64;
            point.label = depth.to_string();
            point = point.with("energy_missing", missing);
            let mut row = vec![name.to_owned(), depth.to_string()];
            row.extend(measurement_cells(&point));
            row.push(format!("{:.2}%", missing * 100.0));
            table.rows.push(row);
            series.points.push(point);
        }
        let xs = || series.points.iter().map(|p| p.x);
        energy.push(Curve::new(
            name,
            xs().zip(series.points.iter().map(|p| p.values["energy_missing"] * 100.0)).collect(),
        ));
        times.push(
            Curve::new(
                name,
                xs().zip(series.points.iter().map(|p| p.time.as_ref().expect("measured").median_ms)).collect(),
            )
            .with_bars(series.points.iter().map(|p| p.time.as_ref().map(|t| (t.min_ms, t.max_ms))).collect()),
        );
        errors.push(Curve::new(
            name,
            xs().zip(series.points.iter().map(|p| p.error.as_ref().expect("measured").rmse)).collect(),
        ));
        // Each point says its depth: the tradeoff's points are not in the order of either axis.
        let depths = series.points.iter().filter(|p| p.time.is_some() && p.error.is_some());
        tradeoff.push(
            Curve::error_against_time(name, &crate::runner::time_and_error(&series))
                .with_point_labels(depths.map(|p| format!("depth {}", p.label)).collect()),
        );
        report.series.push(series);
    }
    let mut findings = Vec::new();
    for series in &report.series {
        if let Some(first) = series.points.iter().find(|p| p.values["energy_missing"].abs() < 0.01) {
            findings
                .push(format!("{}: less than 1% of the energy is missing from depth {} on", series.name, first.label));
        }
        // The error of a shallow depth is mostly bias: energy that is
        // missing, which more samples would not bring back.
        if let Some(first) = series.points.iter().find(|p| !p.error.as_ref().expect("measured").bias_resolved()) {
            findings.push(format!("{}: the bias is not resolved from depth {} on", series.name, first.label));
        }
        if let Some(shallow) = series.points.first() {
            let e = shallow.error.as_ref().expect("measured");
            findings.push(format!(
                "{}: at depth {}, bias² {} is {:.0}% of the MSE (energy missing {:.1}%)",
                series.name,
                shallow.label,
                format_bias(e),
                100.0 * e.bias2.max(0.0) / e.mse().max(1e-300),
                shallow.values["energy_missing"] * 100.0
            ));
        }
    }
    report.findings.extend(findings);
    if let [on, off] = &report.series[..]
        && let (Some(a), Some(b)) = (on.points.last(), off.points.last())
    {
        let (ta, tb) = (a.time.as_ref().expect("measured"), b.time.as_ref().expect("measured"));
        report.findings.push(format!(
            "at depth {}: {}, at {:.2}× its RMSE; {}",
            a.label,
            compare_times("render time", "roulette on", ta, "roulette off", tb),
            a.error.as_ref().expect("measured").rmse / b.error.as_ref().expect("measured").rmse.max(1e-30),
            compare_efficiency("roulette on", a, "roulette off", b)
        ));
    }
    let title = format!("RMSE against render time, max depth 1 to {}, {spp} spp", depths.last().expect("depths"));
    report.plots.push(Plot::error_against_time("depth-tradeoff.svg", title, tradeoff));
    report.plots.push(Plot {
        file: "depth-energy.svg".into(),
        title: "Energy missing against max depth".into(),
        x_label: "max depth (bounces)".into(),
        y_label: "energy missing (% of the reference's mean)".into(),
        log_x: true,
        log_y: false,
        curves: energy,
        legend: Corner::UpperRight,
        y_range: None,
    });
    report.plots.push(Plot {
        file: "depth-time.svg".into(),
        title: format!("Render time against max depth, {spp} spp"),
        x_label: "max depth (bounces)".into(),
        y_label: "render time (ms)".into(),
        log_x: true,
        log_y: false,
        curves: times,
        legend: Corner::UpperLeft,
        y_range: None,
    });
    report.plots.push(Plot {
        file: "depth-error.svg".into(),
        title: format!("RMSE against max depth, {spp} spp"),
        x_label: "max depth (bounces)".into(),
        y_label: "RMSE of linear radiance (radiance)".into(),
        log_x: true,
        log_y: true,
        curves: errors,
        legend: Corner::UpperRight,
        y_range: None,
    });
    // The equal-time panel: the deepest depth with and without roulette, and
    // a shallow one (biased: missing energy), in the time roulette takes at the deepest.
    let deepest = *depths.last().expect("depths");
    let shallow = depths[depths.len().min(2) - 1];
    if let [on, off] = &report.series[..]
        && let (Some(deep_on), Some(deep_off), Some(shallow_on)) =
            (on.points.last(), off.points.last(), on.points.iter().find(|p| p.x == shallow as f64))
    {
        let budget = Budget {
            settings: RenderSettings { max_depth: deepest, russian_roulette: true, ..base.clone() },
            make: crate::runner::render,
            estimate_ms: deep_on.time.as_ref().expect("measured").median_ms,
        };
        let configuration = |label: String, depth: u32, roulette: bool, point: &crate::Point| {
            let settings = RenderSettings { max_depth: depth, russian_roulette: roulette, ..base.clone() };
            Candidate::render(label, settings, crate::runner::ms_per_sample(point, spp))
        };
        let candidates = vec![
            configuration(format!("depth {deepest}, roulette on"), deepest, true, deep_on),
            configuration(format!("depth {deepest}, roulette off"), deepest, false, deep_off),
            configuration(format!("depth {shallow}, roulette on"), shallow, true, shallow_on),
        ];
        let (file, what) = ("depth-equal-time.png".to_owned(), "Depth and Russian roulette");
        add_equal_time_panel(&mut report, subject, &reference, file, what, &budget, &candidates);
    }
    report.tables.push(table);
    report.reference = Some(reference.info);
    Ok(report)
}

/// The `depth` knob.
pub(super) static DEPTH: super::Described = super::Described {
    name: "depth",
    about: "Bounces, with Russian roulette on and off.",
    question: "what do bounces cost, and how much light is missing without them?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::SPONZA]),
    run,
};
