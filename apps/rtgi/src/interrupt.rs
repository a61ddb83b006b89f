//! Ctrl-C and SIGTERM during a render: the first asks the render to stop
//! and write what it has. What a repeat means depends on who sends it:
//!
//! - A second SIGINT, later than [`SAME_REQUEST`] after the first, is a
//!   person pressing Ctrl-C again: it ends the process at once, touching no
//!   output (files are only ever renamed into place whole, so none is left
//!   half written).
//! - A repeated SIGTERM never cuts the stop short. Schedulers send SIGTERM
//!   (Slurm's `--signal` and time limit, `scancel`, Kubernetes, systemd),
//!   and each signals every process of a job at once while the job's script
//!   forwards the signal too, so rtgi gets it twice. On a loaded node the
//!   forwarded copy can come well after the first; taken as a second request
//!   it ended the render without its checkpoint. A scheduler that means to
//!   end a job now sends SIGKILL after its grace period.
//! - Any signal within [`SAME_REQUEST`] of the first is that request again.

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
            let mut first: Option<(i32, Instant)> = None;
            for signal in signals.forever() {
                let Some((first_signal, at)) = first else {
                    SIGNAL.store(signal as usize, Ordering::SeqCst);
                    REQUESTED.store(true, Ordering::SeqCst);
                    cancel.cancel(name(signal));
                    first = Some((signal, Instant::now()));
                    continue;
                };
                match repeat(first_signal, signal, at.elapsed()) {
                    Repeat::SameRequest => {}
                    Repeat::StillStopping => eprintln!(
                        "rtgi: {} while stopping: the stop goes on, saving what is done (SIGKILL ends at once)",
                        name(signal)
                    ),
                    Repeat::EndNow => {
                        eprintln!("rtgi: a second {}: ending at once, writing nothing more", name(signal));
                        std::process::exit(exit_status(signal) as i32)
                    }
                }
            }
        })
        .context("cannot start the signal thread")?;
    Ok(token)
}

/// What a signal arriving `after` the first one means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Repeat {
    /// The first request delivered again (a job's processes all signalled at once).
    SameRequest,
    /// A later SIGTERM: the stop goes on; only SIGKILL cuts it short.
    StillStopping,
    /// A person's second Ctrl-C: end the process now.
    EndNow,
}

fn repeat(first: i32, again: i32, after: Duration) -> Repeat {
    if after < SAME_REQUEST && again == first {
        Repeat::SameRequest
    } else if again == SIGINT && after >= SAME_REQUEST {
        Repeat::EndNow
    } else {
        Repeat::StillStopping
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    const SOON: Duration = Duration::from_millis(5);
    const LATE: Duration = Duration::from_millis(600);
    const MUCH_LATER: Duration = Duration::from_secs(30);

    #[test]
    fn a_signal_repeated_at_once_is_the_same_request() {
        assert_eq!(repeat(SIGTERM, SIGTERM, SOON), Repeat::SameRequest);
        assert_eq!(repeat(SIGINT, SIGINT, SOON), Repeat::SameRequest);
    }

    #[test]
    fn a_later_ctrl_c_ends_the_process() {
        assert_eq!(repeat(SIGINT, SIGINT, LATE), Repeat::EndNow);
        assert_eq!(repeat(SIGTERM, SIGINT, LATE), Repeat::EndNow);
    }

    #[test]
    fn a_late_sigterm_never_cuts_the_stop_short() {
        // A job script's forwarded copy, delayed on a loaded node.
        assert_eq!(repeat(SIGTERM, SIGTERM, LATE), Repeat::StillStopping);
        assert_eq!(repeat(SIGTERM, SIGTERM, MUCH_LATER), Repeat::StillStopping);
        assert_eq!(repeat(SIGINT, SIGTERM, LATE), Repeat::StillStopping);
        // A SIGTERM right after a Ctrl-C is not a Ctrl-C repeated.
        assert_eq!(repeat(SIGINT, SIGTERM, SOON), Repeat::StillStopping);
    }
}
