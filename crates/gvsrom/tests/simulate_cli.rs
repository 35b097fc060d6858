//! `gvsrom simulate` end to end: bad durations, sample rates and input files give one-line errors
//! naming the option or file line, exit code 1 and no panic; a failing integration reports the time it
//! reached and still writes the samples before it; a good run writes NumPy arrays of the right shapes.

mod common;

use common::{expect_error, gvsrom, scratch};
use std::path::Path;

/// Shape of a `.npy` file from its header.
fn npy_shape(path: &Path) -> Vec<usize> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + hl]).unwrap();
    let inside = header
        .split("'shape': (")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    inside
        .split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse().unwrap())
        .collect()
}

fn npy_values(path: &Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    let hl = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + hl..]
        .chunks(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn negative_duration_and_sample_rate_are_rejected() {
    expect_error(
        &["simulate", "six-tendon", "--duration", "-1"],
        &["--duration", "-1", "> 0"],
    );
    // a run shorter than a microsecond took no step and wrote the start alone
    expect_error(
        &["simulate", "six-tendon", "--duration", "1e-300"],
        &["--duration", "1e-300", "at least 1e-6 s"],
    );
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "1",
            "--sample-rate",
            "0",
        ],
        &["--sample-rate", "> 0"],
    );
    expect_error(
        &["simulate", "six-tendon", "--duration", "nan"],
        &["--duration", "NaN"],
    );
}

#[test]
fn input_file_with_missing_columns_or_nan_is_rejected_with_its_line() {
    let f = scratch("missing.csv");
    std::fs::write(&f, "t,u0\n0,-1\n0.5,-2,3\n").unwrap();
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "1",
            "--input",
            f.to_str().unwrap(),
        ],
        &["missing.csv:3", "3 columns, expected 2"],
    );
    let f = scratch("nan.csv");
    std::fs::write(&f, "0,-1\n0.5,nan\n").unwrap();
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "1",
            "--input",
            f.to_str().unwrap(),
        ],
        &["nan.csv:2 column 2", "finite"],
    );
    let f = scratch("order.csv");
    std::fs::write(&f, "0,-1\n0.5,-2\n0.2,-3\n").unwrap();
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "1",
            "--input",
            f.to_str().unwrap(),
        ],
        &["times[2]", "ascending"],
    );
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "1",
            "--input",
            "/nonexistent/in.csv",
        ],
        &["cannot read the input file"],
    );
}

#[test]
fn actuator_count_mismatch_is_rejected() {
    let f = scratch("two.csv");
    std::fs::write(&f, "0,-1,-2\n").unwrap();
    expect_error(
        &[
            "simulate",
            "six-tendon",
            "--duration",
            "1",
            "--input",
            f.to_str().unwrap(),
        ],
        &["two.csv:1", "3 columns, expected 7"],
    );
    expect_error(
        &["simulate", "six-tendon", "--duration", "1", "--steps=-15,0"],
        &["--steps", "3 comma-separated values"],
    );
}

#[test]
fn failed_integration_reports_time_reached_and_keeps_samples() {
    // a tension jump to −30 N at t = 0.5 s (within the rod's range) is more than a 500 ms implicit
    // step can follow, even halved 10 times (250 ms, halved, follows it since the fixed step runs
    // in second-order form)
    let f = scratch("jump.csv");
    std::fs::write(&f, "t,u\n0,0\n0.5,-30\n").unwrap();
    let out_dir = scratch("failed-run");
    let msg = expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "2",
            "--input",
            f.to_str().unwrap(),
            "--fixed-step",
            "0.5",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        &[
            "integration stopped at t = 0.5",
            "samples before it were written",
            "marked partial",
        ],
    );
    let t = npy_values(&out_dir.join("t.npy"));
    assert!(
        !t.is_empty() && *t.last().unwrap() <= 0.5 + 1e-12,
        "{msg}: samples up to {:?}",
        t.last()
    );
    assert_eq!(npy_shape(&out_dir.join("q.npy"))[0], t.len());
    let meta = std::fs::read_to_string(out_dir.join("meta.json")).unwrap();
    assert!(
        meta.contains("\"error\": \"integration stopped at t = 0.5"),
        "{meta}"
    );
    let meta: serde_json::Value = serde_json::from_str(&meta).unwrap();
    assert_eq!(meta["complete"], false);
    assert_eq!(meta["t_reached"], 0.5);
    assert_eq!(meta["samples"], t.len());
}

#[test]
fn simulation_writes_numpy_arrays_with_consistent_shapes() {
    let out_dir = scratch("babble-run");
    let out = gvsrom(&[
        "simulate",
        "six-tendon",
        "--duration",
        "0.5",
        "--babble=-15,0,0.1,0.2",
        "--seed",
        "4",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("real-time factor"), "{stdout}");
    // the summary shows the signal that drives the run, not the scenario's unused tensions
    assert!(
        stdout.contains("tendons    6, u(t) babbling in [-15, 0] N, holds of 0.1–0.2 s (seed 4)\n"),
        "{stdout}"
    );
    assert_eq!(npy_shape(&out_dir.join("t.npy")), vec![51]);
    assert_eq!(npy_shape(&out_dir.join("q.npy")), vec![51, 28]);
    assert_eq!(npy_shape(&out_dir.join("qd.npy")), vec![51, 28]);
    assert_eq!(npy_shape(&out_dir.join("u.npy")), vec![51, 6]);
    assert_eq!(npy_shape(&out_dir.join("tip_position.npy")), vec![51, 3]);
    assert_eq!(npy_shape(&out_dir.join("tip_rotation.npy")), vec![51, 3, 3]);
    assert_eq!(npy_shape(&out_dir.join("strain.npy")), vec![51, 14, 6]);
    assert_eq!(npy_shape(&out_dir.join("strain_x.npy")), vec![14]);
    assert_eq!(
        npy_shape(&out_dir.join("strain_reference.npy")),
        vec![14, 6]
    );
    // each tendon's thread at the 21 centreline abscissae clamped to its span: at rest (the first
    // sample) tendon 0 runs on the surface at angle 0 from (0, 0.02, 0) to (0.6, 0.01, 0) and
    // tendon 1, half length at 60°, ends at X = 0.3 m on the radius 0.015 m
    assert_eq!(
        npy_shape(&out_dir.join("tendon_paths.npy")),
        vec![51, 6, 21, 3]
    );
    let paths = npy_values(&out_dir.join("tendon_paths.npy"));
    let at = |tendon: usize, k: usize| &paths[3 * (tendon * 21 + k)..3 * (tendon * 21 + k) + 3];
    let (s60, c60) = 60f64.to_radians().sin_cos();
    for (got, want) in [
        (at(0, 0), [0.0, 0.02, 0.0]),
        (at(0, 20), [0.6, 0.01, 0.0]),
        (at(1, 20), [0.3, 0.015 * c60, 0.015 * s60]),
    ] {
        assert!(
            got.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-12),
            "{got:?} vs {want:?}"
        );
    }
    // each tendon's length: at rest the straight lines, √(0.6² + 0.01²) for the full tendons
    // (radius 0.02 → 0.01 m) and √(0.3² + 0.005²) for the half ones (0.02 → 0.015 m), as
    // `meta.json` records them; the babbling pulls every tendon in at some time
    assert_eq!(npy_shape(&out_dir.join("tendon_lengths.npy")), vec![51, 6]);
    let lengths = npy_values(&out_dir.join("tendon_lengths.npy"));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("meta.json")).unwrap()).unwrap();
    let (full, half) = (0.6f64.hypot(0.01), 0.3f64.hypot(0.005));
    for k in 0..6 {
        let line = if k % 2 == 0 { full } else { half };
        let rest = meta["tendon_rest_lengths"][k].as_f64().unwrap();
        assert!(
            (lengths[k] - line).abs() < 1e-14 && (rest - line).abs() < 1e-14,
            "tendon {k}: first sample {}, rest {rest}, line {line}",
            lengths[k]
        );
        let shortest = (0..51).map(|s| lengths[6 * s + k]).fold(f64::MAX, f64::min);
        assert!(
            shortest < line - 1e-4,
            "tendon {k} never pulled in: {shortest}"
        );
    }
    // babbled tensions stay in range and the same seed gives the same signal
    let u = npy_values(&out_dir.join("u.npy"));
    assert!(u.iter().all(|v| (-15.0..0.0).contains(v)));
    let again = scratch("babble-run-again");
    assert!(gvsrom(&[
        "simulate",
        "six-tendon",
        "--duration",
        "0.5",
        "--babble=-15,0,0.1,0.2",
        "--seed",
        "4",
        "--out",
        again.to_str().unwrap()
    ])
    .status
    .success());
    assert_eq!(npy_values(&again.join("u.npy")), u);
    assert_eq!(
        npy_values(&again.join("q.npy")),
        npy_values(&out_dir.join("q.npy"))
    );
    assert!(!out_dir.with_extension("partial").exists());
}

#[test]
fn load_schedule_scales_loads_over_time() {
    // gravity on the single-tendon arm ramps from 0 to full over 0.2 s
    let f = scratch("schedule.csv");
    std::fs::write(&f, "t,lambda\n0,0\n0.2,1\n").unwrap();
    let out_dir = scratch("schedule-run");
    let out = gvsrom(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.3",
        "--tension=0",
        "--load-schedule",
        f.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // gravity is scaled by λ(0) = 0: the arm starts straight and has not moved at t = 0.01 s much
    let tip = npy_values(&out_dir.join("tip_position.npy"));
    assert!(
        tip[2].abs() < 1e-12 && tip[5].abs() < 1e-4,
        "tip z at 0 and 0.01 s: {} {}",
        tip[2],
        tip[5]
    );
    assert!(
        tip[3 * 30 + 2] < -0.05,
        "gravity acts by t = 0.3 s: z = {}",
        tip[3 * 30 + 2]
    );
    let bad = scratch("schedule-bad.csv");
    std::fs::write(&bad, "0,1,2\n").unwrap();
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.3",
            "--load-schedule",
            bad.to_str().unwrap(),
        ],
        &["schedule-bad.csv:1", "3 columns, expected 2"],
    );
}

#[test]
fn semicolon_input_file_keeps_its_rows_and_mixed_delimiters_name_the_line() {
    // `;`-delimited with a header: both rows are read (u = -1 then -2 from t = 0.05 s)
    let f = scratch("semicolon.csv");
    std::fs::write(&f, "t;u0\n0;-1\n0.05;-2\n").unwrap();
    let out_dir = scratch("semicolon-run");
    let out = gvsrom(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.1",
        "--sample-rate",
        "100",
        "--input",
        f.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let u = npy_values(&out_dir.join("u.npy"));
    assert_eq!((u[0], u[4], u[5], u[10]), (-1.0, -1.0, -2.0, -2.0), "{u:?}");
    let f = scratch("mixed-delim.csv");
    std::fs::write(&f, "0;-1\n0.05,-2\n").unwrap();
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.1",
            "--input",
            f.to_str().unwrap(),
        ],
        &[
            "mixed-delim.csv:2",
            "the delimiter is `,`",
            "line 1",
            "uses `;`",
        ],
    );
}

#[test]
fn lightly_damped_rod_gets_an_l_stable_method_and_says_so() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let scenario = format!("{root}/undamped-release.toml");
    let schedule = format!("{root}/release-zero.csv");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "simulate",
            scenario.as_str(),
            "--duration",
            "0.05",
            "--from-equilibrium",
            "--load-schedule",
            schedule.as_str(),
        ];
        args.extend_from_slice(extra);
        let out = gvsrom(&args);
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        stdout
    };
    let auto = run(&[]);
    assert!(
        auto.contains("integrator SDIRK4 (order 4, L-stable) with the mass-norm error test at rtol 1e-4: lightly damped (stiffest mode ζ = 0.000"),
        "{auto}"
    );
    // a tolerance given is used
    let given = run(&["--rtol", "3e-4"]);
    assert!(given.contains("at rtol 3e-4: lightly damped"), "{given}");
    // the NDF by name gets its A-stable orders
    let ndf = run(&["--method", "ndf"]);
    assert!(
        ndf.contains("integrator NDF orders ≤ 2 with the mass-norm error test: lightly damped (stiffest mode ζ = 0.000"),
        "{ndf}"
    );
    // a choice by hand is kept, and not announced
    for extra in [
        &["--max-order", "5"][..],
        &["--error-norm", "componentwise"],
        &["--method", "sdirk"],
        &["--method", "galpha"],
        &["--method", "ndf", "--max-order", "5"],
    ] {
        let manual = run(extra);
        assert!(!manual.contains("integrator "), "{extra:?}: {manual}");
    }
    // a damped preset keeps the default NDF
    let out = gvsrom(&["simulate", "six-tendon", "--duration", "0.05"]);
    assert!(out.status.success());
    assert!(!String::from_utf8_lossy(&out.stdout).contains("integrator "));
}

#[test]
fn repeated_runs_record_every_wall_time_and_keep_the_smallest() {
    let args = |dir: &Path, repeat: &str| {
        vec![
            "simulate".to_string(),
            "single-tendon".into(),
            "--duration".into(),
            "0.2".into(),
            "--steps=-3,0,0.1".into(),
            "--repeat".into(),
            repeat.into(),
            "--out".into(),
            dir.to_str().unwrap().into(),
        ]
    };
    let once = scratch("repeat-once");
    let thrice = scratch("repeat-thrice");
    let run = |a: Vec<String>| common::run_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    run(args(&once, "1"));
    let stdout = run(args(&thrice, "3"));
    assert!(
        stdout.contains("the smallest of 3 runs (median"),
        "{stdout}"
    );
    let meta = common::json(&thrice.join("meta.json"));
    let times: Vec<f64> = meta["wall_times_s"]
        .as_array()
        .expect("wall_times_s with --repeat 3")
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(times.len(), 3);
    assert!(times.iter().all(|t| *t > 0.0));
    let smallest = times.iter().copied().fold(f64::INFINITY, f64::min);
    assert_eq!(meta["wall_time_s"].as_f64().unwrap(), smallest);
    assert!(meta["complete"].as_bool().unwrap());
    // the timing runs change nothing that is written
    assert!(common::json(&once.join("meta.json"))
        .get("wall_times_s")
        .is_none());
    for f in ["q.npy", "qd.npy", "u.npy", "tip_position.npy"] {
        assert_eq!(
            npy_values(&once.join(f)),
            npy_values(&thrice.join(f)),
            "{f}"
        );
    }
    // a usage error (clap's exit code 2) naming the option, the value and the accepted range
    let zero = gvsrom(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.1",
        "--repeat",
        "0",
    ]);
    let stderr = String::from_utf8_lossy(&zero.stderr);
    assert_eq!(zero.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("'0' for '--repeat <N>'") && stderr.contains("1..=10000"),
        "{stderr}"
    );
}

#[test]
fn a_state_no_elastic_rod_holds_ends_the_run_naming_it_and_the_load() {
    // 100 N on one off-centre tendon of the gravity-free arm passes the load estimate (~29 rad),
    // but the motion it drives diverges: once the tip was reported kilometres away, "complete"
    let out_dir = scratch("non-physical-run");
    let msg = expect_error(
        &[
            "simulate",
            "six-tendon-no-gravity",
            "--tension=-100,0,0,0,0,0",
            "--duration",
            "0.5",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        &[
            "the state left the rod's elastic range at t = ",
            "accepted |·| <= 10",
            "tendons[0].tension = -100 N",
            "marked partial",
        ],
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["complete"], false, "{msg}");
    // the reason names the stop, not a failed integration
    assert_eq!(
        meta["reason"], "the run left the rod's elastic range",
        "{meta}"
    );
    // every sample written is inside the bounds: the tip within the rod's reach
    let tip = npy_values(&out_dir.join("tip_position.npy"));
    let reach = tip
        .chunks(3)
        .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
        .fold(0.0, f64::max);
    assert!(reach <= 0.6 * 1.5, "{reach}");
    // the same in a dynamic dataset: an error, and the snapshots before it marked incomplete
    let ds = scratch("non-physical-dataset");
    expect_error(
        &[
            "dataset",
            "six-tendon-no-gravity",
            "--set",
            "tendons.0.tension=-100",
            "--duration",
            "0.3",
            "--out",
            ds.to_str().unwrap(),
        ],
        &[
            "the state left the rod's elastic range",
            "marked incomplete",
        ],
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(ds.join("meta.json")).unwrap()).unwrap();
    assert_eq!(
        meta["reason"], "the run left the rod's elastic range",
        "{meta}"
    );
    assert!(
        (meta["error"].as_str())
            .is_some_and(|e| e.starts_with("the state left the rod's elastic range at t = ")),
        "{meta}"
    );
}

#[test]
fn a_massless_rod_is_refused_for_motion_naming_the_density() {
    // density 0 is accepted for statics; a motion (simulate, a dynamic dataset, modes) needs mass
    let out_dir = scratch("massless-run");
    for args in [
        &["simulate", "single-tendon", "--duration", "0.1", "--out"][..],
        &["dataset", "single-tendon", "--duration", "0.1", "--out"][..],
    ] {
        let args = [
            args,
            &[out_dir.to_str().unwrap(), "--set", "material.density=0"],
        ]
        .concat();
        expect_error(&args, &["invalid `material.density`", "a positive density"]);
        assert!(!out_dir.exists());
    }
    expect_error(
        &["modes", "single-tendon", "--set", "material.density=0"],
        &["invalid `material.density`"],
    );
    let out = gvsrom(&[
        "statics",
        "single-tendon",
        "--set",
        "material.density=0",
        "--set",
        "loads.gravity=[0,0,0]",
    ]);
    assert!(out.status.success());
}

#[test]
fn integrator_options_out_of_range_or_ignored_by_the_method_are_refused_before_any_output() {
    let out = scratch("integrator-options");
    let cases: [(&[&str], &[&str]); 12] = [
        (&["--max-order", "0"], &["--max-order", "from 1 to 5"]),
        (&["--max-order", "6"], &["--max-order", "from 1 to 5"]),
        (
            &["--method", "galpha", "--rho-inf", "2"],
            &["--rho-inf", "in [0, 1]"],
        ),
        (
            &["--method", "sdirk", "--max-order", "2"],
            &["--max-order", "does not apply", "NDF"],
        ),
        (&["--rho-inf", "0.5"], &["--rho-inf", "generalized-α"]),
        (
            &["--method", "sdirk", "--fd-jacobian"],
            &["--fd-jacobian", "does not apply", "second-order form"],
        ),
        (
            &["--method", "galpha", "--fd-jacobian"],
            &["--fd-jacobian", "does not apply"],
        ),
        (
            &["--fixed-step", "0.01", "--method", "ndf"],
            &["--method", "fixed-step"],
        ),
        (
            &["--fixed-step", "0.01", "--rtol", "1e-4"],
            &["--rtol", "not controlled"],
        ),
        (
            &["--fixed-step", "0.01", "--atol", "1e-6"],
            &["--atol", "not controlled"],
        ),
        (
            &["--fixed-step", "0.01", "--max-order", "2"],
            &["--max-order", "fixed-step"],
        ),
        (
            &["--fixed-step", "1"],
            &[
                "--fixed-step",
                "longer than the run itself (--duration 0.1 s)",
            ],
        ),
    ];
    for (extra, needles) in cases {
        let base = [
            "simulate",
            "single-tendon",
            "--duration",
            "0.1",
            "--out",
            out.to_str().unwrap(),
        ];
        expect_error(&[&base[..], extra].concat(), needles);
        assert!(!out.exists(), "{extra:?} created {}", out.display());
    }
    // where they apply they run
    for extra in [
        &["--method", "galpha", "--rho-inf", "0.5"][..],
        &["--method", "ndf", "--max-order", "2"],
        &["--fixed-step", "0.1"],
    ] {
        let args = [
            &["simulate", "single-tendon", "--duration", "0.1"][..],
            extra,
        ]
        .concat();
        let o = gvsrom(&args);
        assert!(
            o.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn options_that_would_be_ignored_are_refused_naming_them() {
    // a seed without a random input, random tensions for a rod without tendons, --extrapolate
    // without a model, a chunk size for a dynamic dataset (one chunk): each was accepted and
    // ignored
    let out = scratch("ignored-options");
    let cases: [(&[&str], &[&str]); 5] = [
        (
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "0.01",
                "--seed",
                "5",
            ],
            &["--steps", "--babble"],
        ),
        (
            &[
                "simulate",
                "soft-beam",
                "--duration",
                "0.01",
                "--steps=-1,0,0.005",
            ],
            &["--steps", "no tendons"],
        ),
        (
            &["statics", "single-tendon", "--extrapolate"],
            &["--extrapolate", "--model"],
        ),
        (
            &[
                "simulate",
                "single-tendon",
                "--duration",
                "0.01",
                "--extrapolate",
            ],
            &["--extrapolate", "--model"],
        ),
        (
            &[
                "dataset",
                "single-tendon",
                "--duration",
                "0.01",
                "--chunk-size",
                "5",
                "--out",
                out.to_str().unwrap(),
            ],
            &["--chunk-size", "--duration"],
        ),
    ];
    for (args, needles) in cases {
        let o = gvsrom(args);
        assert!(!o.status.success(), "{args:?} ran");
        let err = String::from_utf8_lossy(&o.stderr);
        for n in needles {
            assert!(err.contains(n), "{args:?}: {err}");
        }
    }
    assert!(!out.exists());
    // where they apply they run
    let o = gvsrom(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.01",
        "--seed",
        "5",
        "--steps=-1,0,0.005",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A signal whose tensions lie far beyond the rod's elastic range is refused naming the signal,
/// the tension and the first time it reaches it, not the scenario's `tendons[k].tension`.
#[test]
fn a_signal_beyond_the_elastic_range_is_refused_naming_the_file_the_tension_and_the_time() {
    let csv = scratch("beyond.csv");
    std::fs::write(&csv, "t,u\n0,-1\n0.5,-1e9\n1,-1e9\n").unwrap();
    let e = expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.1",
            "--input",
            csv.to_str().unwrap(),
        ],
        &[
            "invalid `--input`",
            "beyond.csv",
            "u[0] = -1000000000 N at t = 0.5 s",
            "elastic range",
        ],
    );
    assert!(!e.contains("t = 1 s"), "{e}");
}

/// A straight cantilever under an axial compression of 5 N, 64× its Euler load
/// (`π² EI / 4L²` = 0.078 N), keeps a straight equilibrium, and it diverges: a run started there
/// says so (stderr and `meta.json`'s `start_divergence`), instead of showing a rod at rest.
#[test]
fn a_run_from_a_diverging_equilibrium_says_so() {
    let toml = common::scratch("euler-column.toml");
    std::fs::write(
        &toml,
        r#"name = "euler-column"
[material]
youngs_modulus = 1e6
poisson_ratio = 0.45
density = 1000.0
damping = 0
[[divisions]]
length = 0.5
radius = 0.01
basis = { kind = "legendre", modes = ["bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 4 }
[loads]
gravity = [0, 0, 0]
[[loads.point]]
x = 0.5
force = [-5.0, 0, 0]
frame = "global"
"#,
    )
    .unwrap();
    let out = common::scratch("euler-column-run");
    let (_, stderr) = common::run_ok_with_stderr(&[
        "simulate",
        common::s(&toml),
        "--from-equilibrium",
        "--duration",
        "0.05",
        "--out",
        common::s(&out),
    ]);
    assert!(
        stderr.contains("warning: the equilibrium the run starts from diverges")
            && stderr.contains("1/s² < 0"),
        "{stderr}"
    );
    let meta = common::json(&out.join("meta.json"));
    let w2 = meta["start_divergence"].as_f64().unwrap();
    assert!(w2 < 0.0, "{meta}");
    // from rest (no equilibrium solved) nothing is said
    let rest = common::scratch("euler-column-rest");
    let (_, stderr) = common::run_ok_with_stderr(&[
        "simulate",
        common::s(&toml),
        "--duration",
        "0.05",
        "--out",
        common::s(&rest),
    ]);
    assert!(!stderr.contains("diverges"), "{stderr}");
    assert!(common::json(&rest.join("meta.json"))["start_divergence"].is_null());
}
