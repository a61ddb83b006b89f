//! Ctrl-C and SIGTERM during a render: the first asks the render to stop
//! and write what it has; a second ends the process at once, touching no
//! output (files are only ever renamed into place whole, so none is left half written).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use anyhow::{Context, Result};
use signal_hook::consts::{SIGINT, SIGTERM};

static REQUESTED: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicUsize = AtomicUsize::new(0);

/// The exit status of a process ended by `signal`, as shells report it.
pub(crate) fn exit_status(signal: i32) -> u8 {
    (128 + signal) as u8
}

/// Installs the handlers; from then on [`requested`] tells whether a stop was asked for.
pub(crate) fn install() -> Result<()> {
    for signal in [SIGINT, SIGTERM] {
        // The shutdown goes first: it fires only when an earlier signal already set the flag.
        signal_hook::flag::register_conditional_shutdown(signal, exit_status(signal) as i32, &REQUESTED)
            .and_then(|_| signal_hook::flag::register_usize(signal, &SIGNAL, signal as usize))
            .and_then(|_| signal_hook::flag::register(signal, &REQUESTED))
            .context("cannot install the signal handlers")?;
    }
    Ok(())
}

/// Whether a SIGINT or SIGTERM has arrived.
pub(crate) fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// The signal that asked for the stop, if any.
pub(crate) fn signal() -> Option<i32> {
    requested().then(|| SIGNAL.load(Ordering::SeqCst) as i32)
}

/// The signal's name, for messages.
pub(crate) fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT (Ctrl-C)",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}
