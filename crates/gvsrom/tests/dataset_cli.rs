//! `gvsrom dataset` end to end: the arrays' shapes and layout, the strain of a sample against an
//! independent `gvsrom statics` run, read-back, corrupted files, repeatability across thread counts,
//! bad plans, `*` expansion, and resuming an interrupted run.

mod common;

use common::{copy_dir, expect_error, gvsrom, json, run_ok, scratch, sweep_dataset};
use gvsrom::dataset::Dataset;
use std::path::Path;

const ARRAYS: [&str; 10] = [
    "inputs.npy",
    "strain.npy",
    "q.npy",
    "tip_position.npy",
    "tip_rotation.npy",
    "status.npy",
    "iterations.npy",
    "residual.npy",
    "strain_x.npy",
    "tendon_lengths.npy",
];

/// A 9-sample single-tendon sweep over [-6, 3] N (one chunk).
fn sweep9(name: &str) -> std::path::PathBuf {
    sweep_dataset(name, "-6:3", 9)
}

#[test]
fn single_tendon_sweep_writes_306_strain_columns_and_matches_statics() {
    let dir = sweep9("ds-sweep9");
    let ds = Dataset::load(&dir).unwrap();
    assert_eq!(ds.samples(), 9);
    assert_eq!(ds.meta.components, ["bend_y", "elongation", "shear_z"]);
    assert_eq!(ds.strain_x.len(), 102);
    assert_eq!(ds.row_len(), 306);
    assert_eq!(ds.strain.len(), 9 * 306);
    assert_eq!(ds.q.len(), 9 * 33);
    assert_eq!(ds.ok_rows().len(), 9);
    assert!(ds.meta.complete && ds.problems().is_empty());
    // sweep: both ends included, even steps
    let u: Vec<f64> = ds.inputs.clone();
    assert_eq!(u[0], -6.0);
    assert_eq!(u[8], 3.0);
    assert!((u[4] - (-1.5)).abs() < 1e-15);

    // each sample against an independent statics solve from straight: ξ − ξ* with ξ* = [0,0,0,1,0,0]
    for k in [0, 3, 8] {
        let file = scratch(&format!("ds-sweep9-statics-{k}.json"));
        run_ok(&[
            "statics",
            "single-tendon",
            &format!("--tension={}", u[k]),
            "--json",
            file.to_str().unwrap(),
        ]);
        let sol = json(&file);
        let strain = sol["strain"].as_array().unwrap();
        let x = sol["strain_x"].as_array().unwrap();
        let row = ds.strain_row(k);
        let mut max = 0.0f64;
        for (j, xi) in strain.iter().enumerate() {
            // the JSON's shortest decimals parse back exactly (serde_json's float_roundtrip)
            assert_eq!(x[j].as_f64().unwrap(), ds.strain_x[j]);
            let xi: Vec<f64> = xi
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            // inactive components are exactly zero
            assert_eq!([xi[0], xi[2], xi[4]], [0.0, 0.0, 0.0]);
            for (c, a) in [1, 3, 5].into_iter().enumerate() {
                let dev = xi[a] - if a == 3 { 1.0 } else { 0.0 };
                max = max.max((row[3 * j + c] - dev).abs());
            }
        }
        // both are converged to ftol = 1e-10 of the residual scale from different starts (warm vs
        // straight); |ξ| reaches ~13 1/m here, so 1e-9 relative is ~1e-8 absolute
        assert!(max < 1e-8, "sample {k}: max strain difference {max:e}");
        let tip = sol["tip_position"].as_array().unwrap();
        for i in 0..3 {
            let d = (ds.tip_position[3 * k + i] - tip[i].as_f64().unwrap()).abs();
            assert!(d < 1e-10, "sample {k}: tip differs by {d:e}");
        }
        // the tendon's length, what its actuator reads: as the statics report gives it
        let length = sol["tendon_lengths"][0].as_f64().unwrap();
        let row = ds.tendon_lengths_row(k).unwrap();
        assert_eq!(row.len(), 1);
        assert!(
            (row[0] - length).abs() < 1e-10,
            "sample {k}: {} against {length}",
            row[0]
        );
    }
    // the more it is pulled (u from −6 to 3 N) the shorter it is
    assert_eq!(ds.meta.n_tendons, Some(1));
    let lengths = ds.tendon_lengths.as_ref().unwrap();
    assert!(lengths.windows(2).all(|w| w[0] < w[1]), "{lengths:?}");
}

#[test]
fn a_dataset_read_back_holds_exactly_the_bytes_written() {
    let dir = sweep9("ds-readback");
    let ds = Dataset::load(&dir).unwrap();
    let raw = |name: &str| -> Vec<f64> {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        bytes[10 + hl..]
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let same = |a: &[f64], b: &[f64]| {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
    };
    assert!(same(&ds.strain, &raw("strain.npy")));
    assert!(same(&ds.q, &raw("q.npy")));
    assert!(same(&ds.inputs, &raw("inputs.npy")));
    assert!(same(&ds.tip_rotation, &raw("tip_rotation.npy")));
    assert!(same(&ds.strain_x, &raw("strain_x.npy")));
    assert!(same(
        ds.tendon_lengths.as_ref().unwrap(),
        &raw("tendon_lengths.npy")
    ));
    assert_eq!(ds.status, vec![0u8; 9]);
    // and loading twice gives the same dataset
    assert_eq!(Dataset::load(&dir).unwrap(), ds);
}

#[test]
fn truncated_corrupted_or_missing_files_are_errors_naming_the_file() {
    let dir = sweep9("ds-corrupt");
    let check = |name: &str, damage: &dyn Fn(&Path), needles: &[&str]| {
        let d = copy_dir(&dir, name);
        damage(&d);
        let e = Dataset::load(&d).unwrap_err().to_string();
        assert_eq!(e.lines().count(), 1, "{e}");
        for n in needles {
            assert!(e.contains(n), "`{n}` missing from: {e}");
        }
    };
    check(
        "ds-corrupt-trunc",
        &|d| {
            let p = d.join("strain.npy");
            let len = std::fs::metadata(&p).unwrap().len();
            let f = std::fs::OpenOptions::new().write(true).open(&p).unwrap();
            f.set_len(len - 8).unwrap();
        },
        &["strain.npy", "truncated"],
    );
    check(
        "ds-corrupt-extra",
        &|d| {
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new()
                .append(true)
                .open(d.join("q.npy"))
                .unwrap();
            f.write_all(&[0; 8]).unwrap();
        },
        &["q.npy", "trailing"],
    );
    check(
        "ds-corrupt-meta",
        &|d| std::fs::write(d.join("meta.json"), "{ garbage").unwrap(),
        &["meta.json", "not valid JSON"],
    );
    check(
        "ds-corrupt-missing",
        &|d| std::fs::remove_file(d.join("tip_rotation.npy")).unwrap(),
        &["tip_rotation.npy", "missing"],
    );
    check(
        "ds-corrupt-header",
        &|d| std::fs::write(d.join("status.npy"), b"not an npy file").unwrap(),
        &["status.npy", "not a valid .npy"],
    );
    check(
        "ds-corrupt-samples",
        &|d| {
            let p = d.join("meta.json");
            let t = std::fs::read_to_string(&p)
                .unwrap()
                .replace("\"samples\": 9", "\"samples\": 10");
            std::fs::write(p, t).unwrap();
        },
        &["inputs.npy", "shape [9, 1], expected [10, 1]"],
    );
    // NaN in a row marked ok
    check(
        "ds-corrupt-nan",
        &|d| {
            let p = d.join("strain.npy");
            let mut b = std::fs::read(&p).unwrap();
            let n = b.len();
            b[n - 8..].copy_from_slice(&f64::NAN.to_le_bytes());
            std::fs::write(p, b).unwrap();
        },
        &["strain.npy", "row 8", "NaN"],
    );
}

fn random_six(name: &str, extra: &[&str]) -> std::path::PathBuf {
    random_six_seed(name, "7", extra)
}

fn random_six_seed(name: &str, seed: &str, extra: &[&str]) -> std::path::PathBuf {
    let dir = scratch(name);
    let mut args = vec![
        "dataset",
        "six-tendon",
        "--random",
        "tendons.*.tension=-30:30",
        "--samples",
        "40",
        "--chunk-size",
        "8",
        "--seed",
        seed,
        "--out",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = gvsrom(&args);
    assert!(
        out.status.success() || out.status.code() == Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

fn assert_same_arrays(a: &Path, b: &Path) {
    for f in ARRAYS {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(
            x == y,
            "{f} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn the_same_seed_gives_bit_identical_files_with_one_or_two_threads() {
    let one = random_six("ds-threads-1", &["--threads", "1"]);
    let two = random_six("ds-threads-2", &["--threads", "2"]);
    assert_same_arrays(&one, &two);
    let other = random_six_seed("ds-threads-seed", "8", &[]);
    assert_ne!(
        std::fs::read(one.join("inputs.npy")).unwrap(),
        std::fs::read(other.join("inputs.npy")).unwrap()
    );
}

#[test]
fn star_expands_to_one_input_column_per_tendon() {
    let dir = random_six("ds-star", &[]);
    let ds = Dataset::load(&dir).unwrap();
    let names: Vec<String> = (0..6).map(|k| format!("tendons.{k}.tension")).collect();
    assert_eq!(ds.meta.parameters, names);
    assert_eq!(ds.inputs.len(), 40 * 6);
    assert!(ds.inputs.iter().all(|u| (-30.0..30.0).contains(u)));
    assert_eq!(ds.row_len(), 14 * 6);
    assert_eq!(ds.meta.chunk_done, vec![true; 5]);
    assert_eq!(ds.ok_rows().len(), 40);
}

#[test]
fn a_resumed_run_equals_an_uninterrupted_one() {
    let whole = random_six("ds-resume-whole", &[]);
    let part = random_six("ds-resume-part", &["--stop-after-chunks", "2"]);
    let ds = Dataset::load(&part).unwrap();
    assert!(!ds.meta.complete);
    assert_eq!(ds.meta.chunk_done.iter().filter(|d| **d).count(), 2);
    assert_eq!(ds.meta.counts.not_computed, 24);
    assert_eq!(ds.problems().len(), 24);
    // a different plan is refused, naming what differs
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--random",
            "tendons.*.tension=-30:30",
            "--samples",
            "40",
            "--chunk-size",
            "8",
            "--seed",
            "9",
            "--out",
            part.to_str().unwrap(),
            "--resume",
        ],
        &["--resume", "--seed", "7 there, 9 now"],
    );
    // so is a different scenario, naming the value
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--random",
            "tendons.*.tension=-30:30",
            "--samples",
            "40",
            "--chunk-size",
            "8",
            "--seed",
            "7",
            "--set",
            "tendons.2.friction=0.25",
            "--out",
            part.to_str().unwrap(),
            "--resume",
        ],
        &["--resume", "`tendons[2].friction` differs", "0.25 now"],
    );
    let same_args = [
        "dataset",
        "six-tendon",
        "--random",
        "tendons.*.tension=-30:30",
        "--samples",
        "40",
        "--chunk-size",
        "8",
        "--seed",
        "7",
        "--out",
        part.to_str().unwrap(),
        "--resume",
    ];
    // a dataset written before the coordinate order was recorded (FEM bases were mode-major then)
    // is refused: its q rows would not fit this run's
    let meta_path = part.join("meta.json");
    let meta_text = std::fs::read_to_string(&meta_path).unwrap();
    let mut legacy = json(&meta_path);
    legacy.as_object_mut().unwrap().remove("q_order").unwrap();
    std::fs::write(&meta_path, serde_json::to_string(&legacy).unwrap()).unwrap();
    common::reseal::reseal(&part);
    expect_error(
        &same_args,
        &["--resume", "q_order", "`fem-mode-major` there"],
    );
    // such a dataset predates the content hashes too: whether it was edited cannot be told, and
    // the resumed run would build on it and replace it
    let mut legacy = json(&meta_path);
    let m = legacy["gvsrom"].as_object_mut().unwrap();
    m.shift_remove("sha256");
    m.shift_remove("meta_sha256");
    std::fs::write(&meta_path, serde_json::to_string(&legacy).unwrap()).unwrap();
    expect_error(&same_args, &["--out", "records no content hashes"]);
    std::fs::write(&meta_path, meta_text).unwrap();
    let out = gvsrom(&same_args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 chunks kept"));
    assert_same_arrays(&whole, &part);
    let (resumed, uninterrupted) = (
        Dataset::load(&part).unwrap(),
        Dataset::load(&whole).unwrap(),
    );
    assert!(resumed.meta.complete);
    // the counts too: the kept chunks' warm starts are carried over
    assert_eq!(resumed.meta.counts, uninterrupted.meta.counts);
    // nothing left beside it
    let parent = part.parent().unwrap();
    for e in std::fs::read_dir(parent).unwrap() {
        let n = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!n.starts_with(".ds-resume-part."), "left behind: {n}");
    }
}

/// A dataset written before the tendons' lengths were recorded (no `tendon_lengths.npy`, no
/// `n_tendons`) resumes: the kept rows' lengths are computed from their `q`, and the result equals
/// an uninterrupted run's.
#[test]
fn a_dataset_from_before_tendon_lengths_resumes_with_its_lengths_computed() {
    let whole = random_six("ds-legacy-whole", &[]);
    let part = random_six("ds-legacy-part", &["--stop-after-chunks", "2"]);
    std::fs::remove_file(part.join("tendon_lengths.npy")).unwrap();
    let meta_path = part.join("meta.json");
    let mut legacy = json(&meta_path);
    legacy.as_object_mut().unwrap().remove("n_tendons").unwrap();
    let files = legacy["gvsrom"]["files"].as_array_mut().unwrap();
    files.retain(|f| f != "tendon_lengths.npy");
    std::fs::write(&meta_path, serde_json::to_string(&legacy).unwrap()).unwrap();
    common::reseal::reseal(&part);
    let old = Dataset::load(&part).unwrap();
    assert_eq!(
        (old.meta.n_tendons, old.tendon_lengths_row(0)),
        (None, None)
    );
    run_ok(&[
        "dataset",
        "six-tendon",
        "--random",
        "tendons.*.tension=-30:30",
        "--samples",
        "40",
        "--chunk-size",
        "8",
        "--seed",
        "7",
        "--out",
        part.to_str().unwrap(),
        "--resume",
    ]);
    let (resumed, uninterrupted) = (
        Dataset::load(&part).unwrap(),
        Dataset::load(&whole).unwrap(),
    );
    assert_eq!(resumed.meta.n_tendons, Some(6));
    let (a, b) = (
        resumed.tendon_lengths.as_ref().unwrap(),
        uninterrupted.tendon_lengths.as_ref().unwrap(),
    );
    assert_eq!(a.len(), 40 * 6);
    // the kept rows (chunks 0 and 1: rows 0..16) from q, the others solved: as the whole run's
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= 1e-12 * y,
            "row {}, tendon {}: {x} against {y}",
            k / 6,
            k % 6
        );
    }
    for f in &ARRAYS[..9] {
        let same = std::fs::read(part.join(f)).unwrap() == std::fs::read(whole.join(f)).unwrap();
        assert!(same, "{f} differs from the uninterrupted run's");
    }
}

#[test]
fn an_interrupted_run_exits_like_simulate_and_marks_the_dataset_incomplete() {
    let dir = scratch("ds-interrupted");
    let out = gvsrom(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-6:3",
        "--samples",
        "12",
        "--chunk-size",
        "4",
        "--threads",
        "1",
        "--stop-after-chunks",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(130));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("interrupted:") && stderr.contains("--resume"),
        "{stderr}"
    );
    let meta = json(&dir.join("meta.json"));
    assert_eq!(meta["complete"], false);
    assert_eq!(meta["counts"]["ok"], 4);
}

#[test]
fn bad_plans_are_one_line_errors_naming_the_option() {
    let out = scratch("ds-bad");
    let o = out.to_str().unwrap();
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--random",
            "tendons.*.tensoin=-3:3",
            "--samples",
            "4",
            "--out",
            o,
        ],
        &["--random", "tendons.*.tensoin=-3:3", "tensoin"],
    );
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--sweep",
            "loads.distributed.*.center=0:1",
            "--samples",
            "4",
            "--out",
            o,
        ],
        &["--sweep", "loads.distributed", "no list"],
    );
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--sweep",
            "tendons.9.tension=-3:3",
            "--samples",
            "4",
            "--out",
            o,
        ],
        &["--sweep", "tendons.9.tension", "out of range"],
    );
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--grid",
            "tendons.*.tension=-3:3",
            "--samples",
            "100",
            "--out",
            o,
        ],
        &["--samples 100", "64 (2^6)", "729 (3^6)"],
    );
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--grid",
            "tendons.0.tension=3:x",
            "--samples",
            "4",
            "--out",
            o,
        ],
        &["--grid", "3:x", "PATH=LO:HI"],
    );
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--sweep",
            "tendons.0.tension=0:1",
            "--random",
            "tendons.1.tension=0:1",
            "--samples",
            "4",
            "--out",
            o,
        ],
        &["--sweep and --random", "one kind"],
    );
    expect_error(
        &["dataset", "six-tendon", "--samples", "4", "--out", o],
        &["needs a plan"],
    );
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--sweep",
            "tendons.0.tension=-6:3",
            "--samples",
            "4",
            "--out",
            o,
            "--resume",
        ],
        &["--resume", "no dataset to resume"],
    );
    // values that change the coordinates or the points, and a whole-number field that random
    // draws give fractions of: refused before anything is computed, not failed sample by sample
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--sweep",
            "divisions.0.length=0.25:0.3",
            "--samples",
            "3",
            "--out",
            o,
        ],
        &["--sweep", "divisions.0.length = 0.3", "one layout"],
    );
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--random",
            "divisions.0.basis.order=10:12",
            "--samples",
            "3",
            "--out",
            o,
        ],
        &["--random", "divisions.0.basis.order"],
    );
    assert!(!out.exists());
}

#[test]
fn a_dynamic_dataset_stores_every_sample_of_the_simulate_run() {
    let dir = scratch("ds-dynamic");
    let traj = scratch("ds-dynamic-simulate");
    let common = [
        "six-tendon",
        "--duration",
        "0.3",
        "--babble=-15,0,0.05,0.1",
        "--sample-rate",
        "100",
        "--seed",
        "3",
    ];
    let mut a = vec!["dataset"];
    a.extend(common);
    a.extend(["--out", dir.to_str().unwrap()]);
    run_ok(&a);
    let mut b = vec!["simulate"];
    b.extend(common);
    b.extend(["--out", traj.to_str().unwrap()]);
    run_ok(&b);
    let ds = Dataset::load(&dir).unwrap();
    assert_eq!(ds.meta.kind, "dynamics");
    assert_eq!(ds.samples(), 31);
    assert!(ds.meta.complete);
    assert_eq!(ds.t.as_ref().unwrap().len(), 31);
    assert_eq!(ds.inputs.len(), 31 * 6);
    // the same run as `simulate`: identical q, u and strain (ξ − ξ*, all six components active)
    let raw = |name: &str| -> Vec<f64> {
        let bytes = std::fs::read(traj.join(name)).unwrap();
        let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        bytes[10 + hl..]
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    assert_eq!(ds.q, raw("q.npy"));
    assert_eq!(ds.inputs, raw("u.npy"));
    let xi = raw("strain.npy");
    assert_eq!(xi.len(), ds.strain.len());
    for (i, (d, x)) in ds.strain.iter().zip(&xi).enumerate() {
        let star = if i % 6 == 3 { 1.0 } else { 0.0 };
        assert_eq!(*d, x - star, "value {i}");
    }
    expect_error(
        &[
            "dataset",
            "six-tendon",
            "--duration",
            "1",
            "--random",
            "tendons.0.tension=0:1",
            "--out",
            dir.to_str().unwrap(),
        ],
        &["--random", "--duration"],
    );
}

/// `max |strain row k − (ξ − ξ*)| / max |ξ − ξ*|` against an independent `gvsrom statics` run with
/// `set` overrides, for a dataset whose active components are `active`. Both solutions meet the
/// solver's tolerance (‖R‖∞ ≤ 1e-10 of the force scale) from different starts (warm vs straight),
/// so they agree to about 1e-9 relative.
fn max_strain_difference(
    ds: &Dataset,
    k: usize,
    scenario: &str,
    set: &[String],
    active: &[usize],
) -> f64 {
    let file = scratch(&format!("ds-check-{scenario}-{k}.json"));
    let mut args = vec!["statics".to_string(), scenario.to_string()];
    for s in set {
        args.push("--set".into());
        args.push(s.clone());
    }
    args.extend(["--json".into(), file.to_str().unwrap().to_string()]);
    run_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let sol = json(&file);
    let row = ds.strain_row(k);
    let a = active.len();
    let (mut max, mut scale) = (0.0f64, 0.0f64);
    for (j, xi) in sol["strain"].as_array().unwrap().iter().enumerate() {
        for (c, &i) in active.iter().enumerate() {
            let dev = xi[i].as_f64().unwrap() - if i == 3 { 1.0 } else { 0.0 };
            max = max.max((row[a * j + c] - dev).abs());
            scale = scale.max(dev.abs());
        }
    }
    max / scale.max(1e-300)
}

#[test]
fn load_and_material_parameters_match_statics_with_set() {
    // loads only: the model is shared, the loads rebuilt per sample
    let dir = scratch("ds-soft-beam");
    run_ok(&[
        "dataset",
        "soft-beam",
        "--random",
        "loads.distributed.0.center=0.1:0.7",
        "--random",
        "loads.distributed.0.magnitude=-5:5",
        "--samples",
        "4",
        "--seed",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let ds = Dataset::load(&dir).unwrap();
    assert_eq!(ds.meta.components, ["bend_y"]);
    for k in [0, 3] {
        let (c, m) = (ds.inputs[2 * k], ds.inputs[2 * k + 1]);
        let set = [
            format!("loads.distributed.0.center={c}"),
            format!("loads.distributed.0.magnitude={m}"),
        ];
        let d = max_strain_difference(&ds, k, "soft-beam", &set, &[1]);
        assert!(d < 2e-9, "soft-beam sample {k}: {d:e}");
    }
    // a material value: the model is rebuilt per sample
    let dir = scratch("ds-material");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "material.youngs_modulus=5e5:8e5",
        "--samples",
        "3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let ds = Dataset::load(&dir).unwrap();
    for k in 0..3 {
        let set = [format!("material.youngs_modulus={}", ds.inputs[k])];
        let d = max_strain_difference(&ds, k, "single-tendon", &set, &[1, 3, 5]);
        assert!(d < 2e-9, "single-tendon sample {k}: {d:e}");
    }
}

/// Runs `gvsrom args` (writing `dir`), sends SIGINT after 1 s and checks that it exits with 130
/// within 4 s of its start, marking the dataset incomplete.
fn interrupted_soon(args: &[&str], dir: &Path) {
    let t0 = std::time::Instant::now();
    let out = common::interrupted(args, std::time::Duration::from_millis(1000));
    let elapsed = t0.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(
        elapsed < 4.0,
        "the run ended {elapsed:.1} s after its start, 1 s after SIGINT: {stderr}"
    );
    let meta = json(&dir.join("meta.json"));
    assert_eq!(meta["complete"], false);
    assert!(
        meta["reason"]
            .as_str()
            .is_some_and(|r| r.contains("SIGINT")),
        "{meta}"
    );
}

#[test]
fn an_interrupt_stops_a_long_load_ramp_within_one_stage_not_at_the_next_sample() {
    // one sample with a 10 000-stage ramp takes seconds (≈ 8 s here); SIGINT during it must end
    // the run at the next stage, not after the sample (nor after the chunk)
    let dir = scratch("ds-interrupted-ramp");
    let args = [
        "dataset",
        "six-tendon",
        "--set",
        "solver.ramp_steps=10000",
        "--random",
        "tendons.*.tension=-30:30",
        "--samples",
        "2",
        "--chunk-size",
        "1",
        "--threads",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ];
    interrupted_soon(&args, &dir);
    assert_eq!(json(&dir.join("meta.json"))["counts"]["ok"], 0);
}

#[test]
fn an_interrupt_stops_a_dynamic_dataset_between_integrator_steps_not_at_the_next_sample() {
    // tight tolerances and one sample every 2 s: the first interval takes far longer than 30 s
    // here, so only the per-step poll can end the run soon after SIGINT
    let dir = scratch("ds-interrupted-steps");
    let args = [
        "dataset",
        "six-tendon",
        "--duration",
        "4",
        "--babble=-15,0,0.05,0.1",
        "--sample-rate",
        "0.5",
        "--rtol",
        "1e-12",
        "--atol",
        "1e-14",
        "--out",
        dir.to_str().unwrap(),
    ];
    interrupted_soon(&args, &dir);
    // the initial sample only
    let ds = Dataset::load(&dir).unwrap();
    assert_eq!(ds.t.as_deref(), Some(&[0.0][..]));
}

#[test]
fn bad_tolerances_of_a_dynamic_dataset_are_refused_before_an_earlier_dataset_is_replaced() {
    // a NaN or out-of-range tolerance is a planning error naming the option: the dataset already
    // at --out stays as it was (once it was replaced by an unreadable, empty one)
    let dir = sweep_dataset("ds-bad-tolerances", "-5:0", 3);
    let before = std::fs::read(dir.join("meta.json")).unwrap();
    let bad = [
        ("--rtol", "NaN"),
        ("--atol", "NaN"),
        ("--rtol", "2"),
        // looser than the motion allows: percents of the length off, passing as a normal run
        ("--rtol", "0.5"),
        ("--atol", "100"),
        // a dynamic dataset runs on one thread, but a thread count no machine has is an error
        ("--threads", "0"),
        ("--threads", "5000"),
    ];
    for (opt, value) in bad {
        expect_error(
            &[
                "dataset",
                "single-tendon",
                "--duration",
                "0.02",
                opt,
                value,
                "--force",
                "--out",
                dir.to_str().unwrap(),
            ],
            &[opt, value],
        );
        assert_eq!(std::fs::read(dir.join("meta.json")).unwrap(), before);
        assert_eq!(Dataset::load(&dir).unwrap().status.len(), 3);
    }
}

#[test]
fn integrator_tolerances_of_a_static_dataset_are_refused_not_ignored() {
    // a plan of equilibria runs no integrator: --rtol/--atol there are a mistake, not a setting
    let dir = scratch("ds-static-rtol");
    for opt in [["--rtol", "1e-20"], ["--atol", "1e-9"]] {
        let out = gvsrom(&[
            "dataset",
            "single-tendon",
            "--sweep",
            "tendons.0.tension=-6:0",
            "--samples",
            "3",
            opt[0],
            opt[1],
            "--out",
            dir.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{opt:?} accepted");
        assert!(stderr.contains("--duration"), "{stderr}");
        assert!(!dir.exists());
    }
}

#[test]
fn a_seed_no_part_of_the_plan_draws_from_is_refused_not_ignored() {
    // a sweep or grid draws nothing: `--seed` there is a mistake, not a setting
    let dir = scratch("ds-unused-seed");
    for plan in ["--sweep", "--grid"] {
        let out = gvsrom(&[
            "dataset",
            "single-tendon",
            plan,
            "tendons.0.tension=-6:0",
            "--samples",
            "3",
            "--seed",
            "4",
            "--out",
            dir.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{plan} with --seed accepted");
        // the plan's reason, not clap's list of the options that would take a seed
        assert!(
            stderr.contains("--seed 4: this plan draws nothing")
                && stderr.contains("--seed applies to --random, --steps and --babble"),
            "{stderr}"
        );
        assert!(!dir.exists());
    }
}

#[test]
fn a_plan_none_of_whose_samples_solves_is_an_error() {
    // one Newton iteration per load stage: no sample converges (a plan whose values change the
    // coordinates is refused before computing: `bad_plans_are_one_line_errors_naming_the_option`)
    let dir = scratch("ds-none-solved");
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--set",
            "solver.max_iterations=1",
            "--sweep",
            "tendons.0.tension=-6:-5",
            "--samples",
            "3",
            "--out",
            dir.to_str().unwrap(),
        ],
        &[
            "none of the 3 samples solved",
            "sample 0:",
            "for inspection",
        ],
    );
    assert_eq!(json(&dir.join("meta.json"))["counts"]["ok"], 0);
}

#[test]
fn a_dataset_of_a_tendon_the_basis_cannot_hold_warns() {
    let dir = scratch("ds-helical-planar");
    let out = gvsrom(&[
        "dataset",
        "single-tendon",
        "--set",
        "tendons.0.turns=0.5",
        "--sweep",
        "tendons.0.tension=-2:0",
        "--samples",
        "2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: tendons[0] also loads torsion, bend_z, shear_y"),
        "{stderr}"
    );
}

#[test]
fn a_value_set_that_the_plan_varies_is_refused_naming_both() {
    for (set, plan) in [
        ("tendons.0.tension=-1", "tendons.0.tension=-6:0"),
        ("tendons[0].tension=-1", "tendons.0.tension=-6:0"),
        ("tendons.*.tension=-1", "tendons.0.tension=-6:0"),
        ("tendons.00.tension=-1", "tendons.*.tension=-6:0"),
        ("loads.gravity=[0, 0, -1]", "loads.gravity.2=-9:0"),
    ] {
        let out = scratch("set-varied");
        expect_error(
            &[
                "dataset",
                "single-tendon",
                "--sweep",
                plan,
                "--samples",
                "2",
                "--set",
                set,
                "--out",
                out.to_str().unwrap(),
            ],
            &[
                &format!("--set {set}"),
                &format!(
                    "the plan varies `{}` (--sweep {plan})",
                    plan.split('=').next().unwrap()
                ),
            ],
        );
        assert!(!out.exists(), "nothing written for a refused plan");
    }
    // a value the plan does not vary is set
    let out = scratch("set-other");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-6:0",
        "--samples",
        "2",
        "--set",
        "tendons.0.friction=0",
        "--out",
        out.to_str().unwrap(),
    ]);
}
