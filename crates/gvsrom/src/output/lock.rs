//! One writer at a time (rule 3 of [`super`]): an advisory lock on `.NAME.gvsrom-lock` beside the
//! target.

use super::{Named, OutputError};
use std::fs::{self, File, OpenOptions};
use std::path::{Path, PathBuf};

/// An advisory lock on `.NAME.gvsrom-lock` beside a target, released (and the file removed) on drop.
#[derive(Debug)]
pub(super) struct TargetLock {
    path: PathBuf,
    _file: File,
}

impl TargetLock {
    pub(super) fn acquire(n: &Named, parent: &Path, name: &str) -> Result<Self, OutputError> {
        let path = parent.join(format!(".{name}.gvsrom-lock"));
        for _ in 0..16 {
            let file = OpenOptions::new()
                .create(true)
                .truncate(false)
                .read(true)
                .write(true)
                .open(&path)
                .map_err(n.io(format!("create its lock file `{}`", path.display())))?;
            match file.try_lock() {
                Ok(()) => {}
                Err(fs::TryLockError::WouldBlock) => {
                    return Err(n.refused(format!(
                        "another gvsrom process is writing it (lock `{}` is held); wait for it to finish or choose another path",
                        path.display()
                    )))
                }
                Err(fs::TryLockError::Error(e)) => {
                    return Err(n.io(format!("lock `{}`", path.display()))(e))
                }
            }
            // A releasing holder unlinks the lock file before unlocking: the lock counts only if the
            // path still names the file we locked.
            if same_file(&file, &path) {
                return Ok(TargetLock { path, _file: file });
            }
        }
        Err(n.refused(format!(
            "could not take the lock `{}` (it keeps being replaced)",
            path.display()
        )))
    }
}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
}

impl Drop for TargetLock {
    fn drop(&mut self) {
        // unlink while still holding the lock (see `acquire`); the file handle unlocks after
        let _ = fs::remove_file(&self.path);
    }
}
