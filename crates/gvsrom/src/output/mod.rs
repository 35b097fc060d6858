//! Everything the program writes goes through here: nothing is lost, nothing half-written looks
//! complete.
//!
//! The rules, for a target path `P` (a directory such as `simulate --out`, or a JSON file such as
//! `statics --json`):
//!
//! 1. **Refused targets.** `P` must end in a plain name. `.`, `..` and `/` are refused, and so are the
//!    home directory, the current directory or any of its ancestors, symbolic links, and anything that
//!    is not a regular file (for file outputs) or a directory (for directory outputs).
//! 2. **Never replace what gvsrom did not write.** An existing `P` is replaced only with `--force`, and
//!    only if it is a gvsrom output recognised by its manifest: the `"gvsrom"` object in
//!    `P/meta.json` (directories) or at the top of the JSON file. A directory is replaced only if
//!    it holds nothing but the files its manifest lists, an output only by one of its format (a
//!    dataset never replaces a model: a mistyped path would lose it), and only if it is as gvsrom
//!    wrote it: its files and values match the hashes its manifest records (one that records no
//!    hashes, from an earlier version or only looking like gvsrom's, is not replaced).
//! 3. **One writer at a time.** An advisory lock on `.P.gvsrom-lock` beside `P` is held from the
//!    start of the run to the end of the commit; a second writer of the same `P` is refused at once.
//!    The lock file is removed when the lock is released.
//! 4. **Staging beside the target.** Results are written into a fresh, uniquely named
//!    `.P.gvsrom-staging-<pid>-<n>` in `P`'s directory (same file system, so the final move is an atomic
//!    rename). It is created before the computation starts, which also proves the location writable.
//! 5. **Commit.** Every file is fsynced and its SHA-256 recorded in the manifest with that of
//!    meta.json's other values ([`integrity`]; loaders check them with [`verify_dir`]), then the
//!    staging is renamed to `P`. Replacing (with `--force`) exchanges the staging and the old output
//!    in one step on Linux (`renameat2` with `RENAME_EXCHANGE`: `P` always holds a complete output),
//!    then deletes the old one's manifest-listed files from where the staging was. Where the exchange
//!    is unavailable (other systems; `ENOSYS`, `EINVAL`, `EOPNOTSUPP`, `EPERM` from old kernels, some
//!    file systems and sandboxes) it takes two renames, the old output aside to
//!    `.P.gvsrom-old-<pid>-<n>` and the new one in: between them `P` holds nothing, and a kill there
//!    leaves the old output complete under the `-old-` name (`replace`). The target is re-checked
//!    under the lock at commit time. If the commit cannot complete, the staging is kept and the error
//!    names it.
//! 6. A run that ends without committing (an error before the results exist) removes its staging.
//!    A killed process (SIGKILL, power loss) can leave a hidden `.P.gvsrom-staging-*` directory (the
//!    unfinished new output, or after an exchange the old one being deleted) or `.P.gvsrom-old-*`;
//!    they are never taken for a complete result and can be deleted by hand.

mod dir;
mod file;
mod hashes;
pub mod integrity;
mod lock;
mod manifest;
pub mod read;
mod replace;
mod run_dir;
mod staging;
mod target;
#[cfg(test)]
pub(crate) mod test_util;
pub use dir::OutputDir;
pub use file::OutputFile;
pub use integrity::{
    json_file_edited, verify_dir, verify_dir_meta, Integrity, IntegrityError, ListedFiles, Problem,
    Verified,
};
pub use read::{read_regular, read_regular_to_string};
pub use run_dir::{RunDir, RUN_FORMAT};
pub use target::refuse_overlap;

use std::io;
use std::path::PathBuf;
use thiserror::Error;

/// The file of a directory output that carries its manifest.
pub const MANIFEST_FILE: &str = "meta.json";
/// The key of the manifest object (in `meta.json`, or at the top of a JSON file output).
pub const MANIFEST_KEY: &str = "gvsrom";

#[derive(Debug, Error)]
pub enum OutputError {
    /// The target may not be written (reason says why and what to do).
    #[error("{option} `{path}`: {reason}")]
    Refused {
        option: String,
        path: PathBuf,
        reason: String,
    },
    /// A file-system operation failed.
    #[error("{option} `{path}`: cannot {op}: {source}")]
    Io {
        option: String,
        path: PathBuf,
        op: String,
        source: io::Error,
    },
}

/// What the program writes at a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    File,
    Dir,
}

impl Kind {
    fn noun(self) -> &'static str {
        match self {
            Kind::File => "file",
            Kind::Dir => "directory",
        }
    }
}

/// The `option` and `path` of every error, for one target.
#[derive(Debug, Clone)]
struct Named {
    option: String,
    path: PathBuf,
}

impl Named {
    fn refused(&self, reason: impl Into<String>) -> OutputError {
        OutputError::Refused {
            option: self.option.clone(),
            path: self.path.clone(),
            reason: reason.into(),
        }
    }
    fn io(&self, op: impl Into<String>) -> impl FnOnce(io::Error) -> OutputError + '_ {
        let op = op.into();
        move |source| OutputError::Io {
            option: self.option.clone(),
            path: self.path.clone(),
            op,
            source,
        }
    }
}
