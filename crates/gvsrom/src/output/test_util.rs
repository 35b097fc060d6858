//! Scratch directories of the output module's unit tests.

use std::fs;
use std::path::{Path, PathBuf};

/// A fresh empty directory `name` under the system's temporary directory, in a folder of this
/// process named by `suite` (never the current directory).
pub(super) fn sandbox(suite: &str, name: &str) -> PathBuf {
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
