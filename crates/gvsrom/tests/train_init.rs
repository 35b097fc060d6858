//! `gvsrom train --init MODEL`: a training that starts from a model's weights continues its fit,
//! keeps its architecture, decoder, loss, seed and split, records where it started, and refuses a
//! start that does not fit (a POD model, another architecture or loss, a dataset of another layout
//! or physics, an output in its place) or that it cannot improve on.

mod common;

use common::{
    expect_error, json, run_ok, run_ok_with_stderr, s, scratch, sweep_dataset, with_stderr_gone,
};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// 20 single-tendon equilibria at tensions in [-6, 3] N.
fn dataset() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| sweep_dataset("init-ds20", "-6:3", 20))
}

/// `args` of a short `train` (3 hidden layers, 30 Adam epochs, no L-BFGS, seed 1) into `out`.
fn train(out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "train",
        s(dataset()),
        "--epochs",
        "30",
        "--lbfgs-iterations",
        "0",
        "--patience",
        "0",
        "--seed",
        "1",
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    run_ok(&args)
}

/// A 1-coordinate autoencoder of [`dataset`] after 30 epochs, physical loss.
fn first() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("init-first");
        train(&dir, &["--hidden-layers", "3", "--loss", "physical"]);
        dir
    })
}

fn training(model: &Path) -> serde_json::Value {
    json(&model.join("meta.json"))["training"].clone()
}

/// The arguments of a 3-epoch continuation of [`first`] on [`dataset`] into `out`, no L-BFGS.
fn continuation(out: &Path, extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = [
        "train",
        s(dataset()),
        "--init",
        s(first()),
        "--epochs",
        "3",
        "--lbfgs-iterations",
        "0",
        "--out",
        s(out),
    ]
    .map(String::from)
    .to_vec();
    v.extend(extra.iter().map(|e| e.to_string()));
    v
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn a_training_from_a_model_continues_its_fit_and_records_its_start() {
    let next = scratch("init-next");
    // no --latent, --hidden-layers or --loss: the model's
    train(&next, &["--init", s(first())]);
    let (a, b) = (training(first()), training(&next));
    assert_eq!(b["hidden_layers"], 3);
    assert_eq!(b["loss"], "physical");
    assert_eq!(b["encoder_sizes"], a["encoder_sizes"]);
    let (la, lb) = (
        a["final_train_loss"].as_f64().unwrap(),
        b["final_train_loss"].as_f64().unwrap(),
    );
    // the same seed from random weights would repeat the first model's 30 epochs exactly
    assert!(lb < 0.8 * la, "30 + 30 epochs: loss {lb}, after 30: {la}");
    let start = &json(&next.join("meta.json"))["provenance"]["model"];
    assert_eq!(start["path"], s(first()));
    let manifest = &json(&first().join("meta.json"))["gvsrom"];
    assert_eq!(start["meta_sha256"], manifest["meta_sha256"]);
}

#[test]
fn a_start_that_does_not_fit_is_refused_by_name() {
    let out = scratch("init-refused");
    let base = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = ["train", s(dataset()), "--epochs", "5", "--out", s(&out)]
            .map(String::from)
            .to_vec();
        v.extend(extra.iter().map(|e| e.to_string()));
        v
    };
    let refused = |extra: &[&str], needles: &[&str]| {
        let args = base(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_error(&args, needles);
        assert!(!out.exists(), "a refused training wrote a model");
    };
    let m = s(first());
    refused(
        &["--init", m, "--latent", "2"],
        &["--latent", "2, but the start model", "has 1"],
    );
    refused(
        &["--init", m, "--hidden-layers", "5"],
        &["--hidden-layers", "5", "has 3"],
    );
    refused(
        &["--init", m, "--loss", "energy"],
        &["--loss", "energy", "has physical"],
    );
    refused(
        &["--init", m, "--decoder", "scaled"],
        &["--decoder", "scaled", "has plain"],
    );

    let pod = scratch("init-pod");
    run_ok(&["pod", s(dataset()), "--modes", "2", "--out", s(&pod)]);
    refused(&["--init", s(&pod)], &["--init", "is a POD model"]);
    refused(&["--init", s(&scratch("init-missing"))], &["init-missing"]);

    // a dataset of another scenario: the model's points and basis are not its
    let beam = scratch("init-beam");
    run_ok(&[
        "dataset",
        "soft-beam",
        "--sweep",
        "loads.distributed.0.magnitude=1:2",
        "--samples",
        "3",
        "--out",
        s(&beam),
    ]);
    let args = [
        "train",
        s(&beam),
        "--init",
        m,
        "--epochs",
        "5",
        "--out",
        s(&out),
    ];
    let e = expect_error(&args, &["--init", "was learned on", "single-tendon"]);
    // another discretization altogether: a few of its points, not all 148 (5.9 kB of them)
    assert!(
        e.contains(" in all)") && e.len() < 700,
        "{} bytes: {e}",
        e.len()
    );
    assert!(!out.exists());
}

#[test]
fn a_start_trained_on_other_physics_is_refused_naming_the_field() {
    // the same points, basis and inputs, a stiffer material
    let stiff = scratch("init-stiff-ds");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-6:3",
        "--samples",
        "5",
        "--set",
        "material.youngs_modulus=8e6",
        "--out",
        s(&stiff),
    ]);
    let out = scratch("init-stiff");
    expect_error(
        &[
            "train",
            s(&stiff),
            "--init",
            s(first()),
            "--epochs",
            "5",
            "--out",
            s(&out),
        ],
        &[
            "--init",
            "other physics",
            "material.youngs_modulus",
            "8000000",
        ],
    );
    assert!(!out.exists(), "a refused training wrote a model");
}

#[test]
fn a_continuation_keeps_the_start_models_seed_and_split_unless_told_otherwise() {
    let run = |out: &Path, extra: &[&str]| run_ok_with_stderr(&strs(&continuation(out, extra))).1;
    let kept = scratch("init-kept-split");
    let stderr = run(&kept, &[]);
    assert_eq!(
        training(&kept)["seed"],
        1,
        "the start's seed (1), not the default 0"
    );
    assert_eq!(training(&kept)["validation_fraction"], 0.1);
    assert!(!stderr.contains("optimistic"), "{stderr}");
    let other = scratch("init-other-split");
    let stderr = run(&other, &["--seed", "5"]);
    assert_eq!(training(&other)["seed"], 5);
    assert!(
        stderr.contains("--seed 1") && stderr.contains("optimistic"),
        "{stderr}"
    );
}

/// A warning is best effort too: the one of another seed than the start's, written to a stderr
/// whose reader is gone, does not abort the training (before: `eprintln!` panicked, and the
/// panic's own message to stderr aborted the process, SIGABRT, no model).
#[test]
fn a_warning_to_a_stderr_whose_reader_is_gone_does_not_stop_the_training() {
    let out = scratch("init-warning-stderr-gone");
    let args = continuation(&out, &["--seed", "5"]);
    let o = with_stderr_gone(common::command().args(&args));
    assert!(o.status.success(), "{:?}", o.status);
    assert_eq!(training(&out)["seed"], 5, "the model was written");
}

#[test]
fn a_start_the_training_cannot_improve_on_is_reported_naming_it() {
    // a rate so small that no step changes a weight: the start's loss is never beaten
    let out = scratch("init-no-gain");
    expect_error(
        &strs(&continuation(&out, &["--learning-rate", "1e-300"])),
        &["--init", "was not improved on", "not beaten in 3 epochs"],
    );
    assert!(!out.exists(), "nothing is written");
    // with an L-BFGS fine-tune, that polishes the start's own weights, which Adam left unbeaten
    let polished = scratch("init-no-gain-polished");
    let mut args = continuation(&polished, &["--learning-rate", "1e-300"]);
    let at = args.iter().position(|a| a == "--lbfgs-iterations").unwrap();
    args[at + 1] = "20".into();
    run_ok(&strs(&args));
    let (start, more) = (training(first()), training(&polished));
    assert!(
        more["final_train_loss"].as_f64().unwrap() < start["final_train_loss"].as_f64().unwrap(),
        "{start} → {more}"
    );
}

/// Progress lines are best effort: a stderr whose reader went away must not stop the training.
#[test]
fn a_training_whose_stderr_is_closed_still_finishes() {
    let out = scratch("init-closed-stderr");
    let mut cmd = common::command();
    cmd.args([
        "train",
        s(dataset()),
        "--hidden-layers",
        "3",
        "--epochs",
        "100",
        "--patience",
        "0",
        "--out",
        s(&out),
    ])
    .env("GVSROM_PROGRESS_SECONDS", "0");
    let o = with_stderr_gone(&mut cmd);
    assert!(
        o.status.success(),
        "{:?}: {}",
        o.status,
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(out.join("meta.json").exists());
}

/// Outside a terminal (a log, a batch job) a long training says how far it is in plain lines,
/// at most one per `GVSROM_PROGRESS_SECONDS` (default 30 s: none in a run this short).
#[test]
fn a_training_in_the_background_logs_its_progress_in_plain_lines() {
    let run = |period: Option<&str>| {
        let out = scratch(&format!("init-progress-{}", period.unwrap_or("default")));
        let mut cmd = common::command();
        cmd.args([
            "train",
            s(dataset()),
            "--hidden-layers",
            "3",
            "--epochs",
            "150",
            "--patience",
            "0",
            "--out",
            s(&out),
        ]);
        cmd.env_remove("GVSROM_PROGRESS_SECONDS");
        if let Some(p) = period {
            cmd.env("GVSROM_PROGRESS_SECONDS", p);
        }
        let o = cmd.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let stdout = String::from_utf8(o.stdout).unwrap();
        assert!(
            !stdout.lines().any(|l| l.starts_with("progress")),
            "progress on stdout: {stdout}"
        );
        String::from_utf8(o.stderr).unwrap()
    };
    let lines = run(Some("0"));
    let progress: Vec<&str> = lines
        .lines()
        .filter(|l| l.starts_with("progress"))
        .collect();
    assert!(!progress.is_empty(), "no progress line: {lines:?}");
    for l in &progress {
        assert!(l.contains(" epochs ") && l.contains("elapsed"), "{l}");
        assert!(!l.contains('\r') && !l.contains('\x1b'), "{l:?}");
    }
    assert!(
        progress.iter().any(|l| l.contains("validation")),
        "{progress:?}"
    );
    assert_eq!(run(None), "", "a short run logs nothing by default");
}
