//! What a session asks of the program that runs it: the command line
//! prints and renders with progress bars and signal handling; a test
//! records; a notebook might show images.

use rtgi_job::{Given, RenderRequest, Rendered, Warning};

/// A front end's own error (a reader gone, a render stopped by a signal),
/// carried through [`SessionError::Frontend`](crate::SessionError::Frontend)
/// as it is, so that the front end can tell its own errors apart again.
pub type FrontendError = Box<dyn std::error::Error + Send + Sync>;

/// A `run`, ready to render.
#[derive(Clone, Copy, Debug)]
pub struct Run<'a> {
    /// What to render: everything but the scene's edits, as a request that
    /// renders the same bytes from the scene file when `edits` is empty.
    pub request: &'a RenderRequest,
    /// The session's scene, edited, and its committed structure, to render
    /// in place of the request's (`rtgi_job::render_given`).
    pub given: Given<'a>,
    /// Why the request alone does not render this scene ("material edits",
    /// "model transforms", "several files", ...), sorted; empty when it does.
    pub edits: &'a [&'a str],
}

/// Where a [`Session`](crate::Session) says, notes and renders.
pub trait Frontend {
    /// Says a line of what a command prints (`at`, `material show`,
    /// `stats print`, `echo`, ...), as the course prints it on standard output.
    fn say(&mut self, line: &str) -> Result<(), FrontendError>;

    /// Notes, once, where rtgi does what the course's command asks
    /// differently or not at all ("algo local: rtgi shades with …").
    fn note(&mut self, message: &str);

    /// Warns of what loading a scene found (`Warning::Scene`).
    fn warn(&mut self, warning: &Warning);

    /// Renders a `run`: `rtgi_job::render_given(run.request, run.given, …)`
    /// with whatever observer and cancellation the front end has. The
    /// session records the outcome's time and rays for `stats print`.
    fn render(&mut self, run: Run<'_>) -> Result<Rendered, FrontendError>;
}
