//! A run directory: a gvsrom directory that *accumulates* outputs over several runs (`gvsrom
//! reproduce --out DIR`), where a plain output directory is replaced whole.
//!
//! - It is recognised by its manifest `DIR/meta.json` of format [`RUN_FORMAT`]; an existing
//!   directory without it is refused, so a run never writes into a directory gvsrom did not create.
//! - Its lock (`.DIR.gvsrom-lock` beside it) is held for the whole run: one writer at a time.
//! - Inside it, outputs are ordinary gvsrom outputs ([`super::OutputDir`], [`super::OutputFile`])
//!   under their own names, each replaced atomically; loose files written by
//!   [`RunDir::write_file`] (e.g. `index.html`) are staged, fsynced and renamed into place, and are
//!   listed in the manifest with the SHA-256 of what was written (`files_sha256`): a file the
//!   manifest does not list, or whose content no longer has a recorded hash (edited since), is
//!   never replaced. While a file is replaced both its old and its new hash are recorded, so a
//!   crash between the rename and the manifest's update leaves it replaceable.

use super::lock::TargetLock;
use super::manifest::{manifest, with_manifest};
use super::staging::{sync_dir, unique_sibling};
use super::target::{refuse_special, split_target};
use super::{Named, OutputError, MANIFEST_FILE, MANIFEST_KEY};
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;
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
    /// The SHA-256 of each loose file's content as written (two while it is replaced); a file
    /// listed without any (a run directory of an earlier version) is replaced as before.
    hashes: FileHashes,
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
        let (files, hashes) = match fs::symlink_metadata(&target) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                fs::create_dir(&target).map_err(named.io("create it"))?;
                (vec![], BTreeMap::new())
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
                Some(listed) => listed,
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
            hashes,
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
        // the content there now (a listed file), checked against the hashes recorded for it
        let now = match fs::symlink_metadata(&target) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(shown.io("inspect it")(e)),
            Ok(m) if m.is_file() && self.files.iter().any(|f| f == name) => {
                let now = super::hashes::file_sha256(&target).map_err(shown.io("read it"))?;
                // none recorded: a run directory of an earlier version, whose file is replaced as
                // before; a malformed entry recorded nothing it can match
                if let Some(recorded) = self.hashes.get(name) {
                    if !recorded.contains(&now) {
                        return Err(shown.refused(
                            "was changed after gvsrom wrote it (its SHA-256 is not the one the run directory recorded); gvsrom never replaces what it did not write: move it away, or restore it",
                        ));
                    }
                }
                Some(now)
            }
            Ok(_) => {
                return Err(shown.refused(
                    "exists and was not written by this run directory; gvsrom never replaces what it did not write: move it away",
                ))
            }
        };
        // listed, with the hashes of the content there now and of the new one, before the rename:
        // a crash in between leaves a listed name whose content has a recorded hash, whichever it
        // is, never an unlisted file
        let new = super::hashes::sha256_hex(bytes);
        if !self.files.iter().any(|f| f == name) {
            self.files.push(name.to_string());
        }
        let pending: Vec<String> = (now.into_iter())
            .filter(|h| *h != new)
            .chain([new.clone()])
            .collect();
        self.hashes.insert(name.to_string(), pending);
        self.write_manifest()?;
        #[cfg(test)]
        if tests::CRASH_BEFORE_RENAME.with(std::cell::Cell::get) {
            return Err(shown.io("write it")(io::Error::other("a crash, simulated")));
        }
        write_atomically(&self.path, name, bytes).map_err(shown.io("write it"))?;
        self.hashes.insert(name.to_string(), vec![new]);
        self.write_manifest()?;
        Ok(target)
    }

    fn write_manifest(&self) -> Result<(), OutputError> {
        let mut m = manifest(RUN_FORMAT, Some(&self.files));
        if let Value::Object(map) = &mut m {
            let hashes: Map<String, Value> = (self.hashes.iter())
                .map(|(name, h)| (name.clone(), json!(h)))
                .collect();
            map.insert(FILE_HASHES_KEY.into(), Value::Object(hashes));
        }
        let value = with_manifest(
            json!({ "note": "a gvsrom reproduce run: steps/ holds each step's output, one directory per case holds its report" }),
            m,
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

/// The manifest's key of the loose files' hashes: `{name: [sha256, …]}`.
const FILE_HASHES_KEY: &str = "files_sha256";

/// The recorded SHA-256 hashes of each loose file, by name.
type FileHashes = BTreeMap<String, Vec<String>>;

/// The files listed by a run directory's manifest and their recorded hashes, if `path` is one.
/// A file without an entry recorded none (an earlier version); an entry that is not a list of
/// SHA-256 hex digests records nothing it can match (an edited manifest protects no edit).
fn read_run_manifest(path: &Path) -> Option<(Vec<String>, FileHashes)> {
    let value: Value =
        serde_json::from_str(&super::read::read_regular_to_string(path).ok()?).ok()?;
    let m = value.get(MANIFEST_KEY)?.as_object()?;
    if m.get("format")?.as_str()? != RUN_FORMAT {
        return None;
    }
    let files = m
        .get("files")?
        .as_array()?
        .iter()
        .map(|f| f.as_str().map(str::to_string))
        .collect::<Option<Vec<_>>>()?;
    let hashes = (m
        .get(FILE_HASHES_KEY)
        .and_then(Value::as_object)
        .into_iter())
    .flatten()
    .map(|(name, h)| {
        let list: Option<Vec<String>> = (h.as_array().into_iter().flatten())
            .map(super::hashes::recorded)
            .collect();
        let list = list.filter(|_| h.is_array()).unwrap_or_default();
        (name.clone(), list)
    })
    .collect();
    Some((files, hashes))
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
    fn a_listed_file_edited_since_it_was_written_is_refused_and_kept() {
        let d = sandbox("edited");
        let p = d.join("results");
        {
            let mut r = RunDir::open("--out", &p).unwrap();
            r.write_file("index.html", b"one").unwrap();
        }
        fs::write(p.join("index.html"), "one <!-- my notes -->").unwrap();
        let mut r = RunDir::open("--out", &p).unwrap();
        let e = r.write_file("index.html", b"two").unwrap_err().to_string();
        assert!(e.contains("was changed after gvsrom wrote it"), "{e}");
        assert_eq!(
            fs::read_to_string(p.join("index.html")).unwrap(),
            "one <!-- my notes -->"
        );
        // restored, it is ours again
        fs::write(p.join("index.html"), "one").unwrap();
        r.write_file("index.html", b"two").unwrap();
        assert_eq!(fs::read(p.join("index.html")).unwrap(), b"two");
        // the manifest records the content written, one hash once the write is done
        let m: Value =
            serde_json::from_str(&fs::read_to_string(p.join(MANIFEST_FILE)).unwrap()).unwrap();
        assert_eq!(
            m[MANIFEST_KEY][FILE_HASHES_KEY]["index.html"],
            json!([super::super::hashes::sha256_hex(b"two")])
        );
    }

    thread_local! {
        /// Makes [`RunDir::write_file`] stop after the manifest lists the new content and before
        /// the rename, as a crash there would.
        pub(super) static CRASH_BEFORE_RENAME: std::cell::Cell<bool> =
            const { std::cell::Cell::new(false) };
    }

    fn recorded_hashes(p: &Path) -> Value {
        let m: Value =
            serde_json::from_str(&fs::read_to_string(p.join(MANIFEST_FILE)).unwrap()).unwrap();
        m[MANIFEST_KEY][FILE_HASHES_KEY]["index.html"].clone()
    }

    #[test]
    fn a_crash_between_the_manifest_and_the_rename_leaves_the_file_replaceable() {
        // with a recorded hash (this version), and without (a run directory of an earlier one)
        for earlier_version in [false, true] {
            let d = sandbox(&format!("crash-{earlier_version}"));
            let p = d.join("results");
            {
                let mut r = RunDir::open("--out", &p).unwrap();
                r.write_file("index.html", b"one").unwrap();
            }
            if earlier_version {
                let path = p.join(MANIFEST_FILE);
                let mut m: Value =
                    serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
                m[MANIFEST_KEY]
                    .as_object_mut()
                    .unwrap()
                    .remove(FILE_HASHES_KEY);
                fs::write(&path, serde_json::to_string(&m).unwrap()).unwrap();
            }
            {
                let mut r = RunDir::open("--out", &p).unwrap();
                CRASH_BEFORE_RENAME.with(|c| c.set(true));
                let e = r.write_file("index.html", b"two");
                CRASH_BEFORE_RENAME.with(|c| c.set(false));
                assert!(e.is_err());
            }
            // the old content is on disk, the manifest lists both
            assert_eq!(fs::read(p.join("index.html")).unwrap(), b"one");
            let one = super::super::hashes::sha256_hex(b"one");
            let two = super::super::hashes::sha256_hex(b"two");
            assert_eq!(recorded_hashes(&p), json!([one, two]), "{earlier_version}");
            // the next run replaces it
            let mut r = RunDir::open("--out", &p).unwrap();
            r.write_file("index.html", b"three").unwrap();
            assert_eq!(fs::read(p.join("index.html")).unwrap(), b"three");
            assert_eq!(
                recorded_hashes(&p),
                json!([super::super::hashes::sha256_hex(b"three")])
            );
        }
    }

    #[test]
    fn a_malformed_hash_entry_protects_the_file_rather_than_dropping_its_check() {
        let d = sandbox("malformed");
        let p = d.join("results");
        {
            let mut r = RunDir::open("--out", &p).unwrap();
            r.write_file("index.html", b"one").unwrap();
        }
        let path = p.join(MANIFEST_FILE);
        let mut m: Value = serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
        m[MANIFEST_KEY][FILE_HASHES_KEY]["index.html"] = json!("not a list");
        fs::write(&path, serde_json::to_string(&m).unwrap()).unwrap();
        fs::write(p.join("index.html"), "edited").unwrap();
        let mut r = RunDir::open("--out", &p).unwrap();
        let e = r.write_file("index.html", b"two").unwrap_err().to_string();
        assert!(e.contains("was changed after gvsrom wrote it"), "{e}");
        assert_eq!(fs::read(p.join("index.html")).unwrap(), b"edited");
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
