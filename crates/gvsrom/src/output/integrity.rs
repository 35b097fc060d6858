//! Content hashes of a directory output: recorded in its manifest by [`super::OutputDir::commit`],
//! checked by [`verify_dir`] when the output is loaded, so that a file edited, truncated or swapped
//! after it was written is refused by name instead of being read as a wrong result.
//!
//! An output written before hashes were recorded has neither key: it is accepted as
//! [`Integrity::Unhashed`] (its listed files are still required to exist) and the caller may warn.
//! Files in `DIR` that the manifest does not list are neither checked nor an error: loaders read only
//! listed files.
//!
//! What is recorded, and how (`sha256` per listed file, `meta_sha256` of meta.json without its
//! manifest), is the `hashes` module's; its public items are re-exported here.

pub use super::hashes::{recorded_hashes, sha256_hex, META_SHA256_KEY, SHA256_KEY};

use super::hashes::{file_sha256, meta_sha256, recorded};
use super::read::{file_kind, read_regular};
use super::{MANIFEST_FILE, MANIFEST_KEY};
use serde_json::Value;
use std::collections::BTreeMap;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What [`verify_dir`] could check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrity {
    /// meta.json and every listed file match the hashes recorded when the output was written.
    Checked,
    /// Written before gvsrom recorded hashes (no `sha256` in its manifest): the listed files exist,
    /// their content was not checked.
    Unhashed,
}

/// A directory output that is not as it was written; `path` is the file at fault.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{}: {problem}", path.display())]
pub struct IntegrityError {
    pub path: PathBuf,
    pub problem: Problem,
}

/// What is wrong with [`IntegrityError::path`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum Problem {
    /// meta.json is missing or unreadable, or holds no well-formed manifest of the expected format.
    #[error("{0}")]
    Manifest(String),
    /// A listed file is missing, not a regular file, or unreadable.
    #[error("{0}")]
    File(String),
    /// A listed file's content differs from its recorded hash.
    #[error("differs from the hash recorded when it was written (edited, truncated or replaced)")]
    Changed,
    /// A listed file's content differs from its recorded hash when the loader read it, after it
    /// was checked.
    #[error("differs from the hash recorded when it was written: it changed while the output was being read (is another process writing it?)")]
    ChangedWhileRead,
    /// A loader asked for a file the manifest of a hashed output does not list (records no hash
    /// for): not a file the output was written with, so not read as one.
    #[error("meta.json does not list it among the output's files (records no hash for it): the manifest was edited, or the file is not this output's")]
    NotListed,
    /// meta.json's content (apart from the manifest) differs from its recorded hash.
    #[error("meta.json was edited after it was written: its values (apart from the `{MANIFEST_KEY}` manifest) no longer match the `{META_SHA256_KEY}` recorded in it")]
    MetaEdited,
}

/// A name the manifest may list: a plain file name inside the directory.
fn plain(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && name != MANIFEST_FILE
        && !name.contains(['/', '\\', '\0'])
}

/// A directory output checked by [`verify_dir_meta`]: what could be checked, and its meta.json as
/// it was checked (a loader parses this value rather than reading the file a second time, so what
/// it reads is what was verified).
#[derive(Debug, Clone, PartialEq)]
pub struct Verified {
    pub integrity: Integrity,
    pub meta: Value,
    /// The listed files, for the loader to read through [`ListedFiles::read`].
    pub files: ListedFiles,
}

/// The files of a verified output as a loader reads them: each once, its bytes checked against
/// the hash recorded for it, so that what is parsed is what was verified — a file replaced between
/// [`verify_dir_meta`] and the read is refused, not used.
#[derive(Debug, Clone, PartialEq)]
pub struct ListedFiles {
    dir: PathBuf,
    /// The recorded hashes of a hashed output (`None`: written before hashes were recorded).
    hashes: Option<BTreeMap<String, String>>,
}

impl ListedFiles {
    /// The bytes of the file `name` of the output, read once; for a hashed output they must have
    /// the hash recorded for `name` (an error naming the file otherwise).
    pub fn read(&self, name: &str) -> Result<Vec<u8>, IntegrityError> {
        let path = self.dir.join(name);
        let bytes = read_regular(&path).map_err(|e| IntegrityError {
            path: path.clone(),
            problem: Problem::File(format!("cannot read it: {e}")),
        })?;
        if let Some(hashes) = &self.hashes {
            let problem = match hashes.get(name) {
                None => Problem::NotListed,
                Some(h) if *h != sha256_hex(&bytes) => Problem::ChangedWhileRead,
                Some(_) => return Ok(bytes),
            };
            return Err(IntegrityError { path, problem });
        }
        Ok(bytes)
    }

    /// Whether the output has a file `name`: listed in its manifest (for an output written before
    /// hashes were recorded, present in its directory).
    pub fn lists(&self, name: &str) -> bool {
        match &self.hashes {
            Some(hashes) => hashes.contains_key(name),
            None => plain(name) && self.dir.join(name).is_file(),
        }
    }
}

/// Whether the JSON file output `value` (e.g. a `statics --json` result, a `reproduce` step record)
/// was edited since gvsrom wrote it: its manifest holds a `meta_sha256` that its values no longer
/// have, or one that is not a SHA-256 (an edited manifest). `false` for one whose manifest records
/// no `meta_sha256` (an output of an earlier version) or that has no manifest: a reader that
/// needs one checks for it ([`crate::output::MANIFEST_KEY`]).
pub fn json_file_edited(value: &serde_json::Value) -> bool {
    use super::hashes::META_SHA256_KEY;
    let Some(obj) = value.as_object() else {
        return false;
    };
    let Some(hash) = obj.get(MANIFEST_KEY).and_then(|m| m.get(META_SHA256_KEY)) else {
        return false;
    };
    match recorded(hash) {
        Some(hash) => meta_sha256(obj) != hash,
        None => true,
    }
}

/// Checks the directory output `dir` against its manifest before it is read: `meta.json` holds a
/// manifest of format `expected_format`; every file it lists exists as a regular file; and, if the
/// output records hashes, every listed file and meta.json itself match them. Never panics; an error
/// names the file at fault and what differs.
pub fn verify_dir(dir: &Path, expected_format: &str) -> Result<Integrity, IntegrityError> {
    verify_dir_meta(dir, expected_format).map(|v| v.integrity)
}

/// [`verify_dir`], returning meta.json's value as it was checked with the result.
pub fn verify_dir_meta(dir: &Path, expected_format: &str) -> Result<Verified, IntegrityError> {
    let meta_path = dir.join(MANIFEST_FILE);
    let bad_meta = |message: String| IntegrityError {
        path: meta_path.clone(),
        problem: Problem::Manifest(message),
    };
    let not_ours = format!("not a gvsrom {expected_format} output");
    match fs::symlink_metadata(&meta_path) {
        Ok(m) if m.is_file() => {}
        Ok(m) => {
            return Err(bad_meta(format!(
                "is {}, not a regular file ({not_ours}: gvsrom writes meta.json as a plain file)",
                file_kind(&m.file_type())
            )))
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(bad_meta(format!("missing ({not_ours})")))
        }
        Err(e) => return Err(bad_meta(format!("cannot read it: {e}"))),
    }
    let bytes = read_regular(&meta_path).map_err(|e| bad_meta(format!("cannot read it: {e}")))?;
    let value: Value =
        serde_json::from_slice(&bytes).map_err(|e| bad_meta(format!("not valid JSON: {e}")))?;
    let Value::Object(meta) = value else {
        return Err(bad_meta(format!("not a JSON object ({not_ours})")));
    };
    let Some(Value::Object(manifest)) = meta.get(MANIFEST_KEY) else {
        return Err(bad_meta(format!(
            "no `{MANIFEST_KEY}` manifest object ({not_ours})"
        )));
    };
    match manifest.get("format") {
        Some(Value::String(f)) if f == expected_format => {}
        Some(Value::String(f)) => {
            return Err(bad_meta(format!(
                "{not_ours}: its manifest says format \"{f}\", expected \"{expected_format}\""
            )))
        }
        _ => {
            return Err(bad_meta(format!(
                "its manifest has no format string ({not_ours}, format \"{expected_format}\")"
            )))
        }
    }
    let edited = |what: String| {
        bad_meta(format!(
            "its `{MANIFEST_KEY}` manifest {what}; gvsrom never writes that: the manifest was edited"
        ))
    };
    let files: Vec<&str> = match manifest.get("files") {
        None => vec![],
        Some(Value::Array(a)) => a
            .iter()
            .map(|f| f.as_str().filter(|s| plain(s)))
            .collect::<Option<_>>()
            .ok_or_else(|| {
                edited(
                    "lists an entry of `files` that is not a plain file name in the directory"
                        .into(),
                )
            })?,
        Some(_) => return Err(edited("has `files` that is not a list of names".into())),
    };
    let hashes = match (manifest.get(SHA256_KEY), manifest.get(META_SHA256_KEY)) {
        (None, None) => None,
        (Some(Value::Object(h)), Some(m)) => {
            let m = recorded(m).ok_or_else(|| {
                edited(format!(
                    "records a `{META_SHA256_KEY}` that is not 64 hexadecimal digits"
                ))
            })?;
            Some((h, m))
        }
        (Some(Value::Object(_)), None) => {
            return Err(edited(format!(
                "records `{SHA256_KEY}` without `{META_SHA256_KEY}`"
            )))
        }
        (None, Some(_)) => {
            return Err(edited(format!(
                "records `{META_SHA256_KEY}` without `{SHA256_KEY}`"
            )))
        }
        (Some(_), _) => {
            return Err(edited(format!(
                "records `{SHA256_KEY}` that is not an object of file hashes"
            )))
        }
    };
    if let Some((h, meta_hash)) = &hashes {
        if meta_sha256(&meta) != *meta_hash {
            return Err(IntegrityError {
                path: meta_path.clone(),
                problem: Problem::MetaEdited,
            });
        }
        if let Some(extra) = h.keys().find(|k| !files.contains(&k.as_str())) {
            return Err(edited(format!(
                "records a hash for `{extra}` but does not list that file"
            )));
        }
    }
    for f in &files {
        let path = dir.join(f);
        let bad_file = |message: String| IntegrityError {
            path: path.clone(),
            problem: Problem::File(message),
        };
        match fs::symlink_metadata(&path) {
            Ok(m) if m.is_file() => {}
            Ok(m) => {
                return Err(bad_file(format!(
                    "is {}, not a regular file (gvsrom wrote a regular file here)",
                    file_kind(&m.file_type())
                )))
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                return Err(bad_file(
                    "missing (meta.json lists it as a file of this output)".into(),
                ))
            }
            Err(e) => return Err(bad_file(format!("cannot read it: {e}"))),
        }
        let Some((h, _)) = &hashes else { continue };
        let expected = h
            .get(*f)
            .ok_or_else(|| edited(format!("lists `{f}` but records no hash for it")))?;
        let expected = recorded(expected).ok_or_else(|| {
            edited(format!(
                "records a hash for `{f}` that is not 64 hexadecimal digits"
            ))
        })?;
        let actual = file_sha256(&path).map_err(|e| bad_file(format!("cannot read it: {e}")))?;
        if actual != expected {
            return Err(IntegrityError {
                path,
                problem: Problem::Changed,
            });
        }
    }
    let integrity = match hashes {
        Some(_) => Integrity::Checked,
        None => Integrity::Unhashed,
    };
    let meta = Value::Object(meta);
    let files = ListedFiles {
        dir: dir.to_path_buf(),
        hashes: (integrity == Integrity::Checked).then(|| recorded_hashes(&meta)),
    };
    Ok(Verified {
        integrity,
        meta,
        files,
    })
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{committed_output, meta_of, write_meta};
    use super::*;
    use serde_json::{json, Map};

    /// A committed output of format "test" (`a.bin`, `b.bin` and meta values) in this suite's folder.
    fn written(name: &str) -> PathBuf {
        committed_output("integrity", name)
    }

    fn problem(dir: &Path) -> (String, Problem) {
        let e = verify_dir(dir, "test").unwrap_err();
        let file = e.path.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(e.to_string().lines().count(), 1, "{e}");
        assert!(e.to_string().contains(&file), "{e}");
        (file, e.problem)
    }
    #[test]
    fn one_edited_byte_is_refused_naming_the_file() {
        let dir = written("byte");
        let mut b = fs::read(dir.join("b.bin")).unwrap();
        b[150] ^= 1;
        fs::write(dir.join("b.bin"), b).unwrap();
        assert_eq!(problem(&dir), ("b.bin".into(), Problem::Changed));
        let e = verify_dir(&dir, "test").unwrap_err().to_string();
        assert!(e.contains("differs from the hash recorded"), "{e}");
    }

    #[test]
    fn the_verified_meta_is_the_file_as_checked() {
        let dir = written("verified");
        let v = verify_dir_meta(&dir, "test").unwrap();
        assert_eq!(v.integrity, Integrity::Checked);
        assert_eq!(v.meta, meta_of(&dir));
        assert_eq!(v.meta["samples"], 9);
        // an edited meta.json gives no value at all
        let mut edited = meta_of(&dir);
        edited["samples"] = 10.into();
        write_meta(&dir, &edited);
        assert_eq!(
            verify_dir_meta(&dir, "test").unwrap_err().problem,
            Problem::MetaEdited
        );
    }

    #[test]
    fn a_file_replaced_after_the_check_is_refused_when_read_not_parsed() {
        let dir = written("replaced");
        let v = verify_dir_meta(&dir, "test").unwrap();
        let before = fs::read(dir.join("b.bin")).unwrap();
        assert_eq!(v.files.read("b.bin").unwrap(), before);
        // another process rewrites the file between the check and the loader's read
        let mut after = before.clone();
        after[0] ^= 1;
        fs::write(dir.join("b.bin"), &after).unwrap();
        let e = v.files.read("b.bin").unwrap_err();
        assert_eq!(e.problem, Problem::ChangedWhileRead);
        assert!(e.to_string().contains("b.bin"), "{e}");
        // a name the manifest does not hash is not read as verified either, and the error says why
        fs::write(dir.join("extra.bin"), b"x").unwrap();
        assert!(!v.files.lists("extra.bin") && v.files.lists("a.bin"));
        assert_eq!(
            v.files.read("extra.bin").unwrap_err().problem,
            Problem::NotListed
        );
    }

    #[test]
    fn a_truncated_file_is_refused_naming_it() {
        let dir = written("trunc");
        let f = fs::OpenOptions::new()
            .write(true)
            .open(dir.join("a.bin"))
            .unwrap();
        f.set_len(299).unwrap();
        assert_eq!(problem(&dir), ("a.bin".into(), Problem::Changed));
    }

    #[test]
    fn two_files_with_swapped_contents_are_refused() {
        let dir = written("swap");
        fs::rename(dir.join("a.bin"), dir.join("tmp")).unwrap();
        fs::rename(dir.join("b.bin"), dir.join("a.bin")).unwrap();
        fs::rename(dir.join("tmp"), dir.join("b.bin")).unwrap();
        assert_eq!(problem(&dir), ("a.bin".into(), Problem::Changed));
    }

    #[test]
    fn an_edited_meta_value_is_refused_but_a_reformatted_meta_json_is_not() {
        let dir = written("meta");
        // re-indented, compact, and with the manifest moved last: the same values
        let v = meta_of(&dir);
        fs::write(dir.join(MANIFEST_FILE), serde_json::to_string(&v).unwrap()).unwrap();
        assert_eq!(verify_dir(&dir, "test"), Ok(Integrity::Checked));
        let mut moved = v.as_object().unwrap().clone();
        let m = moved.shift_remove(MANIFEST_KEY).unwrap();
        moved.insert(MANIFEST_KEY.into(), m);
        write_meta(&dir, &Value::Object(moved));
        assert_eq!(verify_dir(&dir, "test"), Ok(Integrity::Checked));
        // one number changed
        let mut edited = v.clone();
        edited["samples"] = json!(10);
        write_meta(&dir, &edited);
        assert_eq!(problem(&dir), (MANIFEST_FILE.into(), Problem::MetaEdited));
        let e = verify_dir(&dir, "test").unwrap_err().to_string();
        assert!(
            e.contains("meta.json was edited after it was written"),
            "{e}"
        );
        // a float changed in its last digit, a key added, keys reordered
        let mut last = v.clone();
        last["x"][0] = json!(0.10000000000000002);
        let mut added = v.clone();
        added["extra"] = json!(true);
        let mut reordered = Map::new();
        for k in [MANIFEST_KEY, "x", "samples", "name"] {
            reordered.insert(k.into(), v[k].clone());
        }
        for bad in [last, added, Value::Object(reordered)] {
            write_meta(&dir, &bad);
            assert_eq!(problem(&dir).1, Problem::MetaEdited, "{bad}");
        }
    }

    #[test]
    fn an_output_without_hashes_is_unhashed_but_half_a_record_is_refused() {
        let dir = written("unhashed");
        let v = meta_of(&dir);
        let mut old = v.clone();
        let m = old[MANIFEST_KEY].as_object_mut().unwrap();
        m.shift_remove(SHA256_KEY);
        m.shift_remove(META_SHA256_KEY);
        write_meta(&dir, &old);
        assert_eq!(verify_dir(&dir, "test"), Ok(Integrity::Unhashed));
        // even unhashed, its listed files must be there
        fs::rename(dir.join("a.bin"), dir.join("a.moved")).unwrap();
        let (file, p) = problem(&dir);
        assert_eq!(file, "a.bin");
        assert!(matches!(p, Problem::File(m) if m.contains("missing")));
        fs::rename(dir.join("a.moved"), dir.join("a.bin")).unwrap();
        for key in [SHA256_KEY, META_SHA256_KEY] {
            let mut half = v.clone();
            half[MANIFEST_KEY]
                .as_object_mut()
                .unwrap()
                .shift_remove(key);
            write_meta(&dir, &half);
            let (file, p) = problem(&dir);
            assert_eq!(file, MANIFEST_FILE);
            assert!(
                matches!(&p, Problem::Manifest(m) if m.contains("edited")),
                "{p}"
            );
        }
        // a file dropped from `files` but still hashed, and a listed file without a hash
        let mut dropped = v.clone();
        dropped[MANIFEST_KEY]["files"] = json!(["a.bin"]);
        let mut unhashed = v.clone();
        unhashed[MANIFEST_KEY][SHA256_KEY]
            .as_object_mut()
            .unwrap()
            .shift_remove("b.bin");
        for bad in [dropped, unhashed] {
            write_meta(&dir, &bad);
            let e = verify_dir(&dir, "test").unwrap_err().to_string();
            assert!(e.contains("b.bin") && e.contains("edited"), "{e}");
        }
    }

    #[test]
    fn an_unlisted_file_is_not_an_error() {
        let dir = written("unlisted");
        fs::write(dir.join("notes.txt"), "the user's").unwrap();
        fs::create_dir(dir.join("plots")).unwrap();
        assert_eq!(verify_dir(&dir, "test"), Ok(Integrity::Checked));
    }

    #[test]
    fn a_listed_file_that_is_missing_or_not_a_regular_file_is_refused() {
        let dir = written("kinds");
        fs::remove_file(dir.join("b.bin")).unwrap();
        fs::create_dir(dir.join("b.bin")).unwrap();
        let (file, p) = problem(&dir);
        assert_eq!(file, "b.bin");
        assert!(matches!(p, Problem::File(m) if m.contains("is a directory, not a regular file")));
        fs::remove_dir(dir.join("b.bin")).unwrap();
        let (file, p) = problem(&dir);
        assert_eq!(file, "b.bin");
        assert!(matches!(p, Problem::File(m) if m.contains("missing")));
        #[cfg(unix)]
        {
            // a link to a file with the right content is still not what gvsrom wrote
            let copy = dir.parent().unwrap().join("b.copy");
            fs::write(&copy, [2u8; 300]).unwrap();
            std::os::unix::fs::symlink(&copy, dir.join("b.bin")).unwrap();
            let (file, p) = problem(&dir);
            assert_eq!(file, "b.bin");
            assert!(matches!(p, Problem::File(_)));
        }
    }

    #[test]
    fn any_meta_json_gives_an_error_never_a_panic() {
        let dir = written("garbage");
        let v = meta_of(&dir);
        let with_manifest = |m: Value| {
            let mut x = v.clone();
            x[MANIFEST_KEY] = m;
            serde_json::to_string(&x).unwrap()
        };
        let mut cases: Vec<String> = [
            "",
            "{ garbage",
            "null",
            "[1, 2]",
            "\"text\"",
            "{}",
            "{\"gvsrom\": 1}",
            "{\"gvsrom\": {}}",
            "{\"gvsrom\": {\"format\": 5}}",
            "\u{feff}{\"gvsrom\": {\"format\": \"test\"}}",
        ]
        .into_iter()
        .map(String::from)
        .collect();
        cases.push(format!("{}{}", "[".repeat(100_000), "]".repeat(100_000)));
        for m in [
            json!({"format": "test", "files": "a.bin"}),
            json!({"format": "test", "files": [1, 2]}),
            json!({"format": "test", "files": ["../escape"]}),
            json!({"format": "test", "files": ["meta.json"]}),
            json!({"format": "test", "files": ["a.bin"], "sha256": [], "meta_sha256": "00"}),
            json!({"format": "test", "files": ["a.bin"], "sha256": {}, "meta_sha256": 7}),
            json!({"format": "test", "files": ["a.bin"], "sha256": {"a.bin": 1}, "meta_sha256": "0".repeat(64)}),
            json!({"format": "test", "files": ["a.bin"], "sha256": {"a.bin": "zz"}, "meta_sha256": "0".repeat(64)}),
        ] {
            cases.push(with_manifest(m));
        }
        for text in &cases {
            fs::write(dir.join(MANIFEST_FILE), text).unwrap();
            let e = verify_dir(&dir, "test").unwrap_err();
            assert_eq!(e.path, dir.join(MANIFEST_FILE), "{e}");
            assert!(
                matches!(e.problem, Problem::Manifest(_) | Problem::MetaEdited),
                "{e}"
            );
        }
        fs::remove_file(dir.join(MANIFEST_FILE)).unwrap();
        assert!(verify_dir(&dir, "test")
            .unwrap_err()
            .to_string()
            .contains("missing"));
        fs::create_dir(dir.join(MANIFEST_FILE)).unwrap();
        assert!(verify_dir(&dir, "test").is_err());
        assert!(verify_dir(&dir.join("nowhere"), "test").is_err());
    }
}
