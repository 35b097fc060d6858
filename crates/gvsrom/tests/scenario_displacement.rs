//! Tendons driven by their displacement through the command line (`--displacement`, the TOML's
//! `tendons[k].displacement`): statics finds the tension, which given back as `--tension` makes
//! the same rod; slack tendons; a reduced model driven the same way; a run whose elastic thread
//! (`tendons[k].axial_stiffness`) carries the motor's displacement; and the refusals of the
//! commands that drive tendons by tension only, and of impossible displacements.

mod common;

use common::{expect_error, f64s, gvsrom, run_json, run_ok, s as path_str, scratch, sweep_dataset};

fn dist(a: &[f64], b: &[f64]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// The IV-A arm (friction 0.88, gravity) wound in by 5 mm: its tendon is 5 mm shorter than at
/// rest, and the tension found, given as `--tension`, makes the same rod.
#[test]
fn a_tendon_wound_in_is_that_much_shorter_and_its_tension_makes_the_same_rod() {
    let (stdout, j) = run_json(
        "statics",
        "drive-single",
        &["single-tendon", "--displacement", "0.005"],
    );
    assert!(
        stdout.contains("driven by displacement: wound in 5 mm"),
        "{stdout}"
    );
    assert!(stdout.contains("tensions   u = [-"), "{stdout}");
    let (rest, length) = (
        f64s(&j["tendon_rest_lengths"])[0],
        f64s(&j["tendon_lengths"])[0],
    );
    // the drive's tolerance: 1e-9 of the 0.25 m rod
    assert!(
        ((rest - length) - 0.005).abs() < 2.5e-10,
        "wound in {} m",
        rest - length
    );
    let u = f64s(&j["u"])[0];
    assert_eq!(j["drives"][0]["displacement"].as_f64(), Some(0.005));
    assert_eq!(j["drives"][0]["slack"].as_bool(), Some(false));
    assert!(j["drive_iterations"].as_u64().unwrap() >= 1);
    // the scenario as run records the drive
    let toml = j["provenance"]["scenario_toml"].as_str().unwrap();
    assert!(toml.contains("displacement = 0.005"), "{toml}");
    let tension = format!("--tension={u}");
    let (_, by_tension) = run_json("statics", "drive-single-u", &["single-tendon", &tension]);
    let (a, b) = (f64s(&j["tip_position"]), f64s(&by_tension["tip_position"]));
    assert!(dist(&a, &b) < 1e-9, "{a:?} vs {b:?}");
    assert!(
        by_tension.get("drives").is_none(),
        "a tension-driven run has no drives"
    );
}

/// The six-tendon arm with one tendon wound in and the others paid out: those whose paths
/// shorten more than they were paid out pull, the others are slack (u = 0) and say so.
#[test]
fn paid_out_tendons_go_slack_and_are_reported() {
    let (stdout, j) = run_json(
        "statics",
        "drive-six",
        &[
            "six-tendon",
            "--displacement=0.01,-0.01,0,-0.01,-0.01,-0.01",
        ],
    );
    let u = f64s(&j["u"]);
    let (rest, length) = (f64s(&j["tendon_rest_lengths"]), f64s(&j["tendon_lengths"]));
    for k in 0..6 {
        let asked = j["drives"][k]["displacement"].as_f64().unwrap();
        let wound = rest[k] - length[k];
        if j["drives"][k]["slack"].as_bool().unwrap() {
            assert_eq!(u[k], 0.0);
            assert!(
                wound > asked,
                "tendon {k}: its path fits ({wound} > {asked})"
            );
        } else {
            assert!(u[k] < 0.0, "tendon {k} pulls: {u:?}");
            assert!(
                (wound - asked).abs() < 6e-10,
                "tendon {k}: {wound} vs {asked}"
            );
        }
    }
    assert!(u.iter().filter(|&&u| u == 0.0).count() >= 1, "{u:?}");
    assert!(stdout.contains("carry no tension (slack"), "{stdout}");
    assert!(j["drive_iterations"].as_u64().is_some());
    assert!(stdout.contains("held at its rest length"), "{stdout}");
    assert!(stdout.contains("paid out 10 mm"), "{stdout}");
}

/// A POD-4 of the IV-A arm's tension sweep over `range` (13 equilibria), in `{name}-model`.
fn pod_of_sweep(name: &str, range: &str) -> std::path::PathBuf {
    let data = sweep_dataset(&format!("{name}-data"), range, 13);
    let model = scratch(&format!("{name}-model"));
    run_ok(&[
        "pod",
        path_str(&data),
        "--modes",
        "4",
        "--out",
        path_str(&model),
    ]);
    model
}

/// A POD model of the IV-A arm's tension sweep, driven by displacement: its tension and tip are
/// the full model's within the reduction's error.
#[test]
fn a_reduced_model_is_driven_by_displacement_too() {
    let model = pod_of_sweep("drive-pod", "-3:0");
    let args = ["single-tendon", "--displacement", "0.004"];
    let (_, full) = run_json("statics", "drive-pod-full", &args);
    let mut with_model = args.to_vec();
    with_model.extend(["--model", path_str(&model)]);
    let (_, reduced) = run_json("statics", "drive-pod-reduced", &with_model);
    let (uf, ur) = (f64s(&full["u"])[0], f64s(&reduced["u"])[0]);
    assert!(uf < -1.0 && uf > -3.0, "inside the sweep: {uf}");
    assert!(((ur - uf) / uf).abs() < 1e-3, "tension {ur} vs {uf}");
    let (a, b) = (f64s(&full["tip_position"]), f64s(&reduced["tip_position"]));
    assert!(dist(&a, &b) < 2.5e-4, "tip {b:?} vs {a:?} (0.1 % L)");
    // the reduced model's tendon is wound in by the same 4 mm
    let wound = f64s(&reduced["tendon_rest_lengths"])[0] - f64s(&reduced["tendon_lengths"])[0];
    assert!((wound - 0.004).abs() < 2.5e-10, "{wound}");
    // the drive given in the TOML: the tension it replaces is no training input to check, the
    // displacement no physics difference
    let (_, in_toml) = run_json(
        "statics",
        "drive-pod-toml",
        &[
            "single-tendon",
            "--set",
            "tendons.0.tension=0",
            "--set",
            "tendons.0.displacement=0.004",
            "--model",
            path_str(&model),
        ],
    );
    assert_eq!(f64s(&in_toml["u"]), f64s(&reduced["u"]));
    // the thread's stiffness is no physics the model was trained on: statics uses it (part of
    // the displacement is now stretch, so the rod bends less and pulls less)
    let mut elastic = with_model.clone();
    elastic.extend(["--set", THREAD]);
    let (_, thread) = run_json("statics", "drive-pod-thread", &elastic);
    assert!(
        f64s(&thread["u"])[0] > ur * 0.9,
        "{:?} vs {ur}",
        f64s(&thread["u"])
    );
    // in motion from the straight rod the thread first carries the whole 4 mm, −3.2 N, beyond
    // the sweep: the run stops at its first sample, naming the tension found
    let run = scratch("drive-pod-run");
    let mut run_args = vec!["simulate"];
    run_args.extend(&elastic);
    run_args.extend(["--duration", "0.1", "--out", path_str(&run)]);
    expect_error(
        &run_args,
        &[
            "at t = 0.0000 s the tensions found from the threads of the tendons driven by displacement lie outside the model's training",
            "tendons.0.tension = -3.19",
            "(found) lies outside the training inputs [-3, 0]",
            "--extrapolate",
            "the 0 samples before it were written",
        ],
    );
    // 12 mm needs about -4.4 N, outside the sweep's [-3, 0]: refused, naming the tension found
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--displacement",
            "0.012",
            "--model",
            path_str(&model),
        ],
        &[
            "was not trained for the tensions these displacements need",
            "tendons.0.tension = -4.",
            "(found) lies outside the training inputs [-3, 0]",
        ],
    );
    // with --extrapolate it answers, and its record says how: the answer is an extrapolation
    let (_, far) = run_json(
        "statics",
        "drive-pod-far",
        &[
            "single-tendon",
            "--displacement",
            "0.012",
            "--model",
            path_str(&model),
            "--extrapolate",
        ],
    );
    let noted = far["model_extrapolated"].to_string();
    assert!(
        noted.contains("the tensions the displacements need: tendons.0.tension = -4.")
            && noted.contains("(found) lies outside the training inputs [-3, 0]"),
        "{noted}"
    );
}

/// A reduced model runs a tendon driven by displacement as the full model does: the IV-A arm
/// stepped by 4 mm at 0.5 s through its thread (a held CSV), on a POD-4 of a tension sweep wide
/// enough for the step's −4.2 N, follows the full model's run within 1.5 % L and settles on its
/// tip and tension. Wound in by 12 mm, the tensions found leave the sweep: without
/// `--extrapolate` the run stops there; with it, it goes on and its record says so.
#[test]
fn a_reduced_model_runs_a_displacement_drive_and_checks_the_tensions_found() {
    let model = pod_of_sweep("drive-rom", "-5:0");
    let ramp = scratch("drive-rom-ramp.csv");
    std::fs::write(&ramp, "t,d0\n0,0\n0.5,0.004\n4,0.004\n").unwrap();
    let args = [
        "simulate",
        "single-tendon",
        "--set",
        "tendons.0.tension=0",
        "--set",
        "tendons.0.displacement=0",
        "--set",
        THREAD,
        "--input",
        path_str(&ramp),
        "--duration",
        "4",
        "--sample-rate",
        "50",
    ];
    let run = |name: &str, extra: &[&str]| {
        let out = scratch(name);
        let mut a = args.to_vec();
        a.extend(extra);
        a.extend(["--out", path_str(&out)]);
        run_ok(&a);
        let (_, tip) = common::npy(&out.join("tip_position.npy"));
        let (_, u) = common::npy(&out.join("u.npy"));
        (out, tip, u)
    };
    let (_, tip_full, u_full) = run("drive-rom-full", &[]);
    let (out, tip_rom, u_rom) = run("drive-rom-reduced", &["--model", path_str(&model)]);
    assert_eq!(tip_rom.len(), 201 * 3);
    let worst = (0..201)
        .map(|i| dist(&tip_rom[3 * i..3 * i + 3], &tip_full[3 * i..3 * i + 3]))
        .fold(0.0, f64::max);
    assert!(worst < 0.015 * 0.25, "largest tip difference {worst} m");
    assert!(
        u_full.iter().any(|&u| u < -3.5),
        "the overshoot the sweep covers"
    );
    // each run settles on its own model's statics drive: the reduced one within its reduction
    // error of the full one
    let statics = ["single-tendon", "--displacement", "0.004", "--set", THREAD];
    let (_, eq_full) = run_json("statics", "drive-rom-eq-full", &statics);
    let mut with_model = statics.to_vec();
    with_model.extend(["--model", path_str(&model)]);
    let (_, eq_rom) = run_json("statics", "drive-rom-eq-reduced", &with_model);
    for (tip, u, eq) in [(&tip_full, &u_full, &eq_full), (&tip_rom, &u_rom, &eq_rom)] {
        let target = f64s(&eq["tip_position"]);
        let end = dist(&tip[600..], &target);
        assert!(end < 1e-5 * 0.25, "settled {end} m from its statics");
        let u_eq = f64s(&eq["u"])[0];
        assert!(
            ((u[200] - u_eq) / u_eq).abs() < 1e-4,
            "u {} vs {u_eq}",
            u[200]
        );
    }
    let apart = dist(
        &f64s(&eq_rom["tip_position"]),
        &f64s(&eq_full["tip_position"]),
    );
    assert!(apart < 5e-4 * 0.25, "the POD's statics {apart} m off");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("meta.json")).unwrap()).unwrap();
    assert!(
        !meta["model_extrapolated"].to_string().contains("tension"),
        "{}",
        meta["model_extrapolated"]
    );
    // 12 mm: beyond the sweep as soon as the thread pulls past −5 N
    let far = scratch("drive-rom-far.csv");
    std::fs::write(&far, "t,d0\n0,0\n0.5,0.012\n4,0.012\n").unwrap();
    let mut refused = args.to_vec();
    refused[9] = path_str(&far);
    let stopped = scratch("drive-rom-stopped");
    let mut a = refused.clone();
    a.extend(["--model", path_str(&model), "--out", path_str(&stopped)]);
    expect_error(
        &a,
        &[
            "the tensions found from the threads of the tendons driven by displacement lie outside the model's training",
            "(found) lies outside the training inputs [-5, 0]",
            "marked partial",
        ],
    );
    let extrapolated = scratch("drive-rom-extrapolated");
    let mut a = refused.clone();
    a.extend([
        "--model",
        path_str(&model),
        "--extrapolate",
        "--out",
        path_str(&extrapolated),
    ]);
    let stdout = run_ok(&a);
    assert!(
        stdout.contains("lie outside the model's training: tendons.0.tension"),
        "{stdout}"
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(extrapolated.join("meta.json")).unwrap())
            .unwrap();
    assert!(
        (meta["model_extrapolated"].to_string())
            .contains("(found) lies outside the training inputs [-5, 0]"),
        "{}",
        meta["model_extrapolated"]
    );
}

/// `modes` about a displacement-driven equilibrium holds its taut tendons at their lengths (the
/// motors locked): one mode fewer per held tendon, each frequency between the free rod's `j`-th
/// and `(j + m)`-th at the same tensions (Rayleigh; six-tendon is frictionless), the first one
/// raised; a slack tendon is not held.
#[test]
fn modes_hold_the_taut_displacement_driven_tendons() {
    let drives = "--displacement=0.01,-0.01,0,-0.01,-0.01,-0.01";
    let (stdout, held) = run_json("modes", "drive-modes-held", &["six-tendon", drives]);
    assert!(
        stdout.contains(
            "held       by the locked motors (driven by displacement): tendons 0, 1, 2 at their length: 3 constraints"
        ),
        "{stdout}"
    );
    let held_tendons: Vec<u64> = (held["held_tendons"].as_array().unwrap().iter())
        .map(|v| v.as_u64().unwrap())
        .collect();
    assert_eq!(held_tendons, [0, 1, 2], "tendons 3–5 are slack");
    let u: Vec<String> = f64s(&held["u"]).iter().map(|u| format!("{u:e}")).collect();
    let tension = format!("--tension={}", u.join(","));
    let (_, free) = run_json("modes", "drive-modes-free", &["six-tendon", &tension]);
    let (h, f) = (
        f64s(&held["all_frequencies_hz"]),
        f64s(&free["all_frequencies_hz"]),
    );
    assert_eq!(h.len() + 3, f.len());
    for j in 0..h.len() {
        assert!(
            h[j] >= f[j] * (1.0 - 1e-9) && h[j] <= f[j + 3] * (1.0 + 1e-9),
            "mode {j}: {} Hz outside [{}, {}]",
            h[j],
            f[j],
            f[j + 3]
        );
    }
    assert!(h[0] > 1.2 * f[0], "held {} Hz vs free {} Hz", h[0], f[0]);
}

/// The commands that drive tendons by tension only refuse a displacement, naming the tendon and
/// where its tension comes from; a tension and a displacement on one tendon, a displacement of
/// the whole tendon and one beyond what the rod can take are refused too.
#[test]
fn displacements_are_refused_where_they_cannot_be_honoured() {
    {
        let cmd = vec!["dataset", "single-tendon", "--samples", "2", "--out"];
        let out = scratch(&format!("drive-refused-{}", cmd[0]));
        let mut args = cmd.clone();
        if args.last() == Some(&"--out") {
            args.push(path_str(&out));
        }
        if cmd[0] == "dataset" {
            // `dataset` sweeps scenario values; it takes no --tension or --displacement
            args.extend([
                "--set",
                "tendons.0.tension=0",
                "--set",
                "tendons.0.displacement=0.004",
            ]);
        } else {
            args.extend(["--displacement", "0.004"]);
        }
        expect_error(
            &args,
            &[
                "tendons[0].displacement",
                &format!("{} drives tendons by their tension only", cmd[0]),
                "`gvsrom statics` (Python: `Robot.statics()`) finds the tension",
            ],
        );
        assert!(!out.exists(), "{}: nothing written", cmd[0]);
    }
    let data = scratch("drive-refused-sweep");
    expect_error(
        &[
            "dataset",
            "single-tendon",
            "--sweep",
            "tendons.0.displacement=0:0.01",
            "--samples",
            "3",
            "--out",
            path_str(&data),
        ],
        &[
            "tendons.0.displacement=0:0.01",
            "dataset drives tendons by their tension only",
        ],
    );
    assert!(!data.exists());
    // a displacement reached only beyond the elastic range is refused where its tension leaves it
    // (single-tendon refuses a tension above 48.46 N: an axial strain past 1), at once
    expect_error(
        &["statics", "single-tendon", "--displacement", "0.045"],
        &[
            "tendons[0].displacement",
            "tendon 0 needs more than its tension limit |u| = 48.4591 N (beyond the rod's elastic range)",
            "reached: tendon 0 at 41.3641 mm of the 45.0000 mm asked",
        ],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "tendons.0.displacement=0.01",
        ],
        &[
            "tendons[0]",
            "both `tension` (-3 N) and `displacement` (0.01 m)",
        ],
    );
    expect_error(
        &["statics", "single-tendon", "--displacement", "0.3"],
        &["tendons[0].displacement", "0.3", "rest length"],
    );
    expect_error(
        &["statics", "single-tendon", "--displacement", "0.2"],
        &[
            "the tendons' displacements were not reached",
            "reached: tendon 0 at",
            "of the 200.0000 mm asked",
        ],
    );
    let out = gvsrom(&[
        "statics",
        "single-tendon",
        "--displacement",
        "0.001",
        "--tension",
        "-1",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("--displacement") && stderr.contains("--tension"),
        "{stderr}"
    );
}

/// The IV-A arm's thread with `EA` = 200 N (`--set tendons.0.axial_stiffness=200`).
const THREAD: &str = "tendons.0.axial_stiffness=200";

/// In dynamics a tendon driven by its displacement is an elastic thread: the IV-A arm wound in by
/// 4 mm settles, under its damping, onto the equilibrium `statics` finds for the same drive and
/// thread — tip and tension —, `u.npy` holds the tension found as the run goes (from the
/// thread stretched by the whole 4 mm at the straight start), and the record names the
/// displacement channel.
#[test]
fn a_run_driven_by_displacement_settles_on_the_statics_drive() {
    let (_, eq) = run_json(
        "statics",
        "drive-thread-statics",
        &["single-tendon", "--displacement", "0.004", "--set", THREAD],
    );
    let u_eq = f64s(&eq["u"])[0];
    let out = scratch("drive-thread-run");
    let stdout = run_ok(&[
        "simulate",
        "single-tendon",
        "--displacement",
        "0.004",
        "--set",
        THREAD,
        "--duration",
        "4",
        "--sample-rate",
        "10",
        "--out",
        path_str(&out),
    ]);
    assert!(
        stdout.contains("driven by displacement: wound in 4 mm"),
        "{stdout}"
    );
    let (_, tip) = common::npy(&out.join("tip_position.npy"));
    let last = &tip[tip.len() - 3..];
    let target = f64s(&eq["tip_position"]);
    assert!(dist(last, &target) < 1e-6 * 0.25, "{last:?} vs {target:?}");
    let (shape, u) = common::npy(&out.join("u.npy"));
    assert_eq!(shape, [41, 1]);
    // the displacement commanded, held
    let (shape, commanded) = common::npy(&out.join("displacement.npy"));
    assert_eq!(shape, [41, 1]);
    assert!(commanded.iter().all(|&d| d == 0.004), "{commanded:?}");
    assert!(
        ((u[40] - u_eq) / u_eq).abs() < 1e-4,
        "u = {} vs {u_eq}",
        u[40]
    );
    // at the straight start the path is the rest length: the thread is stretched by 4 mm,
    // u = −δ EA / ℓ_rest
    let rest = f64s(&eq["tendon_rest_lengths"])[0];
    let start = -0.004 * 200.0 / rest;
    assert!(
        ((u[0] - start) / start).abs() < 1e-9,
        "u(0) = {} vs {start}",
        u[0]
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("meta.json")).unwrap()).unwrap();
    let input = &meta["input"];
    assert_eq!(
        input["displacement_channels"],
        serde_json::json!([0]),
        "{input}"
    );
    assert_eq!(
        input["displacements"],
        serde_json::json!([0.004]),
        "{input}"
    );
    assert_eq!(input["tensions"], serde_json::json!([null]), "{input}");
    // started at the drive's equilibrium, the arm stays there, and the record has its tension
    let still = scratch("drive-thread-still");
    run_ok(&[
        "simulate",
        "single-tendon",
        "--displacement",
        "0.004",
        "--set",
        THREAD,
        "--from-equilibrium",
        "--duration",
        "0.2",
        "--out",
        path_str(&still),
    ]);
    let (_, tip) = common::npy(&still.join("tip_position.npy"));
    let last = &tip[tip.len() - 3..];
    assert!(dist(last, &target) < 1e-9, "{last:?} vs {target:?}");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(still.join("meta.json")).unwrap()).unwrap();
    let start = meta["input"]["start_tensions"][0].as_f64().unwrap();
    assert!(((start - u_eq) / u_eq).abs() < 1e-9, "{start} vs {u_eq}");
}

/// Undamped and frictionless, a tendon held at a constant displacement is a spring that does no
/// work: the run's energy, with the thread's `½ (ℓ − ℓ*)² / c` in place of a tension's `−u ℓ`,
/// keeps within 1 % of the largest kinetic energy — the spring stores about a quarter of it, so
/// a law or an energy off by the thread would show.
#[test]
fn an_undamped_run_at_a_held_displacement_keeps_its_energy() {
    let out = scratch("drive-thread-energy");
    let stdout = run_ok(&[
        "simulate",
        "single-tendon",
        "--displacement",
        "0.004",
        "--set",
        THREAD,
        "--set",
        "material.damping=0",
        "--set",
        "tendons.0.friction=0",
        "--set",
        "divisions.0.basis.order=4",
        "--set",
        "divisions.0.quadrature.gauss=20",
        "--duration",
        "0.5",
        "--rtol",
        "1e-6",
        "--atol",
        "1e-10",
        "--out",
        path_str(&out),
    ]);
    assert!(stdout.contains("energy     conservative run"), "{stdout}");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("meta.json")).unwrap()).unwrap();
    let e = &meta["energy_balance"];
    let kinetic = e["kinetic_max"].as_f64().unwrap();
    for key in ["largest_gain", "largest_loss"] {
        let v = e[key].as_f64().unwrap();
        assert!(v < 0.01 * kinetic, "{key} {v} J of {kinetic} J");
    }
    // the thread's energy at the start: the whole 4 mm stretched, ½ δ² EA / ℓ_rest
    let (_, lengths) = common::npy(&out.join("tendon_lengths.npy"));
    let rest = lengths[0]; // the straight start
    let thread = 0.5 * 0.004f64.powi(2) * 200.0 / rest;
    assert!(
        thread > 0.2 * kinetic,
        "the thread holds {thread} J of {kinetic} J"
    );
}

/// What a run cannot honour with a displacement drive is refused before anything is written,
/// naming the field: an inextensible thread, random tension steps, and an input
/// whose displacement exceeds the tendon.
#[test]
fn displacement_runs_are_refused_where_they_cannot_be_honoured() {
    let out = scratch("drive-run-refused");
    let o = path_str(&out);
    let base = [
        "simulate",
        "single-tendon",
        "--displacement",
        "0.004",
        "--duration",
        "0.1",
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            with(&["--out", o]),
            vec!["tendons[0].axial_stiffness", "missing", "EA in N"],
        ),
        (
            with(&["--set", THREAD, "--steps", "-1,0,0.1", "--out", o]),
            vec![
                "--steps",
                "tendons[0] is driven by its displacement",
                "--input",
            ],
        ),
    ];
    for (args, needles) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_error(&args, &needles);
        assert!(!out.exists(), "{args:?}: nothing written");
    }
    let csv = scratch("drive-run-too-far.csv");
    std::fs::write(&csv, "t,u0\n0,0\n0.05,0.3\n").unwrap();
    let args = with(&["--set", THREAD, "--input", path_str(&csv), "--out", o]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    expect_error(
        &args,
        &[
            "--input (tendon 0's displacement at t = 0.05 s)",
            "0.3",
            "rest length",
        ],
    );
    assert!(!out.exists());
    // a displacement the rod cannot take ends the run where its thread pulls past the rod's
    // elastic range (here at once: 20 cm of a 200 N thread is 160 N), as statics refuses it
    let far = scratch("drive-run-far");
    let args = [
        "simulate",
        "single-tendon",
        "--displacement",
        "0.2",
        "--set",
        THREAD,
    ];
    let mut args = args.to_vec();
    args.extend(["--duration", "0.5", "--out", path_str(&far)]);
    expect_error(
        &args,
        &[
            "tendons[0].displacement: at t = 0 s its thread pulls -159.9",
            "beyond the tension limit |u| = 48.4591 N",
            "the rod has not moved yet",
            "start `--from-equilibrium`",
        ],
    );
}

/// A tendon held through an elastic thread is a spring, not a constraint: `modes` keeps all 33
/// modes of the IV-A arm, lists it in `held_by_threads`, and its first frequency lies between the
/// free arm's at the same tension and the inextensible tendon's held one.
#[test]
fn modes_hold_an_elastic_thread_as_a_spring() {
    let args = ["single-tendon", "--displacement", "0.004", "--set", THREAD];
    let (stdout, thread) = run_json("modes", "drive-modes-thread", &args);
    assert!(
        stdout.contains(
            "tendon 0 through its elastic thread (axial_stiffness): spring, no constraint"
        ),
        "{stdout}"
    );
    assert_eq!(thread["held_by_threads"], serde_json::json!([0]));
    let all = f64s(&thread["all_frequencies_hz"]);
    assert_eq!(all.len(), 33);
    let u = format!("--tension={}", f64s(&thread["u"])[0]);
    let (_, free) = run_json("modes", "drive-modes-free", &["single-tendon", &u]);
    let (_, rigid) = run_json(
        "modes",
        "drive-modes-rigid",
        &["single-tendon", "--displacement", "0.004"],
    );
    let (f, r) = (
        f64s(&free["all_frequencies_hz"])[0],
        f64s(&rigid["all_frequencies_hz"])[0],
    );
    assert!(
        f < all[0] && all[0] < r,
        "free {f} < thread {} < rigid {r}",
        all[0]
    );
}

/// `linearize` about a displacement-driven equilibrium takes the motor's displacement as the
/// tendon's input through its thread: the settled tip response per millimetre wound in is the
/// difference of two `statics` drives 0.1 mm apart; without the thread's stiffness it is refused.
#[test]
fn linearize_takes_the_displacement_as_the_input_through_the_thread() {
    let (stdout, lin) = run_json(
        "linearize",
        "drive-lin",
        &["single-tendon", "--displacement", "0.004", "--set", THREAD],
    );
    assert!(stdout.contains("per mm wound in"), "{stdout}");
    assert_eq!(lin["displacement_channels"], serde_json::json!([0]));
    let gain: Vec<f64> = (0..3)
        .map(|i| lin["static_gain"][i][0].as_f64().unwrap())
        .collect();
    let tip = |d: &str| {
        let (_, j) = run_json(
            "statics",
            &format!("drive-lin-{d}"),
            &["single-tendon", "--displacement", d, "--set", THREAD],
        );
        f64s(&j["tip_position"])
    };
    let (hi, lo) = (tip("0.0041"), tip("0.0039"));
    for i in [0, 2] {
        let fd = (hi[i] - lo[i]) / 0.0002;
        assert!(
            (gain[i] - fd).abs() < 1e-3 * fd.abs().max(1.0),
            "component {i}: {} vs {fd} m/m",
            gain[i]
        );
    }
    expect_error(
        &["linearize", "single-tendon", "--displacement", "0.004"],
        &["tendons[0].axial_stiffness", "missing"],
    );
}

/// With tendons driven both ways on a reduced model, the run checks the tensions found for the
/// displacement-driven ones: a given tension outside the training is the input's (named before
/// the run, never as "found"), and under `--extrapolate` each driven tendon that leaves the
/// training is recorded, not only the first sentence.
#[test]
fn a_reduced_run_with_mixed_drives_records_each_found_tension_outside() {
    let data = scratch("drive-mixed-data");
    run_ok(&[
        "dataset",
        "six-tendon",
        "--random",
        "tendons.*.tension=-10:0",
        "--samples",
        "200",
        "--out",
        path_str(&data),
    ]);
    let model = scratch("drive-mixed-model");
    run_ok(&[
        "pod",
        path_str(&data),
        "--modes",
        "8",
        "--out",
        path_str(&model),
    ]);
    // tendon 0 given −12 N from t = 0.5 s, tendon 2 wound in by 30 mm through a thread
    let csv = scratch("drive-mixed.csv");
    std::fs::write(
        &csv,
        "t,u0,u1,u2,u3,u4,u5\n0,0,0,0,0,0,0\n0.5,-12,0,0.03,0,0,0\n2,-12,0,0.03,0,0,0\n",
    )
    .unwrap();
    let out = scratch("drive-mixed-run");
    let mut args = vec!["simulate", "six-tendon"];
    args.extend([
        "--set",
        "tendons.2.tension=0",
        "--set",
        "tendons.2.displacement=0",
        "--set",
        "tendons.2.axial_stiffness=2000",
        "--input",
        path_str(&csv),
        "--duration",
        "2",
        "--model",
        path_str(&model),
    ]);
    // without --extrapolate the given −12 N is refused before the run, as an input
    let mut refused = args.clone();
    refused.extend(["--out", path_str(&out)]);
    expect_error(
        &refused,
        &[
            "the input signal's tendons.0.tension reaches -12",
            "outside the training inputs",
        ],
    );
    assert!(!out.exists());
    args.extend(["--extrapolate", "--out", path_str(&out)]);
    run_ok(&args);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("meta.json")).unwrap()).unwrap();
    let noted = meta["model_extrapolated"].to_string();
    assert!(
        !noted.contains("tendons.0.tension = -12"),
        "given, not found: {noted}"
    );
    assert!(
        noted.contains("from the threads of the tendons driven by displacement lie outside the model's training: tendons.2.tension = -"),
        "{noted}"
    );
}
