//! Content hashes of a directory output: recorded in its manifest by [`super::OutputDir::commit`],
//! checked by [`verify_dir`] when the output is loaded, so that a file edited, truncated or swapped
//! after it was written is refused by name instead of being read as a wrong result.
//!
//! The manifest (the `"gvsrom"` object at the top of `DIR/meta.json`) records
//! - `"sha256": {"<file>": "<hex>", …}`: the SHA-256 of each file it lists, as written;
//! - `"meta_sha256": "<hex>"`: the SHA-256 of the compact JSON serialization of the meta.json object
//!   *without* its `"gvsrom"` key, keys in the order written. serde_json keeps that order
//!   (`preserve_order`) and parses every number back to the same value (`float_roundtrip`; NaN and
//!   infinities are written as `null`), so the meta.json read back serializes to the same bytes
//!   however it is indented.
//!
//! An output written before hashes were recorded has neither key: it is accepted as
//! [`Integrity::Unhashed`] (its listed files are still required to exist) and the caller may warn.
//! Files in `DIR` that the manifest does not list are neither checked nor an error: loaders read only
//! listed files.

use super::read::{file_kind, open_regular, read_regular};
use super::{MANIFEST_FILE, MANIFEST_KEY};
use serde::ser::{Serialize, SerializeMap, Serializer};
use serde_json::{Map, Value};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::fs;
use std::io::{self, Read};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The manifest key of the files' hashes.
pub const SHA256_KEY: &str = "sha256";
/// The manifest key of the hash of meta.json without its manifest.
pub const META_SHA256_KEY: &str = "meta_sha256";

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
    /// meta.json's content (apart from the manifest) differs from its recorded hash.
    #[error("meta.json was edited after it was written: its values (apart from the `{MANIFEST_KEY}` manifest) no longer match the `{META_SHA256_KEY}` recorded in it")]
    MetaEdited,
}

/// A digest as lowercase hex digits.
fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// The SHA-256 of `bytes` as 64 lowercase hex digits, as the manifest records a file's.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// The SHA-256 of the file at `path`, read in blocks (any size).
pub(super) fn file_sha256(path: &Path) -> io::Result<String> {
    let mut file = open_regular(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => hasher.update(&buf[..n]),
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(hex(&hasher.finalize()))
}

/// A JSON object serialized without its manifest key (as `serde_json` serializes the object itself).
struct WithoutManifest<'a>(&'a Map<String, Value>);

impl Serialize for WithoutManifest<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        for (k, v) in self.0.iter().filter(|(k, _)| *k != MANIFEST_KEY) {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

/// Feeds what is written into a SHA-256.
struct HashWriter(Sha256);

impl io::Write for HashWriter {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.update(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// `meta_sha256`: the SHA-256 of the compact serialization of `meta` without [`MANIFEST_KEY`].
pub(super) fn meta_sha256(meta: &Map<String, Value>) -> String {
    let mut w = HashWriter(Sha256::new());
    // serializing a `Value` into a sink that never fails cannot fail (string keys only)
    let _ = serde_json::to_writer(&mut w, &WithoutManifest(meta));
    hex(&w.0.finalize())
}

/// Records the hashes of `files` (read back from `dir`) and of `meta` itself in `meta`'s manifest
/// (which must already be there; see the module documentation).
pub(super) fn record_hashes(dir: &Path, files: &[String], meta: &mut Value) -> io::Result<()> {
    let mut hashes = Map::new();
    for f in files {
        hashes.insert(f.clone(), Value::from(file_sha256(&dir.join(f))?));
    }
    let Value::Object(obj) = meta else {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "output metadata must be a JSON object",
        ));
    };
    let meta_hash = meta_sha256(obj);
    match obj.get_mut(MANIFEST_KEY) {
        Some(Value::Object(m)) => {
            m.insert(SHA256_KEY.into(), Value::Object(hashes));
            m.insert(META_SHA256_KEY.into(), Value::from(meta_hash));
            Ok(())
        }
        _ => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "output metadata has no manifest to record the hashes in",
        )),
    }
}

/// A name the manifest may list: a plain file name inside the directory.
fn plain(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && name != MANIFEST_FILE
        && !name.contains(['/', '\\', '\0'])
}

/// A recorded hash, if `v` is 64 hex digits (compared case-insensitively).
fn recorded(v: &Value) -> Option<String> {
    let s = v.as_str()?;
    (s.len() == 64 && s.bytes().all(|b| b.is_ascii_hexdigit())).then(|| s.to_ascii_lowercase())
}

/// The file hashes recorded in the manifest of `meta` (a parsed meta.json), by file name: the
/// well-formed ones (64 hexadecimal digits), lower case. Empty for an output without hashes.
pub fn recorded_hashes(meta: &Value) -> BTreeMap<String, String> {
    let hashes = meta.get(MANIFEST_KEY).and_then(|m| m.get(SHA256_KEY));
    match hashes {
        Some(Value::Object(h)) => h
            .iter()
            .filter_map(|(f, v)| Some((f.clone(), recorded(v)?)))
            .collect(),
        _ => BTreeMap::new(),
    }
}

/// Checks the directory output `dir` against its manifest before it is read: `meta.json` holds a
/// manifest of format `expected_format`; every file it lists exists as a regular file; and, if the
/// output records hashes, every listed file and meta.json itself match them. Never panics; an error
/// names the file at fault and what differs.
pub fn verify_dir(dir: &Path, expected_format: &str) -> Result<Integrity, IntegrityError> {
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
    Ok(match hashes {
        Some(_) => Integrity::Checked,
        None => Integrity::Unhashed,
    })
}

#[cfg(test)]
mod tests {
    use super::super::OutputDir;
    use super::*;
    use serde_json::json;
    use std::io::Write;

    fn sandbox(name: &str) -> PathBuf {
        super::super::test_util::sandbox("integrity", name)
    }

    /// A committed output of format "test" with `a.bin`, `b.bin` (same length) and meta values.
    fn written(name: &str) -> PathBuf {
        let target = sandbox(name).join("out");
        let mut out = OutputDir::create("--out", &target, "test", false).unwrap();
        out.write_file("a.bin", |w| w.write_all(&[1u8; 300]))
            .unwrap();
        out.write_file("b.bin", |w| w.write_all(&[2u8; 300]))
            .unwrap();
        out.commit(json!({ "samples": 9, "x": [0.1, 1e-300, -0.0], "name": "é\"\\\n" }))
            .unwrap();
        target
    }

    fn meta_of(dir: &Path) -> Value {
        serde_json::from_str(&fs::read_to_string(dir.join(MANIFEST_FILE)).unwrap()).unwrap()
    }

    fn write_meta(dir: &Path, v: &Value) {
        fs::write(
            dir.join(MANIFEST_FILE),
            serde_json::to_string_pretty(v).unwrap(),
        )
        .unwrap();
    }

    fn problem(dir: &Path) -> (String, Problem) {
        let e = verify_dir(dir, "test").unwrap_err();
        let file = e.path.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(e.to_string().lines().count(), 1, "{e}");
        assert!(e.to_string().contains(&file), "{e}");
        (file, e.problem)
    }

    #[test]
    fn a_fresh_output_records_its_hashes_and_verifies() {
        let dir = written("fresh");
        assert_eq!(verify_dir(&dir, "test"), Ok(Integrity::Checked));
        let m = &meta_of(&dir)[MANIFEST_KEY];
        // independent value: SHA-256 of 300 bytes 0x01, as the file is
        let h = m[SHA256_KEY]["a.bin"].as_str().unwrap();
        assert_eq!(h, hex(&Sha256::digest([1u8; 300])));
        assert_eq!(m[META_SHA256_KEY].as_str().unwrap().len(), 64);
        // the manifest's hash is over the compact serialization of the other values
        let body = r#"{"samples":9,"x":[0.1,1e-300,-0.0],"name":"é\"\\\n"}"#;
        assert_eq!(m[META_SHA256_KEY], hex(&Sha256::digest(body.as_bytes())));
        // another format is refused, naming both
        let e = verify_dir(&dir, "dataset").unwrap_err().to_string();
        assert!(e.contains("\"test\"") && e.contains("\"dataset\""), "{e}");
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

    #[test]
    fn parsed_then_reserialized_meta_gives_the_same_bytes() {
        // serde_json's float_roundtrip: every finite f64 parses back to itself, so meta_sha256 of a
        // meta.json read back equals the one computed when it was written.
        let mut values: Vec<f64> = vec![
            0.1,
            1e-300,
            2.2250738585072014e-308, // smallest normal
            2.225073858507201e-308,  // largest subnormal
            5e-324,
            123456.789e10,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::EPSILON,
            -0.0,
            1.0 / 3.0,
            9007199254740993.0,
            1e23,
            8.98846567431158e307,
        ];
        // and a deterministic spread of bit patterns (SplitMix64)
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        while values.len() < 20_000 {
            s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            let x = f64::from_bits(z ^ (z >> 31));
            if x.is_finite() {
                values.push(x);
            }
        }
        let meta = json!({ "gvsrom": {"format": "test"}, "v": values, "nan": f64::NAN });
        assert_eq!(meta["nan"], Value::Null, "NaN is written as null");
        let Value::Object(m) = &meta else {
            unreachable!()
        };
        let back: Value =
            serde_json::from_str(&serde_json::to_string_pretty(&meta).unwrap()).unwrap();
        let Value::Object(b) = &back else {
            unreachable!()
        };
        for (x, y) in values.iter().zip(back["v"].as_array().unwrap()) {
            assert_eq!(x.to_bits(), y.as_f64().unwrap().to_bits(), "{x:e}");
        }
        assert_eq!(meta_sha256(m), meta_sha256(b));
    }
}
