//! Statics speed (issue 2): one equilibrium from the straight configuration, single thread, for the
//! paper's three robots. The paper's MATLAB (SoRoSim + fsolve) took 670 ms, 810 ms and 276 ms; the
//! target is at least 100× faster (≤ 6.7 ms, ≤ 8.1 ms, ≤ 2.8 ms). The soft beam and the six-tendon
//! arm run in the milder variants this bench has always timed (so its history stays comparable):
//! `soft-beam-peak`, a 4 N·m/m peak pulse (0.16 N·m in total), and `six-tendon-no-gravity`.
//!
//! Run with `cargo bench -p gvsrom --bench statics`.

use criterion::{criterion_group, criterion_main, Criterion};
use gvs::solve::statics::StaticsSolver;
use std::hint::black_box;

fn bench_preset(c: &mut Criterion, label: &str, preset: &str, overrides: &[&str]) {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let scenario = gvsrom::presets::load(preset, &overrides).expect("preset");
    let built = gvsrom::build(&scenario).expect("build");
    let mut solver = StaticsSolver::new(&built.model, built.options.clone());
    c.bench_function(label, |b| {
        b.iter(|| {
            black_box(
                solver
                    .solve(&built.u, &built.loads, None)
                    .expect("converges"),
            )
        })
    });
}

fn statics(c: &mut Criterion) {
    bench_preset(
        c,
        "statics/single-tendon u=-3N",
        "single-tendon",
        &["tendons.0.tension=-3"],
    );
    bench_preset(
        c,
        "statics/soft-beam 4Nm@0.25L",
        "soft-beam-peak",
        &[
            "loads.distributed.0.magnitude=4",
            "loads.distributed.0.center=0.2",
        ],
    );
    bench_preset(
        c,
        "statics/six-tendon u=[-10,0,0,0,0,0]N",
        "six-tendon-no-gravity",
        &[],
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = statics
}
criterion_main!(benches);
