//! `rtgi info`: what a scene contains ([`rtgi_job::describe`]), as text
//! or JSON; `rtgi compare`: the error of an image against a reference.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use rtgi_image::HdrImage;
use rtgi_job::SceneDescription;

use crate::common::load_scene;
use crate::options::{CameraArgs, LightingArgs};
use crate::output::{out, outln};
use crate::phrasing::{Phrasing, job_error};

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

pub(crate) fn run(args: &InfoArgs) -> Result<()> {
    let loaded = load_scene(args.scene.as_deref())?;
    let info = rtgi_job::describe(&loaded, &args.lighting.lighting(), &args.camera.choice())
        .map_err(|e| job_error(e, Phrasing::Options))?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&info)?)?;
    } else {
        print_text(&info)?;
    }
    Ok(())
}

fn print_text(info: &SceneDescription) -> Result<()> {
    out!("{info}")?;
    if !info.material_variants.is_empty() {
        outln!("            (--variant NAME renders one)")?;
    }
    out!("{}", info.plan)
}

/// `rtgi compare`: prints the error of one EXR image against another.
pub(crate) fn compare(args: &CompareArgs) -> Result<()> {
    let image = read_exr(&args.image)?;
    let reference = read_exr(&args.reference)?;
    let Some(d) = rtgi_image::compare(&image, &reference) else {
        bail!(
            "{}: {}x{} pixels, but the reference {} has {}x{}",
            args.image.display(),
            image.width(),
            image.height(),
            args.reference.display(),
            reference.width(),
            reference.height()
        );
    };
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&d)?)?;
    } else {
        out!("{d}")?;
    }
    Ok(())
}

/// Reads an EXR image from a regular file. Anything else is refused first:
/// a FIFO would block until some other program writes to it, and a
/// directory or a device is no image.
fn read_exr(path: &Path) -> Result<HdrImage> {
    let metadata = std::fs::metadata(path).with_context(|| format!("{}: cannot read", path.display()))?;
    if !metadata.is_file() {
        bail!("{}: cannot read: not a file", path.display());
    }
    Ok(HdrImage::read_exr(path)?)
}
