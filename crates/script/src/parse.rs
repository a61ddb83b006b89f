//! Text to [`Command`]s, one line at a time: a line becomes a command or a
//! [`ParseError`] saying what the command expects. The parser knows only
//! the syntax and the ranges the course allows; whether a command makes
//! sense now (a `run` before a `commit`, say) is the interpreter's to say.

use rtgi_accel::AccelKind;
use rtgi_math::{Mat4, Vec3};
use rtgi_render::BounceSampling;

use crate::brdf::CourseBrdf;
use crate::command::{Algo, BvhCommand, Command, CourseSplit, DirectSampling, MaterialCommand, PathSetting, Tracer};

/// The widest and tallest image `resolution` accepts: a render's own
/// bound ([`rtgi_job::MAX_IMAGE_SIDE`]), beyond which a typo (an extra
/// zero) would ask for gigabytes of memory and hours of rendering.
pub const MAX_RESOLUTION: u32 = rtgi_job::MAX_IMAGE_SIDE;

/// A line that is not a command of the language: which command it names
/// and what that command expects instead. Its message is what is wrong;
/// the caller, who knows the file and the line's number, says where.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{problem}")]
pub struct ParseError {
    command: String,
    problem: String,
}

impl ParseError {
    /// The command's name as the line spells it (the first word), known or not.
    pub fn command(&self) -> &str {
        &self.command
    }

    /// What is wrong, as the message says it.
    pub fn problem(&self) -> &str {
        &self.problem
    }
}

/// Parses one line. Blank lines and comments (`#`, `//`) are
/// [`Command::Nothing`]; anything else is a command or an error naming it.
///
/// ```
/// use rtgi_script::{Command, parse};
/// use rtgi_math::Vec3;
///
/// assert_eq!(parse("at 0 1 2")?, Command::At(Some(Vec3::new(0.0, 1.0, 2.0))));
/// let error = parse("sppx many").unwrap_err();
/// assert_eq!((error.command(), error.to_string().as_str()), ("sppx", "expects one positive whole number (got 'many')"));
/// # Ok::<(), rtgi_script::ParseError>(())
/// ```
pub fn parse(line: &str) -> Result<Command, ParseError> {
    let line = line.trim();
    let Some(name) = line.split_whitespace().next() else { return Ok(Command::Nothing) };
    command(name, line).map_err(|problem| ParseError { command: name.to_owned(), problem })
}

/// The command `name`, the first word of `line`; the error says what it expects.
fn command(name: &str, line: &str) -> Result<Command, String> {
    if name.starts_with('#') || name.starts_with("//") {
        return Ok(Command::Nothing);
    }
    let words: Vec<&str> = line.split_whitespace().skip(1).collect();
    // The text after the command's name, as typed (names may hold spaces).
    let rest = line[name.len()..].trim();
    let none = |command: Command| if words.is_empty() { Ok(command) } else { Err("takes no arguments".to_owned()) };
    match name {
        "at" => optional_vec3(&words).map(Command::At),
        "look" => optional_vec3(&words).map(Command::Look),
        "up" => optional_direction(&words).map(Command::Up),
        "camup" => optional_direction(&words).map(Command::CamUp),
        "print-cam" => none(Command::PrintCam),
        "load" => match words[..] {
            [file] => Ok(Command::Load { file: file.into(), name: None }),
            [file, name] => Ok(Command::Load { file: file.into(), name: Some(name.to_owned()) }),
            _ => Err("expects a file name (no spaces) and, optionally, a name".to_owned()),
        },
        "modelpath" => match words[..] {
            [dir] => Ok(Command::ModelPath(dir.into())),
            _ => Err("expects one folder (no spaces)".to_owned()),
        },
        "modelmatrix" => {
            let values = numbers(&words, 16)
                .map_err(|_| "expects 16 numbers, the matrix column by column (the translation last)".to_owned())?;
            // The framework reads m[0][0], m[0][1], ... into a glm matrix,
            // whose first index is the column: column-major, as glam's.
            Ok(Command::ModelMatrix(Mat4::from_cols_slice(&values)))
        }
        "modeltrafo" => model_trafo(&words).map(Command::ModelTrafo),
        "resolution" => match words[..] {
            [w, h] => match (positive_int(w), positive_int(h)) {
                (Some(w), Some(h)) if w <= MAX_RESOLUTION && h <= MAX_RESOLUTION => Ok(Command::Resolution(w, h)),
                _ => Err(format!("expects two whole numbers from 1 to {MAX_RESOLUTION}, W H (got '{rest}')")),
            },
            _ => Err("expects two positive whole numbers, W H".to_owned()),
        },
        "sppx" => one_positive(&words).map(Command::Sppx),
        "outfile" => match words[..] {
            [file] => Ok(Command::Outfile(file.into())),
            _ => Err("expects one file name (no spaces)".to_owned()),
        },
        "commit" => none(Command::Commit),
        "run" => none(Command::Run),
        "raytracer" => tracer(&words).map(Command::Raytracer),
        "bvh" => bvh(&words).map(Command::Bvh),
        "algo" => algo(&words),
        "is" => match words[..] {
            ["uniform"] => Ok(Command::Is(DirectSampling::Uniform)),
            ["cosine"] => Ok(Command::Is(DirectSampling::Cosine)),
            ["light"] => Ok(Command::Is(DirectSampling::Light)),
            ["brdf"] => Ok(Command::Is(DirectSampling::Brdf)),
            ["mis"] => Ok(Command::Is(DirectSampling::Mis)),
            _ => Err(format!("expects one of uniform, cosine, light, brdf (got '{rest}')")),
        },
        "path" => path(&words).map(Command::Path),
        "material" => material(&words, rest).map(Command::Material),
        "default-brdf" => match words[..] {
            [name] => CourseBrdf::from_name(name).map_err(|e| e.to_string()).map(Command::DefaultBrdf),
            _ => Err(format!("expects one BRDF name: {}", CourseBrdf::NAMES)),
        },
        "pointlight" => point_light(&words),
        "skylight" => match words[..] {
            ["load", file, scale] => match scale.parse::<f32>() {
                Ok(scale) if scale.is_finite() && scale > 0.0 => Ok(Command::SkylightLoad { file: file.into(), scale }),
                _ => Err(format!("load: the intensity scale must be a number above 0 (got '{scale}')")),
            },
            ["load", ..] => Err("load expects a file name (no spaces) and an intensity scale".to_owned()),
            ["scale", scale] => match scale.parse::<f32>() {
                Ok(scale) if scale.is_finite() && scale > 0.0 => Ok(Command::SkylightScale(scale)),
                _ => Err(format!("scale: the intensity scale has to be a value above 0 (got '{scale}')")),
            },
            _ => Err("expects 'load FILE SCALE' or 'scale S'".to_owned()),
        },
        "skytest" => Ok(Command::Unavailable { command: "skytest", feature: "debug images of the sky's distribution" }),
        "echo" => Ok(Command::Echo(rest.to_owned())),
        "stats" => match words[..] {
            ["print"] => Ok(Command::StatsPrint),
            ["clear"] => Ok(Command::StatsClear),
            _ => Err("expects 'print' or 'clear'".to_owned()),
        },
        "mem-stats" => none(Command::MemStats),
        "history" => none(Command::History),
        "quit" | "exit" => none(Command::Quit),
        "omp" => on_off(&words).map(Command::Omp),
        "platform" => match words[..] {
            [] => Ok(Command::Platform(None)),
            [name, ..] => Ok(Command::Platform(Some(name.to_owned()))),
        },
        "denoise" => match words[..] {
            ["on"] => Ok(Command::Denoise(true)),
            ["off"] => Ok(Command::Denoise(false)),
            _ => Err("expects 'on' or 'off'".to_owned()),
        },
        "disable" => match words[..] {
            [feature] => Ok(Command::Disable(feature.to_owned())),
            _ => Err("expects one feature to disable".to_owned()),
        },
        "with" => match words[..] {
            [feature, "{"] if ["gl", "cuda", "optix"].contains(&feature) => Ok(Command::With(feature.to_owned())),
            [feature, "{"] => Err(format!("expects one of gl, cuda, optix (got '{feature}')")),
            _ => Err("expects 'with gl|cuda|optix {' on a line of its own".to_owned()),
        },
        "}" => none(Command::EndBlock).map_err(|_| "} must be on an otherwise empty line".to_owned()),
        "preview-offset" => {
            one_positive(&words)?;
            Ok(Command::Unavailable { command: "preview-offset", feature: "preview window" })
        }
        "move-speed" => Ok(Command::Unavailable { command: "move-speed", feature: "preview window" }),
        "add-scene-step" => Ok(Command::Unavailable { command: "add-scene-step", feature: "wavefront steps" }),
        _ => Err(match similar_command(name) {
            Some(known) => format!("unknown command; did you mean '{known}'?"),
            None => "unknown command".to_owned(),
        }),
    }
}

/// Every command's name (the suggestions of "did you mean" come from here).
pub const COMMANDS: &[&str] = &[
    "at",
    "look",
    "up",
    "camup",
    "print-cam",
    "load",
    "modelpath",
    "modelmatrix",
    "modeltrafo",
    "resolution",
    "sppx",
    "outfile",
    "commit",
    "run",
    "raytracer",
    "bvh",
    "algo",
    "is",
    "path",
    "material",
    "default-brdf",
    "pointlight",
    "skylight",
    "skytest",
    "echo",
    "stats",
    "mem-stats",
    "history",
    "quit",
    "exit",
    "omp",
    "platform",
    "denoise",
    "disable",
    "with",
    "preview-offset",
    "move-speed",
    "add-scene-step",
];

/// The command `typed` is most likely a misspelling of: at most two edits
/// away (one for short names, a swap of neighbours counting one), the nearest.
fn similar_command(typed: &str) -> Option<&'static str> {
    let allowed = if typed.len() <= 3 { 1 } else { 2 };
    COMMANDS
        .iter()
        .map(|&known| (strsim::damerau_levenshtein(typed, known), known))
        .filter(|&(distance, _)| distance <= allowed)
        .min()
        .map(|(_, known)| known)
}

/// A direction: three numbers, not all zero.
fn optional_direction(words: &[&str]) -> Result<Option<Vec3>, String> {
    match optional_vec3(words)? {
        Some(v) if v == Vec3::ZERO => Err("the direction must not be 0 0 0".to_owned()),
        v => Ok(v),
    }
}

fn optional_vec3(words: &[&str]) -> Result<Option<Vec3>, String> {
    if words.is_empty() {
        return Ok(None);
    }
    let values = numbers(words, 3).map_err(|got| format!("expects 3 numbers, X Y Z (got '{got}')"))?;
    Ok(Some(Vec3::from_slice(&values)))
}

/// Exactly `count` finite numbers, or the words as typed.
fn numbers(words: &[&str], count: usize) -> Result<Vec<f32>, String> {
    let values: Vec<f32> = words.iter().filter_map(|w| w.parse::<f32>().ok().filter(|v| v.is_finite())).collect();
    if words.len() == count && values.len() == count { Ok(values) } else { Err(words.join(" ")) }
}

fn positive_int(word: &str) -> Option<u32> {
    word.parse::<u32>().ok().filter(|&n| n > 0)
}

fn one_positive(words: &[&str]) -> Result<u32, String> {
    match words[..] {
        [n] => positive_int(n).ok_or_else(|| format!("expects one positive whole number (got '{n}')")),
        _ => Err("expects one positive whole number".to_owned()),
    }
}

fn on_off(words: &[&str]) -> Result<bool, String> {
    match words[..] {
        ["on"] => Ok(true),
        ["off"] => Ok(false),
        _ => Err("expects 'on' or 'off'".to_owned()),
    }
}

fn model_trafo(words: &[&str]) -> Result<Mat4, String> {
    match words {
        [kind @ ("shift" | "translate"), xyz @ ..] => {
            let v = numbers(xyz, 3).map_err(|got| format!("{kind} expects 3 numbers, X Y Z (got '{got}')"))?;
            Ok(Mat4::from_translation(Vec3::from_slice(&v)))
        }
        ["rotate", axis, degrees] => {
            let axis = match *axis {
                "x" | "X" => Vec3::X,
                "y" | "Y" => Vec3::Y,
                "z" | "Z" => Vec3::Z,
                other => return Err(format!("rotate: invalid axis of rotation '{other}' (x, y or z)")),
            };
            let degrees =
                numbers(&[degrees], 1).map_err(|got| format!("rotate expects an angle in degrees (got '{got}')"))?;
            Ok(Mat4::from_axis_angle(axis, degrees[0].to_radians()))
        }
        ["rotate", ..] => Err("rotate expects an axis (x, y or z) and an angle in degrees".to_owned()),
        ["scale", xyz @ ..] => {
            let v = numbers(xyz, 3).map_err(|got| format!("scale expects 3 numbers, X Y Z (got '{got}')"))?;
            Ok(Mat4::from_scale(Vec3::from_slice(&v)))
        }
        [other, ..] => Err(format!("unsupported trafo '{other}' (shift, translate, rotate or scale)")),
        [] => Err("expects shift|translate X Y Z, rotate x|y|z DEGREES or scale X Y Z".to_owned()),
    }
}

fn split(word: &str) -> Option<CourseSplit> {
    match word {
        "om" => Some(CourseSplit::ObjectMedian),
        "sm" => Some(CourseSplit::SpatialMedian),
        "sah" => Some(CourseSplit::Sah),
        _ => None,
    }
}

fn tracer(words: &[&str]) -> Result<Tracer, String> {
    let ours: Vec<&str> = AccelKind::ALL.iter().map(|k| k.name()).filter(|n| *n != "linear").collect();
    let known =
        || format!("seq, naive-bvh, bbvh [om|sm|sah [NPLANES]], embree, or one of rtgi's own: {}", ours.join(", "));
    match words {
        ["seq"] => Ok(Tracer::Seq),
        ["naive-bvh"] => Ok(Tracer::NaiveBvh),
        ["embree" | "embree-alpha"] => Ok(Tracer::Embree),
        ["bbvh", tags @ ..] => {
            // The framework's triangle layouts and escape indices change
            // its memory layout, not the tree: here they change nothing.
            let tags: Vec<&str> = tags.iter().copied().filter(|t| !matches!(*t, "indexed" | "flat" | "esc")).collect();
            match tags[..] {
                [] => Ok(Tracer::Bbvh(None)),
                [method] => split(method)
                    .map(|s| Tracer::Bbvh(Some((s, None))))
                    .ok_or_else(|| format!("there is no such bbvh variant '{method}' (om, sm or sah)")),
                ["sah", planes] => sah_planes(planes).map(|n| Tracer::Bbvh(Some((CourseSplit::Sah, Some(n))))),
                _ => Err("bbvh expects om, sm or sah [NPLANES]".to_owned()),
            }
        }
        [name] => match name.parse::<AccelKind>() {
            Ok(kind) if kind != AccelKind::Linear => Ok(Tracer::Ours(kind)),
            _ => Err(format!("there is no ray tracer called '{name}' ({})", known())),
        },
        _ => Err(format!("expects one ray tracer: {}", known())),
    }
}

/// The planes of the course's SAH: N + 1 bins, and we bin at most 256.
fn sah_planes(word: &str) -> Result<u32, String> {
    positive_int(word)
        .filter(|&n| n <= 255)
        .ok_or_else(|| format!("sah expects a number of planes from 1 to 255 (got '{word}')"))
}

fn bvh(words: &[&str]) -> Result<BvhCommand, String> {
    match words {
        [method] if split(method).is_some() => Ok(BvhCommand::Split(split(method).expect("checked"), None)),
        ["sah", planes] => sah_planes(planes).map(|n| BvhCommand::Split(CourseSplit::Sah, Some(n))),
        ["triangles", "single"] => Ok(BvhCommand::LeafSize(1)),
        ["triangles", "multiple", n] => positive_int(n)
            .filter(|&n| n <= 255)
            .map(BvhCommand::LeafSize)
            .ok_or_else(|| format!("triangles multiple expects a leaf size from 1 to 255 (got '{n}')")),
        ["statistics"] => Ok(BvhCommand::Statistics),
        ["export", depth, file] => depth
            .parse::<usize>()
            .map(|depth| BvhCommand::Export { depth, file: file.into() })
            .map_err(|_| format!("export expects a depth (a whole number) and an .obj file (got '{depth}')")),
        _ => {
            Err("expects om|sm|sah [NPLANES], triangles single|multiple N, statistics or export DEPTH FILE.obj"
                .to_owned())
        }
    }
}

fn algo(words: &[&str]) -> Result<Command, String> {
    let algo = match words {
        ["primary"] => Algo::Primary,
        ["info"] => Algo::Info,
        ["local"] => Algo::Local,
        ["direct"] => Algo::Direct,
        ["direct/mis"] => Algo::DirectMis,
        ["simple-pt"] => Algo::SimplePt,
        ["pt"] => Algo::Pt,
        ["primary-wf"] => return Ok(Command::WavefrontAlgo { name: "primary-wf", instead: Algo::Primary }),
        ["direct-wf"] => return Ok(Command::WavefrontAlgo { name: "direct-wf", instead: Algo::Direct }),
        [name] => {
            return Err(format!(
                "there is no gi algorithm called '{name}' (primary, info, local, direct, direct/mis, simple-pt, pt)"
            ));
        }
        _ => return Err("expects one algorithm: primary, info, local, direct, direct/mis, simple-pt or pt".to_owned()),
    };
    Ok(Command::Algo(algo))
}

fn path(words: &[&str]) -> Result<PathSetting, String> {
    match words {
        ["len", n] => positive_int(n)
            .filter(|&n| n <= 1024)
            .map(PathSetting::Length)
            .ok_or_else(|| format!("len expects a whole number from 1 to 1024 (got '{n}')")),
        ["rr-start", n] => positive_int(n)
            .map(PathSetting::RouletteStart)
            .ok_or_else(|| format!("rr-start expects a positive whole number (got '{n}')")),
        ["bounce", "uniform"] => Ok(PathSetting::Bounce(BounceSampling::Uniform)),
        ["bounce", "cosine"] => Ok(PathSetting::Bounce(BounceSampling::Cosine)),
        ["bounce", "brdf"] => Ok(PathSetting::Bounce(BounceSampling::Bsdf)),
        ["bounce", other] => Err(format!("invalid kind of path bounce '{other}' (uniform, cosine or brdf)")),
        ["mis", "on"] => Ok(PathSetting::Mis(true)),
        ["mis", "off"] => Ok(PathSetting::Mis(false)),
        ["mis", ..] => Err("usage: path mis on|off".to_owned()),
        [other, ..] => Err(format!("unknown subcommand to path '{other}' (len, rr-start, bounce, mis)")),
        [] => Err("expects len N, rr-start N, bounce uniform|cosine|brdf or mis on|off".to_owned()),
    }
}

fn material(words: &[&str], rest: &str) -> Result<MaterialCommand, String> {
    let Some((&sub, args)) = words.split_first() else {
        return Err("expects list, select NAME, blacklist NAME, or a setting of the selected material".to_owned());
    };
    // The name is the rest of the line after the subcommand, spaces and all.
    let name = rest[sub.len()..].trim();
    let colour = |what: &str| {
        numbers(args, 3).map(|v| Vec3::from_slice(&v)).ok().filter(|c| c.min_element() >= 0.0).ok_or_else(|| {
            format!("{what} expects a colour triplet R G B of finite numbers of at least 0 (got '{}')", args.join(" "))
        })
    };
    let number = |what: &str, accept: fn(f32) -> bool, allowed: &str| {
        numbers(args, 1)
            .ok()
            .map(|v| v[0])
            .filter(|&v| accept(v))
            .ok_or_else(|| format!("{what} expects {allowed} (got '{}')", args.join(" ")))
    };
    match sub {
        "list" if args.is_empty() => Ok(MaterialCommand::List),
        "select" if !name.is_empty() => Ok(MaterialCommand::Select(name.to_owned())),
        "blacklist" if !name.is_empty() => Ok(MaterialCommand::Blacklist(name.to_owned())),
        "select" | "blacklist" => Err(format!("{sub} expects a material name")),
        "albedo" => colour("albedo").map(MaterialCommand::Albedo),
        "emissive" => colour("emissive").map(MaterialCommand::Emissive),
        "roughness" => number("roughness", |v| v >= 0.0, "a number of at least 0").map(MaterialCommand::Roughness),
        "ior" => number("ior", |v| v > 0.0, "a number above 0").map(MaterialCommand::Ior),
        "texture" => match args {
            ["drop"] => Ok(MaterialCommand::Texture(None)),
            [file] => Ok(MaterialCommand::Texture(Some(file.into()))),
            _ => Err("texture expects one file name (no spaces) or 'drop'".to_owned()),
        },
        "brdf" => match args {
            [name] => CourseBrdf::from_name(name).map_err(|e| e.to_string()).map(MaterialCommand::Brdf),
            _ => Err(format!("brdf expects one BRDF name: {}", CourseBrdf::NAMES)),
        },
        "show" if args.is_empty() => Ok(MaterialCommand::Show),
        "list" | "show" => Err(format!("{sub} takes no further arguments")),
        other => Err(format!(
            "unknown subcommand '{other}' (list, select, blacklist, albedo, emissive, roughness, ior, texture, brdf, show)"
        )),
    }
}

fn point_light(words: &[&str]) -> Result<Command, String> {
    let usage = "usage: pointlight [replace] pos X Y Z col R G B";
    let (replace, words) = match words.split_first() {
        Some((&"replace", rest)) => (true, rest),
        _ => (false, words),
    };
    match words {
        ["pos", x, y, z, "col", r, g, b] => {
            let position =
                numbers(&[x, y, z], 3).map_err(|got| format!("pos expects 3 numbers (got '{got}'); {usage}"))?;
            let colour = numbers(&[r, g, b], 3)
                .ok()
                .filter(|c| c.iter().all(|&v| v >= 0.0))
                .ok_or_else(|| format!("col expects 3 numbers of at least 0; {usage}"))?;
            Ok(Command::PointLight {
                replace,
                position: Vec3::from_slice(&position),
                colour: Vec3::from_slice(&colour),
            })
        }
        _ => Err(usage.to_owned()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_course_commands() {
        assert_eq!(parse("  # a comment").unwrap(), Command::Nothing);
        assert_eq!(parse("// another").unwrap(), Command::Nothing);
        assert_eq!(parse("").unwrap(), Command::Nothing);
        assert_eq!(parse("at -13 -12 0").unwrap(), Command::At(Some(Vec3::new(-13.0, -12.0, 0.0))));
        assert_eq!(parse("at").unwrap(), Command::At(None));
        assert_eq!(
            parse("raytracer bbvh sah 8").unwrap(),
            Command::Raytracer(Tracer::Bbvh(Some((CourseSplit::Sah, Some(8)))))
        );
        assert_eq!(parse("raytracer bbvh indexed esc").unwrap(), Command::Raytracer(Tracer::Bbvh(None)));
        assert_eq!(parse("raytracer bvh8").unwrap(), Command::Raytracer(Tracer::Ours(AccelKind::Bvh8)));
        assert_eq!(
            parse("material select kamen zid").unwrap(),
            Command::Material(MaterialCommand::Select("kamen zid".into()))
        );
        assert_eq!(parse("echo  >>>> WITH RR").unwrap(), Command::Echo(">>>> WITH RR".into()));
        assert_eq!(
            parse("pointlight replace pos 7 -8 0 col 7 4 2").unwrap(),
            Command::PointLight {
                replace: true,
                position: Vec3::new(7.0, -8.0, 0.0),
                colour: Vec3::new(7.0, 4.0, 2.0)
            }
        );
        let columns = "modelmatrix 1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1";
        assert_eq!(parse(columns).unwrap(), Command::ModelMatrix(Mat4::from_translation(Vec3::new(5.0, 6.0, 7.0))));
        assert_eq!(parse("path bounce cosine").unwrap(), Command::Path(PathSetting::Bounce(BounceSampling::Cosine)));
        assert_eq!(parse("with cuda {").unwrap(), Command::With("cuda".into()));
    }

    #[test]
    fn says_what_a_command_expects() {
        for (line, expected) in [
            ("at 1 2", "expects 3 numbers, X Y Z (got '1 2')"),
            ("resolution 640", "two positive whole numbers"),
            ("sppx -3", "one positive whole number (got '-3')"),
            ("raytracer kd-tree", "no ray tracer called 'kd-tree'"),
            ("raytracer bbvh median", "no such bbvh variant 'median'"),
            ("algo photon-map", "no gi algorithm called 'photon-map'"),
            ("is importance", "uniform, cosine, light, brdf (got 'importance')"),
            ("material roughness x", "roughness expects a number of at least 0 (got 'x')"),
            ("material brdf velvet", "No such brdf defined: velvet"),
            ("pointlight pos 1 2 3", "usage: pointlight [replace] pos X Y Z col R G B"),
            ("skylight scale 0", "above 0"),
            ("} x", "} must be on an otherwise empty line"),
            ("commit now", "takes no arguments"),
            ("teleport", "unknown command"),
            ("laod scene.obj", "unknown command; did you mean 'load'?"),
            ("raytraser seq", "did you mean 'raytracer'?"),
            ("camup 0 0 0", "must not be 0 0 0"),
            ("resolution 100000 10", "from 1 to 16384"),
            ("path len 1025", "from 1 to 1024"),
        ] {
            let error = parse(line).unwrap_err();
            assert!(error.to_string().contains(expected), "{line}: {error}");
            assert_eq!(error.command(), line.split_whitespace().next().unwrap(), "{line}");
        }
    }
}
