//! The libraries' errors, notes and warnings in the words of the front
//! end: `rtgi render`'s options, or the commands of a script in the course
//! framework's language. The libraries name fields; only this file names flags.

use rtgi_job::{Field, JobError, Warning};
use rtgi_render::recipe::{self, ChosenCamera};

/// Whose words the hints of warnings use: the command line's options, or
/// the commands of a script in the course framework's language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phrasing {
    Options,
    Script,
}

impl Phrasing {
    /// How to move the camera.
    pub(crate) fn move_camera(self) -> &'static str {
        match self {
            Phrasing::Options => "--at (and --look)",
            Phrasing::Script => "at (and look)",
        }
    }

    /// How to keep +Y up.
    pub(crate) fn up_y(self) -> &'static str {
        match self {
            Phrasing::Options => "--up 0,1,0",
            Phrasing::Script => "the camera's up (0 1 0)",
        }
    }

    /// How to add light.
    pub(crate) fn add_light(self) -> &'static str {
        match self {
            Phrasing::Options => "--environment 1,1,1 or --light",
            Phrasing::Script => "pointlight or skylight load",
        }
    }
}

/// `rtgi render`'s option for a field of the request.
fn flag(field: Field) -> &'static str {
    match field {
        Field::Output => "-o",
        Field::Aovs => "--aov",
        Field::Checkpoint => "--checkpoint",
        Field::Resume => "--resume",
        Field::TimeLimit => "--time-limit",
        Field::Samples => "--samples",
        Field::Tile => "--tile",
        Field::Environment => "--environment",
    }
}

/// A `--resume` file of another render, or of another share of it: the
/// command ends with exit status [`ResumeOfAnotherRender::EXIT_STATUS`], so
/// that a job script can tell it from a failure that running again may cure.
#[derive(Debug)]
pub(crate) struct ResumeOfAnotherRender(pub(crate) String);

impl ResumeOfAnotherRender {
    /// The exit status.
    pub(crate) const EXIT_STATUS: u8 = 3;
}

impl std::fmt::Display for ResumeOfAnotherRender {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ResumeOfAnotherRender {}

/// A render that cannot be done, in the words of the command line (a
/// script keeps the library's words, which name no option).
pub(crate) fn job_error(error: JobError, phrasing: Phrasing) -> anyhow::Error {
    use anyhow::anyhow;
    if error.is_resume_of_another_render() {
        let message = match &error {
            JobError::ResumeOfAnotherRender { path, differences } => format!(
                "--resume {}: it is of another render ({}); resume it with the scene and options it was started with",
                path.display(),
                differences.join("; ")
            ),
            JobError::ResumeOfAnotherShare { path, theirs_rows, theirs_samples, rows, samples } => format!(
                "--resume {}: it holds rows {theirs_rows:?} and samples {theirs_samples:?}, this job renders rows \
                 {rows:?} and samples {samples:?} (check --tile and --samples)",
                path.display()
            ),
            _ => error.to_string(),
        };
        return ResumeOfAnotherRender(message).into();
    }
    if phrasing == Phrasing::Script {
        return error.into();
    }
    match error {
        JobError::Recipe(error) => recipe_error(error, phrasing),
        JobError::PartNotAccumulated => anyhow!(
            "--samples and --tile render a part of an image: write it to an .accum file (-o part.accum) and put the \
             parts together with 'rtgi merge'"
        ),
        JobError::DenoiseAccumulation { output } => anyhow!(
            "--denoise on: {} keeps the samples' sums, which a filter cannot apply to; denoise the image (-o \
             image.png or .exr) instead",
            output.display()
        ),
        JobError::DenoiseNotLight(integrator) => anyhow!(
            "--denoise on is for the direct and path integrators: the {integrator} integrator's image is not noisy light"
        ),
        JobError::AovOfPart => anyhow!("--aov is for whole renders, not with --samples or --tile"),
        JobError::NotAnAov { aov, allowed } => anyhow!("--aov {aov}: not an output variable (use one of {allowed})"),
        JobError::InputAsOutput { field, path, what } => {
            let what = if what == Field::Environment.name() { "--environment".to_owned() } else { what };
            anyhow!("{} {}: is {what}, which the command reads; write to another file", flag(field), path.display())
        }
        JobError::Memory { width, height, needed_gib, available_gib } => anyhow!(
            "--width {width} --height {height}: the render needs about {needed_gib:.1} GiB of memory and \
             {available_gib:.1} GiB are available; render a smaller image, or split it with --tile and 'rtgi merge'"
        ),
        JobError::AdaptiveSplit(field) => {
            let what = match field {
                Field::TimeLimit => "--time-limit (which stops to checkpoint; --time bounds an adaptive render)",
                Field::Output => "an .accum output",
                other => flag(other),
            };
            anyhow!(
                "--noise and --time sample each pixel until its own samples say it is done, so the render cannot be \
                 split, checkpointed or resumed: {what} cannot go with them; render in one go, or use --spp"
            )
        }
        JobError::TileTooFine { index, count, height } => {
            anyhow!("--tile {index}/{count}: the image has only {height} rows")
        }
        JobError::SamplesBeyond { range, spp } => {
            anyhow!("--samples {}..{}: the render has {spp} samples per pixel (--spp)", range.start, range.end)
        }
        other => other.into(),
    }
}

/// A render that cannot be prepared, in the words of the command line:
/// the library names its fields, the app its options.
pub(crate) fn recipe_error(error: recipe::RecipeError, phrasing: Phrasing) -> anyhow::Error {
    use recipe::RecipeError;
    if phrasing == Phrasing::Script {
        return error.into();
    }
    match error {
        RecipeError::CameraIndex { index, count } => {
            anyhow::anyhow!("--camera {index}: the scene has {count} camera(s), numbered from 0")
        }
        RecipeError::FieldOfView(fov) => {
            anyhow::anyhow!("--fov {fov}: the field of view must be between 0 and 180 degrees")
        }
        RecipeError::DegenerateCamera => anyhow::anyhow!(
            "the camera is degenerate: it must look somewhere other than its own position (--at, --look), and not \
             along --up"
        ),
        other => other.into(),
    }
}

/// Says which of several file cameras was used, which automatic view, and
/// which up axis (the warning of a buried camera is a [`Warning`]).
pub(crate) fn report_camera(chosen: &ChosenCamera, phrasing: Phrasing) {
    if let Some(choice) = &chosen.file_choice {
        eprintln!("note: the view is {choice}");
    }
    if let Some(view) = &chosen.automatic_view {
        eprintln!("note: the automatic view is {view}; {} choose another", phrasing.move_camera());
    }
    if let Some(share) = chosen.up.base_share {
        eprintln!(
            "note: {} is up: the model stands on a flat base facing {} ({:.1}% of its surface) and has none across \
             Y, so the view, the default sky and the sun turn with it; {} keeps +Y",
            chosen.up.name(),
            rtgi_render::up_axis::axis_name(-chosen.up.up),
            100.0 * share,
            phrasing.up_y()
        );
    }
}

/// Prints a render's warning on standard error, with the options (or
/// script commands) that help; `exposure_given` says whether the image's
/// exposure was chosen by hand.
pub(crate) fn warn(warning: &Warning, phrasing: Phrasing, exposure_given: bool) {
    match warning {
        Warning::Scene { message } => eprintln!("warning: {message}"),
        Warning::CameraInsideGeometry { fraction } => eprintln!(
            "warning: the camera seems to be inside geometry: {:.0}% of the rays through its view hit the back of a \
             surface or start against one; move it with {}",
            100.0 * fraction,
            phrasing.move_camera()
        ),
        Warning::AlmostBlack { fraction } => {
            // A script's images are not exposed (as the course's are not).
            let exposure = if exposure_given && phrasing == Phrasing::Options { "raise --exposure, or " } else { "" };
            eprintln!(
                "warning: the image is almost black ({:.0}% of its pixels): the scene's lights may be too weak \
                 or hidden from the view, or the camera inside geometry; {exposure}add light ({}), or move the \
                 camera ({})",
                100.0 * fraction,
                phrasing.add_light(),
                phrasing.move_camera()
            );
        }
        Warning::AlmostWhite { fraction } => {
            let what = match phrasing {
                Phrasing::Script => "the light is too strong for an image that is not exposed: dim the lights \
                                     (pointlight col, skylight scale, material emissive)"
                    .to_owned(),
                Phrasing::Options if exposure_given => {
                    "lower --exposure or leave it out (automatic), or use --tonemap aces".to_owned()
                }
                Phrasing::Options => "lower --exposure, or use --tonemap aces".to_owned(),
            };
            eprintln!("warning: the image is almost white ({:.0}% of its pixels): {what}", 100.0 * fraction);
        }
    }
}
