//! `rtgi merge`: the parts of a split render, put together.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use rtgi_render::Accumulation;

use crate::options::ToneArgs;
use crate::output::outln;
use rtgi_job::{check_output, is_accumulation};

/// `rtgi merge`: accumulations (.accum) of one render into its image.
#[derive(Debug, Args)]
pub(crate) struct MergeArgs {
    /// The parts: .accum files written by 'rtgi render --samples/--tile -o PART.accum' or --checkpoint
    #[arg(required = true)]
    pub(crate) parts: Vec<PathBuf>,

    /// The result: an image (.png, .exr), or an .accum file to merge further
    #[arg(short, long)]
    pub(crate) output: PathBuf,

    /// Write the result even if the parts do not hold every sample of every
    /// pixel (a split render with parts still missing, or an .accum to merge further)
    #[arg(long)]
    pub(crate) allow_incomplete: bool,

    #[command(flatten)]
    pub(crate) tone: ToneArgs,
}

pub(crate) fn run(args: &MergeArgs) -> Result<()> {
    check_output(&args.output).map_err(|e| crate::phrasing::job_error(e, crate::phrasing::Phrasing::Options))?;
    for part in &args.parts {
        if crate::common::same_file(part, &args.output) {
            bail!("-o {}: is also one of the parts; write the result to a new file", args.output.display());
        }
    }
    let merged = Accumulation::merge_files(&args.parts)?;
    let identity = merged.identity();
    let complete = merged.is_complete();
    if !complete && !args.allow_incomplete {
        bail!(
            "incomplete: the {} parts hold samples {:?} of 0..{} of every pixel of rows {:?}; no part holds {}. Add \
             the missing parts, or give --allow-incomplete to write what there is",
            args.parts.len(),
            merged.samples(),
            identity.samples_per_pixel,
            merged.rows(),
            merged.missing().join(" or ")
        );
    }
    if is_accumulation(&args.output) {
        merged.write(&args.output)?;
    } else {
        if merged.rows() != (0..identity.height) {
            bail!(
                "cannot make an image: the parts hold rows {:?} of 0..{}; add the other bands (--tile), or \
                 write an .accum to merge further",
                merged.rows(),
                identity.height
            );
        }
        let image = merged.image();
        let simulates_light = identity.settings.get("integrator").is_some_and(|name| {
            rtgi_math::parse_choice::<rtgi_render::Integrator>(name)
                .is_ok_and(|integrator| integrator.simulates_light())
        });
        let tone_map = rtgi_render::recipe::tone_map(args.tone.exposure, args.tone.tonemap, simulates_light, &image);
        image.write(&args.output, &tone_map).context("cannot write the merged image")?;
    }
    outln!("parts       {}", args.parts.len())?;
    outln!(
        "render      {}x{}, {} spp in all, seed {}",
        identity.width,
        identity.height,
        identity.samples_per_pixel,
        identity.seed
    )?;
    outln!("merged      rows {:?}, samples {:?} of every pixel", merged.rows(), merged.samples())?;
    if !complete {
        outln!("incomplete  {} of {} samples per pixel", merged.samples_done(), identity.samples_per_pixel)?;
    }
    outln!("wrote       {}", args.output.display())?;
    Ok(())
}
