//! `gvsrom train --decoder scaled` end to end: the model records its form and loads back with it,
//! its rest coordinates decode to the straight rod exactly, a zero load's reduced equilibrium is
//! the straight rod to the solver's tolerance, a nonzero load is solved (or, from a model too poor
//! to hold it, refused as a spurious straight rod, never returned as one), and an unknown form is
//! refused (on the command line and in a model file); dynamics from the rest, where the mass matrix
//! is singular, are refused before any step and leave no output.

mod common;

use common::{copy_dir, expect_error, gvsrom, json, run_ok, s, scratch};
use gvsrom::reduced_model::ReducedModel;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// 60 random soft-beam loads (centre in [0, 0.8] m, magnitude in [−5, 5] N·m).
fn dataset() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| {
        let ds = scratch("scaled-ds");
        run_ok(&[
            "dataset",
            "soft-beam",
            "--random",
            "loads.distributed.0.center=0:0.8",
            "--random",
            "loads.distributed.0.magnitude=-5:5",
            "--samples",
            "60",
            "--seed",
            "4",
            "--out",
            s(&ds),
        ]);
        ds
    })
}

/// A scaled-decoder AE-2 of [`dataset`], 3 hidden layers, `epochs` epochs.
fn train(name: &str, epochs: usize) -> PathBuf {
    let dir = scratch(name);
    run_ok(&[
        "train",
        s(dataset()),
        "--latent",
        "2",
        "--hidden-layers",
        "3",
        "--epochs",
        &epochs.to_string(),
        "--decoder",
        "scaled",
        "--out",
        s(&dir),
    ]);
    dir
}

/// The AE-2 of 300 epochs (RMSE about a quarter of the data's RMS: crude, but its equilibria are
/// bent states).
fn model() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| train("scaled-ae", 300))
}

/// `statics soft-beam` at `magnitude` N·m centred at `center` m, with `model` or the full model
/// (`None`), as JSON.
fn statics(name: &str, magnitude: f64, center: f64, model: Option<&Path>) -> serde_json::Value {
    let file = scratch(&format!("{name}.json"));
    let (m, c) = (
        format!("loads.distributed.0.magnitude={magnitude}"),
        format!("loads.distributed.0.center={center}"),
    );
    let mut args = vec![
        "statics",
        "soft-beam",
        "--set",
        &m,
        "--set",
        &c,
        "--json",
        s(&file),
    ];
    if let Some(model) = model {
        args.extend(["--model", s(model)]);
    }
    run_ok(&args);
    json(&file)
}

#[test]
fn a_scaled_model_records_its_form_and_its_rest_decodes_to_the_straight_rod() {
    let dir = model();
    let meta = json(&dir.join("meta.json"));
    assert_eq!(meta["training"]["decoder"], "scaled", "{meta}");
    assert_eq!(meta["rest"][0], 0.0, "{meta}");
    let m = ReducedModel::load(dir).unwrap();
    let gvsrom::reduced_model::ModelWeights::Autoencoder(ae) = &m.weights else {
        panic!("not an autoencoder")
    };
    assert_eq!(ae.form(), rom::nn::DecoderForm::Scaled);
    // the rest and any other point with z₁ = 0 decode to zero strain deviation exactly
    let z = [m.meta.rest.clone(), vec![0.0, 2.5], vec![0.0, -7.0]].concat();
    assert!(ae.decode(&z).unwrap().iter().all(|&v| v == 0.0));
    // and z₁ ≠ 0 does not
    assert!(ae.decode(&[0.5, 0.0]).unwrap().iter().any(|&v| v != 0.0));
}

#[test]
fn a_scaled_model_holds_the_straight_rod_at_zero_load_and_solves_a_load() {
    let dir = model();
    // zero load: the straight rod, tip at (L, 0, 0), to the solver's tolerance (‖R‖ ≤ 1e-10 from
    // the nearest anchor leaves z₁ ~ 1e-11); a plain decoder's straight rod is off its manifold
    // (IV-B's AE-2: its closest point decodes 3 1/m of curvature away)
    let at_zero = statics("scaled-zero", 0.0, 0.4, Some(dir));
    let tip: Vec<f64> = at_zero["tip_position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let off = (tip[0] - 0.8).abs() + tip[1].abs() + tip[2].abs();
    assert!(off < 1e-9, "tip {tip:?}");
    // a load inside the training range: a bent state, the right way (a positive moment about
    // local y curls the beam towards −z), its tip moved at least half as far from the straight
    // rod's as the full model's
    let loaded = statics("scaled-load", 2.0, 0.4, Some(dir));
    let hom = statics("scaled-hom", 2.0, 0.4, None);
    let tip = |v: &serde_json::Value| -> Vec<f64> {
        (0..3)
            .map(|i| v["tip_position"][i].as_f64().unwrap())
            .collect()
    };
    let moved = |t: &[f64]| ((t[0] - 0.8).powi(2) + t[1].powi(2) + t[2].powi(2)).sqrt();
    let (rom, full) = (tip(&loaded), tip(&hom));
    assert!(
        rom[2] < 0.0 && moved(&rom) > 0.5 * moved(&full),
        "{rom:?} vs {full:?}"
    );
    assert_ne!(loaded["q"][0].as_f64().unwrap(), 0.0);
}

#[test]
fn a_spurious_straight_rod_under_load_is_refused_not_returned() {
    // 40 epochs: from its anchors the solve at 2 N·m reaches z₁ = 0, where the reduced residual
    // vanishes (c̃ ⊥ f); the straight rod is not the full model's equilibrium there. In one
    // full-load stage (solver.min_increment = 1: no continuation, no descent) that root stands
    let poor = train("scaled-ae-40", 40);
    let solve = |command: &str, solver: &[&str], needles: &[&str]| {
        let mut args = vec![
            command,
            "soft-beam",
            "--set",
            "loads.distributed.0.magnitude=2",
            "--set",
            "loads.distributed.0.center=0.4",
            "--model",
            s(&poor),
        ];
        args.extend_from_slice(solver);
        expect_error(&args, needles);
    };
    for command in ["statics", "modes"] {
        solve(
            command,
            &["--set", "solver.min_increment=1"],
            &[
                "straight rod",
                "not an equilibrium of the full model",
                "spurious",
            ],
        );
        // with the default solver that root diverges, and the reduced model released from it
        // settles on a stable root of its own far outside its training data: refused as well
        solve(
            command,
            &[],
            &[
                "outside the range of the training data",
                "spurious",
                "the model is poor here",
            ],
        );
    }
}

#[test]
fn dynamics_from_a_scaled_models_rest_are_refused_before_any_step() {
    // at z₁ = 0 every z₂ decodes to the straight rod: ∂ξ/∂z₂ = 0 and M is singular
    let out = scratch("scaled-sim");
    expect_error(
        &[
            "simulate",
            "soft-beam",
            "--model",
            s(model()),
            "--duration",
            "0.01",
            "--out",
            s(&out),
        ],
        &["mass matrix is singular", "z₁ = 0", "--decoder plain"],
    );
    assert!(!out.exists(), "{} written", out.display());
}

#[test]
fn an_unknown_decoder_form_is_refused_on_the_command_line_and_in_a_model_file() {
    let out = gvsrom(&[
        "train",
        "nowhere",
        "--latent",
        "2",
        "--decoder",
        "cone",
        "--out",
        s(&scratch("scaled-bad-cli")),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--decoder") && err.contains("cone") && err.contains("scaled"),
        "{err}"
    );
    // a model file naming an unknown form, resealed so that only the form is wrong
    let copy = copy_dir(model(), "scaled-bad-form");
    let path = copy.join("meta.json");
    let mut meta = json(&path);
    meta["training"]["decoder"] = "cone".into();
    std::fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    common::reseal::reseal(&copy);
    expect_error(
        &["statics", "soft-beam", "--model", s(&copy)],
        &["training.decoder", "cone", "plain", "scaled"],
    );
}
