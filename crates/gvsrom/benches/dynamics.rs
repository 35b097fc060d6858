//! Dynamics speed (issue 3): the six-tendon arm without gravity (preset `six-tendon-no-gravity`, the
//! setup this bench has always timed; 28 DOF), 10 s of the paper's random step actuation
//! (new tensions uniform in [−15, 0] N every 1 s, seed 1), ode15s-class NDF at rtol 1e-3 / atol 1e-6,
//! single thread. The paper's MATLAB took 114.3 s; the target is ≥ 100× faster (≤ 1.2 s).
//!
//! Also the undamped release of issue 8 (`examples/undamped-release.toml`, 75 DOF, 6 s, the tip
//! force removed at t = 0) with the automatically chosen method for lightly damped rods (SDIRK4,
//! mass-norm error test, rtol 1e-4) and with the NDF of orders ≤ 2 at rtol 1e-3.
//!
//! And the cost of a tendon driven by its displacement through an elastic thread (issue 20's
//! follow-up): the IV-A arm (`single-tendon`, 33 DOF) for 4 s wound in by 4 mm on a thread of EA =
//! 200 N, against the same arm under the tension that displacement settles at, constant.
//!
//! Run with `cargo bench -p gvsrom --bench dynamics`.

use criterion::{criterion_group, criterion_main, Criterion};
use gvs::solve::dynamics::{IntegratorOptions, Method, OdeJacobian};
use gvs::solve::ode::NdfOptions;
use gvsrom::simulate::{plan, run, InputSource, SimulateOptions, Start};
use std::hint::black_box;
use std::ops::ControlFlow;

fn options(jacobian: OdeJacobian) -> SimulateOptions {
    SimulateOptions {
        duration: 10.0,
        sample_rate: 100.0,
        input: InputSource::Steps {
            lo: -15.0,
            hi: 0.0,
            period: 1.0,
            seed: 1,
        },
        start: Start::Rest,
        integrator: IntegratorOptions {
            method: Method::Ndf(NdfOptions {
                rtol: 1e-3,
                atol: 1e-6,
                ..NdfOptions::default()
            }),
            jacobian,
        },
        load_schedule: None,
    }
}

fn dynamics(c: &mut Criterion) {
    let built =
        gvsrom::build(&gvsrom::presets::load("six-tendon-no-gravity", &[]).unwrap()).unwrap();
    for (label, jac) in [
        (
            "dynamics/six-tendon 10s random steps (structured Jacobian)",
            OdeJacobian::Structured,
        ),
        (
            "dynamics/six-tendon 10s random steps (finite-difference Jacobian)",
            OdeJacobian::FiniteDifference,
        ),
    ] {
        let opts = options(jac);
        let plan = plan(&built, &opts).unwrap();
        c.bench_function(label, |b| {
            b.iter(|| {
                black_box(
                    run(&built, &plan, &opts.integrator, None, &mut |_| {
                        ControlFlow::Continue(())
                    })
                    .unwrap(),
                )
            })
        });
    }
}

fn release(c: &mut Criterion) {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let built = gvsrom::build(
        &gvsrom::presets::load(&format!("{root}/undamped-release.toml"), &[]).unwrap(),
    )
    .unwrap();
    let (auto, regime) =
        gvs::solve::dynamics::method_for_rod(&built.model, None, NdfOptions::default().atol)
            .unwrap();
    assert!(regime.is_light());
    let (ndf2, _) =
        gvs::solve::dynamics::ndf_for_rod(&built.model, &NdfOptions::default()).unwrap();
    for (label, method) in [
        ("automatic method: SDIRK4, rtol 1e-4", auto),
        ("NDF orders <= 2, rtol 1e-3", Method::Ndf(ndf2)),
    ] {
        let opts = SimulateOptions {
            duration: 6.0,
            sample_rate: 50.0,
            input: InputSource::Constant,
            start: Start::Equilibrium,
            integrator: IntegratorOptions {
                method,
                jacobian: OdeJacobian::Structured,
            },
            load_schedule: Some(format!("{root}/release-zero.csv").into()),
        };
        let plan = plan(&built, &opts).unwrap();
        c.bench_function(&format!("dynamics/undamped release 6s ({label})"), |b| {
            b.iter(|| {
                black_box(
                    run(&built, &plan, &opts.integrator, None, &mut |_| {
                        ControlFlow::Continue(())
                    })
                    .unwrap(),
                )
            })
        });
    }
}

fn drive(c: &mut Criterion) {
    let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let driven = set(&[
        "tendons.0.tension=0",
        "tendons.0.displacement=0.004",
        "tendons.0.axial_stiffness=200",
    ]);
    let built = gvsrom::build(&gvsrom::presets::load("single-tendon", &driven).unwrap()).unwrap();
    let u = gvsrom::statics::solve(&built).unwrap().u[0];
    let by_tension = gvsrom::build(
        &gvsrom::presets::load("single-tendon", &set(&[&format!("tendons.0.tension={u}")]))
            .unwrap(),
    )
    .unwrap();
    for (label, built) in [
        ("wound in 4 mm, thread EA 200 N", &built),
        ("at the tension found, constant", &by_tension),
    ] {
        let opts = SimulateOptions {
            duration: 4.0,
            sample_rate: 100.0,
            input: InputSource::Constant,
            start: Start::Rest,
            integrator: IntegratorOptions::default(),
            load_schedule: None,
        };
        let plan = plan(built, &opts).unwrap();
        c.bench_function(&format!("dynamics/IV-A 4s ({label})"), |b| {
            b.iter(|| {
                black_box(
                    run(built, &plan, &opts.integrator, None, &mut |_| {
                        ControlFlow::Continue(())
                    })
                    .unwrap(),
                )
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = dynamics, release, drive
}
criterion_main!(benches);
