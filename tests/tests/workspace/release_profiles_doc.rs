//! `docs/release-profiles.md` is written by `benches/release-profiles.sh`
//! from what it measured: each row's cells must be the runs listed under
//! the table (the build times as measured, the rates' medians, minima and
//! maxima, and their ratios to the shipped profile's), the shipped row must
//! be the profile in `Cargo.toml`. A figure typed by hand, or a profile
//! changed without measuring it again, fails here. (The table has no copy
//! elsewhere: the README and the guide link to the document.)

use rtgi_tests::workspace_root;

/// The median as the script takes it: the middle value, or the lower of
/// the two middle ones.
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len().div_ceil(2) - 1]
}

fn numbers(text: &str) -> Vec<f64> {
    text.split_whitespace().map(|v| v.parse().unwrap_or_else(|_| panic!("'{v}' is not a number"))).collect()
}

/// A run line: `LTO:CGU build: CLEAN REBUILD trace: R R R render: R R R`.
struct Runs {
    config: String,
    builds: Vec<f64>,
    trace: Vec<f64>,
    render: Vec<f64>,
}

fn runs(doc: &str) -> Vec<Runs> {
    let block = doc.split("```text\n").nth(1).and_then(|b| b.split("```").next()).expect("the runs' block");
    block
        .lines()
        .map(|line| {
            let (config, rest) = line.split_once(" build: ").unwrap_or_else(|| panic!("a run line: {line}"));
            let (builds, rest) = rest.split_once(" trace: ").expect("trace runs");
            let (trace, render) = rest.split_once(" render: ").expect("render runs");
            Runs { config: config.to_owned(), builds: numbers(builds), trace: numbers(trace), render: numbers(render) }
        })
        .collect()
}

/// The table's lines: the header, the rule and a row per configuration.
fn table(doc: &str) -> Vec<&str> {
    doc.lines().filter(|l| l.starts_with('|')).collect()
}

/// `median (min–max)` of `runs`, as the script prints it.
fn cell(runs: &[f64]) -> String {
    let (min, max) = runs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    format!("{:.2} ({min:.2}–{max:.2})", median(runs))
}

/// The shipped release profile's `lto:codegen-units`, from Cargo.toml.
fn shipped_profile() -> String {
    let manifest = std::fs::read_to_string(workspace_root().join("Cargo.toml")).unwrap();
    let release = manifest.split("[profile.release]").nth(1).expect("a release profile").split("\n[").next().unwrap();
    let value = |key: &str| {
        release
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key} = ")))
            .unwrap_or_else(|| panic!("the release profile sets no {key}"))
            .trim_matches('"')
            .to_owned()
    };
    format!("{}:{}", value("lto"), value("codegen-units"))
}

#[test]
fn the_table_is_the_runs_under_it() {
    let doc = std::fs::read_to_string(workspace_root().join("docs/release-profiles.md"))
        .expect("docs/release-profiles.md (benches/release-profiles.sh writes it)");
    let runs = runs(&doc);
    let shipped = shipped_profile();
    let reference = runs.iter().find(|r| r.config == shipped).unwrap_or_else(|| {
        panic!("no runs of the shipped profile {shipped}: measure it again with benches/release-profiles.sh")
    });
    let (trace_reference, render_reference) = (median(&reference.trace), median(&reference.render));
    let rows = table(&doc);
    assert_eq!(rows.len(), runs.len() + 2, "a row per configuration: {rows:#?}");
    for (row, run) in rows[2..].iter().zip(&runs) {
        let (lto, cgu) = run.config.split_once(':').expect("LTO:CGU");
        let name = if run.config == shipped { format!("{lto} (shipped)") } else { lto.to_owned() };
        let [clean, rebuild] = run.builds[..] else { panic!("{}: two build times", run.config) };
        let expected = format!(
            "| {name} | {cgu} | {clean:.1} | {rebuild:.1} | {} | {:.2}× | {} | {:.2}× |",
            cell(&run.trace),
            median(&run.trace) / trace_reference,
            cell(&run.render),
            median(&run.render) / render_reference,
        );
        assert_eq!(*row, expected, "the row of {} is not its runs", run.config);
    }
}
