//! A JSON file output ([`OutputFile`], e.g. `statics --json`): written to a staging file beside the
//! target and moved into place whole (rules 4 and 5 of [`super`]).

use super::lock::TargetLock;
use super::manifest::{manifest, with_manifest};
use super::staging::{sync_dir, Prepared};
use super::target::{inspect, Existing};
use super::{Kind, Named, OutputError};
use serde::Serialize;
use std::fs::{self, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// A JSON file output (e.g. `statics --json`): checked, locked and probed for writability at
/// creation, written and moved into place by [`OutputFile::commit_json`].
#[derive(Debug)]
pub struct OutputFile {
    named: Named,
    format: String,
    force: bool,
    target: PathBuf,
    staging: PathBuf,
    parent: PathBuf,
    committed: bool,
    _lock: TargetLock,
}

impl OutputFile {
    /// Checks the target `path` (given by `option`, e.g. `--json`), takes its lock and creates the
    /// (empty) staging file beside it. Call it before the computation.
    pub fn create(
        option: &str,
        path: &Path,
        format: &str,
        force: bool,
    ) -> Result<Self, OutputError> {
        let Prepared {
            named,
            parent,
            target,
            staging,
            lock,
            ..
        } = Prepared::new(option, path, Kind::File, format, force)?;
        Ok(OutputFile {
            named,
            format: format.into(),
            force,
            target,
            staging,
            parent,
            committed: false,
            _lock: lock,
        })
    }

    /// Writes `value` (which must serialize to a JSON object) with the manifest at its top, fsyncs it
    /// and moves it into place: a new file appears whole or not at all; a previous gvsrom output is
    /// replaced by one atomic rename.
    pub fn commit_json(mut self, value: impl Serialize) -> Result<PathBuf, OutputError> {
        let named = self.named.clone();
        let mut value =
            with_manifest(value, manifest(&self.format, None)).map_err(named.io("write it"))?;
        // the hash of its values, so that an edit is told from what gvsrom wrote (rule 2)
        if let serde_json::Value::Object(obj) = &mut value {
            super::hashes::record_meta_hash(obj);
        }
        (|| -> io::Result<()> {
            let mut w = BufWriter::new(OpenOptions::new().write(true).open(&self.staging)?);
            serde_json::to_writer(&mut w, &value)?;
            w.write_all(b"\n")?;
            w.into_inner().map_err(|e| e.into_error())?.sync_all()
        })()
        .map_err(named.io("write it"))?;
        match inspect(&named, &self.target, Kind::File, &self.format, self.force)? {
            Existing::Previous { .. } => {
                fs::rename(&self.staging, &self.target).map_err(named.io("move it into place"))?;
            }
            Existing::Nothing => {
                // A hard link never replaces a file that appeared meanwhile (unlike a rename).
                match fs::hard_link(&self.staging, &self.target) {
                    Ok(()) => {
                        let _ = fs::remove_file(&self.staging);
                    }
                    Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                        return Err(named.refused(
                            "appeared while gvsrom was computing; it is left untouched: choose another path",
                        ))
                    }
                    // File systems without hard links: the target was checked absent under the lock.
                    Err(_) => fs::rename(&self.staging, &self.target)
                        .map_err(named.io("move it into place"))?,
                }
            }
        }
        self.committed = true;
        let _ = sync_dir(&self.parent);
        Ok(self.named.path.clone())
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_file(&self.staging);
        }
    }
}
