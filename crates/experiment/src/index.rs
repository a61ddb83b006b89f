//! The index of a set of experiments (`rtgi experiment all`): every plot,
//! under its question, with the findings and fits measured beside it.
//!
//! The index is made from the reports' JSON alone ([`index_markdown`]), so
//! that its prose cannot drift from the data: a test regenerates the
//! committed index from the committed JSON and fails on any difference.
//! Reports of different code (another commit, or uncommitted changes) are
//! refused, naming them: their figures are not comparable.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::knobs::direct::DIRECT;
use crate::pareto;
use crate::plot::Plot;
use crate::provenance::Build;
use crate::report::{Point, format_number};
use crate::{ExperimentError, KNOBS, Knob, Machine, Report, knob};

/// What one `rtgi experiment all` run was: its command and how long it took.
/// Written as `run.json` beside the index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// The command, as typed.
    pub command: String,
    /// The optional cargo features the program was built with that change
    /// what is measured (`embree`: Embree measured beside our structures).
    pub features: Vec<String>,
    /// The program that ran it.
    pub build: Build,
    /// The machine it ran on.
    pub machine: Machine,
    /// When it started and finished, in UTC.
    pub started: String,
    /// When it finished.
    pub finished: String,
    /// Its wall time in seconds, references included.
    pub wall_seconds: f64,
}

impl RunRecord {
    /// The measuring features this program was built with.
    pub fn features() -> Vec<String> {
        rtgi_accel::AccelKind::PEERS.iter().map(|k| k.name().to_owned()).collect()
    }
}

/// The name of the run record beside the index.
pub const RUN_RECORD: &str = "run.json";

/// A report read back from its JSON, with its folder relative to the index.
#[derive(Debug)]
pub struct IndexedReport {
    /// The folder of the report's files, relative to the index.
    pub folder: PathBuf,
    /// The report, as read back (no tables; plots by file and title).
    pub report: Report,
}

/// Reads every report below `folder` (files `KNOB.json` named after a
/// knob, in folders not starting with a dot), ordered as `rtgi experiment
/// all` runs the knobs, then by folder.
pub fn read_reports(folder: &Path) -> Result<Vec<IndexedReport>, ExperimentError> {
    let mut found = Vec::new();
    collect(folder, folder, &mut found)?;
    let order = |report: &Report| KNOBS.iter().position(|k| k.name() == report.knob).unwrap_or(usize::MAX);
    found.sort_by(|a, b| order(&a.report).cmp(&order(&b.report)).then_with(|| a.folder.cmp(&b.folder)));
    Ok(found)
}

fn collect(root: &Path, folder: &Path, found: &mut Vec<IndexedReport>) -> Result<(), ExperimentError> {
    let unreadable =
        |path: &Path, e: std::io::Error| ExperimentError::Read { path: path.to_owned(), message: e.to_string() };
    let mut entries: Vec<PathBuf> = std::fs::read_dir(folder)
        .map_err(|e| unreadable(folder, e))?
        .map(|entry| entry.map(|e| e.path()).map_err(|e| unreadable(folder, e)))
        .collect::<Result<_, _>>()?;
    entries.sort();
    for path in entries {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        if name.starts_with('.') {
            continue;
        }
        if path.is_dir() {
            collect(root, &path, found)?;
        } else if let Some(stem) = name.strip_suffix(".json")
            && knob(stem).is_some()
        {
            let text = std::fs::read_to_string(&path).map_err(|e| unreadable(&path, e))?;
            let report: Report = serde_json::from_str(&text).map_err(|e| ExperimentError::Read {
                path: path.clone(),
                message: format!("not a report of this version of rtgi: {e}"),
            })?;
            let relative = folder.strip_prefix(root).unwrap_or(folder).to_owned();
            found.push(IndexedReport { folder: relative, report });
        }
    }
    Ok(())
}

/// Refuses reports of different code, naming the folders of each version.
fn check_one_version(reports: &[IndexedReport], run: Option<&RunRecord>) -> Result<(), ExperimentError> {
    let mut versions: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for r in reports {
        let place = format!("{}/{}.json", r.folder.display(), r.report.knob);
        versions.entry(r.report.build.code_version()).or_default().push(place);
    }
    if let Some(run) = run {
        versions.entry(run.build.code_version()).or_default().push(RUN_RECORD.to_owned());
    }
    if versions.len() > 1 {
        let listed: Vec<String> =
            versions.iter().map(|(version, files)| format!("{version}: {}", files.join(", "))).collect();
        return Err(ExperimentError::MixedVersions(listed.join("; ")));
    }
    Ok(())
}

/// The folder of the per-scene Pareto plots, inside the index's folder.
pub(crate) const PARETO_FOLDER: &str = "pareto";

/// A file name for a scene's plot: its file's stem, lower case, or the
/// built-in scene's name with dashes.
fn scene_slug(scene: &str) -> String {
    let name = scene.split(" (").next().unwrap_or(scene);
    let stem = Path::new(name).file_stem().map_or_else(|| name.to_owned(), |s| s.to_string_lossy().into_owned());
    stem.to_lowercase().chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect()
}

/// Each scene's Pareto plot (`pareto/SCENE.svg`) with its configurations,
/// for the scenes whose reports measured rendered configurations.
fn pareto_plots(reports: &[IndexedReport]) -> Vec<(String, Plot, Vec<pareto::Configuration>)> {
    // The analytic knob measures bias against exact answers, not render
    // error against a reference: it has no front. The direct knob renders
    // three scenes of its own, each against its own reference: a front each.
    let on_the_scene = |r: &&IndexedReport| knob(&r.report.knob).is_some_and(|k| k.uses_scene());
    let direct = reports.iter().filter(|r| r.report.knob == DIRECT.name());
    let reports: Vec<&IndexedReport> = reports.iter().filter(on_the_scene).collect();
    let mut scenes: Vec<&str> = Vec::new();
    for r in &reports {
        if !scenes.contains(&r.report.scene.as_str()) {
            scenes.push(&r.report.scene);
        }
    }
    let mut plots: Vec<(String, Plot, Vec<pareto::Configuration>)> = scenes
        .into_iter()
        .filter_map(|scene| {
            let configurations = pareto::configurations(reports.iter().map(|r| &r.report).filter(|r| r.scene == scene));
            // Every scene with rendered configurations, even of one knob:
            // its front across the knob's settings is the scene's trade-off.
            (!configurations.is_empty()).then(|| {
                let file = format!("{PARETO_FOLDER}/{}.svg", scene_slug(scene));
                (scene.to_owned(), pareto::plot(&file, &configurations), configurations)
            })
        })
        .collect();
    for report in direct {
        // Its series are named "SCENE, STRATEGY".
        let mut names: Vec<&str> =
            report.report.series.iter().filter_map(|s| s.name.split_once(", ").map(|(n, _)| n)).collect();
        names.dedup();
        for name in names {
            let configurations: Vec<pareto::Configuration> = pareto::configurations([&report.report])
                .into_iter()
                .filter(|c| c.label.starts_with(&format!("{name}, ")))
                .collect();
            if !configurations.is_empty() {
                let file = format!("{PARETO_FOLDER}/direct-knob-{}.svg", scene_slug(name));
                let scene = format!("the direct knob's {name} scene");
                plots.push((scene, pareto::plot(&file, &configurations), configurations));
            }
        }
    }
    plots
}

/// The index of the reports below `folder`, as Markdown, from their JSON alone.
pub fn index_markdown(folder: &Path) -> Result<String, ExperimentError> {
    let reports = read_reports(folder)?;
    let run_path = folder.join(RUN_RECORD);
    let run: Option<RunRecord> = match std::fs::read_to_string(&run_path) {
        Ok(text) => Some(serde_json::from_str(&text).map_err(|e| ExperimentError::Read {
            path: run_path.clone(),
            message: format!("not a run record: {e}"),
        })?),
        Err(_) => None,
    };
    check_one_version(&reports, run.as_ref())?;
    let mut md = String::new();
    let _ = writeln!(md, "# What accuracy costs in time\n");
    let _ = writeln!(
        md,
        "This page is generated from the JSON beside it (`rtgi experiment index` remakes it; a test fails when \
         it differs). Every figure is what the command measured.\n"
    );
    if let Some(first) = reports.first() {
        let _ = writeln!(md, "{}\n", first.report.provenance());
    }
    if let Some(run) = &run {
        let features =
            if run.features.is_empty() { String::new() } else { format!(" --features {}", run.features.join(",")) };
        let regenerate = match run.command.strip_prefix("rtgi ") {
            Some(args) => format!("cargo run --release -p rtgi{features} -- {args}"),
            None => run.command.clone(),
        };
        let _ = writeln!(
            md,
            "Regenerate everything with\n\n```sh\n{regenerate}\n```\n\nwhich took {:.0} minutes of wall time \
             ({} to {}, references included).\n",
            run.wall_seconds / 60.0,
            run.started,
            run.finished
        );
    }
    if let Some(first) = reports.first() {
        let _ = writeln!(
            md,
            "Times are medians of {} runs, drawn with their min and max; errors are of linear radiance against \
             converged references with seeds of their own, whose noise each report states. A difference inside \
             the spread is written as not resolved.\n",
            first.report.repeats
        );
    }
    let paretos = pareto_plots(&reports);
    if !paretos.is_empty() {
        let _ = writeln!(
            md,
            "## The trade-off on one plot, per scene\n\nEvery configuration of every knob measured on the scene \
             against the same converged reference, RMSE against time, with the Pareto front: the configurations \
             that no other beats beyond the resolution of the measurement (a rank test at 95% confidence on the \
             runs' times and the seeds' errors) in one without being beaten in the other. Biased configurations \
             can be on it, as error at equal time is their measure; each says its bias.\n"
        );
        for (scene, plot, configurations) in &paretos {
            let count = configurations.len();
            let on = plot.curves.last().map_or(String::new(), |front| front.label.clone());
            let _ = writeln!(md, "### {scene}: {count} configurations, {on}\n\n![{}]({})\n", plot.title, plot.file);
            let _ = writeln!(md, "Front (fastest first): {}\n", pareto::describe_front(configurations));
        }
    }
    // Our wide BVHs against Embree close the `accel` reports they come from.
    let peers = peers_markdown(&reports);
    let mut knob = "";
    for entry in &reports {
        let report = &entry.report;
        if report.knob != knob {
            if knob == "accel" {
                md.push_str(&peers);
            }
            knob = &report.knob;
            let _ = writeln!(md, "## `{}`: {}\n", report.knob, report.question);
        }
        let folder = entry.folder.to_string_lossy().replace('\\', "/");
        let prefix = if folder.is_empty() { String::new() } else { format!("{folder}/") };
        let quick = if report.quick { " (quick run: reduced sizes, not for conclusions)" } else { "" };
        let _ = writeln!(md, "### {}{quick} — [table and all figures]({prefix}{}.md)\n", report.scene, report.knob);
        for plot in &report.plots {
            let _ = writeln!(md, "![{}]({prefix}{})\n", plot.title, plot.file);
        }
        for panel in &report.panels {
            let _ = writeln!(md, "![{}]({prefix}{})\n", panel.title, crate::panel::labelled_file(&panel.file));
        }
        for finding in &report.findings {
            let _ = writeln!(md, "- {finding}");
        }
        for fit in &report.fits {
            let _ = writeln!(md, "- fit, {}: {}", fit.series, fit.describe());
        }
        md.push('\n');
    }
    if knob == "accel" {
        md.push_str(&peers);
    }
    Ok(md)
}

/// Our wide BVHs beside Embree, from the `accel` reports that measured
/// Embree: throughput and build time, and each as a multiple of Embree's
/// (greater is better for rays, less for builds). Empty when no report
/// measured Embree.
fn peers_markdown(reports: &[IndexedReport]) -> String {
    const OURS: [&str; 3] = ["bvh4", "bvh8", "sbvh8"];
    let mut rows = Vec::new();
    let mut threads = 0;
    let mut rays = None;
    for entry in reports.iter().filter(|e| e.report.knob == "accel") {
        let point = |name: &str| entry.report.series.iter().find(|s| s.name == name).and_then(|s| s.points.first());
        let Some(embree) = point("embree") else { continue };
        let figures = |point: &Point| {
            let value = |key: &str| point.values.get(key).copied().unwrap_or(f64::NAN);
            let build = point.time.as_ref().map_or(f64::NAN, |t| t.median_ms);
            [value("camera_mrays"), value("camera_batch_mrays"), value("incoherent_mrays"), build]
        };
        // The runs behind each figure, for the rank test: a ratio the
        // measurement does not resolve is marked so.
        let runs = |point: &Point| {
            let timing = |key: &str| point.timings.get(key).map(|t| t.samples()).unwrap_or_default();
            [
                timing("camera_trace"),
                timing("camera_batch_trace"),
                timing("incoherent_trace"),
                point.time.as_ref().map(|t| t.samples()).unwrap_or_default(),
            ]
        };
        let (theirs, their_runs) = (figures(embree), runs(embree));
        threads = entry.report.machine.threads;
        rays = Some((
            embree.values.get("camera_rays_timed").copied(),
            embree.values.get("incoherent_rays_timed").copied(),
        ));
        let scene = scene_slug(&entry.report.scene);
        for name in OURS {
            let Some(point) = point(name) else { continue };
            let cells: Vec<String> = figures(point)
                .iter()
                .zip(theirs)
                .zip(runs(point).iter().zip(&their_runs))
                .map(|((ours, theirs), (our_runs, their_runs))| {
                    let resolved = !our_runs.is_empty()
                        && !their_runs.is_empty()
                        && crate::verdict::RankComparison::of(our_runs, their_runs).resolved();
                    let mark = if resolved { "" } else { ", not resolved" };
                    format!("{} ({:.2}×{mark})", format_number(*ours), ours / theirs)
                })
                .collect();
            rows.push(format!("| {scene} | {name} | {} |", cells.join(" | ")));
        }
        let cells: Vec<String> = theirs.iter().map(|v| format_number(*v)).collect();
        rows.push(format!("| {scene} | Embree | {} |", cells.join(" | ")));
    }
    if rows.is_empty() {
        return String::new();
    }
    // docs/targets.md measures with the `peers` example's rays: this says how
    // these differ, from the reports themselves.
    let rays_line = match rays {
        Some((Some(camera), Some(incoherent))) => format!(
            "These are the experiment's rays: {} camera rays of the report's camera and image, and {} incoherent \
             rays leaving the scene's surfaces; `docs/targets.md` uses the `peers` example's (a camera on the \
             bounding sphere at 40° in 4×4 tiles, and 1,000,000 rays from random points of the bounding box), so \
             the ratios of the two differ with the rays, not with the code.",
            format_number(camera),
            format_number(incoherent)
        ),
        _ => String::new(),
    };
    let mut md = format!(
        "### Our wide BVHs against Embree\n\nFrom the `accel` reports above: the same rays for all, {threads} threads. \
         In brackets, the multiple of Embree's figure: `rtcIntersect1` for camera and incoherent rays, \
         `rtcIntersect16` for the batch of camera rays, and its build; \"not resolved\" where the rank test of the \
         runs does not tell the two apart at 95% confidence. {rays_line}\n\n\
         | scene | structure | camera Mrays/s | camera batch Mrays/s | incoherent Mrays/s | build ms |\n\
         |---|---|---:|---:|---:|---:|\n",
    );
    for row in rows {
        md.push_str(&row);
        md.push('\n');
    }
    md.push('\n');
    md
}

/// Writes `index.md` and the Pareto plots into `folder` from the reports'
/// JSON below it; returns the index's path.
pub fn write_index(folder: &Path) -> Result<PathBuf, ExperimentError> {
    let md = index_markdown(folder)?;
    let reports = read_reports(folder)?;
    if let Some(first) = reports.first() {
        for (scene, plot, _) in pareto_plots(&reports) {
            let path = folder.join(&plot.file);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)
                    .map_err(|source| ExperimentError::Write { path: parent.to_owned(), source })?;
            }
            let svg = plot.to_svg(&scene, &first.report.machine)?;
            rtgi_image::write_atomically(&path, svg.as_bytes())
                .map_err(|source| ExperimentError::Write { path: path.clone(), source })?;
        }
    }
    let path = folder.join("index.md");
    rtgi_image::write_atomically(&path, md.as_bytes())
        .map_err(|source| ExperimentError::Write { path: path.clone(), source })?;
    Ok(path)
}
