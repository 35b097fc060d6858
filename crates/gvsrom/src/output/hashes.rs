//! The content hashes a directory output records in its manifest when it is committed
//! ([`super::OutputDir::commit`]), and the recorded hashes read back; `integrity.rs` checks
//! them when the output is loaded.
//!
//! The manifest (the `"gvsrom"` object at the top of `DIR/meta.json`) records
//! - `"sha256": {"<file>": "<hex>", …}`: the SHA-256 of each file it lists, as written;
//! - `"meta_sha256": "<hex>"`: the SHA-256 of the compact JSON serialization of the meta.json object
//!   *without* its `"gvsrom"` key, keys in the order written. serde_json keeps that order
//!   (`preserve_order`) and parses every number back to the same value (`float_roundtrip`; NaN and
//!   infinities are written as `null`), so the meta.json read back serializes to the same bytes
//!   however it is indented.

use super::read::open_regular;
use super::MANIFEST_KEY;
use serde::ser::{Serialize, SerializeMap, Serializer};
use serde_json::{Map, Value};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::{self, Read};
use std::path::Path;

/// The manifest key of the files' hashes.
pub const SHA256_KEY: &str = "sha256";
/// The manifest key of the hash of meta.json without its manifest.
pub const META_SHA256_KEY: &str = "meta_sha256";

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
    match obj.get(MANIFEST_KEY) {
        Some(Value::Object(_)) => {
            // the files' hashes first, as written before (the meta hash leaves the manifest out)
            if let Some(Value::Object(m)) = obj.get_mut(MANIFEST_KEY) {
                m.insert(SHA256_KEY.into(), Value::Object(hashes));
            }
            record_meta_hash(obj);
            Ok(())
        }
        _ => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "output metadata has no manifest to record the hashes in",
        )),
    }
}

/// Records [`meta_sha256`] of `obj` in its manifest object (nothing without one): a directory's
/// meta.json, or a JSON file output's own values.
pub(super) fn record_meta_hash(obj: &mut Map<String, Value>) {
    let hash = meta_sha256(obj);
    if let Some(Value::Object(m)) = obj.get_mut(MANIFEST_KEY) {
        m.insert(META_SHA256_KEY.into(), Value::from(hash));
    }
}

/// A recorded hash, if `v` is 64 hex digits (compared case-insensitively).
pub(super) fn recorded(v: &Value) -> Option<String> {
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

#[cfg(test)]
mod tests {
    use super::super::test_util::{committed_output, meta_of};
    use super::super::{verify_dir, Integrity};
    use super::*;
    use serde_json::json;

    #[test]
    fn a_fresh_output_records_its_hashes_and_verifies() {
        let dir = committed_output("hashes", "fresh");
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
