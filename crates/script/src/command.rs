//! The commands of the course framework's language, as data: what a line
//! says, with its numbers read and its names resolved, and nothing done
//! yet. Doing them is the interpreter's business (in the app, `rtgi
//! script`'s session).

use std::path::PathBuf;

use rtgi_accel::AccelKind;
use rtgi_math::{Mat4, Vec3};
use rtgi_render::BounceSampling;

use crate::brdf::CourseBrdf;

/// One line of a script.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// A blank line or a comment (`#`, `//`).
    Nothing,
    /// `at [X Y Z]`: the camera's position, or print it.
    At(Option<Vec3>),
    /// `look [X Y Z]`: the camera's direction, or print it.
    Look(Option<Vec3>),
    /// `up [X Y Z]`: the scene's up (and the camera's, unless `camup` set it), or print it.
    Up(Option<Vec3>),
    /// `camup [X Y Z]`: the camera's up, or print it.
    CamUp(Option<Vec3>),
    /// `print-cam`.
    PrintCam,
    /// `load FILE [NAME]`: adds a file's meshes to the scene.
    Load {
        /// The file, as typed (the interpreter resolves it).
        file: PathBuf,
        /// The name the course gives the loaded object, if any.
        name: Option<String>,
    },
    /// `modelpath DIR`: a folder `load` also looks in.
    ModelPath(PathBuf),
    /// `modelmatrix` with 16 numbers, column by column as the framework's
    /// glm reads them (the translation last): the transform of later loads.
    ModelMatrix(Mat4),
    /// `modeltrafo ...`: multiplies the transform of later loads.
    ModelTrafo(Mat4),
    /// `resolution W H`.
    Resolution(u32, u32),
    /// `sppx N`: samples per pixel.
    Sppx(u32),
    /// `outfile FILE`: where `run` writes.
    Outfile(PathBuf),
    /// `commit`: builds the acceleration structure over the scene.
    Commit,
    /// `run`: renders and writes the image.
    Run,
    /// `raytracer NAME ...`.
    Raytracer(Tracer),
    /// `bvh ...`: the BVH plug-in's settings and reports.
    Bvh(BvhCommand),
    /// `algo NAME`.
    Algo(Algo),
    /// `is uniform|cosine|light|brdf`: how `algo direct` samples.
    Is(DirectSampling),
    /// `path ...`: the path tracers' settings.
    Path(PathSetting),
    /// `material ...`.
    Material(MaterialCommand),
    /// `default-brdf NAME`: the BRDF of materials loaded later.
    DefaultBrdf(CourseBrdf),
    /// `pointlight [replace] pos X Y Z col R G B`.
    PointLight {
        /// `replace`: instead of the point lights so far, not beside them.
        replace: bool,
        /// `pos X Y Z`.
        position: Vec3,
        /// `col R G B`: the intensity, each at least 0.
        colour: Vec3,
    },
    /// `skylight load FILE SCALE`.
    SkylightLoad {
        /// The `.floats` file: width, height, then RGB float triples.
        file: PathBuf,
        /// The intensity scale, finite and above 0.
        scale: f32,
    },
    /// `skylight scale S`.
    SkylightScale(f32),
    /// `echo TEXT`.
    Echo(String),
    /// `stats print`.
    StatsPrint,
    /// `stats clear`.
    StatsClear,
    /// `mem-stats`.
    MemStats,
    /// `history`.
    History,
    /// `quit` or `exit`.
    Quit,
    /// `omp on|off`: all cores, or one thread.
    Omp(bool),
    /// `platform [NAME]`: only `cpu` and `none` (the same here) exist.
    Platform(Option<String>),
    /// `denoise on|off`.
    Denoise(bool),
    /// `disable FEATURE`: `with FEATURE { }` blocks are then skipped.
    Disable(String),
    /// `with gl|cuda|optix {`: a block for a feature.
    With(String),
    /// `}`: the end of a `with` block.
    EndBlock,
    /// A command of the framework's for something rtgi does not have (the
    /// preview window, wavefront steps, the sky's debug output): said in
    /// one line, and the script goes on.
    Unavailable {
        /// The framework's command.
        command: &'static str,
        /// What it is for, which rtgi lacks.
        feature: &'static str,
    },
    /// `algo primary-wf|direct-wf`: a wavefront algorithm, rendered by its
    /// CPU counterpart.
    WavefrontAlgo {
        /// The course's name of the wavefront algorithm.
        name: &'static str,
        /// The algorithm that renders the same image.
        instead: Algo,
    },
}

/// `raytracer NAME`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tracer {
    /// `seq`: the linear scan.
    Seq,
    /// `naive-bvh`: object median, one triangle a leaf.
    NaiveBvh,
    /// `bbvh [om|sm|sah [NPLANES]]` (and the framework's `indexed`/`esc`
    /// layouts, which change nothing here): the binary BVH.
    Bbvh(Option<(CourseSplit, Option<u32>)>),
    /// `embree` (and `embree-alpha`).
    Embree,
    /// One of ours by its own name: `bvh4`, `bvh8`, `sah`, `sah-sweep`, ...
    Ours(AccelKind),
}

/// The course's split methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CourseSplit {
    /// `om`: at the median of the triangles' centroids.
    ObjectMedian,
    /// `sm`: at the middle of the node's box.
    SpatialMedian,
    /// `sah`: by the surface area heuristic.
    Sah,
}

/// `bvh ...`.
#[derive(Clone, Debug, PartialEq)]
pub enum BvhCommand {
    /// `bvh om|sm|sah [NPLANES]`.
    Split(CourseSplit, Option<u32>),
    /// `bvh triangles single|multiple N`: the most triangles a leaf holds.
    LeafSize(u32),
    /// `bvh statistics`.
    Statistics,
    /// `bvh export DEPTH FILE.obj`.
    Export {
        /// The deepest level of boxes written.
        depth: usize,
        /// The OBJ file written.
        file: PathBuf,
    },
}

/// `algo NAME`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algo {
    /// `primary`: the albedo at the first hit.
    Primary,
    /// `info`: the course's pixel inspector.
    Info,
    /// `local`: lit by one point light.
    Local,
    /// `direct`: direct light, sampled as `is` says.
    Direct,
    /// `direct/mis`: direct light, light and BRDF samples weighed.
    DirectMis,
    /// `simple-pt`: a path tracer sampling the BSDF only.
    SimplePt,
    /// `pt`: a path tracer with next-event estimation.
    Pt,
}

impl Algo {
    /// The name the course gives it.
    pub fn name(self) -> &'static str {
        match self {
            Algo::Primary => "primary",
            Algo::Info => "info",
            Algo::Local => "local",
            Algo::Direct => "direct",
            Algo::DirectMis => "direct/mis",
            Algo::SimplePt => "simple-pt",
            Algo::Pt => "pt",
        }
    }
}

/// `is uniform|cosine|light|brdf`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectSampling {
    /// Directions uniform over the hemisphere.
    Uniform,
    /// Directions by the cosine.
    Cosine,
    /// Points on the lights (the course's default).
    Light,
    /// Directions by the BRDF.
    Brdf,
    /// Light and BRDF samples weighed (older scripts of the course say
    /// `is mis` for what `algo direct/mis` does).
    Mis,
}

impl DirectSampling {
    /// The name `is` gives it.
    pub fn name(self) -> &'static str {
        match self {
            DirectSampling::Uniform => "uniform",
            DirectSampling::Cosine => "cosine",
            DirectSampling::Light => "light",
            DirectSampling::Brdf => "brdf",
            DirectSampling::Mis => "mis",
        }
    }
}

/// `path ...`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathSetting {
    /// `path len N`: rays a path traces at most.
    Length(u32),
    /// `path rr-start N`: bounces before Russian roulette.
    RouletteStart(u32),
    /// `path bounce uniform|cosine|brdf`.
    Bounce(BounceSampling),
    /// `path mis on|off`.
    Mis(bool),
}

/// `material ...`.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialCommand {
    /// `list`: the materials' names.
    List,
    /// `select NAME`: the material later settings change (names may hold spaces).
    Select(String),
    /// `blacklist NAME`: files loaded later leave out the triangles of materials of this name.
    Blacklist(String),
    /// `albedo R G B`, each at least 0.
    Albedo(Vec3),
    /// `emissive R G B`, each at least 0.
    Emissive(Vec3),
    /// `roughness F`: the course's (the GGX width), at least 0.
    Roughness(f32),
    /// `ior F`, above 0.
    Ior(f32),
    /// `texture FILE` or `texture drop` (`None`).
    Texture(Option<PathBuf>),
    /// `brdf NAME`.
    Brdf(CourseBrdf),
    /// `show`: the selected material's settings.
    Show,
}
