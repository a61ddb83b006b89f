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
                if let (Some(time), Some(error)) = (point.time, point.error) {
                    found.push(Configuration {
                        knob: report.knob.clone(),
                        label: format!("{} {}", series.name, point.label),
                        time,
                        error: (error.rmse, error.rmse_min, error.rmse_max),
                    });
                }
            }
        }
    }
    found
}

/// The indices of the configurations on the Pareto front, fastest first: a
/// configuration is on it unless another is no slower and no worse, and
/// better in one of the two (medians compared). Equal configurations are
/// all on it.
pub fn front(configurations: &[Configuration]) -> Vec<usize> {
    let dominates = |a: &Configuration, b: &Configuration| {
        let (ta, tb, ea, eb) = (a.time.median_ms, b.time.median_ms, a.error.0, b.error.0);
        ta <= tb && ea <= eb && (ta < tb || ea < eb)
    };
    let mut on: Vec<usize> = (0..configurations.len())
        .filter(|&i| !configurations.iter().any(|other| dominates(other, &configurations[i])))
        .collect();
    on.sort_by(|&a, &b| configurations[a].time.median_ms.total_cmp(&configurations[b].time.median_ms));
    on
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
                .map(|c| (c.time, c.error.0, c.error.1, c.error.2))
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

    fn config(time: f64, error: f64) -> Configuration {
        Configuration {
            knob: "k".into(),
            label: format!("{time}/{error}"),
            time: Timing { median_ms: time, min_ms: time, max_ms: time, runs: 1 },
            error: (error, error, error),
        }
    }

    #[test]
    fn the_front_keeps_what_nothing_beats_in_both() {
        let c = [config(1.0, 10.0), config(2.0, 5.0), config(3.0, 6.0), config(4.0, 1.0), config(5.0, 1.0)];
        assert_eq!(front(&c), vec![0, 1, 3]);
        // A single point is its own front; duplicates are all on it.
        assert_eq!(front(&[config(1.0, 1.0)]), vec![0]);
        assert_eq!(front(&[config(1.0, 1.0), config(1.0, 1.0)]), vec![0, 1]);
        // A chain where each is dominated by the one before leaves only the first.
        let chain = [config(1.0, 1.0), config(2.0, 2.0), config(3.0, 3.0)];
        assert_eq!(front(&chain), vec![0]);
        assert!(front(&[]).is_empty());
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
