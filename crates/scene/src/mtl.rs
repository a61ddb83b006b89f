//! A small parser of Wavefront MTL material libraries.
//!
//! It replaces tobj's MTL parser, which panicked on statements with too few
//! numbers and dropped every material of a file for one bad statement. Here
//! a statement that cannot be read becomes a warning naming `file:line` and
//! the statement, the material keeps its other fields, and the other
//! materials of the file load as they are.
//!
//! Statements read: `newmtl`; the colours `Ka`, `Kd`, `Ks`, `Ke`, `Tf` (one
//! number for grey or three for RGB, as the MTL specification allows; the
//! `spectral` and `xyz` forms are warned about and skipped); `Ns`, `Ni`,
//! `d` (with `-halo`), `Tr` (1 − d, where the material has no `d`), `illum` (0–10), `sharpness`; the PBR
//! extension's `Pr`, `Pm`, `Ps`, `Pc`, `Pcr`, `aniso`, `anisor`; and texture
//! maps (`map_Kd`, `map_Ka`, `map_Ks`, `map_Ke`, `map_Ns`, `map_d`, `map_Pr`,
//! `map_Pm`, `map_Ps`, `map_bump`, `bump`, `disp`, `decal`, `norm`, `refl`)
//! with their options (`-blendu`, `-blendv`, `-boost`, `-mm`, `-o`, `-s`,
//! `-t`, `-texres`, `-clamp`, `-bm`, `-imfchan`, `-type`, `-cc`) before the
//! file name, which may contain spaces. Other statements are ignored, as
//! other readers do.

use std::collections::HashMap;

use rtgi_math::Vec3;

/// One `newmtl` block: the fields the importer uses, `None` where absent.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct MtlMaterial {
    pub(crate) name: String,
    pub(crate) diffuse: Option<Vec3>,
    pub(crate) specular: Option<Vec3>,
    pub(crate) emissive: Option<Vec3>,
    pub(crate) shininess: Option<f32>,
    pub(crate) optical_density: Option<f32>,
    pub(crate) dissolve: Option<f32>,
    pub(crate) illumination_model: Option<u8>,
    /// The file name of `map_Kd`, without its options.
    pub(crate) diffuse_texture: Option<String>,
    /// The file name of `map_d` (a cut-out mask: leaves, fences), without its options.
    pub(crate) dissolve_texture: Option<String>,
    /// Whether `dissolve` came from a `d` statement (which `Tr` does not override).
    has_d: bool,
}

/// The materials of one file, in file order, and the statements that could not be read.
#[derive(Debug, Default)]
pub(crate) struct MtlLibrary {
    pub(crate) materials: Vec<MtlMaterial>,
    pub(crate) warnings: Vec<String>,
}

/// Options of map statements and how many arguments each takes (at most;
/// `-o`, `-s` and `-t` take one to three numbers).
const MAP_OPTIONS: &[(&str, usize)] = &[
    ("-blendu", 1),
    ("-blendv", 1),
    ("-boost", 1),
    ("-mm", 2),
    ("-o", 3),
    ("-s", 3),
    ("-t", 3),
    ("-texres", 1),
    ("-clamp", 1),
    ("-bm", 1),
    ("-imfchan", 1),
    ("-type", 1),
    ("-cc", 1),
];

const MAPS: &[&str] = &[
    "map_Kd", "map_Ka", "map_Ks", "map_Ke", "map_Ns", "map_d", "map_Pr", "map_Pm", "map_Ps", "map_bump", "bump",
    "disp", "decal", "norm", "refl", "map_refl", "map_Bump",
];

/// Parses MTL text; `file` names it in warnings.
pub(crate) fn parse(text: &str, file: &str) -> MtlLibrary {
    let mut library = MtlLibrary::default();
    let mut current: Option<MtlMaterial> = None;
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (keyword, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        // A comment may end a statement (`Ka 0.63 0.065 0.05 # Red`), except
        // a map's, whose file name may hold a '#'.
        let rest = if MAPS.contains(&keyword) { rest } else { rest.split('#').next().unwrap_or("") };
        let rest = rest.trim();
        let warn = |library: &mut MtlLibrary, why: &str| {
            library.warnings.push(format!("{file}:{}: '{}': {why}; the statement is ignored", number + 1, short(line)));
        };
        if keyword == "newmtl" {
            library.materials.extend(current.take());
            if rest.is_empty() {
                warn(&mut library, "a material needs a name");
            } else {
                current = Some(MtlMaterial { name: rest.to_owned(), ..MtlMaterial::default() });
            }
            continue;
        }
        if !is_known(keyword) {
            continue;
        }
        let Some(material) = current.as_mut() else {
            warn(&mut library, "no 'newmtl' before it");
            continue;
        };
        let result = match keyword {
            "Kd" => color(rest).map(|c| material.diffuse = Some(c)),
            "Ks" => color(rest).map(|c| material.specular = Some(c)),
            "Ke" => color(rest).map(|c| material.emissive = Some(c)),
            "Ka" | "Tf" => color(rest).map(drop),
            "Ns" => number_of(rest).map(|n| material.shininess = Some(n)),
            "Ni" => number_of(rest).map(|n| material.optical_density = Some(n)),
            "d" => number_of(rest.strip_prefix("-halo").map_or(rest, str::trim_start)).map(|n| {
                material.dissolve = Some(n);
                material.has_d = true;
            }),
            // Exporters disagree on whether Tr is 1 - d or d itself, so
            // `d` wins where a material has both (as tobj, which ignored Tr).
            "Tr" => number_of(rest).map(|n| {
                if !material.has_d {
                    material.dissolve = Some(1.0 - n);
                }
            }),
            "illum" => match rest.parse::<u8>() {
                Ok(n) if n <= 10 => {
                    material.illumination_model = Some(n);
                    Ok(())
                }
                _ => Err("expects an illumination model from 0 to 10".to_owned()),
            },
            "sharpness" | "Pr" | "Pm" | "Ps" | "Pc" | "Pcr" | "aniso" | "anisor" => number_of(rest).map(drop),
            map => map_file(rest).map(|name| {
                if map == "map_Kd" {
                    material.diffuse_texture = Some(name.to_owned());
                } else if map == "map_d" {
                    material.dissolve_texture = Some(name.to_owned());
                }
            }),
        };
        if let Err(why) = result {
            warn(&mut library, &why);
        }
    }
    library.materials.extend(current);
    library
}

/// The index of each material name; a name given twice means its last material (as tobj did).
pub(crate) fn index_by_name(materials: &[MtlMaterial]) -> HashMap<String, usize> {
    materials.iter().enumerate().map(|(i, m)| (m.name.clone(), i)).collect()
}

fn is_known(keyword: &str) -> bool {
    matches!(
        keyword,
        "Kd" | "Ks"
            | "Ke"
            | "Ka"
            | "Tf"
            | "Ns"
            | "Ni"
            | "d"
            | "Tr"
            | "illum"
            | "sharpness"
            | "Pr"
            | "Pm"
            | "Ps"
            | "Pc"
            | "Pcr"
            | "aniso"
            | "anisor"
    ) || MAPS.contains(&keyword)
}

fn parse_number(token: &str) -> Result<f32, String> {
    match token.parse::<f32>() {
        Ok(n) if n.is_finite() => Ok(n),
        _ => Err(format!("'{}' is not a finite number", short(token))),
    }
}

fn number_of(rest: &str) -> Result<f32, String> {
    let mut tokens = rest.split_whitespace();
    match (tokens.next(), tokens.next()) {
        (Some(token), None) => parse_number(token),
        (None, _) => Err("expects a number".to_owned()),
        (Some(_), Some(extra)) => Err(format!("expects one number, found '{}' after it", short(extra))),
    }
}

/// `r`, or `r g b`; the `spectral` and `xyz` forms are not supported.
fn color(rest: &str) -> Result<Vec3, String> {
    let tokens: Vec<&str> = rest.split_whitespace().take(4).collect();
    if matches!(tokens.first(), Some(&"spectral") | Some(&"xyz")) {
        return Err(format!("the '{}' colour form is not supported", tokens[0]));
    }
    match tokens[..] {
        [r] => parse_number(r).map(Vec3::splat),
        [r, g, b] => Ok(Vec3::new(parse_number(r)?, parse_number(g)?, parse_number(b)?)),
        _ => Err(format!(
            "expects 1 or 3 numbers, found {}",
            if tokens.len() > 3 { "more than 3".to_owned() } else { tokens.len().to_string() }
        )),
    }
}

/// The file name of a map statement, after its options.
fn map_file(mut rest: &str) -> Result<&str, String> {
    loop {
        rest = rest.trim_start();
        let Some(option) = rest.strip_prefix('-').and(rest.split_whitespace().next()) else { break };
        let Some(&(_, max_arguments)) = MAP_OPTIONS.iter().find(|(name, _)| *name == option) else {
            return Err(format!("unknown option '{}'", short(option)));
        };
        rest = &rest[option.len()..];
        for taken in 0..max_arguments {
            let trimmed = rest.trim_start();
            let Some(token) = trimmed.split_whitespace().next() else {
                return Err(format!("option '{option}' lacks its arguments and the file name"));
            };
            // -o, -s and -t take one to three numbers: stop at the first word that is not one.
            if taken > 0 && matches!(option, "-o" | "-s" | "-t") && token.parse::<f32>().is_err() {
                break;
            }
            rest = &trimmed[token.len()..];
        }
    }
    let name = rest.trim();
    if name.is_empty() { Err("names no file".to_owned()) } else { Ok(name) }
}

/// A statement or token shortened for messages.
fn short(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((end, _)) => format!("{}...", &text[..end]),
        None => text.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_fields_and_map_options() {
        let text = "# c\nnewmtl a\nKd 0.5 0.25 1\nKs 0.5\nKe 1 2 3\nNs 10\nNi 1.33\nd -halo 0.5\nillum 3\n\
                    map_Kd -bm 0.5 -s 1 2 -o 0.1 -clamp on my wall.jpg\nTr 1\nnewmtl b\nTr 0.25\nmap_Kd b.png\n";
        let library = parse(text, "m.mtl");
        assert!(library.warnings.is_empty(), "{:?}", library.warnings);
        let [a, b] = &library.materials[..] else { panic!("{:?}", library.materials) };
        assert_eq!(a.diffuse, Some(Vec3::new(0.5, 0.25, 1.0)));
        assert_eq!(a.specular, Some(Vec3::splat(0.5)));
        assert_eq!(a.emissive, Some(Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!((a.shininess, a.optical_density, a.dissolve), (Some(10.0), Some(1.33), Some(0.5)));
        assert_eq!(a.illumination_model, Some(3));
        assert_eq!(a.diffuse_texture.as_deref(), Some("my wall.jpg"));
        assert_eq!((b.name.as_str(), b.dissolve, b.diffuse_texture.as_deref()), ("b", Some(0.75), Some("b.png")));
    }

    #[test]
    fn bad_statements_are_warnings_naming_line_and_token() {
        let text = "newmtl a\nKd 0.5 0.5\nKs 1 x 1\nNs\nmap_Kd -bm\nnewmtl b\nKd 0.1 0.2 0.3 # blue\n";
        let library = parse(text, "car.mtl");
        assert_eq!(library.materials.len(), 2);
        assert_eq!(library.materials[1].diffuse, Some(Vec3::new(0.1, 0.2, 0.3)));
        assert_eq!(library.warnings.len(), 4, "{:?}", library.warnings);
        assert!(library.warnings[0].starts_with("car.mtl:2: 'Kd 0.5 0.5'"), "{}", library.warnings[0]);
        assert!(library.warnings[1].contains("'x'"), "{}", library.warnings[1]);
        assert!(library.warnings[2].starts_with("car.mtl:4: "), "{}", library.warnings[2]);
    }
}
