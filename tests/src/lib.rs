//! Helpers shared by the end-to-end tests: finding the shared scenes,
//! running the CLI, scratch folders.

pub mod convergence;
pub mod corpus;
pub mod voxel_world;

// The examples of the guide's page on the libraries are compiled (and the
// runnable one run) as doctests, so that the page keeps to the crates' API:
// this crate depends on all of them.
#[doc = include_str!("../../docs/guide/library.md")]
#[cfg(doctest)]
pub struct GuideLibraryDoctests;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The environment variable that points the tests at another copy of the shared scenes.
pub const SCENES_VARIABLE: &str = "RTGI_SCENES";

/// The workspace's root folder.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ sits inside the workspace").to_path_buf()
}

/// The folder of shared third-party scenes: `$RTGI_SCENES`, or
/// `../shared/scenes` beside the workspace.
pub fn shared_scenes() -> PathBuf {
    std::env::var_os(SCENES_VARIABLE)
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("..").join("shared").join("scenes"))
}

/// The path of a shared scene file, or `None` after saying why the calling
/// test skips ([`skip_without`]: a failure where `RTGI_REQUIRE_SCENES` is set).
pub fn shared_scene(relative: &str) -> Option<PathBuf> {
    let path = shared_scenes().join(relative);
    if path.is_file() {
        Some(path)
    } else {
        skip_without(
            Requirement::Scenes,
            &format!(
                "shared scene {} not found (set {SCENES_VARIABLE} to the folder of shared scenes)",
                path.display()
            ),
        );
        None
    }
}

/// What some tests need of the machine beyond the workspace, which a
/// developer's machine may lack and CI must have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Requirement {
    /// The shared third-party scenes ([`shared_scenes`]).
    Scenes,
    /// A real Slurm (Debian's `slurm-wlm` and `munge`, and root).
    Slurm,
    /// Intel Embree 3 (`libembree-dev`) and a build with the `embree` feature.
    Embree,
}

impl Requirement {
    /// The environment variable that turns a skip for want of this into a failure.
    pub fn variable(self) -> &'static str {
        match self {
            Requirement::Scenes => "RTGI_REQUIRE_SCENES",
            Requirement::Slurm => "RTGI_REQUIRE_SLURM",
            Requirement::Embree => "RTGI_REQUIRE_EMBREE",
        }
    }

    /// Whether a skip for want of this fails the test (the variable is set,
    /// to anything but `0` or nothing).
    pub fn required(self) -> bool {
        std::env::var_os(self.variable()).is_some_and(|v| !v.is_empty() && v != "0")
    }
}

/// Says on standard error why the calling test skips, for want of
/// `requirement`; panics with that reason instead where the requirement's
/// variable is set (CI sets them all), so that a green run cannot mean
/// "nothing real was tried". The caller returns after it.
pub fn skip_without(requirement: Requirement, why: &str) {
    if requirement.required() {
        panic!("{why}; {} is set, so this skip is a failure", requirement.variable());
    }
    eprintln!("skipping: {why} ({} makes this a failure)", requirement.variable());
}

/// Side of the renders compared with the Cornell box reference,
/// `tests/references/cornell-box-path.exr`.
pub const CORNELL_SIZE: u32 = 64;

/// The shared Cornell box path traced as its reference was
/// (`tests/tests/render/cornell_reference.rs`): `CORNELL_SIZE` square, framed as
/// `rtgi render` frames a scene without a camera (40° field of view),
/// default settings otherwise.
pub fn render_cornell_box(
    scene: &rtgi_scene::Scene,
    samples_per_pixel: u32,
    sampler: rtgi_render::PixelSampler,
    seed: u64,
) -> rtgi_image::HdrImage {
    use rtgi_accel::{AccelKind, BuildParams};
    let accel = AccelKind::Sah.build(&scene.triangle_positions(), &BuildParams::default());
    let camera = rtgi_render::frame_scene(scene, accel.as_ref(), 40f32.to_radians(), 1.0);
    let settings = rtgi_render::RenderSettings {
        width: CORNELL_SIZE,
        height: CORNELL_SIZE,
        samples_per_pixel,
        sampler,
        seed,
        ..rtgi_render::RenderSettings::default()
    };
    rtgi_render::render(scene, accel.as_ref(), &camera, &settings, &|_| {}).0
}

/// A fresh empty folder for one test's files, removed when the test
/// passes and kept (its path printed) when it fails, for a look at what the
/// failing run wrote, or when `RTGI_KEEP_SCRATCH` is set (to measure or
/// profile on the scenes a test builds).
///
/// The folder is this process's own and this call's own: tests of one
/// binary run side by side, and two may choose the same name.
pub fn scratch_dir(test: &str) -> ScratchDir {
    static CALLS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("rtgi-tests-{}-{call}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("cannot create a scratch folder");
    ScratchDir(dir)
}

/// The folder of [`scratch_dir`]; a path wherever one is expected.
#[derive(Debug)]
pub struct ScratchDir(PathBuf);

impl std::ops::Deref for ScratchDir {
    type Target = PathBuf;
    fn deref(&self) -> &PathBuf {
        &self.0
    }
}

impl AsRef<std::path::Path> for ScratchDir {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("the failing test's files are kept in {}", self.0.display());
        } else if std::env::var_os("RTGI_KEEP_SCRATCH").is_some() {
            eprintln!("the test's files are kept in {} (RTGI_KEEP_SCRATCH)", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// What a run of the CLI did.
#[derive(Debug)]
pub struct Run {
    pub success: bool,
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl From<Output> for Run {
    fn from(o: Output) -> Self {
        Run {
            success: o.status.success(),
            code: o.status.code(),
            stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        }
    }
}

/// Runs the `rtgi` command (the binary at `program`) with `args` in the workspace root.
pub fn run_cli(program: &str, args: &[&str]) -> Run {
    Command::new(program)
        .args(args)
        .current_dir(workspace_root())
        .output()
        .expect("cannot start the rtgi binary")
        .into()
}

/// Runs the `rtgi` command (the binary at `program`) with `args` in the
/// workspace root, writing `stdin` to its standard input.
pub fn run_cli_with_input(program: &str, args: &[&str], stdin: &[u8]) -> Run {
    use std::io::Write as _;
    use std::process::Stdio;
    let mut child = Command::new(program)
        .args(args)
        .current_dir(workspace_root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start the rtgi binary");
    // A command that stops reading early closes the pipe: that is its answer, not an error here.
    let _ = child.stdin.take().expect("piped").write_all(stdin);
    child.wait_with_output().expect("cannot wait for the rtgi binary").into()
}

/// Runs `check` on every acceleration structure variant with a spread of
/// build parameters ([`AccelKind::all_configurations`]), built over
/// `triangles` (a soup, an indexed mesh or any [`TriangleSource`]); the
/// label names the variant and all its parameters, one label a
/// configuration and the same for every source, so that answers over two
/// sources can be matched by label. A new
/// variant is tested by every caller as soon as it is added to
/// [`AccelKind::ALL`].
///
/// [`AccelKind::all_configurations`]: rtgi_accel::AccelKind::all_configurations
/// [`AccelKind::ALL`]: rtgi_accel::AccelKind::ALL
/// [`TriangleSource`]: rtgi_accel::TriangleSource
pub fn for_every_variant(
    triangles: &(impl rtgi_accel::TriangleSource + ?Sized),
    mut check: impl FnMut(&str, &dyn rtgi_accel::Accel, &rtgi_accel::BuildParams),
) {
    for (kind, params) in rtgi_accel::AccelKind::all_configurations() {
        let accel = kind.build(triangles, &params);
        let label = format!(
            "{kind} (leaf {}, bins {}, traversal cost {}, {}, {} traversal)",
            params.max_leaf_size, params.sah_bins, params.traversal_cost, params.intersector, params.traversal
        );
        check(&label, accel.as_ref(), &params);
    }
}

/// Where `accel` answers `rays` otherwise than the linear scan with the
/// same intersector does, bit for bit (closest hit: triangle, `t`, `beta`,
/// `gamma`; any hit), one line per difference, labelled with `label`.
pub fn differences_from_linear_scan(
    label: &str,
    accel: &dyn rtgi_accel::Accel,
    reference: &rtgi_accel::LinearScan,
    rays: &[rtgi_math::Ray],
) -> Vec<String> {
    use rtgi_accel::Accel as _;
    let mut differences = Vec::new();
    for ray in rays {
        let (got, expected) = (accel.intersect(ray), reference.intersect(ray));
        if !rtgi_accel::verify::same_hit(got, expected) {
            differences.push(format!("{label}: closest hit {got:?}, the linear scan's {expected:?}, for {ray:?}"));
        }
        let (got, expected) = (accel.occluded(ray), reference.occluded(ray));
        if got != expected {
            differences.push(format!("{label}: occluded {got}, the linear scan's {expected}, for {ray:?}"));
        }
    }
    differences
}
