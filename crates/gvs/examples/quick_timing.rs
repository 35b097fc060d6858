use gvs::actuation::Tendon;
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::loads::Loads;
use gvs::model::Model;
use gvs::rod::{Material, Rod};
use gvs::solve::statics::{StaticsOptions, StaticsSolver};
use gvs::strain::{DivisionBasis, LinearBasis};
use std::time::Instant;

fn main() {
    let rod = Rod::tapered(
        Material {
            youngs_modulus: 0.617e6,
            poisson_ratio: 0.5,
            density: 1121.0,
            damping: 1e4,
        },
        0.25,
        0.0125,
        0.005,
    );
    let disc =
        Discretization::new(&rod, &[Quadrature::Gauss { n: 100 }], MagnusOrder::Z4, &[]).unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Legendre {
            modes: [false, true, false, true, false, true],
            orders: [0, 10, 0, 10, 0, 10],
        }],
    )
    .unwrap();
    let t = Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.88,
    };
    let m = Model::new(rod, disc, b, vec![t]).unwrap();
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Default::default()
    };
    let mut s = StaticsSolver::new(&m, StaticsOptions::default());
    for ramp in [1usize, 2] {
        s.options.ramp_steps = ramp;
        let mut times = vec![];
        let mut last = None;
        for _ in 0..50 {
            let t0 = Instant::now();
            let sol = s.solve(&[-3.0], &loads, None).unwrap();
            times.push(t0.elapsed().as_secs_f64() * 1e3);
            last = Some(sol);
        }
        times.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let sol = last.unwrap();
        let mut ws = m.workspace();
        m.forward(&sol.q, &mut ws, false);
        println!("ramp {ramp}: median {:.3} ms, iters {}, resid evals {}, jac evals {}, |R| {:.2e}, tip {:.6} {:.6}", times[25], sol.iterations, sol.residual_evaluations, sol.jacobian_evaluations, sol.residual_norm, ws.g.last().unwrap().pos[0], ws.g.last().unwrap().pos[2]);
    }
    beam();
    six();
    let q = nalgebra::DVector::from_element(33, 0.1);
    let pl = m.prepare_loads(&loads).unwrap();
    let mut ws = m.workspace();
    let mut r = nalgebra::DVector::zeros(33);
    let mut j = nalgebra::DMatrix::zeros(33, 33);
    let t0 = Instant::now();
    for _ in 0..1000 {
        m.statics_residual(&q, &[-3.0], &pl, &mut ws, &mut r);
    }
    println!("residual {:.1} us", t0.elapsed().as_secs_f64() * 1e3);
    let t0 = Instant::now();
    for _ in 0..200 {
        m.statics_jacobian(&q, &[-3.0], &pl, &mut ws, &mut j);
    }
    println!(
        "jacobian {:.1} us",
        t0.elapsed().as_secs_f64() * 1e6 / 200.0
    );
}

fn time<P: gvs::strain::StrainParam>(name: &str, m: &Model<P>, u: &[f64], loads: &Loads) {
    let mut s = StaticsSolver::new(m, StaticsOptions::default());
    let mut times = vec![];
    let mut last = None;
    for _ in 0..30 {
        let t0 = Instant::now();
        let sol = s.solve(u, loads, None).unwrap();
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        last = Some(sol);
    }
    times.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let sol = last.unwrap();
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    let p = ws.g.last().unwrap().pos;
    println!("{name}: median {:.3} ms, iters {}, resid evals {}, jac evals {}, |R| {:.2e}, tip {:.6} {:.6} {:.6}", times[15], sol.iterations, sol.residual_evaluations, sol.jacobian_evaluations, sol.residual_norm, p[0], p[1], p[2]);
}

fn beam() {
    use gvs::loads::{DistributedWrench, PulseMagnitude};
    use gvs::strain::FemDegree;
    let rod = Rod::tapered(
        Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 1e4,
        },
        0.8,
        0.015,
        0.015,
    );
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Elements {
            elements: 49,
            gauss_per_element: 2,
        }],
        MagnusOrder::Z4,
        &[],
    )
    .unwrap();
    let b = LinearBasis::per_division(
        &disc,
        &[DivisionBasis::Fem {
            modes: [false, true, false, false, false, false],
            elements: 49,
            degree: FemDegree::Linear,
        }],
    )
    .unwrap();
    let m = Model::new(rod, disc, b, vec![]).unwrap();
    let loads = Loads {
        gravity: [0.0; 3],
        point: vec![],
        distributed: vec![DistributedWrench::TriangularPulse {
            center: 0.2,
            width: 0.08,
            magnitude: 4.0,
            axis: [0.0, 1.0, 0.0],
            convention: PulseMagnitude::Peak,
        }],
    };
    time("soft-beam", &m, &[], &loads);
}

fn six() {
    use gvs::rod::DivisionGeometry;
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
            },
            DivisionGeometry {
                length: 0.3,
                radius_start: 0.015,
                radius_end: 0.01,
            },
        ],
    };
    let q5 = Quadrature::Gauss { n: 5 };
    let disc = Discretization::new(&rod, &[q5, q5], MagnusOrder::Z4, &[]).unwrap();
    let bb = DivisionBasis::Legendre {
        modes: [true; 6],
        orders: [1, 2, 2, 1, 1, 1],
    };
    let b = LinearBasis::per_division(&disc, &[bb.clone(), bb]).unwrap();
    let mut ts = vec![];
    for k in 0..6 {
        let th = (k as f64) * std::f64::consts::PI / 3.0;
        let (c, s) = (th.cos(), th.sin());
        if k % 2 == 0 {
            ts.push(Tendon {
                offset_start: [0.02 * c, 0.02 * s],
                offset_end: [0.01 * c, 0.01 * s],
                x_start: 0.0,
                x_end: 0.6,
                friction: 0.0,
            });
        } else {
            ts.push(Tendon {
                offset_start: [0.02 * c, 0.02 * s],
                offset_end: [0.015 * c, 0.015 * s],
                x_start: 0.0,
                x_end: 0.3,
                friction: 0.0,
            });
        }
    }
    let m = Model::new(rod, disc, b, ts).unwrap();
    time(
        "six-tendon",
        &m,
        &[-10.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        &Loads::default(),
    );
    time(
        "six-tendon b",
        &m,
        &[0.0, -10.0, 0.0, 0.0, 0.0, 0.0],
        &Loads::default(),
    );
}
