//! `direct`: light, BSDF and multiple importance sampling of direct light,
//! compared at equal time on three scenes built for it (in `scenes/`,
//! compiled in), one where each strategy should shine: a small bright
//! light, a light that fills the ceiling, and glossy metals.
//!
//! Only direct light is rendered (the `direct` integrator), so the
//! strategies' differences are not drowned in the noise of bounces. Each
//! scene's reference is converged with MIS, which is unbiased like the
//! other two: all three converge to it and differ only in noise, so the
//! error they reach in a given time ranks them.

use std::path::Path;

use rtgi_accel::AccelKind;
use rtgi_render::{DirectStrategy, EffectOverrides, Integrator, RenderSettings};
use rtgi_scene::Scene;
use rtgi_scene::description::Description;

use crate::plot::{Curve, Plot};
use crate::reference::reference;
use crate::report::{Report, Series, Table, format_ms, format_number, measurement_cells, measurement_header};
use crate::runner::{Budget, Candidate, add_equal_time_panel, measure};
use crate::verdict::compare;
use crate::{ExperimentError, Options, Steps, Subject};

/// A scene of the experiment, as compiled in.
struct DirectScene {
    name: &'static str,
    /// What the scene is built to show.
    case: &'static str,
    description: &'static str,
    obj: &'static str,
    mtl: &'static str,
}

macro_rules! direct_scene {
    ($name:literal, $case:literal) => {
        DirectScene {
            name: $name,
            case: $case,
            description: include_str!(concat!("../../../../scenes/direct-", $name, ".toml")),
            obj: include_str!(concat!("../../../../scenes/direct-", $name, "/direct-", $name, ".obj")),
            mtl: include_str!(concat!("../../../../scenes/direct-", $name, "/direct-", $name, ".mtl")),
        }
    };
}

const SCENES: [DirectScene; 3] = [
    direct_scene!("small-light", "a small bright light over a diffuse floor"),
    direct_scene!("large-light", "a room lit by its whole ceiling"),
    direct_scene!("glossy", "glossy metals and a diffuse wall under a middling light"),
];

impl DirectScene {
    fn file(&self) -> String {
        format!("scenes/direct-{}.toml", self.name)
    }

    /// The scene ready to render, with the settings of `base` that the knob does not decide.
    fn subject(&self, base: &RenderSettings) -> Result<Subject, ExperimentError> {
        let unusable =
            |e: rtgi_scene::SceneError| ExperimentError::Unsuitable(format!("built-in {}: {e}", self.file()));
        let description = Description::parse(self.description, Path::new(&self.file())).map_err(unusable)?;
        let obj = format!("scenes/direct-{0}/direct-{0}.obj", self.name);
        let scene: Scene = rtgi_scene::obj::load_from_text(self.obj, self.mtl, &obj).map_err(unusable)?;
        let camera = description.camera().ok_or_else(|| {
            ExperimentError::Unsuitable(format!("built-in {}: the description has no camera", self.file()))
        })?;
        let kind = AccelKind::Bvh8;
        let accel = kind
            .try_build(&scene.triangle_positions(), &kind.default_params())
            .map_err(|e| ExperimentError::Build(e.to_string()))?;
        // The scene's own lights, nothing forced: the subject's lighting options are for its own scene.
        let settings = RenderSettings {
            integrator: Integrator::Direct,
            environment: None,
            effects: EffectOverrides::default(),
            ..base.clone()
        };
        Ok(Subject { name: self.file(), scene, camera, accel, settings })
    }
}

/// `y` at `x`, read off the polyline through `points` on log-log axes;
/// `None` outside their range. The points are taken in order of `x` (the
/// times of short renders need not grow with their samples).
fn log_log_at(points: &[(f64, f64)], x: f64) -> Option<f64> {
    let mut logs: Vec<(f64, f64)> =
        points.iter().filter(|(x, y)| *x > 0.0 && *y > 0.0).map(|(x, y)| (x.ln(), y.ln())).collect();
    logs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let lx = x.ln();
    logs.windows(2).find(|w| w[0].0 <= lx && lx <= w[1].0).map(|w| {
        let t = if w[1].0 > w[0].0 { (lx - w[0].0) / (w[1].0 - w[0].0) } else { 0.0 };
        (w[0].1 + t * (w[1].1 - w[0].1)).exp()
    })
}

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let counts: Vec<u32> = if options.quick { vec![1, 4, 16] } else { (0..=8).map(|k| 1 << k).collect() };
    let strategies = DirectStrategy::ALL;
    let mut steps = Steps::new(SCENES.len() * (1 + strategies.len() * counts.len()), progress);
    let mut summary = Table {
        title: "At equal time: RMSE of each strategy at the longest time all three reach".into(),
        header: ["scene", "time budget ms", "light", "bsdf", "mis", "best", "runner-up / best"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    for direct_scene in &SCENES {
        let scene_subject = direct_scene.subject(&subject.settings)?;
        let name = direct_scene.name;
        steps.next(&format!("{name}: reference"));
        let reference = reference(
            &scene_subject,
            &scene_subject.settings,
            options.reference_spp(),
            options.cache.as_deref(),
            progress,
        )?;
        let noise = reference.info.noise_rmse;
        let mut table = Table {
            title: format!(
                "{name}: {} ({}; MIS reference of {} spp, noise RMSE ≈ {})",
                direct_scene.case,
                direct_scene.file(),
                reference.info.samples_per_pixel,
                format_number(noise)
            ),
            header: measurement_header(&["strategy", "spp"]),
            rows: Vec::new(),
        };
        let mut curves = Vec::new();
        let mut by_time = Vec::new();
        for &strategy in strategies {
            let mut series = Series { name: format!("{name}, {strategy}"), points: Vec::new() };
            for &spp in &counts {
                steps.next(&format!("{name}: {strategy} at {spp} spp"));
                let settings = RenderSettings {
                    direct_strategy: strategy,
                    samples_per_pixel: spp,
                    ..scene_subject.settings.clone()
                };
                let point = measure(&scene_subject, &settings, options, &reference);
                let mut row = vec![strategy.to_string(), spp.to_string()];
                row.extend(measurement_cells(&point));
                table.rows.push(row);
                series.points.push(point);
            }
            let xy: Vec<(f64, f64)> = series
                .points
                .iter()
                .map(|p| (p.time.as_ref().expect("measured").median_ms, p.error.as_ref().expect("measured").rmse))
                .collect();
            curves.push(Curve::error_against_time(strategy.to_string(), &crate::runner::time_and_error(&series)));
            // Each seed's error against the time, a curve per seed: read at
            // the budget, they are the repeats the rank test compares.
            let seeds = series.points.iter().map(|p| p.error.as_ref().expect("measured").seed_mse.len()).min();
            let per_seed: Vec<Vec<(f64, f64)>> = (0..seeds.unwrap_or(0))
                .map(|k| {
                    series
                        .points
                        .iter()
                        .map(|p| {
                            let e = p.error.as_ref().expect("measured");
                            (p.time.as_ref().expect("measured").median_ms, e.seed_mse[k].sqrt())
                        })
                        .collect()
                })
                .collect();
            by_time.push((strategy, xy, per_seed));
            report.series.push(series);
        }
        // Equal time: the longest time every strategy reached, where each curve is read off without extrapolating.
        let budget = by_time
            .iter()
            .filter_map(|(_, xy, _)| xy.iter().map(|p| p.0).reduce(f64::max))
            .fold(f64::INFINITY, f64::min);
        let at_budget: Vec<(DirectStrategy, Option<f64>)> =
            by_time.iter().map(|(strategy, xy, _)| (*strategy, log_log_at(xy, budget))).collect();
        // Each seed's RMSE at the budget: the repeats of the comparison.
        let seeds_at = |strategy: DirectStrategy| -> Option<Vec<f64>> {
            let (_, _, per_seed) = by_time.iter().find(|(s, ..)| *s == strategy)?;
            per_seed
                .iter()
                .map(|curve| log_log_at(curve, budget))
                .collect::<Option<Vec<f64>>>()
                .filter(|v| !v.is_empty())
        };
        // A strategy whose error does not fall over the measured times at
        // half the Monte Carlo rate has not converged: a ratio to it is not a
        // stable number, as it changes with the budget.
        let converging = |strategy: DirectStrategy| -> bool {
            let Some((_, xy, _)) = by_time.iter().find(|(s, ..)| *s == strategy) else { return false };
            let (first, last) = (xy.first().copied(), xy.last().copied());
            match (first, last) {
                (Some((t0, e0)), Some((t1, e1))) if t1 > t0 && e0 > 0.0 && e1 > 0.0 => {
                    (e1 / e0).ln() / (t1 / t0).ln() < -0.25
                }
                _ => false,
            }
        };
        let mut ranked: Vec<(DirectStrategy, f64)> = at_budget.iter().filter_map(|(s, e)| e.map(|e| (*s, e))).collect();
        ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
        let cell = |strategy: DirectStrategy| {
            at_budget.iter().find(|(s, _)| *s == strategy).and_then(|(_, e)| *e).map_or("–".into(), format_number)
        };
        if let [(best, best_error), (second, second_error), ..] = ranked[..] {
            let others: Vec<String> = ranked[1..]
                .iter()
                .map(|(s, e)| {
                    if converging(*s) {
                        format!("{s} {} ({:.2}× the error)", format_number(*e), e / best_error.max(1e-30))
                    } else {
                        format!("{s} {} (not converging over the measured times: no stable ratio)", format_number(*e))
                    }
                })
                .collect();
            let verdict = match (seeds_at(best), seeds_at(second)) {
                (Some(b), Some(s)) => compare("RMSE at equal time", &second.to_string(), &s, &best.to_string(), &b),
                _ => format!("{second} against {best}: not resolved (too few seeds)"),
            };
            report.findings.push(format!(
                "{name} ({}): at equal time ({} ms), {best} sampling has the lowest RMSE {}; {}; {verdict}{}",
                direct_scene.case,
                format_ms(budget),
                format_number(best_error),
                others.join(", "),
                if second_error < 3.0 * noise {
                    format!(" — errors near the reference's noise ({}) are not resolved", format_number(noise))
                } else {
                    String::new()
                }
            ));
            summary.rows.push(vec![
                name.to_owned(),
                format_ms(budget),
                cell(DirectStrategy::Light),
                cell(DirectStrategy::Bsdf),
                cell(DirectStrategy::Mis),
                best.to_string(),
                format!("{:.2} ({second})", second_error / best_error.max(1e-30)),
            ]);
        }
        // The equal-time figures go with each strategy's longest render, the point past the budget.
        let scene_series = report.series.len() - strategies.len();
        for (series, (_, error)) in report.series[scene_series..].iter_mut().zip(&at_budget) {
            if let (Some(last), Some(error)) = (series.points.last_mut(), error) {
                last.values.insert("equal_time_budget_ms".into(), budget);
                last.values.insert("rmse_at_equal_time".into(), *error);
            }
        }
        let times = by_time.iter().flat_map(|(_, xy, _)| xy.iter().map(|p| p.0));
        let (fastest, slowest) = times.fold((f64::INFINITY, 0.0f64), |(lo, hi), t| (lo.min(t), hi.max(t)));
        curves.push(Curve::guide("reference noise", vec![(fastest, noise), (slowest, noise)]));
        report.plots.push(Plot::error_against_time(
            format!("direct-{name}.svg"),
            format!("Direct light, the {name} scene: RMSE against time"),
            curves,
        ));
        // The equal-time panel: each strategy given the budget at its measured time per sample.
        let scene_series = &report.series[report.series.len() - strategies.len()..];
        let candidates: Vec<Candidate> = strategies
            .iter()
            .zip(scene_series)
            .filter_map(|(&strategy, series)| {
                let last = series.points.last()?;
                let settings = RenderSettings { direct_strategy: strategy, ..scene_subject.settings.clone() };
                Some(Candidate::render(
                    strategy.to_string(),
                    settings,
                    crate::runner::ms_per_sample(last, last.x as u32),
                ))
            })
            .collect();
        // The budget is the longest render of the strategy that reached the least time.
        let budget_render = strategies.iter().zip(scene_series).find_map(|(&strategy, series)| {
            let last = series.points.last()?;
            (last.time.as_ref()?.median_ms == budget).then(|| Budget {
                settings: RenderSettings {
                    direct_strategy: strategy,
                    samples_per_pixel: last.x as u32,
                    ..scene_subject.settings.clone()
                },
                make: crate::runner::render,
                estimate_ms: budget,
            })
        });
        if let Some(budget_render) = budget_render {
            let (file, what) = (format!("direct-{name}-equal-time.png"), format!("Direct light, {name},"));
            add_equal_time_panel(&mut report, &scene_subject, &reference, file, &what, &budget_render, &candidates);
        }
        report.tables.push(table);
    }
    report.tables.insert(0, summary);
    Ok(report)
}

/// The `direct` knob (the index gives its scenes' reports a Pareto plot each).
pub(crate) static DIRECT: super::Described = super::Described {
    name: "direct",
    about: "Light, BSDF and MIS sampling of direct light, on scenes built for each.",
    question: "which sampling of direct light (light, BSDF or MIS) gives the least error in equal time, and where?",
    scenes: super::Scenes::Own("scenes/direct-*.toml (built in: small light, large light, glossy)"),
    run,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_power_laws_exactly_between_points() {
        // y = 8 / x on log-log axes is a straight line, given out of order.
        let points = [(4.0, 2.0), (1.0, 8.0), (16.0, 0.5)];
        assert!((log_log_at(&points, 2.0).unwrap() - 4.0).abs() < 1e-12);
        assert!((log_log_at(&points, 16.0).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(log_log_at(&points, 32.0), None);
        assert_eq!(log_log_at(&points, 0.5), None);
    }

    #[test]
    fn the_built_in_scenes_load_with_a_camera_and_a_light() {
        for direct_scene in &SCENES {
            let subject = direct_scene.subject(&RenderSettings::default()).unwrap();
            assert!(subject.scene.materials.iter().any(|m| m.is_emissive()), "{}", direct_scene.name);
            assert_eq!(subject.settings.integrator, Integrator::Direct);
        }
    }
}
