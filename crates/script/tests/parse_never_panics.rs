//! The property the `script_parse` fuzz target checks (`fuzz/`, nightly),
//! run on stable by every `cargo test`: no text makes [`parse`] panic. A
//! refused line names its first word as the command and says something; an
//! accepted one carries only finite numbers in the ranges the course
//! allows, so the interpreter never sees NaN, infinity or an absurd size.
//!
//! Random text alone rarely gets past the command's name, so most cases
//! are a known command (or a near miss) followed by words that sit on the
//! parser's edges: wrong arities, numbers that do not fit (`nan`, `inf`,
//! `1e39`, 2^32), unicode, braces, and very long lines.

use proptest::prelude::*;
use rtgi_math::Vec3;
use rtgi_script::{COMMANDS, Command, MAX_RESOLUTION, MaterialCommand, parse};

/// Near misses of the language's command names ([`COMMANDS`]), and words
/// that end or open blocks.
const NEAR_MISSES: &[&str] = &["laod", "AT", "é", "#", "//", "{", "}"];

/// A command name of the language, or a near miss.
fn name() -> impl Strategy<Value = &'static str> {
    prop::sample::select(COMMANDS.iter().chain(NEAR_MISSES).copied().collect::<Vec<_>>())
}

/// Words the commands look for, and numbers and text on their edges.
#[rustfmt::skip] // In groups, as the comments say, rather than one a line.
const WORDS: &[&str] = &[
    // Subcommands and choices.
    "seq", "naive-bvh", "bbvh", "embree", "om", "sm", "sah", "indexed", "esc", "bvh8", "linear", "triangles",
    "single", "multiple", "statistics", "export", "primary", "direct/mis", "pt", "primary-wf", "uniform", "cosine",
    "light", "brdf", "mis", "len", "rr-start", "bounce", "on", "off", "list", "select", "blacklist", "albedo",
    "emissive", "roughness", "ior", "texture", "drop", "show", "lambert", "gtr2", "velvet", "replace", "pos", "col",
    "load", "scale", "print", "clear", "gl", "cuda", "{", "}", "shift", "translate", "rotate", "x", "Y", "w",
    // Numbers that fit, and numbers that do not (f32 and u32 overflow, NaN, infinities, other notations).
    "0", "-0", "1", "-1", "2", "7.5", "255", "256", "1024", "1025", "16384", "16385", "4294967295", "4294967296",
    "18446744073709551616", "1e38", "3.4028235e38", "1e39", "-1e39", "1e-45", "1e-46", "nan", "NaN", "-nan", "inf",
    "-inf", "infinity", "+3", "0x10", "1_000", ".", "-", "e5", "1e", "\u{661}",
    // Names, unicode (combining, right-to-left, a byte-order mark) and control characters.
    "scene.obj", "a b", "u\u{308}", "\u{1f642}", "\u{0}", "\u{202e}", "\u{feff}", "\t", "#", "//",
];

fn known_word() -> impl Strategy<Value = String> {
    prop::sample::select(WORDS).prop_map(str::to_owned)
}

/// A word: mostly one the parser looks for, sometimes any text without spaces.
fn word() -> impl Strategy<Value = String> {
    prop_oneof![4 => known_word(), 1 => "\\PC{1,12}", 1 => any::<f32>().prop_map(|v| v.to_string())]
}

/// A known command (or a near miss) with 0 to 20 edge words, spaced oddly.
fn line() -> impl Strategy<Value = String> {
    (name(), prop::collection::vec(word(), 0..20), prop::sample::select(&[" ", "  ", "\t", " \u{3000}"][..])).prop_map(
        |(name, words, gap)| {
            let mut line = name.to_owned();
            for w in words {
                line.push_str(gap);
                line.push_str(&w);
            }
            line
        },
    )
}

/// Parses `text` and checks what it returns (a panic fails the case by itself).
fn check(text: &str) -> Result<(), TestCaseError> {
    match parse(text) {
        Ok(command) => check_command(&command),
        Err(error) => {
            let first = text.split_whitespace().next().unwrap_or("");
            prop_assert_eq!(error.command(), first);
            prop_assert!(!error.problem().is_empty());
            prop_assert_eq!(error.to_string(), error.problem());
            Ok(())
        }
    }
}

/// The numbers an accepted command carries are finite and in the course's ranges.
fn check_command(command: &Command) -> Result<(), TestCaseError> {
    match command {
        Command::At(Some(v)) | Command::Look(Some(v)) => prop_assert!(v.is_finite(), "{command:?}"),
        Command::Up(Some(v)) | Command::CamUp(Some(v)) => {
            prop_assert!(v.is_finite() && *v != Vec3::ZERO, "{command:?}")
        }
        Command::ModelMatrix(m) | Command::ModelTrafo(m) => prop_assert!(m.is_finite(), "{command:?}"),
        Command::Resolution(w, h) => {
            prop_assert!((1..=MAX_RESOLUTION).contains(w) && (1..=MAX_RESOLUTION).contains(h), "{command:?}")
        }
        Command::Sppx(n) => prop_assert!(*n > 0),
        Command::PointLight { position, colour, .. } => {
            prop_assert!(position.is_finite() && colour.is_finite() && colour.min_element() >= 0.0, "{command:?}")
        }
        Command::SkylightLoad { scale, .. } | Command::SkylightScale(scale) => {
            prop_assert!(scale.is_finite() && *scale > 0.0, "{command:?}")
        }
        Command::Material(MaterialCommand::Albedo(c) | MaterialCommand::Emissive(c)) => {
            prop_assert!(c.is_finite() && c.min_element() >= 0.0, "{command:?}")
        }
        Command::Material(MaterialCommand::Roughness(r)) => prop_assert!(r.is_finite() && *r >= 0.0),
        Command::Material(MaterialCommand::Ior(ior)) => prop_assert!(ior.is_finite() && *ior > 0.0),
        _ => {}
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn a_command_with_any_words_parses_or_says_why(line in line()) {
        check(&line)?;
    }

    #[test]
    fn any_text_parses_or_says_why(text in any::<String>()) {
        check(&text)?;
        // A whole script in one string, and each of its lines, as the app feeds them.
        for line in text.lines() {
            check(line)?;
        }
    }

    #[test]
    fn any_bytes_read_as_text_parse_or_say_why(bytes in prop::collection::vec(any::<u8>(), 0..256)) {
        check(&String::from_utf8_lossy(&bytes))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Very long lines: a command with thousands of words, or one word of
    /// thousands of characters (misspelt-command suggestions compare it).
    #[test]
    fn very_long_lines_parse_or_say_why(name in name(), w in known_word(), n in 1000usize..20_000) {
        let many = std::iter::repeat_n(w.as_str(), n / 4).collect::<Vec<_>>().join(" ");
        check(&format!("{name} {many}"))?;
        check(&format!("{name}{}", w.repeat(n / w.len().max(1))))?;
        check(&format!("material select {many}"))?;
    }
}

/// The edges that matter most, always tried (proptest samples them only now and then).
#[test]
fn numbers_that_do_not_fit_are_refused_by_name() {
    for line in [
        "at nan 0 0",
        "at 1e39 0 0",
        "look 0 -inf 0",
        "up 0 0 0",
        "camup -0 0 0",
        "resolution 4294967296 10",
        "resolution 16385 1",
        "sppx 0",
        "sppx 18446744073709551616",
        "skylight scale inf",
        "skylight load sky.floats nan",
        "material albedo 1 nan 1",
        "material emissive -1 0 0",
        "material roughness -0.5",
        "material ior 0",
        "pointlight pos 0 0 1e39 col 1 1 1",
        "pointlight pos 0 0 0 col 1 -1 1",
        "modelmatrix 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 nan",
        "modeltrafo rotate x inf",
        "modeltrafo scale 1 1 1e39",
        "bvh export 99999999999999999999 boxes.obj",
        "path len 4294967296",
        "raytracer bbvh sah 256",
    ] {
        let error = parse(line).expect_err(line);
        assert_eq!(error.command(), line.split_whitespace().next().unwrap(), "{line}");
    }
    // The largest finite numbers are numbers.
    assert!(matches!(parse("modeltrafo rotate y 3.4028235e38"), Ok(Command::ModelTrafo(m)) if m.is_finite()));
    assert_eq!(parse("at 3.4028235e38 -0 1e-45").unwrap(), Command::At(Some(Vec3::new(f32::MAX, 0.0, 1e-45))));
}
