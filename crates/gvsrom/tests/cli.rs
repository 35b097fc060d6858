//! The `gvsrom` binary end to end: bad input gives a one-line error naming the field (and the
//! accepted range), exit code 1 and no panic; good input prints a summary and writes the JSON.

mod common;

use common::{expect_error, gvsrom, run_json, run_ok, scratch};
use std::path::PathBuf;

#[test]
fn negative_or_zero_length_is_rejected_with_field_and_range() {
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.length=-0.1",
        ],
        &["divisions[0].length", "-0.1", "> 0 m"],
    );
    expect_error(
        &["statics", "soft-beam", "--set", "divisions.0.length=0"],
        &["divisions[0].length", ": 0 ", "> 0 m"],
    );
}

#[test]
fn the_summary_says_whether_a_wrench_follows_its_section() {
    // IV-B's pulse is a follower moment; a point force is one too unless it says "global"
    // (a dead weight): under large deflection the two bend the rod differently
    let beam = run_ok(&["statics", "soft-beam"]);
    assert!(
        beam.contains(
            "loads      gravity [0, 0, 0] m/s², 0 point wrenches, 1 distributed wrench (follower)"
        ),
        "{beam}"
    );
    let both = run_ok(&[
        "statics",
        "single-tendon",
        "--set",
        "loads.point=[{x=0.25,force=[0,0,-0.01],frame=\"global\"},{x=0.1,force=[0,0,-0.01]}]",
    ]);
    for line in ["scenario", "loads"] {
        let l = both.lines().find(|l| l.starts_with(line)).unwrap();
        assert!(
            l.contains("2 point wrenches (1 follower, 1 world-fixed)"),
            "{l}"
        );
    }
}

#[test]
fn non_positive_radius_is_rejected() {
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.radius_end=0",
        ],
        &["divisions[0].radius_end", "> 0 m"],
    );
    expect_error(
        &["statics", "soft-beam", "--set", "divisions.0.radius=-0.015"],
        &["divisions[0].radius", "-0.015", "> 0 m"],
    );
}

#[test]
fn poisson_ratio_outside_range_is_rejected() {
    for v in ["0.7", "-1", "-1.5"] {
        expect_error(
            &[
                "statics",
                "single-tendon",
                "--set",
                &format!("material.poisson_ratio={v}"),
            ],
            &["material.poisson_ratio", v, "(-1, 0.5]"],
        );
    }
}

#[test]
fn tendon_offset_outside_the_section_is_rejected() {
    // the tip radius is 5 mm
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "tendons.0.offset_end=[0, 0.006]",
        ],
        &["tendons[0].offset_end", "0.006", "radius 0.005", "X = 0.25"],
    );
    expect_error(
        &[
            "statics",
            "six-tendon",
            "--set",
            "tendons.1.radial_fraction=1.2",
        ],
        &["tendons[1].radial_fraction", "1.2", "[0, 1]"],
    );
}

#[test]
fn an_array_of_the_wrong_length_says_what_the_key_takes() {
    // the spec writes a tendon's offset d(X) = [0, y, z]; the key takes [y, z]
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "tendons.0.offset_start=[0,0.012,0]",
        ],
        &[
            "`tendons[0].offset_start`",
            "3 values given",
            "expected 2 values `[y, z]` [m]",
        ],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "tendons.0.offset_end=[0.01]",
        ],
        &["1 value given", "expected 2 values `[y, z]`"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "loads.gravity=[0,0,-9.81,0]",
        ],
        &[
            "`loads.gravity`",
            "4 values given",
            "expected 3 values `[x, y, z]`",
        ],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.reference_strain=[0,1]",
        ],
        &["2 values given", "expected 6 values `[torsion, bend_y"],
    );
}

#[test]
fn empty_basis_is_rejected() {
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.basis.modes=[]",
        ],
        &["divisions[0].basis.modes", "empty"],
    );
}

#[test]
fn unknown_key_is_named_in_a_file_and_in_an_override() {
    let preset = gvsrom(&["show", "single-tendon"]);
    assert!(preset.status.success());
    let text = String::from_utf8(preset.stdout).unwrap().replace(
        "poisson_ratio = 0.5",
        "poisson_ratio = 0.5\nyoungs_moduls = 3",
    );
    let path = scratch("unknown-key.toml");
    std::fs::write(&path, text).unwrap();
    expect_error(
        &["statics", path.to_str().unwrap()],
        &["material.youngs_moduls", "unknown field"],
    );
    expect_error(
        &[
            "statics",
            "soft-beam",
            "--set",
            "loads.distributed.0.widht=0.1",
        ],
        &["loads.distributed[0].widht", "unknown field", "`width`"],
    );
    expect_error(
        &["statics", "single-tendon", "--set", "solver.tolerance=1e-3"],
        &["solver.tolerance", "unknown field"],
    );
}

#[test]
fn unknown_preset_or_missing_file_lists_the_presets() {
    expect_error(
        &["statics", "two-tendon"],
        &[
            "two-tendon",
            "single-tendon, soft-beam, six-tendon, soft-beam-peak, six-tendon-no-gravity, six-tendon-hanging",
        ],
    );
    expect_error(&["statics", "no/such/file.toml"], &["no/such/file.toml"]);
    expect_error(&["show", "two-tendon"], &["unknown preset `two-tendon`"]);
}

#[test]
fn nan_and_infinite_values_are_rejected() {
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "material.youngs_modulus=nan",
        ],
        &["material.youngs_modulus", "NaN", "finite"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "loads.gravity=[0, 0, -inf]",
        ],
        &["loads.gravity[2]", "-inf", "finite"],
    );
    expect_error(
        &["statics", "single-tendon", "--tension", "inf"],
        &["tendons[0].tension", "inf", "finite"],
    );
    let text = String::from_utf8(gvsrom(&["show", "soft-beam"]).stdout)
        .unwrap()
        .replace("magnitude = 4.0", "magnitude = nan");
    let path = scratch("nan.toml");
    std::fs::write(&path, text).unwrap();
    expect_error(
        &["statics", path.to_str().unwrap()],
        &["loads.distributed[0].magnitude", "NaN", "finite"],
    );
}

#[test]
fn malformed_toml_reports_the_line() {
    let path = scratch("malformed.toml");
    std::fs::write(&path, "name = \"x\"\n[material\nyoungs_modulus = 1e6\n").unwrap();
    expect_error(
        &["statics", path.to_str().unwrap()],
        &["malformed.toml", "not valid TOML", "line 2"],
    );
}

#[test]
fn bad_overrides_name_the_path() {
    expect_error(
        &["statics", "single-tendon", "--set", "tendons.3.tension=-1"],
        &["tendons.3.tension", "out of range", "1 entries"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "divisions.0.basis.order=-1",
        ],
        &["divisions[0].basis.order", "integer >= 0"],
    );
    expect_error(
        &["statics", "single-tendon", "--set", "tension"],
        &["path=value"],
    );
    expect_error(
        &["statics", "six-tendon", "--tension=-10,0"],
        &["2 tensions", "6 tendons"],
    );
}

#[test]
fn unreachable_load_reports_iterations_and_residual() {
    let msg = expect_error(
        &[
            "statics",
            "single-tendon",
            "--tension=-30",
            "--set",
            "solver.max_iterations=3",
            "--set",
            "solver.ramp_steps=1",
            "--set",
            "solver.min_increment=1",
        ],
        &[
            "did not converge",
            "3 iterations",
            "‖R‖∞",
            "the largest load is tendons[0].tension = -30 N (implied bending ~24 rad",
            // the scenario's own cap stopped the solve: raise it first, then a finer ramp
            "solver.max_iterations = 3 stopped the solves (the default is 400): raise it",
            "then, if it still fails, try solver.ramp_steps = 10",
        ],
    );
    assert!(msg.contains("tolerance"), "{msg}");
}

#[test]
fn statics_prints_summary_and_writes_json_atomically() {
    let path = scratch("single.json");
    let _ = std::fs::remove_file(&path);
    let out = gvsrom(&[
        "statics",
        "single-tendon",
        "--tension",
        "-2",
        "--centerline-points",
        "11",
        "--json",
        path.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for needle in [
        "single-tendon",
        "33 DOF",
        "102 computational points",
        "u = [-2] N",
        "iteration",
        "‖R‖∞",
        " ms",
        "tip        position",
        "rotation axis",
        "tendons    length [",
    ] {
        assert!(
            stdout.contains(needle),
            "summary lacks `{needle}`:\n{stdout}"
        );
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert!(!PathBuf::from(format!("{}.tmp", path.display())).exists());
    assert_eq!(json["scenario"], "single-tendon");
    assert_eq!(json["u"], serde_json::json!([-2.0]));
    assert_eq!(json["q"].as_array().unwrap().len(), 33);
    assert_eq!(json["tip_position"].as_array().unwrap().len(), 3);
    let rot = json["tip_rotation"].as_array().unwrap();
    assert!(rot.len() == 3 && rot.iter().all(|r| r.as_array().unwrap().len() == 3));
    assert_eq!(json["centerline"].as_array().unwrap().len(), 11);
    assert_eq!(json["centerline_x"][10], 0.25);
    assert_eq!(json["strain"].as_array().unwrap().len(), 102);
    assert_eq!(json["strain"][0].as_array().unwrap().len(), 6);
    assert_eq!(json["strain_x"].as_array().unwrap().len(), 102);
    assert!(json["iterations"].as_u64().unwrap() >= 1);
    assert!(json["residual_norm"].as_f64().unwrap() < 1e-6);
    assert!(json["solve_time_s"].as_f64().unwrap() > 0.0);
    // the tip is the last centreline sample
    let tip = &json["tip_position"];
    let last = &json["centerline"][10];
    for i in 0..3 {
        assert!((tip[i].as_f64().unwrap() - last[i].as_f64().unwrap()).abs() < 1e-12);
    }
    // the tendon at rest is the line from offset 10 mm to 3 mm over 0.25 m; the summary prints
    // how far the equilibrium's length is from it
    let rest = json["tendon_rest_lengths"][0].as_f64().unwrap();
    assert!(
        (rest - 0.25f64.hypot(0.007)).abs() < 1e-15,
        "rest length {rest}"
    );
    let length = json["tendon_lengths"][0].as_f64().unwrap();
    let line = format!(
        "tendons    length [{length:.6}] m, pulled in [{:.3}] mm from rest",
        1e3 * (rest - length)
    );
    assert!(stdout.contains(&line), "summary lacks `{line}`:\n{stdout}");
}

#[test]
fn shown_preset_runs_as_a_file_with_the_same_result() {
    let text = gvsrom(&["show", "six-tendon"]).stdout;
    let path = scratch("six.toml");
    std::fs::write(&path, text).unwrap();
    let (a, b) = (scratch("six-preset.json"), scratch("six-file.json"));
    assert!(
        gvsrom(&["statics", "six-tendon", "--json", a.to_str().unwrap()])
            .status
            .success()
    );
    assert!(gvsrom(&[
        "statics",
        path.to_str().unwrap(),
        "--json",
        b.to_str().unwrap()
    ])
    .status
    .success());
    let read = |p: &PathBuf| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    assert_eq!(read(&a)["tip_position"], read(&b)["tip_position"]);
}

#[test]
fn presets_lists_all_and_check_validates_without_solving() {
    let out = gvsrom(&["presets"]);
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for name in [
        "single-tendon",
        "soft-beam",
        "six-tendon",
        "soft-beam-peak",
        "six-tendon-no-gravity",
    ] {
        assert!(s.contains(name), "{s}");
    }
    let out = gvsrom(&["check", "soft-beam"]);
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{s}");
    assert!(
        s.contains("50 DOF") && s.contains("148 computational points"),
        "{s}"
    );
    assert!(!s.contains("tip"), "{s}");
}

#[test]
fn negative_override_index_says_it_is_not_an_index() {
    let msg = expect_error(
        &["statics", "single-tendon", "--set", "tendons.-1.tension=1"],
        &[
            "tendons.-1.tension",
            "`-1` is not a valid index of `tendons`",
            "0-based non-negative integers",
            "1 entries",
        ],
    );
    assert!(!msg.contains("tendons.0.-1"), "{msg}");
}

#[test]
fn physically_absurd_material_and_geometry_are_rejected_before_solving() {
    let set = |kv: &str| {
        vec!["statics", "single-tendon", "--set"]
            .into_iter()
            .chain([kv])
            .map(String::from)
            .collect::<Vec<_>>()
    };
    let cases: [(&str, &[&str]); 11] = [
        (
            "material.youngs_modulus=1e-300",
            &["material.youngs_modulus", "1e-300", "[1, 1e13] Pa"],
        ),
        (
            "material.youngs_modulus=1e14",
            &["material.youngs_modulus", "[1, 1e13] Pa"],
        ),
        (
            "material.density=1e308",
            &[
                "material.density",
                "0 (massless, for statics) or",
                "[0.01, 1e5] kg/m^3",
            ],
        ),
        (
            // a mass matrix that underflows (modes printed 7e152 Hz beside 0 Hz)
            "material.density=1e-300",
            &["material.density", "1e-300", "[0.01, 1e5] kg/m^3"],
        ),
        (
            "loads.gravity=[0, 0, -1e308]",
            &["loads.gravity", ": 1e308 ", "<= 1e4 m/s^2"],
        ),
        (
            "loads.gravity=[1e4, 0, -1e4]",
            &["loads.gravity", "14142.1", "<= 1e4 m/s^2"],
        ),
        (
            "divisions.0.length=1e308",
            &["divisions[0].length", "[1e-6, 1000] m"],
        ),
        (
            "divisions.0.length=1e-100",
            &["divisions[0].length", "1e-100", "[1e-6, 1000] m"],
        ),
        (
            "divisions.0.radius_start=1e308",
            &["divisions[0].radius_start", "[1e-7, 0.25] m"],
        ),
        (
            "divisions.0.radius_end=1e-100",
            &["divisions[0].radius_end", "1e-100", "[1e-7, 0.25] m"],
        ),
        (
            "divisions.0.radius_start=0.3",
            &[
                "divisions[0].radius_start",
                "0.3",
                "at most the rod's length",
            ],
        ),
    ];
    for (kv, needles) in cases {
        let args = set(kv);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        expect_error(&args, needles);
    }
    // the soft end of the range is accepted: a 1 kPa hydrogel arm builds
    let out = gvsrom(&[
        "check",
        "single-tendon",
        "--set",
        "material.youngs_modulus=1e3",
        "--tension=0",
        "--set",
        "loads.gravity=[0,0,0]",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_basis_with_too_many_dof_is_rejected_naming_its_size() {
    // 6 modes × (2·175 + 1) quadratic nodes = 2106 DOF
    let basis = |e: usize| {
        format!("divisions.0.basis={{ kind = \"fem\", modes = [\"torsion\",\"bend_y\",\"bend_z\",\"elongation\",\"shear_y\",\"shear_z\"], elements = {e}, degree = \"quadratic\" }}")
    };
    let quad =
        |e: usize| format!("divisions.0.quadrature={{ gauss_per_element = 3, elements = {e} }}");
    expect_error(
        &[
            "check",
            "soft-beam",
            "--set",
            &basis(175),
            "--set",
            &quad(175),
        ],
        &["divisions", "2106 DOF", "accepted <= 2000"],
    );
    // 6 × 321 = 1926 DOF stays accepted
    let out = gvsrom(&[
        "check",
        "soft-beam",
        "--set",
        &basis(160),
        "--set",
        &quad(160),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("1926 DOF"), "{stdout}");
}

#[test]
fn loads_far_beyond_the_elastic_range_are_rejected_naming_the_load() {
    for cmd in ["statics", "check"] {
        expect_error(
            &[cmd, "single-tendon", "--tension", "1e300"],
            &[
                "tendons[0].tension = 1e300 N",
                "implies a bending of ~",
                "(accepted <= 200 rad)",
                "axial strain of ~",
                "(accepted <= 1)",
                "far beyond the rod's elastic range",
            ],
        );
    }
    // the peak reading, whose unit the message names: N·m/m
    expect_error(
        &[
            "statics",
            "soft-beam-peak",
            "--set",
            "loads.distributed.0.magnitude=-1e6",
        ],
        &[
            "loads.distributed[0].magnitude = -1000000 N*m/m",
            "bending of ~",
        ],
    );
    expect_error(
        &[
            "statics",
            "six-tendon",
            "--set",
            "loads.point.0={ x = 0.6, force = [0, 0, -1e9] }",
        ],
        &[
            "loads.point[0].force = [0, 0, -1000000000] N",
            "axial/shear strain of ~",
        ],
    );
    // the paper's six-tendon range: all six tendons at -30 N at once solve
    let out = gvsrom(&["statics", "six-tendon", "--tension=-30"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn solver_options_beyond_their_limits_are_rejected_before_solving() {
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "solver.ramp_steps=1000000000",
        ],
        &["solver.ramp_steps", "1000000000", "[1, 10000]"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "solver.max_iterations=100000",
        ],
        &["solver.max_iterations", "100000", "[1, 10000]"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "solver.min_increment=1e-300",
        ],
        &["solver.min_increment", "1e-300", "[1e-6, 1]"],
    );
}

/// A six-tendon input under gravity that the load ramp alone cannot solve (sample 7371 of
/// `dataset six-tendon --random 'tendons.*.tension=-30:30' --samples 20000 --seed 0`): `statics`
/// reaches it by arc-length continuation through two folds, says so, and records it in the JSON.
#[test]
fn an_input_beyond_the_load_ramp_is_solved_by_continuation_and_reported() {
    let json = scratch("continuation.json");
    let out = gvsrom(&[
        "statics",
        "six-tendon",
        "--tension=14.443131761064372,-23.659122666412333,2.0695427183255006,7.619300609702577,10.53722237180915,10.791231360008751",
        "--json",
        json.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("continued") && stdout.contains("through 2 folds at load factor 0.59"),
        "{stdout}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let folds = v["continuation"]["folds"]
        .as_array()
        .expect("continuation.folds");
    assert_eq!(folds.len(), 2, "{v}");
    assert!(v["residual_norm"].as_f64().unwrap() < 1e-8);
}

#[test]
fn check_refuses_extrapolate_that_has_no_model_to_apply_to() {
    // `check` validates the scenario alone: a flag about `--model` is refused, not ignored
    expect_error(
        &["check", "single-tendon", "--extrapolate"],
        &["--extrapolate", "no `--model`", "statics"],
    );
    let out = gvsrom(&["check", "single-tendon"]);
    assert!(out.status.success());
}

#[test]
fn a_name_that_is_both_a_preset_and_a_file_here_is_refused_as_ambiguous() {
    let dir = scratch("preset-and-file");
    std::fs::create_dir_all(&dir).unwrap();
    let shown = gvsrom(&["show", "single-tendon"]);
    std::fs::write(dir.join("single-tendon"), &shown.stdout).unwrap();
    let run = |arg: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_gvsrom"))
            .args(["check", arg])
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let out = run("single-tendon");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("`single-tendon` names both the preset `single-tendon` and a file in this directory: write `./single-tendon` for the file"),
        "{stderr}"
    );
    // the file by its path, and a directory of the same name (an output) does not count
    assert!(run("./single-tendon").status.success());
    std::fs::create_dir_all(dir.join("six-tendon")).unwrap();
    assert!(run("six-tendon").status.success());
}

#[test]
fn a_friction_or_damping_no_material_has_is_refused_naming_the_field() {
    expect_error(
        &["check", "single-tendon", "--set", "tendons.0.friction=1e9"],
        &["tendons[0].friction", "a number in [0, 10]"],
    );
    // single-tendon: E = 617 kPa, so 1e20 Pa·s relaxes in 1.6e14 s: refused for a motion, where
    // the damping acts, not for statics, which ignore it
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--duration",
            "0.01",
            "--set",
            "material.damping=1e20",
        ],
        &[
            "material.damping",
            "at most 6.17e8 Pa*s for this Young's modulus in a motion",
            "relaxation time η / E of 1.62e14 s against 1000 s accepted",
        ],
    );
    let out = gvsrom(&["statics", "single-tendon", "--set", "material.damping=1e20"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // the bounds themselves are accepted
    for set in ["tendons.0.friction=10", "material.damping=6.17e8"] {
        let out = gvsrom(&[
            "simulate",
            "single-tendon",
            "--duration",
            "0.01",
            "--set",
            set,
        ]);
        assert!(
            out.status.success(),
            "{set}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn absurd_positions_are_refused_and_extreme_numbers_print_in_exponent_form() {
    // a base 1e308 m away: the rod vanished in the rounding of positions (the tip equalled the base)
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "base.position=[1e308,0,0]",
        ],
        &["base.position[0]", "1e308", "[-1000, 1000] m"],
    );
    // a tension of 1e-320 N printed with 300 digits before; now as the shortest exponent form
    let out = gvsrom(&["statics", "single-tendon", "--tension=-1e-320"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("u = [-1e-320] N"), "{stdout}");
    assert!(stdout.lines().all(|l| l.len() < 200), "{stdout}");
}

#[test]
fn an_axis_of_tiny_or_huge_components_keeps_its_direction_and_zero_has_none() {
    // its norm under- or overflowed (0, inf) and the axis was refused as zero or infinite
    let tip = |axis: &str| {
        let out = common::run_ok(&[
            "statics",
            "soft-beam",
            "--set",
            &format!("loads.distributed.0.axis={axis}"),
        ]);
        out.lines()
            .find(|l| l.starts_with("tip"))
            .unwrap()
            .to_string()
    };
    let unit = tip("[0, 1, 0]");
    assert_eq!(tip("[0, 1e-300, 0]"), unit);
    assert_eq!(tip("[0, 1e300, 0]"), unit);
    expect_error(
        &[
            "statics",
            "soft-beam",
            "--set",
            "loads.distributed.0.axis=[0, 0, 0]",
        ],
        &["loads.distributed[0].axis", "[0, 0, 0] has no direction"],
    );
    expect_error(
        &[
            "statics",
            "single-tendon",
            "--set",
            "base.axis=[0, 0, 1]",
            "--set",
            "base.angle_deg=1e308",
        ],
        &["base.angle_deg", "1e308", "[-1e6, 1e6] deg"],
    );
}

#[test]
fn check_refuses_a_distributed_load_the_points_do_not_resolve_as_statics_does() {
    // `check` said "the scenario is valid" for a load `statics` then refused
    let set = "loads.distributed.0.width=0.005";
    for cmd in ["check", "statics"] {
        expect_error(
            &[cmd, "soft-beam", "--set", set],
            &["loads.distributed[0].width", "0.005 m", "not resolved"],
        );
    }
}

/// Every tendon of the six-tendon arm pushed at +30 N: the path from the straight rod ends in the
/// arm's plane of symmetry on an equilibrium that diverges; `statics` releases the arm from it and
/// reports the stable one it settles on beside that plane (`buckled`, with the descent's steps, in
/// the summary and the JSON). With `solver.check_stability = false` the in-plane one is returned,
/// and the summary says it was not judged.
#[test]
fn six_tendon_pushed_on_every_tendon_is_reported_buckled_and_unjudged_without_the_check() {
    let (stdout, v) = run_json("statics", "buckled", &["six-tendon", "--tension=30"]);
    assert!(
        stdout.contains("buckled    the equilibrium on the path from the straight rod diverges")
            && stdout.contains("overdamped motion settled in")
            && !stdout.contains("\nunstable "),
        "{stdout}"
    );
    assert!(v["buckled"].as_f64().unwrap() < -1e3, "{v}");
    assert!(v["descent_steps"].as_u64().unwrap() > 0, "{v}");
    assert!(
        v.get("divergence").is_none() && v["stability_checked"] == true,
        "{v}"
    );
    assert!(v["tip_position"][1].as_f64().unwrap().abs() > 0.005, "{v}");
    let stdout = run_ok(&[
        "statics",
        "six-tendon",
        "--tension=30",
        "--set",
        "solver.check_stability=false",
    ]);
    assert!(
        stdout.contains("stability  not checked (solver.check_stability = false)")
            && !stdout.contains("buckled")
            && !stdout.contains("\nunstable ")
            && !stdout.contains("continued"),
        "{stdout}"
    );
}

#[test]
fn a_negative_number_reaches_its_option_instead_of_reading_as_a_flag() {
    // clap took `-1` for an unknown flag ("unexpected argument '-1' found", with the tip `-- -1`);
    // each command now accepts negative values, and the option's own check names it
    let run = gvsrom(&[
        "simulate",
        "single-tendon",
        "--duration",
        "0.1",
        "--seed",
        "-1",
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(
            "invalid value '-1' for '--seed <SEED>': expected a whole number ≥ 0, not a negative one"
        ) && !stderr.contains("unexpected argument"),
        "{stderr}"
    );
    let out = scratch("negative-samples");
    let run = gvsrom(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-1:0",
        "--samples",
        "-1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains(
            "invalid value '-1' for '--samples <N>': expected a whole number ≥ 0, not a negative one"
        ) && !stderr.contains("unexpected argument"),
        "{stderr}"
    );
    assert!(!out.exists());
}

#[test]
fn a_count_that_is_no_whole_number_says_what_is_expected() {
    // clap's own message was "invalid digit found in string" for each of these
    for (value, says) in [
        ("2.5", "not a fraction"),
        ("abc", "expected a whole number ≥ 0"),
        ("99999999999999999999999", "not one this large"),
    ] {
        let run = gvsrom(&[
            "train",
            "nowhere",
            "--out",
            "nowhere-too",
            "--epochs",
            value,
        ]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains(&format!(
                "invalid value '{value}' for '--epochs <EPOCHS>': expected a whole number ≥ 0"
            )) && stderr.contains(says)
                && !stderr.contains("invalid digit"),
            "{value}: {stderr}"
        );
    }
}
