//! The evaluations an implicit integrator repeats — the statics residual, the recursive dynamics
//! residual `M q̈ − τ`, the mass matrix, the statics Jacobian and the iteration parts `M, D, K` —
//! allocate nothing once the
//! workspace exists (issue 8), checked with a counting global allocator in this test binary, on a
//! FEM (local-support) and a Legendre (global) basis, with a friction tendon, damping and gravity.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
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
        &[],
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
    };
    Model::new(rod, disc, b, vec![t]).unwrap()
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
        let u = [-2.0];
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
        // the counter does see allocations
        drop(std::hint::black_box(vec![0u8; 8]));
        assert_eq!(allocations() - before, 1);
        // D is symmetric (it allocates: after the count)
        assert!(
            dd.iter().all(|v| v.is_finite()) && (&dd - dd.transpose()).amax() < 1e-12 * dd.amax()
        );
        assert!(r.iter().chain(jac.iter()).all(|v| v.is_finite()));
    }
}
