//! Scratch directories, FIFOs and committed sample outputs of the unit tests (of the output module
//! and of the readers).

use super::{OutputDir, MANIFEST_FILE};
use serde_json::{json, Value};
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The unit tests' folder under the system's temporary directory: one sub-folder per test process.
const UNIT_ROOT: &str = "gvsrom-unit-tests";

/// A fresh empty directory `name` of the unit-test suite `suite`, under the system's temporary
/// directory in a folder of this process (never the current directory). The first call of a
/// process removes the folders of earlier test processes that have ended, so that repeated test
/// runs do not pile up scratch directories.
pub(crate) fn sandbox(suite: &str, name: &str) -> PathBuf {
    static SWEPT: std::sync::Once = std::sync::Once::new();
    let root = std::env::temp_dir().join(UNIT_ROOT);
    SWEPT.call_once(|| remove_ended(&root));
    let d = root
        .join(std::process::id().to_string())
        .join(suite)
        .join(name);
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

/// Removes the folders under `root` named by the id of a process that no longer runs (Linux's
/// `/proc`; elsewhere nothing is removed).
fn remove_ended(root: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = fs::read_dir(root) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(pid) = name.to_str().and_then(|s| s.parse::<u32>().ok()) else {
            continue;
        };
        if pid != std::process::id() && !Path::new("/proc").join(pid.to_string()).exists() {
            let _ = fs::remove_dir_all(e.path());
        }
    }
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

/// A committed output of format "test" with `a.bin`, `b.bin` (same length) and meta values.
pub(super) fn committed_output(suite: &str, name: &str) -> PathBuf {
    let target = sandbox(suite, name).join("out");
    let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
    out.write_file("a.bin", |w| w.write_all(&[1u8; 300]))
        .unwrap();
    out.write_file("b.bin", |w| w.write_all(&[2u8; 300]))
        .unwrap();
    out.commit(json!({ "samples": 9, "x": [0.1, 1e-300, -0.0], "name": "é\"\\\n" }))
        .unwrap();
    target
}

/// The parsed `meta.json` of the directory output `dir`.
pub(super) fn meta_of(dir: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(dir.join(MANIFEST_FILE)).unwrap()).unwrap()
}

/// Writes `v` as the `meta.json` of `dir`, pretty-printed.
pub(super) fn write_meta(dir: &Path, v: &Value) {
    fs::write(
        dir.join(MANIFEST_FILE),
        serde_json::to_string_pretty(v).unwrap(),
    )
    .unwrap();
}
