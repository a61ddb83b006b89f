/// A closed set of named choices: an option of the command line (an
/// accelerator, an intersector, a tone map) or of a specification string
/// (an effect). The type lists its values in `ALL` and names each with
/// `name`; [`parse_choice`] reads a name back, with an error that lists
/// the names. The command line parses them with clap's `ValueEnum`,
/// derived in each crate behind its `clap` feature; a test of the app
/// checks that `ValueEnum` and this trait agree.
///
/// ```
/// use rtgi_math::{NamedChoice, parse_choice};
///
/// #[derive(Clone, Copy, Debug, PartialEq)]
/// enum Shape { Round, Square }
/// impl NamedChoice for Shape {
///     const KIND: &'static str = "shape";
///     const ALL: &'static [Shape] = &[Shape::Round, Shape::Square];
///     fn name(self) -> &'static str {
///         match self { Shape::Round => "round", Shape::Square => "square" }
///     }
/// }
///
/// assert_eq!(parse_choice::<Shape>("square"), Ok(Shape::Square));
/// assert_eq!(parse_choice::<Shape>("oval").unwrap_err(), "unknown shape 'oval' (expected one of: round, square)");
/// ```
pub trait NamedChoice: Copy + 'static {
    /// What one choice is called in messages ("integrator", "tone map").
    const KIND: &'static str;
    /// Every choice, in the order lists show them.
    const ALL: &'static [Self];
    /// The choice's name on command lines, in reports and in file names.
    fn name(self) -> &'static str;
}

/// The choice of `T` named `text`.
///
/// # Errors
/// For a name no choice has: "unknown KIND 'text' (expected one of: ...)".
pub fn parse_choice<T: NamedChoice>(text: &str) -> Result<T, String> {
    T::ALL.iter().copied().find(|choice| choice.name() == text).ok_or_else(|| {
        let names: Vec<&str> = T::ALL.iter().map(|choice| choice.name()).collect();
        format!("unknown {} '{text}' (expected one of: {})", T::KIND, names.join(", "))
    })
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
