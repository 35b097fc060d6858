//! A run directory: a gvsrom directory that *accumulates* outputs over several runs (`gvsrom
//! reproduce --out DIR`), where a plain output directory is replaced whole.
//!
//! - It is recognised by its manifest `DIR/meta.json` of format [`RUN_FORMAT`]; an existing
//!   directory without it is refused, so a run never writes into a directory gvsrom did not create.
//! - Its lock (`.DIR.gvsrom-lock` beside it) is held for the whole run: one writer at a time.
//! - Inside it, outputs are ordinary gvsrom outputs ([`super::OutputDir`], [`super::OutputFile`])
//!   under their own names, each replaced atomically; loose files written by
//!   [`RunDir::write_file`] (e.g. `index.html`) are staged, fsynced and renamed into place, and are
//!   listed in the manifest: a file the manifest does not list is never replaced.

use super::lock::TargetLock;
use super::manifest::{manifest, with_manifest};
use super::staging::{sync_dir, unique_sibling};
use super::target::{refuse_special, split_target};
use super::{Named, OutputError, MANIFEST_FILE, MANIFEST_KEY};
use serde_json::{json, Value};
use std::fs::{self, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The manifest format of a run directory.
pub const RUN_FORMAT: &str = "reproduce-run";

/// An open run directory (see the module documentation).
#[derive(Debug)]
pub struct RunDir {
    named: Named,
    path: PathBuf,
    files: Vec<String>,
    _lock: TargetLock,
}

impl RunDir {
    /// Opens the run directory `path` (given by `option`, e.g. `--out`): creates it with its manifest
    /// if it does not exist, reuses it if it is an earlier run directory, refuses anything else.
    pub fn open(option: &str, path: &Path) -> Result<RunDir, OutputError> {
        let named = Named {
            option: option.into(),
            path: path.to_path_buf(),
        };
        let (parent, name) = split_target(&named)?;
        refuse_special(&named, &parent, &name)?;
        let lock = TargetLock::acquire(&named, &parent, &name)?;
        let target = parent.join(&name);
        let files = match fs::symlink_metadata(&target) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                fs::create_dir(&target).map_err(named.io("create it"))?;
                vec![]
            }
            Err(e) => return Err(named.io("inspect it")(e)),
            Ok(m) if m.file_type().is_symlink() => {
                return Err(named.refused(
                    "is a symbolic link; gvsrom does not write through links: name the real path",
                ))
            }
            Ok(m) if !m.is_dir() => {
                return Err(named.refused(
                    "exists and is not a directory; gvsrom never replaces what it did not write: choose another path",
                ))
            }
            Ok(_) => match read_run_manifest(&target.join(MANIFEST_FILE)) {
                Some(files) => files,
                None => {
                    return Err(named.refused(format!(
                        "exists and is not a gvsrom run directory (no `{MANIFEST_KEY}` manifest of format `{RUN_FORMAT}` in meta.json); gvsrom writes only into run directories it created: choose a new path"
                    )))
                }
            },
        };
        let dir = RunDir {
            named,
            path: target,
            files,
            _lock: lock,
        };
        dir.write_manifest()?;
        Ok(dir)
    }

    /// The directory's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes the loose file `name` (a plain name) with `bytes`: staged beside it, fsynced and
    /// renamed into place. An existing `name` is replaced only if this run directory's manifest
    /// lists it.
    pub fn write_file(&mut self, name: &str, bytes: &[u8]) -> Result<PathBuf, OutputError> {
        let plain = !name.is_empty()
            && name != MANIFEST_FILE
            && !name.starts_with('.')
            && !name.contains(['/', '\\']);
        let target = self.path.join(name);
        let shown = Named {
            option: self.named.option.clone(),
            path: target.clone(),
        };
        if !plain {
            return Err(shown.refused("is not a plain file name inside the run directory"));
        }
        match fs::symlink_metadata(&target) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(shown.io("inspect it")(e)),
            Ok(m) if m.is_file() && self.files.iter().any(|f| f == name) => {}
            Ok(_) => {
                return Err(shown.refused(
                    "exists and was not written by this run directory; gvsrom never replaces what it did not write: move it away",
                ))
            }
        }
        if !self.files.iter().any(|f| f == name) {
            // listed before it exists: a crash in between leaves a listed name, never an unlisted file
            self.files.push(name.to_string());
            self.write_manifest()?;
        }
        write_atomically(&self.path, name, bytes).map_err(shown.io("write it"))?;
        Ok(target)
    }

    fn write_manifest(&self) -> Result<(), OutputError> {
        let value = with_manifest(
            json!({ "note": "a gvsrom reproduce run: steps/ holds each step's output, one directory per case holds its report" }),
            manifest(RUN_FORMAT, Some(&self.files)),
        )
        .map_err(self.named.io("write its meta.json"))?;
        let text = serde_json::to_string_pretty(&value).map_err(io::Error::from);
        let text = text.map_err(self.named.io("write its meta.json"))?;
        write_atomically(&self.path, MANIFEST_FILE, format!("{text}\n").as_bytes())
            .map_err(self.named.io("write its meta.json"))
    }
}

/// Writes `dir/name` by a fsynced staging file beside it and one rename.
fn write_atomically(dir: &Path, name: &str, bytes: &[u8]) -> io::Result<()> {
    let staging = unique_sibling(dir, name, "staging");
    let result = (|| {
        let mut f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&staging)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        fs::rename(&staging, dir.join(name))?;
        sync_dir(dir)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&staging);
    }
    result
}

/// The files listed by a run directory's manifest, if `path` is one.
fn read_run_manifest(path: &Path) -> Option<Vec<String>> {
    let value: Value =
        serde_json::from_str(&super::read::read_regular_to_string(path).ok()?).ok()?;
    let m = value.get(MANIFEST_KEY)?.as_object()?;
    if m.get("format")?.as_str()? != RUN_FORMAT {
        return None;
    }
    m.get("files")?
        .as_array()?
        .iter()
        .map(|f| f.as_str().map(str::to_string))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sandbox(name: &str) -> PathBuf {
        super::super::test_util::sandbox("run-dir", name)
    }

    #[test]
    fn a_run_directory_is_created_reopened_and_its_files_replaced() {
        let d = sandbox("reopen");
        let p = d.join("results");
        {
            let mut r = RunDir::open("--out", &p).unwrap();
            r.write_file("index.html", b"one").unwrap();
        }
        let mut r = RunDir::open("--out", &p).unwrap();
        r.write_file("index.html", b"two").unwrap();
        assert_eq!(fs::read(p.join("index.html")).unwrap(), b"two");
        let hidden: Vec<_> = fs::read_dir(&p)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('.'))
            .collect();
        assert!(hidden.is_empty(), "{hidden:?}");
    }

    #[test]
    fn a_directory_gvsrom_did_not_create_and_unlisted_files_are_refused() {
        let d = sandbox("refuse");
        let user = d.join("mine");
        fs::create_dir(&user).unwrap();
        fs::write(user.join("notes.txt"), "keep").unwrap();
        let e = RunDir::open("--out", &user).unwrap_err().to_string();
        assert!(e.contains("not a gvsrom run directory"), "{e}");
        let p = d.join("results");
        let mut r = RunDir::open("--out", &p).unwrap();
        fs::write(p.join("user.html"), "keep").unwrap();
        let e = r.write_file("user.html", b"x").unwrap_err().to_string();
        assert!(e.contains("was not written by this run directory"), "{e}");
        assert_eq!(fs::read_to_string(p.join("user.html")).unwrap(), "keep");
        assert!(r.write_file("../escape.html", b"x").is_err());
        assert!(r.write_file(".hidden", b"x").is_err());
    }

    #[test]
    fn one_writer_at_a_time() {
        let d = sandbox("lock");
        let p = d.join("results");
        let _r = RunDir::open("--out", &p).unwrap();
        let e = RunDir::open("--out", &p).unwrap_err().to_string();
        assert!(e.contains("another gvsrom process"), "{e}");
    }
}
