//! SIGINT and SIGTERM: a long run stops at its next sample and writes what it has.

use super::*;

/// A run stopped by SIGINT or SIGTERM; the binary exits with 128 + the signal number.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct Interrupted {
    pub signal: i32,
    pub message: String,
}

/// Installs SIGINT/SIGTERM handlers that record the signal in the returned flag (the run then stops
/// at its next sample and writes what it has); a second signal ends the process at once.
pub(super) fn interrupt_flag() -> Arc<AtomicUsize> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let which = Arc::new(AtomicUsize::new(0));
    let again = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // order matters: the shutdown checks the flag set by the earlier signal
        let _ = signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, again.clone());
        let _ = signal_hook::flag::register(sig, again.clone());
        let _ = signal_hook::flag::register_usize(sig, which.clone(), sig as usize);
    }
    which
}

pub(super) fn signal_name(sig: usize) -> &'static str {
    match sig as i32 {
        signal_hook::consts::SIGINT => "SIGINT",
        signal_hook::consts::SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}
