//! Ctrl-C in the library's long calls, two ways, both running Python's signal handlers (which need
//! the GIL) every [`SIGNAL_POLL`] while the work runs without it:
//!
//! - [`run`], for calls that take an interrupt flag (`dataset`, `reproduce`): the work runs on a
//!   helper thread while the calling thread polls; a `KeyboardInterrupt` (or any exception a
//!   handler raises) sets the flag to SIGINT, and the library stops as it does for the command
//!   line's Ctrl-C;
//! - [`SignalPoll`], for calls that take a callback on their own thread (training's progress, a
//!   simulation's control): the callback asks it whether to stop.

use pyo3::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often the calling thread runs the signal handlers.
pub const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// The signal number the flag holds after Ctrl-C (what the command line's handler stores).
const SIGINT: usize = 2;

/// Runs `work(flag)` with Ctrl-C setting `flag`; returns its result and the exception the signal
/// handlers raised, if any.
pub fn run<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(Arc<AtomicUsize>) -> T + Send,
) -> (T, Option<PyErr>) {
    let flag = Arc::new(AtomicUsize::new(0));
    let mut caught: Option<PyErr> = None;
    let result = py.detach(|| {
        std::thread::scope(|s| {
            let worker_flag = flag.clone();
            let handle = s.spawn(move || work(worker_flag));
            while !handle.is_finished() {
                std::thread::sleep(SIGNAL_POLL);
                if caught.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        caught = Some(e);
                        flag.store(SIGINT, Ordering::SeqCst);
                    }
                }
            }
            match handle.join() {
                Ok(v) => v,
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    });
    (result, caught)
}

/// Ctrl-C for a library loop that calls back on the calling thread: [`SignalPoll::interrupted`]
/// runs Python's signal handlers at most every [`SIGNAL_POLL`] and keeps the exception the first
/// one raises, for the front-end to raise once the library has stopped ([`SignalPoll::caught`]).
pub struct SignalPoll {
    last: Instant,
    caught: Option<PyErr>,
}

impl SignalPoll {
    pub fn new() -> SignalPoll {
        SignalPoll {
            last: Instant::now(),
            caught: None,
        }
    }

    /// Whether the loop is to stop: a signal handler raised (now or at an earlier call).
    pub fn interrupted(&mut self) -> bool {
        if self.caught.is_some() {
            return true;
        }
        if self.last.elapsed() < SIGNAL_POLL {
            return false;
        }
        self.last = Instant::now();
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            self.caught = Some(e);
        }
        self.caught.is_some()
    }

    /// The exception a signal handler raised, if any.
    pub fn caught(self) -> Option<PyErr> {
        self.caught
    }
}
