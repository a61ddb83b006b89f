//! The index of a set of experiments (`rtgi experiment all`): every plot,
//! under its question, with the findings measured beside it, and the
//! command that regenerates everything.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::{ExperimentError, Report};

/// A report and the folder it was written to, relative to the index.
#[derive(Debug)]
pub struct IndexEntry<'a> {
    /// The folder of the report's files, relative to the index.
    pub folder: PathBuf,
    /// The report written there.
    pub report: &'a Report,
}

/// Writes `index.md` into `folder`; returns its path.
pub fn write_index(folder: &Path, entries: &[IndexEntry<'_>], command: &str) -> Result<PathBuf, ExperimentError> {
    let mut md = String::new();
    let regenerate = match command.strip_prefix("rtgi ") {
        Some(args) => format!("cargo run --release -p rtgi -- {args}"),
        None => command.to_owned(),
    };
    let _ = writeln!(md, "# What accuracy costs in time\n");
    if let Some(first) = entries.first() {
        let m = &first.report.machine;
        let _ = writeln!(
            md,
            "Measured on {} ({} cores, {} threads used, SIMD {}, {}) with rtgi {}. Every figure below is what \
             the command measured; regenerate them all with\n\n```sh\n{regenerate}\n```\n",
            m.cpu, m.cores, m.threads, m.simd, m.os, first.report.rtgi_version
        );
        let _ = writeln!(
            md,
            "Times are medians of {} runs, drawn with their min and max; errors are RMSE of linear radiance \
             against converged references with seeds of their own, whose noise each report states.\n",
            first.report.repeats
        );
    }
    let mut knob = "";
    for entry in entries {
        let report = entry.report;
        if report.knob != knob {
            knob = &report.knob;
            let _ = writeln!(md, "## `{}`: {}\n", report.knob, report.question);
        }
        let folder = entry.folder.to_string_lossy().replace('\\', "/");
        let _ = writeln!(md, "### {} — [table and all figures]({folder}/{}.md)\n", report.scene, report.knob);
        for plot in &report.plots {
            let _ = writeln!(md, "![{}]({folder}/{})\n", plot.title, plot.file);
        }
        for finding in &report.findings {
            let _ = writeln!(md, "- {finding}");
        }
        md.push('\n');
    }
    let path = folder.join("index.md");
    std::fs::create_dir_all(folder).map_err(|source| ExperimentError::Write { path: folder.to_owned(), source })?;
    std::fs::write(&path, md).map_err(|source| ExperimentError::Write { path: path.clone(), source })?;
    Ok(path)
}
