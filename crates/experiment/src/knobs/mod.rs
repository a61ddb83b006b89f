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
pub(crate) mod direct;
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

/// One knob of the experiments: what it varies, the question it answers,
/// where it measures, and the measurement with its own settings (quick
/// and full). Each knob is a file of its own in `knobs/` and one line of
/// [`KNOBS`]; the command line, the report, its index and the tests take
/// every knob from there, so a new one cannot be left out of any.
pub trait Knob: Sync {
    /// The knob's name on command lines and in file names (`spp`, `depth`, ...).
    fn name(&self) -> &'static str;

    /// What the knob varies, in a sentence (the command line's help).
    fn about(&self) -> &'static str;

    /// The question the knob's experiment answers.
    fn question(&self) -> &'static str;

    /// Where the knob measures: on the subject's scene, or on scenes of its own.
    fn scenes(&self) -> Scenes;

    /// Measures on `subject` (or on the knob's own scenes) and fills in
    /// `report`, whose provenance is already written; `progress` receives
    /// a line per step.
    fn run(
        &self,
        subject: &Subject,
        options: &Options,
        report: Report,
        progress: &dyn Fn(&str),
    ) -> Result<Report, ExperimentError>;

    /// Whether the knob measures on the subject's scene (and so needs a
    /// reference of it).
    fn uses_scene(&self) -> bool {
        matches!(self.scenes(), Scenes::Subject(_))
    }
}

/// A knob told by its fields, as each knob's file declares itself: the
/// measuring is the file's `run`, the rest is what the registry says of it.
pub(crate) struct Described {
    name: &'static str,
    about: &'static str,
    question: &'static str,
    scenes: Scenes,
    run: MeasureFn,
}

/// A knob's measuring: the subject, the options, the report to fill in and where progress goes.
type MeasureFn = fn(&Subject, &Options, Report, &dyn Fn(&str)) -> Result<Report, ExperimentError>;

impl Knob for Described {
    fn name(&self) -> &'static str {
        self.name
    }

    fn about(&self) -> &'static str {
        self.about
    }

    fn question(&self) -> &'static str {
        self.question
    }

    fn scenes(&self) -> Scenes {
        self.scenes
    }

    fn run(
        &self,
        subject: &Subject,
        options: &Options,
        report: Report,
        progress: &dyn Fn(&str),
    ) -> Result<Report, ExperimentError> {
        (self.run)(subject, options, report, progress)
    }
}

/// Where a knob measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scenes {
    /// The subject's scene; the report (`rtgi experiment all` without a
    /// scene) measures it on each of these shared scenes: paths in the
    /// shared scenes' folder, or `project:NAME` for `scenes/NAME` of this
    /// workspace.
    Subject(&'static [&'static str]),
    /// Scenes the knob makes itself (generated meshes, built-in scenes),
    /// as the report names them.
    Own(&'static str),
}

/// Every knob, in the order `rtgi experiment all` runs them: adding a knob
/// is its file and its line here.
pub static KNOBS: &[&dyn Knob] = &[
    &spp::SPP,
    &depth::DEPTH,
    &bounce_sampling::BOUNCE_SAMPLING_KNOB,
    &roulette_start::ROULETTE_START,
    &accel::ACCEL_STRUCTURES,
    &scaling::SCALING,
    &traversal::TRAVERSAL_TEST,
    &packets::PACKETS,
    &direct::DIRECT,
    &clamp::CLAMP,
    &filter_glossy::FILTER_GLOSSY_KNOB,
    &adaptive::ADAPTIVE,
    &denoise::DENOISE,
    &threads::THREADS,
    &image_size::IMAGE_SIZE,
    &analytic::ANALYTIC,
    &effects::EFFECTS,
    &intersector::INTERSECTORS,
    &precision::PRECISION,
];

/// The knob named `name` (as [`Knob::name`] gives it).
pub fn knob(name: &str) -> Option<&'static dyn Knob> {
    KNOBS.iter().copied().find(|k| k.name() == name)
}

// Knobs are told apart by name: the registry holds each once.
impl PartialEq for dyn Knob + '_ {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for dyn Knob + '_ {}

impl std::fmt::Debug for dyn Knob + '_ {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Knob({})", self.name())
    }
}

impl std::fmt::Display for dyn Knob + '_ {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The shared scenes of the report, relative to the shared scenes' folder.
/// The Cornell box: small, closed, converges; its error at high spp is mostly the emitter's edge.
const CORNELL: &str = "cornell-box/CornellBox-Original.obj";
/// The Cornell box with a mirror block: caustics off the mirror.
const MIRROR: &str = "cornell-box/CornellBox-Mirror.obj";
/// One mesh under the sky.
const BUNNY: &str = "bunny/stanford-bunny.obj";
/// Large, many materials.
const SPONZA: &str = "sponza-dabrovic/sponza.obj";
/// Large, many materials, glossy ones among them.
const CONFERENCE: &str = "conference/conference.obj";
/// Textures, normal maps, emissive details: effects the box does not need.
const HELMET: &str = "gltf/DamagedHelmet/glTF/DamagedHelmet.gltf";
/// The project's own glossy scene (in `scenes/`, not the shared folder):
/// glossy metals, where transport noise is of the BSDF's lobes.
const GLOSSY: &str = "project:direct-glossy.toml";
/// The project's closed room lit only by light bounced off its ceiling:
/// transport noise, with no emitter in view.
const ROOM: &str = "project:indirect-room.toml";
/// The project's Cornell box with a glass and a mirror sphere: caustics.
const CAUSTICS: &str = "project:caustics.toml";

pub(crate) fn run(
    knob: &dyn Knob,
    subject: &Subject,
    options: &Options,
    progress: &dyn Fn(&str),
) -> Result<Report, ExperimentError> {
    let report = Report {
        knob: knob.name().to_owned(),
        question: knob.question().to_owned(),
        scene: match knob.scenes() {
            Scenes::Subject(_) => subject.name.clone(),
            Scenes::Own(scenes) => scenes.to_owned(),
        },
        machine: Machine::this(options.threads),
        build: Build::this(),
        date: String::new(),
        command: options.command.clone(),
        repeats: options.repeats.max(1),
        quick: options.quick,
        reference: None,
        renders: knob.uses_scene().then(|| renders(&at_reference_depth(subject), None)),
        series: Vec::new(),
        fits: Vec::new(),
        findings: Vec::new(),
        tables: Vec::new(),
        plots: Vec::new(),
        panels: Vec::new(),
    };
    let mut report = knob.run(subject, options, report, progress)?;
    report.date = crate::provenance::utc_now();
    Ok(report)
}

/// The report's line on what the knob's renders share; `depth` says how
/// deep paths go where the knob varies it, else the settings' maximum depth.
fn renders(settings: &rtgi_render::RenderSettings, depth: Option<&str>) -> String {
    let depth = depth.map_or_else(|| settings.max_depth.to_string(), str::to_owned);
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
