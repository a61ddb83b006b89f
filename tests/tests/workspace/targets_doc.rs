//! `docs/targets.md` is written by `benches/targets.sh` from what it
//! measured: its table must be the medians of the runs listed under it,
//! their ratios, and the verdicts those ratios give. A figure edited by hand
//! (or a run dropped) fails here.

use rtgi_tests::workspace_root;

/// The median as the script takes it: the middle value, or the lower of
/// the two middle ones.
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len().div_ceil(2) - 1]
}

fn numbers(text: &str) -> Result<Vec<f64>, String> {
    text.split_whitespace().map(|v| v.parse().map_err(|_| format!("'{v}' is not a number"))).collect()
}

/// Every way the table disagrees with the runs, one line each.
fn disagreements(doc: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let runs: Vec<(&str, &str, &str)> = doc
        .split("```text\n")
        .nth(1)
        .and_then(|block| block.split("```").next())
        .unwrap_or_default()
        .lines()
        .filter_map(|line| {
            let (id, rest) = line.split_once(" ours: ")?;
            let (ours, against) = rest.split_once(" against:")?;
            Some((id, ours, against))
        })
        .collect();
    if runs.is_empty() {
        problems.push("no runs listed".to_string());
    }
    let rows: Vec<Vec<&str>> = doc
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| id |"))
        .map(|l| l.trim_matches('|').split(" | ").map(str::trim).collect())
        .collect();
    for &(id, _, _) in &runs {
        if !rows.iter().any(|row| row[0] == id) {
            problems.push(format!("{id}: runs without a row"));
        }
    }
    for row in &rows {
        let [id, _scene, _measure, ours_cell, against_cell, ratio_cell, target, met] = row[..] else {
            problems.push(format!("a row without 8 cells: {row:?}"));
            continue;
        };
        let Some(&(_, ours, against)) = runs.iter().find(|r| r.0 == id) else {
            problems.push(format!("{id}: no runs"));
            continue;
        };
        let (ours, against) = match (numbers(ours), numbers(against)) {
            (Ok(o), Ok(a)) if !o.is_empty() => (o, a),
            _ => {
                problems.push(format!("{id}: unreadable runs"));
                continue;
            }
        };
        let ours_median = format!("{:.2}", median(&ours));
        if ours_cell != ours_median {
            problems.push(format!("{id}: ours is {ours_cell}, the runs' median {ours_median}"));
        }
        let ratio = if against.is_empty() {
            if (against_cell, ratio_cell) != ("—", "—") {
                problems.push(format!("{id}: no runs to compare with, yet '{against_cell}' and '{ratio_cell}'"));
            }
            None
        } else {
            let against_median = format!("{:.2} (", median(&against));
            if !against_cell.starts_with(&against_median) {
                problems.push(format!("{id}: against is {against_cell}, the runs' median {against_median}…)"));
            }
            let ratio = format!("{:.2}×", median(&ours) / median(&against));
            if ratio_cell != ratio {
                problems.push(format!("{id}: the ratio is {ratio_cell}, the medians' {ratio}"));
            }
            Some(ratio)
        };
        // A row for comparison only has no target and no verdict.
        if target == "—" {
            if met != "—" {
                problems.push(format!("{id}: says '{met}' without a target"));
            }
            continue;
        }
        // The verdict, from the rounded figures as the script decides it.
        let (at_least, bound) = match target.split_once(' ') {
            Some(("≥", bound)) => (true, bound),
            Some(("≤", bound)) => (false, bound),
            _ => {
                problems.push(format!("{id}: unreadable target '{target}'"));
                continue;
            }
        };
        let (value, bound) = match bound.strip_suffix('×') {
            Some(bound) => (ratio.as_deref().and_then(|r| r.strip_suffix('×')), bound),
            None => (Some(ours_median.as_str()), bound),
        };
        let (Some(Ok(value)), Ok(bound)) = (value.map(str::parse::<f64>), bound.parse::<f64>()) else {
            problems.push(format!("{id}: the target '{target}' has nothing to compare"));
            continue;
        };
        let expected = if (at_least && value >= bound) || (!at_least && value <= bound) { "**met**" } else { "no" };
        if met != expected {
            problems.push(format!("{id}: says '{met}' for {value} against {target}"));
        }
    }
    problems
}

#[test]
fn the_targets_table_is_what_its_runs_measured() {
    let path = workspace_root().join("docs/targets.md");
    let doc = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(doc.contains("Measured from "), "{}: no line saying when and where it was measured", path.display());
    let problems = disagreements(&doc);
    assert!(problems.is_empty(), "{} disagrees with its runs:\n{}", path.display(), problems.join("\n"));
}

#[test]
fn a_figure_changed_by_hand_is_caught() {
    let doc = "\
| id | scene | measure | ours | against | ours / against | target | met |
|---|---|---|---:|---:|---:|---|---|
| a | s | m | 2.00 | 1.00 (x) | 2.00× | ≥ 1.5× | **met** |
| b | s | m | 4.00 | — | — | ≥ 5 | no |
| c | s | m | 1.00 | 2.00 (y) | 0.50× | — | — |

```text
a ours: 1.9 2.0 2.1 against: 1.0 1.1 0.9
b ours: 4.0 3.0 5.0 against: 
c ours: 1.0 against: 2.0
```
";
    assert_eq!(disagreements(doc), Vec::<String>::new());
    for (from, to) in [
        ("1.9 2.0 2.1", "1.9 2.2 2.1"),                           // a different median
        ("| 2.00× |", "| 2.10× |"),                               // a different ratio
        ("| **met** |", "| no |"),                                // the wrong verdict
        ("| ≥ 5 | no |", "| ≥ 3 | no |"),                         // a target that is met, said not to be
        ("b ours: 4.0 3.0 5.0 against: \n", ""),                  // a row without runs
        ("| 0.50× | — | — |", "| 0.50× | — | **met** |"),         // a verdict without a target
        ("c ours: 1.0 against: 2.0", "c ours: 1.0 against: 2.5"), // its ratio is checked too
    ] {
        let changed = doc.replacen(from, to, 1);
        assert_ne!(changed, doc, "{from}");
        assert!(!disagreements(&changed).is_empty(), "not caught: {from} -> {to}");
    }
}
