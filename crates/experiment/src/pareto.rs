//! The trade-off of a scene on one plot: every configuration of every knob
//! measured on it, error against time, with the Pareto front marked (the
//! configurations no other beats in both time and error).
//!
//! Made from the reports' JSON alone, as the index is, so that it is
//! regenerated with it. Only configurations measured against the scene's
//! one converged reference take part (points marked
//! [`crate::report::OWN_REFERENCE`] are left out).

use crate::plot::{Corner, Curve, Plot};
use crate::report::{OWN_REFERENCE, Report};
use crate::stats::Timing;

/// One measured configuration: which knob, its setting, time and error.
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// The knob whose report measured it.
    pub knob: String,
    /// The configuration, as its report names it (series and point).
    pub label: String,
    /// Its time: median, min and max.
    pub time: Timing,
    /// Its RMSE over the seeds, and the smallest and largest of one seed.
    pub error: (f64, f64, f64),
    /// The MSE of each seed's render: what the rank test compares.
    pub seed_mse: Vec<f64>,
    /// What its bias is, where the measurement resolves one.
    pub bias: Option<String>,
}

/// The configurations of `reports` that rendered with an error against their reference.
pub fn configurations<'a>(reports: impl IntoIterator<Item = &'a Report>) -> Vec<Configuration> {
    let mut found = Vec::new();
    for report in reports {
        for series in &report.series {
            for point in &series.points {
                if point.values.contains_key(OWN_REFERENCE) {
                    continue;
                }
                if let (Some(time), Some(error)) = (point.time.clone(), point.error.clone()) {
                    found.push(Configuration {
                        knob: report.knob.clone(),
                        label: format!("{} {}", series.name, point.label),
                        time,
                        error: (error.rmse, error.rmse_min, error.rmse_max),
                        bias: error.bias_resolved().then(|| crate::verdict::describe_bias(&error)),
                        seed_mse: if error.seed_mse.is_empty() { vec![error.mse()] } else { error.seed_mse },
                    });
                }
            }
        }
    }
    found
}

/// The indices of the configurations on the Pareto front, fastest first.
///
/// Dominance is decided beyond the resolution of the measurement
/// ([`crate::verdict`]'s rank test on the runs' times and the seeds'
/// errors), not on medians: `a` dominates `b` when it is resolved faster or
/// resolved more accurate, and not resolved worse in the other. A
/// configuration the measurement cannot tell from a front member in either
/// is on the front too, but tied: [`ties`] groups them.
pub fn front(configurations: &[Configuration]) -> Vec<usize> {
    let mut on: Vec<usize> = (0..configurations.len())
        .filter(|&i| !configurations.iter().any(|other| dominates(other, &configurations[i])))
        .collect();
    on.sort_by(|&a, &b| configurations[a].time.median_ms.total_cmp(&configurations[b].time.median_ms));
    on
}

/// Whether `a` beats `b` beyond the resolution in time or error without
/// being beaten beyond it in the other.
pub fn dominates(a: &Configuration, b: &Configuration) -> bool {
    use crate::verdict::resolved_lower;
    let (ta, tb) = (a.time.samples(), b.time.samples());
    let faster = resolved_lower(&ta, &tb);
    let slower = resolved_lower(&tb, &ta);
    let better = resolved_lower(&a.seed_mse, &b.seed_mse);
    let worse = resolved_lower(&b.seed_mse, &a.seed_mse);
    (faster && !worse) || (better && !slower)
}

/// The front's members grouped by ties: members whose times and errors the
/// measurement does not tell apart share a group. Groups follow the front's order.
pub fn ties(configurations: &[Configuration], front: &[usize]) -> Vec<Vec<usize>> {
    use crate::verdict::RankComparison;
    let apart = |a: &Configuration, b: &Configuration| {
        RankComparison::of(&a.time.samples(), &b.time.samples()).resolved()
            || RankComparison::of(&a.seed_mse, &b.seed_mse).resolved()
    };
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for &i in front {
        match groups.iter_mut().find(|g| g.iter().all(|&j| !apart(&configurations[i], &configurations[j]))) {
            Some(group) => group.push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
}

/// The front in words, fastest first: each member, its bias where
/// resolved, and which members the measurement does not tell apart.
pub fn describe_front(configurations: &[Configuration]) -> String {
    let on = front(configurations);
    let groups = ties(configurations, &on);
    let member = |i: usize| {
        let c = &configurations[i];
        match &c.bias {
            Some(bias) => format!("{} ({bias})", c.label),
            None => c.label.clone(),
        }
    };
    let described: Vec<String> = groups
        .iter()
        .map(|g| {
            if g.len() == 1 {
                member(g[0])
            } else {
                format!("[tied: {}]", g.iter().map(|&i| member(i)).collect::<Vec<_>>().join("; "))
            }
        })
        .collect();
    let biased = on.iter().filter(|&&i| configurations[i].bias.is_some()).count();
    format!(
        "{} configurations in {} groups the measurement tells apart, {biased} of them biased: {}",
        on.len(),
        groups.len(),
        described.join("; ")
    )
}

/// The scene's Pareto plot: each knob's configurations as markers with
/// their spread in time and error, and the front as a step line.
pub fn plot(file: &str, configurations: &[Configuration]) -> Plot {
    let mut knobs: Vec<&str> = configurations.iter().map(|c| c.knob.as_str()).collect();
    knobs.dedup();
    knobs.sort_unstable();
    knobs.dedup();
    let mut curves: Vec<Curve> = knobs
        .iter()
        .map(|knob| {
            let points: Vec<(Timing, f64, f64, f64)> = configurations
                .iter()
                .filter(|c| c.knob == *knob)
                .map(|c| (c.time.clone(), c.error.0, c.error.1, c.error.2))
                .collect();
            Curve {
                markers_only: true,
                ..Curve::error_against_time(format!("{knob} ({} configurations)", points.len()), &points)
            }
        })
        .collect();
    let on = front(configurations);
    // A step line: from each front member along its error to the next one's time.
    let mut steps = Vec::new();
    for (k, &i) in on.iter().enumerate() {
        let (t, e) = (configurations[i].time.median_ms, configurations[i].error.0);
        steps.push((t, e));
        if let Some(&next) = on.get(k + 1) {
            steps.push((configurations[next].time.median_ms, e));
        }
    }
    curves.push(Curve::guide(format!("Pareto front ({} configurations)", on.len()), steps));
    Plot {
        file: file.to_owned(),
        title: "Every configuration measured on the scene: RMSE against render time".to_owned(),
        x_label: "render time (ms, median; bars: min–max)".to_owned(),
        y_label: "RMSE of linear radiance (radiance; bars: seeds' min–max)".to_owned(),
        log_x: true,
        log_y: true,
        curves,
        legend: Corner::UpperRight,
        y_range: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Five runs and five seeds about `time` and `error`, spread by ±`spread` of each.
    fn spread_config(time: f64, error: f64, spread: f64) -> Configuration {
        let jitter = [-1.0, -0.5, 0.0, 0.5, 1.0];
        let runs: Vec<f64> = jitter.iter().map(|j| time * (1.0 + spread * j)).collect();
        let seed_mse: Vec<f64> = jitter.iter().rev().map(|j| (error * (1.0 + spread * j)).powi(2)).collect();
        Configuration {
            knob: "k".into(),
            label: format!("{time}/{error}"),
            time: Timing::of(&runs),
            error: (error, error * (1.0 - spread), error * (1.0 + spread)),
            seed_mse,
            bias: None,
        }
    }

    fn config(time: f64, error: f64) -> Configuration {
        spread_config(time, error, 0.01)
    }

    #[test]
    fn the_front_keeps_what_nothing_beats_in_both() {
        let c = [config(1.0, 10.0), config(2.0, 5.0), config(3.0, 6.0), config(4.0, 1.0), config(5.0, 1.0)];
        // (5, 1) is resolved slower than (4, 1) and its error is not resolved better.
        assert_eq!(front(&c), vec![0, 1, 3]);
        assert_eq!(front(&[config(1.0, 1.0)]), vec![0]);
        // A chain where each is dominated by the one before leaves only the first.
        let chain = [config(1.0, 1.0), config(2.0, 2.0), config(3.0, 3.0)];
        assert_eq!(front(&chain), vec![0]);
        assert!(front(&[]).is_empty());
    }

    #[test]
    fn dominance_needs_a_resolved_difference() {
        // Medians 2% apart inside a ±20% spread: neither dominates, both
        // stay on the front, tied in one group.
        let (a, b) = (spread_config(1.0, 1.0, 0.2), spread_config(1.02, 1.02, 0.2));
        assert!(!dominates(&a, &b) && !dominates(&b, &a));
        assert_eq!(front(&[a.clone(), b.clone()]), vec![0, 1]);
        assert_eq!(ties(&[a.clone(), b.clone()], &[0, 1]), vec![vec![0, 1]]);
        // Twice as fast at an error the seeds do not tell apart: dominates.
        let (fast, slow) = (spread_config(1.0, 1.0, 0.05), spread_config(2.0, 1.01, 0.05));
        assert!(dominates(&fast, &slow) && !dominates(&slow, &fast));
        assert_eq!(front(&[slow, fast]), vec![1]);
        // Faster but resolved worse: a trade-off, both on the front, in two groups.
        let (quick, accurate) = (spread_config(1.0, 3.0, 0.05), spread_config(2.0, 1.0, 0.05));
        assert_eq!(front(&[quick.clone(), accurate.clone()]), vec![0, 1]);
        assert_eq!(ties(&[quick, accurate], &[0, 1]).len(), 2);
    }

    #[test]
    fn the_plot_marks_the_front_as_steps() {
        let c = [config(1.0, 10.0), config(2.0, 5.0), config(3.0, 6.0)];
        let plot = plot("p.svg", &c);
        let front = plot.curves.last().unwrap();
        assert!(front.guide && front.label.contains("2 configurations"), "{front:?}");
        assert_eq!(front.points, vec![(1.0, 10.0), (2.0, 10.0), (2.0, 5.0)]);
    }
}
