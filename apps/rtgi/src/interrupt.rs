//! Ctrl-C and SIGTERM during a render: the first asks the render to stop
//! and write what it has; a second ends the process at once, touching no
//! output (files are only ever renamed into place whole, so none is left half written).
//!
//! Signals that arrive within [`SAME_REQUEST`] of the first are that first
//! request delivered again, not a second one: a scheduler signals every
//! process of a job at once (Slurm's time limit, `scancel`), and the job's
//! script forwards the signal to rtgi as well, so rtgi gets two within
//! milliseconds. Taken as two, they would end the render without its
//! checkpoint. A person's second Ctrl-C comes later than that.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// How soon after the first a signal counts as the same request.
pub(crate) const SAME_REQUEST: Duration = Duration::from_millis(250);

static REQUESTED: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicUsize = AtomicUsize::new(0);

/// The exit status of a process ended by `signal`, as shells report it.
pub(crate) fn exit_status(signal: i32) -> u8 {
    (128 + signal) as u8
}

/// Installs the handlers; from then on [`requested`] tells whether a stop was asked for.
pub(crate) fn install() -> Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM]).context("cannot install the signal handlers")?;
    // The handlers only note the signal; this thread decides what it means.
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let mut first: Option<Instant> = None;
            for signal in signals.forever() {
                match first {
                    None => {
                        SIGNAL.store(signal as usize, Ordering::SeqCst);
                        REQUESTED.store(true, Ordering::SeqCst);
                        first = Some(Instant::now());
                    }
                    Some(at) if at.elapsed() < SAME_REQUEST => {}
                    Some(_) => std::process::exit(exit_status(signal) as i32),
                }
            }
        })
        .context("cannot start the signal thread")?;
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
