//! The option groups several commands share (lighting, camera, structure,
//! image size, tone map, threads, seed, output), and how each becomes the
//! libraries' typed values. A command's own options live in its file.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, ValueEnum};
use rtgi_accel::{AccelKind, BuildError, BuildParams, Intersector, SahAxes, Traversal};
use rtgi_image::ToneOperator;
use rtgi_job::{DEFAULT_IMAGE_SIDE, MAX_IMAGE_SIDE, Structure};
use rtgi_math::Vec3;
use rtgi_render::recipe::{CameraChoice, Lighting};
use rtgi_render::{BounceSampling, DirectStrategy, EffectOverrides, EnvironmentSpec, EnvironmentSpecError, Integrator};
use rtgi_scene::{Light, LightSpecError, LoadOptions};

/// `--allow-outside-scene`, set once by `main` for every command.
pub(crate) static ALLOW_OUTSIDE_SCENE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// `--variant`, set once by `main` for every command.
pub(crate) static GLTF_VARIANT: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();

/// How scene files are loaded: `--allow-outside-scene` and `--variant`.
pub(crate) fn load_options() -> LoadOptions {
    LoadOptions {
        allow_outside_folder: ALLOW_OUTSIDE_SCENE.get() == Some(&true),
        gltf_variant: GLTF_VARIANT.get().cloned().flatten(),
        ..LoadOptions::default()
    }
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

pub(crate) fn parse_positive(text: &str) -> Result<f32, String> {
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
        Ok(rtgi_job::thread_pool(self.count()?)?)
    }
}

/// The environment variable that sets the worker threads of every command
/// (a cluster task's CPUs, say); `--threads` overrides it.
pub(crate) const THREADS_VARIABLE: &str = "RTGI_THREADS";

/// `RTGI_THREADS`, checked as clap checks `--threads`.
pub(crate) fn threads_from_environment() -> anyhow::Result<Option<u32>> {
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
pub(crate) struct ImageSizeArgs {
    /// Width in pixels [default: 512, or to match the aspect ratio of a camera from the scene file that has one]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) width: Option<u32>,

    /// Height in pixels [default: 512, or to match the aspect ratio of a camera from the scene file that has one]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) height: Option<u32>,
}

impl ImageSizeArgs {
    pub(crate) fn width(&self) -> u32 {
        self.width.unwrap_or(DEFAULT_IMAGE_SIDE)
    }

    pub(crate) fn height(&self) -> u32 {
        self.height.unwrap_or(DEFAULT_IMAGE_SIDE)
    }

    pub(crate) fn aspect(&self) -> f32 {
        self.width() as f32 / self.height() as f32
    }
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
    #[arg(long, value_parser = clap::value_parser!(u32).range(range_of(BuildParams::LEAF_SIZES)))]
    pub(crate) leaf_size: Option<u32>,

    /// Bins per axis of the binned SAH build
    #[arg(long, default_value_t = BuildParams::default().sah_bins as u32, value_parser = clap::value_parser!(u32).range(range_of(BuildParams::SAH_BINS)))]
    pub(crate) sah_bins: u32,

    /// Axes the binned SAH build tries planes on: all three, or only the longest (the course's
    /// SAH, with --sah-bins minus one planes)
    #[arg(long, value_enum, default_value_t = SahAxes::All)]
    pub(crate) sah_axes: SahAxes,

    /// Cost of a BVH traversal step relative to a leaf test (a ray/triangle test; for the wide BVHs, a block of four triangles tested at once), for the SAH [default: 1; for the wide BVHs 2/width: 1/2 for bvh4, 1/4 for the eight-wide]
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    pub(crate) traversal_cost: Option<f32>,

    /// Ray/triangle test
    #[arg(long, value_enum, default_value_t = Intersector::default())]
    pub(crate) intersector: Intersector,

    /// Slab test of the binary BVHs (the wide BVHs always use the robust one)
    #[arg(long, value_enum, default_value_t = Traversal::default())]
    pub(crate) traversal: Traversal,
}

/// A library's range of counts as clap's ranges take them.
fn range_of(range: std::ops::RangeInclusive<usize>) -> std::ops::RangeInclusive<i64> {
    *range.start() as i64..=*range.end() as i64
}

impl BuildArgs {
    /// `kind` with these build options ([`Structure`]).
    pub(crate) fn structure(&self, kind: AccelKind) -> Structure {
        Structure {
            kind,
            leaf_size: self.leaf_size,
            sah_bins: self.sah_bins,
            sah_axes: self.sah_axes,
            traversal_cost: self.traversal_cost,
            intersector: self.intersector,
            traversal: self.traversal,
        }
    }

    /// The parameters for `kind`: its own defaults
    /// ([`AccelKind::default_params`]), with the options given on the
    /// command line in their place.
    pub(crate) fn params_for(&self, kind: AccelKind) -> BuildParams {
        self.structure(kind).params()
    }
}

impl AccelArgs {
    /// The structure and its parameters.
    pub(crate) fn structure(&self) -> Structure {
        self.build.structure(self.accel)
    }

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

impl CameraArgs {
    /// The camera options as the recipe takes them.
    pub(crate) fn choice(&self) -> CameraChoice {
        CameraChoice { index: self.camera, at: self.at, look: self.look, up: self.up, fov_degrees: self.fov }
    }
}

impl LightingArgs {
    /// The lighting options as the recipe takes them; `--filter-glossy 0`
    /// is a threshold of 0 (off), no `--filter-glossy` none (automatic).
    pub(crate) fn lighting(&self) -> Lighting {
        Lighting {
            lights: self.lights.clone(),
            integrator: self.integrator,
            max_depth: self.max_depth,
            roulette_start: self.roulette_start,
            bounce_sampling: self.bounce_sampling,
            direct_strategy: self.direct_strategy,
            indirect_clamp: self.clamp_indirect,
            filter_glossy: self.filter_glossy.map(rtgi_render::FilterGlossy::all_lobes),
            environment: self.environment.clone(),
            environment_scale: self.environment_scale,
            effects: self.effects.clone(),
            no_default_lighting: self.no_default_lighting,
        }
    }
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
}
