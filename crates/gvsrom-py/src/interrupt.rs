//! Ctrl-C for library calls that take an interrupt flag (`dataset`, `reproduce`): the work runs on
//! a helper thread while the calling thread, without the GIL, runs Python's signal handlers every
//! [`SIGNAL_POLL`]; a `KeyboardInterrupt` (or any exception a handler raises) sets the flag to
//! SIGINT, and the library stops as it does for the command line's Ctrl-C.

use pyo3::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

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
