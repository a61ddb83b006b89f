//! The knobs: one file each, each answering one question a user of the
//! course asks about what accuracy costs.

use crate::provenance::Build;
use crate::report::Report;
use crate::{ExperimentError, Machine, Options, Subject};

mod accel;
mod adaptive;
mod analytic;
mod bounce_sampling;
mod clamp;
mod denoise;
mod depth;
mod direct;
mod effects;
mod filter_glossy;
mod image_size;
mod intersector;
mod packets;
mod precision;
mod roulette_start;
mod scaling;
mod spp;
mod sweep;
mod threads;
mod traversal;

/// Something an experiment varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Knob {
    /// Samples per pixel, for each pixel sampler.
    Spp,
    /// Bounces, with Russian roulette on and off.
    Depth,
    /// Where bounce directions come from: the BSDF, the cosine or the uniform hemisphere.
    BounceSampling,
    /// The bounce from which Russian roulette may end paths.
    RouletteStart,
    /// The acceleration structures and their build parameters.
    Accel,
    /// The naive O(n) search against the BVH, over triangle counts.
    Scaling,
    /// The robust slab test of traversal against the textbook one.
    Traversal,
    /// Batch queries (packets of 16 coherent rays) against one ray at a time.
    Packets,
    /// Light, BSDF and MIS sampling of direct light, on scenes built for each.
    Direct,
    /// The indirect-light clamp: bias traded for variance.
    Clamp,
    /// Path regularisation (Cycles' "filter glossy") against the clamp.
    FilterGlossy,
    /// Adaptive sampling (noise targets) against fixed samples per pixel.
    Adaptive,
    /// The edge-avoiding denoiser against the samples' mean.
    Denoise,
    /// Worker threads: render time, and the same bits at every count.
    Threads,
    /// Render time against the image's pixel count.
    ImageSize,
    /// Each estimator's bias against answers known in closed form (white furnaces).
    Analytic,
    /// Each decision of the effects planner reversed.
    Effects,
    /// The ray/triangle tests: time, and failures on the hard cases of `rtgi verify`.
    Intersector,
    /// The triangle test in single against double precision: time, and
    /// error against the exact answer on hard triangles.
    ///
    /// The hard triangles are near-degenerate ones and far ones.
    Precision,
}

impl Knob {
    /// Every knob, in the order `all` runs them.
    pub const ALL: &'static [Knob] = &[
        Knob::Spp,
        Knob::Depth,
        Knob::BounceSampling,
        Knob::RouletteStart,
        Knob::Accel,
        Knob::Scaling,
        Knob::Traversal,
        Knob::Packets,
        Knob::Direct,
        Knob::Clamp,
        Knob::FilterGlossy,
        Knob::Adaptive,
        Knob::Denoise,
        Knob::Threads,
        Knob::ImageSize,
        Knob::Analytic,
        Knob::Effects,
        Knob::Intersector,
        Knob::Precision,
    ];

    /// The knob's name on command lines and in file names (`spp`, `depth`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Knob::Spp => "spp",
            Knob::Depth => "depth",
            Knob::BounceSampling => "bounce-sampling",
            Knob::RouletteStart => "roulette-start",
            Knob::Accel => "accel",
            Knob::Scaling => "scaling",
            Knob::Traversal => "traversal",
            Knob::Packets => "packets",
            Knob::Direct => "direct",
            Knob::Clamp => "clamp",
            Knob::FilterGlossy => "filter-glossy",
            Knob::Adaptive => "adaptive",
            Knob::Denoise => "denoise",
            Knob::Threads => "threads",
            Knob::ImageSize => "image-size",
            Knob::Analytic => "analytic",
            Knob::Effects => "effects",
            Knob::Intersector => "intersector",
            Knob::Precision => "precision",
        }
    }

    /// The question the knob's experiment answers.
    pub fn question(self) -> &'static str {
        match self {
            Knob::Spp => {
                "how fast does the error fall with samples per pixel, for each pixel sampler, and at equal time?"
            }
            Knob::Depth => "what do bounces cost, and how much light is missing without them?",
            Knob::BounceSampling => {
                "which source of bounce directions (BSDF, cosine or uniform hemisphere) reaches the least error in \
                 equal time?"
            }
            Knob::RouletteStart => {
                "from which bounce should Russian roulette end paths: what does an early start save in time and cost \
                 in noise?"
            }
            Knob::Accel => {
                "what does each acceleration structure cost to build and to trace, and does it change any answer?"
            }
            Knob::Scaling => {
                "how does the time per ray grow with the triangle count, for the naive search and for the BVH?"
            }
            Knob::Traversal => {
                "what does the robust slab test cost, and how many answers does the textbook one change?"
            }
            Knob::Packets => {
                "what do packets of coherent rays gain over one ray at a time, and do they change any answer?"
            }
            Knob::Direct => {
                "which sampling of direct light (light, BSDF or MIS) gives the least error in equal time, and where?"
            }
            Knob::Clamp => "how much bias does clamping indirect light add for the variance it removes?",
            Knob::FilterGlossy => {
                "does widening mirrors, glass and sharp highlights after a diffuse bounce (path regularisation) \
                 remove the fireflies of caustics at less bias than the clamp, raw and denoised?"
            }
            Knob::Adaptive => {
                "does sampling until each pixel meets a noise target beat the same samples everywhere, at equal time?"
            }
            Knob::Denoise => {
                "does the denoiser lower the error at equal time, and how much bias does it trade for the noise?"
            }
            Knob::Threads => {
                "what do worker threads buy in render time, and is the image the same bits at every count?"
            }
            Knob::ImageSize => {
                "does render time grow in proportion to the pixels, or does a fixed cost weigh on small images?"
            }
            Knob::Analytic => {
                "is any estimator (sampler, direct-light strategy, roulette) biased against an answer known exactly?"
            }
            Knob::Effects => {
                "what does each effect cost, and does leaving out one the scene does not call for cost accuracy?"
            }
            Knob::Intersector => {
                "what does each ray/triangle test cost, and how often do rays slip through shared edges or hit \
                 the surface they leave?"
            }
            Knob::Precision => {
                "how far are t and the barycentrics from the exact answer in single and double precision, on \
                 near-degenerate and far-from-origin triangles, and what does double precision cost?"
            }
        }
    }

    /// Whether the knob measures on the subject's scene (and so needs a
    /// reference of it); `scaling` and `precision` make their own
    /// triangles and `direct` renders scenes of its own, at the subject's size.
    pub fn uses_scene(self) -> bool {
        !matches!(self, Knob::Scaling | Knob::Direct | Knob::Precision | Knob::Analytic)
    }
}

impl rtgi_math::NamedChoice for Knob {
    const KIND: &'static str = "experiment";
    const ALL: &'static [Self] = Knob::ALL;
    fn name(self) -> &'static str {
        Knob::name(self)
    }
}

impl std::fmt::Display for Knob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

pub(crate) fn run(
    knob: Knob,
    subject: &Subject,
    options: &Options,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let report = Report {
        knob: knob.name().to_owned(),
        question: knob.question().to_owned(),
        scene: match knob {
            _ if knob.uses_scene() => subject.name.clone(),
            Knob::Direct => "scenes/direct-*.toml (built in: small light, large light, glossy)".to_owned(),
            Knob::Precision => "generated triangles".to_owned(),
            Knob::Analytic => "white furnaces (built in: closed emitting spheres)".to_owned(),
            _ => "generated meshes".to_owned(),
        },
        machine: Machine::this(options.threads),
        build: Build::this(),
        date: String::new(),
        command: options.command.clone(),
        repeats: options.repeats.max(1),
        quick: options.quick,
        reference: None,
        renders: knob.uses_scene().then(|| {
            let settings = at_reference_depth(subject);
            let depth = if knob == Knob::Depth { "varied".to_owned() } else { settings.max_depth.to_string() };
            format!(
                "{}x{} pixels, {} integrator, maximum depth {depth}, Russian roulette {} from bounce {}, {} bounce \
                 sampling, {} sampler, {} direct light",
                settings.width,
                settings.height,
                settings.integrator,
                if settings.russian_roulette { "on" } else { "off" },
                settings.roulette_start,
                settings.bounce_sampling,
                settings.sampler,
                settings.direct_strategy
            )
        }),
        series: Vec::new(),
        fits: Vec::new(),
        findings: Vec::new(),
        tables: Vec::new(),
        plots: Vec::new(),
        panels: Vec::new(),
    };
    let mut report = match knob {
        Knob::Spp => spp::run(subject, options, report, progress),
        Knob::Depth => depth::run(subject, options, report, progress),
        Knob::BounceSampling => bounce_sampling::run(subject, options, report, progress),
        Knob::RouletteStart => roulette_start::run(subject, options, report, progress),
        Knob::Threads => threads::run(subject, options, report, progress),
        Knob::ImageSize => image_size::run(subject, options, report, progress),
        Knob::Accel => accel::run(subject, options, report, progress),
        Knob::Scaling => scaling::run(options, report, progress),
        Knob::Traversal => traversal::run(subject, options, report, progress),
        Knob::Packets => packets::run(subject, options, report, progress),
        Knob::Direct => direct::run(subject, options, report, progress),
        Knob::Clamp => clamp::run(subject, options, report, progress),
        Knob::FilterGlossy => filter_glossy::run(subject, options, report, progress),
        Knob::Adaptive => adaptive::run(subject, options, report, progress),
        Knob::Denoise => denoise::run(subject, options, report, progress),
        Knob::Analytic => analytic::run(options, report, progress),
        Knob::Effects => effects::run(subject, options, report, progress),
        Knob::Intersector => intersector::run(subject, options, report, progress),
        Knob::Precision => precision::run(options, report, progress),
    }?;
    report.date = crate::provenance::utc_now();
    Ok(report)
}

/// Refuses a subject whose integrator simulates no light, for the knobs
/// that change how light transport is sampled (`knob` names the experiment).
fn require_light_transport(subject: &Subject, knob: &str) -> Result<(), ExperimentError> {
    if subject.settings.integrator.simulates_light() {
        return Ok(());
    }
    Err(ExperimentError::Unsuitable(format!(
        "the {knob} experiment needs an integrator that simulates light (the subject uses '{}')",
        subject.settings.integrator
    )))
}

/// The subject's settings at the depth of the references
/// ([`crate::reference::CONVERGED_DEPTH`] for paths, with Russian roulette
/// as the subject has it): what every knob but `depth` renders, so that the
/// truncation of shallower paths is not a bias shared by every
/// configuration and called theirs. The `depth` knob measures truncation itself.
pub(crate) fn at_reference_depth(subject: &Subject) -> rtgi_render::RenderSettings {
    let mut settings = subject.settings.clone();
    if settings.integrator == rtgi_render::Integrator::Path {
        settings.max_depth = settings.max_depth.max(crate::reference::CONVERGED_DEPTH);
    }
    settings
}
