//! Tests of the plausibility check: the estimates against linear-beam closed forms, the paper's
//! presets inside the bounds, absurd and overflowing loads refused by name, run bounds.

use super::estimates::{estimates, Estimate};
use super::{check, largest_load, MAX_BENDING};
use crate::build::Built;
use crate::error::ScenarioError;
use crate::presets;
use crate::scenario::Scenario;
use std::f64::consts::PI;

fn built(preset: &str, overrides: &[String]) -> Result<Built, ScenarioError> {
    crate::build(&presets::load(preset, overrides)?)
}

/// A uniform rod: L = 0.5 m, r = 0.01 m, E = 1e6 Pa, ν = 0.5, ρ = 1000, no gravity, no loads.
const UNIFORM: &str = r#"
    [material]
    youngs_modulus = 1e6
    poisson_ratio = 0.5
    density = 1000
    [[divisions]]
    length = 0.5
    radius = 0.01
    basis = { kind = "legendre", modes = ["bend_y"], order = 2 }
    [loads]
    gravity = [0, 0, 0]
"#;

fn uniform(overrides: &[&str]) -> Result<Built, ScenarioError> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    crate::build(&Scenario::from_toml("uniform", UNIFORM, &o)?)
}

fn only_estimate(b: &Built) -> Estimate {
    let mut e = estimates(&b.into(), &b.u, 1.0, false);
    e.retain(|e| e.severity() > 0.0);
    assert_eq!(e.len(), 1);
    e.pop().unwrap()
}

// uniform rod: EI = E π r⁴/4, EA = E π r², GA = EA/3 (ν = 0.5)
const L: f64 = 0.5;
fn ei() -> f64 {
    1e6 * PI * 1e-8 / 4.0
}
fn ea() -> f64 {
    1e6 * PI * 1e-4
}

#[test]
fn estimates_match_linear_beam_closed_forms_on_a_uniform_rod() {
    // tendon at constant offset d over the whole rod: θ = |u| d L / EI, ε = |u| / EA
    let b = uniform(&[
        "tendons.0.offset_start=[0, 0.005]",
        "tendons.0.offset_end=[0, 0.005]",
        "tendons.0.tension=-2",
    ])
    .unwrap();
    let e = only_estimate(&b);
    assert!(
        (e.bending - 2.0 * 0.005 * L / ei()).abs() < 1e-8 * e.bending,
        "{}",
        e.bending
    );
    assert!((e.strain - 2.0 / ea()).abs() < 1e-8 * e.strain);
    // tendon on the second half only: θ = |u| d (L/2) / EI
    let b = uniform(&[
        "tendons.0.offset_start=[0, 0.005]",
        "tendons.0.offset_end=[0, 0.005]",
        "tendons.0.x_start=0.25",
        "tendons.0.tension=-2",
    ])
    .unwrap();
    let e = only_estimate(&b);
    assert!((e.bending - 2.0 * 0.005 * 0.25 / ei()).abs() < 1e-8 * e.bending);
    // tip moment M: θ = M L / EI
    let b = uniform(&["loads.point.0.x=0.5", "loads.point.0.moment=[0, 0.01, 0]"]).unwrap();
    let e = only_estimate(&b);
    assert!((e.bending - 0.01 * L / ei()).abs() < 1e-8 * e.bending);
    assert_eq!(e.strain, 0.0);
    // tip force F: θ = F L² / (2 EI), shear strain F / GA
    let b = uniform(&["loads.point.0.x=0.5", "loads.point.0.force=[0, 0, -0.01]"]).unwrap();
    let e = only_estimate(&b);
    assert!((e.bending - 0.01 * L * L / (2.0 * ei())).abs() < 1e-8 * e.bending);
    assert!((e.strain - 0.01 / (ea() / 3.0)).abs() < 1e-8 * e.strain);
    // a follower force along the rod's axis only compresses it: no bending, strain F / GA
    let b = uniform(&["loads.point.0.x=0.5", "loads.point.0.force=[-0.3, 0, 0.01]"]).unwrap();
    let e = only_estimate(&b);
    assert!((e.bending - 0.01 * L * L / (2.0 * ei())).abs() < 1e-8 * e.bending);
    let f = 0.3f64.hypot(0.01);
    assert!((e.strain - f / (ea() / 3.0)).abs() < 1e-8 * e.strain);
    // a world-fixed force turns the rod at most until it lies along it: the linear beam's
    // F L² / (2 EI) = 80 rad is capped at π (a hanging rod pulled down along its axis, which was
    // refused as ~80 turns of bending); its strain still counts whole
    let world = |force: &str| {
        uniform(&[
            "loads.point.0.x=0.5",
            force,
            "loads.point.0.frame=\"global\"",
        ])
    };
    let e = only_estimate(&world("loads.point.0.force=[-5, 0, 0]").unwrap());
    assert!(5.0 * L * L / (2.0 * ei()) > 25.0 * PI);
    assert_eq!(e.bending, PI);
    assert!((e.strain - 5.0 / (ea() / 3.0)).abs() < 1e-8 * e.strain);
    // below the cap, the linear beam's angle (the whole force, whatever its direction)
    let e = only_estimate(&world("loads.point.0.force=[0.001, 0, 0]").unwrap());
    assert!((e.bending - 0.001 * L * L / (2.0 * ei())).abs() < 1e-8 * e.bending);
    // a world-fixed force too large for any rod is still refused, by its strain
    let err = world("loads.point.0.force=[-500, 0, 0]")
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("loads.point[0].force") && err.contains("strain"),
        "{err}"
    );
    // gravity: θ = ρ A g L³ / (6 EI) (trapezoid on a quadratic moment: O(h²) ≈ 1e-4 relative)
    // (a tenth of Earth's, so that it turns the rod by less than π, the cap below)
    let b = uniform(&["loads.gravity=[0, 0, -0.981]"]).unwrap();
    let e = only_estimate(&b);
    let w = 1000.0 * PI * 1e-4 * 0.981;
    let theta = w * L.powi(3) / (6.0 * ei());
    assert!(
        (e.bending - theta).abs() < 1e-3 * theta,
        "{} vs {theta}",
        e.bending
    );
    // its strain: the hanging rod's stretch at the clamp, w L / EA
    assert!((e.strain - w * L / ea()).abs() < 1e-9 * e.strain);
    // a rod so soft that the linear beam would turn it by far more than π only droops: capped
    let b = uniform(&["loads.gravity=[0, 0, -9.81]", "material.youngs_modulus=1e5"]).unwrap();
    let e = only_estimate(&b);
    assert_eq!(e.bending, PI);
    // uniform moment density m on the whole rod: θ = m L² / (2 EI)
    let b = uniform(&[
        "loads.distributed.0.kind=uniform",
        "loads.distributed.0.moment=[0, 0.02, 0]",
    ])
    .unwrap();
    let e = only_estimate(&b);
    assert!((e.bending - 0.02 * L * L / (2.0 * ei())).abs() < 1e-8 * e.bending);
    // a triangular pulse of total moment Mt wholly inside: θ ≥ Mt (c − h) / EI and
    // ≤ Mt (c + h) / EI (the moment is Mt up to c − h, decreasing to 0 at c + h)
    let b = uniform(&[
        // enough points to resolve the pulse (`prepare_loads` refuses it on the default 5)
        "divisions.0.quadrature.gauss=40",
        "loads.distributed.0.kind=triangular_pulse",
        "loads.distributed.0.center=0.25",
        "loads.distributed.0.width=0.1",
        "loads.distributed.0.magnitude=0.01",
        "loads.distributed.0.convention=total",
    ])
    .unwrap();
    let e = only_estimate(&b);
    assert!(
        e.bending > 0.01 * 0.2 / ei() && e.bending < 0.01 * 0.3 / ei(),
        "{}",
        e.bending
    );
    // symmetric pulse: the exact value is Mt · c / EI
    assert!((e.bending - 0.01 * 0.25 / ei()).abs() < 1e-3 * e.bending);
}

#[test]
fn paper_presets_pass_over_their_documented_ranges() {
    for u in [-30.0, 30.0] {
        built("single-tendon", &[format!("tendons.0.tension={u}")]).unwrap();
        let all: Vec<String> = (0..6).map(|k| format!("tendons.{k}.tension={u}")).collect();
        built("six-tendon", &all).unwrap();
        let alternating: Vec<String> = (0..6)
            .map(|k| format!("tendons.{k}.tension={}", if k % 2 == 0 { u } else { -u }))
            .collect();
        built("six-tendon", &alternating).unwrap();
    }
    // the paper's IV-B range, ±5 N·m in total (the coiled beam), and its peak reading ±5 N·m/m
    for preset in ["soft-beam", "soft-beam-peak"] {
        for m in [-5.0, 5.0] {
            for i in 0..=8 {
                built(
                    preset,
                    &[
                        format!("loads.distributed.0.magnitude={m}"),
                        format!("loads.distributed.0.center={}", i as f64 * 0.1),
                    ],
                )
                .unwrap();
            }
        }
    }
    // with a margin: single-tendon at ±30 N, the tightest in strain, at ~24 rad and strain 0.62
    let b = built("single-tendon", &["tendons.0.tension=-30".into()]).unwrap();
    let e = &estimates(&(&b).into(), &b.u, 1.0, false)[0];
    assert!(
        e.bending < MAX_BENDING / 5.0 && e.strain < 0.7,
        "{} {}",
        e.bending,
        e.strain
    );
    // the tightest in bending: 5 N·m in total reaching the tip (X₀ = L − w/2 = 0.76 m) implies
    // θ = M X₀ / EI ≈ 96 rad (the symmetric pulse's closed form above), under half the bound
    let b = built(
        "soft-beam",
        &[
            "loads.distributed.0.magnitude=5".into(),
            "loads.distributed.0.center=0.76".into(),
        ],
    )
    .unwrap();
    let e = only_estimate(&b);
    let theta = 5.0 * 0.76 / (1e6 * PI * 0.015f64.powi(4) / 4.0);
    assert!(
        (e.bending - theta).abs() < 1e-3 * theta && e.bending < MAX_BENDING / 2.0,
        "{} vs {theta}",
        e.bending
    );
}

#[test]
fn absurd_tension_is_rejected_naming_the_tendon_and_its_strains() {
    let e = built("single-tendon", &["tendons.0.tension=1e300".into()])
        .err()
        .unwrap()
        .to_string();
    for needle in [
        "tendons[0].tension = 1e300 N",
        "bending of ~",
        "rad over the rod (accepted <= 200 rad)",
        "axial strain of ~",
        "(accepted <= 1)",
        "far beyond",
    ] {
        assert!(e.contains(needle), "lacks `{needle}`: {e}");
    }
    assert!(!e.contains("NaN"), "{e}");
}

#[test]
fn overflowing_loads_reject_without_nan() {
    // a pulse of total 1e308 over the paper's width: its peak 2·1e308/0.08 overflows to inf
    let e = built(
        "soft-beam",
        &[
            "loads.distributed.0.magnitude=1e308".into(),
            "loads.distributed.0.convention=total".into(),
        ],
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("loads.distributed[0].magnitude = 1e308 N*m") && e.contains("~inf rad"),
        "{e}"
    );
    // a moment implies no strain: the message does not claim one
    assert!(!e.contains("strain"), "{e}");
    assert!(!e.contains("NaN"), "{e}");
    // a point force of 1e308 at the tip and 1e308 moment: inf, not NaN
    let e = uniform(&[
        "loads.point.0.x=0.5",
        "loads.point.0.force=[1e308, 1e308, 0]",
        "loads.point.0.moment=[0, 1e308, 0]",
    ])
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("loads.point[0] (force [1e308, 1e308, 0] N"),
        "{e}"
    );
    assert!(e.contains("inf") && !e.contains("NaN"), "{e}");
    // gravity at its bound on a very soft, heavy rod
    let e = uniform(&[
        "loads.gravity=[0, 0, -1e4]",
        "material.youngs_modulus=1",
        "material.density=1e5",
    ])
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("loads.gravity = [0, 0, -10000] m/s^2") && e.contains("100000 kg/m^3"),
        "{e}"
    );
}

#[test]
fn run_bounds_scale_the_loads_and_name_the_bound() {
    let b = built("single-tendon", &["tendons.0.tension=-3".into()]).unwrap();
    // the scenario's own tension, by its sign
    assert!(check(&b, &[3.0], 1.0).is_ok());
    let e = check(&b, &[3000.0], 1.0).unwrap_err().to_string();
    assert!(e.contains("tendons[0].tension up to |u| = 3000 N"), "{e}");
    // gravity implies ~0.83 rad: a load factor of 1000 makes it ~830 rad
    let e = check(&b, &[3.0], 1000.0).unwrap_err().to_string();
    assert!(
        e.contains("loads.gravity") && e.contains("scaled by λ = 1000"),
        "{e}"
    );
    let e = check(&b, &[3.0, 1.0], 1.0).unwrap_err().to_string();
    assert!(e.contains("2 tension bounds given for 1 tendons"), "{e}");
}

#[test]
fn largest_load_names_the_dominant_load() {
    let b = built("single-tendon", &["tendons.0.tension=-3".into()]).unwrap();
    let s = largest_load(&b, &b.u, 1.0).unwrap();
    assert!(
        s.starts_with("the largest load is tendons[0].tension = -3 N (implied bending ~2.4 rad"),
        "{s}"
    );
    // without tension, gravity is the largest
    let s = largest_load(&b, &[0.0], 1.0).unwrap();
    assert!(s.starts_with("the largest load is loads.gravity"), "{s}");
    let b = uniform(&[]).unwrap();
    assert_eq!(largest_load(&b, &[], 1.0), None);
}
