//! `image-size`: render time against the pixel count, at a fixed count of
//! samples per pixel: whether time grows in proportion to the pixels (the
//! cost is the samples) or a fixed cost (the plan, threads, the first
//! touches of the structure) weighs on small images.

use rtgi_render::RenderSettings;

use crate::plot::{Corner, Curve, Plot};
use crate::report::{Point, Report, Series, Table, format_number, format_timing};
use crate::runner::render;
use crate::verdict::compare;
use crate::{ExperimentError, Options, Steps, Subject};

/// The image sizes, as multiples of the subject's side.
const SCALES: [f64; 5] = [0.125, 0.25, 0.5, 1.0, 2.0];

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let spp = if options.quick { 1 } else { 4 };
    let scales: &[f64] = if options.quick { &SCALES[..2] } else { &SCALES };
    let base = RenderSettings { samples_per_pixel: spp, adaptive: None, ..super::at_reference_depth(subject) };
    let mut steps = Steps::new(scales.len(), progress);
    let mut table = Table {
        title: format!("{spp} spp at every size; times of {} runs, each with its own seed", options.repeats.max(1)),
        header: ["size", "pixels", "time ms", "ns per pixel sample (median)"].map(String::from).to_vec(),
        rows: Vec::new(),
    };
    let mut series = Series { name: "render".to_owned(), points: Vec::new() };
    let mut per_sample_runs = Vec::new();
    for &scale in scales {
        let (width, height) =
            (((base.width as f64 * scale).round() as u32).max(1), ((base.height as f64 * scale).round() as u32).max(1));
        steps.next(&format!("{width}x{height}"));
        let settings = RenderSettings { width, height, ..base.clone() };
        let timing = crate::measure::time_each(
            options.repeats,
            |repeat| render(subject, &RenderSettings { seed: repeat as u64, ..settings.clone() }),
            drop,
        );
        let times = &timing.runs_ms;
        let samples = (width as f64) * (height as f64) * spp as f64;
        let ns: Vec<f64> = times.iter().map(|ms| ms * 1e6 / samples).collect();
        table.rows.push(vec![
            format!("{width}x{height}"),
            format!("{}", width as u64 * height as u64),
            format_timing(&timing),
            format_number(crate::verdict::median(&ns)),
        ]);
        let mut point = Point::new((width as u64 * height as u64) as f64, format!("{width}x{height}"));
        point.time = Some(timing);
        series.points.push(point.with("ns_per_sample", crate::verdict::median(&ns)));
        per_sample_runs.push((format!("{width}x{height}"), ns));
    }
    let time_points: Vec<(f64, f64)> =
        series.points.iter().map(|p| (p.x, p.time.as_ref().expect("timed").median_ms)).collect();
    if let Some(fit) = report.fit("render", "render time against pixels", time_points.len(), &time_points) {
        // Two points fit any line: their slope has no standard error.
        let standard_error = (fit.law.points > 2).then_some(fit.law.standard_error);
        report.findings.push(format!(
            "render time ∝ pixels^{} over {} sizes (1 is in proportion to the pixels)",
            crate::plot::with_standard_error(fit.law.exponent, standard_error),
            time_points.len()
        ));
    }
    if let (Some((small, small_ns)), Some((large, large_ns))) = (per_sample_runs.first(), per_sample_runs.last()) {
        report.findings.push(compare(
            "time per pixel sample",
            &format!("the smallest image ({small})"),
            small_ns,
            &format!("the largest ({large})"),
            large_ns,
        ));
    }
    let bars = series.points.iter().map(|p| p.time.as_ref().map(|t| (t.min_ms, t.max_ms))).collect();
    report.plots.push(Plot {
        file: "image-size-time.svg".into(),
        title: format!("Render time against the pixel count, {spp} spp"),
        x_label: "pixels".into(),
        y_label: "render time (ms, median; bars: runs' min–max)".into(),
        log_x: true,
        log_y: true,
        curves: vec![Curve::new("render", time_points).with_bars(bars)],
        legend: Corner::UpperLeft,
        y_range: None,
    });
    report.series.push(series);
    report.tables.push(table);
    Ok(report)
}

/// The `image-size` knob.
pub(super) static IMAGE_SIZE: super::Described = super::Described {
    name: "image-size",
    about: "Render time against the image's pixel count.",
    question: "does render time grow in proportion to the pixels, or does a fixed cost weigh on small images?",
    scenes: super::Scenes::Subject(&[super::CORNELL]),
    run,
};
