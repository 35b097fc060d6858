//! Replacing a previous directory output by a finished staging directory (rule 5 of the module
//! documentation of [`super`]).
//!
//! On Linux the two directories are exchanged in one step, `renameat2(staging, target,
//! RENAME_EXCHANGE)`: at every moment the target path holds a complete output, the old one or the
//! new one. The old output ends up at the staging path, from where it is removed.
//!
//! Where the exchange is not available (kernels before 3.15, file systems that refuse it: `ENOSYS`,
//! `EINVAL`, `EOPNOTSUPP`, or `EPERM` from a sandbox that filters the call; every system but Linux)
//! the replacement takes two renames: the old output aside to `.NAME.gvsrom-old-…`, then the staging
//! to the target. Between the two the target path holds nothing; a process killed there leaves the
//! complete old output under the `-old-` name.

use std::io;
use std::path::{Path, PathBuf};

/// Exchanges the directories (or files) `a` and `b` atomically: `renameat2(a, b, RENAME_EXCHANGE)`.
/// Both must exist on the same file system.
#[cfg(target_os = "linux")]
pub(super) fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_bytes())
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "path contains a NUL byte"))
    };
    let (a, b) = (c(a)?, c(b)?);
    // The raw system call rather than glibc's wrapper (glibc ≥ 2.28 only): an old kernel answers
    // ENOSYS, which selects the fallback.
    // SAFETY: both pointers are NUL-terminated strings that outlive the call.
    let r = unsafe {
        libc::syscall(
            libc::SYS_renameat2,
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Exchanges `a` and `b` atomically: not available on this system.
#[cfg(not(target_os = "linux"))]
pub(super) fn exchange(_a: &Path, _b: &Path) -> io::Result<()> {
    Err(io::Error::from(io::ErrorKind::Unsupported))
}

/// Whether an [`exchange`] failure means "not available here" (then two renames do the job).
fn unsupported(e: &io::Error) -> bool {
    #[cfg(target_os = "linux")]
    if let Some(code) = e.raw_os_error() {
        return matches!(
            code,
            libc::ENOSYS | libc::EINVAL | libc::EOPNOTSUPP | libc::EPERM
        );
    }
    e.kind() == io::ErrorKind::Unsupported
}

#[cfg(test)]
thread_local! {
    /// Testing aid: stop [`swap_in`] right after its first step, as a killed process would.
    pub(super) static KILLED_AFTER_FIRST_STEP: std::cell::Cell<bool> =
        const { std::cell::Cell::new(false) };
}

/// Why [`swap_in`] failed: the step (`"set the previous output aside"` or `"move the results into
/// place"`) and its error. The staging directory is then unchanged and the target holds the old
/// output.
pub(super) type SwapError = (&'static str, io::Error);

/// Puts the directory `staging` at `target`, which holds a previous output, and returns where the
/// previous output now is: the staging path after an [`exchange`], or `aside()` (a fresh hidden
/// name beside the target) after the two-rename fallback.
pub(super) fn swap_in(
    staging: &Path,
    target: &Path,
    aside: impl FnOnce() -> PathBuf,
) -> Result<PathBuf, SwapError> {
    const INTO_PLACE: &str = "move the results into place";
    match exchange(staging, target) {
        Ok(()) => return Ok(staging.to_path_buf()),
        Err(e) if !unsupported(&e) => return Err((INTO_PLACE, e)),
        Err(_) => {}
    }
    let aside = aside();
    std::fs::rename(target, &aside).map_err(|e| ("set the previous output aside", e))?;
    #[cfg(test)]
    if KILLED_AFTER_FIRST_STEP.with(|k| k.get()) {
        return Ok(aside);
    }
    if let Err(e) = std::fs::rename(staging, target) {
        let _ = std::fs::rename(&aside, target);
        return Err((INTO_PLACE, e));
    }
    Ok(aside)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn sandbox(name: &str) -> PathBuf {
        super::super::test_util::sandbox("replace", name)
    }

    use super::super::test_util::names;

    #[test]
    fn a_forced_replace_leaves_the_new_output_and_nothing_of_the_old_one() {
        use super::super::{verify_dir, Integrity, OutputDir};
        use std::io::Write;
        let d = sandbox("force");
        let target = d.join("run");
        let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
        out.write_file("old.bin", |w| w.write_all(b"old")).unwrap();
        out.commit(serde_json::json!({ "v": 1 })).unwrap();
        let mut out = OutputDir::create("--out", &target, "test", true).unwrap();
        out.write_file("new.bin", |w| w.write_all(b"new")).unwrap();
        out.commit(serde_json::json!({ "v": 2 })).unwrap();
        assert_eq!(names(&target), ["meta.json", "new.bin"]);
        assert_eq!(fs::read(target.join("new.bin")).unwrap(), b"new");
        let meta: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(target.join("meta.json")).unwrap()).unwrap();
        assert_eq!(meta["v"], 2);
        assert_eq!(verify_dir(&target, "test"), Ok(Integrity::Checked));
        assert_eq!(names(&d), ["run"], "no staging, lock or old copy left");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn exchange_swaps_two_directories_in_one_step() {
        let d = sandbox("exchange");
        let (a, b) = (d.join("a"), d.join("b"));
        fs::create_dir(&a).unwrap();
        fs::create_dir(&b).unwrap();
        fs::write(a.join("x"), "in a").unwrap();
        fs::write(b.join("y"), "in b").unwrap();
        exchange(&a, &b).expect("renameat2(RENAME_EXCHANGE) on the temporary directory");
        assert_eq!(fs::read_to_string(b.join("x")).unwrap(), "in a");
        assert_eq!(fs::read_to_string(a.join("y")).unwrap(), "in b");
        assert!(!a.join("x").exists() && !b.join("y").exists());
        // a missing side is an error that is not taken for "unsupported"
        let e = exchange(&a, &d.join("missing")).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::NotFound, "{e}");
        assert!(!unsupported(&e));
    }

    #[test]
    fn the_fallback_is_chosen_only_when_the_exchange_is_not_available() {
        assert!(unsupported(&io::Error::from(io::ErrorKind::Unsupported)));
        assert!(!unsupported(&io::Error::from(io::ErrorKind::NotFound)));
        #[cfg(target_os = "linux")]
        {
            for code in [libc::ENOSYS, libc::EINVAL, libc::EOPNOTSUPP, libc::EPERM] {
                assert!(unsupported(&io::Error::from_raw_os_error(code)), "{code}");
            }
            for code in [libc::ENOENT, libc::EXDEV, libc::EACCES, libc::ENOSPC] {
                assert!(!unsupported(&io::Error::from_raw_os_error(code)), "{code}");
            }
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_swap_killed_after_its_first_step_leaves_the_new_output_in_place() {
        // the two-rename fallback would leave the target empty here
        let d = sandbox("killed");
        let (staging, target) = (d.join(".new"), d.join("run"));
        fs::create_dir(&staging).unwrap();
        fs::create_dir(&target).unwrap();
        fs::write(staging.join("f"), "new").unwrap();
        fs::write(target.join("f"), "old").unwrap();
        KILLED_AFTER_FIRST_STEP.with(|k| k.set(true));
        let old = swap_in(&staging, &target, || d.join(".aside"));
        KILLED_AFTER_FIRST_STEP.with(|k| k.set(false));
        assert_eq!(old.unwrap(), staging);
        assert_eq!(fs::read_to_string(target.join("f")).unwrap(), "new");
        assert_eq!(fs::read_to_string(staging.join("f")).unwrap(), "old");
        assert!(!d.join(".aside").exists());
    }
}
