//! `gvsrom train --rate-weight β`: the strain-rate term makes the autoencoder's tangent map carry
//! the trajectory's rates, `J_f(x) ẋ ≈ ẋ`, which a reconstruction loss alone does not ask for.
//!
//! Judged independently of the trainer: the rates are central differences of the dataset's own
//! samples computed here, and `J_f v` is a central difference of the loaded model's
//! `decode(encode(·))` along `v`. Measured: 1.30 without the term, 0.43 with β = 1 (r = 1, 3 hidden
//! layers, 400 epochs, seed 1); the test asks for at most half.

mod common;

use common::{expect_error, npy, run_ok, s, scratch, sweep_dataset};
use gvsrom::reduced_model::{ModelWeights, ReducedModel};
use std::path::Path;
use std::sync::OnceLock;

/// 4 s of single-tendon babbling under gravity at 100 Hz (401 snapshots).
fn babbling() -> &'static Path {
    static DIR: OnceLock<std::path::PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = scratch("rates-babble");
        run_ok(&[
            "dataset",
            "single-tendon",
            "--duration",
            "4",
            "--babble=-3,0,0.3,0.6",
            "--sample-rate",
            "100",
            "--seed",
            "4",
            "--out",
            s(&dir),
        ]);
        dir
    })
}

/// Trains r = 1, 3 hidden layers with rate weight `beta` (and `more` options); returns the model
/// directory.
fn train_with(name: &str, beta: &str, more: &[&str]) -> std::path::PathBuf {
    let model = scratch(name);
    let mut args = vec![
        "train",
        s(babbling()),
        "--latent",
        "1",
        "--hidden-layers",
        "3",
        "--epochs",
        "400",
        "--seed",
        "1",
        "--rate-weight",
        beta,
        "--out",
        s(&model),
    ];
    args.extend_from_slice(more);
    run_ok(&args);
    model
}

/// Trains r = 1, 3 hidden layers with rate weight `beta`; returns the model directory.
fn train(name: &str, beta: &str) -> std::path::PathBuf {
    static MODELS: OnceLock<std::sync::Mutex<Vec<(String, std::path::PathBuf)>>> = OnceLock::new();
    let models = MODELS.get_or_init(Default::default);
    let mut models = models.lock().unwrap();
    if let Some((_, m)) = models.iter().find(|(n, _)| n == name) {
        return m.clone();
    }
    let m = train_with(name, beta, &[]);
    models.push((name.to_string(), m.clone()));
    m
}

/// `‖J_f v − v‖ / ‖v‖` over the interior samples of the dataset, `v` the central difference of its
/// strain snapshots, `J_f v` that of the model's reconstruction along `v`; and the recorded β.
fn tangent_error(model: &Path) -> (f64, f64) {
    let m = ReducedModel::load(model).unwrap();
    let ModelWeights::Autoencoder(ae) = &m.weights else {
        panic!("an autoencoder model")
    };
    let (_, x) = npy(&babbling().join("strain.npy"));
    let (_, t) = npy(&babbling().join("t.npy"));
    let n = x.len() / t.len();
    let f = |y: &[f64]| ae.decode(&ae.encode(y).unwrap()).unwrap();
    let (mut miss, mut norm) = (0.0, 0.0);
    for k in 1..t.len() - 1 {
        let row = |j: usize| &x[j * n..(j + 1) * n];
        let dt = t[k + 1] - t[k - 1];
        let v: Vec<f64> = row(k + 1)
            .iter()
            .zip(row(k - 1))
            .map(|(a, b)| (a - b) / dt)
            .collect();
        let h = 1e-4;
        let along = |sign: f64| -> Vec<f64> {
            f(&row(k)
                .iter()
                .zip(&v)
                .map(|(x, v)| x + sign * h * v)
                .collect::<Vec<_>>())
        };
        let (plus, minus) = (along(1.0), along(-1.0));
        for ((p, q), v) in plus.iter().zip(&minus).zip(&v) {
            let jv = (p - q) / (2.0 * h);
            miss += (jv - v) * (jv - v);
            norm += v * v;
        }
    }
    let beta = m.meta.training.as_ref().unwrap().rate_weight.unwrap();
    ((miss / norm).sqrt(), beta)
}

#[test]
fn the_rate_term_makes_the_tangent_map_carry_the_trajectory_rates() {
    let (plain, beta0) = tangent_error(&train("rates-model-0", "0"));
    let (rated, beta1) = tangent_error(&train("rates-model-1", "1"));
    assert_eq!((beta0, beta1), (0.0, 1.0), "meta.json records β");
    eprintln!("relative tangent error: {plain:.4} without the rate term, {rated:.4} with β = 1");
    assert!(
        rated < 0.5 * plain,
        "relative tangent error with the rate term {rated:.3} against {plain:.3} without"
    );
}

#[test]
fn the_rate_weight_is_refused_where_it_has_nothing_to_fit_or_is_not_a_weight() {
    let statics = sweep_dataset("rates-static", "-3:0", 20);
    let out = scratch("rates-refused");
    let refuse = |beta: &str, needles: &[&str]| {
        let weight = format!("--rate-weight={beta}");
        #[rustfmt::skip]
        let args = [
            "train", s(&statics), "--latent", "1", "--hidden-layers", "3", "--epochs", "5",
            &weight, "--out", s(&out),
        ];
        expect_error(&args, needles);
        assert!(!out.exists(), "a refused run writes nothing");
    };
    refuse("0.1", &["--rate-weight", "static equilibria", "trajectory"]);
    refuse("-1", &["--rate-weight", "-1", "≥ 0"]);
    refuse("NaN", &["--rate-weight", "finite"]);
}

#[test]
fn a_kinetic_weight_is_recorded_changes_the_training_and_is_refused_without_a_rate_term() {
    // the norm's value is checked against q̇ᵀ M q̇ in `reduce::kinetic`, its gradient in `rom`
    let rated = train("rates-model-1", "1");
    let kinetic = train_with("rates-model-k", "1", &["--kinetic-weight", "1"]);
    let m = ReducedModel::load(&kinetic).unwrap();
    let t = m.meta.training.as_ref().unwrap();
    assert_eq!((t.rate_weight, t.kinetic_weight), (Some(1.0), Some(1.0)));
    assert_eq!(
        ReducedModel::load(&rated)
            .unwrap()
            .meta
            .training
            .unwrap()
            .kinetic_weight,
        None
    );
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(
        weights(&kinetic) != weights(&rated),
        "the norm changes the training"
    );
    let out = scratch("kinetic-refused");
    let refuse = |beta: &str, kappa: &str, needles: &[&str]| {
        let (weight, k) = (
            format!("--rate-weight={beta}"),
            format!("--kinetic-weight={kappa}"),
        );
        #[rustfmt::skip]
        let args = [
            "train", s(babbling()), "--latent", "1", "--hidden-layers", "3", "--epochs", "5",
            &weight, &k, "--out", s(&out),
        ];
        expect_error(&args, needles);
        assert!(!out.exists(), "a refused run writes nothing");
    };
    refuse("0", "1", &["--kinetic-weight", "--rate-weight"]);
    refuse("1", "-1", &["--kinetic-weight", "-1", "≥ 0"]);
    refuse("1", "NaN", &["--kinetic-weight", "finite"]);
}
