//! `bounce-sampling`: where bounce directions come from (`--bounce`): the
//! BSDF's importance sampling, the cosine-weighted hemisphere or the uniform
//! one. All three are unbiased; they differ in noise, and so in the error
//! each reaches in a given time.

use rtgi_render::{BounceSampling, RenderSettings};

use super::sweep::{Setting, Sweep, measure_settings};
use crate::report::Report;
use crate::{ExperimentError, Options, Subject};

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    report: Report,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    super::require_light_transport(subject, "bounce-sampling")?;
    let counts: &[u32] = if options.quick { &[2, 8] } else { &[4, 16, 64] };
    let base = RenderSettings { adaptive: None, ..super::at_reference_depth(subject) };
    let settings: Vec<Setting> = BounceSampling::ALL
        .iter()
        .map(|&bounce_sampling| Setting {
            label: format!("{bounce_sampling} bounces"),
            settings: RenderSettings { bounce_sampling, ..base.clone() },
        })
        .collect();
    let default = BounceSampling::ALL.iter().position(|&b| b == BounceSampling::default()).unwrap_or(0);
    let compared_at = counts[counts.len() / 2];
    let sweep = Sweep {
        base,
        settings,
        default,
        counts,
        compared_at,
        file: "bounce-sampling-tradeoff.svg",
        what: "bounce sampling",
    };
    measure_settings(subject, options, report, progress, sweep)
}

/// The `bounce-sampling` knob.
pub(super) static BOUNCE_SAMPLING_KNOB: super::Described = super::Described {
    name: "bounce-sampling",
    about: "Where bounce directions come from: the BSDF, the cosine or the uniform hemisphere.",
    question: "which source of bounce directions (BSDF, cosine or uniform hemisphere) reaches the least error in \
            equal time?",
    scenes: super::Scenes::Subject(&[super::CORNELL, super::GLOSSY]),
    run,
};
