//! A stop asked for from outside long offline work (`simulate`, `study`,
//! `replay`, `fit`): SIGINT or SIGTERM in the command line, Ctrl-C in
//! Python. The work polls [`Stop::requested`] between steps (an atomic
//! load) and ends with its [`Interrupted`] error; its outputs, written to
//! temporary siblings ([`crate::output::AtomicFile`]), are then removed
//! when dropped, so nothing half-written is left.
//!
//! The command line installs [`Stop::install_signal_handlers`]: the first
//! SIGINT/SIGTERM requests the stop, a second one of either removes the
//! temporary files still registered ([`crate::output::remove_temporaries`],
//! microseconds) and ends the process at once (exit 130/143). A stop that
//! arrives after the work's last check still ends the command with its
//! exit code (the command line checks once more before it exits 0).
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

    /// How a command that returned `Ok` ends: 0, or the stop's exit code
    /// when a stop was requested after the work's last check (its outputs
    /// are then complete, but the caller asked it to stop).
    pub fn exit_code_on_success(&self) -> i32 {
        self.check().err().map_or(0, |i| i.exit_code())
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

    /// SIGINT and SIGTERM request this stop; a second one removes the
    /// registered temporary files and ends the process at once with 128 +
    /// its number. The signals are handled on a thread of their own (the
    /// removal is not async-signal-safe work).
    pub fn install_signal_handlers(&self) -> std::io::Result<()> {
        let mut signals = signal_hook::iterator::Signals::new([
            signal_hook::consts::SIGINT,
            signal_hook::consts::SIGTERM,
        ])?;
        let stop = self.clone();
        std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                for sig in signals.forever() {
                    stop.on_signal(sig);
                }
            })?;
        Ok(())
    }

    /// The first signal requests the stop; a second one ends the process.
    fn on_signal(&self, sig: i32) {
        if self.requested() {
            crate::output::remove_temporaries();
            std::process::exit(128 + sig);
        }
        self.request(sig);
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

    #[test]
    fn a_stop_after_the_last_check_still_ends_the_command_with_its_code() {
        let s = Stop::new();
        assert_eq!(s.exit_code_on_success(), 0);
        s.request(2);
        assert_eq!(s.exit_code_on_success(), 130);
        let t = Stop::new();
        t.on_signal(15);
        assert_eq!(t.exit_code_on_success(), 143);
    }
}
