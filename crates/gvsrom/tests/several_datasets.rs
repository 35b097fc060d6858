//! `gvsrom pod A B …` and `gvsrom train A B …`: a model made from several datasets of one scenario
//! is the model of their stacked snapshots, records every dataset it was made from, covers the
//! union of their inputs, and datasets of other physics, inputs or points are refused by name.

mod common;

use common::{
    assert_sigma_squared_are_eigenvalues, expect_error, json, npy, run_ok, s, scratch, snapshots,
    sweep_dataset,
};
use gvsrom::reduced_model::ReducedModel;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// `gvsrom dataset single-tendon --random tendons.0.tension=-3:2.5 --samples 10 --seed 4` plus
/// `extra` arguments, at the scratch path `name`.
fn random_dataset(name: &str, extra: &[&str]) -> PathBuf {
    let dir = scratch(name);
    let mut args = vec![
        "dataset",
        "single-tendon",
        "--random",
        "tendons.0.tension=-3:2.5",
        "--samples",
        "10",
        "--seed",
        "4",
    ];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--out", s(&dir)]);
    run_ok(&args);
    dir
}

/// A: a sweep of 15 tensions over [-6, 0] N; B: 10 random tensions in [-3, 2.5] N.
fn two() -> &'static (PathBuf, PathBuf) {
    static D: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    D.get_or_init(|| {
        (
            sweep_dataset("several-a", "-6:0", 15),
            random_dataset("several-b", &[]),
        )
    })
}

fn inputs(dir: &Path) -> Vec<f64> {
    npy(&dir.join("inputs.npy")).1
}

#[test]
fn pod_of_two_datasets_is_the_pod_of_their_stacked_snapshots() {
    let (a, b) = two();
    let ab = scratch("several-pod-ab");
    let printed = run_ok(&["pod", s(a), s(b), "--modes", "3", "--out", s(&ab)]);
    assert!(
        printed.contains(&format!("{} (15 rows) + {} (10 rows)", s(a), s(b))),
        "{printed}"
    );
    // σ_k² are the eigenvalues of XᵀX = X_Aᵀ X_A + X_Bᵀ X_B (a symmetric eigensolver, not an SVD)
    let (xa, xb) = (snapshots(a), snapshots(b));
    let gram = xa.transpose() * &xa + xb.transpose() * &xb;
    assert_sigma_squared_are_eigenvalues(&ab, &gram, 3, 1e-9);
    let sigma = npy(&ab.join("singular_values.npy")).1;
    // one dataset alone is another POD
    let a_only = scratch("several-pod-a");
    run_ok(&["pod", s(a), "--modes", "3", "--out", s(&a_only)]);
    let sigma_a = npy(&a_only.join("singular_values.npy")).1;
    assert!((sigma_a[1] - sigma[1]).abs() > 1e-6 * sigma[0]);
    // the other order: the same snapshots, the same modes' energies
    let ba = scratch("several-pod-ba");
    run_ok(&["pod", s(b), s(a), "--modes", "3", "--out", s(&ba)]);
    let sigma_ba = npy(&ba.join("singular_values.npy")).1;
    for k in 0..3 {
        assert!((sigma_ba[k] - sigma[k]).abs() <= 1e-9 * sigma[0]);
    }

    // what the model records: both datasets with their rows and strain hashes, in order
    let meta = json(&ab.join("meta.json"));
    let strain_hash =
        |dir: &Path| json(&dir.join("meta.json"))["gvsrom"]["sha256"]["strain.npy"].clone();
    assert_eq!(meta["dataset"]["path"], s(a));
    assert_eq!(meta["dataset"]["rows"], 15);
    assert_eq!(meta["dataset"]["strain_hash"], strain_hash(a));
    assert_eq!(meta["more_datasets"][0]["path"], s(b));
    assert_eq!(meta["more_datasets"][0]["rows"], 10);
    assert_eq!(meta["more_datasets"][0]["strain_hash"], strain_hash(b));
    assert_eq!(meta["provenance"]["dataset"]["path"], s(a));
    assert_eq!(meta["provenance"]["more_datasets"][0]["path"], s(b));
    // a one-dataset model keeps its old form
    assert!(json(&a_only.join("meta.json"))
        .get("more_datasets")
        .is_none());

    // the input range is the union of both datasets' tensions
    let all: Vec<f64> = inputs(a).into_iter().chain(inputs(b)).collect();
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let range = &meta["input_range"][0];
    assert_eq!(range["parameter"], "tendons.0.tension");
    assert_eq!(range["min"].as_f64().unwrap(), lo);
    assert_eq!(range["max"].as_f64().unwrap(), hi);
    assert!(
        lo < -5.9 && hi > 2.0,
        "[{lo}, {hi}]: A reaches -6, B beyond 0"
    );

    // every sample of both is an anchor, in order: inputs as given
    let model = ReducedModel::load(&ab).unwrap();
    let anchors = model.anchors.expect("anchors");
    assert_eq!(anchors.n, 25);
    assert_eq!(anchors.inputs, all);
}

#[test]
fn training_on_two_datasets_uses_both_and_anchors_rest_for_trajectory_rows_only() {
    let (a, b) = two();
    let train = |data: &[&Path], name: &str| {
        let out = scratch(name);
        let mut args = vec!["train"];
        args.extend(data.iter().map(|p| s(p)));
        args.extend_from_slice(&[
            "--latent",
            "1",
            "--hidden-layers",
            "3",
            "--epochs",
            "5",
            "--lbfgs-iterations",
            "0",
            "--out",
            s(&out),
        ]);
        (run_ok(&args), json(&out.join("meta.json")))
    };
    let (printed, meta) = train(&[a, b], "several-train-ab");
    // 25 rows, every one trained on (training + validation), no zero-strain rows for equilibria
    assert!(printed.contains("snapshots  25 × 306"), "{printed}");
    assert_eq!(split_rows(&printed), 25, "{printed}");
    assert_eq!(meta["training"]["zero_anchor_rows"], 0);
    assert_eq!(meta["more_datasets"][0]["rows"], 10);
    let model = ReducedModel::load(&scratch_path("several-train-ab")).unwrap();
    let anchors = model.anchors.expect("anchors");
    assert_eq!(anchors.n, 25);
    let all: Vec<f64> = inputs(a).into_iter().chain(inputs(b)).collect();
    assert_eq!(anchors.inputs, all);
    assert!(
        model.meta.anchor_equilibria > 0,
        "equilibria only: the model's own equilibria"
    );

    // A, then a 0.3 s trajectory (31 rows): the trajectory brings the zero-strain rows (1 % of its
    // rows, at least 10) although the first dataset holds equilibria
    let dynamic = scratch("several-dyn");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--duration",
        "0.3",
        "--sample-rate",
        "100",
        "--babble=-6,0,0.1,0.2",
        "--out",
        s(&dynamic),
    ]);
    let (printed, meta) = train(&[a, &dynamic], "several-train-dyn");
    assert!(
        printed.contains("snapshots  46 × 306 + 10 zero-strain rows ("),
        "{printed}"
    );
    assert_eq!(split_rows(&printed), 46 + 10, "{printed}");
    assert_eq!(meta["training"]["zero_anchor_rows"], 10);
    assert_eq!(meta["more_datasets"][0]["rows"], 31);
    // with a trajectory among the datasets every anchor keeps its encoding
    assert!(
        meta.get("anchor_equilibria").is_none_or(|v| v == 0),
        "{meta}"
    );

    // 1100 equilibria and the trajectory, in either order: 1 % of the 31 trajectory rows (at least
    // 10), not 1 % of all 1131 rows (11)
    let many = sweep_dataset("several-sweep1100", "-6:0", 1100);
    for (order, name) in [
        ([&many, &dynamic], "several-1100-dyn"),
        ([&dynamic, &many], "several-dyn-1100"),
    ] {
        let (printed, meta) = train(&[order[0].as_path(), order[1].as_path()], name);
        assert_eq!(meta["training"]["zero_anchor_rows"], 10, "{name}");
        assert_eq!(split_rows(&printed), 1131 + 10, "{printed}");
    }
}

/// The scratch path `name` without clearing it (a model a test just wrote there).
fn scratch_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("gvsrom-cli-tests")
        .join(name)
}

/// The rows `train` printed it trained on: `(N training, M validation)` → N + M.
fn split_rows(printed: &str) -> usize {
    let inner = printed
        .split('(')
        .find(|p| p.contains(" training, "))
        .unwrap_or_else(|| panic!("no training split in: {printed}"));
    inner
        .split(|c: char| !c.is_ascii_digit())
        .filter(|t| !t.is_empty())
        .take(2)
        .map(|t| t.parse::<usize>().unwrap())
        .sum()
}

#[test]
fn datasets_of_other_physics_inputs_or_points_are_refused_naming_both() {
    let (a, _) = two();
    let out = scratch("several-refused");
    let stiffer = random_dataset("several-stiffer", &["--set", "material.youngs_modulus=2e6"]);
    expect_error(
        &["pod", s(a), s(&stiffer), "--modes", "2", "--out", s(&out)],
        &[
            "invalid `DATASET`",
            s(&stiffer),
            s(a),
            "material.youngs_modulus",
            "2000000",
        ],
    );
    let two_inputs = random_dataset("several-inputs", &["--random", "material.density=900:1100"]);
    expect_error(
        &["train", s(a), s(&two_inputs), "--out", s(&out)],
        &[
            "invalid `DATASET`",
            "inputs are [tendons.0.tension, material.density]",
        ],
    );
    let beam = scratch("several-beam");
    run_ok(&[
        "dataset",
        "soft-beam",
        "--random",
        "loads.distributed.0.magnitude=-1:1",
        "--samples",
        "2",
        "--out",
        s(&beam),
    ]);
    expect_error(
        &["pod", s(a), s(&beam), "--modes", "2", "--out", s(&out)],
        &["invalid `DATASET`", s(&beam), "points"],
    );
    // the same dataset twice, and ranges of an input with a gap no sample covers: A holds [-6, 0] N,
    // this one [1, 3] N; a model of both would accept 0.5 N
    expect_error(
        &["pod", s(a), s(a), "--modes", "2", "--out", s(&out)],
        &[
            "invalid `DATASET`",
            "same snapshots",
            "give each dataset once",
        ],
    );
    let beyond = scratch("several-beyond");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--random",
        "tendons.0.tension=1:3",
        "--samples",
        "5",
        "--out",
        s(&beyond),
    ]);
    expect_error(
        &["train", s(a), s(&beyond), "--out", s(&out)],
        &[
            "invalid `DATASET`",
            "tendons.0.tension",
            "without a sample",
            s(&beyond),
        ],
    );
    // nothing was written
    assert!(!out.exists());
    // and no dataset at all is a usage error of the command line
    let e = common::gvsrom(&["pod", "--modes", "2", "--out", s(&out)]);
    assert!(!e.status.success());
    assert!(String::from_utf8_lossy(&e.stderr).contains("DATASET"));
}
