//! `rtgi merge`: the parts of a split render, put together.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use rtgi_render::{Accumulation, MergeFilesError};

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
    let names: Vec<String> = args.parts.iter().map(|p| p.display().to_string()).collect();
    let merged = Accumulation::merge_files(&args.parts).map_err(|e| {
        let e = match e {
            MergeFilesError::File(e) => return anyhow::Error::new(e),
            MergeFilesError::Merge(e) => e,
        };
        // The error numbers the parts; name them.
        let mut message = e.to_string();
        message = message.replace("than part 0", &format!("than {}", names[0]));
        for (index, name) in names.iter().enumerate().rev() {
            message = message.replace(&format!("part {index} "), &format!("{name} "));
            message = message.replace(&format!("parts {index} "), &format!("{name} "));
            message = message.replace(&format!("and {index} "), &format!("and {name} "));
        }
        anyhow::anyhow!("cannot merge: {message}")
    })?;
    let identity = merged.identity();
    let complete = merged.is_complete();
    if !complete && !args.allow_incomplete {
        let (rows, samples) = (merged.rows(), merged.samples());
        let mut missing = Vec::new();
        if samples.start > 0 {
            missing.push(format!("samples {:?}", 0..samples.start));
        }
        if samples.end < identity.samples_per_pixel {
            missing.push(format!("samples {:?}", samples.end..identity.samples_per_pixel));
        }
        if rows != (0..identity.height) {
            missing.push(format!("the rows outside {rows:?} of 0..{}", identity.height));
        }
        bail!(
            "incomplete: the {} parts hold samples {samples:?} of 0..{} of every pixel of rows {rows:?}; no part \
             holds {}. Add the missing parts, or give --allow-incomplete to write what there is",
            args.parts.len(),
            identity.samples_per_pixel,
            missing.join(" or ")
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
