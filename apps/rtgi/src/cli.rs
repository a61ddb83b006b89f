use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand, ValueEnum};
use rtgi_accel::{AccelKind, BuildError, BuildParams, Intersector, SahAxes, Traversal};
use rtgi_image::ToneOperator;
use rtgi_math::Vec3;
use rtgi_render::{
    BounceSampling, DirectStrategy, EffectOverrides, EnvironmentSpec, EnvironmentSpecError, Integrator, PixelSampler,
};
use rtgi_scene::{Light, LightSpecError};

/// Largest image side accepted: beyond this a typo (an extra zero) would
/// ask for gigabytes of memory and hours of rendering.
pub(crate) const MAX_IMAGE_SIDE: u32 = 16_384;

#[derive(Debug, Parser)]
#[command(name = "rtgi", version, about = "Ray tracing and global illumination toolkit")]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,

    /// Let a scene's references (OBJ mtllib and textures, glTF buffers and images, meshes of a
    /// TOML description) reach outside the scene file's folder: only for scenes you trust
    #[arg(long, global = true)]
    pub(crate) allow_outside_scene: bool,

    /// The material variant of a glTF scene to render (KHR_materials_variants; `rtgi info`
    /// lists a scene's variants); without it each primitive has its default material
    #[arg(long, global = true, value_name = "NAME")]
    pub(crate) variant: Option<String>,
}

#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Render a scene to an image (.png or .exr)
    Render(RenderArgs),
    /// Trace a batch of rays from a binary file and write their hits
    Trace(TraceArgs),
    /// Write a ray file for 'rtgi trace': camera rays of a scene's view, random rays in its
    /// bounds, or rays leaving its surfaces
    Rays(crate::rays_cmd::RaysArgs),
    /// Measure build time, tree quality and ray throughput of acceleration structures
    Bench(crate::bench_cmd::BenchArgs),
    /// Export the boxes of chosen BVH levels as an OBJ file, to look at the tree
    BvhBoxes(BvhBoxesArgs),
    /// Render the traversal cost (BVH nodes visited per pixel) as a heat map
    Heatmap(HeatmapArgs),
    /// Describe a scene: triangles, materials, textures, lights, cameras, bounds, extensions,
    /// and the effects a render of it simulates
    Info(InfoArgs),
    /// Measure how far an EXR image is from a reference EXR image (RMSE, relative MSE, max)
    Compare(CompareArgs),
    /// Measure what each effect costs: render time with effects forced on and off, and how the image changes
    BenchEffects(crate::effects_cmd::BenchEffectsArgs),
    /// Check that every acceleration structure answers hard rays exactly as the linear scan does,
    /// bit for bit, and that rays aimed inside closed surfaces never leak
    Verify(VerifyArgs),
    /// Put the parts of a split render (--samples, --tile) or a checkpoint together into one
    /// image or accumulation, bit-identical to the render in one go
    Merge(crate::merge_cmd::MergeArgs),
    /// A contact sheet of scenes, each rendered as 'rtgi render SCENE' renders it with no options
    Gallery(crate::gallery_cmd::GalleryArgs),
    /// What accuracy costs in time: vary one knob (or all) and write a table (KNOB.md), every
    /// measurement (KNOB.json) and SVG plots
    Experiment(crate::experiment_cmd::ExperimentArgs),
    /// Run scripts in the command language of the course framework (at, load, raytracer, algo,
    /// commit, run, ...); with no script, open a prompt
    Script(crate::script::ScriptArgs),
    /// Open a prompt that takes the course framework's commands (after running any scripts given)
    Repl(crate::script::ScriptArgs),
}

/// `rtgi verify`: the exactness contract, checked on a scene or on the built-in adversarial set.
#[derive(Debug, Args)]
pub(crate) struct VerifyArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in adversarial scenes when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Rays in all, shared evenly among the ray kinds (and scenes)
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u32).range(1..=1_000_000_000))]
    pub(crate) rays: u32,

    /// Structures to check against the linear scan: names separated by commas, or all
    #[arg(long, default_value = "all", value_parser = AccelParser { list: true })]
    pub(crate) accel: AccelList,

    /// Check every leaf size (1, 2, 4, 8, 16), bin count and intersector, as the tests do,
    /// instead of the build options below
    #[arg(long)]
    pub(crate) exhaustive: bool,

    #[command(flatten)]
    pub(crate) build: BuildArgs,

    /// Triangle tests the linear scan may spend per ray kind; on big scenes it answers only the
    /// first rays of each kind within this budget, and the others are compared with the first
    /// structure checked
    #[arg(long, default_value_t = 2_000_000_000, value_parser = clap::value_parser!(u64).range(1..))]
    pub(crate) linear_budget: u64,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,

    /// Also write the table as JSON to this file
    #[arg(long)]
    pub(crate) json: Option<PathBuf>,
}

/// `rtgi compare`: the error of an image against a reference.
#[derive(Debug, Args)]
pub(crate) struct CompareArgs {
    /// The image to measure (.exr)
    pub(crate) image: PathBuf,

    /// The reference (.exr), for example a high-sample render
    pub(crate) reference: PathBuf,

    /// Print JSON instead of text
    #[arg(long)]
    pub(crate) json: bool,
}

/// `rtgi info`: what a scene file contains.
#[derive(Debug, Args)]
pub(crate) struct InfoArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Print JSON instead of text
    #[arg(long)]
    pub(crate) json: bool,

    /// The render options the printed plan is for
    #[command(flatten)]
    pub(crate) lighting: LightingArgs,

    /// The view the plan is for: the lights a render adds depend on what the camera sees
    #[command(flatten)]
    pub(crate) camera: CameraArgs,
}

/// How light is simulated: shared by `render` and `info` (which prints the plan).
#[derive(Debug, Args)]
pub(crate) struct LightingArgs {
    /// What to compute per pixel
    #[arg(long, value_enum, default_value_t = Integrator::Path)]
    pub(crate) integrator: Integrator,

    /// Bounces a path may take after the camera ray (path integrator; 0 sees only what the camera
    /// rays hit)
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=1024))]
    pub(crate) max_depth: u32,

    /// The bounce from which Russian roulette may end dim paths (path integrator); a start
    /// beyond --max-depth turns it off
    #[arg(long, default_value_t = rtgi_render::ROULETTE_START, value_name = "BOUNCE")]
    pub(crate) roulette_start: u32,

    /// Where bounce directions and the bsdf strategy's light rays come from: the BSDF, or the
    /// cosine or uniform hemisphere (noisier; mirrors and glass always sample the BSDF)
    #[arg(long, value_enum, default_value_t = BounceSampling::Bsdf)]
    pub(crate) bounce_sampling: BounceSampling,

    /// How direct light is sampled
    #[arg(long, value_enum, default_value_t = DirectStrategy::Mis)]
    pub(crate) direct_strategy: DirectStrategy,

    /// Clamp the light each path brings in after two or more bounces to this value (brightest
    /// channel): fewer fireflies from caustics and glossy paths at low sample counts, at the
    /// price of a bias (darker caustics and highlights); the plan says when it is on [default:
    /// no clamp]
    #[arg(long, visible_alias = "clamp", value_parser = parse_positive, allow_negative_numbers = true)]
    pub(crate) clamp_indirect: Option<f32>,

    /// Path regularisation, as Cycles' "filter glossy": after a bounce sampled with a density
    /// below this value (diffuse bounces: about 0.3 and less), mirrors, glass and sharp highlights
    /// are widened (to a GGX width of up to 0.5), so caustics and highlights seen through diffuse
    /// bounces are found by light sampling instead of as fireflies; biased (blurrier caustics).
    /// 0 turns it off [default: for denoised PNG previews, mirrors and smooth glass only, at 1;
    /// off for EXR and .accum, which stay exact]
    #[arg(long, value_parser = parse_non_negative)]
    pub(crate) filter_glossy: Option<f32>,

    /// Light from far away: a radiance R,G,B, an equirectangular .exr image or a .floats sky of
    /// the course framework
    #[arg(long, value_parser = parse_environment, allow_hyphen_values = true)]
    pub(crate) environment: Option<EnvironmentSpec>,

    /// Multiplies the --environment's radiance
    #[arg(long, default_value_t = 1.0, value_parser = parse_positive, requires = "environment")]
    pub(crate) environment_scale: f32,

    /// Add a light (repeatable): point:X,Y,Z:INTENSITY[:R,G,B],
    /// directional:DX,DY,DZ:IRRADIANCE[:R,G,B] (the direction light travels),
    /// spot:X,Y,Z:DX,DY,DZ:INTENSITY:INNER_DEG:OUTER_DEG[:R,G,B]
    #[arg(long = "light", value_parser = parse_light)]
    pub(crate) lights: Vec<Light>,

    /// Force effects on or off, like +glossy,-textures (see the plan `rtgi info` prints)
    #[arg(long, allow_hyphen_values = true, default_value = "")]
    pub(crate) effects: EffectOverrides,

    /// Never add light the scene does not bring: no default sky and sun (for scenes without
    /// lights, with emitters too weak to light them, or whose lights leave the view dark), and
    /// no lamp over an enclosed, unlit room
    #[arg(long)]
    pub(crate) no_default_lighting: bool,
}

/// Parses a finite number that `accept` allows; the error names the
/// allowed values, `allowed`, so that the user knows what to type instead.
fn parse_number(text: &str, accept: impl Fn(f32) -> bool, allowed: &str) -> Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && accept(*v))
        .ok_or_else(|| format!("expected {allowed} (got '{text}')"))
}

fn parse_positive(text: &str) -> Result<f32, String> {
    parse_number(text, |v| v > 0.0, "a finite number greater than 0")
}

fn parse_non_negative(text: &str) -> Result<f32, String> {
    parse_number(text, |v| v >= 0.0, "a finite number of at least 0")
}

/// Exposure in stops: 2^±64 already turns any radiance black or white.
fn parse_exposure(text: &str) -> Result<f32, String> {
    parse_number(text, |v| (-64.0..=64.0).contains(&v), "a number of stops from -64 to 64")
}

fn parse_fov(text: &str) -> Result<f32, String> {
    parse_number(text, |v| v > 0.0 && v < 180.0, "an angle in degrees greater than 0 and less than 180")
}

/// Parses "r,g,b" into a colour: three finite numbers, none negative.
pub(crate) fn parse_colour(text: &str) -> Result<Vec3, String> {
    parse_vec3(text).ok().filter(|c| c.min_element() >= 0.0).ok_or_else(|| {
        format!("expected three finite numbers of at least 0 separated by commas, like 0.05,0.05,0.06 (got '{text}')")
    })
}

/// Parses "x,y,z" into a direction: three finite numbers, not all zero.
pub(crate) fn parse_direction(text: &str) -> Result<Vec3, String> {
    parse_vec3(text).ok().filter(|d| *d != Vec3::ZERO).ok_or_else(|| {
        format!("expected three finite numbers, not all 0, separated by commas, like 0,1,0 (got '{text}')")
    })
}

/// Parses `--environment` (the file is read later, once the outputs are checked).
fn parse_environment(text: &str) -> Result<EnvironmentSpec, String> {
    text.parse().map_err(|e: EnvironmentSpecError| e.to_string())
}

/// Parses `--light`: fields separated by colons, vectors by commas.
pub(crate) fn parse_light(text: &str) -> Result<Light, String> {
    text.parse().map_err(|e: LightSpecError| e.to_string())
}

/// `rtgi bvh-boxes`: the boxes of some levels of a BVH as a wireframe-able mesh.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "OBJ file to write; each level becomes a group named level_N [default: SCENE.boxes.obj, in the current folder]"
)))]
pub(crate) struct BvhBoxesArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    /// Depths to export, separated by commas (the root is 0)
    #[arg(long, default_value = "0,1,2,3", value_delimiter = ',')]
    pub(crate) levels: Vec<usize>,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,
}

/// `rtgi heatmap`: nodes visited per pixel, in false colour.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "Output image: .png for the false-colour map, .exr for the raw counts [default: SCENE.heatmap.png, in the current folder]"
)))]
pub(crate) struct HeatmapArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    #[command(flatten)]
    pub(crate) size: ImageSize,

    /// Count that maps to the top of the colour scale [default: the image's maximum]
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    pub(crate) scale: Option<f32>,

    /// Count triangle tests instead of nodes visited
    #[arg(long)]
    pub(crate) triangles: bool,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,
}

/// A list of acceleration structures chosen on the command line.
#[derive(Clone, Debug)]
pub(crate) struct AccelList(pub(crate) Vec<AccelKind>);

/// Parses the name of an acceleration structure (from [`AccelKind`]'s
/// `ValueEnum`: an unknown name is clap's invalid-value error, with the
/// possible values and a suggestion) or, for a `list`, names separated by
/// commas or `all`: our structures and the peers built in. `embree` in a
/// build without the feature is refused with [`AccelKind`]'s own message,
/// which says how to build it in.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AccelParser {
    pub(crate) list: bool,
}

impl TypedValueParser for AccelParser {
    type Value = AccelList;

    fn parse_ref(&self, cmd: &clap::Command, arg: Option<&clap::Arg>, value: &OsStr) -> Result<AccelList, clap::Error> {
        let names = PossibleValuesParser::new(self.possible_values().into_iter().flatten());
        let text = value.to_string_lossy();
        let items: Vec<&str> = if self.list { text.split(',').map(str::trim).collect() } else { vec![&*text] };
        let mut kinds = Vec::new();
        for item in items {
            if item == "embree" && !AccelKind::PEERS.iter().any(|peer| peer.name() == "embree") {
                // clap's value-validation error, with the library's explanation.
                let not_built = |text: &str| text.parse::<AccelKind>().map(|_| AccelList(Vec::new()));
                return not_built.parse_ref(cmd, arg, OsStr::new(item));
            }
            match names.parse_ref(cmd, arg, OsStr::new(item))?.as_str() {
                "all" => kinds.extend(AccelKind::ALL.iter().chain(AccelKind::PEERS)),
                name => kinds.push(AccelKind::from_str(name, false).expect("one of the possible values")),
            }
        }
        Ok(AccelList(kinds))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        let all = PossibleValue::new("all").help("Every structure, and the peers built in");
        let kinds = AccelKind::value_variants().iter().filter_map(ValueEnum::to_possible_value);
        Some(Box::new(kinds.chain(self.list.then_some(all))))
    }
}

/// `rtgi trace`: rays in, hits out, for tests and comparisons with other ray tracers.
///
/// Files are little-endian without a header. A ray is 8 × f32: origin x y z,
/// direction x y z, t_min, t_max. A hit is 16 bytes: t (f32; +inf for a
/// miss), triangle (u32; 0xFFFFFFFF for a miss), beta (f32), gamma (f32).
/// With --any-hit, triangle is 0 when the ray is occluded and 0xFFFFFFFF when
/// not, and t, beta and gamma are 0. Triangles are numbered in file order
/// (an OBJ polygon becomes a fan of triangles, in order). The rays are read,
/// traced and written in chunks, so a file of any size (or a stream) fits
/// in memory; a ray with a NaN or infinite origin or direction, a zero
/// direction or a NaN bound is refused, naming its index.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.visible_alias("out").help(
    "Binary file of hits to write, 16 bytes each [default: RAYS.hits.bin, after the ray file, in the current folder]"
)))]
pub(crate) struct TraceArgs {
    /// Scene file (.obj, .gltf, .glb or .toml)
    pub(crate) scene: PathBuf,

    /// Binary file of rays (32 bytes each)
    #[arg(long)]
    pub(crate) rays: PathBuf,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    /// Answer whether each ray is occluded (any hit) instead of its closest hit
    #[arg(long)]
    pub(crate) any_hit: bool,

    /// Trace cut-outs (alpha-masked and blended materials) as solid surfaces; by default
    /// rays pass through their holes as in renders, and blended surfaces count where their
    /// alpha exceeds one half
    #[arg(long)]
    pub(crate) no_alpha: bool,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,
}

/// `rtgi render`: an image of a scene.
#[derive(Debug, Args)]
#[command(mut_arg("output", |arg| arg.help(
    "Output image; the format follows the extension (.png or .exr), or .accum for the render's exact sums \
     (a part of a split render, for 'rtgi merge') [default: SCENE.png, in the current folder]"
)))]
pub(crate) struct RenderArgs {
    /// Scene file (.obj, .gltf, .glb or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    #[command(flatten)]
    pub(crate) output: OutputArgs,

    #[command(flatten)]
    pub(crate) size: ImageSize,

    /// A quick look: a quarter of the width and height, and at most 4 samples per pixel
    #[arg(long)]
    pub(crate) quick: bool,

    /// Samples per pixel [default: 16 for the direct and path integrators, 1 otherwise]; with
    /// --noise or --time, the most a pixel takes [default: 1024]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub(crate) spp: Option<u32>,

    #[command(flatten)]
    pub(crate) adaptive: AdaptiveArgs,

    #[command(flatten)]
    pub(crate) lighting: LightingArgs,

    /// Also write arbitrary output variables beside the output, as OUTPUT.NAME.exr (names
    /// separated by commas)
    #[arg(long, value_delimiter = ',', value_parser = aov_parser())]
    pub(crate) aov: Vec<Integrator>,

    /// Where samples go in a pixel, and how the first bounce's light and direction samples are
    /// spread over them [default: center for 1 spp, stratified otherwise]
    #[arg(long, value_enum)]
    pub(crate) sampler: Option<PixelSampler>,

    #[command(flatten)]
    pub(crate) seed: SeedArgs,

    #[command(flatten)]
    pub(crate) threads: ThreadArgs,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    #[command(flatten)]
    pub(crate) tone: ToneArgs,

    /// Smooth the noise of a PNG across surfaces, keeping edges (an albedo-, normal- and
    /// depth-guided filter): auto denoises PNG output of the direct and path integrators and
    /// never EXR or .accum files, which keep the unbiased estimate
    #[arg(long, value_enum, default_value_t = Denoise::Auto)]
    pub(crate) denoise: Denoise,

    /// Radiance of camera rays that hit nothing and see no environment, as R,G,B
    #[arg(long, value_parser = parse_colour, default_value = "0.05,0.05,0.06", allow_hyphen_values = true)]
    pub(crate) background: Vec3,

    #[command(flatten)]
    pub(crate) job: crate::render_job::JobArgs,

    /// Print the summary as JSON (the plan, the camera and how it was chosen, the exposure, the
    /// times and the files written) instead of text; warnings and notes still go to standard error
    #[arg(long)]
    pub(crate) json: bool,
}

impl RenderArgs {
    /// Where the image goes: `-o`, else the scene's name with `.png` in the
    /// current folder (`cornell-box.png` for the built-in scene).
    pub(crate) fn output(&self) -> PathBuf {
        self.output.or_named_after(self.scene.as_deref(), ".png")
    }

    /// Image width, height and samples per pixel (the most a pixel takes,
    /// when sampling adapts), after `--quick`.
    pub(crate) fn resolution(&self) -> (u32, u32, u32) {
        let default = if self.adaptive.sampling().is_some() {
            ADAPTIVE_SPP
        } else if self.lighting.integrator.simulates_light() {
            16
        } else {
            1
        };
        let spp = self.spp.unwrap_or(default);
        if self.quick {
            ((self.size.width() / 4).max(16), (self.size.height() / 4).max(16), spp.min(4))
        } else {
            (self.size.width(), self.size.height(), spp)
        }
    }
}

/// The most samples a pixel takes with `--noise` or `--time` when `--spp` is not given.
pub(crate) const ADAPTIVE_SPP: u32 = 1024;

/// Adaptive sampling: rounds of 16, 32, 64, ... samples, each pixel
/// stopping when its noise is low enough ([`rtgi_render::adaptive`]).
#[derive(Args, Debug, Clone, Default)]
pub(crate) struct AdaptiveArgs {
    /// Sample each pixel until the standard error of its mean is at most this fraction of it
    /// (0.02 for 2%), checked after 16, 32, 64, ... samples; deterministic: the same seed and
    /// options give the same image on any machine. Not with --samples, --tile, --resume,
    /// --checkpoint, --time-limit or .accum output: a pixel's stop depends on all its samples
    #[arg(long, value_name = "FRACTION", value_parser = parse_noise)]
    pub(crate) noise: Option<f32>,

    /// Render in rounds of doubling samples until the next round is predicted to end after
    /// SECONDS (with --noise, whichever stops first); it then prints the --spp that renders the
    /// same image without a time bound
    #[arg(long, value_name = "SECONDS", value_parser = crate::render_job::parse_seconds)]
    pub(crate) time: Option<f64>,
}

impl AdaptiveArgs {
    /// The adaptive sampling asked for, if any.
    pub(crate) fn sampling(&self) -> Option<rtgi_render::AdaptiveSampling> {
        (self.noise.is_some() || self.time.is_some())
            .then_some(rtgi_render::AdaptiveSampling { noise: self.noise, seconds: self.time })
    }
}

fn parse_noise(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|n| n.is_finite() && *n > 0.0 && *n < 1.0)
        .ok_or_else(|| format!("expected a fraction between 0 and 1, like 0.02 for 2% (got '{text}')"))
}

/// The arbitrary output variables: the integrators that compute a property
/// of the closest hit ([`Integrator::is_aov`]), named as `ValueEnum` names them.
fn aov_parser() -> impl TypedValueParser<Value = Integrator> {
    let aovs = Integrator::value_variants().iter().filter(|i| i.is_aov()).filter_map(ValueEnum::to_possible_value);
    PossibleValuesParser::new(aovs).map(|name| ValueEnum::from_str(&name, false).expect("one of the possible values"))
}

/// Whether `rtgi render` denoises its image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Denoise {
    /// PNG output of the direct and path integrators
    Auto,
    /// Every image of a light-simulating integrator, EXR included
    On,
    /// Never: the image is the samples' mean
    Off,
}

/// How an image becomes 8-bit PNG (EXR keeps linear floats): shared by `render` and `merge`.
#[derive(Debug, Args)]
pub(crate) struct ToneArgs {
    /// Exposure in stops, for PNG output [default: automatic for the direct and path integrators
    /// (the image's log-average luminance brought to middle grey, highlights kept), 0 otherwise]
    #[arg(long, value_parser = parse_exposure, allow_negative_numbers = true)]
    pub(crate) exposure: Option<f32>,

    /// Tone map for PNG output [default: aces for the direct and path integrators, clamp otherwise]
    #[arg(long, value_enum)]
    pub(crate) tonemap: Option<ToneOperator>,
}

/// Worker threads: shared by every command that runs in parallel.
#[derive(Debug, Args)]
pub(crate) struct ThreadArgs {
    /// Worker threads: every thread that works, loading and building included [default:
    /// $RTGI_THREADS, else one per core]
    #[arg(short = 't', long = "threads", value_parser = clap::value_parser!(u32).range(1..=MAX_THREADS as i64))]
    count: Option<u32>,
}

/// Most worker threads accepted by `--threads` and `RTGI_THREADS`.
const MAX_THREADS: u32 = 1024;

impl ThreadArgs {
    /// `--threads`, else `RTGI_THREADS`; `None` for one per core.
    pub(crate) fn count(&self) -> anyhow::Result<Option<u32>> {
        match self.count {
            Some(count) => Ok(Some(count)),
            None => threads_from_environment(),
        }
    }

    /// A pool of that many worker threads.
    pub(crate) fn pool(&self) -> anyhow::Result<rayon::ThreadPool> {
        crate::common::thread_pool(self.count()?)
    }
}

impl Command {
    /// The worker threads the command asks for: `--threads`, else
    /// `RTGI_THREADS` (which commands without `--threads` read too); `None`
    /// for one per core.
    pub(crate) fn threads(&self) -> anyhow::Result<Option<u32>> {
        let args = match self {
            Command::Render(args) => &args.threads,
            Command::Trace(args) => &args.threads,
            Command::Bench(args) => &args.threads,
            Command::Heatmap(args) => &args.threads,
            Command::BenchEffects(args) => &args.threads,
            Command::Verify(args) => &args.threads,
            Command::Experiment(args) => &args.threads,
            Command::Script(args) | Command::Repl(args) => &args.threads,
            Command::BvhBoxes(_)
            | Command::Info(_)
            | Command::Compare(_)
            | Command::Merge(_)
            | Command::Gallery(_)
            | Command::Rays(_) => return threads_from_environment(),
        };
        args.count()
    }
}

/// The environment variable that sets the worker threads of every command
/// (a cluster task's CPUs, say); `--threads` overrides it.
pub(crate) const THREADS_VARIABLE: &str = "RTGI_THREADS";

/// `RTGI_THREADS`, checked as clap checks `--threads`.
fn threads_from_environment() -> anyhow::Result<Option<u32>> {
    let Some(value) = std::env::var_os(THREADS_VARIABLE) else { return Ok(None) };
    let value = value.to_string_lossy();
    match value.trim().parse::<u32>() {
        Ok(count) if (1..=MAX_THREADS).contains(&count) => Ok(Some(count)),
        _ => anyhow::bail!("{THREADS_VARIABLE}={value}: expected a number of threads from 1 to {MAX_THREADS}"),
    }
}

/// The seed: shared by every command that draws random numbers (`render`'s
/// samples, the rays of `verify`, `bench` and `rays`).
#[derive(Debug, Args)]
pub(crate) struct SeedArgs {
    /// Seed of the random numbers; the same seed gives the same result
    #[arg(long = "seed", value_name = "SEED", default_value_t = 0)]
    pub(crate) value: u64,
}

/// The one file a command writes: shared by the commands that name it
/// after their input when `-o` is not given (each says how in its help).
#[derive(Debug, Args)]
pub(crate) struct OutputArgs {
    /// The file to write [default: named after the scene, in the current folder]
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
}

impl OutputArgs {
    /// `-o`, else the file name of `input` without its extension, followed
    /// by `suffix`, in the current folder (`cornell-box` for the built-in scene).
    pub(crate) fn or_named_after(&self, input: Option<&Path>, suffix: &str) -> PathBuf {
        if let Some(output) = &self.output {
            return output.clone();
        }
        let stem = input.map_or("cornell-box".into(), |path| {
            path.file_stem().map_or("render".into(), |stem| stem.to_string_lossy().into_owned())
        });
        PathBuf::from(format!("{stem}{suffix}"))
    }
}

/// The size of an image in pixels.
#[derive(Debug, Args)]
pub(crate) struct ImageSize {
    /// Width in pixels [default: 512, or to match the aspect ratio of a camera from the scene file that has one]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    width: Option<u32>,

    /// Height in pixels [default: 512, or to match the aspect ratio of a camera from the scene file that has one]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    height: Option<u32>,
}

/// The side of an image when neither --width nor --height says otherwise.
const DEFAULT_IMAGE_SIDE: u32 = 512;

impl ImageSize {
    pub(crate) fn width(&self) -> u32 {
        self.width.unwrap_or(DEFAULT_IMAGE_SIDE)
    }

    pub(crate) fn height(&self) -> u32 {
        self.height.unwrap_or(DEFAULT_IMAGE_SIDE)
    }

    pub(crate) fn aspect(&self) -> f32 {
        self.width() as f32 / self.height() as f32
    }

    /// Whether --width or --height was given.
    pub(crate) fn given(&self) -> bool {
        self.width.is_some() || self.height.is_some()
    }
}

/// `width` × `height` reshaped to `aspect` (width over height), the longer
/// side kept: how an image follows a file camera's aspect ratio.
pub(crate) fn reshaped(width: u32, height: u32, aspect: f32) -> (u32, u32) {
    let side = width.max(height) as f32;
    let clamp = |x: f32| (x.round() as u32).clamp(1, MAX_IMAGE_SIDE);
    if aspect >= 1.0 { (clamp(side), clamp(side / aspect)) } else { (clamp(side * aspect), clamp(side)) }
}

/// The acceleration structure and its build parameters.
#[derive(Debug, Args)]
pub(crate) struct AccelArgs {
    /// Acceleration structure (in builds with the embree feature also embree, Intel Embree 3)
    #[arg(long, default_value = "bvh8", value_parser = AccelParser { list: false }.map(|list| list.0[0]))]
    pub(crate) accel: AccelKind,

    #[command(flatten)]
    pub(crate) build: BuildArgs,
}

/// Build parameters of the BVH variants.
#[derive(Debug, Args)]
pub(crate) struct BuildArgs {
    /// Most triangles in a BVH leaf [default: 4; 8 for the wide BVHs]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub(crate) leaf_size: Option<u32>,

    /// Bins per axis of the binned SAH build
    #[arg(long, default_value_t = BuildParams::default().sah_bins as u32, value_parser = clap::value_parser!(u32).range(2..=256))]
    pub(crate) sah_bins: u32,

    /// Axes the binned SAH build tries planes on: all three, or only the longest (the course's
    /// SAH, with --sah-bins minus one planes)
    #[arg(long, value_enum, default_value_t = SahAxes::All)]
    pub(crate) sah_axes: SahAxes,

    /// Cost of a BVH traversal step relative to a leaf test (a ray/triangle test; for the wide BVHs, a block of four triangles tested at once), for the SAH [default: 1]
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    pub(crate) traversal_cost: Option<f32>,

    /// Ray/triangle test
    #[arg(long, value_enum, default_value_t = Intersector::default())]
    pub(crate) intersector: Intersector,

    /// Slab test of the binary BVHs (the wide BVHs always use the robust one)
    #[arg(long, value_enum, default_value_t = Traversal::default())]
    pub(crate) traversal: Traversal,
}

impl BuildArgs {
    /// The parameters for `kind`: its own defaults
    /// ([`AccelKind::default_params`]), with the options given on the
    /// command line in their place.
    pub(crate) fn params_for(&self, kind: AccelKind) -> BuildParams {
        let defaults = kind.default_params();
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

impl AccelArgs {
    /// Builds the chosen structure over the scene's triangles.
    pub(crate) fn build(&self, scene: &rtgi_scene::Scene) -> Result<Box<dyn rtgi_accel::Accel>, BuildError> {
        self.accel.try_build(&scene.triangle_positions(), &self.build.params_for(self.accel))
    }
}

/// Camera options; any given override the scene's camera (or the automatic framing).
#[derive(Debug, Default, Args)]
pub(crate) struct CameraArgs {
    /// Which of the scene's cameras to use, counting from 0 [default: the first]
    #[arg(long)]
    pub(crate) camera: Option<usize>,

    /// Camera position, as X,Y,Z (it looks at the scene's centre unless --look is given)
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) at: Option<Vec3>,

    /// Point the camera looks at, as X,Y,Z
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) look: Option<Vec3>,

    /// World up direction, as X,Y,Z
    #[arg(long, value_parser = parse_direction, allow_hyphen_values = true)]
    pub(crate) up: Option<Vec3>,

    /// Vertical field of view in degrees, greater than 0 and less than 180
    #[arg(long, value_parser = parse_fov, allow_negative_numbers = true)]
    pub(crate) fov: Option<f32>,
}

/// Parses "x,y,z" into a vector of finite numbers.
pub(crate) fn parse_vec3(text: &str) -> Result<Vec3, String> {
    rtgi_math::parse_vec3(text)
        .ok_or_else(|| format!("expected three finite numbers separated by commas, like 0,1.5,-2 (got '{text}')"))
}

/// Prints a command-line error as one line (help and version as clap writes them).
pub(crate) fn report_parse_error(error: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(error.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion)
        || error.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    {
        let _ = error.print();
        return ExitCode::from(if error.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand { 2 } else { 0 });
    }
    eprintln!("error: {}", parse_error_line(&error));
    ExitCode::from(2)
}

/// One line for a parse error, made from clap's error kind, its context
/// (the argument, the value, the valid values, a suggestion) and, for a
/// value our parsers refused, their own message: not from clap's printed text.
fn parse_error_line(error: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let context = |kind: ContextKind| -> Option<String> {
        error.get(kind).map(|value| match value {
            ContextValue::String(s) => s.clone(),
            ContextValue::Strings(list) => list.join(", "),
            ContextValue::StyledStr(styled) => styled.to_string(),
            ContextValue::StyledStrs(list) => list.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", "),
            ContextValue::Number(n) => n.to_string(),
            other => other.to_string(),
        })
    };
    let argument = context(ContextKind::InvalidArg).unwrap_or_default();
    let value = context(ContextKind::InvalidValue).unwrap_or_default();
    let mut line = match error.kind() {
        ErrorKind::ValueValidation => {
            let why = std::error::Error::source(error).map(|e| e.to_string()).unwrap_or_default();
            format!("invalid value '{value}' for '{argument}': {why}")
        }
        ErrorKind::InvalidValue => format!("invalid value '{value}' for '{argument}'"),
        ErrorKind::UnknownArgument => format!("unexpected argument '{argument}'"),
        ErrorKind::InvalidSubcommand => {
            format!("unrecognized subcommand '{}'", context(ContextKind::InvalidSubcommand).unwrap_or_default())
        }
        ErrorKind::MissingRequiredArgument => format!("the following required arguments were not provided: {argument}"),
        ErrorKind::ArgumentConflict => {
            let other = context(ContextKind::PriorArg).unwrap_or_default();
            if other == argument {
                format!("the argument '{argument}' cannot be used multiple times")
            } else {
                format!("the argument '{argument}' cannot be used with '{other}'")
            }
        }
        ErrorKind::TooManyValues => format!("unexpected value '{value}' for '{argument}'"),
        ErrorKind::TooFewValues | ErrorKind::WrongNumberOfValues => {
            let expected = context(ContextKind::ExpectedNumValues).unwrap_or_default();
            format!("'{argument}' takes {expected} value(s)")
        }
        ErrorKind::NoEquals => format!("'{argument}' needs a value after '='"),
        kind if !argument.is_empty() => format!("{kind}: '{argument}'"),
        kind => kind.to_string(),
    };
    if let Some(valid) = context(ContextKind::ValidValue) {
        line.push_str(&format!(" (possible values: {valid})"));
    }
    let suggestion = [ContextKind::SuggestedArg, ContextKind::SuggestedSubcommand, ContextKind::SuggestedValue]
        .into_iter()
        .find_map(context);
    if let Some(suggestion) = suggestion {
        line.push_str(&format!("; did you mean '{suggestion}'?"));
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_and_reject_garbage() {
        assert_eq!(parse_vec3("1, -2.5,3e2"), Ok(Vec3::new(1.0, -2.5, 300.0)));
        for bad in ["1,2", "1,2,3,4", "a,b,c", "1,2,nan", "1,inf,2", ""] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn numbers_outside_their_range_are_refused_with_the_range() {
        assert_eq!(parse_exposure("-2.5"), Ok(-2.5));
        assert_eq!(parse_fov(" 45 "), Ok(45.0));
        assert_eq!(parse_positive("1e-3"), Ok(1e-3));
        for (result, range) in [
            (parse_exposure("nan"), "from -64 to 64"),
            (parse_exposure("65"), "from -64 to 64"),
            (parse_fov("0"), "greater than 0"),
            (parse_fov("inf"), "less than 180"),
            (parse_positive("-1"), "greater than 0"),
            (parse_positive("0"), "greater than 0"),
            (parse_positive("abc"), "greater than 0"),
        ] {
            assert!(result.as_ref().is_err_and(|e| e.contains(range)), "{result:?}");
        }
        assert_eq!(parse_colour("0,0.5,2"), Ok(Vec3::new(0.0, 0.5, 2.0)));
        assert!(parse_colour("-0.1,0,0").is_err() && parse_colour("nan,0,0").is_err());
        assert_eq!(parse_direction("0,-1,0"), Ok(Vec3::NEG_Y));
        assert!(parse_direction("0,0,0").is_err() && parse_direction("0,inf,0").is_err());
        assert!(parse_light("point:0,1,0:5:1,-1,1").is_err_and(|e| e.contains("at least 0")));
    }

    /// `ValueEnum` (what clap parses and lists) and `ALL`/`name()` (what
    /// the libraries list, print and parse) must name the same choices.
    #[test]
    fn value_enums_agree_with_the_named_choices() {
        fn agree<T: ValueEnum + PartialEq + std::fmt::Debug>(all: &[T], name: fn(&T) -> &'static str) {
            assert_eq!(T::value_variants(), all);
            for value in T::value_variants() {
                let possible = value.to_possible_value().expect("no variant is skipped");
                assert_eq!(possible.get_name(), name(value), "{value:?}");
            }
        }
        let accels: Vec<AccelKind> = AccelKind::ALL.iter().chain(AccelKind::PEERS).copied().collect();
        agree(&accels, |k| k.name());
        agree(Intersector::ALL, |i| i.name());
        agree(Traversal::ALL, |t| t.name());
        agree(rtgi_accel::simd::SimdLevel::ALL, |l| l.name());
        agree(ToneOperator::ALL, |t| t.name());
        agree(PixelSampler::ALL, |p| p.name());
        agree(rtgi_render::Effect::ALL, |e| e.name());
        agree(Integrator::ALL, |i| i.name());
        agree(DirectStrategy::ALL, |d| d.name());
    }

    #[test]
    fn command_line_is_well_formed() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
