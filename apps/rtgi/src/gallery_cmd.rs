//! `rtgi gallery`: a contact sheet of scenes rendered as `rtgi render
//! SCENE` renders them with no options, to look at every default at once.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use rtgi_image::{ToneMap, contact_sheet};
use rtgi_job::{ImageSize, RenderRequest, SceneSource, check_output};

use crate::options::{load_options, threads_from_environment};
use crate::output::outln;
use crate::phrasing::{Phrasing, job_error};
use crate::render_cmd::{Printer, finish, render};

/// `rtgi gallery`: scenes side by side, each as a first `rtgi render` shows it.
#[derive(Debug, Args)]
pub(crate) struct GalleryArgs {
    /// Scene files (.obj, .gltf, .glb or .toml)
    #[arg(required = true)]
    pub(crate) scenes: Vec<PathBuf>,

    /// The contact sheet (.png)
    #[arg(short, long)]
    pub(crate) output: PathBuf,

    /// Width of each picture
    #[arg(long, default_value_t = 320, value_parser = clap::value_parser!(u32).range(16..=2048))]
    pub(crate) width: u32,

    /// Height of each picture
    #[arg(long, default_value_t = 240, value_parser = clap::value_parser!(u32).range(16..=2048))]
    pub(crate) height: u32,

    /// Pictures per row
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub(crate) columns: u32,
}

/// Grey between the pictures, in pixels.
const GAP: u32 = 4;

pub(crate) fn run(args: &GalleryArgs) -> Result<()> {
    check_output(&args.output).map_err(|e| job_error(e, Phrasing::Options))?;
    let scratch = std::env::temp_dir().join(format!("rtgi-gallery-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).with_context(|| format!("{}: cannot create", scratch.display()))?;
    let mut pictures = Vec::new();
    for (index, scene) in args.scenes.iter().enumerate() {
        outln!("== {}", scene.display())?;
        // What `rtgi render SCENE -o PICTURE --width W --height H` renders,
        // so the sheet shows the real defaults.
        let picture = scratch.join(format!("{index}.png"));
        let source = SceneSource::File { path: scene.clone(), options: load_options() };
        let mut request = RenderRequest::new(source, picture);
        request.size = ImageSize::exactly(args.width, args.height);
        request.threads = threads_from_environment()?;
        let rendered = render(&request, None, &Printer::new(&request, true, Phrasing::Options))?;
        finish(&rendered)?;
        pictures.push(rendered.image);
    }
    let _ = std::fs::remove_dir_all(&scratch);

    let sheet = contact_sheet(&pictures, args.width, args.height, args.columns, GAP);
    sheet.write(&args.output, &ToneMap::default())?;
    outln!("wrote       {} ({} scenes)", args.output.display(), pictures.len())?;
    Ok(())
}
