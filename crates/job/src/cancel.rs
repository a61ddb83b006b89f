//! Stopping a render from outside: a token the front end holds (and
//! connects to what it listens to: signals, a button, a scheduler) and
//! the render polls between samples.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// Asks a render to stop; clones share the request. A render that sees it
/// abandons its pass, writes what it has (the samples of the passes done,
/// and a checkpoint when it keeps them) and reports why it stopped.
#[derive(Clone, Debug, Default)]
pub struct CancelToken {
    inner: Arc<Inner>,
}

#[derive(Debug, Default)]
struct Inner {
    cancelled: AtomicBool,
    reason: Mutex<Option<String>>,
}

impl CancelToken {
    /// A token nobody has used yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the render to stop; `reason` is what its outcome says stopped it.
    /// The first reason stays.
    pub fn cancel(&self, reason: impl Into<String>) {
        let mut stored = self.inner.reason.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if stored.is_none() {
            *stored = Some(reason.into());
        }
        self.inner.cancelled.store(true, Ordering::SeqCst);
    }

    /// Whether a stop was asked for (cheap: polled between samples).
    pub fn is_cancelled(&self) -> bool {
        self.inner.cancelled.load(Ordering::Relaxed)
    }

    /// Why, once a stop was asked for.
    pub fn reason(&self) -> Option<String> {
        if !self.is_cancelled() {
            return None;
        }
        self.inner.reason.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_request_and_the_first_reason_stays() {
        let token = CancelToken::new();
        let held = token.clone();
        assert!(!held.is_cancelled() && held.reason().is_none());
        token.cancel("SIGTERM");
        token.cancel("a second request");
        assert!(held.is_cancelled());
        assert_eq!(held.reason().as_deref(), Some("SIGTERM"));
    }
}
