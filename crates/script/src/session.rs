//! The state a script builds up, command by command, as the course
//! framework keeps it: the camera, the scene and its materials, the ray
//! tracer and whether its structure is up to date, the algorithm and its
//! options. `run` turns that state into a [`RenderRequest`] with the
//! session's scene and committed structure, which the front end renders
//! (and prints as the equivalent `rtgi render` command), so that a script
//! and that command write the same bytes.

use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::{Path, PathBuf};

use rtgi_accel::{Accel, AccelKind, BuildParams, SahAxes};
use rtgi_image::ToneOperator;
use rtgi_job::{Denoise, Given, ImageSize, LoadedScene, RenderRequest, SceneSource, Structure, Tone, Warning};
use rtgi_math::{Mat3, Mat4, Vec3};
use rtgi_render::recipe::CameraChoice;
use rtgi_render::{BounceSampling, DirectStrategy, EnvironmentSpec, Integrator};
use rtgi_scene::{ColorEncoding, LoadOptions, Scene, Texture, TextureId};

use crate::error::SessionError;
use crate::frontend::{Frontend, Run};
use crate::{
    Algo, BvhCommand, Command, CourseBrdf, CourseSplit, DirectSampling, MaterialCommand, PathSetting, Tracer,
    course_roughness, our_roughness,
};

/// A line for the front end to say, formatted as `println!` formats; its
/// failure (a reader gone) ends the command.
macro_rules! say {
    ($frontend:expr, $($arg:tt)*) => {
        $frontend.say(&::std::format!($($arg)*)).map_err(SessionError::Frontend)
    };
}

/// The command is refused, for the reason formatted.
macro_rules! refused {
    ($($arg:tt)*) => {
        SessionError::Refused(::std::format!($($arg)*))
    };
}

/// Returns the command refused, for the reason formatted.
macro_rules! refuse {
    ($($arg:tt)*) => {
        return Err(refused!($($arg)*))
    };
}

/// The course framework's camera defaults.
const COURSE_FOV_DEGREES: f32 = 65.0;
const COURSE_RESOLUTION: (u32, u32) = (1280, 720);
/// The course's default path length and roulette start (`path len`, `path rr-start`).
const COURSE_PATH_LENGTH: u32 = 10;
const COURSE_ROULETTE_START: u32 = 2;

/// What holds for a whole session, whatever its scripts say: what a front
/// end takes from its user (`rtgi script`'s options).
#[derive(Clone, Debug)]
pub struct SessionOptions {
    /// Where `run` writes until `outfile` says otherwise (`out.png`, as the course's).
    pub output: PathBuf,
    /// The seed of every render's samples.
    pub seed: u64,
    /// Worker threads for builds and renders; one per core when `None`
    /// (`omp off` makes it one).
    pub threads: Option<u32>,
    /// Folders `load` looks in after the current one, the script's and those `modelpath` adds.
    pub model_paths: Vec<PathBuf>,
    /// How `load` reads scene files (whether references may leave the scene's folder, the glTF variant).
    pub load: LoadOptions,
}

impl Default for SessionOptions {
    fn default() -> Self {
        Self {
            output: PathBuf::from("out.png"),
            seed: 0,
            threads: None,
            model_paths: Vec::new(),
            load: LoadOptions::default(),
        }
    }
}

/// What the session does after a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Go on with the next line.
    Continue,
    /// `quit` or `exit`: the session is over.
    Quit,
}

/// The camera as the course sets it: a position, a direction and up vectors.
#[derive(Clone, Copy, Debug)]
struct CourseCamera {
    position: Vec3,
    direction: Vec3,
    /// The scene's up (`up`), set at most once.
    scene_up: Option<Vec3>,
    /// The camera's up (`camup`, or `up` when no `camup` came first).
    up: Vec3,
    up_given: bool,
}

/// The tracer and its BVH options.
#[derive(Clone, Copy, Debug)]
struct TracerSetup {
    /// What the script named, for messages.
    name: &'static str,
    kind: AccelKind,
    leaf_size: u32,
    sah_bins: u32,
    sah_axes: SahAxes,
    /// Whether `bvh ...` commands apply (the course's BVH tracers).
    course_bvh: bool,
}

/// The algorithm and its options; a new `algo` starts from the defaults,
/// as the course's framework makes a new algorithm object.
#[derive(Clone, Copy, Debug)]
struct AlgoSetup {
    algo: Algo,
    sampling: DirectSampling,
    length: u32,
    roulette_start: u32,
    bounce: BounceSampling,
    mis: bool,
}

impl AlgoSetup {
    fn new(algo: Algo) -> Self {
        Self {
            algo,
            sampling: DirectSampling::Light,
            length: COURSE_PATH_LENGTH,
            roulette_start: COURSE_ROULETTE_START,
            bounce: BounceSampling::Bsdf,
            mis: false,
        }
    }
}

/// A material given a course BRDF: the course's albedo and roughness,
/// from which its fields are derived again after every edit.
#[derive(Clone, Copy, Debug)]
struct CourseLook {
    brdf: CourseBrdf,
    albedo: Vec3,
    roughness: f32,
}

/// One `run`, as `stats print` reports it.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// The image written.
    pub output: PathBuf,
    /// The algorithm.
    pub algo: Algo,
    /// The ray tracer, as the script named it.
    pub tracer: &'static str,
    /// Seconds spent rendering (not loading or building).
    pub seconds: f64,
    /// Rays traced.
    pub rays: u64,
}

/// Which command last changed what, to tell whether the structure is current.
#[derive(Clone, Copy, Debug, Default)]
struct Clock {
    now: u64,
    scene: Option<u64>,
    tracer: Option<u64>,
    commit: Option<u64>,
}

/// The state of a script or prompt session: feed it lines with
/// [`Session::execute`]; what they print, note and render goes through the
/// [`Frontend`] given with each line.
pub struct Session {
    options: SessionOptions,
    /// The script's folder, where `load` also looks.
    script_folder: Option<PathBuf>,
    camera: CourseCamera,
    model_matrix: Mat4,
    model_paths: Vec<PathBuf>,
    scene: Scene,
    /// The files loaded, as found.
    loaded: Vec<PathBuf>,
    /// Why no `rtgi render` command renders this scene (material edits,
    /// transforms, several files), if so.
    edits: BTreeSet<&'static str>,
    blacklist: Vec<String>,
    default_brdf: Option<CourseBrdf>,
    looks: HashMap<usize, CourseLook>,
    said: HashSet<String>,
    selected: Option<usize>,
    resolution: (u32, u32),
    sppx: u32,
    outfile: PathBuf,
    tracer: Option<TracerSetup>,
    algo: Option<AlgoSetup>,
    /// Point lights: position and colour (the intensity, per channel).
    point_lights: Vec<(Vec3, Vec3)>,
    sky: Option<(PathBuf, f32)>,
    one_thread: bool,
    /// `denoise on|off`: whether `run` denoises images of the light-simulating algorithms.
    denoise: bool,
    committed: Option<Box<dyn Accel>>,
    clock: Clock,
    runs: Vec<RunRecord>,
    history: Vec<String>,
    /// Inside a `with` block that is skipped.
    skipping: bool,
}

// By hand: the committed structure is a `dyn Accel`, and a scene's
// triangles are too many to print.
impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("loaded", &self.loaded)
            .field("camera", &self.camera)
            .field("tracer", &self.tracer)
            .field("committed", &self.committed.as_ref().map(|a| a.build_stats().variant.clone()))
            .field("algo", &self.algo)
            .field("outfile", &self.outfile)
            .finish_non_exhaustive()
    }
}

impl Session {
    /// A session as the course's framework starts one: no scene, the
    /// camera at the origin looking down -z, 1280×720, one sample a pixel.
    pub fn new(options: SessionOptions) -> Self {
        let outfile = options.output.clone();
        Self {
            model_paths: Vec::new(),
            options,
            script_folder: None,
            camera: CourseCamera {
                position: Vec3::ZERO,
                direction: Vec3::NEG_Z,
                scene_up: None,
                up: Vec3::Y,
                up_given: false,
            },
            model_matrix: Mat4::IDENTITY,
            scene: Scene::default(),
            loaded: Vec::new(),
            edits: BTreeSet::new(),
            blacklist: Vec::new(),
            default_brdf: None,
            looks: HashMap::new(),
            said: HashSet::new(),
            selected: None,
            resolution: COURSE_RESOLUTION,
            sppx: 1,
            outfile,
            tracer: None,
            algo: None,
            point_lights: Vec::new(),
            sky: None,
            one_thread: false,
            denoise: false,
            committed: None,
            clock: Clock::default(),
            runs: Vec::new(),
            history: Vec::new(),
            skipping: false,
        }
    }

    /// The runs since the last `stats clear`, first first.
    pub fn runs(&self) -> &[RunRecord] {
        &self.runs
    }

    /// Whether a `with` block is being skipped (its `}` not yet seen).
    pub fn in_skipped_block(&self) -> bool {
        self.skipping
    }

    /// Sets the folder of the script being run, where `load` also looks
    /// (`None` between scripts and at a prompt).
    pub fn set_script_folder(&mut self, folder: Option<PathBuf>) {
        self.script_folder = folder;
    }

    /// Runs one line, saying, noting and rendering through `f`. The error
    /// says what went wrong; the caller names the file, line and command. A
    /// refused line changes nothing but the history.
    pub fn execute(&mut self, line: &str, f: &mut dyn Frontend) -> Result<Flow, SessionError> {
        if self.skipping {
            if line.trim() == "}" {
                self.skipping = false;
            }
            return Ok(Flow::Continue);
        }
        // The framework keeps every line in the history, bad ones too.
        let trimmed = line.trim();
        if !trimmed.is_empty() && trimmed != "history" {
            self.history.push(trimmed.to_owned());
        }
        let command = crate::parse(line)?;
        self.clock.now += 1;
        self.apply(command, f)
    }

    fn apply(&mut self, command: Command, f: &mut dyn Frontend) -> Result<Flow, SessionError> {
        match command {
            Command::Nothing | Command::EndBlock => {}
            Command::At(None) => say!(f, "{}", triple(self.camera.position))?,
            Command::At(Some(p)) => self.camera.position = p,
            Command::Look(None) => say!(f, "{}", triple(self.camera.direction))?,
            Command::Look(Some(d)) if d == Vec3::ZERO => refuse!("the direction must not be 0 0 0"),
            Command::Look(Some(d)) => self.camera.direction = d,
            Command::Up(None) => say!(f, "{}", triple(self.camera.scene_up.unwrap_or(Vec3::Y)))?,
            Command::Up(Some(_)) if self.camera.scene_up.is_some() => {
                refuse!("cannot set the scene's up vector twice; did you mean camup?")
            }
            Command::Up(Some(up)) => {
                self.camera.scene_up = Some(up);
                if !self.camera.up_given {
                    self.camera.up = up;
                    self.camera.up_given = true;
                }
            }
            Command::CamUp(None) => say!(f, "{}", triple(self.camera.up))?,
            Command::CamUp(Some(up)) => {
                self.camera.up = up;
                self.camera.up_given = true;
            }
            Command::PrintCam => {
                say!(f, "at {}", triple(self.camera.position))?;
                say!(f, "look {}", triple(self.camera.direction))?;
                say!(f, "up {}", triple(self.camera.scene_up.unwrap_or(Vec3::Y)))?;
                say!(f, "camup {}", triple(self.camera.up))?;
            }
            Command::Load { file, .. } => self.load(f, &file)?,
            Command::ModelPath(folder) => self.model_paths.push(folder),
            Command::ModelMatrix(matrix) => self.model_matrix = matrix,
            Command::ModelTrafo(matrix) => self.model_matrix *= matrix,
            Command::Resolution(w, h) => self.resolution = (w, h),
            Command::Sppx(n) => self.sppx = n,
            Command::Outfile(file) => self.outfile = file,
            Command::Commit => self.commit()?,
            Command::Run => self.run(f)?,
            Command::Raytracer(tracer) => {
                self.tracer = Some(self.tracer_setup(f, tracer));
                self.clock.tracer = Some(self.clock.now);
            }
            Command::Bvh(command) => self.bvh(f, command)?,
            Command::Algo(algo) => {
                if algo == Algo::Local {
                    self.say_once(
                        f,
                        "algo local",
                        "algo local: rtgi shades with the point light's intensity, col / d² times the BRDF and the \
                         cosine, as its direct light does; the course's local multiplies by the light's power \
                         (4π col) instead, so its images are about 12.6 times brighter",
                    );
                }
                if algo == Algo::Info {
                    self.say_once(
                        f,
                        "algo info",
                        "algo info: rtgi has no pixel inspector; it renders the albedo at the hit, as primary does",
                    );
                }
                self.algo = Some(AlgoSetup::new(algo));
            }
            Command::Is(DirectSampling::Mis) => match &mut self.algo {
                Some(setup) if setup.algo == Algo::DirectMis => {}
                Some(setup) if setup.algo == Algo::Direct => {
                    *setup = AlgoSetup::new(Algo::DirectMis);
                    self.say_once(
                        f,
                        "is mis",
                        "is mis: algo direct now weighs light and BRDF samples, as algo direct/mis does",
                    );
                }
                other => refuse!(
                    "unknown command for {}: 'is' chooses how algo direct samples (select it first)",
                    algo_name(other.as_ref())
                ),
            },
            Command::Is(sampling) => match &mut self.algo {
                Some(setup) if setup.algo == Algo::Direct => setup.sampling = sampling,
                Some(setup) if setup.algo == Algo::DirectMis => refuse!(
                    "algo direct/mis samples the light and the BRDF and weighs them; 'is {}' chooses one strategy \
                     for algo direct",
                    sampling.name()
                ),
                other => refuse!(
                    "unknown command for {}: 'is' chooses how algo direct samples (select it first)",
                    algo_name(other.as_ref())
                ),
            },
            Command::WavefrontAlgo { name, instead } => {
                self.say_once(
                    f,
                    name,
                    &format!(
                        "algo {name}: rtgi has no wavefront algorithms; algo {} renders what it renders",
                        instead.name()
                    ),
                );
                self.algo = Some(AlgoSetup::new(instead));
            }
            Command::Path(setting) => self.path(setting)?,
            Command::Material(command) => self.material(f, command)?,
            Command::DefaultBrdf(brdf) => {
                if self.default_brdf.is_some() && !self.loaded.is_empty() {
                    say!(f, "Replacing a default brdf that has already been applied to some materials.")?;
                }
                self.default_brdf = Some(brdf);
            }
            Command::PointLight { replace, position, colour } => match self.point_lights.first_mut() {
                Some(first) if replace => *first = (position, colour),
                _ => self.point_lights.push((position, colour)),
            },
            Command::SkylightLoad { file, scale } => {
                let path = self.find(&file).ok_or_else(|| refused!("{}: no such file", file.display()))?;
                rtgi_render::Environment::load(&path)?;
                self.sky = Some((path, scale));
            }
            Command::SkylightScale(scale) => match &mut self.sky {
                Some((_, s)) => *s = scale,
                None => refuse!("there is no skylight to scale (skylight load FILE SCALE first)"),
            },
            Command::Echo(text) => say!(f, "{text}")?,
            Command::StatsPrint => self.print_stats(f)?,
            Command::StatsClear => self.runs.clear(),
            Command::MemStats => self.print_memory(f)?,
            Command::History => {
                for line in &self.history {
                    say!(f, "{line}")?;
                }
            }
            Command::Quit => return Ok(Flow::Quit),
            Command::Omp(on) => self.one_thread = !on,
            Command::Platform(None) => say!(f, "platform: none")?,
            Command::Platform(Some(name)) if name == "none" => {}
            Command::Platform(Some(name)) => self.say_once(
                f,
                "platform",
                &format!("platform {name}: rtgi has no GPU or wavefront platforms; rendering stays on the CPU"),
            ),
            Command::Denoise(on) => self.denoise = on,
            // Every `with` block is skipped already: rtgi has none of the features.
            Command::Disable(feature) => say!(f, "DISABLING {feature}")?,
            Command::With(feature) => {
                self.skipping = true;
                say!(f, "Skipping a block due to missing {feature} (rtgi has no {feature})")?;
            }
            Command::Unavailable { command, feature } => {
                self.say_once(f, feature, &format!("{command}: rtgi has no {feature}; the script goes on"))
            }
        }
        Ok(Flow::Continue)
    }

    /// Notes `message` the first time `key` comes up: a difference from
    /// the course is worth saying once, not at every line that meets it.
    fn say_once(&mut self, f: &mut dyn Frontend, key: &str, message: &str) {
        if self.said.insert(key.to_owned()) {
            f.note(message);
        }
    }

    /// Where files named relatively are looked for, after the current
    /// folder: the script's, then `modelpath`'s, then `--modelpath`'s.
    fn search_folders(&self) -> impl Iterator<Item = &PathBuf> {
        self.script_folder.iter().chain(&self.model_paths).chain(&self.options.model_paths)
    }

    /// A file as the script names it: as given, else in the script's
    /// folder, else in the model paths.
    fn find(&self, file: &Path) -> Option<PathBuf> {
        if file.is_absolute() || file.exists() {
            return file.exists().then(|| file.to_owned());
        }
        for folder in self.search_folders() {
            let candidate = folder.join(file);
            if candidate.exists() {
                return Some(candidate);
            }
            if let Some(script) = &self.script_folder
                && folder.is_relative()
                && script.join(folder).join(file).exists()
            {
                return Some(script.join(folder).join(file));
            }
        }
        None
    }

    fn load(&mut self, f: &mut dyn Frontend, file: &Path) -> Result<(), SessionError> {
        let path = self.find(file).ok_or_else(|| {
            let looked: Vec<String> = self.search_folders().map(|p| p.display().to_string()).collect();
            let where_ =
                if looked.is_empty() { String::new() } else { format!(" (also looked in {})", looked.join(", ")) };
            refused!("{}: no such file{where_}; modelpath DIR adds a folder to look in", file.display())
        })?;
        let source = SceneSource::File { path: path.clone(), options: self.options.load.clone() };
        let LoadedScene { mut scene, .. } = source.load()?;
        for message in &scene.warnings {
            f.warn(&Warning::Scene { message: message.clone() });
        }
        let before = scene.triangles.len();
        if !self.blacklist.is_empty() {
            let blacklisted: Vec<bool> = scene.materials.iter().map(|m| self.blacklist.contains(&m.name)).collect();
            scene.triangles.retain(|t| !blacklisted[t.material as usize]);
            if scene.triangles.len() != before {
                self.edits.insert("blacklisted materials");
            }
        }
        if self.model_matrix != Mat4::IDENTITY {
            transform(&mut scene, &self.model_matrix);
            self.edits.insert("model transforms");
        }
        let base = self.scene.materials.len();
        self.scene.append(scene);
        if let Some(brdf) = self.default_brdf {
            for index in base..self.scene.materials.len() {
                let material = &self.scene.materials[index];
                let look =
                    CourseLook { brdf, albedo: material.base_color, roughness: course_roughness(material.roughness) };
                self.set_look(f, index, look);
            }
            self.edits.insert("BRDFs");
        }
        self.loaded.push(path);
        if self.loaded.len() > 1 {
            self.edits.insert("several files");
        }
        self.clock.scene = Some(self.clock.now);
        Ok(())
    }

    fn set_look(&mut self, f: &mut dyn Frontend, index: usize, look: CourseLook) {
        if let Some(difference) = look.brdf.difference() {
            self.say_once(f, look.brdf.name(), &format!("brdf {}: {difference}", look.brdf.name()));
        }
        look.brdf.realise(look.albedo, look.roughness, &mut self.scene.materials[index]);
        self.looks.insert(index, look);
    }

    fn tracer_setup(&mut self, f: &mut dyn Frontend, tracer: Tracer) -> TracerSetup {
        let course = |name, kind: AccelKind, leaf_size| TracerSetup {
            name,
            kind,
            leaf_size,
            sah_bins: 2,
            sah_axes: SahAxes::Longest,
            course_bvh: true,
        };
        match tracer {
            Tracer::Seq => TracerSetup { course_bvh: false, ..course("seq", AccelKind::Linear, 1) },
            Tracer::NaiveBvh => course("naive-bvh", AccelKind::ObjectMedian, 1),
            Tracer::Bbvh(split) => {
                let (method, planes) = split.unwrap_or((CourseSplit::ObjectMedian, None));
                let mut setup = course("bbvh", AccelKind::ObjectMedian, 1);
                setup.set_split(method, planes);
                setup
            }
            Tracer::Embree => {
                let fastest = AccelKind::PEERS.first().copied();
                if fastest.is_none() {
                    self.say_once(
                        f,
                        "embree",
                        "raytracer embree: this rtgi was built without the embree feature; bvh8, its fastest own \
                         structure, traces instead",
                    );
                }
                TracerSetup::own("embree", fastest.unwrap_or(AccelKind::Bvh8))
            }
            Tracer::Ours(kind) => TracerSetup::own(kind.name(), kind),
        }
    }

    fn bvh(&mut self, f: &mut dyn Frontend, command: BvhCommand) -> Result<(), SessionError> {
        let Some(setup) = self.tracer.as_mut().filter(|t| t.course_bvh) else {
            refuse!(
                "unknown command for {}: 'bvh' sets up the course's BVH tracers (raytracer naive-bvh or bbvh)",
                self.tracer.map_or("no ray tracer", |t| t.name)
            );
        };
        if setup.name == "naive-bvh" && matches!(command, BvhCommand::Split(..) | BvhCommand::LeafSize(_)) {
            refuse!(
                "naive-bvh splits at the object median with one triangle a leaf; raytracer bbvh takes the split and \
                 leaf size"
            );
        }
        match command {
            BvhCommand::Split(method, planes) => {
                setup.set_split(method, planes);
                self.clock.tracer = Some(self.clock.now);
            }
            BvhCommand::LeafSize(n) => {
                setup.leaf_size = n;
                self.clock.tracer = Some(self.clock.now);
            }
            BvhCommand::Statistics => {
                let stats = self.current_structure()?.build_stats().clone();
                let sizes: Vec<usize> = stats
                    .leaf_size_histogram
                    .iter()
                    .enumerate()
                    .flat_map(|(size, &count)| std::iter::repeat_n(size, count))
                    .collect();
                let (min, max) = (sizes.first().copied().unwrap_or(0), sizes.last().copied().unwrap_or(0));
                let mean = sizes.iter().sum::<usize>() as f64 / sizes.len().max(1) as f64;
                let median = sizes.get(sizes.len() / 2).copied().unwrap_or(0);
                say!(
                    f,
                    "bvh         {} ({} nodes, depth {}, SAH cost {:.2})",
                    stats.variant,
                    stats.nodes,
                    stats.depth,
                    stats.sah_cost
                )?;
                say!(f, "leaves      {}", stats.leaves)?;
                say!(f, "triangles   per leaf: min {min}, max {max}, average {mean:.2}, median {median}")?;
            }
            BvhCommand::Export { depth, file } => {
                let setup = *setup;
                self.current_structure()?;
                let levels: Vec<usize> = (0..=depth).collect();
                let triangles = self.scene.triangle_positions();
                // The course's BVH tracers are all BVHs: `bvh` refuses the others above.
                let (obj, count) = rtgi_accel::boxes_obj(setup.kind, &triangles, &setup.params(), &levels)
                    .ok_or_else(|| refused!("{}: only BVH variants have boxes to export", setup.kind))?;
                rtgi_image::write_atomically(&file, obj.as_bytes())
                    .map_err(|source| SessionError::Write { path: file.clone(), source })?;
                say!(f, "wrote {count} boxes of levels 0 to {depth} to {}", file.display())?;
            }
        }
        Ok(())
    }

    fn path(&mut self, setting: PathSetting) -> Result<(), SessionError> {
        let Some(setup) = self.algo.as_mut().filter(|a| matches!(a.algo, Algo::SimplePt | Algo::Pt)) else {
            refuse!(
                "unknown command for {}: 'path' sets up the path tracers (algo simple-pt or pt)",
                algo_name(self.algo.as_ref())
            );
        };
        match setting {
            PathSetting::Length(n) => setup.length = n,
            PathSetting::RouletteStart(n) => setup.roulette_start = n,
            PathSetting::Bounce(b) => setup.bounce = b,
            PathSetting::Mis(on) if setup.algo == Algo::Pt => setup.mis = on,
            PathSetting::Mis(_) => refuse!("'path mis' belongs to algo pt; simple-pt samples the BRDF only"),
        }
        Ok(())
    }

    fn material(&mut self, f: &mut dyn Frontend, command: MaterialCommand) -> Result<(), SessionError> {
        let selected = || self.selected.ok_or_else(|| refused!("no material selected (material select NAME)"));
        match command {
            MaterialCommand::List => {
                for material in &self.scene.materials {
                    say!(f, "{}", material.name)?;
                }
            }
            MaterialCommand::Select(name) => {
                let index = self.scene.materials.iter().position(|m| m.name == name).ok_or_else(|| {
                    refused!(
                        "no material called '{name}' ({} materials; material list shows them)",
                        self.scene.materials.len()
                    )
                })?;
                self.selected = Some(index);
            }
            MaterialCommand::Blacklist(name) => self.blacklist.push(name),
            MaterialCommand::Albedo(colour) => {
                let index = selected()?;
                self.edit(f, index, |look, material| match look {
                    Some(look) => look.albedo = colour,
                    None => material.base_color = colour,
                });
            }
            MaterialCommand::Emissive(colour) => {
                let index = selected()?;
                self.edit(f, index, |_, material| material.emission = colour);
            }
            MaterialCommand::Roughness(roughness) => {
                let index = selected()?;
                self.edit(f, index, |look, material| match look {
                    Some(look) => look.roughness = roughness,
                    None => material.roughness = our_roughness(roughness),
                });
            }
            MaterialCommand::Ior(ior) => {
                let index = selected()?;
                self.edit(f, index, |_, material| material.ior = ior);
            }
            MaterialCommand::Texture(file) => {
                let index = selected()?;
                let texture = match file {
                    None => None,
                    Some(file) => {
                        let path = self.find(&file).ok_or_else(|| refused!("{}: no such file", file.display()))?;
                        let texture = Texture::load(&path, ColorEncoding::Srgb)
                            .map_err(|message| SessionError::Texture { path: path.clone(), message })?;
                        self.scene.textures.push(texture);
                        Some(TextureId(self.scene.textures.len() as u32 - 1))
                    }
                };
                self.edit(f, index, |_, material| material.base_color_texture = texture);
            }
            MaterialCommand::Brdf(brdf) => {
                let index = selected()?;
                let material = &self.scene.materials[index];
                let look = match self.looks.get(&index) {
                    Some(look) => CourseLook { brdf, ..*look },
                    None => CourseLook {
                        brdf,
                        albedo: material.base_color,
                        roughness: course_roughness(material.roughness),
                    },
                };
                self.set_look(f, index, look);
                self.edits.insert("material edits");
            }
            MaterialCommand::Show => {
                let index = selected()?;
                let material = &self.scene.materials[index];
                let look = self.looks.get(&index);
                let texture = material
                    .base_color_texture
                    .map_or("none".to_owned(), |t| self.scene.textures[t.0 as usize].name.clone());
                say!(f, "albedo     {}", triple(look.map_or(material.base_color, |l| l.albedo)))?;
                say!(f, "albedo-tex {texture}")?;
                say!(f, "emissive   {}", triple(material.emission))?;
                say!(f, "roughness  {}", look.map_or(course_roughness(material.roughness), |l| l.roughness))?;
                say!(f, "ior        {}", material.ior)?;
                say!(f, "brdf       {}", look.map_or("as loaded", |l| l.brdf.name()))?;
            }
        }
        Ok(())
    }

    /// Edits material `index` (its course look, if it has one, whose BRDF
    /// then derives the fields again).
    fn edit(
        &mut self,
        f: &mut dyn Frontend,
        index: usize,
        change: impl FnOnce(Option<&mut CourseLook>, &mut rtgi_scene::Material),
    ) {
        let mut look = self.looks.get(&index).copied();
        change(look.as_mut(), &mut self.scene.materials[index]);
        if let Some(look) = look {
            self.set_look(f, index, look);
        }
        self.edits.insert("material edits");
    }

    fn commit(&mut self) -> Result<(), SessionError> {
        if self.scene.triangles.is_empty() {
            refuse!("there is no scene data to work with (load a scene first)");
        }
        let Some(setup) = self.tracer else {
            refuse!("there is no ray tracer to commit the scene data to (raytracer seq|naive-bvh|bbvh|embree)");
        };
        let pool = rtgi_job::thread_pool(self.threads())?;
        let triangles = self.scene.triangle_positions();
        let accel = pool.install(|| setup.kind.try_build(&triangles, &setup.params()))?;
        self.committed = Some(accel);
        self.clock.commit = Some(self.clock.now);
        Ok(())
    }

    /// The committed structure, refused when the scene or tracer changed since.
    fn current_structure(&self) -> Result<&dyn Accel, SessionError> {
        let (Some(committed), Some(commit)) = (&self.committed, self.clock.commit) else {
            refuse!("there is no acceleration structure yet (commit builds it)");
        };
        if self.clock.tracer.is_some_and(|t| t > commit) {
            refuse!("the ray tracer changed after the last commit: acceleration structure is out-dated: commit again");
        }
        if self.clock.scene.is_some_and(|s| s > commit) {
            refuse!("the scene changed after the last commit: acceleration structure is out-dated: commit again");
        }
        Ok(committed.as_ref())
    }

    fn threads(&self) -> Option<u32> {
        if self.one_thread { Some(1) } else { self.options.threads }
    }

    fn run(&mut self, f: &mut dyn Frontend) -> Result<(), SessionError> {
        let mut missing = Vec::new();
        if self.clock.scene.is_none() {
            missing.push("a scene loaded (load FILE)");
        }
        if self.tracer.is_none() {
            missing.push("a ray tracer set (raytracer ...)");
        }
        if self.clock.commit.is_none() {
            missing.push("an acceleration structure built (commit)");
        }
        if self.algo.is_none() {
            missing.push("an algorithm set (algo ...)");
        }
        if !missing.is_empty() {
            refuse!("run needs {} first", missing.join(", "));
        }
        let accel = self.current_structure()?;
        let (algo, tracer) = (self.algo.expect("checked"), self.tracer.expect("checked"));
        if self.camera.direction.cross(self.camera.up).length_squared() <= 0.0 {
            refuse!("the camera looks along its up vector ({}): change look or camup", triple(self.camera.direction));
        }
        if algo.algo == Algo::Local && self.point_lights.is_empty() {
            refuse!("algo local shades with a point light: add one (pointlight pos X Y Z col R G B)");
        }
        let request = self.render_request(&algo, &tracer)?;
        let edits: Vec<&str> = self.edits.iter().copied().collect();
        let name = self.loaded.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(" + ");
        // The renderer takes a loaded scene; the session's, edited, is one.
        let scene = LoadedScene { scene: self.scene.clone(), name, load_ms: 0.0 };
        let given = Given { scene: &scene, accel };
        let rendered = f.render(Run { request: &request, given, edits: &edits }).map_err(SessionError::Frontend)?;
        self.runs.push(RunRecord {
            output: self.outfile.clone(),
            algo: algo.algo,
            tracer: tracer.name,
            seconds: rendered.outcome.render.ms * 1e-3,
            rays: rendered.outcome.render.rays,
        });
        Ok(())
    }

    /// The `rtgi render` request that renders what `run` renders.
    fn render_request(&self, algo: &AlgoSetup, tracer: &TracerSetup) -> Result<RenderRequest, SessionError> {
        let source = SceneSource::File { path: self.loaded[0].clone(), options: self.options.load.clone() };
        let mut request = RenderRequest::new(source, self.outfile.clone());
        request.size = ImageSize::exactly(self.resolution.0, self.resolution.1);
        request.sampling.samples_per_pixel = Some(self.sppx);
        request.sampling.seed = self.options.seed;
        let (integrator, strategy, bounce, depth, roulette) = match algo.algo {
            Algo::Primary | Algo::Info => (Integrator::Albedo, None, None, None, None),
            Algo::Local => (Integrator::Direct, Some(DirectStrategy::Light), None, None, None),
            Algo::Direct => match algo.sampling {
                DirectSampling::Light => (Integrator::Direct, Some(DirectStrategy::Light), None, None, None),
                DirectSampling::Mis => (Integrator::Direct, Some(DirectStrategy::Mis), None, None, None),
                DirectSampling::Brdf => (Integrator::Direct, Some(DirectStrategy::Bsdf), None, None, None),
                DirectSampling::Cosine => {
                    (Integrator::Direct, Some(DirectStrategy::Bsdf), Some(BounceSampling::Cosine), None, None)
                }
                DirectSampling::Uniform => {
                    (Integrator::Direct, Some(DirectStrategy::Bsdf), Some(BounceSampling::Uniform), None, None)
                }
            },
            Algo::DirectMis => (Integrator::Direct, Some(DirectStrategy::Mis), None, None, None),
            // The course's simple path tracer traces at most `len` rays, the
            // camera's included; ours counts bounces after the camera ray.
            // Its roulette starts after bounce rr-start + 1 (it tests the
            // ray index after the bounce, from 0): ours counts bounces from 1.
            Algo::SimplePt => (
                Integrator::Path,
                Some(DirectStrategy::Bsdf),
                Some(algo.bounce),
                Some(algo.length - 1),
                Some(algo.roulette_start + 2),
            ),
            // With next-event estimation, `len` hits each light their paths.
            Algo::Pt => (
                Integrator::Path,
                Some(if algo.mis { DirectStrategy::Mis } else { DirectStrategy::Light }),
                Some(algo.bounce),
                Some(algo.length),
                Some(algo.roulette_start + 2),
            ),
        };
        let lighting = &mut request.lighting;
        lighting.integrator = integrator;
        // The course's images show the estimators' noise as it is, unless
        // `denoise on` asked otherwise (for the algorithms that simulate light).
        request.denoise = if self.denoise && integrator.simulates_light() { Denoise::On } else { Denoise::Off };
        if let Some(strategy) = strategy {
            lighting.direct_strategy = strategy;
        }
        if let Some(bounce) = bounce {
            lighting.bounce_sampling = bounce;
        }
        if let Some(depth) = depth {
            lighting.max_depth = depth;
        }
        if let Some(roulette) = roulette {
            lighting.roulette_start = roulette;
        }
        for &(position, colour) in &self.point_lights {
            lighting.lights.push(format!("point:{}:1:{}", comma(position), comma(colour)).parse()?);
        }
        let lit_by_sky = !matches!(algo.algo, Algo::Primary | Algo::Info | Algo::Local);
        if let Some((file, scale)) = self.sky.as_ref().filter(|_| lit_by_sky) {
            lighting.environment = Some(EnvironmentSpec::File(file.clone()));
            lighting.environment_scale = *scale;
        }
        if algo.algo == Algo::Local {
            // Local illumination is the point light's alone.
            lighting.effects = "-emission".parse().map_err(SessionError::Refused)?;
        }
        lighting.no_default_lighting = true;
        // Build parameters only where they shape the tree.
        let mut structure = Structure::of(tracer.kind);
        let (defaults, params) = (tracer.kind.default_params(), tracer.params());
        if tracer.kind.split_method().is_some() && params.max_leaf_size != defaults.max_leaf_size {
            structure.leaf_size = Some(params.max_leaf_size as u32);
        }
        if tracer.kind == AccelKind::Sah {
            structure.sah_bins = params.sah_bins as u32;
            structure.sah_axes = params.sah_axes;
        }
        request.structure = structure;
        let camera = &self.camera;
        request.camera = CameraChoice {
            index: None,
            at: Some(camera.position),
            look: Some(camera.position + camera.direction),
            up: Some(camera.up),
            fov_degrees: Some(COURSE_FOV_DEGREES),
        };
        request.background = Vec3::ZERO;
        request.tone = Tone { exposure: Some(0.0), operator: Some(ToneOperator::Clamp) };
        request.threads = self.threads();
        Ok(request)
    }

    fn print_stats(&self, f: &mut dyn Frontend) -> Result<(), SessionError> {
        if self.runs.is_empty() {
            say!(f, "no runs since the last 'stats clear'")?;
        }
        for (i, run) in self.runs.iter().enumerate() {
            say!(
                f,
                "run {}: {} ({}, {}): {:.3} s rendering, {} rays, {:.2} Mrays/s",
                i + 1,
                run.output.display(),
                run.algo.name(),
                run.tracer,
                run.seconds,
                run.rays,
                run.rays as f64 / run.seconds.max(1e-9) * 1e-6
            )?;
        }
        Ok(())
    }

    fn print_memory(&self, f: &mut dyn Frontend) -> Result<(), SessionError> {
        let scene = &self.scene;
        let vertices = std::mem::size_of_val(scene.vertices.as_slice());
        let triangles = std::mem::size_of_val(scene.triangles.as_slice());
        let textures: usize = scene.textures.iter().map(|t| t.width() as usize * t.height() as usize * 4).sum();
        let mib = |bytes: usize| bytes as f64 / (1 << 20) as f64;
        say!(f, "vertices    {} ({:.1} MiB)", scene.vertices.len(), mib(vertices))?;
        say!(f, "triangles   {} ({:.1} MiB)", scene.triangles.len(), mib(triangles))?;
        say!(f, "textures    {} ({:.1} MiB)", scene.textures.len(), mib(textures))?;
        match &self.committed {
            Some(accel) => say!(
                f,
                "structure   {} ({:.1} MiB)",
                accel.build_stats().variant,
                mib(accel.build_stats().memory_bytes)
            )?,
            None => say!(f, "structure   none (commit builds it)")?,
        }
        Ok(())
    }
}

impl TracerSetup {
    /// A structure by rtgi's (or a peer's) own name, with its own build parameters.
    fn own(name: &'static str, kind: AccelKind) -> Self {
        let defaults = kind.default_params();
        Self {
            name,
            kind,
            leaf_size: defaults.max_leaf_size as u32,
            sah_bins: defaults.sah_bins as u32,
            sah_axes: defaults.sah_axes,
            course_bvh: false,
        }
    }

    fn set_split(&mut self, method: CourseSplit, planes: Option<u32>) {
        self.kind = match method {
            CourseSplit::ObjectMedian => AccelKind::ObjectMedian,
            CourseSplit::SpatialMedian => AccelKind::SpatialMedian,
            CourseSplit::Sah => AccelKind::Sah,
        };
        // N planes on the longest axis are N + 1 bins there.
        self.sah_bins = planes.unwrap_or(1) + 1;
        self.sah_axes = SahAxes::Longest;
    }

    fn params(&self) -> BuildParams {
        BuildParams {
            max_leaf_size: self.leaf_size as usize,
            sah_bins: self.sah_bins as usize,
            sah_axes: self.sah_axes,
            ..self.kind.default_params()
        }
    }
}

fn algo_name(algo: Option<&AlgoSetup>) -> String {
    algo.map_or("no algorithm".to_owned(), |a| format!("algo {}", a.algo.name()))
}

/// A vector as the course prints it.
fn triple(v: Vec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

/// A vector as rtgi's options take it.
fn comma(v: Vec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

/// Transforms a loaded scene by a model matrix: positions as points,
/// normals by the inverse transpose, tangents as directions; its lights
/// and cameras move with it.
fn transform(scene: &mut Scene, matrix: &Mat4) {
    let linear = Mat3::from_mat4(*matrix);
    let normals = linear.inverse().transpose();
    let flips = linear.determinant() < 0.0;
    for v in &mut scene.vertices {
        v.position = matrix.transform_point3(v.position);
        v.normal = (normals * v.normal).normalize_or_zero();
        let tangent = (linear * v.tangent.truncate()).normalize_or_zero();
        v.tangent = tangent.extend(if flips { -v.tangent.w } else { v.tangent.w });
    }
    for light in &mut scene.lights {
        light.position = matrix.transform_point3(light.position);
        light.direction = (linear * light.direction).normalize_or_zero();
    }
    for camera in &mut scene.cameras {
        camera.position = matrix.transform_point3(camera.position);
        camera.direction = linear * camera.direction;
        camera.up = linear * camera.up;
    }
}

#[cfg(test)]
mod tests {
    use rtgi_job::{CancelToken, Unobserved};

    use super::*;

    /// The team's Cornell box (millimetres), from this crate's folder.
    const BOX: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/cornell-box/cornell-box.obj");

    /// A front end that keeps what the session hands it, and renders as a
    /// Rust caller would: with no observer and no way to cancel.
    #[derive(Default)]
    struct Recorder {
        said: Vec<String>,
        notes: Vec<String>,
        warnings: Vec<Warning>,
        runs: Vec<(RenderRequest, Vec<String>)>,
    }

    impl Frontend for Recorder {
        fn say(&mut self, line: &str) -> Result<(), crate::FrontendError> {
            self.said.push(line.to_owned());
            Ok(())
        }

        fn note(&mut self, message: &str) {
            self.notes.push(message.to_owned());
        }

        fn warn(&mut self, warning: &Warning) {
            self.warnings.push(warning.clone());
        }

        fn render(&mut self, run: Run<'_>) -> Result<rtgi_job::Rendered, crate::FrontendError> {
            self.runs.push((run.request.clone(), run.edits.iter().map(|e| e.to_string()).collect()));
            Ok(rtgi_job::render_given(run.request, run.given, &Unobserved, &CancelToken::new())?)
        }
    }

    /// Runs `script`'s lines, stopping at the first error (returned with its line).
    fn execute(session: &mut Session, recorder: &mut Recorder, script: &str) -> Result<Flow, (String, SessionError)> {
        for line in script.lines() {
            match session.execute(line, recorder) {
                Ok(Flow::Continue) => {}
                Ok(Flow::Quit) => return Ok(Flow::Quit),
                Err(error) => return Err((line.to_owned(), error)),
            }
        }
        Ok(Flow::Continue)
    }

    #[test]
    fn commands_say_what_the_course_prints_and_quit_ends_the_session() {
        let (mut session, mut recorder) = (Session::new(SessionOptions::default()), Recorder::default());
        let flow =
            execute(&mut session, &mut recorder, "at\nat 1 2 3\nlook 0 0 1\nprint-cam\necho hello there\nquit\n");
        assert_eq!(flow.unwrap(), Flow::Quit);
        assert_eq!(recorder.said, ["0 0 0", "at 1 2 3", "look 0 0 1", "up 0 1 0", "camup 0 1 0", "hello there"]);
        // The history holds every line, bad ones too.
        let error = session.execute("at 1 2", &mut recorder).unwrap_err();
        assert!(matches!(error, SessionError::Parse(_)), "{error:?}");
        recorder.said.clear();
        session.execute("history", &mut recorder).unwrap();
        assert_eq!(recorder.said.last().map(String::as_str), Some("at 1 2"));
    }

    #[test]
    fn a_difference_from_the_course_is_noted_once() {
        let (mut session, mut recorder) = (Session::new(SessionOptions::default()), Recorder::default());
        execute(&mut session, &mut recorder, "algo local\nalgo info\nalgo local\nplatform cuda\nplatform opengl\n")
            .unwrap();
        assert_eq!(recorder.notes.len(), 3, "{:?}", recorder.notes);
        assert!(recorder.notes[0].starts_with("algo local: rtgi shades with the point light's intensity"));
        assert!(recorder.said.is_empty(), "notes are not said: {:?}", recorder.said);
    }

    #[test]
    fn run_is_refused_until_the_course_allows_it() {
        let (mut session, mut recorder) = (Session::new(SessionOptions::default()), Recorder::default());
        let (line, error) = execute(&mut session, &mut recorder, "echo start\nrun\n").unwrap_err();
        assert_eq!(line, "run");
        assert!(matches!(error, SessionError::Refused(_)));
        assert_eq!(
            error.to_string(),
            "run needs a scene loaded (load FILE), a ray tracer set (raytracer ...), an acceleration structure \
             built (commit), an algorithm set (algo ...) first"
        );
        let script = format!("load {BOX}\nraytracer bbvh\ncommit\nraytracer seq\nalgo primary\nrun\n");
        let (_, error) = execute(&mut session, &mut recorder, &script).unwrap_err();
        assert!(error.to_string().starts_with("the ray tracer changed after the last commit"), "{error}");
        assert!(recorder.runs.is_empty() && session.runs().is_empty());
        let (_, error) = execute(&mut session, &mut recorder, "load no/such/scene.obj\n").unwrap_err();
        assert!(error.to_string().starts_with("no/such/scene.obj: no such file"), "{error}");
    }

    #[test]
    fn run_hands_the_front_end_the_request_of_the_equivalent_render_and_records_it() {
        let dir = std::env::temp_dir().join(format!("rtgi-script-session-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let output = dir.join("run.png");
        let options = SessionOptions { seed: 7, threads: Some(1), ..SessionOptions::default() };
        let (mut session, mut recorder) = (Session::new(options), Recorder::default());
        let script = format!(
            "at 278 273 -800\nlook 0 0 1\nload {BOX}\nraytracer bbvh sah 4\ncommit\nresolution 8 6\nsppx 2\n\
             algo direct\nis brdf\noutfile {}\nrun\n",
            output.display()
        );
        execute(&mut session, &mut recorder, &script).unwrap();
        let (request, edits) = &recorder.runs[0];
        assert!(edits.is_empty(), "the file as loaded: {edits:?}");
        assert_eq!(request.output, output);
        assert_eq!(request.size, ImageSize::exactly(8, 6));
        assert_eq!((request.sampling.samples_per_pixel, request.sampling.seed, request.threads), (Some(2), 7, Some(1)));
        assert_eq!(request.lighting.integrator, Integrator::Direct);
        assert_eq!(request.lighting.direct_strategy, DirectStrategy::Bsdf);
        // Four planes on the longest axis are five bins there.
        assert_eq!((request.structure.kind, request.structure.sah_bins), (AccelKind::Sah, 5));
        assert_eq!(request.camera.at, Some(Vec3::new(278.0, 273.0, -800.0)));
        assert_eq!(request.camera.fov_degrees, Some(COURSE_FOV_DEGREES));
        assert!(matches!(&request.scene, SceneSource::File { path, .. } if path.ends_with("cornell-box.obj")));
        assert!(output.is_file(), "the front end rendered it");
        let runs = session.runs();
        assert_eq!(runs.len(), 1);
        assert_eq!((runs[0].algo, runs[0].tracer, runs[0].output.as_path()), (Algo::Direct, "bbvh", output.as_path()));
        assert!(runs[0].rays >= 8 * 6 * 2, "{:?}", runs[0]);
        // A material edit: the request alone no longer renders the scene.
        execute(&mut session, &mut recorder, "material select white\nmaterial albedo 0 1 0\nrun\nstats print\n")
            .unwrap();
        assert_eq!(recorder.runs[1].1, ["material edits"]);
        assert!(recorder.said.last().unwrap().starts_with("run 2: "), "{:?}", recorder.said);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
