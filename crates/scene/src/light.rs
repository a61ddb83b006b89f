use rtgi_math::{Vec3, parse_vec3};

/// A light that is not a surface (emissive surfaces are materials).
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// A name for messages: the file's name for the light, or its specification text.
    pub name: String,
    /// Point, spot or directional, with the spot's cone.
    pub kind: LightKind,
    /// Where a point or spot light is.
    pub position: Vec3,
    /// The unit direction light travels in, for spot and directional lights.
    pub direction: Vec3,
    /// Linear RGB colour.
    pub color: Vec3,
    /// In glTF's units: candela (lm/sr) for point and spot lights, lux (lm/m²) for directional lights.
    pub intensity: f32,
    /// Distance beyond which the light has no effect, if limited.
    pub range: Option<f32>,
}

/// The shape of a light's emission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Light from one point, equally in every direction.
    Point,
    /// Full intensity inside `inner_cone`, none outside `outer_cone` (half-angles in radians).
    Spot {
        /// Half-angle of full intensity, in radians.
        inner_cone: f32,
        /// Half-angle beyond which there is no light, in radians, at least `inner_cone`.
        outer_cone: f32,
    },
    /// Parallel light from infinitely far away (the sun), along `direction`.
    Directional,
}

/// A light specification that [`Light::from_str`](std::str::FromStr) could
/// not read: the whole text and what is wrong with which field.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("light '{text}': {problem}")]
pub struct LightSpecError {
    /// The specification as given.
    pub text: String,
    /// The field at fault and what it must be, as a phrase.
    pub problem: String,
}

/// Reads the light specifications of the `rtgi` command's `--light`, fields
/// separated by colons and vectors by commas:
///
/// - `point:X,Y,Z:INTENSITY[:R,G,B]`, intensity in candela;
/// - `directional:DX,DY,DZ:IRRADIANCE[:R,G,B]`, the direction light
///   travels in, irradiance in lux;
/// - `spot:X,Y,Z:DX,DY,DZ:INTENSITY:INNER_DEG:OUTER_DEG[:R,G,B]`, the cone's
///   half-angles in degrees, `inner <= outer <= 90`.
///
/// The colour is linear RGB, white when omitted; the light is named by its
/// text. Numbers must be finite, intensities, angles and colours not
/// negative, directions not zero (they are normalised).
///
/// ```
/// use rtgi_scene::{Light, LightKind};
///
/// let light: Light = "spot:0,2,0:0,-1,0:50:20:30:1,0.9,0.8".parse()?;
/// assert!(matches!(light.kind, LightKind::Spot { .. }));
/// assert!("point:0,1:5".parse::<Light>().is_err());
/// # Ok::<(), rtgi_scene::LightSpecError>(())
/// ```
impl std::str::FromStr for Light {
    type Err = LightSpecError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let error = |problem: String| LightSpecError { text: text.to_owned(), problem };
        let fields: Vec<&str> = text.split(':').map(str::trim).collect();
        let number = |s: &str, what: &str| -> Result<f32, LightSpecError> {
            s.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| error(format!("{what} must be a non-negative number (got '{s}')")))
        };
        let vector = |s: &str, what: &str| {
            parse_vec3(s).ok_or_else(|| {
                error(format!("{what}: expected three finite numbers separated by commas, like 0,1.5,-2 (got '{s}')"))
            })
        };
        let colour = |rest: &[&str]| -> Result<Vec3, LightSpecError> {
            match rest {
                [] => Ok(Vec3::ONE),
                [c] => parse_vec3(c).filter(|c| c.min_element() >= 0.0).ok_or_else(|| {
                    error(format!(
                        "the colour: expected three finite numbers of at least 0 separated by commas, like \
                         0.05,0.05,0.06 (got '{c}')"
                    ))
                }),
                _ => Err(error("too many fields".into())),
            }
        };
        let unit = |v: Vec3| v.try_normalize().ok_or_else(|| error("the direction is zero".into()));
        let mut light = Light {
            name: text.to_owned(),
            kind: LightKind::Point,
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            intensity: 1.0,
            range: None,
        };
        match fields.as_slice() {
            ["point", position, intensity, rest @ ..] => {
                light.position = vector(position, "the position")?;
                light.intensity = number(intensity, "the intensity")?;
                light.color = colour(rest)?;
            }
            ["directional", direction, irradiance, rest @ ..] => {
                light.kind = LightKind::Directional;
                light.direction = unit(vector(direction, "the direction")?)?;
                light.intensity = number(irradiance, "the irradiance")?;
                light.color = colour(rest)?;
            }
            ["spot", position, direction, intensity, inner, outer, rest @ ..] => {
                let (inner, outer) = (number(inner, "the inner angle")?, number(outer, "the outer angle")?);
                if !(inner <= outer && outer <= 90.0) {
                    return Err(error("angles must satisfy inner <= outer <= 90 degrees".into()));
                }
                light.kind = LightKind::Spot { inner_cone: inner.to_radians(), outer_cone: outer.to_radians() };
                light.position = vector(position, "the position")?;
                light.direction = unit(vector(direction, "the direction")?)?;
                light.intensity = number(intensity, "the intensity")?;
                light.color = colour(rest)?;
            }
            _ => {
                return Err(error(
                    "expected point:X,Y,Z:INTENSITY, directional:DX,DY,DZ:IRRADIANCE or \
                     spot:X,Y,Z:DX,DY,DZ:INTENSITY:INNER:OUTER, each optionally followed by :R,G,B"
                        .into(),
                ));
            }
        }
        Ok(light)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specifications_parse_with_their_defaults() {
        let point: Light = "point:1,2,3:5".parse().unwrap();
        assert_eq!(
            (point.kind, point.position, point.intensity, point.color),
            (LightKind::Point, Vec3::new(1.0, 2.0, 3.0), 5.0, Vec3::ONE)
        );
        let sun: Light = "directional:0,-2,0:3:1,0.5,0".parse().unwrap();
        assert_eq!(
            (sun.kind, sun.direction, sun.color),
            (LightKind::Directional, Vec3::NEG_Y, Vec3::new(1.0, 0.5, 0.0))
        );
        let spot: Light = "spot:0,1,0:0,-1,0:5:30:45".parse().unwrap();
        assert_eq!(spot.kind, LightKind::Spot { inner_cone: 30f32.to_radians(), outer_cone: 45f32.to_radians() });
        assert_eq!(spot.name, "spot:0,1,0:0,-1,0:5:30:45");
    }

    #[test]
    fn errors_name_the_text_and_the_field() {
        for (text, expected) in [
            ("point:0,1,0:5:1,-1,1", "the colour: expected three finite numbers of at least 0"),
            ("point:nan,0,0:1", "the position: expected three finite numbers"),
            ("point:1,2:5", "expected three finite numbers"),
            ("point:0,1,0:nan", "the intensity must be a non-negative number"),
            ("point:0,1,0:-3", "the intensity must be a non-negative number"),
            ("point:0,1,0:5:1,1,1:2", "too many fields"),
            ("directional:0,0,0:1", "the direction is zero"),
            ("spot:0,1,0:0,-1,0:5:30:inf", "the outer angle must be a non-negative number"),
            ("spot:0,0,0:0,-1,0:5:40:30", "inner <= outer <= 90"),
            ("lamp:1,2,3:5", "expected point:"),
        ] {
            let message = text.parse::<Light>().unwrap_err().to_string();
            assert!(message.starts_with(&format!("light '{text}': ")) && message.contains(expected), "{message}");
        }
    }
}
