//! Statics cost vs the number of DOF (issue 8): one equilibrium of the soft beam (IV-B load in the
//! peak reading, preset `soft-beam-peak`: 4 N·m/m peak) with a rich FEM-like basis — all six strain
//! modes, quadratic elements, `E` elements and 3 Gauss points per element, `n = 6 (2E + 1)` DOF —
//! from the straight rod, single thread. The solve converges in one dogleg iteration at every size,
//! so this measures the residual, the analytic Jacobian and the LU of one Newton step.
//!
//! Run with `cargo bench -p gvsrom --bench statics_dof` (the largest size takes a few seconds per
//! sample group; `STATICS_DOF_ELEMENTS=4,10,20` selects the sizes).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use gvs::solve::statics::StaticsSolver;
use std::hint::black_box;

/// Element counts `E` benchmarked by default: 54 to 1926 DOF.
const ELEMENTS: [usize; 6] = [4, 10, 20, 40, 80, 160];

fn elements() -> Vec<usize> {
    match std::env::var("STATICS_DOF_ELEMENTS") {
        Ok(s) => s
            .split(',')
            .map(|e| e.trim().parse().expect("STATICS_DOF_ELEMENTS: integers"))
            .collect(),
        Err(_) => ELEMENTS.to_vec(),
    }
}

fn statics_dof(c: &mut Criterion) {
    let mut group = c.benchmark_group("statics_dof/soft-beam fem6 quadratic");
    for e in elements() {
        let overrides = vec![
            format!(
                "divisions.0.basis={{ kind = \"fem\", modes = [\"torsion\",\"bend_y\",\"bend_z\",\"elongation\",\"shear_y\",\"shear_z\"], elements = {e}, degree = \"quadratic\" }}"
            ),
            format!("divisions.0.quadrature={{ gauss_per_element = 3, elements = {e} }}"),
        ];
        let scenario = gvsrom::presets::load("soft-beam-peak", &overrides).expect("preset");
        let built = gvsrom::build(&scenario).expect("build");
        let n = built.model.n_dof();
        let mut solver = StaticsSolver::new(&built.model, built.options.clone());
        group.sample_size(if n > 1000 { 10 } else { 20 });
        group.bench_with_input(
            BenchmarkId::from_parameter(format!("{n} DOF")),
            &n,
            |b, _| {
                b.iter(|| {
                    black_box(
                        solver
                            .solve(&built.u, &built.loads, None)
                            .expect("converges"),
                    )
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, statics_dof);
criterion_main!(benches);
