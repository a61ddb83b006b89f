//! The committed report (`docs/experiments`) says only what its JSON holds:
//! `index.md` is regenerated from the JSON and must equal what is
//! committed, byte for byte. Edit a figure by hand and this test fails;
//! rerun the experiments and regenerate instead:
//!
//! ```sh
//! cargo run --release -p rtgi -- experiment all --out docs/experiments
//! cargo run --release -p rtgi -- experiment index --out docs/experiments   # the index alone, from the JSON
//! ```
//!
//! `index.md` is the one home of the results: the README and the guide,
//! written by hand, link to it and copy none of its findings, figures or
//! provenance (a copy would not be regenerated with it, and would go stale).

use std::path::{Path, PathBuf};

use rtgi_experiment::index_markdown;
use rtgi_tests::{scratch_dir, workspace_root};

fn docs() -> PathBuf {
    workspace_root().join("docs/experiments")
}

/// The pages written by hand through which a reader comes to the results:
/// the README and the guide.
fn hand_written_pages() -> Vec<PathBuf> {
    let guide = workspace_root().join("docs/guide");
    let mut pages: Vec<PathBuf> = std::fs::read_dir(&guide)
        .unwrap_or_else(|e| panic!("{}: {e}", guide.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "md"))
        .collect();
    pages.sort();
    pages.insert(0, workspace_root().join("README.md"));
    pages
}

/// The lines of the index that state results: its provenance ("Measured
/// ... at commit ..."), its findings and fits (list items) and the rows of
/// its tables, those with a figure and long enough not to recur by chance.
fn result_lines(index: &str) -> impl Iterator<Item = &str> {
    index.lines().map(str::trim).filter(|line| {
        let kind = line.starts_with("Measured ") || line.starts_with("- ") || line.starts_with("| ");
        kind && line.len() >= 40 && line.contains(|c: char| c.is_ascii_digit())
    })
}

/// The index's results that `page` repeats.
fn copied_results<'a>(page: &str, index: &'a str) -> Vec<&'a str> {
    result_lines(index).filter(|line| page.contains(line)).collect()
}

#[test]
fn the_committed_index_is_its_json() {
    let generated = index_markdown(&docs()).unwrap_or_else(|e| panic!("{e}"));
    let committed = std::fs::read_to_string(docs().join("index.md")).expect("docs/experiments/index.md");
    if generated != committed {
        let line = generated.lines().zip(committed.lines()).position(|(a, b)| a != b);
        panic!(
            "docs/experiments/index.md differs from what its JSON gives (first at line {}): regenerate it with \
             'rtgi experiment index --out docs/experiments', never by hand",
            line.map_or("the end".to_owned(), |l| (l + 1).to_string())
        );
    }
}

#[test]
fn the_readme_and_the_guide_link_to_the_results_and_copy_none() {
    let index = std::fs::read_to_string(docs().join("index.md")).expect("docs/experiments/index.md");
    assert!(result_lines(&index).count() > 30, "the index's results were not found: has its form changed?");
    let readme = std::fs::read_to_string(workspace_root().join("README.md")).expect("README.md");
    assert!(readme.contains("](docs/experiments/index.md)"), "the README does not link to docs/experiments/index.md");
    for page in hand_written_pages() {
        let text = std::fs::read_to_string(&page).unwrap_or_else(|e| panic!("{}: {e}", page.display()));
        let copied = copied_results(&text, &index);
        assert!(
            copied.is_empty(),
            "{} repeats results of docs/experiments/index.md, which is their only home (it is regenerated from \
             the JSON, a copy is not): link to it instead of\n{}",
            page.display(),
            copied.join("\n")
        );
    }
}

#[test]
fn a_result_copied_into_a_page_is_caught() {
    let index = std::fs::read_to_string(docs().join("index.md")).expect("docs/experiments/index.md");
    let finding = index.lines().find(|l| l.starts_with("- ") && l.contains("Mann–Whitney")).expect("a finding");
    let provenance = index.lines().find(|l| l.starts_with("Measured ")).expect("the provenance line");
    let row = index.lines().find(|l| l.starts_with("| ") && l.contains("Embree |")).expect("a row against Embree");
    let page = "# A page\n\nSee [the report](../experiments/index.md).\n";
    assert_eq!(copied_results(page, &index), Vec::<&str>::new());
    for copy in [finding, provenance, row] {
        let planted = format!("{page}\n{copy}\n");
        assert_eq!(copied_results(&planted, &index), vec![copy.trim()], "not caught: {copy}");
    }
}

/// Copies the committed reports into a scratch folder.
fn copy_reports(to: &Path) {
    fn copy(from: &Path, to: &Path) {
        std::fs::create_dir_all(to).unwrap();
        for entry in std::fs::read_dir(from).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap();
            if path.is_dir() && !name.to_string_lossy().starts_with('.') {
                copy(&path, &to.join(name));
            } else if path.extension().is_some_and(|e| e == "json") {
                std::fs::copy(&path, to.join(name)).unwrap();
            }
        }
    }
    copy(&docs(), to);
}

#[test]
fn a_figure_edited_by_hand_is_caught() {
    let dir = scratch_dir("experiment-index-edited");
    copy_reports(&dir);
    let generated = index_markdown(&dir).unwrap();
    // Change the first digit of the first finding, as a hand edit would.
    let finding = generated.lines().position(|l| l.starts_with("- ")).expect("findings");
    let mut lines: Vec<String> = generated.lines().map(String::from).collect();
    let digit = lines[finding].find(|c: char| c.is_ascii_digit()).expect("a figure in the finding");
    let replaced = if &lines[finding][digit..digit + 1] == "7" { "8" } else { "7" };
    lines[finding].replace_range(digit..digit + 1, replaced);
    let edited = lines.join("\n") + "\n";
    assert_ne!(edited, index_markdown(&dir).unwrap(), "the regenerated index differs from the edited one");
}

#[test]
fn reports_of_different_code_are_refused_by_name() {
    let dir = scratch_dir("experiment-index-mixed");
    copy_reports(&dir);
    let victim = dir.join("scaling/scaling.json");
    let mut json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&victim).unwrap()).unwrap();
    json["build"]["commit"] = "0123456789abcdef0123456789abcdef01234567".into();
    std::fs::write(&victim, serde_json::to_string(&json).unwrap()).unwrap();
    let error = index_markdown(&dir).expect_err("mixed commits are refused").to_string();
    assert!(error.contains("0123456789abcdef") && error.contains("scaling/scaling.json"), "{error}");
    assert!(error.contains("different code"), "{error}");
}

/// Every report's JSON under `docs/experiments` (a knob's folder holds
/// its report, or a folder per scene), with its path.
fn committed_reports() -> Vec<(PathBuf, serde_json::Value)> {
    fn walk(folder: &Path, found: &mut Vec<(PathBuf, serde_json::Value)>) {
        for entry in std::fs::read_dir(folder).expect("a report folder").flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, found);
            } else if path.extension().is_some_and(|e| e == "json") {
                let json: serde_json::Value =
                    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).expect("valid JSON");
                if json.get("knob").is_some() {
                    found.push((path, json));
                }
            }
        }
    }
    let mut found = Vec::new();
    walk(&docs(), &mut found);
    assert!(found.len() >= 19, "the committed reports: {}", found.len());
    found
}

/// Every equal-time entry records its time and the budget's render timed
/// alongside it, and took the budget within ±5%: an equal-time claim is
/// never made of renders that were not. (A panel whose entry misses says
/// so in its caption, which is checked too, but the committed report has none.)
#[test]
fn every_equal_time_entry_took_its_budget_within_five_percent() {
    let mut entries = 0;
    for (path, report) in committed_reports() {
        let findings = report["findings"].to_string();
        for panel in report["panels"].as_array().into_iter().flatten() {
            if panel["budget_ms"].as_f64().is_none() {
                continue;
            }
            for entry in panel["entries"].as_array().expect("the panel's entries") {
                let share = entry["budget_share"].as_f64().expect("each entry's share of the budget");
                let time = entry["time_ms"].as_f64().unwrap();
                let budget = entry["budget_ms"].as_f64().expect("the budget's render timed alongside each entry");
                assert!((time / budget - share).abs() < 1e-9, "{}: {entry}", path.display());
                let label = entry["label"].as_str().unwrap();
                assert!(
                    (0.95..=1.05).contains(&share),
                    "{}, {}: {label} took {time} ms against a {budget} ms budget",
                    path.display(),
                    panel["file"]
                );
                let said = format!("{:+.1}% of the budget", 100.0 * (share - 1.0));
                assert!(findings.contains(label) && findings.contains(&said), "{}: {label}: {said}", path.display());
                entries += 1;
            }
        }
    }
    assert!(entries >= 20, "equal-time entries checked: {entries}");
}

#[test]
fn no_biased_configuration_is_given_an_efficiency() {
    let mut biased = 0;
    for (path, report) in committed_reports() {
        for series in report["series"].as_array().into_iter().flatten() {
            for point in series["points"].as_array().into_iter().flatten() {
                if point["values"]["biased"].as_f64() == Some(1.0) {
                    biased += 1;
                    assert!(point["values"].get("efficiency").is_none(), "{}: {point}", path.display());
                }
            }
        }
        // A finding names an efficiency ratio only through the verdict
        // module, which refuses biased configurations: "biased" and "× the
        // efficiency" never meet in one comparison.
        for finding in report["findings"].as_array().into_iter().flatten() {
            let finding = finding.as_str().unwrap();
            for clause in finding.split("; ") {
                assert!(
                    !(clause.contains("biased:") && clause.contains("× the efficiency")),
                    "{}: {finding}",
                    path.display()
                );
            }
        }
    }
    assert!(biased > 0, "the report measures biased configurations (clamps, the denoiser, shallow depths)");
}
