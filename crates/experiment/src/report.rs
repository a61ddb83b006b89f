//! What an experiment produced, and how it is written: a Markdown table a
//! person reads, JSON with every measurement, and SVG plots.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::ExperimentError;
pub use crate::format::{format_bias, format_efficiency, format_ms, format_number, format_timing};
use crate::machine::Machine;
use crate::panel::Panel;
use crate::plot::Plot;
use crate::provenance::Build;
pub use crate::stats::ImageError;
use crate::stats::{PowerLaw, Timing};

/// The converged reference an experiment measured errors against.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceInfo {
    /// Samples per pixel, over both halves.
    pub samples_per_pixel: u32,
    /// The estimator that rendered it (sampler, direct-light strategy, roulette).
    pub estimator: String,
    /// Its seeds, independent of every measured render's.
    pub seeds: [u64; 2],
    /// The reference's own RMSE against the truth, estimated from its two
    /// independent halves: differences below it are not resolved.
    pub noise_rmse: f64,
    /// The same image by an independent estimator, which shares none of the
    /// reference's sampler, MIS or roulette: a bias of either shows as a
    /// difference beyond their noise.
    pub check: Option<IndependentCheck>,
    /// Its render settings, described as in the cache key.
    pub settings: String,
    /// The code that rendered it (commit, `+dirty-HASH` for uncommitted
    /// changes): the cache keeps references of this code only.
    pub code_version: String,
    /// Whether it came from the cache on disk.
    pub cached: bool,
}

/// A reference compared with an independent estimator's image of the same scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IndependentCheck {
    /// The independent estimator.
    pub estimator: String,
    /// Its samples per pixel, over both halves.
    pub samples_per_pixel: u32,
    /// Its own noise, from its two halves as for the reference.
    pub noise_rmse: f64,
    /// RMSE between the two images.
    pub difference_rmse: f64,
    /// The RMSE their noise alone gives: `√(σ_ref² + σ_check²)`.
    pub expected_rmse: f64,
    /// The same comparison on the means of 8×8 blocks, where a bias over a
    /// region stands out of noise that averaging reduces.
    pub block_difference_rmse: f64,
    /// What noise alone gives on the blocks, from the halves' blocks.
    pub block_expected_rmse: f64,
}

impl IndependentCheck {
    /// The larger of the two ratios of difference to noise: about 1 when
    /// both estimators converge to the same image, well above where one is biased.
    pub fn ratio(&self) -> f64 {
        (self.difference_rmse / self.expected_rmse.max(1e-30))
            .max(self.block_difference_rmse / self.block_expected_rmse.max(1e-30))
    }

    /// One sentence for the report.
    pub fn describe(&self) -> String {
        format!(
            "an independent estimator ({}, {} spp) differs from it by RMSE {} where their noise alone gives {} \
             (on 8×8 blocks {} against {}): {}",
            self.estimator,
            self.samples_per_pixel,
            format_number(self.difference_rmse),
            format_number(self.expected_rmse),
            format_number(self.block_difference_rmse),
            format_number(self.block_expected_rmse),
            if self.ratio() < 1.5 {
                "no bias of either is resolved".to_owned()
            } else {
                format!("{:.1}× their noise: one of them is biased", self.ratio())
            }
        )
    }
}

/// The name of a point's value that marks it as measured against a
/// reference other than its report's (a different integrand): such points
/// are left out of the scene's Pareto front.
pub const OWN_REFERENCE: &str = "own_reference";

/// One measurement of a series: the knob's value, the time it took and
/// what it gave.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Further timings of this point, by name (the tracing of each ray
    /// batch beside a build's time...), with every run for the rank test.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub timings: BTreeMap<String, Timing>,
}

impl Point {
    /// A point at knob value `x`, labelled `label`, with nothing measured yet.
    pub fn new(x: f64, label: impl Into<String>) -> Point {
        Point { x, label: label.into(), time: None, error: None, values: BTreeMap::new(), timings: BTreeMap::new() }
    }

    /// The point with a further named figure.
    pub fn with(mut self, name: &str, value: f64) -> Point {
        self.values.insert(name.to_owned(), value);
        self
    }
}

/// Measurements under one setting of the other knobs (a sampler, a
/// structure, a scene...).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// The setting the series is measured under, as the legend and tables name it.
    pub name: String,
    /// The measurements, in increasing knob value.
    pub points: Vec<Point>,
}

/// A table for the Markdown file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table {
    /// The heading above the table.
    pub title: String,
    /// Column names.
    pub header: Vec<String>,
    /// The cells, row by row, as many as the header has columns.
    pub rows: Vec<Vec<String>>,
}

/// A power law fitted to a series, as a number with its uncertainty and
/// the range it was fitted on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// The series fitted.
    pub series: String,
    /// What was fitted against what, e.g. `RMSE against spp`.
    pub quantity: String,
    /// The fitted law.
    pub law: PowerLaw,
    /// Points of the series offered to the fit, of which `law.points` were used.
    pub offered: usize,
}

impl Fit {
    /// `RMSE against spp ∝ x^-0.746 ± 0.012 (9 of 9 points, 1–256)`.
    pub fn describe(&self) -> String {
        format!(
            "{} ∝ x^{:.3} ± {:.3} (fitted on {} of {} points, x from {} to {})",
            self.quantity,
            self.law.exponent,
            self.law.standard_error,
            self.law.points,
            self.offered,
            format_number(self.law.x_min),
            format_number(self.law.x_max)
        )
    }
}

/// Everything one run of one knob produced.
///
/// Written as `KNOB.json` and read back by [`crate::write_index`]: the
/// index is made from the JSON alone, so that its prose cannot drift from
/// the data. Read back, a report has no tables, and its plots only their
/// file names and titles (the SVGs are beside the JSON).
#[derive(Debug, Serialize, Deserialize)]
pub struct Report {
    /// The knob varied (`spp`, `depth`, ...).
    pub knob: String,
    /// The question the knob answers.
    pub question: String,
    /// The scene's file, or the built-in scene's name.
    pub scene: String,
    /// The machine it ran on.
    pub machine: Machine,
    /// The program that measured: version, commit, compiler, profile, flags.
    pub build: Build,
    /// When the measurement finished, in UTC.
    pub date: String,
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
    /// Power laws fitted to the series, as numbers.
    pub fits: Vec<Fit>,
    /// What the measurements show, in sentences computed from them.
    pub findings: Vec<String>,
    /// Tables for the Markdown file.
    #[serde(skip)]
    pub tables: Vec<Table>,
    /// The plots: in JSON, their file names and titles.
    #[serde(with = "plot_files")]
    pub plots: Vec<Plot>,
    /// The settings every render shares unless the knob varies them (size,
    /// integrator, maximum depth, Russian roulette...), for knobs that render.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub renders: Option<String>,
    /// Equal-time image panels (PNG): in JSON, their file names and titles;
    /// their captions are findings.
    #[serde(with = "panel_files", default)]
    pub panels: Vec<Panel>,
}

/// A panel in a report's JSON: its file and title.
mod panel_files {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use crate::panel::{Crop, Panel};

    #[derive(Serialize, Deserialize)]
    struct PanelFile {
        file: String,
        title: String,
        /// The time each entry was given, for equal-time panels.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        budget_ms: Option<f64>,
        #[serde(default)]
        entries: Vec<EntryRecord>,
    }

    /// An entry's figures: what the panel's labels show.
    #[derive(Serialize, Deserialize)]
    struct EntryRecord {
        label: String,
        time_ms: f64,
        /// The budget's render's time, timed in alternation with this entry.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        budget_ms: Option<f64>,
        /// Its time over the budget (1.0 = exactly the budget).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        budget_share: Option<f64>,
        rmse: f64,
    }

    pub(super) fn serialize<S: Serializer>(panels: &[Panel], serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(panels.iter().map(|p| {
            PanelFile {
                file: p.file.clone(),
                title: p.title.clone(),
                budget_ms: p.budget_ms,
                entries: p
                    .entries
                    .iter()
                    .map(|e| EntryRecord {
                        label: e.label.clone(),
                        time_ms: e.time_ms,
                        budget_ms: e.budget_ms,
                        budget_share: p.budget_share(e),
                        rmse: e.rmse,
                    })
                    .collect(),
            }
        }))
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Panel>, D::Error> {
        let files = Vec::<PanelFile>::deserialize(deserializer)?;
        Ok(files
            .into_iter()
            .map(|f| Panel {
                file: f.file,
                title: f.title,
                reference: rtgi_image::HdrImage::new(1, 1),
                entries: Vec::new(),
                crop: Crop { x: 0, y: 0, side: 1 },
                scale: 0.0,
                budget_ms: f.budget_ms,
            })
            .collect())
    }
}

/// A plot in a report's JSON: its file and title.
mod plot_files {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use crate::plot::{Corner, Plot};

    #[derive(Serialize, Deserialize)]
    struct PlotFile {
        file: String,
        title: String,
    }

    pub(super) fn serialize<S: Serializer>(plots: &[Plot], serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(plots.iter().map(|p| PlotFile { file: p.file.clone(), title: p.title.clone() }))
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<Plot>, D::Error> {
        let files = Vec::<PlotFile>::deserialize(deserializer)?;
        Ok(files
            .into_iter()
            .map(|f| Plot {
                file: f.file,
                title: f.title,
                x_label: String::new(),
                y_label: String::new(),
                log_x: false,
                log_y: false,
                curves: Vec::new(),
                legend: Corner::default(),
                y_range: None,
            })
            .collect())
    }
}

/// The column names of [`measurement_cells`].
pub(crate) const MEASUREMENT_HEADER: [&str; 7] =
    ["time ms", "RMSE (min–max)", "relMSE", "bias²", "variance", "efficiency 1/(MSE·s)", "mean / reference"];

/// A measurement table's header: the `leading` columns that name the
/// configuration, then those of [`measurement_cells`].
pub(crate) fn measurement_header(leading: &[&str]) -> Vec<String> {
    leading.iter().chain(MEASUREMENT_HEADER.iter()).map(|s| s.to_string()).collect()
}

/// The table cells of a rendered measurement: time, RMSE with its range
/// over the seeds, relative MSE, squared bias (or "not resolved"),
/// variance, efficiency (none for a resolved bias: a biased estimator's MSE
/// does not fall as 1/time), and mean radiance over the reference's.
pub(crate) fn measurement_cells(point: &Point) -> [String; 7] {
    let (time, error) = (point.time.as_ref().expect("measured"), point.error.as_ref().expect("measured"));
    [
        format_timing(time),
        format!("{} ({}–{})", format_number(error.rmse), format_number(error.rmse_min), format_number(error.rmse_max)),
        format_number(error.relative_mse),
        format_bias(error),
        format_number(error.variance),
        format_efficiency(error, time),
        format!("{:.4}", error.mean / error.reference_mean.max(1e-30)),
    ]
}

impl Report {
    /// Fits a power law to `points` of `series` and records it; returns it
    /// for the caller's finding or legend, `None` if it cannot be fitted.
    pub fn fit(&mut self, series: &str, quantity: &str, offered: usize, points: &[(f64, f64)]) -> Option<Fit> {
        let law = PowerLaw::fit(points)?;
        let fit = Fit { series: series.to_owned(), quantity: quantity.to_owned(), law, offered };
        self.fits.push(fit.clone());
        Some(fit)
    }

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
        // A report over a set of scenes (a glob) leaves the scene out of its
        // plots' titles: each title names its own.
        let scene = if self.scene.contains('*') { "" } else { self.scene.as_str() };
        for plot in &self.plots {
            write(&plot.file, &plot.to_svg(scene, &self.machine)?)?;
        }
        let json = serde_json::to_string_pretty(self).expect("reports serialise");
        write(&format!("{}.json", self.knob), &json)?;
        write(&format!("{}.md", self.knob), &self.markdown())?;
        for panel in &self.panels {
            let path = folder.join(&panel.file);
            panel.write(&path)?;
            written.push(path);
        }
        Ok(written)
    }

    /// Where and with what the figures were measured, in one sentence.
    pub fn provenance(&self) -> String {
        let (m, b) = (&self.machine, &self.build);
        format!(
            "Measured {} on {}{} ({} cores, {} threads used, SIMD {}, {}) by rtgi {} at commit {}{}, built by {} \
             ({} profile, opt-level {}{}){}{}.",
            self.date,
            m.cpu,
            if m.cpu_id.is_empty() { String::new() } else { format!(" ({})", m.cpu_id) },
            m.cores,
            m.threads,
            m.simd,
            m.os,
            b.version,
            b.commit,
            if b.dirty.is_some() { " with uncommitted changes" } else { "" },
            b.rustc,
            b.profile,
            b.opt_level,
            if b.rustflags.is_empty() { String::new() } else { format!(", RUSTFLAGS {}", b.rustflags) },
            if b.peers.is_empty() { String::new() } else { format!(", with {}", b.peers.join(", ")) },
            match &self.renders {
                Some(renders) => format!("; renders: {renders}"),
                None => String::new(),
            }
        )
    }

    /// The report as Markdown: the question, the machine, findings, tables and plots.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let _ = writeln!(md, "# `{}`: {}\n", self.knob, self.question);
        let _ = writeln!(md, "Scene: {}. {}\n", self.scene, self.provenance());
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
                 ({}; seeds {} and {}, independent of the measured renders) whose own noise is RMSE ≈ {}: \
                 differences below that are not resolved.{}\n",
                r.samples_per_pixel,
                r.estimator,
                r.seeds[0],
                r.seeds[1],
                format_number(r.noise_rmse),
                r.check
                    .as_ref()
                    .map_or(String::new(), |c| format!(" To see a bias it shares with the renders, {}.", c.describe()))
            );
        }
        for finding in &self.findings {
            let _ = writeln!(md, "- {finding}");
        }
        for fit in &self.fits {
            let _ = writeln!(md, "- fit, {}: {}", fit.series, fit.describe());
        }
        if !self.findings.is_empty() || !self.fits.is_empty() {
            md.push('\n');
        }
        for plot in &self.plots {
            let _ = writeln!(md, "![{}]({})\n", plot.title, plot.file);
        }
        for panel in &self.panels {
            let _ = writeln!(md, "![{}]({})\n", panel.title, crate::panel::labelled_file(&panel.file));
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

#[cfg(test)]
mod tests {
    use super::format_number;

    #[test]
    fn numbers_have_about_four_significant_digits() {
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(30409.6859), "30410");
        assert_eq!(format_number(1.5), "1.5");
        assert_eq!(format_number(0.012345), "0.01235");
        assert_eq!(format_number(-2.0), "-2");
        assert_eq!(format_number(1.25e-7), "1.250e-7");
    }
}
