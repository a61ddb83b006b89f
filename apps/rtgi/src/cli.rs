use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use rtgi_accel::{AccelKind, BuildParams};
use rtgi_image::ToneOperator;
use rtgi_math::Vec3;
use rtgi_render::PixelSampler;

/// Largest image side accepted: beyond this a typo (an extra zero) would
/// ask for gigabytes of memory and hours of rendering.
pub(crate) const MAX_IMAGE_SIDE: u32 = 16_384;

#[derive(Debug, Parser)]
#[command(name = "rtgi", version, about = "Ray tracing and global illumination toolkit")]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Render a scene to an image (.png or .exr)
    Render(RenderArgs),
}

#[derive(Debug, Args)]
pub(crate) struct RenderArgs {
    /// Scene file (.obj or .toml); the built-in Cornell box when omitted
    pub(crate) scene: Option<PathBuf>,

    /// Output image; the format follows the extension (.png or .exr)
    #[arg(short, long)]
    pub(crate) output: PathBuf,

    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) width: u32,

    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIDE as i64))]
    pub(crate) height: u32,

    /// Samples per pixel
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub(crate) spp: u32,

    /// Where samples go in a pixel: center, uniform [default: center for 1 spp, uniform otherwise]
    #[arg(long)]
    pub(crate) sampler: Option<PixelSampler>,

    /// Seed of the random numbers; the same seed gives the same image
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,

    /// Worker threads [default: one per core]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub(crate) threads: Option<u32>,

    #[command(flatten)]
    pub(crate) accel: AccelArgs,

    #[command(flatten)]
    pub(crate) camera: CameraArgs,

    /// Exposure in stops, for PNG output
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub(crate) exposure: f32,

    /// Tone map for PNG output: clamp, reinhard, aces
    #[arg(long, default_value = "clamp")]
    pub(crate) tonemap: ToneOperator,

    /// Radiance of rays that hit nothing, as R,G,B
    #[arg(long, value_parser = parse_vec3, default_value = "0.05,0.05,0.06")]
    pub(crate) background: Vec3,
}

/// The acceleration structure and its build parameters.
#[derive(Debug, Args)]
pub(crate) struct AccelArgs {
    /// Acceleration structure: linear, object-median, spatial-median, sah, sah-sweep
    #[arg(long, default_value = "sah")]
    pub(crate) accel: AccelKind,

    /// Most triangles in a BVH leaf
    #[arg(long, default_value_t = BuildParams::default().max_leaf_size as u32, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub(crate) leaf_size: u32,

    /// Bins per axis of the binned SAH build
    #[arg(long, default_value_t = BuildParams::default().sah_bins as u32, value_parser = clap::value_parser!(u32).range(2..=256))]
    pub(crate) sah_bins: u32,

    /// Cost of a BVH traversal step relative to a ray/triangle test, for the SAH
    #[arg(long, default_value_t = BuildParams::default().traversal_cost)]
    pub(crate) traversal_cost: f32,
}

impl AccelArgs {
    pub(crate) fn params(&self) -> BuildParams {
        BuildParams {
            max_leaf_size: self.leaf_size as usize,
            sah_bins: self.sah_bins as usize,
            traversal_cost: self.traversal_cost,
        }
    }

    /// Builds the chosen structure over the scene's triangles.
    pub(crate) fn build(&self, scene: &rtgi_scene::Scene) -> Box<dyn rtgi_accel::Accel> {
        self.accel.build(&scene.triangle_positions(), &self.params())
    }
}

/// Camera options; any given override the scene's camera (or the automatic framing).
#[derive(Debug, Args)]
pub(crate) struct CameraArgs {
    /// Camera position, as X,Y,Z (it looks at the scene's centre unless --look is given)
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) at: Option<Vec3>,

    /// Point the camera looks at, as X,Y,Z
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) look: Option<Vec3>,

    /// World up direction, as X,Y,Z
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub(crate) up: Option<Vec3>,

    /// Vertical field of view in degrees
    #[arg(long)]
    pub(crate) fov: Option<f32>,
}

/// Parses "x,y,z" into a vector of finite numbers.
pub(crate) fn parse_vec3(text: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let numbers: Result<Vec<f32>, _> = parts.iter().map(|p| p.parse::<f32>()).collect();
    match numbers {
        Ok(n) if n.len() == 3 && n.iter().all(|c| c.is_finite()) => Ok(Vec3::new(n[0], n[1], n[2])),
        _ => Err(format!("expected three finite numbers separated by commas, like 0,1.5,-2 (got '{text}')")),
    }
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
    let rendered = error.render().to_string();
    let message: Vec<&str> = rendered
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty())
        .collect();
    eprintln!("{}", message.join(" "));
    ExitCode::from(2)
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
    fn command_line_is_well_formed() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
