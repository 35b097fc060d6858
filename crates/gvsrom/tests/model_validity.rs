//! Reduced models refuse what they cannot answer: failed trainings leave no model, incomplete or
//! inconsistent datasets are refused, and `--model` refuses a scenario outside what the model was
//! trained on (its inputs' ranges, its scenario's physics) unless `--extrapolate` is given.

mod common;

use common::{
    copy_dir, expect_error, gvsrom, json, run_ok, run_ok_with_stderr, s, scratch, sweep_dataset,
};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

/// 12 single-tendon equilibria at tensions in [-6, 3] N.
fn dataset12() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| sweep_dataset("val-ds12", "-6:3", 12))
}

/// POD-2 of [`dataset12`].
fn pod2() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("val-pod2");
        run_ok(&["pod", s(dataset12()), "--modes", "2", "--out", s(&dir)]);
        dir
    })
}

#[test]
fn zero_epochs_and_a_diverging_training_leave_no_model() {
    let out = scratch("val-ae-failed");
    let train = |extra: &[&str], needles: &[&str]| {
        let args = [&["train", s(dataset12()), "--out", s(&out)][..], extra].concat();
        expect_error(&args, needles);
        assert!(!out.exists(), "a failed training wrote a model");
    };
    train(
        &["--hidden-layers", "3", "--epochs", "0"],
        &["--epochs", "≥ 1"],
    );
    // the largest learning rate accepted, 10³× the default, on a deeper network: the loss explodes
    // (by epoch 3)
    train(
        &[
            "--epochs",
            "200",
            "--learning-rate",
            "1",
            "--patience",
            "0",
            "--hidden-layers",
            "7",
        ],
        &["--learning-rate", "diverged", "lower the learning rate"],
    );
    // beyond it, refused before any epoch
    train(
        &[
            "--hidden-layers",
            "3",
            "--epochs",
            "200",
            "--learning-rate",
            "1000",
        ],
        &["--learning-rate", "`--learning-rate`: 1000:", "in (0, 1]"],
    );
    // a rate too small to move any weight: the loss never falls below the initial weights'
    train(
        &[
            "--hidden-layers",
            "3",
            "--epochs",
            "3",
            "--learning-rate",
            "1e-300",
            "--lbfgs-iterations",
            "0",
        ],
        &["did not lower the loss"],
    );
}

#[test]
fn an_incomplete_dataset_is_refused_by_pod_and_train() {
    let dir = scratch("val-ds-incomplete");
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
        s(&dir),
    ]);
    assert_eq!(out.status.code(), Some(130));
    let model = scratch("val-ds-incomplete-model");
    for args in [
        vec!["pod", s(&dir), "--modes", "1", "--out", s(&model)],
        vec!["train", s(&dir), "--epochs", "2", "--out", s(&model)],
    ] {
        expect_error(&args, &["incomplete", "8 of its 12 samples", "--resume"]);
        assert!(!model.exists());
    }
}

/// The JSON output at `path` records the extrapolation `what` first in `model_extrapolated`.
fn assert_records_extrapolation(path: &std::path::Path, what: &str) {
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert!(
        doc["model_extrapolated"][0]
            .as_str()
            .is_some_and(|e| e.contains(what)),
        "{doc}"
    );
}

#[test]
fn a_model_refuses_inputs_outside_its_training_range_unless_extrapolating() {
    let m = pod2();
    // inside [-6, 3] N (and its 2 % margin): answered
    run_ok(&[
        "statics",
        "single-tendon",
        "--tension=-6.1",
        "--model",
        s(m),
    ]);
    // outside: refused, naming the input, its value and the range
    expect_error(
        &["statics", "single-tendon", "--tension=-9", "--model", s(m)],
        &[
            "--model",
            "tendons.0.tension = -9",
            "outside the training inputs [-6, 3]",
            "--extrapolate",
        ],
    );
    // on purpose: answered, with a warning naming the extrapolation, recorded in the JSON
    let json = scratch("val-extrapolated.json");
    let (stdout, stderr) = run_ok_with_stderr(&[
        "statics",
        "single-tendon",
        "--tension=-9",
        "--model",
        s(m),
        "--extrapolate",
        "--json",
        s(&json),
    ]);
    assert_records_extrapolation(&json, "tendons.0.tension = -9");
    assert!(stdout.contains("tip"), "{stdout}");
    assert!(
        stderr.contains("warning: extrapolating (--extrapolate): tendons.0.tension = -9"),
        "{stderr}"
    );
    // the same for simulate and modes
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--tension=-9",
            "--duration",
            "0.01",
            "--model",
            s(m),
        ],
        &["tendons.0.tension = -9"],
    );
    expect_error(
        &["modes", "single-tendon", "--tension=-9", "--model", s(m)],
        &["tendons.0.tension = -9"],
    );
    // modes --json records an extrapolation as statics --json does
    let json = scratch("val-extrapolated-modes.json");
    run_ok(&[
        "modes",
        "single-tendon",
        "--tension=-9",
        "--model",
        s(m),
        "--extrapolate",
        "--count",
        "1",
        "--json",
        s(&json),
    ]);
    assert_records_extrapolation(&json, "tendons.0.tension = -9");
}

#[test]
fn a_model_refuses_a_scenario_with_other_physics_naming_the_field() {
    let m = pod2();
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--tension=-3",
            "--set",
            "loads.gravity=[0,0,0]",
            "--model",
            s(m),
        ],
        &[
            "--model",
            "loads.gravity[2] differs",
            "-9.81",
            "single-tendon",
        ],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--tension=-3",
            "--set",
            "tendons.0.friction=0",
            "--model",
            s(m),
        ],
        &["tendons[0].friction differs", "0.88"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--tension=-3",
            "--set",
            "material.youngs_modulus=2e6",
            "--model",
            s(m),
        ],
        &["material.youngs_modulus differs"],
    );
    // what is not physics may change: solver settings, output, the name
    run_ok(&[
        "statics",
        "single-tendon",
        "--tension=-3",
        "--set",
        "solver.max_iterations=80",
        "--set",
        "name=renamed",
        "--set",
        "output.centerline_points=5",
        "--model",
        s(m),
    ]);
}

#[test]
fn a_model_from_an_interrupted_training_is_used_with_a_warning() {
    let dir = scratch("val-ae-interrupted");
    let out = common::interrupted(
        &[
            "train",
            s(dataset12()),
            "--hidden-layers",
            "3",
            "--epochs",
            "1000000",
            "--patience",
            "0",
            "--out",
            s(&dir),
        ],
        // a few hundred epochs of the small network
        Duration::from_millis(1500),
    );
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (_, stderr) = run_ok_with_stderr(&[
        "statics",
        "single-tendon",
        "--tension=-3",
        "--model",
        s(&dir),
    ]);
    assert!(
        stderr.contains("warning:") && stderr.contains("interrupted training"),
        "{stderr}"
    );
    // a model trained to its end carries no such warning
    let (_, stderr) = run_ok_with_stderr(&[
        "statics",
        "single-tendon",
        "--tension=-3",
        "--model",
        s(pod2()),
    ]);
    assert!(!stderr.contains("warning"), "{stderr}");
}

fn write_json(path: &Path, v: &serde_json::Value) {
    std::fs::write(path, serde_json::to_string_pretty(v).unwrap()).unwrap();
}

/// Byte offset of the data of a version-1 `.npy` file.
fn npy_data_offset(bytes: &[u8]) -> usize {
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    10 + u16::from_le_bytes([bytes[8], bytes[9]]) as usize
}

#[test]
fn edited_weights_with_their_shapes_intact_are_refused() {
    let m = copy_dir(pod2(), "val-pod2-edited");
    let w = m.join("weights.safetensors");
    let mut bytes = std::fs::read(&w).unwrap();
    // one mantissa byte of the last value: same shapes, a slightly different model
    let n = bytes.len();
    bytes[n - 3] ^= 0x01;
    std::fs::write(&w, &bytes).unwrap();
    expect_error(
        &["statics", "single-tendon", "--tension=-3", "--model", s(&m)],
        &[
            "weights.safetensors",
            "differs from the hash",
            "re-create it",
        ],
    );
}

#[test]
fn a_directory_that_holds_no_model_is_not_called_an_edited_model() {
    // nothing there, and a dataset given as a model: neither was edited
    let missing = scratch("val-no-model");
    for (dir, needle) in [
        (missing.as_path(), "meta.json: missing"),
        (dataset12(), "not a gvsrom reduced-model output"),
    ] {
        let e = expect_error(
            &[
                "statics",
                "single-tendon",
                "--tension=-3",
                "--model",
                s(dir),
            ],
            &[needle],
        );
        assert!(!e.contains("edited"), "{e}");
    }
}

#[test]
fn dataset_metadata_inconsistent_with_its_arrays_is_refused_not_a_panic() {
    let out = scratch("val-ds-inconsistent-model");
    // the component names reordered (hashes re-recorded, as by a writer with a bug)
    let ds = copy_dir(dataset12(), "val-ds-renamed");
    let mut meta = json(&ds.join("meta.json"));
    meta["components"].as_array_mut().unwrap().reverse();
    write_json(&ds.join("meta.json"), &meta);
    common::reseal::reseal(&ds);
    for cmd in [
        vec!["pod", s(&ds), "--modes", "1", "--out", s(&out)],
        vec!["train", s(&ds), "--epochs", "2", "--out", s(&out)],
    ] {
        expect_error(&cmd, &["DATASET", "meta.json is inconsistent"]);
        assert!(!out.exists());
    }
    // meta.json naming another scenario (a two-mode rod) over the single tendon's arrays
    let ds = copy_dir(dataset12(), "val-ds-other-scenario");
    let mut meta = json(&ds.join("meta.json"));
    let text = "[material]\nyoungs_modulus = 1e6\npoisson_ratio = 0.5\ndensity = 1000\n[[divisions]]\nlength = 0.5\nradius = 0.01\nbasis = { kind = \"legendre\", modes = [\"bend_y\", \"bend_z\"], order = 3 }\n";
    meta["scenario_toml"] = text.into();
    write_json(&ds.join("meta.json"), &meta);
    common::reseal::reseal(&ds);
    expect_error(
        &["pod", s(&ds), "--modes", "1", "--out", s(&out)],
        &["DATASET", "meta.json is inconsistent", "coordinates"],
    );
}

#[test]
fn a_pathological_strain_is_blamed_on_the_dataset_not_on_an_option() {
    let ds = copy_dir(dataset12(), "val-ds-huge");
    let f = ds.join("strain.npy");
    let mut bytes = std::fs::read(&f).unwrap();
    let at = npy_data_offset(&bytes) + 8 * 5;
    bytes[at..at + 8].copy_from_slice(&1e300f64.to_le_bytes());
    std::fs::write(&f, &bytes).unwrap();
    common::reseal::reseal(&ds);
    let out = scratch("val-ds-huge-model");
    let msg = expect_error(
        &["pod", s(&ds), "--modes", "1", "--out", s(&out)],
        &["DATASET", "sample 0", "1e300", "corrupt sample"],
    );
    assert!(!msg.contains("--modes"), "{msg}");
    assert!(!out.exists());
}

/// The 1-latent, 3-hidden-layer autoencoder of [`dataset12`] (30 epochs).
fn ae1() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("val-ae1");
        run_ok(&[
            "train",
            s(dataset12()),
            "--latent",
            "1",
            "--hidden-layers",
            "3",
            "--epochs",
            "30",
            "--seed",
            "3",
            "--out",
            s(&dir),
        ]);
        dir
    })
}

#[test]
fn a_solution_off_the_learned_manifold_names_its_cause() {
    use safetensors::tensor::{SafeTensors, TensorView};
    // the autoencoder with its training range narrowed to ±1e-6 about its rest coordinates: every
    // loaded equilibrium lies "off the manifold", an in-range load included
    let narrowed = |name: &str, drop_anchors: bool| {
        let dir = copy_dir(ae1(), name);
        let mut meta = json(&dir.join("meta.json"));
        let rest = meta["rest"][0].as_f64().unwrap();
        meta["latent_range"] = serde_json::json!([[rest - 1e-6, rest + 1e-6]]);
        write_json(&dir.join("meta.json"), &meta);
        if drop_anchors {
            let w = dir.join("weights.safetensors");
            let bytes = std::fs::read(&w).unwrap();
            let st = SafeTensors::deserialize(&bytes).unwrap();
            let kept: Vec<(String, TensorView<'_>)> = st
                .tensors()
                .into_iter()
                .filter(|(n, _)| !n.starts_with("anchors."))
                .collect();
            assert_eq!(kept.len() + 2, st.len());
            let out = safetensors::serialize(kept, None).unwrap();
            std::fs::write(&w, out).unwrap();
        }
        common::reseal::reseal(&dir);
        dir
    };
    let statics = |m: &Path, tension: &str, extra: &[&str], needles: &[&str]| {
        let t = format!("--tension={tension}");
        let args = [
            &["statics", "single-tendon", &t, "--model", s(m)][..],
            extra,
        ]
        .concat();
        expect_error(&args, needles)
    };
    // with anchors: the inputs were in range, so the model is poor there
    let m = narrowed("val-ae1-narrow", false);
    let msg = statics(
        &m,
        "-4",
        &[],
        &["inputs lie inside the training range", "poor"],
    );
    assert!(!msg.contains("outside the dataset"), "{msg}");
    // without anchors: that is named
    let m = narrowed("val-ae1-narrow-noanchors", true);
    statics(&m, "-4", &[], &["no anchors", "re-create the model"]);
    // extrapolating on purpose: that is named
    let m = narrowed("val-ae1-narrow-x", false);
    let out = gvsrom(&[
        "statics",
        "single-tendon",
        "--tension=-9",
        "--model",
        s(&m),
        "--extrapolate",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    let last = err.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: ") && last.contains("the model is extrapolating"),
        "{err}"
    );
}

#[test]
fn a_simulation_input_signal_is_checked_against_the_training_inputs() {
    let m = pod2();
    let out = scratch("val-sim-extrapolated");
    // random steps in [-30, -20] N lie outside the training range [-6, 3] N
    let sim = |extra: &[&'static str]| -> Vec<String> {
        [
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "0.02",
                "--steps=-30,-20,0.005",
                "--model",
                s(m),
            ][..],
            extra,
        ]
        .concat()
        .iter()
        .map(|a| a.to_string())
        .collect()
    };
    let args = sim(&[]);
    expect_error(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &[
            "--model",
            "input signal's tendons.0.tension reaches",
            "[-6, 3]",
        ],
    );
    // inside: answered (the scenario's own tension, 0 N, is not what drives the run)
    run_ok(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.02",
        "--steps=-5,2,0.005",
        "--model",
        s(m),
    ]);
    // on purpose: a warning, and the record in the trajectory's meta.json
    let mut args = sim(&["--extrapolate", "--out"]);
    args.push(s(&out).to_string());
    let (_, stderr) = run_ok_with_stderr(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(stderr.contains("warning: extrapolating"), "{stderr}");
    let meta = json(&out.join("meta.json"));
    assert!(
        meta["model_extrapolated"][0]
            .as_str()
            .is_some_and(|e| e.contains("tendons.0.tension reaches")),
        "{meta}"
    );
}

#[test]
fn a_model_without_a_recorded_range_is_refused_and_one_without_hashes_warns() {
    // written before ranges were recorded: no `input_range` (hashes re-recorded)
    let m = copy_dir(pod2(), "val-pod2-norange");
    let mut meta = json(&m.join("meta.json"));
    meta.as_object_mut().unwrap().remove("input_range").unwrap();
    write_json(&m.join("meta.json"), &meta);
    common::reseal::reseal(&m);
    expect_error(
        &["statics", "single-tendon", "--tension=-3", "--model", s(&m)],
        &["records no range of training inputs", "re-create it"],
    );
    // written before hashes were recorded: used, with a warning that it could not be checked
    let m = copy_dir(pod2(), "val-pod2-nohash");
    let mut meta = json(&m.join("meta.json"));
    let manifest = meta["gvsrom"].as_object_mut().unwrap();
    manifest.shift_remove("sha256").unwrap();
    manifest.shift_remove("meta_sha256").unwrap();
    write_json(&m.join("meta.json"), &meta);
    let (_, stderr) =
        run_ok_with_stderr(&["statics", "single-tendon", "--tension=-3", "--model", s(&m)]);
    assert!(
        stderr.contains("warning:") && stderr.contains("before gvsrom recorded content hashes"),
        "{stderr}"
    );
}

#[test]
fn more_reduced_coordinates_than_the_full_models_dof_are_refused() {
    // single-tendon has 33 DOF: a 34th coordinate would make the reduced mass matrix singular
    let out = scratch("val-pod34");
    expect_error(
        &["pod", s(dataset12()), "--modes", "34", "--out", s(&out)],
        &["invalid `--modes`", "34", "33 DOF"],
    );
    assert!(!out.exists());
    expect_error(
        &["train", s(dataset12()), "--latent", "34", "--out", s(&out)],
        &["invalid `--latent`", "34", "33 DOF"],
    );
    expect_error(
        &[
            "train",
            s(dataset12()),
            "--latent",
            "1",
            "--hidden-layers",
            "1000001",
            "--out",
            s(&out),
        ],
        &["--hidden-layers", "1000001", "from 1 to 63"],
    );
    assert!(!out.exists());
}

#[test]
fn a_signal_moving_a_tension_training_held_fixed_is_refused_unless_extrapolating() {
    // trained on the stiffness, the tension held at the preset's −3 N
    let ds = scratch("val-ds-stiffness");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "material.youngs_modulus=1e5:1e6",
        "--samples",
        "3",
        "--out",
        s(&ds),
    ]);
    let m = scratch("val-pod-stiffness");
    run_ok(&["pod", s(&ds), "--modes", "2", "--out", s(&m)]);
    let run = scratch("val-run-held");
    let args = [
        "simulate",
        "single-tendon",
        "--model",
        s(&m),
        "--steps=-4,-2,0.01",
        "--duration",
        "0.03",
        "--out",
        s(&run),
    ];
    expect_error(
        &args,
        &[
            "tendons.0.tension reaches",
            "but training held it at -3",
            "--extrapolate",
        ],
    );
    // the held value itself runs, and --extrapolate runs the signal and records it
    run_ok(&[
        "simulate",
        "single-tendon",
        "--model",
        s(&m),
        "--duration",
        "0.02",
        "--out",
        s(&run),
    ]);
    let (_, stderr) = run_ok_with_stderr(&[&args[..], &["--extrapolate", "--force"]].concat());
    assert!(stderr.contains("but training held it at -3"), "{stderr}");
    let meta = json(&run.join("meta.json"));
    assert!(
        meta.to_string().contains("but training held it at -3"),
        "{meta}"
    );
    // a comparison with the full model says the run was an extrapolation
    let hom = scratch("val-run-held-hom");
    run_ok(&[
        "simulate",
        "single-tendon",
        "--steps=-4,-2,0.01",
        "--duration",
        "0.03",
        "--out",
        s(&hom),
    ]);
    let out = run_ok(&["compare", s(&hom), s(&run)]);
    assert!(
        out.contains("note       RUN used its model outside what it was trained on (--extrapolate): the input signal's tendons.0.tension reaches"),
        "{out}"
    );
    assert!(!out.contains("REFERENCE used"), "{out}");
}

#[test]
fn a_load_schedule_is_checked_against_the_loads_a_model_was_trained_under() {
    // pod2 was trained under gravity at λ = 1; a schedule up to λ = 100 is 981 m/s²
    let f = scratch("val-schedule.csv");
    std::fs::write(&f, "t,lambda\n0,1\n0.02,100\n").unwrap();
    let run = scratch("val-run-schedule");
    let args = [
        "simulate",
        "single-tendon",
        "--tension=-3",
        "--model",
        s(pod2()),
        "--load-schedule",
        s(&f),
        "--duration",
        "0.03",
        "--out",
        s(&run),
    ];
    expect_error(
        &args,
        &[
            "λ = 100 at t = 0.02 s",
            "training held them at λ = 1",
            "--extrapolate",
        ],
    );
    let (_, stderr) = run_ok_with_stderr(&[&args[..], &["--extrapolate"]].concat());
    assert!(stderr.contains("λ = 100"), "{stderr}");
    assert!(json(&run.join("meta.json")).to_string().contains("λ = 100"));
    // a schedule holding λ = 1 is the training's loads
    std::fs::write(&f, "t,lambda\n0,1\n0.02,1\n").unwrap();
    run_ok(&[&args[..], &["--force"]].concat());
}

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn a_combination_of_inputs_training_never_came_near_is_refused_though_each_is_in_range() {
    // six tensions moved together from -10 to 0 N: one line of the six-dimensional box
    let ds = scratch("val-ds-together");
    run_ok(&[
        "dataset",
        "six-tendon-no-gravity",
        "--sweep",
        "tendons.*.tension=-10:0",
        "--samples",
        "11",
        "--out",
        s(&ds),
    ]);
    let m = scratch("val-pod-together");
    run_ok(&["pod", s(&ds), "--modes", "2", "--out", s(&m)]);
    let statics = |tension: &str| {
        vec![
            "statics".to_string(),
            "six-tendon-no-gravity".into(),
            format!("--tension={tension}"),
            "--model".into(),
            s(&m).into(),
        ]
    };
    // on the line, between two samples: answered
    run_ok(&args(&statics("-4.5,-4.5,-4.5,-4.5,-4.5,-4.5")));
    // one tendon alone at -10 N: each tension lies in [-10, 0], the combination far off the line:
    // in units of the range, sqrt(0.8² + 5 × 0.2²) ≈ 0.917 from its nearest sample (all at -2 N),
    // where the samples lie sqrt(6) × 0.1 ≈ 0.245 apart, and 3 × 0.245 is accepted
    let corner = statics("-10,0,0,0,0,0");
    expect_error(
        &args(&corner),
        &[
            "--model",
            "tendons.0.tension = -10",
            "lie 0.917 from the nearest training input",
            "within 0.245 of one another and at most 0.735 is accepted",
            "never came near this combination",
            "--extrapolate",
        ],
    );
    // on purpose: answered and recorded
    let json = scratch("val-together.json");
    let mut on_purpose = corner.clone();
    on_purpose.extend(["--extrapolate".into(), "--json".into(), s(&json).into()]);
    run_ok(&args(&on_purpose));
    let doc = self::json(&json);
    assert!(
        doc["model_extrapolated"][0]
            .as_str()
            .is_some_and(|e| e.contains("never came near this combination")),
        "{doc}"
    );
    // an input signal pulling one tendon alone is refused at its farthest time
    let signal = scratch("val-together.csv");
    std::fs::write(
        &signal,
        "t,u0,u1,u2,u3,u4,u5\n0,-2,-2,-2,-2,-2,-2\n0.01,-10,0,0,0,0,0\n",
    )
    .unwrap();
    let run = scratch("val-run-together");
    expect_error(
        &[
            "simulate",
            "six-tendon-no-gravity",
            "--model",
            s(&m),
            "--input",
            s(&signal),
            "--duration",
            "0.02",
            "--out",
            s(&run),
        ],
        &[
            "at t = 0.01 s the inputs together",
            "tendons.0.tension = -10",
            "never came near this combination",
        ],
    );
}

#[test]
fn a_linear_input_signal_is_checked_between_its_knots() {
    // trained along an L: tendon 0 from -10 N to 0, then tendon 1 from 0 to -10 N
    let l = scratch("val-l.csv");
    std::fs::write(
        &l,
        "t,u0,u1,u2,u3,u4,u5\n0,-10,0,0,0,0,0\n1,0,0,0,0,0,0\n2,0,-10,0,0,0,0\n",
    )
    .unwrap();
    let ds = scratch("val-ds-l");
    run_ok(&[
        "dataset",
        "six-tendon-no-gravity",
        "--duration",
        "2",
        "--sample-rate",
        "100",
        "--input",
        s(&l),
        "--interpolate",
        "--out",
        s(&ds),
    ]);
    let m = scratch("val-pod-l");
    run_ok(&["pod", s(&ds), "--modes", "2", "--out", s(&m)]);
    // the chord from one end of the L to the other: both knots were trained on, its middle not
    let chord = scratch("val-chord.csv");
    std::fs::write(
        &chord,
        "t,u0,u1,u2,u3,u4,u5\n0,-10,0,0,0,0,0\n0.1,0,-10,0,0,0,0\n",
    )
    .unwrap();
    let args = |interpolate: bool| {
        let mut a = vec![
            "simulate",
            "six-tendon-no-gravity",
            "--model",
            s(&m),
            "--input",
            s(&chord),
            "--duration",
            "0.1",
        ];
        if interpolate {
            a.push("--interpolate");
        }
        a
    };
    expect_error(
        &args(true),
        &[
            "at t = 0.05 s the inputs together (tendons.0.tension = -5, tendons.1.tension = -5",
            "never came near this combination",
        ],
    );
    // held, the signal only takes the two trained combinations
    run_ok(&args(false));
    // a ramp past the trained -10 N that steps back at its end (a time given twice): the value
    // before the step is the ramp's end, which `u(t)` at the step's time does not give
    let step = scratch("val-ramp-step.csv");
    std::fs::write(
        &step,
        "t,u0,u1,u2,u3,u4,u5\n0,0,0,0,0,0,0\n0.1,-10.5,0,0,0,0,0\n0.1,0,0,0,0,0,0\n",
    )
    .unwrap();
    let e = expect_error(
        &[
            "simulate",
            "six-tendon-no-gravity",
            "--model",
            s(&m),
            "--input",
            s(&step),
            "--interpolate",
            "--duration",
            "0.2",
        ],
        &["tendons.0.tension reaches -10.5 at t = 0.1 s, outside the training inputs"],
    );
    assert!(!e.contains("0.0999"), "{e}");
}

#[test]
fn a_model_made_from_equilibria_only_says_so_in_motion_not_in_statics() {
    let equilibria_only = "was made from equilibria only";
    for command in [
        vec!["simulate", "single-tendon", "--duration", "0.05"],
        vec!["modes", "single-tendon", "--count", "1"],
        vec!["linearize", "single-tendon", "--count", "1"],
    ] {
        let mut args = command.clone();
        args.extend(["--model", s(pod2())]);
        let out = run_ok(&args);
        let note = out
            .lines()
            .find(|l| l.starts_with("note") && l.contains(equilibria_only))
            .unwrap_or_else(|| panic!("{command:?}: no note: {out}"));
        assert!(note.contains("gvsrom dataset --duration"), "{note}");
    }
    let out = run_ok(&["statics", "single-tendon", "--model", s(pod2())]);
    assert!(!out.contains(equilibria_only), "{out}");
    // a model that saw a motion: no note
    let motion = scratch("val-motion");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--duration",
        "0.3",
        "--steps=-6,0,0.05",
        "--out",
        s(&motion),
    ]);
    let pod = scratch("val-motion-pod2");
    run_ok(&["pod", s(&motion), "--modes", "2", "--out", s(&pod)]);
    // (its few steps leave the scenario's −3 N uncovered: extrapolated, which is noted apart)
    let out = run_ok(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.05",
        "--model",
        s(&pod),
        "--extrapolate",
    ]);
    assert!(out.contains("simulated") || out.contains("steps"), "{out}");
    assert!(!out.contains(equilibria_only), "{out}");
}

#[test]
fn a_division_material_is_physics_a_model_and_a_motion_name() {
    // a model of the rod's material is refused for a division of another, naming it
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.material={youngs_modulus=2e6}",
            "--model",
            s(pod2()),
        ],
        &["--model", "divisions[0].material differs"],
    );
    // a motion's mass check names the key that set the density: the division's own ...
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "0.01",
            "--set",
            "divisions.1.material={density=0}",
        ],
        &[
            "`divisions[1].material.density`",
            "a motion needs a rod with mass",
        ],
    );
    // ... or the rod's, which a division with a material of its own inherits
    let e = expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "0.01",
            "--set",
            "material.density=0",
            "--set",
            "divisions.0.material={youngs_modulus=2e6}",
        ],
        &["`material.density`", "a motion needs a rod with mass"],
    );
    assert!(!e.contains("divisions[0].material.density"), "{e}");
    // a damping beyond what the division's stiffness admits
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "0.01",
            "--set",
            "divisions.1.material={damping=1e10}",
        ],
        &["`divisions[1].material.damping`", "relaxation time"],
    );
}
