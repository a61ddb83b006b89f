//! [`RenderRequest`]: everything a render can be asked, as data, in groups
//! a front end fills from its own options (`rtgi render`'s flags, a
//! script's commands, a gallery's defaults, a test's literals).

use std::ops::Range;
use std::path::{Path, PathBuf};

use rtgi_accel::{AccelKind, BuildParams, Intersector, SahAxes, Traversal};
use rtgi_image::ToneOperator;
use rtgi_math::Vec3;
use rtgi_render::recipe::{CameraChoice, Lighting};
use rtgi_render::{AdaptiveSampling, BounceSampling, DirectStrategy, EffectOverrides, Integrator, PixelSampler};

use crate::scene_source::SceneSource;

/// A render, as asked: the scene, what to simulate and how, where the
/// image goes, and how the work is split, checkpointed and bounded.
///
/// [`RenderRequest::new`] gives the defaults of `rtgi render SCENE`; set
/// the fields that differ. [`crate::render`] carries it out.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderRequest {
    /// The scene: a file, or the built-in Cornell box.
    pub scene: SceneSource,
    /// The image (.png, .exr) or accumulation (.accum) to write.
    pub output: PathBuf,
    /// Arbitrary output variables written beside the output as
    /// `OUTPUT.NAME.exr` (integrators whose [`Integrator::is_aov`] holds).
    pub aovs: Vec<Integrator>,
    /// The image's size.
    pub size: ImageSize,
    /// How many samples, where in the pixel, and whether they adapt.
    pub sampling: Sampling,
    /// The integrator, its settings, and the light added to the scene.
    pub lighting: Lighting,
    /// Radiance of camera rays that hit nothing and see no environment.
    pub background: Vec3,
    /// Which camera, and what of it is overridden.
    pub camera: CameraChoice,
    /// The acceleration structure and its build parameters.
    pub structure: Structure,
    /// How the image becomes 8-bit PNG.
    pub tone: Tone,
    /// Whether the image is denoised.
    pub denoise: Denoise,
    /// Which share of the render this job does.
    pub split: Split,
    /// Time limit, checkpoints and resumption.
    pub checkpoints: Checkpoints,
    /// Worker threads (`None`: one per core).
    pub threads: Option<u32>,
}

impl RenderRequest {
    /// The defaults of `rtgi render`, for `scene` written to `output`.
    pub fn new(scene: SceneSource, output: impl Into<PathBuf>) -> Self {
        Self {
            scene,
            output: output.into(),
            aovs: Vec::new(),
            size: ImageSize::default(),
            sampling: Sampling::default(),
            lighting: default_lighting(),
            background: DEFAULT_BACKGROUND,
            camera: CameraChoice::default(),
            structure: Structure::default(),
            tone: Tone::default(),
            denoise: Denoise::Auto,
            split: Split::default(),
            checkpoints: Checkpoints::default(),
            threads: None,
        }
    }

    /// Samples per pixel: as asked, else the default of the integrator
    /// (16 for light transport, 1 for the others) or, when sampling
    /// adapts, [`ADAPTIVE_SPP`].
    pub fn samples_per_pixel(&self) -> u32 {
        self.sampling.samples_per_pixel.unwrap_or(if self.sampling.adaptive().is_some() {
            ADAPTIVE_SPP
        } else if self.lighting.integrator.simulates_light() {
            16
        } else {
            1
        })
    }

    /// Whether this job renders a part of the image (for a merge).
    pub fn is_part(&self) -> bool {
        self.split.samples.is_some() || self.split.tile.is_some()
    }

    /// Whether the output is an accumulation (.accum) rather than an image.
    pub fn writes_accumulation(&self) -> bool {
        is_accumulation(&self.output)
    }
}

/// The lighting of `rtgi render` without options: the path integrator at
/// depth 8, BSDF bounces, MIS for direct light, no lights added.
pub fn default_lighting() -> Lighting {
    Lighting {
        lights: Vec::new(),
        integrator: Integrator::Path,
        max_depth: 8,
        roulette_start: rtgi_render::ROULETTE_START,
        bounce_sampling: BounceSampling::Bsdf,
        direct_strategy: DirectStrategy::Mis,
        indirect_clamp: None,
        filter_glossy: None,
        environment: None,
        environment_scale: 1.0,
        effects: EffectOverrides::default(),
        no_default_lighting: false,
    }
}

/// Radiance of camera rays that miss, unless told otherwise: a dark grey
/// that tells the background from black surfaces.
pub const DEFAULT_BACKGROUND: Vec3 = Vec3::new(0.05, 0.05, 0.06);

/// The most samples a pixel takes when sampling adapts and no count is given.
pub const ADAPTIVE_SPP: u32 = 1024;

/// Extension of accumulation files: checkpoints and the parts of split renders.
pub const ACCUMULATION_EXTENSION: &str = "accum";

/// Whether `path` names an accumulation file rather than an image.
pub fn is_accumulation(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case(ACCUMULATION_EXTENSION))
}

/// Largest image side accepted: beyond this a typo (an extra zero) would
/// ask for gigabytes of memory and hours of rendering.
pub const MAX_IMAGE_SIDE: u32 = 16_384;

/// The side of an image when no size is given.
pub const DEFAULT_IMAGE_SIDE: u32 = 512;

/// The image's size; a side not given is [`DEFAULT_IMAGE_SIDE`], and when
/// neither is, a file camera's aspect ratio reshapes the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ImageSize {
    /// Width in pixels.
    pub width: Option<u32>,
    /// Height in pixels.
    pub height: Option<u32>,
}

impl ImageSize {
    /// Both sides given.
    pub fn exactly(width: u32, height: u32) -> Self {
        Self { width: Some(width), height: Some(height) }
    }

    /// The width, or the default.
    pub fn width(&self) -> u32 {
        self.width.unwrap_or(DEFAULT_IMAGE_SIDE)
    }

    /// The height, or the default.
    pub fn height(&self) -> u32 {
        self.height.unwrap_or(DEFAULT_IMAGE_SIDE)
    }

    /// Whether a side was given (a file camera's aspect then does not reshape it).
    pub fn given(&self) -> bool {
        self.width.is_some() || self.height.is_some()
    }
}

/// `width` × `height` reshaped to `aspect` (width over height), the longer
/// side kept: how an image follows a file camera's aspect ratio.
pub fn reshaped(width: u32, height: u32, aspect: f32) -> (u32, u32) {
    let side = width.max(height) as f32;
    let clamp = |x: f32| (x.round() as u32).clamp(1, MAX_IMAGE_SIDE);
    if aspect >= 1.0 { (clamp(side), clamp(side / aspect)) } else { (clamp(side * aspect), clamp(side)) }
}

/// How a pixel is sampled.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sampling {
    /// Samples per pixel (the most a pixel takes, when sampling adapts);
    /// `None`: [`RenderRequest::samples_per_pixel`]'s default.
    pub samples_per_pixel: Option<u32>,
    /// The pixel sampler; `None`: the center for 1 sample, stratified
    /// otherwise, Sobol when sampling adapts.
    pub sampler: Option<PixelSampler>,
    /// Seed of the random numbers.
    pub seed: u64,
    /// Adaptive sampling: each pixel until the standard error of its mean
    /// is at most this fraction of it.
    pub noise: Option<f32>,
    /// Adaptive sampling: rounds of doubling samples until the next would
    /// end after this many seconds.
    pub time: Option<f64>,
}

impl Sampling {
    /// The adaptive sampling asked for, if any.
    pub fn adaptive(&self) -> Option<AdaptiveSampling> {
        (self.noise.is_some() || self.time.is_some())
            .then_some(AdaptiveSampling { noise: self.noise, seconds: self.time })
    }
}

/// The acceleration structure and its build parameters; a parameter left
/// `None` is the structure's own default ([`AccelKind::default_params`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Structure {
    /// Which structure.
    pub kind: AccelKind,
    /// Most triangles in a leaf.
    pub leaf_size: Option<u32>,
    /// Bins per axis of the binned SAH build.
    pub sah_bins: u32,
    /// Axes the binned SAH build tries planes on.
    pub sah_axes: SahAxes,
    /// Cost of a traversal step relative to a leaf test, for the SAH;
    /// `None` takes the structure's own ([`rtgi_accel::AccelKind::default_params`]).
    pub traversal_cost: Option<f32>,
    /// The ray/triangle test.
    pub intersector: Intersector,
    /// The slab test of the binary BVHs.
    pub traversal: Traversal,
}

impl Default for Structure {
    fn default() -> Self {
        Self::of(AccelKind::Bvh8)
    }
}

impl Structure {
    /// `kind` with its default parameters.
    pub fn of(kind: AccelKind) -> Self {
        let defaults = BuildParams::default();
        Self {
            kind,
            leaf_size: None,
            sah_bins: defaults.sah_bins as u32,
            sah_axes: defaults.sah_axes,
            traversal_cost: None,
            intersector: defaults.intersector,
            traversal: defaults.traversal,
        }
    }

    /// The build parameters: `kind`'s defaults with the fields given in their place.
    pub fn params(&self) -> BuildParams {
        let defaults = self.kind.default_params();
        BuildParams {
            max_leaf_size: self.leaf_size.map_or(defaults.max_leaf_size, |size| size as usize),
            sah_bins: self.sah_bins as usize,
            sah_axes: self.sah_axes,
            traversal_cost: self.traversal_cost.unwrap_or(defaults.traversal_cost),
            intersector: self.intersector,
            traversal: self.traversal,
        }
    }
}

/// How an image becomes 8-bit PNG (EXR keeps linear floats).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tone {
    /// Exposure in stops; `None`: chosen from the image for light
    /// transport, 0 otherwise ([`rtgi_render::recipe::tone_map`]).
    pub exposure: Option<f32>,
    /// The tone map; `None`: ACES for light transport, clamp otherwise.
    pub operator: Option<ToneOperator>,
}

/// Whether the image is denoised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Denoise {
    /// PNG output of the integrators that simulate light; EXR and
    /// accumulations keep the unbiased mean.
    #[default]
    Auto,
    /// Every image of a light-simulating integrator, EXR included.
    On,
    /// Never: the image is the samples' mean.
    Off,
}

impl Denoise {
    /// Every choice, in the order help texts list them.
    pub const ALL: &'static [Denoise] = &[Denoise::Auto, Denoise::On, Denoise::Off];

    /// The name on command lines and in reports (`auto`, `on`, `off`).
    pub fn name(self) -> &'static str {
        match self {
            Denoise::Auto => "auto",
            Denoise::On => "on",
            Denoise::Off => "off",
        }
    }
}

impl rtgi_math::NamedChoice for Denoise {
    const KIND: &'static str = "denoise choice";
    const ALL: &'static [Self] = Denoise::ALL;
    fn name(self) -> &'static str {
        Denoise::name(self)
    }
}

/// Which share of a render this job does: a range of every pixel's
/// samples, a band of rows, or both; the parts go to .accum files that a
/// merge puts together, bit-identical to the render in one go.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Split {
    /// Samples `start..end` of every pixel.
    pub samples: Option<Range<u32>>,
    /// Band `index` of `count` bands of rows of equal height.
    pub tile: Option<(u32, u32)>,
}

/// Long renders: a time limit, checkpoints, and resuming one.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoints {
    /// Stop once this many seconds have passed since the render started,
    /// and write the image of the samples done.
    pub time_limit: Option<f64>,
    /// Save the render's state here every `every_seconds` and when it stops.
    pub checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    pub every_seconds: f64,
    /// Continue the render saved in this file (checkpoints then go there
    /// too, unless `checkpoint` says otherwise).
    pub resume: Option<PathBuf>,
}

impl Default for Checkpoints {
    fn default() -> Self {
        Self { time_limit: None, checkpoint: None, every_seconds: 60.0, resume: None }
    }
}

impl Checkpoints {
    /// Where checkpoints go: `checkpoint`, else the file resumed.
    pub fn path(&self) -> Option<&Path> {
        self.checkpoint.as_deref().or(self.resume.as_deref())
    }
}
