//! The evaluations an implicit integrator repeats — the statics residual, the recursive dynamics
//! residual `M q̈ − τ`, the mass matrix, the statics Jacobian and the iteration parts `M, D, K` —
//! allocate nothing once the
//! workspace exists (issue 8), checked with a counting global allocator in this test binary, on a
//! FEM (local-support) and a Legendre (global) basis, with a friction tendon, damping and gravity;
//! and the steps of the second-order integrators (SDIRK4, generalized-α, the NDF in second-order
//! form) allocate nothing either.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::bodies::RigidBody;
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::strain::{DivisionBasis, FemDegree, LinearBasis};
use nalgebra::{DMatrix, DVector};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts calls on the current thread.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn arm(basis: DivisionBasis) -> Model<LinearBasis> {
    let mat = Material {
        youngs_modulus: 0.617e6,
        poisson_ratio: 0.5,
        density: 1121.0,
        damping: 1e4,
    };
    let rod = Rod::tapered(mat, 0.25, 0.0125, 0.005);
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Elements {
            elements: 6,
            gauss_per_element: 3,
        }],
        MagnusOrder::Z4,
        &[0.13],
    )
    .unwrap();
    let b = LinearBasis::per_division(&disc, &[basis]).unwrap();
    let t = Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.88,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    // a second tendon on a custom path: its offset is interpolated at every evaluation
    let knots = vec![[0.0, 0.0, -0.01], [0.1, 0.004, -0.004], [0.25, 0.0, -0.003]];
    let on_path = Tendon {
        offset_start: [0.0, -0.01],
        offset_end: [0.0, -0.003],
        friction: 0.3,
        path: knots,
        axial_stiffness: None,
        ..t.clone()
    };
    // an off-centre payload at the tip and a disc at an extra point: their inertia, inertial
    // wrenches and weights (with the offset's Jacobian term) join every pass
    let payload = RigidBody {
        x: 0.25,
        mass: 0.02,
        center: [0.01, 0.003, -0.002],
        inertia: [[2e-6, 1e-7, 0.0], [1e-7, 1.5e-6, 0.0], [0.0, 0.0, 1.2e-6]],
    };
    let disc_body = RigidBody {
        center: [0.0, 0.0, 0.001],
        ..RigidBody::point_mass(0.13, 0.004)
    };
    Model::new(rod, disc, b, vec![t, on_path])
        .unwrap()
        .with_bodies(vec![payload, disc_body])
        .unwrap()
}

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

#[test]
fn residuals_mass_matrix_and_statics_jacobian_do_not_allocate() {
    let modes = [false, true, false, true, false, true];
    for basis in [
        DivisionBasis::Fem {
            modes,
            elements: 6,
            degree: FemDegree::Quadratic,
        },
        DivisionBasis::Legendre {
            modes,
            orders: [0, 4, 0, 2, 0, 2],
        },
    ] {
        let m = arm(basis);
        let n = m.n_dof();
        let loads = m
            .prepare_loads(&Loads {
                gravity: [0.0, 0.0, -9.81],
                ..Loads::default()
            })
            .unwrap();
        let u = [-2.0, -1.0];
        let q = DVector::from_fn(n, |i, _| 0.2 * ((i as f64) * 0.7).sin());
        let qd = DVector::from_fn(n, |i, _| 1.5 * ((i as f64) * 1.3).cos());
        let qdd = DVector::from_fn(n, |i, _| 4.0 * ((i as f64) * 0.4 + 1.0).sin());
        let mut ws = m.workspace();
        let (mut r, mut jac) = (DVector::zeros(n), DMatrix::zeros(n, n));
        // first calls size the lazily allocated buffers
        m.statics_residual(&q, &u, &loads, &mut ws, &mut r);
        m.dynamics_residual(&q, &qd, &qdd, &u, &loads, &mut ws, &mut r);
        m.forward(&q, &mut ws, true);
        m.assemble_mass(&mut ws);
        m.statics_jacobian(&q, &u, &loads, &mut ws, &mut jac);
        let (mut mm, mut dd, mut kk) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n), jac.clone());
        m.iteration_parts(&q, &u, &loads, &mut ws, &mut mm, &mut dd, &mut kk);
        let before = allocations();
        let mut counts = [0usize; 6];
        let mut mark = before;
        let mut tick = |k: usize| {
            let now = allocations();
            counts[k] = now - mark;
            mark = now;
        };
        m.statics_residual(&q, &u, &loads, &mut ws, &mut r);
        tick(0);
        m.dynamics_residual(&q, &qd, &qdd, &u, &loads, &mut ws, &mut r);
        tick(1);
        m.forward(&q, &mut ws, true);
        tick(2);
        m.assemble_mass(&mut ws);
        tick(3);
        m.statics_jacobian(&q, &u, &loads, &mut ws, &mut jac);
        tick(4);
        m.iteration_parts(&q, &u, &loads, &mut ws, &mut mm, &mut dd, &mut kk);
        tick(5);
        assert_eq!(
            counts,
            [0; 6],
            "allocations of: statics residual, dynamics residual, forward pass with Jacobians, mass matrix, statics Jacobian, iteration parts M, D, K (n = {n})"
        );
        // what a displacement-driven tendon's thread needs (`gvs::solve::dynamics::drive`): the
        // strains and tendon lengths at q for its tension, ∂ℓ/∂q and B for its stiffness
        let na = m.n_actuators();
        let (mut lengths, mut unit) = (vec![0.0; na], vec![0.0; na]);
        let (mut grad, mut b) = (DMatrix::zeros(n, na), DMatrix::zeros(n, na));
        let mut col = DVector::zeros(n);
        m.forward(&q, &mut ws, false);
        m.tendon_length_jacobian_after_forward(&mut ws, &mut grad, &mut col);
        m.actuation_matrix_after_forward(&mut ws, &mut b, &mut unit, &mut col);
        let thread = allocations();
        m.strains_at(&q, &mut ws);
        m.tendon_lengths_after_forward(&ws, &mut lengths);
        m.forward(&q, &mut ws, false);
        m.tendon_length_jacobian_after_forward(&mut ws, &mut grad, &mut col);
        m.actuation_matrix_after_forward(&mut ws, &mut b, &mut unit, &mut col);
        assert_eq!(
            allocations() - thread,
            0,
            "allocations of a thread's tension and stiffness: strains, tendon lengths, ∂ℓ/∂q, B"
        );
        assert!(lengths.iter().all(|l| *l > 0.0) && grad.amax() > 0.0 && b.amax() > 0.0);
        // the counter does see allocations
        let before = allocations();
        drop(std::hint::black_box(vec![0u8; 8]));
        assert_eq!(allocations() - before, 1);
        // D is symmetric (it allocates: after the count)
        assert!(
            dd.iter().all(|v| v.is_finite()) && (&dd - dd.transpose()).amax() < 1e-12 * dd.amax()
        );
        assert!(r.iter().chain(jac.iter()).all(|v| v.is_finite()));
    }
}

/// A chain of unit masses between springs (`k = 100`, fixed ends) with a cubic spring to ground
/// and light damping: `M q̈ = τ` in second-order form, evaluated without allocating.
struct Chain {
    n: usize,
}

impl Chain {
    fn force(&self, q: &DVector<f64>, qd: &DVector<f64>, i: usize) -> f64 {
        let left = if i > 0 { q[i - 1] } else { 0.0 };
        let right = if i + 1 < self.n { q[i + 1] } else { 0.0 };
        100.0 * (left - 2.0 * q[i] + right) - 50.0 * q[i].powi(3) - 0.01 * qd[i]
    }
}

impl gvs::solve::ode::MechanicalSystem for Chain {
    fn dim(&self) -> usize {
        self.n
    }
    fn residual(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        eps: &mut DVector<f64>,
    ) -> Result<(), gvs::solve::ode::RhsError> {
        for i in 0..self.n {
            eps[i] = qdd[i] - self.force(q, qd, i);
        }
        Ok(())
    }
    fn accelerations(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &mut DVector<f64>,
    ) -> Result<(), gvs::solve::ode::RhsError> {
        for i in 0..self.n {
            qdd[i] = self.force(q, qd, i);
        }
        Ok(())
    }
    fn mass(
        &mut self,
        _t: f64,
        _q: &DVector<f64>,
        m: &mut DMatrix<f64>,
    ) -> Result<(), gvs::solve::ode::RhsError> {
        m.fill_with_identity();
        Ok(())
    }
    fn iteration_parts(
        &mut self,
        _t: f64,
        q: &DVector<f64>,
        _qd: &DVector<f64>,
        m: &mut DMatrix<f64>,
        d: &mut DMatrix<f64>,
        k: &mut DMatrix<f64>,
    ) -> Result<(), gvs::solve::ode::RhsError> {
        m.fill_with_identity();
        d.fill_with_identity();
        *d *= 0.01;
        k.fill(0.0);
        for i in 0..self.n {
            k[(i, i)] = 200.0 + 150.0 * q[i] * q[i];
            if i > 0 {
                k[(i, i - 1)] = -100.0;
                k[(i - 1, i)] = -100.0;
            }
        }
        Ok(())
    }
}

#[test]
fn integrator_steps_do_not_allocate() {
    use gvs::solve::ode::{
        integrate_generalized_alpha, integrate_ndf_second_order, integrate_sdirk, ErrorNorm,
        GeneralizedAlphaOptions, NdfOptions, SdirkOptions,
    };
    use std::ops::ControlFlow;
    let n = 12;
    let q0 = DVector::from_fn(n, |i, _| 0.3 * ((i as f64) * 0.9).sin());
    let qd0 = DVector::zeros(n);
    // allocations of one integration over [0, t_end] with 11 outputs and a breakpoint at 0.5:
    // the set-up allocates, the steps must not, so a run 8 times as long allocates as many
    let count = |method: usize, t_end: f64| -> (usize, usize) {
        let t_out: Vec<f64> = (0..=10).map(|k| t_end * k as f64 / 10.0).collect();
        let mut sys = Chain { n };
        let mut last = 0.0;
        let mut out = |t: f64, _: &DVector<f64>| {
            last = t;
            ControlFlow::<String>::Continue(())
        };
        let before = allocations();
        let stats = match method {
            0 => integrate_sdirk(
                &mut sys,
                0.0,
                &q0,
                &qd0,
                &t_out,
                &[0.5],
                &SdirkOptions {
                    error_norm: ErrorNorm::Mass,
                    ..SdirkOptions::default()
                },
                &mut out,
            ),
            1 => integrate_generalized_alpha(
                &mut sys,
                0.0,
                &q0,
                &qd0,
                &t_out,
                &[0.5],
                &GeneralizedAlphaOptions {
                    error_norm: ErrorNorm::Mass,
                    ..GeneralizedAlphaOptions::default()
                },
                &mut out,
            ),
            _ => integrate_ndf_second_order(
                &mut sys,
                0.0,
                &q0,
                &qd0,
                &t_out,
                &[0.5],
                &NdfOptions::default(),
                &mut out,
            ),
        }
        .unwrap();
        let allocated = allocations() - before;
        assert_eq!(last, t_end);
        (allocated, stats.steps)
    };
    for (method, name) in [
        (0, "SDIRK4"),
        (1, "generalized-α"),
        (2, "NDF (second order)"),
    ] {
        let (short, steps_short) = count(method, 1.0);
        let (long, steps_long) = count(method, 8.0);
        assert!(
            steps_long > 4 * steps_short,
            "{name}: {steps_short} and {steps_long} steps"
        );
        assert_eq!(
            short, long,
            "{name}: {short} allocations over {steps_short} steps, {long} over {steps_long}"
        );
    }
}
