//! One dynamics residual of an IV-C2-sized autoencoder ROM, with and without the mass matrix: the
//! two evaluations an AE-ROM's implicit steps are made of (the mass matrix is renewed at every
//! attempt). On the preset `six-tendon` (28-DOF Legendre basis, 14 points, 38 strain sites), a
//! decoder of the paper's IV-C2 AE-7 shape (7 → 10 → 21 → 42 → 84 point strains, tanh) with
//! Glorot weights (seed 1) folded with the least-squares projection onto the basis: the cost does
//! not depend on trained weights. The state is a small offset from the straight rod. Single thread.
//!
//! Run with `cargo bench -p gvsrom --bench ae_residual`.

use criterion::{criterion_group, criterion_main, Criterion};
use gvs::inputs::SplitMix64;
use gvs::model::Model;
use gvs::strain::StrainParam;
use nalgebra::DVector;
use rom::nn::{DecoderMap, Mlp, Scaling};
use rom::reduced::{point_matrix, projection, PointLayout, ReducedParam};
use std::hint::black_box;

fn ae_residual(c: &mut Criterion) {
    let built = gvsrom::build(&gvsrom::presets::load("six-tendon", &[]).unwrap()).unwrap();
    let hom = &built.model;
    let layout = PointLayout::active_in(&hom.param, &hom.disc);
    let p = projection(&point_matrix(&hom.param, &layout)).unwrap();
    let r = 7;
    let decoder = Mlp::glorot(&[r, 10, 21, 42, layout.len()], &mut SplitMix64::new(1)).unwrap();
    let map = DecoderMap::new(
        &decoder,
        &Scaling::identity(layout.len()),
        p.as_slice(),
        p.nrows(),
    )
    .unwrap();
    let param: Box<dyn StrainParam> =
        Box::new(ReducedParam::new(&hom.param, map, DVector::zeros(r)).unwrap());
    let model = Model::new(
        hom.rod.clone(),
        hom.disc.clone(),
        param,
        hom.tendons.clone(),
    )
    .unwrap()
    .with_base(hom.base);
    let q = DVector::from_fn(r, |i, _| 0.05 * (1.3 * i as f64).sin());
    let qd = DVector::from_fn(r, |i, _| 0.3 * (0.7 * i as f64).cos());
    let qdd = DVector::from_fn(r, |i, _| 2.0 * (0.4 * i as f64).sin());
    let u = [-3.0, -1.0, 0.0, -5.0, 0.0, -2.0];
    let loads = model.prepare_loads(&built.loads).unwrap();
    let mut ws = model.workspace();
    let mut res = DVector::zeros(r);
    c.bench_function(
        "ae_residual/AE-7 six-tendon residual and mass matrix",
        |b| {
            b.iter(|| {
                model.dynamics_residual_and_mass(&q, &qd, &qdd, &u, &loads, &mut ws, &mut res);
                black_box(res[0])
            })
        },
    );
    c.bench_function("ae_residual/AE-7 six-tendon residual", |b| {
        b.iter(|| {
            model.dynamics_residual(&q, &qd, &qdd, &u, &loads, &mut ws, &mut res);
            black_box(res[0])
        })
    });
}

criterion_group!(benches, ae_residual);
criterion_main!(benches);
