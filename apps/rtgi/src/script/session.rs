//! The state a script builds up, command by command, as the course
//! framework keeps it: the camera, the scene and its materials, the ray
//! tracer and whether its structure is up to date, the algorithm and its
//! options. `run` turns that state into the arguments of `rtgi render` and
//! renders through the very same code, so that a script and the equivalent
//! command write the same bytes.

use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, anyhow, bail};
use rtgi_accel::{Accel, AccelKind, BuildParams, SahAxes};
use rtgi_math::{Mat3, Mat4, Vec3};
use rtgi_render::BounceSampling;
use rtgi_scene::{ColorEncoding, Scene, Texture, TextureId};
use rtgi_script::{
    Algo, BvhCommand, Command, CourseBrdf, CourseSplit, DirectSampling, MaterialCommand, PathSetting, Tracer,
    course_roughness, our_roughness,
};

use rtgi_image::ToneOperator;
use rtgi_job::{Denoise, Given, ImageSize, RenderRequest, SceneSource, Structure, Tone};
use rtgi_render::recipe::CameraChoice;
use rtgi_render::{DirectStrategy, EnvironmentSpec, Integrator};

use crate::command_line::{CommandLine, shell_words};
use crate::common::{LoadedScene, load_scene};
use crate::options::load_options;
use crate::output::outln;
use crate::phrasing::Phrasing;
use crate::render_cmd::{Printer, finish, render};

/// The course framework's camera defaults.
const COURSE_FOV_DEGREES: f32 = 65.0;
const COURSE_RESOLUTION: (u32, u32) = (1280, 720);
/// The course's default path length and roulette start (`path len`, `path rr-start`).
const COURSE_PATH_LENGTH: u32 = 10;
const COURSE_ROULETTE_START: u32 = 2;

/// Options of `rtgi script` that hold for the whole session.
#[derive(Clone, Debug, Default)]
pub(crate) struct SessionOptions {
    /// `-o`: where `run` writes until `outfile` says otherwise (default `out.png`).
    pub(crate) output: Option<PathBuf>,
    /// `--seed`.
    pub(crate) seed: u64,
    /// `--threads`.
    pub(crate) threads: Option<u32>,
    /// Folders `load` looks in after the current one and the script's.
    pub(crate) model_paths: Vec<PathBuf>,
}

/// What the session does after a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Flow {
    Continue,
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

/// One `run`, for `stats print`.
#[derive(Clone, Debug)]
struct RunRecord {
    output: PathBuf,
    algo: Algo,
    tracer: &'static str,
    seconds: f64,
    rays: u64,
}

/// Which command last changed what, to tell whether the structure is current.
#[derive(Clone, Copy, Debug, Default)]
struct Clock {
    now: u64,
    scene: Option<u64>,
    tracer: Option<u64>,
    commit: Option<u64>,
}

/// The state of a script or prompt session.
pub(crate) struct Session {
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

impl Session {
    pub(crate) fn new(options: SessionOptions) -> Self {
        let outfile = options.output.clone().unwrap_or_else(|| PathBuf::from("out.png"));
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

    /// Whether a `with` block is being skipped (its `}` not yet seen).
    pub(crate) fn in_skipped_block(&self) -> bool {
        self.skipping
    }

    /// Sets the folder of the script being run, where `load` also looks.
    pub(crate) fn set_script_folder(&mut self, folder: Option<PathBuf>) {
        self.script_folder = folder;
    }

    /// Runs one line. The error says what went wrong; the caller names the
    /// file, line and command.
    pub(crate) fn execute(&mut self, line: &str) -> Result<Flow> {
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
        let command = rtgi_script::parse(line).map_err(|e| anyhow!(e))?;
        self.clock.now += 1;
        self.apply(command)
    }

    fn apply(&mut self, command: Command) -> Result<Flow> {
        match command {
            Command::Nothing | Command::EndBlock => {}
            Command::At(None) => outln!("{}", triple(self.camera.position))?,
            Command::At(Some(p)) => self.camera.position = p,
            Command::Look(None) => outln!("{}", triple(self.camera.direction))?,
            Command::Look(Some(d)) if d == Vec3::ZERO => bail!("the direction must not be 0 0 0"),
            Command::Look(Some(d)) => self.camera.direction = d,
            Command::Up(None) => outln!("{}", triple(self.camera.scene_up.unwrap_or(Vec3::Y)))?,
            Command::Up(Some(_)) if self.camera.scene_up.is_some() => {
                bail!("cannot set the scene's up vector twice; did you mean camup?")
            }
            Command::Up(Some(up)) => {
                self.camera.scene_up = Some(up);
                if !self.camera.up_given {
                    self.camera.up = up;
                    self.camera.up_given = true;
                }
            }
            Command::CamUp(None) => outln!("{}", triple(self.camera.up))?,
            Command::CamUp(Some(up)) => {
                self.camera.up = up;
                self.camera.up_given = true;
            }
            Command::PrintCam => {
                outln!("at {}", triple(self.camera.position))?;
                outln!("look {}", triple(self.camera.direction))?;
                outln!("up {}", triple(self.camera.scene_up.unwrap_or(Vec3::Y)))?;
                outln!("camup {}", triple(self.camera.up))?;
            }
            Command::Load { file, .. } => self.load(&file)?,
            Command::ModelPath(folder) => self.model_paths.push(folder),
            Command::ModelMatrix(matrix) => self.model_matrix = matrix,
            Command::ModelTrafo(matrix) => self.model_matrix *= matrix,
            Command::Resolution(w, h) => self.resolution = (w, h),
            Command::Sppx(n) => self.sppx = n,
            Command::Outfile(file) => self.outfile = file,
            Command::Commit => self.commit()?,
            Command::Run => self.run()?,
            Command::Raytracer(tracer) => {
                self.tracer = Some(self.tracer_setup(tracer));
                self.clock.tracer = Some(self.clock.now);
            }
            Command::Bvh(command) => self.bvh(command)?,
            Command::Algo(algo) => {
                if algo == Algo::Local {
                    self.say_once(
                        "algo local",
                        "algo local: rtgi shades with the point light's intensity, col / d² times the BRDF and the \
                         cosine, as its direct light does; the course's local multiplies by the light's power \
                         (4π col) instead, so its images are about 12.6 times brighter",
                    );
                }
                if algo == Algo::Info {
                    self.say_once(
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
                        "is mis",
                        "is mis: algo direct now weighs light and BRDF samples, as algo direct/mis does",
                    );
                }
                other => bail!(
                    "unknown command for {}: 'is' chooses how algo direct samples (select it first)",
                    algo_name(other.as_ref())
                ),
            },
            Command::Is(sampling) => match &mut self.algo {
                Some(setup) if setup.algo == Algo::Direct => setup.sampling = sampling,
                Some(setup) if setup.algo == Algo::DirectMis => bail!(
                    "algo direct/mis samples the light and the BRDF and weighs them; 'is {}' chooses one strategy \
                     for algo direct",
                    sampling.name()
                ),
                other => bail!(
                    "unknown command for {}: 'is' chooses how algo direct samples (select it first)",
                    algo_name(other.as_ref())
                ),
            },
            Command::WavefrontAlgo { name, instead } => {
                self.say_once(
                    name,
                    &format!(
                        "algo {name}: rtgi has no wavefront algorithms; algo {} renders what it renders",
                        instead.name()
                    ),
                );
                self.algo = Some(AlgoSetup::new(instead));
            }
            Command::Path(setting) => self.path(setting)?,
            Command::Material(command) => self.material(command)?,
            Command::DefaultBrdf(brdf) => {
                if self.default_brdf.is_some() && !self.loaded.is_empty() {
                    outln!("Replacing a default brdf that has already been applied to some materials.")?;
                }
                self.default_brdf = Some(brdf);
            }
            Command::PointLight { replace, position, colour } => match self.point_lights.first_mut() {
                Some(first) if replace => *first = (position, colour),
                _ => self.point_lights.push((position, colour)),
            },
            Command::SkylightLoad { file, scale } => {
                let path = self.find(&file).ok_or_else(|| anyhow!("{}: no such file", file.display()))?;
                rtgi_render::Environment::load(&path)?;
                self.sky = Some((path, scale));
            }
            Command::SkylightScale(scale) => match &mut self.sky {
                Some((_, s)) => *s = scale,
                None => bail!("there is no skylight to scale (skylight load FILE SCALE first)"),
            },
            Command::Echo(text) => outln!("{text}")?,
            Command::StatsPrint => self.print_stats()?,
            Command::StatsClear => self.runs.clear(),
            Command::MemStats => self.print_memory()?,
            Command::History => {
                for line in &self.history {
                    outln!("{line}")?;
                }
            }
            Command::Quit => return Ok(Flow::Quit),
            Command::Omp(on) => self.one_thread = !on,
            Command::Platform(None) => outln!("platform: none")?,
            Command::Platform(Some(name)) if name == "none" => {}
            Command::Platform(Some(name)) => self.say_once(
                "platform",
                &format!("platform {name}: rtgi has no GPU or wavefront platforms; rendering stays on the CPU"),
            ),
            Command::Denoise(on) => self.denoise = on,
            // Every `with` block is skipped already: rtgi has none of the features.
            Command::Disable(feature) => outln!("DISABLING {feature}")?,
            Command::With(feature) => {
                self.skipping = true;
                outln!("Skipping a block due to missing {feature} (rtgi has no {feature})")?;
            }
            Command::Unavailable { command, feature } => {
                self.say_once(feature, &format!("{command}: rtgi has no {feature}; the script goes on"))
            }
        }
        Ok(Flow::Continue)
    }

    /// Prints `message` on standard error the first time `key` comes up.
    fn say_once(&mut self, key: &str, message: &str) {
        if self.said.insert(key.to_owned()) {
            eprintln!("note: {message}");
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

    fn load(&mut self, file: &Path) -> Result<()> {
        let path = self.find(file).ok_or_else(|| {
            let looked: Vec<String> = self.search_folders().map(|p| p.display().to_string()).collect();
            let where_ =
                if looked.is_empty() { String::new() } else { format!(" (also looked in {})", looked.join(", ")) };
            anyhow!("{}: no such file{where_}; modelpath DIR adds a folder to look in", file.display())
        })?;
        let LoadedScene { mut scene, .. } = load_scene(Some(&path))?;
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
                self.set_look(index, look);
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

    fn set_look(&mut self, index: usize, look: CourseLook) {
        if let Some(difference) = look.brdf.difference() {
            self.say_once(look.brdf.name(), &format!("brdf {}: {difference}", look.brdf.name()));
        }
        look.brdf.realise(look.albedo, look.roughness, &mut self.scene.materials[index]);
        self.looks.insert(index, look);
    }

    fn tracer_setup(&mut self, tracer: Tracer) -> TracerSetup {
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

    fn bvh(&mut self, command: BvhCommand) -> Result<()> {
        let Some(setup) = self.tracer.as_mut().filter(|t| t.course_bvh) else {
            bail!(
                "unknown command for {}: 'bvh' sets up the course's BVH tracers (raytracer naive-bvh or bbvh)",
                self.tracer.map_or("no ray tracer", |t| t.name)
            );
        };
        if setup.name == "naive-bvh" && matches!(command, BvhCommand::Split(..) | BvhCommand::LeafSize(_)) {
            bail!(
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
                outln!(
                    "bvh         {} ({} nodes, depth {}, SAH cost {:.2})",
                    stats.variant,
                    stats.nodes,
                    stats.depth,
                    stats.sah_cost
                )?;
                outln!("leaves      {}", stats.leaves)?;
                outln!("triangles   per leaf: min {min}, max {max}, average {mean:.2}, median {median}")?;
            }
            BvhCommand::Export { depth, file } => {
                let setup = *setup;
                self.current_structure()?;
                let levels: Vec<usize> = (0..=depth).collect();
                let triangles = self.scene.triangle_positions();
                let (obj, count) = crate::debug_cmd::boxes_obj(setup.kind, &triangles, &setup.params(), &levels)?;
                crate::common::write_atomically(&file, obj.as_bytes())?;
                outln!("wrote {count} boxes of levels 0 to {depth} to {}", file.display())?;
            }
        }
        Ok(())
    }

    fn path(&mut self, setting: PathSetting) -> Result<()> {
        let Some(setup) = self.algo.as_mut().filter(|a| matches!(a.algo, Algo::SimplePt | Algo::Pt)) else {
            bail!(
                "unknown command for {}: 'path' sets up the path tracers (algo simple-pt or pt)",
                algo_name(self.algo.as_ref())
            );
        };
        match setting {
            PathSetting::Length(n) => setup.length = n,
            PathSetting::RouletteStart(n) => setup.roulette_start = n,
            PathSetting::Bounce(b) => setup.bounce = b,
            PathSetting::Mis(on) if setup.algo == Algo::Pt => setup.mis = on,
            PathSetting::Mis(_) => bail!("'path mis' belongs to algo pt; simple-pt samples the BRDF only"),
        }
        Ok(())
    }

    fn material(&mut self, command: MaterialCommand) -> Result<()> {
        let selected = || self.selected.ok_or_else(|| anyhow!("no material selected (material select NAME)"));
        match command {
            MaterialCommand::List => {
                for material in &self.scene.materials {
                    outln!("{}", material.name)?;
                }
            }
            MaterialCommand::Select(name) => {
                let index = self.scene.materials.iter().position(|m| m.name == name).ok_or_else(|| {
                    anyhow!(
                        "no material called '{name}' ({} materials; material list shows them)",
                        self.scene.materials.len()
                    )
                })?;
                self.selected = Some(index);
            }
            MaterialCommand::Blacklist(name) => self.blacklist.push(name),
            MaterialCommand::Albedo(colour) => {
                let index = selected()?;
                self.edit(index, |look, material| match look {
                    Some(look) => look.albedo = colour,
                    None => material.base_color = colour,
                });
            }
            MaterialCommand::Emissive(colour) => {
                let index = selected()?;
                self.edit(index, |_, material| material.emission = colour);
            }
            MaterialCommand::Roughness(roughness) => {
                let index = selected()?;
                self.edit(index, |look, material| match look {
                    Some(look) => look.roughness = roughness,
                    None => material.roughness = our_roughness(roughness),
                });
            }
            MaterialCommand::Ior(ior) => {
                let index = selected()?;
                self.edit(index, |_, material| material.ior = ior);
            }
            MaterialCommand::Texture(file) => {
                let index = selected()?;
                let texture = match file {
                    None => None,
                    Some(file) => {
                        let path = self.find(&file).ok_or_else(|| anyhow!("{}: no such file", file.display()))?;
                        let texture = Texture::load(&path, ColorEncoding::Srgb)
                            .map_err(|e| anyhow!("{}: cannot read the texture: {e}", path.display()))?;
                        self.scene.textures.push(texture);
                        Some(TextureId(self.scene.textures.len() as u32 - 1))
                    }
                };
                self.edit(index, |_, material| material.base_color_texture = texture);
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
                self.set_look(index, look);
                self.edits.insert("material edits");
            }
            MaterialCommand::Show => {
                let index = selected()?;
                let material = &self.scene.materials[index];
                let look = self.looks.get(&index);
                let texture = material
                    .base_color_texture
                    .map_or("none".to_owned(), |t| self.scene.textures[t.0 as usize].name.clone());
                outln!("albedo     {}", triple(look.map_or(material.base_color, |l| l.albedo)))?;
                outln!("albedo-tex {texture}")?;
                outln!("emissive   {}", triple(material.emission))?;
                outln!("roughness  {}", look.map_or(course_roughness(material.roughness), |l| l.roughness))?;
                outln!("ior        {}", material.ior)?;
                outln!("brdf       {}", look.map_or("as loaded", |l| l.brdf.name()))?;
            }
        }
        Ok(())
    }

    /// Edits material `index` (its course look, if it has one, whose BRDF
    /// then derives the fields again).
    fn edit(&mut self, index: usize, change: impl FnOnce(Option<&mut CourseLook>, &mut rtgi_scene::Material)) {
        let mut look = self.looks.get(&index).copied();
        change(look.as_mut(), &mut self.scene.materials[index]);
        if let Some(look) = look {
            self.set_look(index, look);
        }
        self.edits.insert("material edits");
    }

    fn commit(&mut self) -> Result<()> {
        if self.scene.triangles.is_empty() {
            bail!("there is no scene data to work with (load a scene first)");
        }
        let Some(setup) = self.tracer else {
            bail!("there is no ray tracer to commit the scene data to (raytracer seq|naive-bvh|bbvh|embree)");
        };
        let pool = crate::common::thread_pool(self.threads())?;
        let triangles = self.scene.triangle_positions();
        let accel = pool.install(|| setup.kind.try_build(&triangles, &setup.params()))?;
        self.committed = Some(accel);
        self.clock.commit = Some(self.clock.now);
        Ok(())
    }

    /// The committed structure, refused when the scene or tracer changed since.
    fn current_structure(&self) -> Result<&dyn Accel> {
        let (Some(committed), Some(commit)) = (&self.committed, self.clock.commit) else {
            bail!("there is no acceleration structure yet (commit builds it)");
        };
        if self.clock.tracer.is_some_and(|t| t > commit) {
            bail!("the ray tracer changed after the last commit: acceleration structure is out-dated: commit again");
        }
        if self.clock.scene.is_some_and(|s| s > commit) {
            bail!("the scene changed after the last commit: acceleration structure is out-dated: commit again");
        }
        Ok(committed.as_ref())
    }

    fn threads(&self) -> Option<u32> {
        if self.one_thread { Some(1) } else { self.options.threads }
    }

    fn run(&mut self) -> Result<()> {
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
            bail!("run needs {} first", missing.join(", "));
        }
        let accel = self.current_structure()?;
        let (algo, tracer) = (self.algo.expect("checked"), self.tracer.expect("checked"));
        if self.camera.direction.cross(self.camera.up).length_squared() <= 0.0 {
            bail!("the camera looks along its up vector ({}): change look or camup", triple(self.camera.direction));
        }
        if algo.algo == Algo::Local && self.point_lights.is_empty() {
            bail!("algo local shades with a point light: add one (pointlight pos X Y Z col R G B)");
        }
        let request = self.render_request(&algo, &tracer)?;
        let words = request.to_command_line();
        if self.edits.is_empty() {
            outln!("the same as  rtgi {}", shell_words(&words))?;
        } else {
            let edits: Vec<&str> = self.edits.iter().copied().collect();
            outln!("like         rtgi {} (with {}, which no option expresses)", shell_words(&words), edits.join(", "))?;
        }
        let name = self.loaded.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(" + ");
        let scene = LoadedScene { scene: self.scene.clone(), name, load_ms: 0.0 };
        let started = Instant::now();
        let printer = Printer::new(&request, true, Phrasing::Script);
        let rendered = render(&request, Some(Given { scene: &scene, accel }), &printer)?;
        finish(&rendered)?;
        let took = started.elapsed().as_secs_f64();
        eprintln!("Took {}", crate::progress::short_duration(took));
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
    fn render_request(&self, algo: &AlgoSetup, tracer: &TracerSetup) -> Result<RenderRequest> {
        let source = SceneSource::File { path: self.loaded[0].clone(), options: load_options() };
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
            lighting.effects = "-emission".parse().map_err(|e: String| anyhow!(e))?;
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

    fn print_stats(&self) -> Result<()> {
        if self.runs.is_empty() {
            outln!("no runs since the last 'stats clear'")?;
        }
        for (i, run) in self.runs.iter().enumerate() {
            outln!(
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

    fn print_memory(&self) -> Result<()> {
        let scene = &self.scene;
        let vertices = std::mem::size_of_val(scene.vertices.as_slice());
        let triangles = std::mem::size_of_val(scene.triangles.as_slice());
        let textures: usize = scene.textures.iter().map(|t| t.width() as usize * t.height() as usize * 4).sum();
        let mib = |bytes: usize| bytes as f64 / (1 << 20) as f64;
        outln!("vertices    {} ({:.1} MiB)", scene.vertices.len(), mib(vertices))?;
        outln!("triangles   {} ({:.1} MiB)", scene.triangles.len(), mib(triangles))?;
        outln!("textures    {} ({:.1} MiB)", scene.textures.len(), mib(textures))?;
        match &self.committed {
            Some(accel) => outln!(
                "structure   {} ({:.1} MiB)",
                accel.build_stats().variant,
                mib(accel.build_stats().memory_bytes)
            )?,
            None => outln!("structure   none (commit builds it)")?,
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
