//! `threads`: what worker threads buy in render time, and that they change
//! no answer: every sample draws from `(seed, pixel, sample)`, so the image
//! must be the same bits whatever the thread count.

use rtgi_render::RenderSettings;

use crate::plot::{Corner, Curve, Plot};
use crate::report::{Point, Report, Series, Table, format_timing};
use crate::runner::render;
use crate::stats::Timing;
use crate::verdict::compare_times;
use crate::{ExperimentError, Options, Steps, Subject};

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let spp = if options.quick { 2 } else { 16 };
    let settings = RenderSettings { samples_per_pixel: spp, adaptive: None, ..super::at_reference_depth(subject) };
    let most = options.threads.max(std::thread::available_parallelism().map_or(1, |n| n.get()));
    let counts: Vec<usize> = (0..).map(|k| 1usize << k).take_while(|&n| n < most).chain([most]).collect();
    let mut steps = Steps::new(counts.len(), progress);
    let mut table = Table {
        title: format!("{spp} spp; times of {} runs, each with its own seed", options.repeats.max(1)),
        header: ["threads", "time ms", "speed-up (median)", "image bits as with 1 thread"].map(String::from).to_vec(),
        rows: Vec::new(),
    };
    let mut series = Series { name: "render".to_owned(), points: Vec::new() };
    let mut first: Option<(rtgi_image::HdrImage, Timing)> = None;
    let mut findings = Vec::new();
    for &threads in &counts {
        steps.next(&format!("{threads} threads"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| ExperimentError::Unsuitable(format!("cannot start {threads} threads: {e}")))?;
        let (image, timing) = pool.install(|| {
            let mut image = None;
            let timing = crate::measure::time_each(
                options.repeats,
                |repeat| render(subject, &RenderSettings { seed: repeat as u64, ..settings.clone() }),
                |rendered| {
                    image.get_or_insert(rendered);
                },
            );
            (image.expect("at least one run"), timing)
        });
        let (same, speedup) = match &first {
            Some((one, one_time)) => {
                findings.push(format!(
                    "{threads} threads: {}",
                    compare_times("render time", &format!("{threads} threads"), &timing, "1 thread", one_time)
                ));
                (one.pixels() == image.pixels(), one_time.median_ms / timing.median_ms.max(1e-9))
            }
            None => (true, 1.0),
        };
        table.rows.push(vec![
            threads.to_string(),
            format_timing(&timing),
            format!("{speedup:.2}"),
            if same { "identical".into() } else { "DIFFERENT".into() },
        ]);
        let mut point = Point::new(threads as f64, format!("{threads} threads"));
        point.time = Some(timing.clone());
        series.points.push(point.with("speedup", speedup).with("identical", if same { 1.0 } else { 0.0 }));
        if first.is_none() {
            first = Some((image, timing));
        }
    }
    let differing: Vec<&str> =
        series.points.iter().filter(|p| p.values["identical"] == 0.0).map(|p| p.label.as_str()).collect();
    report.findings.push(if differing.is_empty() {
        format!("the image is the same bits at every thread count ({} tried)", counts.len())
    } else {
        format!("the image differs from the 1-thread one with {}: a determinism bug", differing.join(", "))
    });
    report.findings.extend(findings);
    let measured: Vec<(f64, f64)> = series.points.iter().map(|p| (p.x, p.values["speedup"])).collect();
    let bars = series
        .points
        .iter()
        .map(|p| {
            let (t, one) = (p.time.as_ref()?, series.points[0].time.as_ref()?);
            Some((one.median_ms / t.max_ms.max(1e-9), one.median_ms / t.min_ms.max(1e-9)))
        })
        .collect();
    let ideal: Vec<(f64, f64)> = counts.iter().map(|&n| (n as f64, n as f64)).collect();
    report.plots.push(Plot {
        file: "threads-speedup.svg".into(),
        title: format!("Render speed-up against worker threads, {spp} spp"),
        x_label: "worker threads".into(),
        y_label: "speed-up over 1 thread (median; bars: runs' min–max)".into(),
        log_x: false,
        log_y: false,
        curves: vec![Curve::new("measured", measured).with_bars(bars), Curve::guide("ideal (linear)", ideal)],
        legend: Corner::UpperLeft,
        y_range: None,
    });
    report.series.push(series);
    report.tables.push(table);
    Ok(report)
}

/// The `threads` knob.
pub(super) static THREADS: super::Described = super::Described {
    name: "threads",
    about: "Worker threads: render time, and the same bits at every count.",
    question: "what do worker threads buy in render time, and is the image the same bits at every count?",
    scenes: super::Scenes::Subject(&[super::CORNELL]),
    run,
};
