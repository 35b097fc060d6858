//! A directory output ([`OutputDir`]): files written into its staging directory, then the commit
//! (rules 5 and 6 of [`super`]): fsync, hashes in the manifest, the move into place or the exchange
//! with the output it replaces.

use super::lock::TargetLock;
use super::manifest::{manifest, with_manifest};
use super::staging::{sync_dir, unique_sibling, Prepared};
use super::target::{inspect, Existing};
use super::{hashes, replace, Kind, Named, OutputError, MANIFEST_FILE};
use serde::Serialize;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// A directory output being written: files go into its staging directory; [`OutputDir::commit`]
/// moves it into place. Dropped without a commit, it removes its staging.
#[derive(Debug)]
pub struct OutputDir {
    named: Named,
    format: String,
    force: bool,
    target: PathBuf,
    staging: PathBuf,
    files: Vec<String>,
    parent: PathBuf,
    name: String,
    committed: bool,
    _lock: TargetLock,
}

impl OutputDir {
    /// Checks the target `path` (given by command-line `option`, e.g. `--out`), takes its lock and
    /// creates the staging directory. Call it before the computation, so a bad path fails at once.
    /// `format` names what is written (`"trajectory"`, `"dataset"`, …) in the manifest.
    pub fn create(
        option: &str,
        path: &Path,
        format: &str,
        force: bool,
    ) -> Result<Self, OutputError> {
        let Prepared {
            named,
            parent,
            name,
            target,
            staging,
            lock,
        } = Prepared::new(option, path, Kind::Dir, format, force)?;
        Ok(OutputDir {
            named,
            format: format.into(),
            force,
            target,
            staging,
            files: vec![],
            parent,
            name,
            committed: false,
            _lock: lock,
        })
    }

    /// The final path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// An I/O error of this output while doing `op`.
    pub fn io_error(&self, op: &str, e: io::Error) -> OutputError {
        self.named.io(op)(e)
    }

    /// The staging directory (the files as written so far).
    pub fn staging(&self) -> &Path {
        &self.staging
    }

    fn check_name(&self, name: &str) -> io::Result<()> {
        let plain = !name.is_empty()
            && name != MANIFEST_FILE
            && !name.starts_with('.')
            && !name.contains(['/', '\\']);
        if plain {
            Ok(())
        } else {
            Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("`{name}` is not an allowed output file name"),
            ))
        }
    }

    /// Creates the new file `name` in the staging directory and records it in the manifest.
    pub fn create_file(&mut self, name: &str) -> io::Result<File> {
        self.check_name(name)?;
        let f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(self.staging.join(name))?;
        self.files.push(name.to_string());
        Ok(f)
    }

    /// Writes the file `name` through `write` (buffered) and fsyncs it.
    pub fn write_file(
        &mut self,
        name: &str,
        write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    ) -> io::Result<()> {
        let mut w = BufWriter::new(self.create_file(name)?);
        write(&mut w)?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()
    }

    /// Removes the scratch file `name` this output created (and drops it from the manifest).
    pub fn remove_file(&mut self, name: &str) -> io::Result<()> {
        if let Some(i) = self.files.iter().position(|f| f == name) {
            fs::remove_file(self.staging.join(name))?;
            self.files.remove(i);
        }
        Ok(())
    }

    /// Writes `meta` (a JSON object) with the manifest as `meta.json`, fsyncs everything and moves the
    /// staging directory to the target (replacing a previous gvsrom output if `force` was given; see
    /// the module documentation). Returns the target path.
    pub fn commit(mut self, meta: impl Serialize) -> Result<PathBuf, OutputError> {
        let named = self.named.clone();
        let keep = |e: OutputError, staging: &Path| match e {
            OutputError::Refused {
                option,
                path,
                reason,
            } => OutputError::Refused {
                option,
                path,
                reason: format!("{reason} (the results are kept in `{}`)", staging.display()),
            },
            OutputError::Io {
                option,
                path,
                op,
                source,
            } => OutputError::Io {
                option,
                path,
                op: format!("{op} (the results are kept in `{}`)", staging.display()),
                source,
            },
        };
        let mut meta = with_manifest(meta, manifest(&self.format, Some(&self.files)))
            .map_err(named.io("write meta.json"))?;
        let staging = self.staging.clone();
        (|| -> io::Result<()> {
            for f in &self.files {
                File::open(staging.join(f))?.sync_all()?;
            }
            // the hashes of the files as they are on disk, read back
            hashes::record_hashes(&staging, &self.files, &mut meta)?;
            let mut w = BufWriter::new(
                OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(staging.join(MANIFEST_FILE))?,
            );
            serde_json::to_writer_pretty(&mut w, &meta)?;
            w.write_all(b"\n")?;
            w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
            sync_dir(&staging)
        })()
        .map_err(named.io("write its files"))?;
        // From here on the staging holds the complete result: never removed on failure.
        self.committed = true;
        let existing = inspect(&named, &self.target, Kind::Dir, &self.format, self.force)
            .map_err(|e| keep(e, &staging))?;
        match existing {
            Existing::Nothing => {
                fs::rename(&staging, &self.target)
                    .map_err(|e| keep(named.io("move the results into place")(e), &staging))?;
            }
            Existing::Previous { files } => {
                let old = replace::swap_in(&staging, &self.target, || {
                    unique_sibling(&self.parent, &self.name, "old")
                })
                .map_err(|(op, e)| keep(named.io(op)(e), &staging))?;
                // The new output is in place; the old one goes only by its own manifest.
                if let Err(e) = remove_previous_dir(&old, &files) {
                    // best effort: a closed stderr must not turn a finished output into a panic
                    let _ = writeln!(
                        std::io::stderr().lock(),
                        "warning: the replaced output was kept in `{}`: {e}",
                        old.display()
                    );
                }
            }
        }
        let _ = sync_dir(&self.parent);
        Ok(self.named.path.clone())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            for f in &self.files {
                let _ = fs::remove_file(self.staging.join(f));
            }
            let _ = fs::remove_file(self.staging.join(MANIFEST_FILE));
            let _ = fs::remove_dir(&self.staging);
        }
    }
}

/// Removes a previous output set aside: its listed files and manifest, then the directory if empty.
fn remove_previous_dir(dir: &Path, files: &[String]) -> io::Result<()> {
    let plain = |f: &&str| !f.is_empty() && *f != "." && *f != ".." && !f.contains(['/', '\\']);
    for f in files
        .iter()
        .map(String::as_str)
        .chain([MANIFEST_FILE])
        .filter(plain)
    {
        match fs::remove_file(dir.join(f)) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    fs::remove_dir(dir)
}

#[cfg(test)]
mod tests {
    use super::super::{OutputFile, MANIFEST_KEY};
    use super::*;
    use serde_json::{json, Value};

    fn sandbox(name: &str) -> PathBuf {
        super::super::test_util::sandbox("output", name)
    }

    use super::super::test_util::names;

    #[test]
    fn dropping_an_uncommitted_output_leaves_nothing_behind() {
        let d = sandbox("drop");
        {
            let mut out = OutputDir::create("--out", &d.join("run"), "test", false).unwrap();
            out.write_file("a.bin", |w| w.write_all(b"123")).unwrap();
            assert_eq!(names(&d).len(), 2, "staging and lock exist while writing");
            let _f = OutputFile::create("--json", &d.join("x.json"), "test", false).unwrap();
        }
        assert!(names(&d).is_empty(), "left behind: {:?}", names(&d));
    }

    #[test]
    fn a_directory_that_appears_during_the_run_is_not_replaced_and_the_results_are_kept() {
        let d = sandbox("appears");
        let target = d.join("run");
        let mut out = OutputDir::create("--out", &target, "test", true).unwrap();
        out.write_file("a.bin", |w| w.write_all(b"new")).unwrap();
        fs::create_dir(&target).unwrap();
        fs::write(target.join("user.txt"), "mine").unwrap();
        let err = out.commit(json!({})).unwrap_err().to_string();
        assert!(err.contains("results are kept in"), "{err}");
        assert_eq!(fs::read_to_string(target.join("user.txt")).unwrap(), "mine");
        let staging: Vec<_> = names(&d)
            .into_iter()
            .filter(|n| n.contains("gvsrom-staging"))
            .collect();
        assert_eq!(staging.len(), 1, "{:?}", names(&d));
        assert_eq!(fs::read(d.join(&staging[0]).join("a.bin")).unwrap(), b"new");
    }

    #[test]
    fn a_committed_directory_lists_its_files_and_force_replaces_only_it() {
        let d = sandbox("replace");
        let target = d.join("run");
        let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
        out.write_file("a.bin", |w| w.write_all(b"old")).unwrap();
        out.commit(json!({ "k": 1 })).unwrap();
        let meta: Value =
            serde_json::from_str(&fs::read_to_string(target.join(MANIFEST_FILE)).unwrap()).unwrap();
        assert_eq!(meta[MANIFEST_KEY]["format"], "test");
        assert_eq!(meta[MANIFEST_KEY]["files"], json!(["a.bin"]));
        assert_eq!(meta["k"], 1);

        let refused = OutputDir::create("--out", &target, "test", false).unwrap_err();
        assert!(refused.to_string().contains("--force"), "{refused}");

        let mut out = OutputDir::create("--out", &target, "test", true).unwrap();
        out.write_file("b.bin", |w| w.write_all(b"new")).unwrap();
        out.commit(json!({})).unwrap();
        assert_eq!(names(&target), ["b.bin", "meta.json"]);
        assert_eq!(names(&d), ["run"], "no staging, lock or old copy left");
    }

    #[test]
    fn a_manifest_naming_paths_outside_its_directory_removes_nothing_there() {
        let d = sandbox("escape");
        let target = d.join("run");
        let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
        out.write_file("a.bin", |w| w.write_all(b"old")).unwrap();
        out.commit(json!({})).unwrap();
        fs::write(d.join("victim.txt"), "keep").unwrap();
        // an edited manifest that lists a file outside the output and one that is not there
        let meta_path = target.join(MANIFEST_FILE);
        let mut meta: Value =
            serde_json::from_str(&fs::read_to_string(&meta_path).unwrap()).unwrap();
        meta[MANIFEST_KEY]["files"] = json!(["a.bin", "../victim.txt", "missing.bin"]);
        fs::write(&meta_path, serde_json::to_string(&meta).unwrap()).unwrap();
        let mut out = OutputDir::create("--out", &target, "test", true).unwrap();
        out.write_file("b.bin", |w| w.write_all(b"new")).unwrap();
        out.commit(json!({})).unwrap();
        assert_eq!(fs::read_to_string(d.join("victim.txt")).unwrap(), "keep");
        assert_eq!(names(&target), ["b.bin", "meta.json"]);
        assert_eq!(names(&d), ["run", "victim.txt"]);
    }

    #[test]
    fn force_replaces_an_output_only_by_one_of_its_kind() {
        let d = sandbox("kind");
        let target = d.join("model");
        let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
        out.write_file("a.bin", |w| w.write_all(b"old")).unwrap();
        out.commit(json!({})).unwrap();
        let e = OutputDir::create("--out", &target, "dataset", true)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a gvsrom test output") && e.contains("only by one of its kind"),
            "{e}"
        );
        assert_eq!(fs::read(target.join("a.bin")).unwrap(), b"old");
        let file = d.join("x.json");
        OutputFile::create("--json", &file, "statics", false)
            .unwrap()
            .commit_json(json!({ "tip": 1 }))
            .unwrap();
        let e = OutputFile::create("--json", &file, "modes", true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("only by one of its kind"), "{e}");
    }

    #[test]
    fn an_output_that_records_no_hashes_is_not_replaced_even_with_force() {
        // an older version's output, or a file that only looks like one: an edit cannot be told
        let d = sandbox("unhashed");
        let target = d.join("run");
        let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
        out.write_file("a.bin", |w| w.write_all(b"old")).unwrap();
        out.commit(json!({ "k": 1 })).unwrap();
        let meta_path = target.join(MANIFEST_FILE);
        let mut meta: Value =
            serde_json::from_str(&fs::read_to_string(&meta_path).unwrap()).unwrap();
        let m = meta[MANIFEST_KEY].as_object_mut().unwrap();
        m.remove("sha256").unwrap();
        m.remove("meta_sha256").unwrap();
        fs::write(&meta_path, serde_json::to_string(&meta).unwrap()).unwrap();
        fs::write(target.join("a.bin"), b"the user's processed data").unwrap();
        let e = OutputDir::create("--out", &target, "test", true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("records no content hashes"), "{e}");
        assert_eq!(
            fs::read(target.join("a.bin")).unwrap(),
            b"the user's processed data"
        );
        let file = d.join("mine.json");
        fs::write(&file, r#"{"gvsrom": {"format": "test"}, "mydata": 1}"#).unwrap();
        let e = OutputFile::create("--json", &file, "test", true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("records no content hashes"), "{e}");
        assert!(fs::read_to_string(&file).unwrap().contains("mydata"));
    }

    #[test]
    fn file_names_inside_an_output_are_plain() {
        let d = sandbox("names");
        let mut out = OutputDir::create("--out", &d.join("run"), "test", false).unwrap();
        for bad in ["", ".hidden", "../escape", "a/b", MANIFEST_FILE] {
            assert!(out.create_file(bad).is_err(), "{bad:?} accepted");
        }
    }
}
