//! Runs that explain themselves: every output records how it was made under `"provenance"`, and
//! that record alone rebuilds the run bit for bit; a trajectory stores the centreline of every
//! sample.

mod common;

use common::{gvsrom, json, npy, run_ok, s, scratch};
use serde_json::Value;
use std::path::Path;

/// Length of the single-tendon rod [m] (`examples/single-tendon.toml`: one division of 0.25 m).
const L: f64 = 0.25;

fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Seconds since 1970 of `YYYY-MM-DDThh:mm:ssZ` (H. Hinnant's `days_from_civil`), or `None` if
/// the text is not of that form.
fn parse_rfc3339_utc(t: &str) -> Option<i64> {
    let b = t.as_bytes();
    let shape_ok = b.len() == 20
        && b[4] == b'-'
        && b[7] == b'-'
        && b[10] == b'T'
        && b[13] == b':'
        && b[16] == b':'
        && b[19] == b'Z';
    if !shape_ok {
        return None;
    }
    let num = |r: std::ops::Range<usize>| t[r].parse::<i64>().ok();
    let (y, m, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    let (hh, mm, ss) = (num(11..13)?, num(14..16)?, num(17..19)?);
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days * 86_400 + hh * 3600 + mm * 60 + ss)
}

fn now_s() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_secs() as i64
}

/// The provenance fields every output shares: this version, this command line, a start time
/// within the test's run.
fn check_common(p: &Value, args: &[&str], t_before: i64) {
    assert_eq!(p["gvsrom_version"], env!("CARGO_PKG_VERSION"), "{p}");
    let command: Vec<&str> = p["command"]
        .as_array()
        .unwrap_or_else(|| panic!("no command: {p}"))
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(&command[1..], args, "the recorded argv");
    let started = p["started"].as_str().unwrap_or_default();
    let t = parse_rfc3339_utc(started).unwrap_or_else(|| panic!("`started` = {started:?}"));
    assert!(
        (t_before - 1..=now_s() + 1).contains(&t),
        "started {started} is not within the run"
    );
}

const PRESET_TEXT: &str = include_str!("../../../examples/single-tendon.toml");

#[test]
fn statics_json_records_its_provenance_and_a_summary_true_to_the_overrides() {
    let file = scratch("prov-statics.json");
    let args = [
        "statics",
        "single-tendon",
        "--set",
        "tendons.0.friction=0",
        "--set",
        "divisions.0.basis.order=6",
        "--tension=-2.5",
        "--json",
        s(&file),
    ];
    let t0 = now_s();
    let stdout = run_ok(&args);
    // the summary line follows the overrides: 3 modes × 7 Legendre coefficients = 21 DOF, μ = 0
    let line = stdout.lines().next().unwrap();
    assert!(
        line.contains("friction 0,") || line.contains("friction 0)"),
        "{line}"
    );
    assert!(line.contains("21-DOF"), "{line}");
    // (the preset's own friction, not any "0.88": the solve time, e.g. "10.88 ms", may hold it)
    assert!(
        !stdout.contains("friction 0.88") && !stdout.contains("33-DOF"),
        "{stdout}"
    );
    let doc = json(&file);
    let p = &doc["provenance"];
    check_common(p, &args, t0);
    assert_eq!(p["scenario"]["source"], "preset");
    assert_eq!(p["scenario"]["name"], "single-tendon");
    assert_eq!(p["scenario"]["sha256"], sha256_hex(PRESET_TEXT.as_bytes()));
    assert_eq!(
        p["overrides"],
        serde_json::json!(["tendons.0.friction=0", "divisions.0.basis.order=6"])
    );
    assert_eq!(p["seeds"], serde_json::json!({}));
    // the preset's [solver] with the defaults it leaves out
    assert_eq!(p["solver"]["ramp_steps"], 1, "{p}");
    assert!(p["solver"]["ftol"].is_number(), "{p}");
    assert!(p.get("model").is_none(), "{p}");
    // the scenario as run: the overrides and --tension applied
    let toml: toml::Table = p["scenario_toml"].as_str().unwrap().parse().unwrap();
    let tendon = &toml["tendons"].as_array().unwrap()[0];
    assert_eq!(tendon["friction"].as_float(), Some(0.0));
    assert_eq!(tendon["tension"].as_float(), Some(-2.5));
    assert_eq!(
        toml["divisions"].as_array().unwrap()[0]["basis"]["order"].as_integer(),
        Some(6)
    );
    // the fields it had before are still there
    assert_eq!(doc["n_dof"], 21);
    assert_eq!(doc["scenario"], "single-tendon");
}

/// A statics JSON without what differs between two runs of the same problem.
fn without_run_fields(mut doc: Value) -> Value {
    let o = doc.as_object_mut().unwrap();
    for k in ["provenance", "solve_time_s"] {
        assert!(o.remove(k).is_some(), "no `{k}`");
    }
    // the manifest's hash of the values covers the run fields too
    let manifest = o["gvsrom"].as_object_mut().unwrap();
    assert!(manifest.remove("meta_sha256").is_some(), "no `meta_sha256`");
    doc
}

#[test]
fn a_statics_run_rebuilt_from_its_provenance_gives_the_same_bytes() {
    let first = scratch("prov-rebuild-a.json");
    run_ok(&[
        "statics",
        "single-tendon",
        "--set",
        "tendons.0.friction=0.30000000000000004",
        "--set",
        "material.youngs_modulus=0.7e6",
        "--set",
        "loads.gravity=[0.1,0,-9.7]",
        "--tension=-1.7000000000000002",
        "--centerline-points",
        "13",
        "--json",
        s(&first),
    ]);
    let a = json(&first);
    // numbers that need all 17 digits survive the TOML
    let toml_text = a["provenance"]["scenario_toml"].as_str().unwrap();
    let table: toml::Table = toml_text.parse().unwrap();
    let tendon = &table["tendons"].as_array().unwrap()[0];
    assert_eq!(tendon["friction"].as_float(), Some(0.30000000000000004));
    assert_eq!(tendon["tension"].as_float(), Some(-1.7000000000000002));
    // the provenance alone: its scenario as a file, nothing else on the command line
    let toml = scratch("prov-rebuild.toml");
    std::fs::write(&toml, a["provenance"]["scenario_toml"].as_str().unwrap()).unwrap();
    let second = scratch("prov-rebuild-b.json");
    run_ok(&["statics", s(&toml), "--json", s(&second)]);
    let b = json(&second);
    assert_eq!(b["provenance"]["scenario"]["source"], "file");
    assert_eq!(b["provenance"]["scenario"]["path"], s(&toml));
    assert_eq!(
        b["provenance"]["scenario"]["sha256"],
        sha256_hex(&std::fs::read(&toml).unwrap())
    );
    assert_eq!(a["centerline"].as_array().unwrap().len(), 13);
    // the arrays as written, digit for digit (serde_json writes the shortest round-trip form)
    for key in [
        "q",
        "tip_position",
        "tip_rotation",
        "centerline",
        "strain",
        "u",
    ] {
        assert_eq!(
            serde_json::to_string(&a[key]).unwrap(),
            serde_json::to_string(&b[key]).unwrap(),
            "`{key}` differs"
        );
    }
    assert_eq!(without_run_fields(a), without_run_fields(b));
}

/// `simulate` of the bending-only single-tendon arm (no elongation or shear: the centreline is
/// inextensible) with its base moved off the origin, random steps, 21 centreline points.
const SIM_SETS: [&str; 4] = [
    "--set",
    "divisions.0.basis.modes=[\"bend_y\"]",
    "--set",
    "base.position=[0.01,-0.02,0.03]",
];

#[test]
fn a_trajectory_stores_the_centreline_of_every_sample_and_its_provenance() {
    let dir = scratch("prov-sim");
    let mut args = vec!["simulate", "single-tendon"];
    args.extend(SIM_SETS);
    args.extend([
        "--duration",
        "0.06",
        "--sample-rate",
        "100",
        "--steps=-4,0,0.02",
        "--seed",
        "7",
        "--out",
        s(&dir),
    ]);
    let t0 = now_s();
    run_ok(&args);
    let meta = json(&dir.join("meta.json"));
    let n = meta["samples"].as_u64().unwrap() as usize;
    assert_eq!(n, 7);
    let c = 21; // output.centerline_points of the preset
    let (shape, line) = npy(&dir.join("centerline.npy"));
    assert_eq!(shape, vec![n, c, 3]);
    let (_, tip) = npy(&dir.join("tip_position.npy"));
    // listed and hashed like every other file of the trajectory
    let bytes = std::fs::read(dir.join("centerline.npy")).unwrap();
    assert_eq!(
        meta["gvsrom"]["sha256"]["centerline.npy"],
        sha256_hex(&bytes)
    );
    let x: Vec<f64> = serde_json::from_value(meta["centerline_x"].clone()).unwrap();
    assert_eq!(x.len(), c);
    let ds = L / (c - 1) as f64;
    for (k, xk) in x.iter().enumerate() {
        assert!((xk - k as f64 * ds).abs() <= 1e-15, "x[{k}] = {xk}");
    }
    let mut bent = false;
    for i in 0..n {
        let p = |k: usize| &line[(i * c + k) * 3..(i * c + k) * 3 + 3];
        assert_eq!(p(0), &[0.01, -0.02, 0.03], "sample {i}: the base");
        for a in 0..3 {
            assert!(
                (p(c - 1)[a] - tip[3 * i + a]).abs() <= 1e-12,
                "sample {i}: the last point {:?} is not the tip {:?}",
                p(c - 1),
                &tip[3 * i..3 * i + 3]
            );
        }
        // an inextensible centreline: a chord is at most its arc L/(c − 1), and shorter only by
        // (κ Δs)²/24 ≈ 1e-3 relative at the curvature of these tensions
        for k in 1..c {
            let d = (0..3)
                .map(|a| (p(k)[a] - p(k - 1)[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                d <= ds * (1.0 + 1e-6) && d >= ds * (1.0 - 1e-2),
                "sample {i}: points {} and {k} are {d} m apart, the arc between them {ds} m",
                k - 1
            );
        }
        bent |= (p(c - 1)[2] - 0.03).abs() > 1e-3;
    }
    assert!(
        bent,
        "the tendon never bent the arm: the test proves nothing"
    );

    // the loader reads it
    let tr = gvsrom::compare::Trajectory::load(&dir, "RUN").unwrap();
    assert_eq!(tr.centerline.as_deref(), Some(&line[..]));
    assert_eq!(tr.centerline_x.as_deref(), Some(&x[..]));

    let p = &meta["provenance"];
    check_common(p, &args, t0);
    assert_eq!(p["seeds"], serde_json::json!({"input": 7}));
    assert_eq!(p["input"]["signal"], "steps");
    assert_eq!(p["input"]["lo"], -4.0);
    assert_eq!(p["input"]["period"], 0.02);
    assert_eq!(p["input"]["seed"], 7);
    assert_eq!(
        p["sampling"],
        serde_json::json!({"duration": 0.06, "sample_rate": 100.0})
    );
    assert_eq!(p["integrator"]["requested"]["method"], "auto");
    assert!(p["integrator"]["method"].is_string(), "{p}");
    assert!(p["integrator"]["atol"] == 1e-6, "{p}");
    assert_eq!(
        p["overrides"],
        serde_json::json!([
            "divisions.0.basis.modes=[\"bend_y\"]",
            "base.position=[0.01,-0.02,0.03]"
        ])
    );
}

#[test]
fn a_trajectory_rebuilt_from_its_provenance_alone_has_the_same_bytes() {
    let first = scratch("prov-sim-rebuild-a");
    let mut args = vec!["simulate", "single-tendon"];
    args.extend(SIM_SETS);
    args.extend([
        "--set",
        "tendons.0.friction=0.5",
        "--duration",
        "0.05",
        "--sample-rate",
        "200",
        "--babble=-3,0,0.01,0.02",
        "--seed",
        "11",
        "--centerline-points",
        "9",
        "--out",
        s(&first),
    ]);
    run_ok(&args);
    let p = json(&first.join("meta.json"))["provenance"].clone();
    // every argument from the provenance, none from `args`
    let toml = scratch("prov-sim-rebuild.toml");
    std::fs::write(&toml, p["scenario_toml"].as_str().unwrap()).unwrap();
    let second = scratch("prov-sim-rebuild-b");
    let num = |v: &Value| v.as_f64().unwrap().to_string();
    let input = &p["input"];
    assert_eq!(input["signal"], "babble");
    assert_eq!(input["start"], "rest");
    let babble = format!(
        "--babble={},{},{},{}",
        num(&input["lo"]),
        num(&input["hi"]),
        num(&input["hold_min"]),
        num(&input["hold_max"])
    );
    let requested = &p["integrator"]["requested"];
    let rebuilt = [
        "simulate".to_string(),
        s(&toml).to_string(),
        "--duration".into(),
        num(&p["sampling"]["duration"]),
        "--sample-rate".into(),
        num(&p["sampling"]["sample_rate"]),
        babble,
        "--seed".into(),
        p["seeds"]["input"].as_u64().unwrap().to_string(),
        "--method".into(),
        requested["method"].as_str().unwrap().to_string(),
        "--out".into(),
        s(&second).to_string(),
    ];
    // a tolerance is recorded as requested only when it was given (null: the default)
    assert!(
        requested["atol"].is_null() && requested["rtol"].is_null(),
        "{requested}"
    );
    let rebuilt: Vec<&str> = rebuilt.iter().map(String::as_str).collect();
    run_ok(&rebuilt);
    for f in [
        "t.npy",
        "q.npy",
        "u.npy",
        "strain.npy",
        "tip_position.npy",
        "centerline.npy",
    ] {
        assert!(
            std::fs::read(first.join(f)).unwrap() == std::fs::read(second.join(f)).unwrap(),
            "{f} differs"
        );
    }
    assert_eq!(npy(&second.join("centerline.npy")).0[1], 9);
}

#[test]
fn datasets_models_and_model_runs_record_where_they_came_from() {
    let t0 = now_s();
    let ds = scratch("prov-ds");
    let ds_args = [
        "dataset",
        "single-tendon",
        "--set",
        "tendons.0.friction=0.6",
        "--random",
        "tendons.0.tension=-5:0",
        "--samples",
        "6",
        "--seed",
        "9",
        "--out",
        s(&ds),
    ];
    run_ok(&ds_args);
    let ds_meta = json(&ds.join("meta.json"));
    let p = &ds_meta["provenance"];
    check_common(p, &ds_args, t0);
    assert_eq!(p["seeds"], serde_json::json!({"plan": 9}));
    assert_eq!(
        p["overrides"],
        serde_json::json!(["tendons.0.friction=0.6"])
    );
    assert_eq!(p["scenario"]["sha256"], sha256_hex(PRESET_TEXT.as_bytes()));
    // what it recorded before is kept
    assert_eq!(ds_meta["seed"], 9);
    assert_eq!(ds_meta["scenario_toml"], p["scenario_toml"]);

    let model = scratch("prov-pod");
    let pod_args = ["pod", s(&ds), "--modes", "2", "--out", s(&model)];
    run_ok(&pod_args);
    let m_meta = json(&model.join("meta.json"));
    let p = &m_meta["provenance"];
    check_common(p, &pod_args, t0);
    assert_eq!(p["dataset"]["path"], s(&ds));
    assert_eq!(
        p["dataset"]["meta_sha256"],
        ds_meta["gvsrom"]["meta_sha256"]
    );
    assert_eq!(p["dataset"]["sha256"], ds_meta["gvsrom"]["sha256"]);

    let file = scratch("prov-pod-statics.json");
    let st_args = [
        "statics",
        "single-tendon",
        "--set",
        "tendons.0.friction=0.6",
        "--tension=-2",
        "--model",
        s(&model),
        "--json",
        s(&file),
    ];
    run_ok(&st_args);
    let doc = json(&file);
    let p = &doc["provenance"];
    check_common(p, &st_args, t0);
    assert_eq!(p["model"]["path"], s(&model));
    assert_eq!(p["model"]["meta_sha256"], m_meta["gvsrom"]["meta_sha256"]);
    let weights = std::fs::read(model.join("weights.safetensors")).unwrap();
    assert_eq!(
        p["model"]["sha256"]["weights.safetensors"],
        sha256_hex(&weights)
    );
    assert_eq!(doc["n_dof"], 2);
}

#[test]
fn an_autoencoder_modes_and_a_comparison_record_where_they_came_from() {
    let t0 = now_s();
    let ds = scratch("prov-ae-ds");
    run_ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-5:0",
        "--samples",
        "12",
        "--out",
        s(&ds),
    ]);
    let ds_meta = json(&ds.join("meta.json"));
    let model = scratch("prov-ae");
    let train_args = [
        "train",
        s(&ds),
        "--latent",
        "1",
        "--hidden-layers",
        "3",
        "--epochs",
        "30",
        "--seed",
        "4",
        "--out",
        s(&model),
    ];
    run_ok(&train_args);
    let m_meta = json(&model.join("meta.json"));
    let p = &m_meta["provenance"];
    check_common(p, &train_args, t0);
    assert_eq!(p["seeds"], serde_json::json!({"training": 4}));
    assert_eq!(p["dataset"]["path"], s(&ds));
    assert_eq!(p["dataset"]["sha256"], ds_meta["gvsrom"]["sha256"]);

    // the fixed step keeps the first-order form for a decoder (its M(q) can be nearly singular
    // where the decoder flattens), the second-order form for the full model and a POD-ROM
    let fixed = |name: &str, model: Option<&Path>| {
        let out = scratch(name);
        let mut a = vec!["simulate", "single-tendon", "--duration", "0.05"];
        a.extend([
            "--from-equilibrium",
            "--fixed-step",
            "0.01",
            "--out",
            s(&out),
        ]);
        if let Some(m) = model {
            a.extend(["--model", s(m)]);
        }
        run_ok(&a);
        let meta = json(&out.join("meta.json"));
        meta["provenance"]["integrator"]["form"].clone()
    };
    assert_eq!(fixed("prov-fixed-ae", Some(&model)), "first_order");
    assert_eq!(fixed("prov-fixed-hom", None), "second_order");

    // modes about an equilibrium: the scenario as run, the solver
    let modes = scratch("prov-modes.json");
    let modes_args = [
        "modes",
        "single-tendon",
        "--tension=-2",
        "--count",
        "2",
        "--json",
        s(&modes),
    ];
    run_ok(&modes_args);
    let doc = json(&modes);
    let p = &doc["provenance"];
    check_common(p, &modes_args, t0);
    assert_eq!(p["scenario"]["sha256"], sha256_hex(PRESET_TEXT.as_bytes()));
    let toml: toml::Table = p["scenario_toml"].as_str().unwrap().parse().unwrap();
    assert_eq!(toml["tendons"][0]["tension"].as_float(), Some(-2.0));
    assert!(p["solver"].is_object(), "{p}");

    // a comparison: both trajectories by their manifests' hashes (a POD-ROM: a 30-epoch
    // autoencoder is too rough to follow the motion)
    let pod = scratch("prov-cmp-pod");
    run_ok(&["pod", s(&ds), "--modes", "3", "--out", s(&pod)]);
    let hom = scratch("prov-cmp-hom");
    let rom = scratch("prov-cmp-rom");
    let sim = |out: &Path, model: Option<&Path>| {
        let mut a = vec![
            "simulate",
            "single-tendon",
            "--duration",
            "0.2",
            "--from-equilibrium",
            "--out",
            s(out),
        ];
        if let Some(m) = model {
            a.extend(["--model", s(m)]);
        }
        run_ok(&a);
    };
    sim(&hom, None);
    sim(&rom, Some(&pod));
    assert_eq!(fixed("prov-fixed-pod", Some(&pod)), "second_order");
    let report = scratch("prov-compare.json");
    let cmp_args = ["compare", s(&hom), s(&rom), "--json", s(&report)];
    run_ok(&cmp_args);
    let doc = json(&report);
    let p = &doc["provenance"];
    check_common(p, &cmp_args, t0);
    for (key, dir) in [("reference", &hom), ("run", &rom)] {
        let meta = json(&dir.join("meta.json"));
        assert_eq!(p[key]["path"], s(dir), "{p}");
        assert_eq!(p[key]["meta_sha256"], meta["gvsrom"]["meta_sha256"]);
        assert_eq!(p[key]["sha256"], meta["gvsrom"]["sha256"]);
    }
    assert_eq!(doc["reference"]["n_dof"], 33);
    assert_eq!(doc["run"]["n_dof"], 3);
    let tip_max = doc["comparison"]["tip_max"].as_f64().unwrap();
    assert!(tip_max.is_finite() && tip_max >= 0.0, "{doc}");
    // the report is an output of its own: replaced only with --force, never over an input
    let again = gvsrom(&cmp_args);
    assert!(!again.status.success());
    let over_input = gvsrom(&["compare", s(&hom), s(&rom), "--json", s(&hom), "--force"]);
    let stderr = String::from_utf8_lossy(&over_input.stderr);
    assert!(
        !over_input.status.success() && stderr.contains("--json"),
        "{stderr}"
    );
}
