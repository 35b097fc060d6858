//! Tests of [`super::continuation`]: a closed-form S-curve through two folds, a closed path that
//! turns back, and a six-tendon input the load ramp misses.

use super::continuation::*;
use crate::loads::Loads;
use crate::model::Model;
use nalgebra::{DMatrix, DVector};

/// `R(x, λ) = [x³ − 3x + 4 − 8λ; y − x² − λ]`: on the curve `λ = (x³ − 3x + 4)/8`, which rises
/// from `x₀ = −c` at λ = 0 to a fold at x = −1 (λ = 3/4), falls to a fold at x = 1 (λ = 1/4) and
/// rises through λ = 1 at `x = c`, `c = ∛(2 + √3) + ∛(2 − √3)` (Cardano: the one real root of
/// `x³ − 3x − 4`).
struct SCurve;

impl ParametrizedSystem for SCurve {
    fn dim(&self) -> usize {
        2
    }
    fn residual(
        &mut self,
        z: &DVector<f64>,
        lambda: f64,
        r: &mut DVector<f64>,
        rl: &mut DVector<f64>,
    ) -> f64 {
        let (x, y) = (z[0], z[1]);
        r[0] = x * x * x - 3.0 * x + 4.0 - 8.0 * lambda;
        r[1] = y - x * x - lambda;
        rl[0] = -8.0;
        rl[1] = -1.0;
        1.0
    }
    fn jacobian(&mut self, z: &DVector<f64>, _lambda: f64, jac: &mut DMatrix<f64>) {
        let x = z[0];
        jac[(0, 0)] = 3.0 * x * x - 3.0;
        jac[(0, 1)] = 0.0;
        jac[(1, 0)] = -2.0 * x;
        jac[(1, 1)] = 1.0;
    }
}

fn cardano() -> f64 {
    (2.0 + 3f64.sqrt()).cbrt() + (2.0 - 3f64.sqrt()).cbrt()
}

#[test]
fn s_curve_is_followed_through_both_folds_to_the_closed_form_root() {
    let c = cardano();
    let x0 = DVector::from_vec(vec![-c, c * c]);
    let rep = follow(&mut SCurve, &x0, 0.0, &ContinuationOptions::default()).unwrap();
    // landed on the far branch: x = c, y = c² + 1 (the dogleg's ftol 1e-10 on R)
    assert!((rep.x[0] - c).abs() < 1e-10, "x = {}", rep.x[0]);
    assert!((rep.x[1] - (c * c + 1.0)).abs() < 1e-9, "y = {}", rep.x[1]);
    assert!(rep.residual_norm <= 1e-10);
    // two folds, at λ = 3/4 then λ = 1/4, each within the path's resolution there (the
    // turning-angle limit keeps the steps near a fold short)
    let f = &rep.stats.folds;
    assert_eq!(f.len(), 2, "{f:?}");
    assert!(
        (f[0] - 0.75).abs() < 0.01 && (f[1] - 0.25).abs() < 0.01,
        "{f:?}"
    );
    // det ∂R/∂x = 3x² − 3 changes sign at each fold and nowhere else
    assert_eq!(rep.stats.det_sign_changes, 2);
    assert!(rep.stats.lambda_max >= 0.75 - 1e-3 && rep.stats.lambda_max < 1.0 + 0.2);
    // every accepted point lies on the curve, within the corrector's tolerance
    for p in &rep.path {
        let x = p.x[0];
        assert!((x * x * x - 3.0 * x + 4.0 - 8.0 * p.lambda).abs() <= 1e-8);
    }
}

#[test]
fn a_path_that_closes_before_the_target_is_reported_as_turned_back() {
    // R = x² + λ² − 1/4: a circle from (−1/2, 0) over its fold at λ = 1/2 back to λ = 0
    struct Circle;
    impl ParametrizedSystem for Circle {
        fn dim(&self) -> usize {
            1
        }
        fn residual(
            &mut self,
            z: &DVector<f64>,
            l: f64,
            r: &mut DVector<f64>,
            rl: &mut DVector<f64>,
        ) -> f64 {
            r[0] = z[0] * z[0] + l * l - 0.25;
            rl[0] = 2.0 * l;
            1.0
        }
        fn jacobian(&mut self, z: &DVector<f64>, _l: f64, jac: &mut DMatrix<f64>) {
            jac[(0, 0)] = 2.0 * z[0];
        }
    }
    let x0 = DVector::from_vec(vec![-0.5]);
    let e = follow(&mut Circle, &x0, 0.0, &ContinuationOptions::default()).unwrap_err();
    match e {
        ContinuationError::Stopped {
            why: Stop::TurnedBack(_),
            lambda,
            lambda_max,
            folds,
            ..
        } => {
            assert!(lambda < 0.0);
            // the highest accepted point is within half a step (Δs ≤ 0.1, θ = 1) of the top:
            // λ ≥ 0.5 cos(0.1) = 0.5 − 2.5e-3 (and ≤ 0.5 up to the corrector's 1e-8 on R)
            assert!(
                lambda_max <= 0.5 + 1e-8 && lambda_max >= 0.5 * 0.1f64.cos(),
                "{lambda_max}"
            );
            assert_eq!(folds, 1);
        }
        other => panic!("expected TurnedBack, got {other}"),
    }
}

/// The six-tendon arm of `examples/six-tendon.toml` (paper IV-C): 0.6 m in two divisions tapered
/// 0.02 → 0.015 → 0.01 m, E = 1e6 Pa, ρ = 1000 kg/m³, Legendre orders [1, 2, 2, 1, 1, 1] on all
/// six strains per division (28 DOF), 5 Gauss points each; frictionless tendons at 60k° on the
/// surface, full length for even k, half length (to 0.3 m) for odd k; base along +x.
fn six_tendon() -> Model<crate::strain::LinearBasis> {
    use crate::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
    use crate::discretize::{Discretization, MagnusOrder, Quadrature};
    use crate::rod::{DivisionGeometry, Material, Rod};
    use crate::strain::{DivisionBasis, LinearBasis};
    let material = Material {
        youngs_modulus: 1e6,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 1e4,
    };
    let division = |radius_start, radius_end| DivisionGeometry {
        length: 0.3,
        radius_start,
        radius_end,
        material: None,
        section: None,
    };
    let rod = Rod {
        material,
        divisions: vec![division(0.02, 0.015), division(0.015, 0.01)],
    };
    let gauss = Quadrature::Gauss { n: 5 };
    let disc = Discretization::new(&rod, &[gauss, gauss], MagnusOrder::Z4, &[]).unwrap();
    let legendre = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    let basis = LinearBasis::per_division(&disc, &[legendre.clone(), legendre]).unwrap();
    let tendons = (0..6)
        .map(|k| {
            let (s, c) = (60.0 * k as f64).to_radians().sin_cos();
            let (x_end, r_end) = if k % 2 == 0 {
                (0.6, 0.01)
            } else {
                (0.3, 0.015)
            };
            Tendon {
                offset_start: [0.02 * c, 0.02 * s],
                offset_end: [r_end * c, r_end * s],
                x_start: 0.0,
                x_end,
                friction: 0.0,
                friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
                turns: 0.0,
                path: Vec::new(),
                axial_stiffness: None,
            }
        })
        .collect();
    Model::new(rod, disc, basis, tendons).unwrap()
}

#[test]
fn six_tendon_input_the_ramp_misses_is_solved_through_two_folds_from_the_straight_rod() {
    use crate::solve::statics::{StaticsOptions, StaticsSolver};
    // sample 7371 of `gvsrom dataset six-tendon --random 'tendons.*.tension=-30:30' --samples
    // 20000 --seed 0`: the ramp converges onto another branch and stalls there; the branch of
    // the straight rod folds at λ ≈ 0.5966 and back at λ ≈ 0.5957, then reaches λ = 1
    let u = [
        14.443131761064372,
        -23.659122666412333,
        2.0695427183255006,
        7.619300609702577,
        10.53722237180915,
        10.791231360008751,
    ];
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    let model = six_tendon();
    let sol = StaticsSolver::new(&model, StaticsOptions::default())
        .solve(&u, &loads, None)
        .unwrap();
    let c = sol.continuation.as_ref().expect("the ramp alone fails");
    assert_eq!(c.start_lambda, 0.0);
    assert_eq!(c.folds.len(), 2, "{c:?}");
    assert!(c.folds.iter().all(|f| (f - 0.5962).abs() < 0.002), "{c:?}");
    assert_eq!(c.det_sign_changes, 2, "{c:?}");
    // the equilibrium, checked by a fresh residual evaluation at the full load
    let mut ws = model.workspace();
    let mut r = DVector::zeros(model.n_dof());
    let prepared = model.prepare_loads(&loads).unwrap();
    model.statics_residual(&sol.q, &u, &prepared, &mut ws, &mut r);
    assert!(
        r.amax() <= 1e-10 * ws.residual_scale,
        "‖R‖∞ = {:e}",
        r.amax()
    );
    // the same equilibrium as the dataset built from the scenario file (row 7371 of
    // tip_position.npy, printed to 5 digits): the hand-built model is the preset's
    let tip = model.tip_pose(&ws).pos;
    let expected = [-0.09081, 0.06413, -0.09881];
    for k in 0..3 {
        assert!((tip[k] - expected[k]).abs() < 1e-5, "tip {tip:?}");
    }
}
