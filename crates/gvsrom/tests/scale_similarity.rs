//! Geometric similarity: a rod scaled by `s` in every length, its material the same, under forces
//! scaled by `s²` and moments by `s³`, takes the same shape scaled by `s` (the bending angle
//! `F L² / EI` and the strains `F / EA` do not change), and vibrates `1/s` times as fast
//! (`ω ∝ √(EI / ρA L⁴)`). Dimensional analysis, independent of the code: a solver whose
//! convergence test held an absolute force (gvs-spec §8.3's floor of 1 N) called a micrometre
//! rod's straight start converged under any load.

mod common;

use common::{f64s, run_json, s as path_str, scratch};

/// The IV-A-like tapered arm scaled by `s`: 0.25 s long, radii 12.5 s → 5 s mm, a tendon with
/// friction (the capstan law depends on angles only; its smoothing `κ_ε` is a curvature, scaled
/// by `1/s`), a tip force and a tip moment; no gravity (the weight scales as `s³`).
fn scaled(s: f64) -> std::path::PathBuf {
    let l = 0.25 * s;
    let path = scratch(&format!("similar-{s:e}.toml"));
    let toml = format!(
        r#"name = "similar"
[material]
youngs_modulus = 6.17e5
poisson_ratio = 0.5
density = 1121
damping = 1e4

[[divisions]]
length = {l:e}
radius_start = {r0:e}
radius_end = {r1:e}
basis = {{ kind = "legendre", modes = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 4 }}

[[tendons]]
offset_start = [{d0:e}, {d1:e}]
offset_end = [{d2:e}, {d3:e}]
friction = 0.5
friction_smoothing = {k:e}
tension = {u:e}

[loads]
gravity = [0.0, 0.0, 0.0]

[[loads.point]]
x = {l:e}
force = [0.0, {fy:e}, {fz:e}]
moment = [{mx:e}, 0.0, 0.0]
"#,
        r0 = 0.0125 * s,
        r1 = 0.005 * s,
        d0 = 0.004 * s,
        d1 = 0.008 * s,
        d2 = -0.002 * s,
        d3 = 0.003 * s,
        u = -1.5 * s * s,
        fy = 0.05 * s * s,
        fz = -0.1 * s * s,
        mx = 2e-3 * s * s * s,
        k = 0.05 / s,
    );
    std::fs::write(&path, toml).unwrap();
    path
}

#[test]
fn a_rod_scaled_in_every_length_takes_the_same_shape_and_vibrates_inversely_faster() {
    let shape = |s: f64| {
        let (_, eq) = run_json(
            "statics",
            &format!("similar-{s:e}"),
            &[path_str(&scaled(s))],
        );
        let tip: Vec<f64> = f64s(&eq["tip_position"]).iter().map(|p| p / s).collect();
        let rot: Vec<f64> = (eq["tip_rotation"].as_array().unwrap().iter())
            .flat_map(f64s)
            .collect();
        (tip, rot)
    };
    let (tip, rot) = shape(1.0);
    // a large, three-dimensional deflection: the comparison means something
    let angle = ((rot[0] + rot[4] + rot[8] - 1.0) / 2.0).acos();
    assert!(
        angle > 0.5 && tip[1].abs() > 0.01,
        "{angle} rad, tip {tip:?}"
    );
    for s in [1e-4, 1e-2, 10.0] {
        let (tip_s, rot_s) = shape(s);
        for (k, (a, b)) in tip_s.iter().zip(&tip).enumerate() {
            assert!(
                (a - b).abs() < 1e-9,
                "s = {s}: tip/s [{k}] = {a} against {b} at s = 1"
            );
        }
        for (k, (a, b)) in rot_s.iter().zip(&rot).enumerate() {
            assert!(
                (a - b).abs() < 1e-9,
                "s = {s}: tip rotation [{k}] = {a} against {b} at s = 1"
            );
        }
    }
    // the modes about the rest shape: ω s the same at every scale
    let freqs = |s: f64| {
        let (_, m) = run_json(
            "modes",
            &format!("similar-modes-{s:e}"),
            &[path_str(&scaled(s)), "--count", "4"],
        );
        (m["modes"].as_array().unwrap().iter())
            .map(|m| m["frequency_hz"].as_f64().unwrap() * s)
            .collect::<Vec<_>>()
    };
    let reference = freqs(1.0);
    for s in [1e-4, 10.0] {
        for (k, (a, b)) in freqs(s).iter().zip(&reference).enumerate() {
            assert!(
                ((a - b) / b).abs() < 1e-7,
                "s = {s}: mode {k}: f s = {a} against {b} at s = 1"
            );
        }
    }
}
