//! Staging beside the target (rule 4 of [`super`]): a target checked and locked, with a fresh,
//! uniquely named staging directory or file in the same directory, so the final move is a rename.

use super::lock::TargetLock;
use super::target::{inspect, refuse_inside_output, refuse_special, split_target};
use super::{Kind, Named, OutputError};
use std::fs::{self, File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A unique hidden name beside the target: `.NAME.gvsrom-TAG-<pid>-<counter><nanos>`.
pub(super) fn unique_sibling(parent: &Path, name: &str, tag: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let c = COUNTER.fetch_add(1, Ordering::Relaxed);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    parent.join(format!(
        ".{name}.gvsrom-{tag}-{}-{c}{nanos:08x}",
        std::process::id()
    ))
}

/// Fsyncs the directory `dir` itself, so that entries created or renamed in it survive a crash.
pub(super) fn sync_dir(dir: &Path) -> io::Result<()> {
    // Directories can be opened and fsynced on Unix; elsewhere this is a no-op.
    #[cfg(unix)]
    File::open(dir)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

/// A checked, locked target with its fresh staging (a directory or an empty file) beside it.
pub(super) struct Prepared {
    pub(super) named: Named,
    pub(super) parent: PathBuf,
    pub(super) name: String,
    pub(super) target: PathBuf,
    pub(super) staging: PathBuf,
    pub(super) lock: TargetLock,
}

impl Prepared {
    pub(super) fn new(
        option: &str,
        path: &Path,
        kind: Kind,
        format: &str,
        force: bool,
    ) -> Result<Self, OutputError> {
        let named = Named {
            option: option.into(),
            path: path.to_path_buf(),
        };
        // `out/` names a directory: a file written there under the name `out` would surprise
        let trailing = path.as_os_str().as_encoded_bytes().last() == Some(&b'/');
        if kind == Kind::File && trailing {
            return Err(named.refused(
                "ends in `/`, which names a directory; this output is one file: name it, e.g. `results/statics.json`",
            ));
        }
        let (parent, name) = split_target(&named)?;
        refuse_special(&named, &parent, &name)?;
        refuse_inside_output(&named, &parent)?;
        let lock = TargetLock::acquire(&named, &parent, &name)?;
        let target = parent.join(&name);
        inspect(&named, &target, kind, format, force)?;
        let staging = loop {
            let s = unique_sibling(&parent, &name, "staging");
            let made = match kind {
                Kind::Dir => fs::create_dir(&s),
                Kind::File => OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(&s)
                    .map(drop),
            };
            match made {
                Ok(()) => break s,
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => {
                    return Err(named.io(format!(
                        "create its staging {} in `{}`",
                        kind.noun(),
                        parent.display()
                    ))(e))
                }
            }
        };
        Ok(Prepared {
            named,
            parent,
            name,
            target,
            staging,
            lock,
        })
    }
}
