//! A reduced model as a map between snapshots and codes (`ReducedModel::encode`, `decode`,
//! `reconstruct`), checked against what must hold independently of the code under test:
//!
//! - POD: the reconstruction is the orthogonal projection onto the modes, so `‖x̂‖² + ‖x − x̂‖² =
//!   ‖x‖²` and the residual is orthogonal to every mode (read from the stored `modes` array);
//!   `E(D(q)) = q` (orthonormal modes).
//! - Autoencoder: `D(E(x))` equals a forward pass written here from the stored weights (tanh hidden
//!   layers, linear output, `x = s ⊙ y + μ`), and its RMS error over the dataset is the training's.
//! - Codes far outside the training encodings and malformed input are refused, naming the value.

mod common;

use common::{run_ok, s, scratch, sweep_dataset};
use gvsrom::reduced_model::{CodecError, ReducedModel};
use std::path::PathBuf;
use std::sync::OnceLock;

fn data() -> &'static PathBuf {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| sweep_dataset("codec-data", "-6:3", 40))
}

fn strain(dir: &std::path::Path) -> (usize, Vec<f64>) {
    let (shape, v) = common::npy(&dir.join("strain.npy"));
    (shape[1], v)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[test]
fn pod_reconstruction_is_the_orthogonal_projection_onto_its_modes() {
    let model = scratch("codec-pod");
    run_ok(&["pod", s(data()), "--modes", "2", "--out", s(&model)]);
    let m = ReducedModel::load(&model).unwrap();
    let (n, x) = strain(data());
    assert_eq!(m.features(), n);
    let arrays = m.arrays();
    let (shape, modes) = &arrays["modes"]; // row-major n × 2
    assert_eq!(shape, &vec![n, 2]);
    let mode = |k: usize| -> Vec<f64> { (0..n).map(|i| modes[i * 2 + k]).collect() };
    let q = m.encode(&x, false).unwrap();
    let rec = m.reconstruct(&x, false).unwrap();
    for (row, (xr, rr)) in x.chunks_exact(n).zip(rec.chunks_exact(n)).enumerate() {
        let resid: Vec<f64> = xr.iter().zip(rr).map(|(a, b)| a - b).collect();
        let scale = dot(xr, xr).max(1e-300);
        let pythagoras = dot(rr, rr) + dot(&resid, &resid) - dot(xr, xr);
        assert!(
            pythagoras.abs() <= 1e-10 * scale,
            "row {row}: {pythagoras:e}"
        );
        for k in 0..2 {
            let along = dot(&resid, &mode(k));
            assert!(
                along.abs() <= 1e-10 * scale.sqrt(),
                "row {row} mode {k}: {along:e}"
            );
            assert!((q[row * 2 + k] - dot(xr, &mode(k))).abs() <= 1e-12 * scale.sqrt());
        }
    }
    // E(D(q)) = q for codes inside the range
    let back = m.encode(&m.decode(&q, false).unwrap(), false).unwrap();
    for (a, b) in q.iter().zip(&back) {
        assert!((a - b).abs() <= 1e-10 * (1.0 + a.abs()), "{a} vs {b}");
    }
}

/// `D(E(x))` of a model whose stored weights are read back here and evaluated by hand.
fn by_hand(m: &ReducedModel, x: &[f64]) -> Vec<f64> {
    let a = m.arrays();
    let layers = |prefix: &str| -> Vec<(Vec<usize>, Vec<f64>, Vec<f64>)> {
        (0..)
            .map_while(|k| {
                let (shape, w) = a.get(&format!("{prefix}.{k}.weight"))?;
                let (_, b) = &a[&format!("{prefix}.{k}.bias")];
                Some((shape.clone(), w.clone(), b.clone()))
            })
            .collect()
    };
    let forward = |layers: &[(Vec<usize>, Vec<f64>, Vec<f64>)], mut v: Vec<f64>| {
        for (l, (shape, w, b)) in layers.iter().enumerate() {
            let (rows, cols) = (shape[0], shape[1]);
            v = (0..rows)
                .map(|i| {
                    let z = dot(&w[i * cols..(i + 1) * cols], &v) + b[i];
                    if l + 1 < layers.len() {
                        z.tanh()
                    } else {
                        z
                    }
                })
                .collect();
        }
        v
    };
    let (mean, scale) = (&a["scaling.mean"].1, &a["scaling.scale"].1);
    let y: Vec<f64> = x
        .iter()
        .zip(mean.iter().zip(scale))
        .map(|(x, (mu, s))| (x - mu) / s)
        .collect();
    let z = forward(&layers("encoder"), y);
    forward(&layers("decoder"), z)
        .iter()
        .zip(mean.iter().zip(scale))
        .map(|(y, (mu, s))| s * y + mu)
        .collect()
}

#[test]
fn autoencoder_reconstruction_is_its_network_evaluated_from_the_stored_weights() {
    let model = scratch("codec-ae");
    let out = run_ok(&[
        "train",
        s(data()),
        "--latent",
        "1",
        "--hidden-layers",
        "3",
        "--epochs",
        "60",
        "--lbfgs-iterations",
        "20",
        "--validation-fraction",
        "0",
        "--out",
        s(&model),
    ]);
    let m = ReducedModel::load(&model).unwrap();
    let (n, x) = strain(data());
    let rec = m.reconstruct(&x, false).unwrap();
    let mut sq = 0.0;
    for (row, (xr, rr)) in x.chunks_exact(n).zip(rec.chunks_exact(n)).enumerate() {
        let hand = by_hand(&m, xr);
        for (i, (a, b)) in rr.iter().zip(&hand).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "row {row} [{i}]: {a} vs {b}"
            );
        }
        sq += xr
            .iter()
            .zip(rr)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>();
    }
    // the training summary's RMSE (physical units, every row trains here)
    let rmse = (sq / x.len() as f64).sqrt();
    let line = out.lines().find(|l| l.starts_with("RMSE")).unwrap();
    let reported: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(
        (rmse - reported).abs() <= 1e-3 * reported,
        "{rmse} against the training's {reported} ({line})"
    );
}

#[test]
fn codes_far_outside_the_training_encodings_and_malformed_input_are_refused() {
    let model = scratch("codec-range");
    run_ok(&["pod", s(data()), "--modes", "1", "--out", s(&model)]);
    let m = ReducedModel::load(&model).unwrap();
    let [lo, hi] = m.meta.latent_range[0];
    let far = hi + 2.0 * (hi - lo);
    let e = m.decode(&[far], false).unwrap_err();
    assert!(matches!(e, CodecError::OutsideRange(_)), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("q_r[0]") && msg.contains("extrapolate"),
        "{msg}"
    );
    assert!(m.decode(&[far], true).is_ok(), "extrapolate decodes anyway");
    assert!(m.decode(&[0.5 * (lo + hi)], false).is_ok());
    // a snapshot 100 times the data's largest encodes far outside
    let (n, x) = strain(data());
    let big: Vec<f64> = x[..n].iter().map(|v| 100.0 * v).collect();
    let e = m.encode(&big, false).unwrap_err().to_string();
    assert!(e.contains("unlike the training data"), "{e}");
    // a ragged buffer and a NaN are named
    let e = m.encode(&x[..n + 1], false).unwrap_err().to_string();
    assert!(e.contains("`strain`") && e.contains(&n.to_string()), "{e}");
    let mut nan = x[..n].to_vec();
    nan[3] = f64::NAN;
    let e = m.encode(&nan, false).unwrap_err().to_string();
    assert!(e.contains("entry 3") && e.contains("NaN"), "{e}");
    let e = m.decode(&[], false).unwrap_err().to_string();
    assert!(e.contains("`q`"), "{e}");
}

/// The value after `label` on the line of `gvsrom reconstruct`'s output that starts with it.
fn printed(out: &str, label: &str) -> f64 {
    let line = out.lines().find(|l| l.starts_with(label)).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

#[test]
fn reconstruct_cli_gives_pods_discarded_singular_values_and_counts_extrapolated_snapshots() {
    let model = scratch("codec-cli-pod");
    run_ok(&["pod", s(data()), "--modes", "2", "--out", s(&model)]);
    let out = run_ok(&["reconstruct", s(&model), s(data())]);
    // the SVD: ‖X − X̂‖²_F = Σ_{k>K} σ_k², ‖X‖²_F = Σ σ_k² (the stored singular values)
    let m = ReducedModel::load(&model).unwrap();
    let sigma = &m.arrays()["singular_values"].1;
    let (n, x) = strain(data());
    let tail: f64 = sigma[2..].iter().map(|v| v * v).sum();
    let all: f64 = sigma.iter().map(|v| v * v).sum();
    let rmse = printed(&out, "RMSE");
    let expected = (tail / x.len() as f64).sqrt();
    assert!(
        (rmse - expected).abs() <= 1e-4 * expected,
        "{rmse} vs {expected}\n{out}"
    );
    let relative = printed(&out, "relative") / 100.0;
    let expected = (tail / all).sqrt();
    assert!(
        (relative - expected).abs() <= 1e-4 * expected,
        "{relative} vs {expected}\n{out}"
    );
    assert!(
        out.contains(&format!("({} solved snapshots × {n} values)", x.len() / n)),
        "{out}"
    );
    assert!(out.contains("outside    0 of"), "{out}");
    assert!(out.contains("inputs     0 of"), "{out}");
    assert!(!out.contains("physics"), "{out}");
    // tensions beyond the training's [-6, 3] N encode outside its codes, and their inputs are
    // counted as unseen
    let wide = sweep_dataset("codec-cli-wide", "-30:-20", 5);
    let out = run_ok(&["reconstruct", s(&model), s(&wide)]);
    assert!(
        out.contains("outside    5 of 5") && out.contains("extrapolates"),
        "{out}"
    );
    assert!(
        out.contains("inputs     5 of 5 snapshots have inputs the model was not trained on"),
        "{out}"
    );
    // the training's tensions on a stiffer rod: every input seen, the physics not
    let stiff = scratch("codec-cli-stiff");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-6:3",
        "--samples",
        "3",
        "--set",
        "material.youngs_modulus=2e7",
        "--out",
        s(&stiff),
    ]);
    let out = run_ok(&["reconstruct", s(&model), s(&stiff)]);
    assert!(out.contains("inputs     0 of 3"), "{out}");
    assert!(
        out.contains("physics    differs from the model's training: material.youngs_modulus is 20000000.0 in the dataset's scenario `single-tendon`, 617000.0 in the model's"),
        "{out}"
    );
    let other_input = scratch("codec-cli-other-input");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "material.youngs_modulus=1e6:2e6",
        "--samples",
        "2",
        "--out",
        s(&other_input),
    ]);
    // a dataset of another input: each snapshot's stiffness is not the 617 kPa training held
    let out = run_ok(&["reconstruct", s(&model), s(&other_input)]);
    assert!(
        out.contains("inputs     2 of 2 snapshots have inputs the model was not trained on"),
        "{out}"
    );
    // another layout is refused, naming the dataset
    let other = scratch("codec-cli-other");
    run_ok(&[
        "dataset",
        "soft-beam",
        "--sweep",
        "loads.distributed.0.magnitude=1:2",
        "--samples",
        "2",
        "--out",
        s(&other),
    ]);
    let e = common::expect_error(
        &["reconstruct", s(&model), s(&other)],
        &["DATASET", "layout"],
    );
    assert!(
        e.contains("soft-beam") && e.contains("single-tendon"),
        "{e}"
    );
    // several datasets: each judged on its own, then the RMSE over all their values; a refusal
    // names the dataset's directory
    let out = run_ok(&["reconstruct", s(&model), s(data()), s(&wide)]);
    let rmses: Vec<f64> = out
        .lines()
        .filter(|l| l.starts_with("RMSE"))
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(rmses.len(), 2, "{out}");
    let (rows_a, rows_b) = ((x.len() / n) as f64, 5.0);
    let pooled =
        ((rmses[0].powi(2) * rows_a + rmses[1].powi(2) * rows_b) / (rows_a + rows_b)).sqrt();
    let all = out.lines().find(|l| l.starts_with("all")).expect(&out);
    let printed_all: f64 = all.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!(
        (printed_all - pooled).abs() <= 1e-3 * pooled,
        "{printed_all} vs {pooled}\n{out}"
    );
    let e = common::expect_error(
        &["reconstruct", s(&model), s(data()), s(&other)],
        &["DATASET", "layout"],
    );
    assert!(e.contains(&format!("`{}`", other.display())), "{e}");
}

#[test]
fn abscissae_match_to_rounding_only() {
    use gvsrom::reduced_model::same_abscissae;
    let a = [0.0, 0.0141, 0.3, 0.6];
    assert!(same_abscissae(&a, &a));
    assert!(same_abscissae(&a, &[0.0, 0.0141 + 1e-16, 0.3, 0.6 - 1e-16]));
    assert!(!same_abscissae(&a, &[0.0, 0.0141 + 1e-9, 0.3, 0.6]));
    assert!(!same_abscissae(&a, &a[..3]));
}
