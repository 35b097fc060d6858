//! A dataset changed after it was written is refused by the command that reads it, naming the file:
//! the SHA-256 of every file and of meta.json's values are recorded in its manifest when it is
//! written (`gvsrom::output::integrity`) and checked when it is loaded.

mod common;

use common::{expect_error, gvsrom, s, scratch, sweep_dataset};
use std::fs;
use std::path::{Path, PathBuf};

/// A 3-sample single-tendon sweep (one chunk), made once.
fn dataset() -> &'static Path {
    static D: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    D.get_or_init(|| sweep_dataset("integ-ds", "-3:0", 3))
}

/// A copy of the dataset in a fresh scratch directory.
fn copy(name: &str) -> PathBuf {
    let dst = scratch(name);
    fs::create_dir_all(&dst).unwrap();
    for e in fs::read_dir(dataset()).unwrap() {
        let e = e.unwrap();
        fs::copy(e.path(), dst.join(e.file_name())).unwrap();
    }
    dst
}

fn meta(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap()
}

/// `gvsrom pod DIR --modes 1 --out MODEL` refused with `needles`; no model is written.
fn pod_refused(dir: &Path, name: &str, needles: &[&str]) -> String {
    let model = scratch(name);
    let msg = expect_error(
        &["pod", s(dir), "--modes", "1", "--out", s(&model)],
        needles,
    );
    assert!(!model.exists(), "a model was written: {msg}");
    msg
}

#[test]
fn the_untouched_dataset_is_accepted() {
    let model = scratch("integ-ok-model");
    let out = gvsrom(&["pod", s(dataset()), "--modes", "1", "--out", s(&model)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let m = &meta(dataset())["gvsrom"];
    assert_eq!(m["sha256"].as_object().unwrap().len(), 10, "{m}");
    assert_eq!(m["meta_sha256"].as_str().unwrap().len(), 64, "{m}");
}

#[test]
fn one_flipped_byte_in_the_strain_data_is_refused_naming_strain_npy() {
    let dir = copy("integ-flip");
    let p = dir.join("strain.npy");
    let mut b = fs::read(&p).unwrap();
    // past the header (magic, version, header length, header): the lowest mantissa bit of the first
    // value, so the array still reads as a valid, finite one
    let data = 10 + u16::from_le_bytes([b[8], b[9]]) as usize;
    assert!(b.len() > data + 8);
    b[data] ^= 1;
    fs::write(&p, b).unwrap();
    pod_refused(
        &dir,
        "integ-flip-model",
        &[
            "strain.npy",
            "differs from the hash recorded when it was written",
        ],
    );
}

#[test]
fn an_edited_number_in_meta_json_is_refused_naming_meta_json() {
    let dir = copy("integ-meta");
    let text = fs::read_to_string(dir.join("meta.json")).unwrap();
    // the seed is read by nothing that checks the arrays: only the hash can tell
    assert!(text.contains("\"seed\": 0,"), "{text}");
    fs::write(
        dir.join("meta.json"),
        text.replacen("\"seed\": 0,", "\"seed\": 1,", 1),
    )
    .unwrap();
    pod_refused(
        &dir,
        "integ-meta-model",
        &["meta.json", "edited after it was written"],
    );
}

#[test]
fn a_dataset_written_before_hashes_were_recorded_is_still_read() {
    let dir = copy("integ-unhashed");
    let mut v = meta(&dir);
    let m = v["gvsrom"].as_object_mut().unwrap();
    m.shift_remove("sha256").unwrap();
    m.shift_remove("meta_sha256").unwrap();
    fs::write(
        dir.join("meta.json"),
        serde_json::to_string_pretty(&v).unwrap(),
    )
    .unwrap();
    let ds = gvsrom::dataset::Dataset::load(&dir).unwrap();
    assert_eq!(ds.integrity, gvsrom::output::Integrity::Unhashed);
    assert_eq!(
        gvsrom::dataset::Dataset::load(dataset()).unwrap().integrity,
        gvsrom::output::Integrity::Checked
    );
}
