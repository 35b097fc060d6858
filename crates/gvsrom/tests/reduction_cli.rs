//! The reduction commands end to end (issue 7): `gvsrom pod` and `gvsrom train` on a
//! single-tendon dataset, and their models through `statics --model [--compare]` and
//! `simulate --model`: a POD-ROM with all modes reproduces the HOM equilibrium and trajectory, a
//! trained autoencoder is repeatable and loads back identically, an AE-ROM equilibrium is within
//! 1 % strain error, and mismatched or damaged models and datasets are one-line errors.
//!
//! The datasets and models shared by several tests are built once per run of this file
//! ([`OnceLock`]).

mod common;

use common::{copy_dir, expect_error, json, npy, run_ok, s, scratch, sweep_dataset};
use gvsrom::reduced_model::ReducedModel;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Length of the single-tendon rod [m].
const L: f64 = 0.25;

fn tip(v: &serde_json::Value) -> [f64; 3] {
    let t = v.as_array().unwrap();
    std::array::from_fn(|i| t[i].as_f64().unwrap())
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// `gvsrom dataset single-tendon --sweep tendons.0.tension=LO:HI --samples N --out DIR`.
fn sweep(name: &str, lo: f64, hi: f64, samples: usize) -> PathBuf {
    sweep_dataset(name, &format!("{lo}:{hi}"), samples)
}

/// The 40-sample sweep over [-6, 3] N shared by the POD and autoencoder tests: tensions
/// `-6 + 9 k / 39`.
fn dataset40() -> &'static Path {
    static D: OnceLock<PathBuf> = OnceLock::new();
    D.get_or_init(|| sweep("red-ds40", -6.0, 3.0, 40))
}

/// The numerical rank `pod` prints (`numerical rank R`).
fn printed_rank(stdout: &str) -> usize {
    stdout
        .split("numerical rank ")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|r| r.parse().ok())
        .unwrap_or_else(|| panic!("no numerical rank in: {stdout}"))
}

/// POD of [`dataset40`] with as many modes as the data's numerical rank.
fn pod_full() -> &'static (PathBuf, usize) {
    static M: OnceLock<(PathBuf, usize)> = OnceLock::new();
    M.get_or_init(|| {
        let ds = dataset40();
        // the rank first, with one mode
        let probe = scratch("red-pod-probe");
        let out = run_ok(&["pod", s(ds), "--modes", "1", "--out", s(&probe)]);
        let rank = printed_rank(&out);
        let dir = scratch("red-pod-full");
        run_ok(&["pod", s(ds), "--modes", &rank.to_string(), "--out", s(&dir)]);
        (dir, rank)
    })
}

/// POD of [`dataset40`] with 33 modes, as many as the HOM has coordinates: the 40 snapshots span
/// the HOM's whole coefficient space (σ₃₃/σ₁ ≈ 1e-14, above round-off), so `P V` is a basis of it.
fn pod33() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| {
        let dir = scratch("red-pod-33");
        run_ok(&["pod", s(dataset40()), "--modes", "33", "--out", s(&dir)]);
        dir
    })
}

/// `statics single-tendon --tension=U [--model M --compare] --json F`.
fn statics(name: &str, tension: f64, model: Option<&Path>) -> serde_json::Value {
    let file = scratch(&format!("{name}.json"));
    let t = format!("--tension={tension}");
    let mut args = vec!["statics", "single-tendon", &t, "--json", s(&file)];
    if let Some(m) = model {
        args.extend(["--model", s(m), "--compare"]);
    }
    run_ok(&args);
    json(&file)
}

/// The trained 1-latent, 3-hidden-layer autoencoder of [`dataset40`] (30 epochs, seed 3).
fn train_small(name: &str) -> PathBuf {
    let dir = scratch(name);
    run_ok(&[
        "train",
        s(dataset40()),
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
}

fn ae_small() -> &'static Path {
    static M: OnceLock<PathBuf> = OnceLock::new();
    M.get_or_init(|| train_small("red-ae-m1"))
}

#[test]
fn a_model_records_the_strain_hash_its_dataset_manifest_records() {
    use sha2::{Digest, Sha256};
    let ds = dataset40();
    // the hash of the file's bytes, computed here, not by gvsrom
    let bytes = std::fs::read(ds.join("strain.npy")).unwrap();
    let sha: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(
        json(&ds.join("meta.json"))["gvsrom"]["sha256"]["strain.npy"],
        sha.as_str()
    );
    for model in [pod33(), ae_small()] {
        let meta = json(&model.join("meta.json"));
        assert_eq!(meta["dataset"]["strain_hash"], sha.as_str(), "{model:?}");
    }
}

#[test]
fn a_decaying_learning_rate_is_recorded_and_a_bad_factor_refused() {
    // the same run as `ae_small` with the rate decaying to 5 % over its 30 epochs
    let dir = scratch("red-ae-decay");
    #[rustfmt::skip]
    run_ok(&[
        "train", s(dataset40()), "--latent", "1", "--hidden-layers", "3", "--epochs", "30",
        "--seed", "3", "--lr-decay", "0.05", "--out", s(&dir),
    ]);
    let meta = json(&dir.join("meta.json"));
    assert_eq!(meta["training"]["lr_decay"], 0.05);
    assert!(json(&ae_small().join("meta.json"))["training"]
        .get("lr_decay")
        .is_none());
    let weights = |d: &Path| std::fs::read(d.join("weights.safetensors")).unwrap();
    assert!(
        weights(&dir) != weights(ae_small()),
        "the decay changes the training"
    );
    let refused = scratch("red-ae-decay-refused");
    for bad in ["0", "1.5", "NaN", "-0.1"] {
        let decay = format!("--lr-decay={bad}");
        #[rustfmt::skip]
        expect_error(
            &["train", s(dataset40()), "--latent", "1", "--hidden-layers", "3", "--epochs", "5",
              &decay, "--out", s(&refused)],
            &["--lr-decay", "(0, 1]"],
        );
        assert!(!refused.exists(), "a refused run writes nothing");
    }
}

#[test]
fn a_penalty_that_empties_the_network_or_a_split_that_leaves_one_row_is_refused() {
    // the audit trained at λ = 1e300 and on 1 of 200 rows ("RMSE 0 training") without a word
    let refused = scratch("red-ae-option-refused");
    for (option, value, needles) in [
        (
            "--lambda",
            "2",
            &["--lambda", "`--lambda`: 2:", "in [0, 1]"][..],
        ),
        ("--lambda", "1e300", &["--lambda", "in [0, 1]"][..]),
        (
            "--validation-fraction",
            "0.99",
            &[
                "--validation-fraction",
                "holds out 39 of the 40 rows and leaves 1",
                "at least 2",
            ][..],
        ),
    ] {
        #[rustfmt::skip]
        expect_error(
            &["train", s(dataset40()), "--latent", "1", "--hidden-layers", "3", "--epochs", "5",
              option, value, "--out", s(&refused)],
            needles,
        );
        assert!(!refused.exists(), "a refused run writes nothing");
    }
}

#[test]
fn a_pod_rom_with_all_modes_reproduces_the_hom_equilibrium() {
    let (model, rank) = pod_full();
    // sample k = 13 of the sweep: -6 + 9·13/39 = -3 N
    let tension = -3.0;
    let hom = statics("red-pod-hom", tension, None);
    let rom = statics("red-pod-rom", tension, Some(model));
    assert_eq!(rom["n_dof"], *rank);
    let c = &rom["comparison"];
    let tip_rom = tip(&rom["tip_position"]);
    let tip_hom = tip(&hom["tip_position"]);
    let err = dist(&tip_rom, &tip_hom);
    let reported = c["tip_error_percent"].as_f64().unwrap() / 100.0 * L;
    assert!(
        (reported - err).abs() <= 1e-12,
        "comparison.tip_error_percent {reported:e} m vs {err:e} m"
    );
    assert!(
        dist(&tip(&c["hom_tip_position"]), &tip_hom) <= 1e-12,
        "the comparison's HOM tip is the HOM statics' tip"
    );
    assert!(err <= 1e-8 * L, "tip error {err:e} m > 1e-8 L");
    // the tendon length error is the difference of the two reports' lengths, in mm
    let length = |r: &serde_json::Value| r["tendon_lengths"][0].as_f64().unwrap();
    let dl = 1e3 * (length(&rom) - length(&hom)).abs();
    let reported = c["tendon_length_error_mm"].as_f64().unwrap();
    assert!(
        (reported - dl).abs() <= 1e-12,
        "comparison.tendon_length_error_mm {reported:e} vs {dl:e}"
    );
    assert!(dl < 1e-5, "POD with all modes: tendon length {dl:e} mm off");
    let strain = c["strain_error_percent"].as_f64().unwrap();
    assert!(strain < 1e-6, "strain error {strain:e} %");
}

/// The paper's dynamic use (IV-C2) in small: POD modes of a babbling trajectory, a reduced model
/// run on an input it never saw (random steps of another distribution and seed, 1 s) against the
/// HOM. Measured (2026-12-07): POD-6 mean 0.020 % L, max 0.094 % L; POD-2 0.58 % and 1.6 %.
#[test]
fn a_truncated_pod_rom_follows_the_hom_on_an_input_it_was_not_trained_on() {
    let data = scratch("red-dyn-babble");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--duration",
        "3",
        "--babble=-6,0,0.05,0.2",
        "--sample-rate",
        "100",
        "--seed",
        "1",
        "--out",
        s(&data),
    ]);
    let run = |name: &str, model: Option<&Path>| -> Vec<f64> {
        let dir = scratch(name);
        let mut args = vec![
            "simulate",
            "single-tendon",
            "--duration",
            "1",
            "--steps=-5,-0.5,0.1",
            "--seed",
            "7",
            "--out",
            s(&dir),
        ];
        if let Some(m) = model {
            args.extend(["--model", s(m)]);
        }
        run_ok(&args);
        npy(&dir.join("tip_position.npy")).1
    };
    let hom = run("red-dyn-hom", None);
    // mean and largest tip distance to the HOM over the run, in units of L
    let errors = |k: usize| -> (f64, f64) {
        let model = scratch(&format!("red-dyn-pod{k}"));
        run_ok(&[
            "pod",
            s(&data),
            "--modes",
            &k.to_string(),
            "--out",
            s(&model),
        ]);
        let rom = run(&format!("red-dyn-rom{k}"), Some(&model));
        assert_eq!(rom.len(), hom.len());
        let d: Vec<f64> = (hom.chunks_exact(3).zip(rom.chunks_exact(3)))
            .map(|(h, r)| dist(h, r) / L)
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        (mean, d.iter().copied().fold(0.0, f64::max))
    };
    let (mean6, max6) = errors(6);
    let (mean2, _) = errors(2);
    eprintln!(
        "unseen steps: POD-6 tip error mean {mean6:e} L, max {max6:e} L; POD-2 mean {mean2:e} L"
    );
    assert!(
        mean6 < 5e-4 && max6 < 2e-3,
        "POD-6: mean {mean6:e} L, max {max6:e} L"
    );
    // the modes carry the accuracy: two of them leave ten times the error
    assert!(
        mean2 > 10.0 * mean6,
        "POD-2 mean {mean2:e} L vs POD-6 {mean6:e} L"
    );
    // the tip travels far more than the error allowed
    let travel = (hom.chunks_exact(3))
        .map(|h| dist(h, &hom[..3]))
        .fold(0.0, f64::max);
    assert!(travel > 0.1 * L, "the tip moves ({travel:e} m)");
}

/// With K = 33 = the HOM's coordinates the POD-ROM is the HOM in other coordinates. (With K = 26,
/// the statics data's numerical rank, the trajectory differs by 5.5e-6 L: the dynamic transient
/// leaves the span of the static snapshots.)
#[test]
fn a_pod_rom_trajectory_follows_the_hom() {
    let model = pod33();
    let run = |name: &str, model: Option<&Path>| -> (PathBuf, Vec<usize>, Vec<f64>) {
        let dir = scratch(name);
        // the release from straight under -3 N: the first 0.05 s hold the fast transient (about
        // 3000 steps at these tolerances; later steps are long, so a longer run adds little)
        let mut args = vec![
            "simulate",
            "single-tendon",
            "--duration",
            "0.05",
            "--sample-rate",
            "400",
            "--tension=-3",
            "--rtol",
            "1e-6",
            "--atol",
            "1e-9",
            "--out",
            s(&dir),
        ];
        if let Some(m) = model {
            args.extend(["--model", s(m)]);
        }
        run_ok(&args);
        let (shape, tips) = npy(&dir.join("tip_position.npy"));
        (dir, shape, tips)
    };
    let (dir_h, shape_h, hom) = run("red-sim-hom", None);
    let (dir_r, shape_r, rom) = run("red-sim-rom", Some(model));
    assert_eq!(shape_h, [21, 3]);
    assert_eq!(shape_r, shape_h);
    // Both runs keep the local error per step below rtol·|y| + atol (1e-6 relative); the HOM
    // alone, run at rtol 1e-6 and 1e-7, moves its tip by 5e-9 L over this transient, and the
    // POD-33 run agrees with it to 4e-9 L. 1e-7 L leaves 20× for other step sequences, while a
    // missing direction (K = 26) shows as 5e-6 L.
    let mut worst = 0.0f64;
    for (k, (h, r)) in hom.chunks_exact(3).zip(rom.chunks_exact(3)).enumerate() {
        let d = dist(h, r);
        worst = worst.max(d);
        assert!(
            d <= 1e-7 * L,
            "sample {k}: tip differs by {d:e} m ({:e} L)",
            d / L
        );
    }
    let travel = dist(&hom[..3], &hom[hom.len() - 3..]);
    assert!(travel > 1e-3 * L, "the tip moves ({travel:e} m)");
    eprintln!(
        "POD-33 vs HOM trajectory: max tip difference {:e} L",
        worst / L
    );
    // `gvsrom compare` measures the same: its largest tip error (printed in % of L to 3 decimals)
    // rounds to zero, and it names both runs
    let report = run_ok(&["compare", s(&dir_h), s(&dir_r)]);
    assert!(report.contains("compared   21 samples"), "{report}");
    assert!(
        report.contains("tip error  mean 0.000 %, max 0.000 %"),
        "{report}"
    );
    assert!(
        report.contains("33 DOF") && (report.contains("faster") || report.contains("slower")),
        "{report}"
    );
    assert!(report.contains("strain     error mean 0.000 %"), "{report}");
    // and the tendon's length, which both runs record, agrees to well below 0.1 µm
    assert!(
        report.contains("tendons    length error mean 0.0000 mm, max 0.0000 mm"),
        "{report}"
    );
    // the other way round with another sample rate is refused
    let coarse = scratch("red-sim-hom-coarse");
    run_ok(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.05",
        "--sample-rate",
        "200",
        "--tension=-3",
        "--out",
        s(&coarse),
    ]);
    expect_error(
        &["compare", s(&dir_h), s(&coarse)],
        &["RUN", "--sample-rate"],
    );
}

#[test]
fn an_autoencoder_model_is_repeatable_and_loads_back_identically() {
    let m1 = ae_small();
    let m2 = train_small("red-ae-m2");
    let w1 = std::fs::read(m1.join("weights.safetensors")).unwrap();
    let w2 = std::fs::read(m2.join("weights.safetensors")).unwrap();
    assert!(
        w1 == w2,
        "weights.safetensors differ between two seeded runs"
    );
    let strip = |v: &mut serde_json::Value| {
        v["training"]
            .as_object_mut()
            .unwrap()
            .remove("wall_time_s")
            .expect("training.wall_time_s");
        // how each run was made: its own command line (output path) and start time
        v.as_object_mut()
            .unwrap()
            .remove("provenance")
            .expect("provenance");
        // the hash of the metadata covers the wall time
        v["gvsrom"].as_object_mut().unwrap().remove("meta_sha256");
    };
    let (mut j1, mut j2) = (json(&m1.join("meta.json")), json(&m2.join("meta.json")));
    strip(&mut j1);
    strip(&mut j2);
    assert_eq!(j1, j2, "meta.json apart from the wall time");
    assert_eq!(j1["kind"], "autoencoder");
    assert_eq!(
        j1["training"]["encoder_sizes"],
        serde_json::json!([306, 153, 1])
    );
    for curve in ["train_loss.npy", "val_loss.npy"] {
        assert_eq!(
            std::fs::read(m1.join(curve)).unwrap(),
            std::fs::read(m2.join(curve)).unwrap(),
            "{curve}"
        );
    }
    let mut a = ReducedModel::load(m1).unwrap();
    let mut b = ReducedModel::load(&m2).unwrap();
    let t1 = a.meta.training.as_mut().unwrap();
    let t2 = b.meta.training.as_mut().unwrap();
    assert!(t1.wall_time_s > 0.0 && t2.wall_time_s > 0.0);
    t1.wall_time_s = 0.0;
    t2.wall_time_s = 0.0;
    assert!(a.meta.provenance.is_some() && b.meta.provenance.is_some());
    a.meta.provenance = None;
    b.meta.provenance = None;
    // each records the directory it was loaded from, by its manifest's hashes (of meta.json, which
    // holds the provenance, and of the weights, which are the same)
    let (o1, o2) = (a.origin().unwrap(), b.origin().unwrap());
    // and meta.json as it was verified (which differs in the provenance) beside its files
    assert_eq!(
        a.dir.as_ref().unwrap().meta_json,
        json(&m1.join("meta.json"))
    );
    (a.dir, b.dir) = (None, None);
    assert_eq!(o1.sha256, o2.sha256);
    let recorded = &json(&m1.join("meta.json"))["gvsrom"];
    assert_eq!(
        serde_json::to_value(&o1.sha256).unwrap(),
        recorded["sha256"]
    );
    assert_eq!(o1.meta_sha256.as_deref(), recorded["meta_sha256"].as_str());
    assert_ne!(o1.meta_sha256, o2.meta_sha256);
    assert_eq!(a, b);
    // loading is exact: the tensors are the file's bytes
    let again = ReducedModel::load(m1).unwrap();
    assert_eq!(again.weights, a.weights);
    assert_eq!(again.anchors, a.anchors);
}

#[test]
fn statics_at_a_training_tension_starts_on_the_reduced_models_own_equilibrium() {
    for (m, name) in [(ae_small(), "ae"), (pod_full().0.as_path(), "pod")] {
        // every anchor of a tension sweep is solved when the model is made
        let meta = json(&m.join("meta.json"));
        assert_eq!(meta["anchor_equilibria"], 40, "{name}: {meta}");
        // −3 N = −6 + 9·13/39 is a training tension: the guess is its anchor, already in equilibrium
        let at = statics(&format!("red-anchor-at-{name}"), -3.0, Some(m));
        assert_eq!(at["iterations"], 0, "{name}: {at}");
        let model = ReducedModel::load(m).unwrap();
        let a = model.anchors.as_ref().unwrap();
        let k = a
            .inputs
            .iter()
            .position(|&x| x == -3.0)
            .expect("anchor at -3 N");
        let r = model.meta.latent;
        let q: Vec<f64> = at["q"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        // (the JSON text round-trip may move the last bit)
        for (v, w) in q.iter().zip(&a.latent[k * r..(k + 1) * r]) {
            assert!((v - w).abs() <= 1e-15 * w.abs(), "{name}: {q:?}");
        }
    }
}

#[test]
fn a_load_input_anchor_is_the_reduced_models_equilibrium_too() {
    // soft-beam: the distributed load's magnitude swept over −5, −4, …, 5 N·m/m
    let ds = scratch("red-beam-ds");
    run_ok(&[
        "dataset",
        "soft-beam",
        "--sweep",
        "loads.distributed.0.magnitude=-5:5",
        "--samples",
        "11",
        "--out",
        s(&ds),
    ]);
    let pod = scratch("red-beam-pod");
    let out = run_ok(&["pod", s(&ds), "--modes", "2", "--out", s(&pod)]);
    assert!(out.contains("anchors    11 of 11"), "{out}");
    assert_eq!(json(&pod.join("meta.json"))["anchor_equilibria"], 11);
    let file = scratch("red-beam-statics.json");
    run_ok(&[
        "statics",
        "soft-beam",
        "--set",
        "loads.distributed.0.magnitude=2",
        "--model",
        s(&pod),
        "--json",
        s(&file),
    ]);
    let at = json(&file);
    assert_eq!(at["iterations"], 0, "{at}");
}

#[test]
fn a_model_from_another_scenario_is_refused_naming_the_layout() {
    let (model, _) = pod_full();
    for model in [model.as_path(), ae_small()] {
        let msg = expect_error(
            &["statics", "six-tendon", "--model", s(model)],
            &["--model", "single-tendon", "points ×", "bend_y"],
        );
        assert!(msg.contains(s(model)), "{msg}");
        expect_error(
            &[
                "simulate",
                "six-tendon",
                "--duration",
                "0.1",
                "--model",
                s(model),
            ],
            &["--model", "points ×"],
        );
    }
    // the same scenario with another basis (more DOF) is refused as well
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.basis.order=6",
            "--model",
            s(&pod_full().0),
        ],
        &["--model", "DOF"],
    );
}

#[test]
fn a_reduced_trajectory_leaving_the_training_region_stops_with_the_reason() {
    // The small autoencoder with its recorded training range narrowed to ±1e-3 about the
    // straight rod's encoding: a release from straight under -3 N leaves it within milliseconds.
    let dir = copy_dir(ae_small(), "red-ae-narrow");
    let mut meta = json(&dir.join("meta.json"));
    let rest = meta["rest"][0].as_f64().unwrap();
    meta["latent_range"] = serde_json::json!([[rest - 1e-3, rest + 1e-3]]);
    std::fs::write(
        dir.join("meta.json"),
        serde_json::to_string_pretty(&meta).unwrap(),
    )
    .unwrap();
    common::reseal::reseal(&dir);
    let release = [
        "simulate",
        "single-tendon",
        "--duration",
        "0.5",
        "--tension=-3",
        "--model",
    ];
    let out = scratch("red-sim-narrow");
    let args = [&release[..], &[s(&dir), "--out", s(&out)]].concat();
    let msg = expect_error(
        &args,
        &[
            "left the training region at t = ",
            "q_r[0] = ",
            "marked partial",
        ],
    );
    // the samples before it are kept, and the run is marked partial
    let (shape, _) = npy(&out.join("t.npy"));
    assert!(shape[0] >= 1 && shape[0] < 51, "{shape:?}: {msg}");
    let meta = json(&out.join("meta.json"));
    assert_eq!(meta["complete"], false, "{msg}");
    // the integrator's work up to the stop is counted
    assert!(meta["steps"].as_u64().is_some_and(|n| n > 0), "{meta}");
    assert!(
        meta["error"]
            .as_str()
            .is_some_and(|e| e.contains("left the training region")),
        "{meta}"
    );
    assert_eq!(
        meta["reason"], "the reduced model left its training region",
        "{meta}"
    );
    // the full range lets the same run finish
    run_ok(&[&release[..], &[s(ae_small())]].concat());
}

#[test]
fn a_reduced_start_off_the_straight_rod_is_reported() {
    // The single-tendon data all sag under gravity: the autoencoder's rest decodes to a bent rod,
    // POD's `q_r = 0` is the straight rod, and a start at equilibrium is shared by both models.
    let run = |model: &Path, extra: &[&str]| {
        let args = [
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "0.05",
                "--model",
                s(model),
            ][..],
            extra,
        ]
        .concat();
        run_ok(&args)
    };
    let note = "start      the reduced model's rest coordinates decode to max |ξ − ξ*| = ";
    assert!(run(ae_small(), &[]).contains(note));
    assert!(!run(ae_small(), &["--from-equilibrium"]).contains(note));
    assert!(!run(pod33(), &[]).contains(note));
}

#[test]
fn a_start_at_equilibrium_is_the_equilibrium_statics_finds_with_the_same_model() {
    // `simulate --from-equilibrium --model` starts where `statics --model` solves (from the
    // model's anchors, checked against its training), not at a root the engine's ramp from the
    // decoder's rest may reach
    for (model, u) in [(ae_small(), "-5"), (ae_small(), "-1"), (pod33(), "-5")] {
        let json_out = scratch("red-feq-statics").join("eq.json");
        std::fs::create_dir_all(json_out.parent().unwrap()).unwrap();
        let tension = format!("--tension={u}");
        run_ok(&[
            "statics",
            "single-tendon",
            &tension,
            "--model",
            s(model),
            "--json",
            s(&json_out),
        ]);
        let eq = tip(&json(&json_out)["tip_position"]);
        let out = scratch("red-feq-sim");
        run_ok(&[
            "simulate",
            "single-tendon",
            "--duration",
            "0.01",
            "--from-equilibrium",
            &tension,
            "--model",
            s(model),
            "--out",
            s(&out),
        ]);
        let (_, tips) = npy(&out.join("tip_position.npy"));
        assert!(
            dist(&tips[..3], &eq) < 1e-9 * L,
            "{model:?} at {u} N: {:?} against {eq:?}",
            &tips[..3]
        );
    }
    // the start's tensions are the model's input too: outside its training they are refused,
    // with an input signal as without
    for extra in [&[][..], &["--steps=-1,0,0.005"]] {
        let args = [
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "0.01",
                "--from-equilibrium",
                "--tension=-8",
                "--model",
                s(pod33()),
            ][..],
            extra,
        ]
        .concat();
        expect_error(
            &args,
            &[
                "--model",
                "tendons.0.tension = -8 lies outside the training inputs",
            ],
        );
    }
}

/// A copy of `model` whose `weights.safetensors` lacks the tensor `drop`.
fn without_tensor(model: &Path, name: &str, drop: &str) -> PathBuf {
    use safetensors::tensor::{SafeTensors, TensorView};
    let dir = copy_dir(model, name);
    let bytes = std::fs::read(dir.join("weights.safetensors")).unwrap();
    let st = SafeTensors::deserialize(&bytes).unwrap();
    let kept: Vec<(String, TensorView<'_>)> = st
        .tensors()
        .into_iter()
        .filter(|(n, _)| n != drop)
        .collect();
    assert_eq!(
        kept.len() + 1,
        st.len(),
        "`{drop}` is a tensor of the model"
    );
    let out = safetensors::serialize(kept, None).unwrap();
    std::fs::write(dir.join("weights.safetensors"), out).unwrap();
    dir
}

#[test]
fn a_damaged_model_or_dataset_is_an_error_not_a_wrong_model() {
    let (pod, _) = pod_full();
    let ae = ae_small();
    let use_model = |m: &Path, needles: &[&str]| {
        expect_error(
            &["statics", "single-tendon", "--tension=-3", "--model", s(m)],
            needles,
        )
    };
    // Every damage below is refused first by the content hashes (shown for the truncation); the
    // hashes are then re-recorded, as a writer with a bug would, so that the loader's own checks
    // of what it reads are exercised too.
    use common::reseal::reseal;
    for (model, tag) in [(pod.as_path(), "pod"), (ae, "ae")] {
        // a truncated weights file
        let dir = copy_dir(model, &format!("red-bad-{tag}-trunc"));
        let w = dir.join("weights.safetensors");
        let bytes = std::fs::read(&w).unwrap();
        std::fs::write(&w, &bytes[..bytes.len() / 2]).unwrap();
        use_model(
            &dir,
            &["weights.safetensors", "differs from the hash", s(&dir)],
        );
        reseal(&dir);
        use_model(&dir, &["weights.safetensors", "damaged", s(&dir)]);
        // the weights file deleted
        std::fs::remove_file(&w).unwrap();
        use_model(&dir, &["weights.safetensors", "missing"]);
        // an unknown kind in meta.json
        let dir = copy_dir(model, &format!("red-bad-{tag}-kind"));
        let m = dir.join("meta.json");
        let mut meta = json(&m);
        meta["kind"] = "pca".into();
        std::fs::write(&m, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
        use_model(&dir, &["meta.json was edited"]);
        reseal(&dir);
        use_model(&dir, &["meta.json", "unknown kind \"pca\""]);
        // POD ↔ autoencoder swapped: the tensors the kind needs are missing
        let dir = copy_dir(model, &format!("red-bad-{tag}-swap"));
        let m = dir.join("meta.json");
        let mut meta = json(&m);
        meta["kind"] = if tag == "pod" { "autoencoder" } else { "pod" }.into();
        std::fs::write(&m, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
        reseal(&dir);
        use_model(&dir, &[s(&dir)]);
        // meta.json missing
        let dir = copy_dir(model, &format!("red-bad-{tag}-nometa"));
        std::fs::remove_file(dir.join("meta.json")).unwrap();
        use_model(&dir, &["meta.json"]);
    }
    // one tensor removed from an otherwise valid weights file
    let dir = without_tensor(pod, "red-bad-pod-tensor", "modes");
    reseal(&dir);
    use_model(&dir, &["weights.safetensors", "tensor `modes` is missing"]);
    let dir = without_tensor(ae, "red-bad-ae-tensor", "decoder.1.weight");
    reseal(&dir);
    use_model(
        &dir,
        &[
            "weights.safetensors",
            "tensor `decoder.1.weight` is missing",
        ],
    );
    // a tensor of the wrong shape: meta.json claims 2 latent coordinates for 1-column modes
    let dir = copy_dir(pod, "red-bad-pod-shape");
    let m = dir.join("meta.json");
    let mut meta = json(&m);
    meta["latent"] = (meta["latent"].as_u64().unwrap() + 1).into();
    meta["rest"].as_array_mut().unwrap().push(0.0.into());
    std::fs::write(&m, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
    reseal(&dir);
    use_model(
        &dir,
        &["weights.safetensors", "tensor `modes`", "expected F64"],
    );

    // a dataset with a truncated strain.npy
    let ds = copy_dir(dataset40(), "red-bad-ds-trunc");
    let f = ds.join("strain.npy");
    let bytes = std::fs::read(&f).unwrap();
    std::fs::write(&f, &bytes[..bytes.len() - 100]).unwrap();
    let out = scratch("red-bad-ds-trunc-pod");
    expect_error(
        &["pod", s(&ds), "--modes", "2", "--out", s(&out)],
        &["strain.npy", "truncated"],
    );
    assert!(!out.exists(), "no model is left behind");
    expect_error(
        &["train", s(&ds), "--epochs", "1", "--out", s(&out)],
        &["strain.npy", "truncated"],
    );
    assert!(!out.exists(), "no model is left behind");
    std::fs::remove_file(&f).unwrap();
    expect_error(
        &["pod", s(&ds), "--modes", "2", "--out", s(&out)],
        &["strain.npy", "missing"],
    );

    // a latent size larger than the model it reduces (and than the data)
    let out = scratch("red-bad-latent");
    expect_error(
        &["train", s(dataset40()), "--latent", "400", "--out", s(&out)],
        &["--latent", "400", "more than the 33 DOF"],
    );
    assert!(!out.exists(), "no model is left behind");
    // modes out of range
    for (k, needles) in [
        ("0", &["--modes", "0: an integer in [1, 33]"][..]),
        ("1000", &["--modes", "1000", "more than the 33 DOF"][..]),
    ] {
        let out = scratch(&format!("red-bad-modes-{k}"));
        expect_error(
            &["pod", s(dataset40()), "--modes", k, "--out", s(&out)],
            needles,
        );
        assert!(!out.exists(), "no model is left behind");
    }
}

#[test]
fn pod_bounds_its_modes_by_the_dof_and_the_snapshots_and_warns_past_the_numerical_rank() {
    // five snapshots bound the modes below the 33 DOF; the accepted range is the one checked
    let few = sweep("red-few", -6.0, 3.0, 5);
    let out = scratch("red-few-pod");
    expect_error(
        &["pod", s(&few), "--modes", "6", "--out", s(&out)],
        &["--modes", "6: an integer in [1, 5]", "5 snapshots"],
    );
    expect_error(
        &["train", s(dataset40()), "--latent", "0", "--out", s(&out)],
        &["--latent", "0: an integer in [1, 33]"],
    );
    assert!(!out.exists());
    // modes past the numerical rank are kept, with a warning naming them
    let (stdout, stderr) =
        common::run_ok_with_stderr(&["pod", s(dataset40()), "--modes", "33", "--out", s(&out)]);
    let rank = printed_rank(&stdout);
    assert!(rank < 33, "{stdout}");
    assert!(
        stderr.contains(&format!(
            "warning: --modes 33 exceeds the data's numerical rank {rank}: modes {}–33",
            rank + 1
        )),
        "{stderr}"
    );
    let (_, stderr) = common::run_ok_with_stderr(&[
        "pod",
        s(dataset40()),
        "--modes",
        &rank.to_string(),
        "--out",
        s(&out),
        "--force",
    ]);
    assert!(!stderr.contains("numerical rank"), "{stderr}");
}

/// `train DATASET --latent 1 --hidden-layers H --epochs E --out DIR` (seed 0); returns the model.
fn train(dataset: &Path, name: &str, hidden: usize, epochs: usize) -> PathBuf {
    let dir = scratch(name);
    run_ok(&[
        "train",
        s(dataset),
        "--latent",
        "1",
        "--hidden-layers",
        &hidden.to_string(),
        "--epochs",
        &epochs.to_string(),
        "--out",
        s(&dir),
    ]);
    dir
}

/// The AE-ROM's strain error (%) at `tension` against the HOM, from `statics --compare`.
fn ae_strain_error(model: &Path, name: &str, tension: f64) -> (f64, f64) {
    let rom = statics(name, tension, Some(model));
    let c = &rom["comparison"];
    assert_eq!(rom["n_dof"], 1);
    (
        c["strain_error_percent"].as_f64().unwrap(),
        c["tip_error_percent"].as_f64().unwrap(),
    )
}

/// 200 tensions and the default epochs (early stopping ends near 340 + 55 fine-tuning): about 15 s
/// in the dev profile on 2 busy cores.
const AE_SAMPLES: usize = 200;
const AE_EPOCHS: usize = 1000;

#[test]
fn an_ae_rom_equilibrium_is_within_one_percent_strain_error() {
    // at tensions midway between the sweep's samples, none of them a snapshot of the training
    let t0 = Instant::now();
    let ds = sweep("red-ds-ae", -6.0, 3.0, AE_SAMPLES);
    let model = train(&ds, "red-ae7", 7, AE_EPOCHS);
    let step = 9.0 / (AE_SAMPLES - 1) as f64;
    for k in [10, 72, 140, 190] {
        let tension = -6.0 + (k as f64 + 0.5) * step;
        let (strain, tip) = ae_strain_error(&model, &format!("red-ae7-rom-{k}"), tension);
        eprintln!(
            "AE-7 ({AE_SAMPLES} samples, {AE_EPOCHS} epochs) at {tension:.4} N: strain {strain:.4} %, tip {tip:.4} % L, {:.1} s",
            t0.elapsed().as_secs_f64()
        );
        assert!(strain < 1.0, "strain error {strain} % at {tension} N");
    }
}

#[test]
fn interrupted_training_keeps_the_best_weights() {
    let dir = scratch("red-ae-interrupted");
    let out = common::interrupted(
        &[
            "train",
            s(dataset40()),
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
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(
        err.contains("training interrupted") && err.contains(s(&dir)),
        "{err}"
    );
    let model = ReducedModel::load(&dir).unwrap();
    let t = model.meta.training.as_ref().unwrap();
    assert!(t.epochs_run >= 1 && t.epochs_run < 1_000_000, "{t:?}");
    assert!(t.best_epoch <= t.epochs_run, "{t:?}");
    assert!(t.stop.contains("Interrupt"), "stop reason {}", t.stop);
    let (shape, curve) = npy(&dir.join("train_loss.npy"));
    assert_eq!(shape, [t.epochs_run]);
    assert!(curve.iter().all(|v| v.is_finite()));
    // the saved model runs
    let (strain, _) = ae_strain_error(&dir, "red-ae-interrupted-rom", -3.0);
    assert!(strain.is_finite());
}

#[test]
fn all_zero_snapshots_give_no_pod_and_no_relative_error() {
    // a dataset whose snapshots are all zero (no gravity, no tension): a POD of it is refused
    // (it was written, "capturing 1.00000000 of the energy", 0/0 read as 1), and a model's
    // reconstruction of it has no relative error, rather than "inf %"
    let zero = scratch("red-zero-ds");
    let _ = std::fs::remove_dir_all(&zero);
    run_ok(&[
        "dataset",
        "single-tendon",
        "--set",
        "loads.gravity=[0,0,0]",
        "--sweep",
        "tendons.0.tension=0:0",
        "--samples",
        "2",
        "--out",
        s(&zero),
    ]);
    let pod = scratch("red-zero-pod");
    let _ = std::fs::remove_dir_all(&pod);
    expect_error(
        &["pod", s(&zero), "--modes", "1", "--out", s(&pod)],
        &["all 2 snapshots are zero: there is no strain to reduce"],
    );
    assert!(!pod.exists());
    let out = run_ok(&["reconstruct", s(ae_small()), s(&zero)]);
    assert!(
        out.contains("relative   none: every snapshot is zero (‖X‖ = 0)") && !out.contains("inf"),
        "{out}"
    );
}

#[test]
fn a_one_snapshot_pod_is_plotted_without_its_empty_energy_panel() {
    let ds = sweep("red-one-ds", -2.0, -2.0, 1);
    let pod = scratch("red-one-pod");
    let _ = std::fs::remove_dir_all(&pod);
    run_ok(&["pod", s(&ds), "--modes", "1", "--out", s(&pod)]);
    let figs = scratch("red-one-figs");
    let _ = std::fs::remove_dir_all(&figs);
    let out = run_ok(&["plot", s(&pod), "--out", s(&figs)]);
    assert!(figs.join("pod_spectrum.png").exists(), "{out}");
    assert!(
        out.contains("the first mode holds all the snapshot energy"),
        "{out}"
    );
}

/// Snapshots of one input value (`-1:-1`) do not differ: `train` refuses them naming the dataset,
/// before anything is written, where a model trained on them was unstable in statics and failed
/// in motion at once.
#[test]
fn train_refuses_snapshots_that_do_not_differ() {
    let ds = sweep_dataset("constant-sweep", "-1:-1", 3);
    let out = scratch("constant-model");
    expect_error(
        &["train", s(&ds), "--epochs", "5", "--out", s(&out)],
        &[
            "DATASET",
            "constant-sweep",
            "the 3 usable snapshots do not differ",
            "--sweep",
        ],
    );
    assert!(!out.exists());
}
