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

use std::sync::OnceLock;

use anyhow::{Context, Result};
use rtgi_job::CancelToken;
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

/// The render's cancellation, which the signal thread sets.
static TOKEN: OnceLock<CancelToken> = OnceLock::new();

/// Installs the handlers (once) and returns the token they cancel: from
/// then on a first SIGINT or SIGTERM asks the render to stop, naming itself.
pub(crate) fn install() -> Result<CancelToken> {
    if let Some(token) = TOKEN.get() {
        return Ok(token.clone());
    }
    let token = TOKEN.get_or_init(CancelToken::new).clone();
    let mut signals = Signals::new([SIGINT, SIGTERM]).context("cannot install the signal handlers")?;
    let cancel = token.clone();
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
                        cancel.cancel(name(signal));
                        first = Some(Instant::now());
                    }
                    Some(at) if at.elapsed() < SAME_REQUEST => {}
                    Some(_) => std::process::exit(exit_status(signal) as i32),
                }
            }
        })
        .context("cannot start the signal thread")?;
    Ok(token)
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

/// A render stopped by a signal, after writing what it had: the command
/// ends with the signal's exit status (130 for SIGINT, 143 for SIGTERM).
#[derive(Debug)]
pub(crate) struct StoppedBySignal(pub(crate) i32);

impl std::fmt::Display for StoppedBySignal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "stopped by {}", name(self.0))
    }
}

impl std::error::Error for StoppedBySignal {}
