//! `roulette-start`: the bounce from which Russian roulette may end paths
//! (`--roulette-start`), and roulette off. Roulette is unbiased wherever it
//! starts: an early start saves the time of long paths and pays in noise.
//! Renders run to the references' depth, so that without roulette every
//! path runs that far.

use rtgi_render::RenderSettings;

use super::sweep::{Setting, Sweep, measure_settings};
use crate::report::Report;
use crate::{ExperimentError, Options, Subject};

/// The bounces roulette starts at: the first, the default (the second) and later ones.
const STARTS: [u32; 5] = [1, 2, 3, 5, 8];

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    super::require_light_transport(subject, "roulette-start")?;
    let counts: &[u32] = if options.quick { &[4] } else { &[4, 16] };
    let base = RenderSettings { adaptive: None, ..super::at_reference_depth(subject) };
    let starts: &[u32] = if options.quick { &[1, 2] } else { &STARTS };
    let mut settings: Vec<Setting> = starts
        .iter()
        .map(|&roulette_start| Setting {
            label: format!("roulette from bounce {roulette_start}"),
            settings: RenderSettings { russian_roulette: true, roulette_start, ..base.clone() },
        })
        .collect();
    settings.push(Setting {
        label: "roulette off".to_owned(),
        settings: RenderSettings { russian_roulette: false, ..base.clone() },
    });
    let default = starts.iter().position(|&s| s == rtgi_render::ROULETTE_START).unwrap_or(0);
    let compared_at = *counts.last().expect("counts");
    let sweep = Sweep {
        base,
        settings,
        default,
        counts,
        compared_at,
        file: "roulette-start-tradeoff.svg",
        what: "roulette start",
    };
    measure_settings(subject, options, report, progress, sweep)
}

/// The `roulette-start` knob.
pub(super) static ROULETTE_START: super::Described = super::Described {
    name: "roulette-start",
    about: "The bounce from which Russian roulette may end paths.",
    question: "from which bounce should Russian roulette end paths: what does an early start save in time and cost \
            in noise?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::ROOM]),
    run,
};
