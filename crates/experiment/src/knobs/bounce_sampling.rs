//! `bounce-sampling`: where bounce directions come from (`--bounce`): the
//! BSDF's importance sampling, the cosine-weighted hemisphere or the uniform
//! one. All three are unbiased; they differ in noise, and so in the error
//! each reaches in a given time.

use rtgi_render::{BounceSampling, RenderSettings};

use super::sweep::{Setting, measure_settings};
use crate::reference::reference;
use crate::report::Report;
use crate::{ExperimentError, Options, Steps, Subject};

pub(super) fn run(
    subject: &Subject,
    options: &Options,
    mut report: Report,
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
    let mut steps = Steps::new(1 + settings.len() * counts.len(), progress);
    steps.next("reference");
    let reference = reference(subject, &base, options.reference_spp(), options.cache.as_deref(), progress)?;
    let compared_at = counts[counts.len() / 2];
    measure_settings(
        subject,
        options,
        &mut report,
        &mut steps,
        &reference,
        &settings,
        default,
        counts,
        compared_at,
        "bounce-sampling-tradeoff.svg",
        "bounce sampling",
    );
    report.reference = Some(reference.info);
    Ok(report)
}
