//! SIGINT and SIGTERM: a long run stops at its next sample and writes what it has.

use super::*;

/// A run stopped by SIGINT or SIGTERM; the binary exits with 128 + the signal number.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct Interrupted {
    pub signal: i32,
    pub message: String,
}

/// A second signal this soon after the first is the same request, not a second one: `timeout`,
/// shells and batch schedulers send the signal to the process and again to its process group.
const SAME_REQUEST: std::time::Duration = std::time::Duration::from_secs(1);

/// Installs SIGINT/SIGTERM handlers that record the signal in the returned flag (the run then stops
/// at its next sample and writes what it has); a signal more than [`SAME_REQUEST`] after the first
/// ends the process at once.
pub(super) fn interrupt_flag() -> Arc<AtomicUsize> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let which = Arc::new(AtomicUsize::new(0));
    let armed = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        let _ = signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, armed.clone());
        let _ = signal_hook::flag::register_usize(sig, which.clone(), sig as usize);
    }
    // arms the shutdown a moment after the first signal (a thread, not the handler: a handler may
    // only do async-signal-safe work)
    if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) {
        let armed = armed.clone();
        std::thread::spawn(move || {
            if signals.forever().next().is_some() {
                std::thread::sleep(SAME_REQUEST);
                armed.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        });
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
