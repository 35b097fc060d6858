//! Physics checks on the built-in presets: the analytic statics Jacobian against central finite
//! differences at each preset's equilibrium (gvs-spec §10.3.9, relative error ≤ 1e-6), and the
//! six-tendon symmetry (gvs-spec §10.2): pulling a tendon or the one 120° away gives configurations
//! related by a 120° rotation about the rod axis.

use gvs::solve::statics::solve_statics;
use nalgebra::{DMatrix, DVector, Rotation3, Vector3};

fn built(preset: &str, overrides: &[&str]) -> gvsrom::Built {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    gvsrom::build(&gvsrom::presets::load(preset, &o).unwrap()).unwrap()
}

fn jacobian_error(b: &gvsrom::Built) -> f64 {
    let m = &b.model;
    let n = m.n_dof();
    let q = solve_statics(m, &b.u, &b.loads, None, &b.options)
        .unwrap()
        .q;
    let pl = m.prepare_loads(&b.loads).unwrap();
    let mut ws = m.workspace();
    let mut an = DMatrix::zeros(n, n);
    m.statics_jacobian(&q, &b.u, &pl, &mut ws, &mut an);
    let mut fd = DMatrix::zeros(n, n);
    let (mut rp, mut rm) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let h = 1e-6 * (1.0 + q[j].abs());
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        m.statics_residual(&qp, &b.u, &pl, &mut ws, &mut rp);
        m.statics_residual(&qm, &b.u, &pl, &mut ws, &mut rm);
        fd.set_column(j, &((&rp - &rm) / (2.0 * h)));
    }
    (&an - &fd).norm() / fd.norm()
}

#[test]
fn statics_jacobian_matches_finite_differences_for_every_preset() {
    for (preset, overrides) in [
        ("single-tendon", vec!["tendons.0.tension=-3"]),
        ("single-tendon", vec!["tendons.0.tension=-6"]),
        ("soft-beam", vec![]),
        ("six-tendon", vec![]),
        (
            "six-tendon",
            vec!["tendons.1.tension=-8", "tendons.4.tension=-3"],
        ),
    ] {
        let err = jacobian_error(&built(preset, &overrides));
        assert!(
            err < 1e-6,
            "{preset} {overrides:?}: relative Jacobian error {err:e}"
        );
    }
}

fn tip(b: &gvsrom::Built) -> Vector3<f64> {
    let q = solve_statics(&b.model, &b.u, &b.loads, None, &b.options)
        .unwrap()
        .q;
    let mut ws = b.model.workspace();
    b.model.forward(&q, &mut ws, false);
    ws.g[b.model.disc.tip()].pos
}

#[test]
fn six_tendon_pulls_120_degrees_apart_give_rotated_configurations() {
    let rot = Rotation3::from_axis_angle(&Vector3::x_axis(), 120f64.to_radians());
    for (a, b) in [(0usize, 2usize), (1, 3), (2, 4)] {
        let ta = tip(&built(
            "six-tendon",
            &["tendons.0.tension=0", &format!("tendons.{a}.tension=-10")],
        ));
        let tb = tip(&built(
            "six-tendon",
            &["tendons.0.tension=0", &format!("tendons.{b}.tension=-10")],
        ));
        let err = (rot * ta - tb).norm();
        assert!(
            err < 1e-9,
            "tendon {a} vs {b}: |R(120°) tip_a − tip_b| = {err:e}"
        );
        assert!(ta.y.abs() + ta.z.abs() > 0.05, "the pull bends the arm");
    }
}
