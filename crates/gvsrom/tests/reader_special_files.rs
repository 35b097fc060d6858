//! A FIFO, device or directory in place of a file of a dataset or a reduced model is refused at once,
//! naming the file and what it is, by the command that reads it: a reader that opened the FIFO would
//! wait forever for a writer. Checked both for outputs with a full manifest (the integrity check
//! refuses the file) and for older ones whose manifest lists no files (the loaders refuse it).
//! Every run has a deadline, so a regression fails instead of hanging.

mod common;

use common::{expect_error_within, fifo_at, run_ok, s, scratch, sweep_dataset};
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Longer than any of these runs takes when it ends (well under a second), short enough to fail.
const DEADLINE: Duration = Duration::from_secs(20);

/// A 3-sample single-tendon sweep, made once.
fn dataset() -> &'static Path {
    static D: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    D.get_or_init(|| sweep_dataset("special-ds", "-3:0", 3))
}

/// A one-mode POD model of [`dataset`], made once.
fn model() -> &'static Path {
    static M: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("special-model");
        run_ok(&["pod", s(dataset()), "--modes", "1", "--out", s(&dir)]);
        dir
    })
}

/// A copy of `from` at scratch `name`; with `unlisted`, its manifest is that of an older output
/// which lists no files and records no hashes (so no integrity check looks at the files).
fn copy(from: &Path, name: &str, unlisted: bool) -> PathBuf {
    let dir = common::copy_dir(from, name);
    if unlisted {
        let path = dir.join("meta.json");
        let mut meta: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&path).unwrap()).unwrap();
        let m = meta["gvsrom"].as_object_mut().unwrap();
        for key in ["files", "sha256", "meta_sha256"] {
            m.shift_remove(key).unwrap();
        }
        fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    }
    dir
}

fn pod_refused(dir: &Path, needles: &[&str]) -> String {
    let out = scratch(&format!(
        "{}-model",
        dir.file_name().unwrap().to_str().unwrap()
    ));
    let msg = expect_error_within(
        DEADLINE,
        &["pod", s(dir), "--modes", "1", "--out", s(&out)],
        needles,
    );
    assert!(!out.exists(), "a model was written: {msg}");
    msg
}

fn statics_refused(model: &Path, needles: &[&str]) -> String {
    expect_error_within(
        DEADLINE,
        &[
            "statics",
            "single-tendon",
            "--tension=-2",
            "--model",
            s(model),
        ],
        needles,
    )
}

#[test]
fn an_older_dataset_whose_manifest_lists_no_files_is_still_read() {
    // the copies below differ from this one only by the special file
    let dir = copy(dataset(), "special-ds-unlisted", true);
    run_ok(&[
        "pod",
        s(&dir),
        "--modes",
        "1",
        "--out",
        s(&scratch("special-ds-unlisted-model")),
    ]);
}

#[test]
fn a_fifo_in_place_of_a_dataset_array_is_refused_naming_it() {
    for unlisted in [true, false] {
        let dir = copy(dataset(), &format!("special-ds-fifo-{unlisted}"), unlisted);
        fifo_at(&dir.join("strain.npy"));
        pod_refused(
            &dir,
            &["strain.npy", "a FIFO (named pipe), not a regular file"],
        );
    }
}

#[test]
fn a_fifo_in_place_of_a_dataset_meta_json_is_refused_naming_it() {
    let dir = copy(dataset(), "special-ds-meta-fifo", false);
    fifo_at(&dir.join("meta.json"));
    pod_refused(
        &dir,
        &["meta.json", "a FIFO (named pipe), not a regular file"],
    );
}

#[test]
fn a_directory_or_device_in_place_of_a_dataset_array_is_refused_saying_what_it_is() {
    for unlisted in [true, false] {
        let dir = copy(dataset(), &format!("special-ds-dir-{unlisted}"), unlisted);
        fs::remove_file(dir.join("q.npy")).unwrap();
        fs::create_dir(dir.join("q.npy")).unwrap();
        pod_refused(&dir, &["q.npy", "a directory, not a regular file"]);
    }
    // a link to a device: the link is refused by the integrity check, the device by the loader
    let dir = copy(dataset(), "special-ds-device", true);
    fs::remove_file(dir.join("residual.npy")).unwrap();
    std::os::unix::fs::symlink("/dev/null", dir.join("residual.npy")).unwrap();
    pod_refused(
        &dir,
        &["residual.npy", "a character device, not a regular file"],
    );
}

#[test]
fn a_fifo_in_place_of_a_model_file_is_refused_naming_it() {
    for unlisted in [true, false] {
        let dir = copy(
            model(),
            &format!("special-model-weights-{unlisted}"),
            unlisted,
        );
        fifo_at(&dir.join("weights.safetensors"));
        statics_refused(
            &dir,
            &[
                "weights.safetensors",
                "a FIFO (named pipe), not a regular file",
            ],
        );
    }
    let dir = copy(model(), "special-model-meta", false);
    fifo_at(&dir.join("meta.json"));
    statics_refused(
        &dir,
        &["meta.json", "a FIFO (named pipe), not a regular file"],
    );
}
