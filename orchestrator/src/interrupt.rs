//! Interruption by a signal: SIGINT (Ctrl-C), SIGTERM and SIGHUP all stop a
//! run or a sweep the same way (results so far kept, marked incomplete, with
//! the signal named; everything the run created removed), and the process
//! exits with 128 + the signal's number.
//!
//! One handler for the three signals, installed once by the binary
//! ([`Interrupt::install`]), with `signal-hook`'s async-signal-safe flag
//! actions: each signal stores its number, then raises the flag the engines
//! poll (an [`AtomicBool`], as [`crate::processes::run`] takes it).
//!
//! The flag is polled only once work that leaves something behind has
//! begun (a staging directory, a namespace, nodes): the command says so with
//! [`Interrupt::arm`]. Until then — reading and validating a scenario, which
//! at 10⁵ agents takes seconds, or waiting on a FIFO — a signal ends the
//! process at once with 128 + its number, as it would without a handler:
//! a thread of the handler's own watches for the signals and exits while
//! the interrupt is not armed.

use std::io;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// The signals that interrupt a run.
pub const SIGNALS: [i32; 3] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
];

/// A signal's name (`SIGTERM`), or `signal N` for one not in [`SIGNALS`].
#[must_use]
pub fn signal_name(signal: i32) -> String {
    match signal {
        signal_hook::consts::SIGINT => "SIGINT".into(),
        signal_hook::consts::SIGTERM => "SIGTERM".into(),
        signal_hook::consts::SIGHUP => "SIGHUP".into(),
        n => format!("signal {n}"),
    }
}

/// The reason written to `summary.json` (`incomplete_reason`) for a run
/// stopped by `signal`: `interrupted by SIGTERM`.
#[must_use]
pub fn reason(signal: i32) -> String {
    format!("interrupted by {}", signal_name(signal))
}

/// The exit code of a process stopped by `signal` ([`crate::exit::interrupted`]).
#[must_use]
pub fn exit_code(signal: i32) -> u8 {
    crate::exit::interrupted(signal)
}

/// Whether, and by which signal, the work was asked to stop.
#[derive(Debug, Clone, Default)]
pub struct Interrupt {
    flag: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
    /// Whether a command has begun work that the flag must stop (see
    /// [`Interrupt::arm`]); the watching thread holds it while it exits.
    armed: Arc<Mutex<bool>>,
}

impl Interrupt {
    /// Not interrupted, and no handler installed (tests, library use:
    /// [`Interrupt::trigger`] stops the work).
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A new interrupt raised by SIGINT, SIGTERM and SIGHUP. Until it is
    /// [armed](Interrupt::arm) they end the process at once (exit 128 + the
    /// signal's number); once armed they only raise the flag.
    ///
    /// # Errors
    /// The OS refused a handler, or the watching thread could not start.
    pub fn install() -> io::Result<Self> {
        let i = Self::new();
        for sig in SIGNALS {
            // The number first: whoever sees the flag finds the signal set.
            let value = usize::try_from(sig).expect("signal numbers are positive");
            signal_hook::flag::register_usize(sig, i.signal.clone(), value)?;
            signal_hook::flag::register(sig, i.flag.clone())?;
        }
        let mut signals = signal_hook::iterator::Signals::new(SIGNALS)?;
        let armed = i.armed.clone();
        std::thread::Builder::new()
            .name("attsync-signals".into())
            .spawn(move || {
                for sig in signals.forever() {
                    exit_unless_armed(&armed, sig);
                }
            })?;
        Ok(i)
    }

    /// From now on a signal only raises the flag, which the work polls to
    /// stop cleanly: called by a command before it creates anything that
    /// must be kept or removed. If a signal is already ending the process,
    /// this waits for the end.
    pub fn arm(&self) {
        *self.armed.lock().unwrap_or_else(PoisonError::into_inner) = true;
    }

    /// Stops the work as `signal` would.
    pub fn trigger(&self, signal: i32) {
        let value = usize::try_from(signal).unwrap_or(0);
        self.signal.store(value, Ordering::SeqCst);
        self.flag.store(true, Ordering::SeqCst);
    }

    /// The flag the engines poll: true once interrupted.
    #[must_use]
    pub fn flag(&self) -> &AtomicBool {
        &self.flag
    }

    /// Whether the work was asked to stop.
    #[must_use]
    pub fn is_set(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// The signal that stopped the work (the last one, if several came).
    #[must_use]
    pub fn signal(&self) -> Option<i32> {
        if !self.is_set() {
            return None;
        }
        let n = self.signal.load(Ordering::SeqCst);
        Some(i32::try_from(n).unwrap_or(signal_hook::consts::SIGINT))
    }
}

/// Ends the process for `signal` (exit 128 + its number, the reason on
/// stderr) unless the interrupt is armed; holds the lock while it exits, so
/// [`Interrupt::arm`] cannot begin work the exit would abandon.
fn exit_unless_armed(armed: &Mutex<bool>, signal: i32) {
    let armed = armed.lock().unwrap_or_else(PoisonError::into_inner);
    if !*armed {
        eprintln!("attsync: {} before anything was written", reason(signal));
        std::process::exit(exit_code(signal).into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_reasons_name_the_signal() {
        assert_eq!(exit_code(signal_hook::consts::SIGINT), 130);
        assert_eq!(exit_code(signal_hook::consts::SIGTERM), 143);
        assert_eq!(exit_code(signal_hook::consts::SIGHUP), 129);
        assert_eq!(
            reason(signal_hook::consts::SIGTERM),
            "interrupted by SIGTERM"
        );
        assert_eq!(reason(signal_hook::consts::SIGHUP), "interrupted by SIGHUP");
    }

    #[test]
    fn trigger_sets_the_flag_and_the_signal() {
        let i = Interrupt::new();
        assert!(!i.is_set() && i.signal().is_none());
        i.trigger(signal_hook::consts::SIGHUP);
        assert!(i.flag().load(Ordering::Relaxed));
        assert_eq!(i.signal(), Some(signal_hook::consts::SIGHUP));
    }
}
