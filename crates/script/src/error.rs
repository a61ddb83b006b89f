//! What can go wrong in a session's command.

use std::path::PathBuf;

use crate::ParseError;
use crate::frontend::FrontendError;

/// Why a line of a session failed. The session's own rules (no scene yet,
/// the structure out of date, no material selected, ...) are
/// [`SessionError::Refused`] with a message that says what to do in the
/// course's commands: there are some thirty of them, each said once, and
/// no caller acts on one rather than another, so they are prose rather
/// than variants. The errors of the libraries the session calls keep their
/// types (and their sources).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SessionError {
    /// The line is not a command of the language.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// The command does not fit the session as it is; the message says why and what to do.
    #[error("{0}")]
    Refused(String),
    /// A scene file could not be loaded.
    #[error(transparent)]
    Scene(#[from] rtgi_scene::SceneError),
    /// A texture could not be read.
    #[error("{}: cannot read the texture: {message}", path.display())]
    Texture {
        /// The texture's file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A sky could not be read.
    #[error(transparent)]
    Sky(#[from] rtgi_image::ImageError),
    /// A point light the renderer does not take.
    #[error(transparent)]
    Light(#[from] rtgi_scene::LightSpecError),
    /// The structure could not be built.
    #[error(transparent)]
    Build(#[from] rtgi_accel::BuildError),
    /// The worker threads could not be started.
    #[error(transparent)]
    Job(#[from] rtgi_job::JobError),
    /// A file a command writes (`bvh export`) could not be written.
    #[error("{}: cannot write", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The front end failed to say a line or to render; its error, as it is.
    #[error(transparent)]
    Frontend(FrontendError),
}
