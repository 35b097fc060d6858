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
//!    it holds nothing but the files its manifest lists.
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
//!    leaves the old output complete under the `-old-` name ([`replace`]). The target is re-checked
//!    under the lock at commit time. If the commit cannot complete, the staging is kept and the error
//!    names it.
//! 6. A run that ends without committing (an error before the results exist) removes its staging.
//!    A killed process (SIGKILL, power loss) can leave a hidden `.P.gvsrom-staging-*` directory (the
//!    unfinished new output, or after an exchange the old one being deleted) or `.P.gvsrom-old-*`;
//!    they are never taken for a complete result and can be deleted by hand.

pub mod integrity;
mod replace;
mod run_dir;
#[cfg(test)]
mod test_util;
pub use integrity::{verify_dir, Integrity, IntegrityError};
pub use run_dir::{RunDir, RUN_FORMAT};

use serde::Serialize;
use serde_json::{Map, Value};
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
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

/// Where a target stands before writing.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Existing {
    Nothing,
    /// A gvsrom output that `--force` lets us replace; for directories, the files its manifest lists.
    Previous {
        files: Vec<String>,
    },
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

/// The final name of `path` and the directory that holds it (created if missing).
fn split_target(n: &Named) -> Result<(PathBuf, String), OutputError> {
    let path = &n.path;
    let name = match path.components().next_back() {
        Some(Component::Normal(s)) => s.to_string_lossy().into_owned(),
        _ => {
            return Err(n.refused(
                "not a new file or directory name: `.`, `..`, `/` and empty paths would mean writing over a directory gvsrom did not create; name a new path such as `results/run1`",
            ))
        }
    };
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&parent).map_err(n.io(format!(
        "create its parent directory `{}`",
        parent.display()
    )))?;
    Ok((parent, name))
}

/// Refuses an output path (`out_option` = `out`) that equals or contains one of the command's
/// `inputs` (`(option, path)` pairs; compared by canonical path, so `./d`, `d/` and a link to `d` are
/// the same): with `--force` such an output would replace the command's own input. Call it before
/// the output is created. Inputs that do not exist are skipped (reading them fails on its own).
pub fn refuse_overlap(
    out_option: &str,
    out: &Path,
    inputs: &[(&str, &Path)],
) -> Result<(), OutputError> {
    let named = Named {
        option: out_option.into(),
        path: out.to_path_buf(),
    };
    let Some(Component::Normal(name)) = out.components().next_back() else {
        return Ok(()); // refused later by split_target, with its own reason
    };
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let Ok(target) = fs::canonicalize(parent).map(|p| p.join(name)) else {
        return Ok(()); // the parent does not exist yet: nothing in it can be an input
    };
    // the target itself may be a link to an input
    let target = fs::canonicalize(&target).unwrap_or(target);
    for (option, input) in inputs {
        let Ok(input_c) = fs::canonicalize(input) else {
            continue;
        };
        if input_c.starts_with(&target) {
            let how = if input_c == target { "is" } else { "contains" };
            return Err(named.refused(format!(
                "{how} the input {option} `{}`; an output never replaces the command's own input: choose another path",
                input.display()
            )));
        }
    }
    Ok(())
}

/// Refuses the home directory and the current directory or its ancestors (by canonical path).
fn refuse_special(n: &Named, parent: &Path, name: &str) -> Result<(), OutputError> {
    let Ok(target) = fs::canonicalize(parent).map(|p| p.join(name)) else {
        return Ok(());
    };
    if let Ok(cwd) = std::env::current_dir().and_then(fs::canonicalize) {
        if cwd.starts_with(&target) {
            return Err(n.refused(
                "is the current directory or one of its ancestors; gvsrom only writes new paths or its own earlier outputs",
            ));
        }
    }
    if let Some(home) = std::env::var_os("HOME").and_then(|h| fs::canonicalize(h).ok()) {
        if home == target {
            return Err(n.refused("is the home directory; name a new path inside it"));
        }
    }
    Ok(())
}

/// Reads the manifest of an existing output: the `"gvsrom"` object of `json_path`, and its `files`
/// (only a directory output's manifest has them).
fn read_manifest(json_path: &Path) -> Option<(String, Option<Vec<String>>)> {
    let text = fs::read_to_string(json_path).ok()?;
    let value: Value = serde_json::from_str(&text).ok()?;
    let m = value.get(MANIFEST_KEY)?.as_object()?;
    let format = m.get("format")?.as_str()?.to_string();
    let files = match m.get("files") {
        Some(Value::Array(a)) => Some(
            a.iter()
                .map(|f| f.as_str().map(str::to_string))
                .collect::<Option<Vec<_>>>()?,
        ),
        None => None,
        Some(_) => return None,
    };
    Some((format, files))
}

/// Checks what is at the target now; see the module documentation for the rules.
fn inspect(n: &Named, target: &Path, kind: Kind, force: bool) -> Result<Existing, OutputError> {
    let meta = match fs::symlink_metadata(target) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Existing::Nothing),
        Err(e) => return Err(n.io("inspect it")(e)),
    };
    let ft = meta.file_type();
    if ft.is_symlink() {
        return Err(n.refused(
            "is a symbolic link; gvsrom does not write through links: name the real path",
        ));
    }
    let is_kind = match kind {
        Kind::File => ft.is_file(),
        Kind::Dir => ft.is_dir(),
    };
    if !is_kind {
        let what = if ft.is_dir() {
            "a directory"
        } else if ft.is_file() {
            "a regular file"
        } else {
            "a special file (device, FIFO or socket)"
        };
        return Err(n.refused(format!(
            "exists and is {what}, not a {}; gvsrom never replaces what it did not write: choose another path",
            kind.noun()
        )));
    }
    let manifest_path = match kind {
        Kind::File => target.to_path_buf(),
        Kind::Dir => target.join(MANIFEST_FILE),
    };
    let Some((format, files)) = read_manifest(&manifest_path) else {
        return Err(n.refused(format!(
            "exists and is not a gvsrom output (no `{MANIFEST_KEY}` manifest{}); gvsrom never replaces what it did not write: choose another path or move it away",
            if kind == Kind::Dir { " in meta.json" } else { "" }
        )));
    };
    if kind == Kind::File && files.is_some() {
        // e.g. `--json MODEL/meta.json`: replacing it would break the directory output around it
        return Err(n.refused(format!(
            "is the meta.json of a gvsrom {format} directory, not a file output; gvsrom never replaces part of an output: choose another path"
        )));
    }
    let files = files.unwrap_or_default();
    if !force {
        return Err(n.refused(format!(
            "exists (a gvsrom {format} output); pass --force to replace it, or choose another path"
        )));
    }
    // Only the regular files actually present *and* listed are ever removed later: a manifest
    // naming `../elsewhere` or a missing file removes nothing outside the directory.
    let mut present = vec![];
    if kind == Kind::Dir {
        let mut foreign = vec![];
        for entry in fs::read_dir(target).map_err(n.io("list it"))? {
            let entry = entry.map_err(n.io("list it"))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let listed = name == MANIFEST_FILE || files.contains(&name);
            let plain = entry.file_type().map(|t| t.is_file()).unwrap_or(false);
            if !(listed && plain) {
                foreign.push(name);
            } else if name != MANIFEST_FILE {
                present.push(name);
            }
        }
        if !foreign.is_empty() {
            foreign.sort();
            let shown: Vec<_> = foreign.iter().take(3).map(|f| format!("`{f}`")).collect();
            return Err(n.refused(format!(
                "holds {} that gvsrom did not write ({}{}); it is not replaced even with --force: move them away or choose another path",
                if foreign.len() == 1 { "an entry" } else { "entries" },
                shown.join(", "),
                if foreign.len() > 3 { ", …" } else { "" }
            )));
        }
    }
    Ok(Existing::Previous { files: present })
}

/// A unique hidden name beside the target: `.NAME.gvsrom-TAG-<pid>-<counter><nanos>`.
fn unique_sibling(parent: &Path, name: &str, tag: &str) -> PathBuf {
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

/// An advisory lock on `.NAME.gvsrom-lock` beside a target, released (and the file removed) on drop.
#[derive(Debug)]
struct TargetLock {
    path: PathBuf,
    _file: File,
}

impl TargetLock {
    fn acquire(n: &Named, parent: &Path, name: &str) -> Result<Self, OutputError> {
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

fn sync_dir(dir: &Path) -> io::Result<()> {
    // Directories can be opened and fsynced on Unix; elsewhere this is a no-op.
    #[cfg(unix)]
    File::open(dir)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

/// The manifest object written with every output.
fn manifest(format: &str, files: Option<&[String]>) -> Value {
    let mut m = Map::new();
    m.insert("format".into(), Value::from(format));
    m.insert("version".into(), Value::from(env!("CARGO_PKG_VERSION")));
    if let Some(files) = files {
        m.insert("files".into(), Value::from(files.to_vec()));
    }
    Value::Object(m)
}

/// Puts `manifest` under [`MANIFEST_KEY`] at the top of `value` (which must serialize to an object).
fn with_manifest(value: impl Serialize, manifest: Value) -> io::Result<Value> {
    match serde_json::to_value(value)? {
        Value::Object(mut map) => {
            let mut out = Map::new();
            out.insert(MANIFEST_KEY.into(), manifest);
            out.append(&mut map);
            Ok(Value::Object(out))
        }
        _ => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "output metadata must be a JSON object",
        )),
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

/// A checked, locked target with its fresh staging (a directory or an empty file) beside it.
struct Prepared {
    named: Named,
    parent: PathBuf,
    name: String,
    target: PathBuf,
    staging: PathBuf,
    lock: TargetLock,
}

impl Prepared {
    fn new(option: &str, path: &Path, kind: Kind, force: bool) -> Result<Self, OutputError> {
        let named = Named {
            option: option.into(),
            path: path.to_path_buf(),
        };
        let (parent, name) = split_target(&named)?;
        refuse_special(&named, &parent, &name)?;
        let lock = TargetLock::acquire(&named, &parent, &name)?;
        let target = parent.join(&name);
        inspect(&named, &target, kind, force)?;
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
        } = Prepared::new(option, path, Kind::Dir, force)?;
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
            integrity::record_hashes(&staging, &self.files, &mut meta)?;
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
        let existing =
            inspect(&named, &self.target, Kind::Dir, self.force).map_err(|e| keep(e, &staging))?;
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
                    eprintln!(
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
        } = Prepared::new(option, path, Kind::File, force)?;
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
        let value =
            with_manifest(value, manifest(&self.format, None)).map_err(named.io("write it"))?;
        (|| -> io::Result<()> {
            let mut w = BufWriter::new(OpenOptions::new().write(true).open(&self.staging)?);
            serde_json::to_writer(&mut w, &value)?;
            w.write_all(b"\n")?;
            w.into_inner().map_err(|e| e.into_error())?.sync_all()
        })()
        .map_err(named.io("write it"))?;
        match inspect(&named, &self.target, Kind::File, self.force)? {
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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn sandbox(name: &str) -> PathBuf {
        super::test_util::sandbox("output", name)
    }

    use super::test_util::names;

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
    fn an_output_that_is_or_contains_an_input_is_refused_by_any_spelling() {
        let d = sandbox("overlap");
        let data = d.join("data");
        fs::create_dir_all(data.join("inner")).unwrap();
        let other = d.join("other");
        for (out, inputs) in [
            (data.clone(), vec![("DATASET", data.as_path())]),
            (d.join("data/"), vec![("DATASET", data.as_path())]),
            (d.join("./data"), vec![("DATASET", data.as_path())]),
            (
                data.clone(),
                vec![("--model", data.join("inner").as_path())],
            ),
        ] {
            let err = refuse_overlap("--out", &out, &inputs)
                .unwrap_err()
                .to_string();
            assert!(err.contains("input") && err.contains("--out"), "{err}");
        }
        #[cfg(unix)]
        {
            let link = d.join("link");
            std::os::unix::fs::symlink(&data, &link).unwrap();
            assert!(refuse_overlap("--out", &link, &[("DATASET", &data)]).is_err());
        }
        // distinct paths, an input inside nothing, and a missing input pass
        refuse_overlap("--out", &other, &[("DATASET", &data)]).unwrap();
        refuse_overlap("--out", &data.join("inner/new"), &[("DATASET", &data)]).unwrap();
        refuse_overlap("--out", &other, &[("DATASET", &d.join("missing"))]).unwrap();
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
    fn file_names_inside_an_output_are_plain() {
        let d = sandbox("names");
        let mut out = OutputDir::create("--out", &d.join("run"), "test", false).unwrap();
        for bad in ["", ".hidden", "../escape", "a/b", MANIFEST_FILE] {
            assert!(out.create_file(bad).is_err(), "{bad:?} accepted");
        }
    }
}
