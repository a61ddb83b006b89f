/// Implements `Display` and `FromStr` for an enum of named choices (an
/// option of the command line: an accelerator, an intersector, a tone map):
/// the type provides `const ALL: &[Self]` and `fn name(self) -> &'static str`,
/// and `what` names the kind of choice in the error of an unknown name.
///
/// ```
/// #[derive(Clone, Copy, Debug, PartialEq)]
/// enum Shape { Round, Square }
/// impl Shape {
///     const ALL: &'static [Shape] = &[Shape::Round, Shape::Square];
///     fn name(self) -> &'static str {
///         match self { Shape::Round => "round", Shape::Square => "square" }
///     }
/// }
/// rtgi_math::named_choices!(Shape, "shape");
///
/// assert_eq!("square".parse::<Shape>(), Ok(Shape::Square));
/// assert_eq!(Shape::Round.to_string(), "round");
/// assert_eq!("oval".parse::<Shape>().unwrap_err(), "unknown shape 'oval' (expected one of: round, square)");
/// ```
#[macro_export]
macro_rules! named_choices {
    ($type:ty, $what:literal) => {
        impl ::std::fmt::Display for $type {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::std::str::FromStr for $type {
            type Err = String;

            fn from_str(text: &str) -> Result<Self, Self::Err> {
                Self::ALL.iter().copied().find(|choice| choice.name() == text).ok_or_else(|| {
                    let names: Vec<&str> = Self::ALL.iter().map(|choice| choice.name()).collect();
                    format!("unknown {} '{text}' (expected one of: {})", $what, names.join(", "))
                })
            }
        }
    };
}

/// Parses "x,y,z" (spaces allowed around the commas) into a vector of three
/// finite numbers, as command lines and specification strings write them;
/// `None` for anything else.
///
/// ```
/// use rtgi_math::{Vec3, parse_vec3};
/// assert_eq!(parse_vec3("1, -2.5,3e2"), Some(Vec3::new(1.0, -2.5, 300.0)));
/// assert_eq!(parse_vec3("1,2,nan"), None);
/// ```
pub fn parse_vec3(text: &str) -> Option<crate::Vec3> {
    let numbers: Result<Vec<f32>, _> = text.split(',').map(|p| p.trim().parse::<f32>()).collect();
    match numbers {
        Ok(n) if n.len() == 3 && n.iter().all(|c| c.is_finite()) => Some(crate::Vec3::new(n[0], n[1], n[2])),
        _ => None,
    }
}
