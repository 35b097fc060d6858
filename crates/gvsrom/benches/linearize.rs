//! Linearization speed (`gvsrom linearize`, `Robot.linearize`), single thread, on the IV-A arm
//! (33 DOF, 102 points) and the six-tendon arm (28 DOF, 14 points):
//! * the engine's `A`, `B` about the equilibrium (`Model::linearize_equilibrium`, `q̈ = 0` held:
//!   analytic throughout);
//! * the same state through `Model::linearize`, which takes the residual's small `q̈` as given and
//!   so differences the inertial part in `q` (`4n` residuals);
//! * a moving state (also `2n` residuals for `∂ε/∂q̇`);
//! * the library's whole report about the equilibrium (with `C`, the balanced poles and the static
//!   gain), and the poles alone.
//!
//! Run with `cargo bench -p gvsrom --bench linearize`.

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DVector;
use std::hint::black_box;

fn bench_preset(c: &mut Criterion, label: &str, preset: &str) {
    let scenario = gvsrom::presets::load(preset, &[]).expect("preset");
    let built = gvsrom::build(&scenario).expect("build");
    let (_, lin) =
        gvsrom::linearize::about_equilibrium(&built, &gvsrom::linearize::Outputs::tip(&built))
            .expect("linearizes");
    let model = &built.model;
    let n = model.n_dof();
    let q = DVector::from_column_slice(&lin.q);
    let rest = DVector::zeros(n);
    // a moving state: small velocities, decreasing along the coordinates
    let qd = DVector::from_fn(n, |i, _| 1e-2 / (1.0 + i as f64));
    let loads = model.prepare_loads(&built.loads).expect("loads");
    let mut ws = model.workspace();
    let u = &built.u;
    c.bench_function(
        &format!("linearize/{label} A, B about the equilibrium"),
        |b| b.iter(|| black_box(model.linearize_equilibrium(&q, u, &loads, &mut ws))),
    );
    c.bench_function(
        &format!("linearize/{label} A, B with the residual's q̈"),
        |b| b.iter(|| black_box(model.linearize(&q, &rest, u, &loads, &mut ws))),
    );
    c.bench_function(&format!("linearize/{label} A, B moving"), |b| {
        b.iter(|| black_box(model.linearize(&q, &qd, u, &loads, &mut ws)))
    });
    c.bench_function(
        &format!("linearize/{label} report about the equilibrium"),
        |b| {
            b.iter(|| {
                black_box(gvsrom::linearize::about_equilibrium(
                    &built,
                    &gvsrom::linearize::Outputs::tip(&built),
                ))
            })
        },
    );
    let a = lin.a_matrix();
    c.bench_function(&format!("linearize/{label} poles alone"), |b| {
        b.iter(|| black_box(gvsrom::linearize::poles(&a)))
    });
}

fn linearize(c: &mut Criterion) {
    bench_preset(c, "single-tendon", "single-tendon");
    bench_preset(c, "six-tendon", "six-tendon");
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = linearize
}
criterion_main!(benches);
