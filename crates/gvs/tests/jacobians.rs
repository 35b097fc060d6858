//! Analytic derivatives against central finite differences (gvs-spec §10.2, §10.3.9):
//! the geometric Jacobian `J_i` at every point, the centreline position's between the points, and
//! the statics Jacobian `∂R/∂q` with gravity,
//! follower and world-fixed wrenches, distributed loads, tendons with and without friction, two
//! divisions, Z2 and Z4, and a nonlinear (sigmoid) strain parameterization; the Jacobian that
//! reuses a residual's forward pass is the same matrix.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::lie::{Pose, V6};
use gvs::loads::{DistributedWrench, Frame, Loads, PointWrench, PulseMagnitude};
use gvs::model::Model;
use gvs::rod::{DivisionGeometry, Material, Rod};
use gvs::strain::{DivisionBasis, LinearBasis, SigmoidBend, StrainParam};
mod common;

use common::pseudo_random;
use nalgebra::{DMatrix, DVector};

fn material() -> Material {
    Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 1e4,
    }
}

fn check_geometric_jacobian<P: StrainParam>(model: &Model<P>, q: &DVector<f64>) {
    let n = model.n_dof();
    let mut ws = model.workspace();
    model.forward(q, &mut ws, true);
    let jac = ws.jac.clone();
    let g0 = ws.g.clone();
    let (mut wp, mut wm) = (model.workspace(), model.workspace());
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let mut qp = q.clone();
        qp[j] += h;
        let mut qm = q.clone();
        qm[j] -= h;
        model.forward(&qp, &mut wp, false);
        model.forward(&qm, &mut wm, false);
        for i in 0..model.disc.n_points() {
            let d = (wp.g[i].to_homogeneous() - wm.g[i].to_homogeneous()) / (2.0 * h);
            let m = g0[i].inverse().to_homogeneous() * d;
            let fd = V6::new(
                m[(2, 1)],
                m[(0, 2)],
                m[(1, 0)],
                m[(0, 3)],
                m[(1, 3)],
                m[(2, 3)],
            );
            let an = jac.column(i * n + j);
            for a in 0..6 {
                worst = worst.max((fd[a] - an[a]).abs() / (1.0 + an[a].abs()));
            }
        }
    }
    assert!(
        worst < 1e-7,
        "J vs central differences: worst relative error {worst:e}"
    );
}

/// `∂p/∂q` of the centreline between the points ([`Model::position_jacobian_at`]) against central
/// differences of [`Model::position_at`]: at every point, half-way and a quarter of the way
/// between neighbours (junctions of divisions included), the ends and beyond the tip.
fn check_position_jacobian<P: StrainParam>(model: &Model<P>, q: &DVector<f64>) {
    let n = model.n_dof();
    let mut ws = model.workspace();
    model.forward(q, &mut ws, true);
    let (mut wp, mut wm) = (model.workspace(), model.workspace());
    let pts = &model.disc.points;
    let length = model.disc.length();
    let mut xs: Vec<f64> = pts.iter().map(|p| p.x).collect();
    for w in pts.windows(2) {
        xs.push(0.5 * (w[0].x + w[1].x));
        xs.push(0.75 * w[0].x + 0.25 * w[1].x);
    }
    xs.extend([0.0, length, 1.1 * length]);
    let h = 1e-6;
    let analytic: Vec<_> = (xs.iter())
        .map(|&x| {
            let (p, an) = model.position_jacobian_at(&ws, x);
            assert!((p - model.position_at(&ws, x)).norm() == 0.0, "X = {x}");
            an
        })
        .collect();
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        model.forward(&qp, &mut wp, false);
        model.forward(&qm, &mut wm, false);
        for (&x, an) in xs.iter().zip(&analytic) {
            let fd = (model.position_at(&wp, x) - model.position_at(&wm, x)) / (2.0 * h);
            for a in 0..3 {
                worst = worst.max((fd[a] - an[(a, j)]).abs() / (1.0 + an[(a, j)].abs()));
            }
        }
    }
    assert!(
        worst < 1e-7,
        "centreline position Jacobian: worst relative error {worst:.3e}"
    );
}

fn check_statics_jacobian<P: StrainParam>(
    model: &Model<P>,
    q: &DVector<f64>,
    u: &[f64],
    loads: &Loads,
) {
    let n = model.n_dof();
    let pl = model.prepare_loads(loads).unwrap();
    let mut ws = model.workspace();
    let mut an = DMatrix::zeros(n, n);
    model.statics_jacobian(q, u, &pl, &mut ws, &mut an);
    let mut fd = DMatrix::zeros(n, n);
    let (mut rp, mut rm) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let h = 1e-6 * (1.0 + q[j].abs());
        let mut qp = q.clone();
        qp[j] += h;
        let mut qm = q.clone();
        qm[j] -= h;
        model.statics_residual(&qp, u, &pl, &mut ws, &mut rp);
        model.statics_residual(&qm, u, &pl, &mut ws, &mut rm);
        fd.set_column(j, &((&rp - &rm) / (2.0 * h)));
    }
    // central differences at h = 1e-6 leave ~1e-10 of round-off (measured 2e-11 – 5e-11 over the
    // norm, ≤ 1.2e-8 per entry against 1e-3 of the largest entry): the bounds leave a margin of
    // about 100, tight enough that a wrong term of the Z4 tangent (5e-8 over the norm) fails
    let err = (&an - &fd).norm() / fd.norm();
    let floor = 1e-3 * fd.amax();
    let entry = (&an - &fd)
        .iter()
        .zip(fd.iter())
        .map(|(d, f)| d.abs() / (floor + f.abs()))
        .fold(0.0, f64::max);
    assert!(
        err < 1e-8 && entry < 1e-6,
        "statics Jacobian vs central differences: relative error {err:e}, worst entry {entry:e}"
    );
    // the solver's path: a residual at q, then the Jacobian reusing its forward pass
    let mut r = DVector::zeros(n);
    let mut reused = DMatrix::from_element(n, n, f64::NAN);
    model.statics_residual(q, u, &pl, &mut ws, &mut r);
    model.statics_jacobian_after_forward(q, u, &pl, &mut ws, &mut reused);
    assert_eq!(
        reused, an,
        "Jacobian after a residual's forward pass differs"
    );
}

fn single_division_model(order: MagnusOrder, friction: f64) -> Model<LinearBasis> {
    let rod = Rod::tapered(material(), 0.25, 0.0125, 0.005);
    let disc = Discretization::new(&rod, &[Quadrature::Gauss { n: 12 }], order, &[0.1]).unwrap();
    let basis = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [true; 6],
            orders: [1, 3, 2, 1, 1, 2],
        }],
    )
    .unwrap();
    let tendons = vec![
        Tendon {
            offset_start: [0.0, 0.01],
            offset_end: [0.0, 0.003],
            x_start: 0.0,
            x_end: 0.25,
            friction,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
        Tendon {
            offset_start: [0.006, -0.002],
            offset_end: [0.002, 0.001],
            x_start: 0.0,
            x_end: 0.25,
            friction: 0.3,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
        // a span inside the division, ending on the weight-0 extra point at 0.1: its points
        // share the span by their cells (`Model::tendon_weights`), that extra point included
        Tendon {
            offset_start: [-0.004, 0.002],
            offset_end: [-0.003, -0.001],
            x_start: 0.047,
            x_end: 0.1,
            friction: 0.5,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
    ];
    Model::new(rod, disc, basis, tendons).unwrap()
}

fn all_loads() -> Loads {
    Loads {
        gravity: [0.0, 0.0, -9.81],
        point: vec![
            PointWrench {
                x: 0.25,
                wrench: [0.001, -0.002, 0.003, 0.05, -0.1, 0.2],
                frame: Frame::Local,
            },
            PointWrench {
                x: 0.25,
                wrench: [0.002, 0.001, -0.001, -0.1, 0.05, -0.3],
                frame: Frame::Global,
            },
            PointWrench {
                x: 0.1,
                wrench: [0.0, 0.01, 0.0, 0.0, 0.2, 0.0],
                frame: Frame::Global,
            },
        ],
        distributed: vec![
            DistributedWrench::TriangularPulse {
                center: 0.12,
                width: 0.2,
                magnitude: 0.2,
                axis: [0.0, 1.0, 0.3],
                convention: PulseMagnitude::Peak,
            },
            // ends inside cells: the end points apply their cells' overlap with the span
            DistributedWrench::Uniform {
                x_start: 0.03,
                x_end: 0.21,
                density: [0.0, 0.0, 0.01, 0.0, 0.3, 0.1],
                frame: Frame::Global,
            },
        ],
    }
}

#[test]
fn geometric_jacobian_matches_finite_differences_z4_and_z2() {
    for order in [MagnusOrder::Z4, MagnusOrder::Z2] {
        let m = single_division_model(order, 0.0).with_base(Pose::new(
            nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.7).into_inner(),
            nalgebra::Vector3::new(0.1, -0.2, 0.3),
        ));
        let q = pseudo_random(m.n_dof(), 1, 0.6);
        check_geometric_jacobian(&m, &q);
        check_position_jacobian(&m, &q);
    }
}

#[test]
fn statics_jacobian_matches_finite_differences_with_all_loads_and_friction() {
    for order in [MagnusOrder::Z4, MagnusOrder::Z2] {
        let m = single_division_model(order, 0.88);
        let q = pseudo_random(m.n_dof(), 2, 0.5);
        check_statics_jacobian(&m, &q, &[-2.0, -0.7, -1.5], &all_loads());
    }
}

#[test]
fn jacobians_match_finite_differences_on_a_rod_precurved_along_its_length() {
    // a reference strain ξ*(X) that varies along the rod (a curvature growing with X and a
    // twist), evaluated at the Magnus sub-points too: it enters the kinematics, the elastic force
    // and the tendon's path (t_u includes κ* × d), with friction, gravity and every load
    let xi_star =
        |x: f64, _div: usize| V6::new(0.8 * x, 2.0 + 12.0 * x, -3.0 * x * x, 1.0, 0.0, 0.0);
    for order in [MagnusOrder::Z4, MagnusOrder::Z2] {
        let m = single_division_model(order, 0.88).with_reference_strain(xi_star);
        let q = pseudo_random(m.n_dof(), 5, 0.5);
        check_geometric_jacobian(&m, &q);
        check_position_jacobian(&m, &q);
        check_statics_jacobian(&m, &q, &[-2.0, -0.7, -1.5], &all_loads());
    }
}

#[test]
fn statics_jacobian_matches_finite_differences_two_divisions_half_tendon() {
    let rod = Rod {
        material: Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 1e4,
        },
        divisions: vec![
            DivisionGeometry {
                length: 0.3,
                radius_start: 0.02,
                radius_end: 0.015,
                material: None,
                section: None,
            },
            DivisionGeometry {
                length: 0.3,
                radius_start: 0.015,
                radius_end: 0.01,
                material: None,
                section: None,
            },
        ],
    };
    let q5 = Quadrature::Gauss { n: 5 };
    let disc = Discretization::new(&rod, &[q5, q5], MagnusOrder::Z4, &[]).unwrap();
    let b = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    let basis = LinearBasis::per_division(&disc, &[b.clone(), b]).unwrap();
    let tendons = vec![
        Tendon {
            offset_start: [0.02, 0.0],
            offset_end: [0.01, 0.0],
            x_start: 0.0,
            x_end: 0.6,
            friction: 0.4,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
        Tendon {
            offset_start: [0.01, 0.0173],
            offset_end: [0.0075, 0.01299],
            x_start: 0.0,
            x_end: 0.3,
            friction: 0.2,
            friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
            turns: 0.0,
            path: Vec::new(),
            axial_stiffness: None,
        },
    ];
    let m = Model::new(rod, disc, basis, tendons).unwrap();
    let q = pseudo_random(m.n_dof(), 3, 0.4);
    check_geometric_jacobian(&m, &q);
    check_position_jacobian(&m, &q);
    let loads = Loads {
        gravity: [0.0, 3.0, -9.81],
        point: vec![PointWrench {
            x: 0.6,
            wrench: [0.01, 0.0, -0.02, 0.1, 0.2, -0.1],
            frame: Frame::Global,
        }],
        distributed: vec![],
    };
    check_statics_jacobian(&m, &q, &[-6.0, -3.0], &loads);
}

#[test]
fn statics_jacobian_matches_finite_differences_for_nonlinear_sigmoid_basis() {
    let rod = Rod::tapered(material(), 0.8, 0.015, 0.015);
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 20 }], MagnusOrder::Z4, &[]).unwrap();
    let p = SigmoidBend::new(&disc);
    let tendons = vec![Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.005],
        x_start: 0.0,
        x_end: 0.8,
        friction: 0.5,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    }];
    let m = Model::new(rod, disc, p, tendons).unwrap();
    let q = DVector::from_vec(vec![1.1, 8.0, 0.45]);
    check_geometric_jacobian(&m, &q);
    check_position_jacobian(&m, &q);
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        point: vec![PointWrench {
            x: 0.8,
            wrench: [0.0, 0.01, 0.0, 0.0, 0.0, -0.05],
            frame: Frame::Global,
        }],
        distributed: vec![DistributedWrench::TriangularPulse {
            center: 0.3,
            width: 0.3,
            magnitude: 2.0,
            axis: [0.0, 1.0, 0.0],
            convention: PulseMagnitude::Peak,
        }],
    };
    check_statics_jacobian(&m, &q, &[-1.5], &loads);
}
