//! A stop asked for from outside long offline work (`simulate`, `study`,
//! `replay`, `fit`): SIGINT or SIGTERM in the command line, Ctrl-C in
//! Python. The work polls [`Stop::requested`] between steps (an atomic
//! load) and ends with its [`Interrupted`] error; its outputs, written to
//! temporary siblings ([`crate::output::AtomicFile`]), are then removed
//! when dropped, so nothing half-written is left.
//!
//! The command line installs [`Stop::install_signal_handlers`]: the first
//! SIGINT/SIGTERM requests the stop, a second one of either ends the
//! process at once (exit 130/143; a temporary file may then stay behind).
//! The real-time node has its own handlers (it finalises its recording).

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Arc, OnceLock};

/// The work stopped because a stop was requested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("interrupted by {}: stopped, nothing half-written is left", signal_name(*signal))]
pub struct Interrupted {
    /// The signal number (SIGINT 2, SIGTERM 15), 0 when requested in-process.
    pub signal: i32,
}

impl Interrupted {
    /// The conventional exit status of a process ended by this signal
    /// (128 + the signal number; 130 when requested in-process).
    pub fn exit_code(&self) -> i32 {
        128 + if self.signal > 0 { self.signal } else { 2 }
    }
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        2 => "SIGINT",
        15 => "SIGTERM",
        0 => "a stop request",
        _ => "a signal",
    }
}

/// A shareable stop flag.
#[derive(Debug, Clone, Default)]
pub struct Stop {
    flag: Arc<AtomicBool>,
    signal: Arc<AtomicI32>,
}

impl Stop {
    /// A stop nothing has requested yet (not tied to the process's signals).
    pub fn new() -> Self {
        Self::default()
    }

    /// The process-wide stop that the command line's signal handlers set.
    pub fn process() -> &'static Stop {
        static STOP: OnceLock<Stop> = OnceLock::new();
        STOP.get_or_init(Stop::new)
    }

    /// Ask the work to stop (`signal`: which signal asked, 0 for none).
    pub fn request(&self, signal: i32) {
        self.signal.store(signal, Ordering::Relaxed);
        self.flag.store(true, Ordering::Release);
    }

    /// Whether a stop was requested.
    pub fn requested(&self) -> bool {
        self.flag.load(Ordering::Acquire)
    }

    /// `Err(Interrupted)` once a stop was requested.
    pub fn check(&self) -> Result<(), Interrupted> {
        if self.requested() {
            Err(Interrupted {
                signal: self.signal.load(Ordering::Relaxed),
            })
        } else {
            Ok(())
        }
    }

    /// SIGINT and SIGTERM request this stop; a second one ends the process
    /// at once with 128 + its number.
    pub fn install_signal_handlers(&self) -> std::io::Result<()> {
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            // A second signal: the stop was already requested, end now.
            signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, self.flag.clone())?;
            let (flag, signal) = (self.flag.clone(), self.signal.clone());
            // SAFETY: the action only stores to atomics (async-signal-safe).
            unsafe {
                signal_hook::low_level::register(sig, move || {
                    signal.store(sig, Ordering::Relaxed);
                    flag.store(true, Ordering::Release);
                })?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_requested_stop_is_an_interruption_with_the_signals_exit_code() {
        let s = Stop::new();
        assert!(s.check().is_ok());
        let t = s.clone();
        t.request(15);
        let e = s.check().unwrap_err();
        assert_eq!(e.exit_code(), 143);
        assert!(e.to_string().contains("SIGTERM"), "{e}");
        assert_eq!(Interrupted { signal: 0 }.exit_code(), 130);
    }
}
