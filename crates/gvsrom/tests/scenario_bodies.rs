//! `[[bodies]]` of the scenario format (rigid bodies fixed to the rod) reached through the TOML:
//! a tip payload against its weight as a world-fixed force and against the closed-form frequency
//! of a cantilever carrying a tip mass, the point it adds, the summaries, and the errors of bad
//! bodies naming the field.

mod common;

use common::{npy, run_json, run_ok, s as path_str, scratch};
use gvsrom::statics::solve;
use gvsrom::Scenario;
use std::f64::consts::PI;

/// A uniform rod, r = 5 mm, L = 0.5 m, E = 1 MPa, ρ = 1000 kg/m³ (39.3 g), bending in x-z only.
const ROD: &str = r#"
    name = "payload"
    [material]
    youngs_modulus = 1e6
    poisson_ratio = 0.5
    density = 1000
    damping = 0
    [[divisions]]
    length = 0.5
    radius = 0.005
    basis = { kind = "legendre", modes = ["bend_y", "elongation", "shear_z"], order = 6 }
    quadrature = { gauss = 21 }
"#;

const PAYLOAD: &str = r#"
    [[bodies]]
    x = 0.5
    mass = 0.01
"#;

fn scenario(text: &str, overrides: &[&str]) -> Result<Scenario, String> {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scenario::from_toml("test", text, &overrides).map_err(|e| e.to_string())
}

fn built(text: &str, overrides: &[&str]) -> Result<gvsrom::Built, String> {
    gvsrom::build(&scenario(text, overrides)?).map_err(|e| e.to_string())
}

#[test]
fn a_tip_payload_weighs_like_its_weight_as_a_world_fixed_tip_force() {
    // stiffer than the preset rod, so that the payload moves the tip by centimetres
    let stiff = "material.youngs_modulus=1e8";
    let with_body = solve(&built(&format!("{ROD}{PAYLOAD}"), &[stiff]).unwrap()).unwrap();
    let with_force = solve(
        &built(
            ROD,
            &[
                stiff,
                "loads.point.0.x=0.5",
                &format!("loads.point.0.force=[0, 0, {}]", -0.01 * 9.81),
                "loads.point.0.frame=\"global\"",
            ],
        )
        .unwrap(),
    )
    .unwrap();
    let bare = solve(&built(ROD, &[stiff]).unwrap()).unwrap();
    for i in 0..3 {
        assert!(
            (with_body.tip_position[i] - with_force.tip_position[i]).abs() < 1e-10,
            "{:?} vs {:?}",
            with_body.tip_position,
            with_force.tip_position
        );
    }
    let moved = (0..3).map(|i| (with_body.tip_position[i] - bare.tip_position[i]).abs());
    assert!(
        moved.fold(0.0, f64::max) > 0.01,
        "{:?} vs {:?}",
        with_body.tip_position,
        bare.tip_position
    );
}

/// Euler–Bernoulli cantilever with a tip mass `μ ρAL`: `ω = β² √(EI / ρAL⁴)`, β the least root of
/// `1 + cos β cosh β + μ β (cos β sinh β − sin β cosh β) = 0`; `μ = 0.01 kg / 0.0393 kg = 0.255`.
#[test]
fn modes_of_a_cantilever_with_a_tip_mass_match_the_closed_form() {
    let b = built(&format!("{ROD}{PAYLOAD}"), &["loads.gravity=[0, 0, 0]"]).unwrap();
    let (_, modes) = gvsrom::modes::compute(&b, 3).unwrap();
    let (l, r, e, rho) = (0.5, 0.005, 1e6, 1000.0);
    let (area, inertia) = (PI * r * r, PI * r.powi(4) / 4.0);
    let mu = 0.01 / (rho * area * l);
    let f = |b: f64| 1.0 + b.cos() * b.cosh() + mu * b * (b.cos() * b.sinh() - b.sin() * b.cosh());
    let (mut lo, mut hi) = (0.5, 1.875);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let beta = 0.5 * (lo + hi);
    let f1 = beta * beta / (2.0 * PI) * (e * inertia / (rho * area * l.powi(4))).sqrt();
    let got = modes.modes[0].frequency_hz;
    assert!(
        ((got - f1) / f1).abs() < 1e-3,
        "f1 = {got} Hz, closed form {f1} Hz"
    );
}

#[test]
fn a_body_adds_its_point_and_the_summaries_name_it() {
    let text = format!("{ROD}{PAYLOAD}");
    let b = built(
        &text,
        &[
            "bodies.0.x=0.3",
            "bodies.0.center=[0.01, 0, 0]",
            "bodies.0.inertia=[2e-6, 1.5e-6, 1.5e-6]",
        ],
    )
    .unwrap();
    let plain = built(ROD, &[]).unwrap();
    assert_eq!(b.model.disc.n_points(), plain.model.disc.n_points() + 1);
    assert!(b.model.disc.point_at(0.3).is_some());
    let s = scenario(&text, &[]).unwrap();
    let described = gvsrom::build::describe(&s, &built(&text, &[]).unwrap());
    assert!(described.contains("1 rigid body (0.01 kg)"), "{described}");
    assert_eq!(
        gvsrom::build::body_lines(&b),
        ["0.01 kg at X = 0.3 m, centre of mass [0.01, 0, 0] m, inertia [2e-6, 1.5e-6, 1.5e-6] kg·m²"]
    );
    let tensor = built(
        &text,
        &["bodies.0.inertia=[[2e-6, 1e-7, 0], [1e-7, 1.5e-6, 0], [0, 0, 1.5e-6]]"],
    )
    .unwrap();
    assert!(gvsrom::build::body_lines(&tensor)[0].contains("inertia tensor [2e-6, 1e-7, 0,"));
}

#[test]
fn bad_bodies_are_refused_naming_the_field() {
    let text = format!("{ROD}{PAYLOAD}");
    for (set, expected) in [
        (
            "bodies.0.x=0.7",
            "`bodies[0].x`: 0.7 (expected an abscissa in [0, 0.5] m)",
        ),
        (
            "bodies.0.mass=-1",
            "`bodies[0].mass`: -1 (expected a finite number >= 0 kg)",
        ),
        (
            "bodies.0.inertia=[1, 2]",
            "`bodies[0].inertia`: [1, 2] is not an inertia",
        ),
        ("bodies.0.inertia=[1e-6, 1e-6, 5e-6]", "are not a solid's"),
        (
            "bodies.0.inertia=[[1e-6, 1e-7, 0], [0, 1e-6, 0], [0, 0, 1e-6]]",
            "not symmetric",
        ),
        ("bodies.0.centre=[0, 0, 0]", "unknown field `centre`"),
        (
            "bodies.0.center=[1, 2, 3, 4]",
            "`bodies[0].center`: 4 values given; expected 3 values `[x, y, z]` [m]",
        ),
        (
            "bodies.0.mass=1e6",
            "bodies[0].mass = 1000000 kg under gravity 9.81 m/s^2 implies",
        ),
    ] {
        let e = built(&text, &[set]).err().unwrap_or_default();
        assert!(e.contains(expected), "{set}: {e}");
    }
}

/// The outputs say where the payload is: `statics --json`'s `bodies` (section and centre of mass,
/// `center = section + R c` with the tip rotation), `simulate`'s `body_positions.npy` (samples ×
/// bodies × 2 × 3, the section being the tip) with `n_bodies` and the bodies in `meta.json`'s
/// physics, and `plot` draws both.
#[test]
fn outputs_record_where_the_payload_is_and_plot_draws_it() {
    let file = scratch("payload.toml");
    let text = format!("{ROD}{PAYLOAD}center = [0.02, 0.0, -0.01]\n");
    std::fs::write(&file, text).unwrap();
    let (_, doc) = run_json("statics", "payload-statics", &[path_str(&file)]);
    let body = &doc["bodies"][0];
    let v = |x: &serde_json::Value| -> Vec<f64> { common::f64s(x) };
    let (section, center, tip) = (
        v(&body["section"]),
        v(&body["center"]),
        v(&doc["tip_position"]),
    );
    let r: Vec<Vec<f64>> = doc["tip_rotation"]
        .as_array()
        .unwrap()
        .iter()
        .map(v)
        .collect();
    for i in 0..3 {
        assert!((section[i] - tip[i]).abs() < 1e-15);
        let expected = section[i] + r[i][0] * 0.02 + r[i][2] * -0.01;
        assert!(
            (center[i] - expected).abs() < 1e-15,
            "{center:?} vs section + R c"
        );
    }
    assert_eq!(body["mass"].as_f64(), Some(0.01));
    let figs = scratch("payload-statics-figures");
    let json = scratch("payload-statics.json");
    run_ok(&["statics", path_str(&file), "--json", path_str(&json)]);
    run_ok(&["plot", path_str(&json), "--out", path_str(&figs)]);
    assert!(figs.join("rod_side.png").is_file());

    let out = scratch("payload-run");
    run_ok(&[
        "simulate",
        path_str(&file),
        "--duration",
        "0.05",
        "--out",
        path_str(&out),
    ]);
    let (shape, bodies) = npy(&out.join("body_positions.npy"));
    let (_, tips) = npy(&out.join("tip_position.npy"));
    let samples = tips.len() / 3;
    assert_eq!(shape, [samples, 1, 2, 3]);
    for k in 0..samples {
        for i in 0..3 {
            assert!((bodies[6 * k + i] - tips[3 * k + i]).abs() < 1e-15);
        }
    }
    let meta = common::json(&out.join("meta.json"));
    assert_eq!(meta["n_bodies"], 1);
    assert_eq!(meta["physics"]["bodies"][0]["mass"].as_f64(), Some(0.01));
    let figs = scratch("payload-run-figures");
    run_ok(&["plot", path_str(&out), "--out", path_str(&figs)]);
    assert!(figs.join("rod_animation.gif").is_file());
}

/// A reduced model over payloads: a dataset drawing the body's mass, its POD, used at a mass inside
/// the range; a scenario whose body moved names the body behind the point the model lacks.
#[test]
fn a_model_over_payload_masses_names_a_moved_body() {
    let file = scratch("payload-rom.toml");
    // stiffer than ROD, so that the payload moves the tip by centimetres
    let stiff = ROD.replace("youngs_modulus = 1e6", "youngs_modulus = 1e8");
    std::fs::write(&file, format!("{stiff}{PAYLOAD}")).unwrap();
    let (data, model) = (scratch("payload-rom-data"), scratch("payload-rom-model"));
    let f = path_str(&file);
    run_ok(&[
        "dataset",
        f,
        "--random",
        "bodies.0.mass=0:0.02",
        "--samples",
        "20",
        "--out",
        path_str(&data),
    ]);
    run_ok(&[
        "pod",
        path_str(&data),
        "--modes",
        "3",
        "--out",
        path_str(&model),
    ]);
    // the reduced model carries the body: its tip is the full model's, not the bare rod's
    let tip = |name: &str, extra: &[&str]| -> Vec<f64> {
        let mut args = vec![f, "--set", "bodies.0.mass=0.015"];
        args.extend_from_slice(extra);
        common::f64s(&run_json("statics", name, &args).1["tip_position"])
    };
    let full = tip("payload-rom-full", &[]);
    let reduced = tip("payload-rom-reduced", &["--model", path_str(&model)]);
    let bare = tip("payload-rom-bare", &["--set", "bodies.0.mass=0"]);
    let dist = |a: &[f64], b: &[f64]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    assert!(
        dist(&full, &bare) > 0.02,
        "the payload moves the tip: {full:?} vs {bare:?}"
    );
    // within 0.1 % of L = 0.5 m
    assert!(
        dist(&reduced, &full) < 5e-4,
        "reduced {reduced:?} vs full {full:?}"
    );
    common::expect_error(
        &[
            "statics",
            f,
            "--model",
            path_str(&model),
            "--set",
            "bodies.0.x=0.3",
        ],
        &["this scenario has a point at X = 0.3 m (bodies[0].x) that the model's lacks"],
    );
}
