//! No output path may equal or contain an input path of the same command: with `--force`, such an
//! output would replace the command's own input. Each case must fail naming the input and leave it
//! byte-identical.

mod common;

use common::{expect_error, gvsrom, run_ok, s, scratch, sweep_dataset};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Every file below `dir` (or `dir` itself if it is a file) with its bytes, sorted by path.
fn snapshot(path: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = vec![];
    if path.is_dir() {
        for e in fs::read_dir(path).unwrap() {
            out.extend(snapshot(&e.unwrap().path()));
        }
    } else {
        out.push((path.to_path_buf(), fs::read(path).unwrap()));
    }
    out.sort();
    out
}

/// A fresh directory holding the single-tendon preset as `scen.toml`.
fn with_scenario(name: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    fs::create_dir_all(&dir).unwrap();
    let out = gvsrom(&["show", "single-tendon"]);
    assert!(out.status.success());
    let scen = dir.join("scen.toml");
    fs::write(&scen, &out.stdout).unwrap();
    (dir, scen)
}

/// A reduced model (POD, 1 mode, of a 3-sample sweep), made once.
fn model() -> &'static Path {
    static M: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    M.get_or_init(|| {
        let ds = sweep_dataset("overlap-ds", "-3:0", 3);
        let m = scratch("overlap-model");
        run_ok(&["pod", s(&ds), "--modes", "1", "--out", s(&m)]);
        m
    })
}

#[test]
fn simulate_out_naming_its_scenario_file_is_refused_naming_the_input() {
    let (_dir, scen) = with_scenario("overlap-sim-scen");
    let before = snapshot(&scen);
    expect_error(
        &[
            "simulate",
            s(&scen),
            "--duration",
            "0.01",
            "--out",
            s(&scen),
            "--force",
        ],
        &["--out", "is the input SCENARIO", "scen.toml"],
    );
    assert_eq!(snapshot(&scen), before);
}

#[test]
fn simulate_out_naming_its_model_is_refused_and_the_model_kept() {
    let m = model();
    let before = snapshot(m);
    // the model is a gvsrom output holding only its own files: --force alone would replace it
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.01",
            "--model",
            s(m),
            "--out",
            s(m),
            "--force",
        ],
        &["--out", "is the input --model"],
    );
    assert_eq!(snapshot(m), before);
    // another spelling of the same directory
    let spelled = m.parent().unwrap().join(".").join(m.file_name().unwrap());
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.01",
            "--model",
            s(m),
            "--out",
            s(&spelled),
            "--force",
        ],
        &["is the input --model"],
    );
    assert_eq!(snapshot(m), before);
}

#[test]
fn simulate_out_containing_its_input_csv_is_refused() {
    let (dir, _scen) = with_scenario("overlap-sim-csv");
    let csv = dir.join("u.csv");
    fs::write(&csv, "0,-1\n").unwrap();
    let before = snapshot(&dir);
    for option in ["--input", "--load-schedule"] {
        expect_error(
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "0.01",
                option,
                s(&csv),
                "--out",
                s(&dir),
                "--force",
            ],
            &["--out", &format!("contains the input {option}")],
        );
    }
    assert_eq!(snapshot(&dir), before);
}

#[test]
fn statics_and_modes_json_naming_an_input_are_refused() {
    let (_dir, scen) = with_scenario("overlap-json");
    let before = snapshot(&scen);
    for cmd in ["statics", "modes"] {
        expect_error(
            &[cmd, s(&scen), "--json", s(&scen), "--force"],
            &["--json", "is the input SCENARIO"],
        );
        assert_eq!(snapshot(&scen), before);
        let m = model();
        let model_before = snapshot(m);
        expect_error(
            &[
                cmd,
                "single-tendon",
                "--model",
                s(m),
                "--json",
                s(m),
                "--force",
            ],
            &["--json", "is the input --model"],
        );
        // a file inside the model (its meta.json): refused as lying inside the input
        expect_error(
            &[
                cmd,
                "single-tendon",
                "--model",
                s(m),
                "--json",
                s(&m.join("meta.json")),
                "--force",
            ],
            &["--json", "lies inside the input --model"],
        );
        assert_eq!(snapshot(m), model_before);
    }
}

#[test]
fn dataset_out_naming_its_scenario_file_or_input_is_refused() {
    let (dir, scen) = with_scenario("overlap-dataset");
    let before = snapshot(&scen);
    expect_error(
        &[
            "dataset",
            s(&scen),
            "--sweep",
            "tendons.0.tension=-3:0",
            "--samples",
            "3",
            "--out",
            s(&scen),
            "--force",
        ],
        &["--out", "is the input SCENARIO"],
    );
    let csv = dir.join("u.csv");
    fs::write(&csv, "0,-1\n").unwrap();
    let before_csv = snapshot(&dir);
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--duration",
            "0.01",
            "--input",
            s(&csv),
            "--out",
            s(&dir),
            "--force",
        ],
        &["--out", "contains the input --input"],
    );
    assert_eq!(snapshot(&scen), before);
    assert_eq!(snapshot(&dir), before_csv);
}

#[test]
fn a_preset_name_is_not_an_input_path() {
    // `single-tendon` names the preset (presets are resolved first), so an output of that name in
    // the current directory is a new path, not the scenario
    let dir = scratch("overlap-preset");
    fs::create_dir_all(&dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_gvsrom"))
        .args(["statics", "single-tendon", "--json", "single-tendon"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("single-tendon").is_file());
}

#[test]
fn pod_and_train_out_naming_their_inputs_are_refused_and_the_inputs_kept() {
    let ds = sweep_dataset("overlap-train-ds", "-6:3", 10);
    let ae = scratch("overlap-train-ae");
    let small = [
        "--hidden-layers",
        "3",
        "--epochs",
        "5",
        "--lbfgs-iterations",
        "0",
    ];
    let mut args = vec!["train", s(&ds), "--out", s(&ae)];
    args.extend_from_slice(&small);
    run_ok(&args);
    let (before_ds, before_ae) = (snapshot(&ds), snapshot(&ae));
    expect_error(
        &["pod", s(&ds), "--modes", "1", "--out", s(&ds), "--force"],
        &["--out", "is the input DATASET"],
    );
    let mut args = vec!["train", s(&ds), "--out", s(&ds), "--force"];
    args.extend_from_slice(&small);
    expect_error(&args, &["--out", "is the input DATASET"]);
    // a continuation written over its own start model
    let mut args = vec![
        "train",
        s(&ds),
        "--init",
        s(&ae),
        "--out",
        s(&ae),
        "--force",
    ];
    args.extend_from_slice(&["--epochs", "5", "--lbfgs-iterations", "0"]);
    expect_error(&args, &["--out", "is the input --init"]);
    assert_eq!(snapshot(&ds), before_ds);
    assert_eq!(snapshot(&ae), before_ae);
}

#[test]
fn an_output_inside_an_input_directory_is_refused_and_the_input_stays_usable() {
    // a figures directory or a model written into the model (or dataset) it was made from would be
    // an entry that directory's manifest does not list: the input would then be refused as damaged
    let m = model();
    let before = snapshot(m);
    let inside = m.join("figs");
    expect_error(
        &["plot", s(m), "--out", s(&inside)],
        &[
            "--out",
            "lies inside the input INPUT",
            "choose a path beside it",
        ],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--tension=-3",
            "--model",
            s(m),
            "--json",
            s(&m.join("eq.json")),
        ],
        &["--json", "lies inside the input --model"],
    );
    assert_eq!(snapshot(m), before);
    // still a usable model
    run_ok(&["statics", "single-tendon", "--tension=-3", "--model", s(m)]);
}
