//! `docs/counters.md` is written by `benches/counters.sh` from what it
//! counted: each row's figures per ray must be the differences of the
//! cachegrind totals listed under the table (rays traced twice less rays
//! traced once, divided by the rays), its time the median of the listed
//! runs, and its instructions per node the quotient of two of its cells. A
//! figure edited by hand (or a count dropped) fails here.

use rtgi_tests::workspace_root;

/// The median as the script takes it: the middle value, or the lower of
/// the two middle ones.
fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len().div_ceil(2) - 1]
}

/// A figure the script printed with one decimal from `exact`: within half
/// a unit of the last digit, whichever way a tie was rounded.
fn agrees(cell: &str, exact: f64) -> bool {
    cell.parse::<f64>().is_ok_and(|shown| (shown - exact).abs() <= 0.05 + 1e-9)
}

/// The counts of one line under the table.
struct Counts<'a> {
    id: &'a str,
    accel: &'a str,
    rays: f64,
    once: Vec<f64>,
    twice: Vec<f64>,
    /// Nodes and triangle tests per ray, or `None` for a structure that reports neither.
    work: Option<(&'a str, &'a str)>,
    times: Vec<f64>,
}

fn parse_line(line: &str) -> Option<Counts<'_>> {
    let numbers = |text: &str| text.split_whitespace().map(str::parse).collect::<Result<Vec<f64>, _>>().ok();
    let (head, rest) = line.split_once(" rays: ")?;
    let (id, accel) = head.split_once(' ')?;
    let (rays, rest) = rest.split_once(" once: ")?;
    let (once, rest) = rest.split_once(" twice: ")?;
    let (twice, rest) = rest.split_once(" work: ")?;
    let (work, times) = rest.split_once(" ns: ")?;
    let (nodes, tests) = work.split_once(' ')?;
    let work = (nodes != "—").then_some((nodes, tests));
    let (once, twice, times) = (numbers(once)?, numbers(twice)?, numbers(times)?);
    (once.len() == 4 && twice.len() == 4 && !times.is_empty()).then_some(Counts {
        id,
        accel,
        rays: rays.parse().ok()?,
        once,
        twice,
        work,
        times,
    })
}

/// Every way the table disagrees with the counts, one line each.
fn disagreements(doc: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let block = doc.split("```text\n").nth(1).and_then(|block| block.split("```").next()).unwrap_or_default();
    let mut counts = Vec::new();
    for line in block.lines() {
        match parse_line(line) {
            Some(c) => counts.push(c),
            None => problems.push(format!("an unreadable line of counts: {line}")),
        }
    }
    if counts.is_empty() {
        problems.push("no counts listed".to_string());
    }
    let rows: Vec<Vec<&str>> = doc
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| rays |"))
        .map(|l| l.trim_matches('|').split(" | ").map(str::trim).collect())
        .collect();
    for c in &counts {
        if !rows.iter().any(|row| row.len() > 1 && row[0] == c.id && row[1] == c.accel) {
            problems.push(format!("{} {}: counts without a row", c.id, c.accel));
        }
    }
    for row in &rows {
        let &[id, accel, ref per_ray @ .., time, nodes, tests, per_node] = row.as_slice() else {
            problems.push(format!("a row without 10 cells: {row:?}"));
            continue;
        };
        if per_ray.len() != 4 {
            problems.push(format!("a row without 10 cells: {row:?}"));
            continue;
        }
        let Some(c) = counts.iter().find(|c| c.id == id && c.accel == accel) else {
            problems.push(format!("{id} {accel}: no counts"));
            continue;
        };
        for (k, cell) in per_ray.iter().enumerate() {
            let exact = (c.twice[k] - c.once[k]) / c.rays;
            if !agrees(cell, exact) {
                problems.push(format!("{id} {accel}: column {} is {cell}, the counts give {exact:.2}", k + 3));
            }
        }
        let median = format!("{:.2}", median(&c.times));
        if time != median {
            problems.push(format!("{id} {accel}: the time is {time}, the runs' median {median}"));
        }
        match c.work {
            None => {
                if (nodes, tests, per_node) != ("—", "—", "—") {
                    problems.push(format!("{id} {accel}: no work counted, yet {nodes}, {tests}, {per_node}"));
                }
            }
            Some((n, t)) => {
                if (nodes, tests) != (n, t) {
                    problems.push(format!("{id} {accel}: nodes and tests are {nodes}, {tests}; counted {n}, {t}"));
                }
                let quotient = per_ray[0].parse::<f64>().ok().zip(n.parse::<f64>().ok()).map(|(i, n)| i / n);
                if !quotient.is_some_and(|q| agrees(per_node, q)) {
                    problems
                        .push(format!("{id} {accel}: instructions per node {per_node}, the cells give {quotient:?}"));
                }
            }
        }
    }
    problems
}

#[test]
fn the_counters_table_is_what_was_counted() {
    let path = workspace_root().join("docs/counters.md");
    let doc = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(doc.contains("Measured from "), "{}: no line saying when and where it was measured", path.display());
    let problems = disagreements(&doc);
    assert!(problems.is_empty(), "{} disagrees with its counts:\n{}", path.display(), problems.join("\n"));
}

#[test]
fn a_count_changed_by_hand_is_caught() {
    let doc = "\
| rays | structure | instructions / ray | L1D misses / ray | LL misses / ray | mispredicted branches / ray | ns / ray (native) | nodes / ray | triangle tests / ray | instructions / node |
|---|---|---:|---:|---:|---:|---:|---:|---:|---:|
| r | ours | 1000.0 | 20.0 | 1.5 | 3.0 | 250.00 | 10.00 | 16.00 | 100.0 |
| r | peer | 800.0 | 10.0 | 1.0 | 2.5 | 200.00 | — | — | — |

```text
r ours rays: 100 once: 500000 3000 200 400 twice: 600000 5000 350 700 work: 10.00 16.00 ns: 240.00 250.00 260.00
r peer rays: 100 once: 400000 2000 100 300 twice: 480000 3000 200 550 work: — — ns: 200.00 190.00 210.00
```
";
    assert_eq!(disagreements(doc), Vec::<String>::new());
    for (from, to) in [
        ("| 1000.0 |", "| 990.0 |"),                      // instructions per ray
        ("| 1.5 | 3.0 |", "| 1.5 | 2.0 |"),               // mispredictions
        ("240.00 250.00 260.00", "240.00 270.00 260.00"), // a different median
        ("| 100.0 |", "| 90.0 |"),                        // instructions per node
        ("| 200.00 | — |", "| 200.00 | 5.00 |"),          // work Embree does not report
        (
            "r peer rays: 100 once: 400000 2000 100 300 twice: 480000 3000 200 550 work: — — ns: 200.00 190.00 210.00\n",
            "",
        ),
    ] {
        let changed = doc.replacen(from, to, 1);
        assert_ne!(changed, doc, "{from}");
        assert!(!disagreements(&changed).is_empty(), "not caught: {from} -> {to}");
    }
}
