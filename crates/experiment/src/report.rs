//! What an experiment produced, and how it is written: a Markdown table a
//! person reads, JSON with every measurement, and SVG plots.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::ExperimentError;
use crate::machine::Machine;
use crate::plot::Plot;
use crate::stats::Timing;

/// How far a render is from the converged reference, over all pixels and
/// channels of linear radiance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ImageError {
    /// Root mean square error: `sqrt` of the mean squared error over the
    /// repeats (each repeat with its own seed), and the smallest and
    /// largest RMSE of one repeat.
    pub rmse: f64,
    /// The smallest RMSE of one repeat.
    pub rmse_min: f64,
    /// The largest RMSE of one repeat.
    pub rmse_max: f64,
    /// Mean of `(test − reference)² / (reference² + 0.01)` over the repeats.
    pub relative_mse: f64,
    /// Mean radiance of the render, against the reference's: where they
    /// differ, energy is missing (or added), not only noise.
    pub mean: f64,
    /// Mean radiance of the reference.
    pub reference_mean: f64,
}

/// The converged reference an experiment measured errors against.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReferenceInfo {
    /// Samples per pixel, over both halves.
    pub samples_per_pixel: u32,
    /// Its seeds, independent of every measured render's.
    pub seeds: [u64; 2],
    /// The reference's own RMSE against the truth, estimated from its two
    /// independent halves: differences below it are not resolved.
    pub noise_rmse: f64,
    /// Its render settings, described as in the cache key.
    pub settings: String,
    /// Whether it came from the cache on disk.
    pub cached: bool,
}

/// One measurement of a series: the knob's value, the time it took and
/// what it gave.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Point {
    /// The knob's value, as plotted (spp, depth, triangle count...).
    pub x: f64,
    /// The knob's value as a person reads it.
    pub label: String,
    /// The time the measurement took, if it was timed.
    pub time: Option<Timing>,
    /// The image's error against the reference, if an image was measured.
    pub error: Option<ImageError>,
    /// Further figures of this point: nodes visited, disagreements, failure rates...
    pub values: BTreeMap<String, f64>,
}

impl Point {
    /// A point at knob value `x`, labelled `label`, with nothing measured yet.
    pub fn new(x: f64, label: impl Into<String>) -> Point {
        Point { x, label: label.into(), time: None, error: None, values: BTreeMap::new() }
    }

    /// The point with a further named figure.
    pub fn with(mut self, name: &str, value: f64) -> Point {
        self.values.insert(name.to_owned(), value);
        self
    }
}

/// Measurements under one setting of the other knobs (a sampler, a
/// structure, a scene...).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    /// The setting the series is measured under, as the legend and tables name it.
    pub name: String,
    /// The measurements, in increasing knob value.
    pub points: Vec<Point>,
}

/// A table for the Markdown file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Table {
    /// The heading above the table.
    pub title: String,
    /// Column names.
    pub header: Vec<String>,
    /// The cells, row by row, as many as the header has columns.
    pub rows: Vec<Vec<String>>,
}

/// Everything one run of one knob produced.
#[derive(Debug, Serialize)]
pub struct Report {
    /// The knob varied (`spp`, `depth`, ...).
    pub knob: String,
    /// The question the knob answers.
    pub question: String,
    /// The scene's file, or the built-in scene's name.
    pub scene: String,
    /// The machine it ran on.
    pub machine: Machine,
    /// The version of rtgi that measured.
    pub rtgi_version: String,
    /// The command that produced the report, as typed.
    pub command: String,
    /// Timed runs behind each timing.
    pub repeats: usize,
    /// Whether the reduced, quick version ran (its numbers are rough).
    pub quick: bool,
    /// The reference errors were measured against, if the knob used one.
    pub reference: Option<ReferenceInfo>,
    /// Every measurement, one series per setting of the other knobs.
    pub series: Vec<Series>,
    /// What the measurements show, in sentences (fitted slopes...).
    pub findings: Vec<String>,
    #[serde(skip)]
    /// Tables for the Markdown file.
    pub tables: Vec<Table>,
    /// The plots, by file name.
    #[serde(serialize_with = "plot_files")]
    pub plots: Vec<Plot>,
}

fn plot_files<S: serde::Serializer>(plots: &[Plot], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(plots.iter().map(|p| &p.file))
}

/// Formats milliseconds as a person reads them.
pub fn format_ms(ms: f64) -> String {
    if ms >= 100.0 {
        format!("{ms:.0}")
    } else if ms >= 1.0 {
        format!("{ms:.2}")
    } else {
        format!("{ms:.4}")
    }
}

/// `median (min–max)` of a timing, in ms.
pub fn format_timing(t: &Timing) -> String {
    format!("{} ({}–{})", format_ms(t.median_ms), format_ms(t.min_ms), format_ms(t.max_ms))
}

/// The table cells of a rendered measurement: time, RMSE with its range
/// over the repeats, relative MSE, and mean radiance over the reference's.
pub(crate) fn measurement_cells(point: &Point) -> [String; 4] {
    let (time, error) = (point.time.expect("measured"), point.error.expect("measured"));
    [
        format_timing(&time),
        format!("{} ({}–{})", format_number(error.rmse), format_number(error.rmse_min), format_number(error.rmse_max)),
        format_number(error.relative_mse),
        format!("{:.4}", error.mean / error.reference_mean.max(1e-30)),
    ]
}

/// A number in 4 significant digits, in scientific notation when small or large.
pub fn format_number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e5).contains(&x.abs()) {
        format!("{:.4}", x).trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        format!("{x:.3e}")
    }
}

impl Report {
    /// Writes `KNOB.md`, `KNOB.json` and the plots into `folder` (created
    /// if needed); returns the paths written.
    pub fn write(&self, folder: &Path) -> Result<Vec<PathBuf>, ExperimentError> {
        std::fs::create_dir_all(folder).map_err(|source| ExperimentError::Write { path: folder.to_owned(), source })?;
        let mut written = Vec::new();
        let mut write = |name: &str, text: &str| -> Result<(), ExperimentError> {
            let path = folder.join(name);
            rtgi_image::write_atomically(&path, text.as_bytes())
                .map_err(|source| ExperimentError::Write { path: path.clone(), source })?;
            written.push(path);
            Ok(())
        };
        for plot in &self.plots {
            write(&plot.file, &plot.to_svg(&self.scene, &self.machine)?)?;
        }
        let json = serde_json::to_string_pretty(self).expect("reports serialise");
        write(&format!("{}.json", self.knob), &json)?;
        write(&format!("{}.md", self.knob), &self.markdown())?;
        Ok(written)
    }

    /// The report as Markdown: the question, the machine, findings, tables and plots.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let _ = writeln!(md, "# `{}`: {}\n", self.knob, self.question);
        let _ = writeln!(
            md,
            "Scene: {}. Machine: {} ({} cores, {} threads used, SIMD {}, {}). rtgi {}.\n",
            self.scene,
            self.machine.cpu,
            self.machine.cores,
            self.machine.threads,
            self.machine.simd,
            self.machine.os,
            self.rtgi_version
        );
        let _ = writeln!(md, "Command: `{}`\n", self.command);
        let _ = writeln!(
            md,
            "Times are the median of {} run{} with min and max in brackets.{}\n",
            self.repeats,
            if self.repeats == 1 { "" } else { "s" },
            if self.quick { " **Quick run**: reduced sizes, for tests; not for conclusions." } else { "" }
        );
        if let Some(r) = &self.reference {
            let _ = writeln!(
                md,
                "Errors are RMSE and relative MSE of linear radiance over the image, against a reference of {} spp \
                 (seeds {} and {}, independent of the measured renders) whose own noise is RMSE ≈ {}: \
                 differences below that are not resolved.\n",
                r.samples_per_pixel,
                r.seeds[0],
                r.seeds[1],
                format_number(r.noise_rmse)
            );
        }
        for finding in &self.findings {
            let _ = writeln!(md, "- {finding}");
        }
        if !self.findings.is_empty() {
            md.push('\n');
        }
        for plot in &self.plots {
            let _ = writeln!(md, "![{}]({})\n", plot.title, plot.file);
        }
        for table in &self.tables {
            let _ = writeln!(md, "## {}\n", table.title);
            let _ = writeln!(md, "| {} |", table.header.join(" | "));
            let _ = writeln!(md, "|{}", "---|".repeat(table.header.len()));
            for row in &table.rows {
                let _ = writeln!(md, "| {} |", row.join(" | "));
            }
            md.push('\n');
        }
        md
    }
}
