//! gvsrom against an independent implementation of the same GVS model: soromox 0.5.0 (JAX), whose
//! GVS rod with one segment and a Legendre basis of order 2 in all six strains is the model of
//! `scripts/peers/gravity-release.toml` at `divisions.0.basis.order=2` (18 coordinates, 5 Gauss
//! points, `K = diag(GJ, EI, EI, EA, GA, GA)`, rotational inertia, no damping). The soromox numbers
//! are a fixture (`tests/peers/soromox-gravity-release-order2.csv`, made by
//! `scripts/peers/soromox_release.py`; soromox is a 600 MB JAX install, not a test dependency).
//!
//! - The sagged cantilever: the equilibrium under gravity, its tip 0.245 m (49 % of the length)
//!   below the base's line, where linear beam theory says 0.307 m: geometrically nonlinear.
//! - The release: 1 s of the undamped rod falling from straight under gravity, the tip falling
//!   0.40 m; the two codes integrate with different methods (SDIRK4 here, Tsit5 there), so
//!   they agree to their tolerances only if mass matrix, Coriolis, elastic and gravity forces agree.
//! - A tendon: `scripts/peers/tendon-statics.toml`, the same rod without gravity and a full-length
//!   frictionless tendon pulled with 2 N, at a constant offset and on an oblique path. soromox
//!   derives the tendon's generalized force from the path length, `−T ∂ℓ/∂q`
//!   (`scripts/peers/soromox_tendon.py`); gvsrom from the internal wrench of gvs-spec §7.6. The
//!   equilibria agree to rounding (observed 1.5e-13 m).
//! - A rod pre-curved and pre-twisted onto a helix, released under gravity: a 3-D motion
//!   (`tests/peers/soromox-precurved-release-order2.csv`, soromox at rtol 1e-10), within 1.4e-7 m.

mod common;

use common::{json, npy, run_ok, s, scratch};

const SCENARIO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../scripts/peers/gravity-release.toml"
);
const FIXTURE: &str = include_str!("peers/soromox-gravity-release-order2.csv");
const PRECURVED: &str = include_str!("peers/soromox-precurved-release-order2.csv");
const TENDON: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../scripts/peers/tendon-statics.toml"
);

/// A soromox fixture's static tip (if it records one) and its 101 rows `[t, x, y, z]`.
fn fixture(text: &str) -> (Option<[f64; 3]>, Vec<[f64; 4]>) {
    let mut static_tip = None;
    let mut rows = Vec::new();
    for line in text.lines() {
        let values =
            |rest: &str| -> Vec<f64> { rest.split(',').map(|v| v.parse().unwrap()).collect() };
        if let Some(rest) = line.strip_prefix("# static_tip,") {
            let v = values(rest);
            static_tip = Some([v[0], v[1], v[2]]);
        } else if !line.starts_with('#') && !line.starts_with("t,") {
            let v = values(line);
            rows.push([v[0], v[1], v[2], v[3]]);
        }
    }
    assert_eq!(rows.len(), 101);
    (static_tip, rows)
}

/// The gravity release's fixture: its static tip and rows.
fn soromox() -> ([f64; 3], Vec<[f64; 4]>) {
    let (static_tip, rows) = fixture(FIXTURE);
    (static_tip.unwrap(), rows)
}

/// `gvsrom simulate` of the peer scenario at order 2 with the `--set` overrides `extra`, over 1 s
/// at tight tolerances; the largest tip distance [m] to soromox's `expected` rows (whose times
/// must be the run's).
fn release_against(name: &str, extra: &[&str], expected: &[[f64; 4]]) -> f64 {
    let dir = scratch(name);
    let mut args = vec!["simulate", SCENARIO, "--set", "divisions.0.basis.order=2"];
    for e in extra {
        args.extend(["--set", e]);
    }
    args.extend([
        "--duration",
        "1",
        "--rtol",
        "1e-8",
        "--atol",
        "1e-10",
        "--out",
        s(&dir),
    ]);
    run_ok(&args);
    let (shape, t) = npy(&dir.join("t.npy"));
    assert_eq!(shape, vec![expected.len()]);
    let (_, tip) = npy(&dir.join("tip_position.npy"));
    let mut worst: f64 = 0.0;
    for (i, row) in expected.iter().enumerate() {
        assert!((t[i] - row[0]).abs() < 1e-12, "sample {i} at t = {}", t[i]);
        let d = (0..3)
            .map(|k| (tip[3 * i + k] - row[k + 1]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    worst
}

#[test]
fn the_sagged_cantilever_agrees_with_soromox_to_a_tenth_of_a_micrometre() {
    let (expected, _) = soromox();
    let tip = statics_tip(SCENARIO, "peer-soromox-statics.json", 2, &[]);
    // the tip sags far: a linear model would be 0.06 m off here
    assert!(expected[2] < -0.2, "fixture's sag {}", expected[2]);
    assert_tip_near("sagged cantilever", &tip, &expected, 1e-7);
}

#[test]
fn the_undamped_release_under_gravity_agrees_with_soromox_over_a_second() {
    let (_, expected) = soromox();
    let worst = release_against("peer-soromox-release", &[], &expected);
    let deepest = expected.iter().map(|r| r[3]).fold(0.0, f64::min);
    // the swing is large (0.40 m of a 0.5 m rod) and the two agree to a micrometre (observed
    // 2.6e-7 m: the tolerances of the two integrators)
    assert!(deepest < -0.3, "fixture's deepest tip {deepest}");
    assert!(worst <= 1e-6, "tip {worst:.3e} m from soromox's at worst");
}

#[test]
fn a_precurved_rod_released_under_gravity_moves_in_3d_as_in_soromox() {
    // the rod at rest on a helix (reference strain [2, 0, 3, 1, 0, 0]: 1 rad of twist, 1.5 rad of
    // bending about z), released under gravity along −z: a motion in all three directions, with the
    // twist coupling bending about y and z, where the straight rod's release stays in its plane.
    // No coordinates are mapped between the codes: both start at q = 0, q̇ = 0.
    let (_, expected) = fixture(PRECURVED);
    let worst = release_against(
        "peer-soromox-precurved",
        &["divisions.0.reference_strain=[2, 0, 3, 1, 0, 0]"],
        &expected,
    );
    let span = |k: usize| {
        let v = expected.iter().map(|r| r[k]);
        v.clone().fold(f64::MIN, f64::max) - v.fold(f64::MAX, f64::min)
    };
    // the tip sweeps 0.12 m across and 0.46 m down; the two agree to 0.14 µm (observed 1.37e-7 m)
    assert!(
        span(2) > 0.1 && span(3) > 0.4,
        "fixture's sweep {} {}",
        span(2),
        span(3)
    );
    assert!(worst <= 1e-6, "tip {worst:.3e} m from soromox's at worst");
}

/// Every component of gvsrom's `tip` within `tol` [m] of soromox's `expected`.
fn assert_tip_near(case: &str, tip: &[f64], expected: &[f64; 3], tol: f64) {
    for k in 0..3 {
        assert!(
            (tip[k] - expected[k]).abs() <= tol,
            "{case}: tip component {k}: gvsrom {} against soromox {}",
            tip[k],
            expected[k]
        );
    }
}

/// The equilibrium's tip of `scenario` at Legendre order `order`, with `extra` overrides.
fn statics_tip(scenario: &str, name: &str, order: usize, extra: &[&str]) -> Vec<f64> {
    let out = scratch(name);
    let order = format!("divisions.0.basis.order={order}");
    let mut args = vec!["statics", scenario, "--set", &order];
    for e in extra {
        args.extend(["--set", e]);
    }
    args.extend(["--json", s(&out)]);
    run_ok(&args);
    json(&out)["tip_position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

#[test]
fn a_pulled_tendon_bends_the_rod_as_in_soromox_to_rounding() {
    // soromox 0.5.0, `python scripts/peers/soromox_tendon.py --case const|linear --order 2|4`
    // (GVS, one segment, five Gauss points; residual ≤ 2.1e-17)
    let cases: [(&str, usize, &[&str], [f64; 3]); 4] = [
        (
            "peer-tendon-const-2",
            2,
            &[],
            [0.49881808123760935, 0.0, 0.02542658408248584],
        ),
        (
            "peer-tendon-const-4",
            4,
            &[],
            [0.49881808123760935, 0.0, 0.02542658408248584],
        ),
        (
            "peer-tendon-oblique-2",
            2,
            &[
                "tendons.0.offset_start=[0.0,0.01]",
                "tendons.0.offset_end=[0.0,0.003]",
            ],
            [0.49894102847321214, 0.0, 0.024382836800395553],
        ),
        (
            "peer-tendon-oblique-4",
            4,
            &[
                "tendons.0.offset_start=[0.0,0.01]",
                "tendons.0.offset_end=[0.0,0.003]",
            ],
            [0.49894102847314536, 0.0, 0.024382836800596414],
        ),
    ];
    for (name, order, extra, expected) in cases {
        let tip = statics_tip(TENDON, name, order, extra);
        assert_tip_near(name, &tip, &expected, 1e-10);
    }
    // the closed form of the constant offset: a constant moment T d and axial force −T, so the
    // curvature T d / EI (0.2037 1/m) per reference length and the stretch 1 − T / EA: an arc of
    // angle κ L and radius (1 − T / EA) / κ
    let (t, d, r, e): (f64, f64, f64, f64) = (2.0, 0.008, 0.01, 1e7);
    let ei = e * std::f64::consts::PI * r.powi(4) / 4.0;
    let ea = e * std::f64::consts::PI * r * r;
    let (kappa, stretch) = (t * d / ei, 1.0 - t / ea);
    let x = stretch * (kappa * 0.5).sin() / kappa;
    let z = stretch * (1.0 - (kappa * 0.5).cos()) / kappa;
    let tip = statics_tip(TENDON, "peer-tendon-closed-form", 2, &[]);
    assert!((tip[0] - x).abs() <= 1e-9, "tip x {} against {x}", tip[0]);
    assert!((tip[2] - z).abs() <= 1e-9, "tip z {} against {z}", tip[2]);
}
