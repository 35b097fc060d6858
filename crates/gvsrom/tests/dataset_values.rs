//! A dataset whose arrays have the right shapes but impossible values is refused by
//! `Dataset::load`, naming the file and the row: a non-finite coordinate, tip position, tip rotation
//! or residual in a row of status ok, a negative residual, a tip rotation that is not a rotation.
//! Each copy is resealed (`common::reseal`), so the content hashes match and the value check is
//! what must refuse it.

mod common;

use common::reseal::reseal;
use common::sweep_dataset;
use gvsrom::dataset::Dataset;
use std::fs;
use std::path::{Path, PathBuf};

/// A 3-sample single-tendon sweep (all samples ok), made once.
fn dataset() -> &'static Path {
    static D: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    D.get_or_init(|| sweep_dataset("values-ds", "-3:0", 3))
}

/// The values of the f64 array `file` of `dir` (flat, C order), and the byte offset of its data.
fn read_f64(dir: &Path, file: &str) -> (Vec<f64>, usize) {
    let bytes = fs::read(dir.join(file)).unwrap();
    // .npy 1.0: magic (6), version (2), header length (u16), header
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let data = 10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let values = bytes[data..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    (values, data)
}

/// Overwrites the values of `file` from flat index `at` on with `values`.
fn write_f64(dir: &Path, file: &str, at: usize, values: &[f64]) {
    let (_, data) = read_f64(dir, file);
    let mut bytes = fs::read(dir.join(file)).unwrap();
    for (i, v) in values.iter().enumerate() {
        let o = data + 8 * (at + i);
        bytes[o..o + 8].copy_from_slice(&v.to_le_bytes());
    }
    fs::write(dir.join(file), bytes).unwrap();
}

/// A resealed copy of the dataset with `edit` applied; returns `Dataset::load`'s error message.
fn refused(name: &str, edit: impl FnOnce(&Path)) -> String {
    let dir = common::copy_dir(dataset(), name);
    edit(&dir);
    reseal(&dir);
    match Dataset::load(&dir) {
        Ok(_) => panic!("{name}: the edited dataset was accepted"),
        Err(e) => e.to_string(),
    }
}

fn assert_names(msg: &str, needles: &[&str]) {
    for n in needles {
        assert!(msg.contains(n), "error lacks `{n}`: {msg}");
    }
}

#[test]
fn the_resealed_untouched_dataset_is_accepted_and_all_its_rows_are_ok() {
    let dir = common::copy_dir(dataset(), "values-untouched");
    reseal(&dir);
    let ds = Dataset::load(&dir).unwrap();
    assert_eq!(ds.ok_rows(), [0, 1, 2]);
    // what the edits below change is there to be changed: a solved rod has a residual and a rotation
    assert!(ds.residual.iter().all(|r| r.is_finite() && *r >= 0.0));
    for k in 0..3 {
        assert!(gvsrom::dataset::reader::is_rotation(&ds.tip_rotation[9 * k..9 * k + 9]).is_ok());
    }
}

#[test]
fn a_non_finite_value_in_an_ok_row_is_refused_naming_file_and_row() {
    let n_dof = {
        let (q, _) = read_f64(dataset(), "q.npy");
        q.len() / 3
    };
    for (file, at, value) in [
        ("q.npy", n_dof + 1, f64::NAN),
        ("tip_position.npy", 3 + 2, f64::INFINITY),
        ("tip_rotation.npy", 9 + 4, f64::NAN),
        ("residual.npy", 1, f64::NAN),
    ] {
        let msg = refused(&format!("values-nonfinite-{file}"), |d| {
            write_f64(d, file, at, &[value])
        });
        assert_names(
            &msg,
            &[file, "row 1 has status ok", "expected finite values"],
        );
    }
}

#[test]
fn a_tendon_length_that_is_not_a_length_is_refused_naming_file_and_row() {
    for (at, value, shown) in [
        (1, f64::NAN, "NaN"),
        (2, 0.0, "length 0 "),
        (0, -0.2, "-0.2"),
    ] {
        let msg = refused(&format!("values-tendon-length-{at}"), |d| {
            write_f64(d, "tendon_lengths.npy", at, &[value])
        });
        assert_names(
            &msg,
            &[
                "tendon_lengths.npy",
                &format!("row {at} has status ok"),
                shown,
                "tendon 0",
                "> 0 m",
            ],
        );
    }
}

#[test]
fn a_negative_residual_is_refused_naming_file_and_row() {
    let msg = refused("values-negative-residual", |d| {
        write_f64(d, "residual.npy", 2, &[-1e-9])
    });
    assert_names(&msg, &["residual.npy", "row 2", "-0.000000001", "≥ 0"]);
}

#[test]
fn a_tip_rotation_that_is_not_a_rotation_is_refused_naming_file_and_row() {
    let (r, _) = read_f64(dataset(), "tip_rotation.npy");
    // row 1 scaled by 1 + 1e-5: ‖RᵀR − I‖_F = (2·1e-5 + 1e-10)·√3 ≈ 3.5e-5
    let scaled: Vec<f64> = r[9..18].iter().map(|v| v * (1.0 + 1e-5)).collect();
    let msg = refused("values-rotation-scaled", |d| {
        write_f64(d, "tip_rotation.npy", 9, &scaled)
    });
    assert_names(
        &msg,
        &["tip_rotation.npy", "row 1 is not a rotation", "≤ 1e-6"],
    );
    // row 0 with its first column negated: orthogonal, but a reflection (det −1)
    let mut reflected = r[..9].to_vec();
    for i in 0..3 {
        reflected[3 * i] = -reflected[3 * i];
    }
    let msg = refused("values-rotation-reflected", |d| {
        write_f64(d, "tip_rotation.npy", 0, &reflected)
    });
    assert_names(
        &msg,
        &["tip_rotation.npy", "row 0 is not a rotation", "det R = -"],
    );
}
