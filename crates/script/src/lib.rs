//! The command language of the course framework rtgi comes from: a
//! university course's C++ ray tracer, driven by scripts and a prompt of
//! one command a line (`at`, `look`, `load`, `raytracer`, `bvh`, `algo`,
//! `material`, `pointlight`, `commit`, `run`, ...), with `#` and `//`
//! comments. What each command does there, and the framework's defaults,
//! are described in `../shared/notes/course-framework.md` (beside the
//! repository); `rtgi script` and `rtgi repl` interpret the language with
//! rtgi's renderer.
//!
//! This crate is the language and its interpreter. The language is pure
//! code that reads nothing and prints nothing, so that it can be fuzzed:
//!
//! - [`parse`] turns a line into a [`Command`], or a [`ParseError`] naming
//!   the command and what it expects (the caller knows the file and the
//!   line's number, and adds them);
//! - [`Command`] and the types beside it are what a line says, numbers read
//!   and names resolved;
//! - [`CourseBrdf`] realises the course's BRDF names as rtgi's material
//!   fields and says where they reflect differently.
//!
//! The interpreter, [`Session`], holds what the commands set up (camera,
//! scene and material edits, tracer, committed structure, algorithm) and
//! turns each `run` into an `rtgi_job` render request. It loads the files
//! the script names but prints nothing: what it says, notes and renders goes
//! through a [`Frontend`] the caller implements (the `rtgi` app prints and
//! renders with progress bars; a test records). Its errors are
//! [`SessionError`]s.
//!
//! ```
//! use rtgi_script::{Command, Tracer, CourseSplit, parse};
//!
//! let script = "raytracer bbvh sah 16\n# the course's binary BVH\ncommit\n";
//! let commands: Vec<Command> = script.lines().map(parse).collect::<Result<_, _>>()?;
//! assert_eq!(commands[0], Command::Raytracer(Tracer::Bbvh(Some((CourseSplit::Sah, Some(16))))));
//! assert_eq!(&commands[1..], &[Command::Nothing, Command::Commit]);
//! # Ok::<(), rtgi_script::ParseError>(())
//! ```

#![warn(missing_docs)]

// The README's examples are compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

mod brdf;
mod command;
mod error;
mod frontend;
mod parse;
mod session;

pub use brdf::{CourseBrdf, UnknownBrdf, course_roughness, our_roughness};
pub use command::{Algo, BvhCommand, Command, CourseSplit, DirectSampling, MaterialCommand, PathSetting, Tracer};
pub use error::SessionError;
pub use frontend::{Frontend, FrontendError, Run};
pub use parse::{COMMANDS, MAX_RESOLUTION, ParseError, parse};
pub use session::{Flow, RunRecord, Session, SessionOptions};
