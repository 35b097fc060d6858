//! Scratch directories and FIFOs of the unit tests (of the output module and of the readers).

use std::fs;
use std::path::{Path, PathBuf};

/// A fresh empty directory `name` under the system's temporary directory, in a folder of this
/// process named by `suite` (never the current directory).
pub(crate) fn sandbox(suite: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir()
        .join(format!("gvsrom-{suite}-unit-{}", std::process::id()))
        .join(name);
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// The entries of `dir`, sorted.
pub(super) fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A FIFO at `path` that no process writes: opening it plainly for reading waits forever, so a
/// reader that does not refuse it hangs the test.
#[cfg(target_os = "linux")]
pub(crate) fn fifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path
    assert_eq!(
        unsafe { libc::mkfifo(c.as_ptr(), 0o600) },
        0,
        "mkfifo {path:?}"
    );
}
