//! Standard output of the commands, written so that a reader that goes
//! away is an error to return, not a panic.
//!
//! `println!` panics when a write to standard output fails, and it fails
//! with `BrokenPipe` as soon as the other end of a pipe is closed:
//! `rtgi info scene.obj | head -1`. The commands print through [`out!`] and
//! [`outln!`] instead, which take the same arguments as `print!` and
//! `println!` and return a `Result` for `?`. When the reader has gone, the
//! error is [`Closed`], and `main` ends quietly with success on it, as
//! command-line tools do; any other write error ("no space left on device")
//! is reported like every other error.
//!
//! ```text
//! use crate::output::{out, outln};
//!
//! outln!("triangles   {}", scene.triangles.len())?;
//! out!("{plan}")?;
//! ```
//!
//! A command that must go on after its reader has gone, because it still
//! writes files or decides its exit status (`bench --json`, `verify`), keeps
//! the first failed write and returns it last; `and_then` prints nothing
//! more once one write has failed:
//!
//! ```text
//! let mut printed = out!("{plan}");
//! // ... work ...
//! printed = printed.and_then(|()| outln!("rendered in {ms} ms"));
//! write_atomically(json, &bytes)?;
//! printed
//! ```

use std::fmt;
use std::io::{ErrorKind, Write};

/// Standard output was closed by its reader (a pipe into `head`, say):
/// nobody is left to read what the command would still print.
#[derive(Debug)]
pub(crate) struct Closed;

impl fmt::Display for Closed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("standard output was closed")
    }
}

impl std::error::Error for Closed {}

/// Like `print!`, but returns an error instead of panicking: [`Closed`]
/// when the reader has gone.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::write_fmt(::std::format_args!($($arg)*))
    };
}

/// Like `println!`, but returns an error instead of panicking: [`Closed`]
/// when the reader has gone.
macro_rules! outln {
    () => {
        $crate::output::write_fmt(::std::format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::write_fmt(::std::format_args!("{}\n", ::std::format_args!($($arg)*)))
    };
}

pub(crate) use {out, outln};

/// Writes formatted text to standard output (what [`out!`] and [`outln!`]
/// expand to).
pub(crate) fn write_fmt(args: fmt::Arguments<'_>) -> anyhow::Result<()> {
    std::io::stdout().lock().write_fmt(args).map_err(describe)
}

/// Writes out what standard output still buffers; `main` calls it last, so
/// that an error in the final write is not lost in the flush at exit.
pub(crate) fn flush() -> anyhow::Result<()> {
    std::io::stdout().lock().flush().map_err(describe)
}

fn describe(error: std::io::Error) -> anyhow::Error {
    if error.kind() == ErrorKind::BrokenPipe {
        anyhow::Error::new(Closed)
    } else {
        anyhow::Error::new(error).context("cannot write to standard output")
    }
}

/// True when `error` comes from writing to a standard output that its
/// reader has closed: the command has nothing left to say, and ends quietly.
pub(crate) fn is_closed(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| cause.is::<Closed>())
}
