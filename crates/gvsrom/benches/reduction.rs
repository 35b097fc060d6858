//! Reduced models against the full one (issue 7, paper IV-A): one equilibrium of the single-tendon
//! arm at u = −2.7 N (not a training tension) with the HOM (33 DOF, from the straight rod), the
//! AE-ROM (r = 1, 7 hidden layers, from its anchors as `statics --model` starts: its own equilibria
//! at the training tensions, solved as `gvsrom train` does and interpolated at u) and the POD-ROM
//! with 7 modes (from its anchors likewise, and from the straight rod), and, as the floor of any
//! one-DOF reduced model on this engine, POD-1 (a constant strain column: no decoder cost; from its
//! anchors). Each solver as
//! `statics` runs it (`solver.jacobian = auto`: forward differences at one coordinate). Single thread.
//! The paper's MATLAB: HOM 670 ms, AE 42 ms, POD-7 165 ms.
//!
//! Dynamics in the same run: 2 s of random steps (new tensions uniform in [−6, 0] N every second,
//! seed 1, 100 samples/s) from rest in the equilibrium under gravity alone (the straight rod is
//! not on a decoder's manifold: the data all sag under gravity) with the HOM (second-order NDF, structured
//! iteration parts), the AE-ROM (first-order NDF with a finite-difference Jacobian, as
//! `simulate --model` runs decoders) and POD-7 (structured), all at rtol 1e-3 / atol 1e-6.
//!
//! The setup solves 200 training equilibria (tensions evenly in [−6, 3] N) and trains the AE for at
//! most 300 epochs, a few seconds.
//!
//! Also, for equal starts, the HOM from its own training solutions interpolated at u the same way,
//! and the AE-ROM from the nearest training sample's encoding (the start before anchors held
//! equilibria).
//!
//! Run with `cargo bench -p gvsrom --bench reduction`.

use criterion::{criterion_group, criterion_main, Criterion};
use gvs::inputs::random_steps;
use gvs::model::Model;
use gvs::solve::dynamics::{
    simulate, InitialState, IntegratorOptions, Method, OdeJacobian, Simulation,
};
use gvs::solve::ode::NdfOptions;
use gvs::solve::statics::{StaticsOptions, StaticsSolver};
use gvs::strain::StrainParam;
use gvsrom::reduce::{anchor_guess, solve_anchors, AnchorInput, AnchorProblem};
use nalgebra::DVector;
use rom::nn::{Autoencoder, TrainOptions};
use rom::pod::Pod;
use rom::reduced::{point_matrix, projection, PointLayout, ReducedParam};
use std::hint::black_box;
use std::ops::ControlFlow;

const TEST_TENSION: f64 = -2.7;

fn reduction(c: &mut Criterion) {
    let scenario = gvsrom::presets::load("single-tendon", &[]).expect("preset");
    let built = gvsrom::build(&scenario).expect("build");
    let hom = &built.model;
    let layout = PointLayout::active_in(&hom.param, &hom.disc);
    let pm = point_matrix(&hom.param, &layout);
    let p = projection(&pm).expect("projection");

    // training data: point strain deviations at 200 tensions
    let tensions: Vec<f64> = (0..200).map(|i| -6.0 + 9.0 * i as f64 / 199.0).collect();
    let mut solver = StaticsSolver::new(hom, built.options.clone());
    let mut rows = Vec::new();
    let mut qs = Vec::new();
    for &u in &tensions {
        let sol = solver
            .solve(&[u], &built.loads, None)
            .expect("training solve");
        rows.extend((&pm * &sol.q).iter());
        qs.push(sol.q);
    }
    let features = layout.len();

    // POD-7 and POD-1 on the HOM basis
    let pod = Pod::compute(&rows, features, 7).expect("pod");
    let pod_basis = hom.param.compose(&(&p * &pod.modes)).expect("compose");
    let pod_model = rom_model(&built, pod_basis);
    let pod1 = Pod::compute(&rows, features, 1).expect("pod");
    let pod1_model = rom_model(
        &built,
        hom.param.compose(&(&p * &pod1.modes)).expect("compose"),
    );

    // AE r = 1, 7 hidden layers
    let options = TrainOptions {
        latent: 1,
        hidden_layers: 7,
        epochs: 300,
        seed: 1,
        ..TrainOptions::default()
    };
    let (ae, _) = Autoencoder::train(&rows, features, &options, &mut |_, _, _| {
        ControlFlow::Continue(())
    })
    .expect("training");
    let nearest = tensions
        .iter()
        .enumerate()
        .min_by(|a, b| {
            (a.1 - TEST_TENSION)
                .abs()
                .total_cmp(&(b.1 - TEST_TENSION).abs())
        })
        .map(|(i, _)| i)
        .unwrap();
    let map = ae
        .decoder_map(p.as_slice(), p.nrows())
        .expect("decoder map");
    let mut latent: Vec<f64> = rows
        .chunks_exact(features)
        .flat_map(|row| ae.encode(row).expect("encode"))
        .collect();
    let z_enc = DVector::from_column_slice(&latent[nearest..nearest + 1]);
    let ae_param = ReducedParam::new(&hom.param, map, z_enc.clone()).expect("reduced");
    let ae_model = rom_model(&built, ae_param);
    // anchors as `gvsrom train` makes them: the AE-ROM's own equilibria at the training tensions
    let problem = AnchorProblem {
        u: &built.u,
        loads: &built.loads,
        inputs: &[AnchorInput::Tension(0)],
        table: None,
        length: hom.rod.length(),
    };
    let solved = solve_anchors(
        &ae_model,
        &built.options,
        &problem,
        &tensions,
        &mut latent,
        &|_| true,
    );
    assert_eq!(solved, tensions.len(), "anchor equilibria");
    let u = [TEST_TENSION];
    let z0 = anchor_guess(&tensions, &latent, 1, 1, &u).expect("anchor guess");
    // the HOM's counterpart: its training solutions, interpolated the same way
    let q_flat: Vec<f64> = qs.iter().flat_map(|q| q.iter().copied()).collect();
    let q_guess = anchor_guess(&tensions, &q_flat, 1, hom.n_dof(), &u).expect("hom guess");

    let mut hom_solver = StaticsSolver::new(hom, built.options.clone());
    c.bench_function("reduction/HOM 33 DOF equilibrium u=-2.7N", |b| {
        b.iter(|| black_box(hom_solver.solve(&u, &built.loads, None).expect("hom")))
    });
    let one_stage = StaticsOptions {
        ramp_steps: 1,
        ..built.options.clone()
    };
    // the HOM from its training solutions interpolated at u, as the AE-ROM starts from its anchors
    let mut hom_warm = StaticsSolver::new(hom, one_stage.clone());
    c.bench_function(
        "reduction/HOM 33 DOF equilibrium u=-2.7N from the training solutions",
        |b| {
            b.iter(|| {
                black_box(
                    hom_warm
                        .solve(&u, &built.loads, Some(&q_guess))
                        .expect("hom"),
                )
            })
        },
    );
    let mut ae_solver = StaticsSolver::new(&ae_model, one_stage.clone());
    c.bench_function("reduction/AE-ROM r=1 equilibrium u=-2.7N", |b| {
        b.iter(|| black_box(ae_solver.solve(&u, &built.loads, Some(&z0)).expect("ae")))
    });
    c.bench_function(
        "reduction/AE-ROM r=1 equilibrium u=-2.7N from the nearest encoding",
        |b| b.iter(|| black_box(ae_solver.solve(&u, &built.loads, Some(&z_enc)).expect("ae"))),
    );
    // POD anchors as `gvsrom pod` makes them: Vᵀx of each sample, then the POD-ROM's equilibria
    let pod_guess = |pod: &Pod, model: &Model<gvs::strain::LinearBasis>| {
        let k = pod.modes.ncols();
        let mut latent = pod.encode_rows(&rows);
        let solved = solve_anchors(
            model,
            &built.options,
            &problem,
            &tensions,
            &mut latent,
            &|_| true,
        );
        assert_eq!(solved, tensions.len(), "POD anchor equilibria");
        anchor_guess(&tensions, &latent, 1, k, &u).expect("pod guess")
    };
    let (pod7_z0, pod1_z0) = (pod_guess(&pod, &pod_model), pod_guess(&pod1, &pod1_model));
    let mut pod_solver = StaticsSolver::new(&pod_model, built.options.clone());
    c.bench_function(
        "reduction/POD-ROM 7 modes equilibrium u=-2.7N from the straight rod",
        |b| b.iter(|| black_box(pod_solver.solve(&u, &built.loads, None).expect("pod"))),
    );
    let mut pod_anchored = StaticsSolver::new(&pod_model, one_stage.clone());
    c.bench_function("reduction/POD-ROM 7 modes equilibrium u=-2.7N", |b| {
        b.iter(|| {
            black_box(
                pod_anchored
                    .solve(&u, &built.loads, Some(&pod7_z0))
                    .expect("pod"),
            )
        })
    });
    let mut pod1_solver = StaticsSolver::new(&pod1_model, one_stage.clone());
    for (label, sol) in [
        ("HOM", hom_solver.solve(&u, &built.loads, None)),
        (
            "HOM from the training solutions",
            hom_warm.solve(&u, &built.loads, Some(&q_guess)),
        ),
        ("AE-ROM", ae_solver.solve(&u, &built.loads, Some(&z0))),
        (
            "AE-ROM from the nearest encoding",
            ae_solver.solve(&u, &built.loads, Some(&z_enc)),
        ),
        (
            "POD-7",
            pod_anchored.solve(&u, &built.loads, Some(&pod7_z0)),
        ),
        (
            "POD-7 from the straight rod",
            pod_solver.solve(&u, &built.loads, None),
        ),
        ("POD-1", pod1_solver.solve(&u, &built.loads, Some(&pod1_z0))),
    ] {
        let sol = sol.expect("solve");
        eprintln!(
            "{label}: {} iterations, {} residuals, {} Jacobians",
            sol.iterations, sol.residual_evaluations, sol.jacobian_evaluations
        );
    }
    c.bench_function("reduction/POD-ROM 1 mode equilibrium u=-2.7N", |b| {
        b.iter(|| {
            black_box(
                pod1_solver
                    .solve(&u, &built.loads, Some(&pod1_z0))
                    .expect("pod1"),
            )
        })
    });

    // dynamics: the AE-ROM from the straight rod's coordinates (the encoder of zero strain, refined)
    let zero = vec![0.0; features];
    let z_guess = DVector::from_vec(ae.encode(&zero).expect("encode"));
    let map = ae
        .decoder_map(p.as_slice(), p.nrows())
        .expect("decoder map");
    let (z_rest, rest_norm) = ReducedParam::find_rest(&map, &z_guess);
    eprintln!(
        "AE rest z = {:?}, ‖c(z)‖ = {rest_norm:.3e}",
        z_rest.as_slice()
    );
    let ae_rest_model = rom_model(
        &built,
        ReducedParam::new(&hom.param, map, z_rest).expect("reduced"),
    );
    let hom_run = random_steps_run(hom, &built.loads, OdeJacobian::Structured);
    for (label, run) in [
        (
            "AE-ROM",
            random_steps_run(&ae_rest_model, &built.loads, OdeJacobian::FiniteDifference),
        ),
        (
            "POD-7",
            random_steps_run(&pod_model, &built.loads, OdeJacobian::Structured),
        ),
    ] {
        let (a, b) = (&hom_run.trajectory.tip, &run.trajectory.tip);
        let worst = a
            .iter()
            .zip(b)
            .map(|(a, b)| (a.pos - b.pos).norm())
            .fold(0.0, f64::max);
        eprintln!(
            "{label}: {} steps (HOM {}), tip within {:.3} % L of the HOM's over 2 s (start {:.3} %, end {:.3} %)",
            run.stats.steps,
            hom_run.stats.steps,
            100.0 * worst / hom.rod.length(),
            100.0 * (a[0].pos - b[0].pos).norm() / hom.rod.length(),
            100.0 * (a[a.len() - 1].pos - b[b.len() - 1].pos).norm() / hom.rod.length()
        );
    }
    c.bench_function("reduction/HOM 33 DOF 2 s random steps", |b| {
        b.iter(|| black_box(random_steps_run(hom, &built.loads, OdeJacobian::Structured)))
    });
    c.bench_function("reduction/AE-ROM r=1 2 s random steps", |b| {
        b.iter(|| {
            black_box(random_steps_run(
                &ae_rest_model,
                &built.loads,
                OdeJacobian::FiniteDifference,
            ))
        })
    });
    c.bench_function("reduction/POD-ROM 7 modes 2 s random steps", |b| {
        b.iter(|| {
            black_box(random_steps_run(
                &pod_model,
                &built.loads,
                OdeJacobian::Structured,
            ))
        })
    });
}

/// 2 s of random steps (uniform in [−6, 0] N every second, seed 1) from rest in the equilibrium
/// under gravity alone, sampled at 100 Hz, NDF at its default tolerances.
fn random_steps_run<P: StrainParam>(
    m: &Model<P>,
    loads: &gvs::loads::Loads,
    jacobian: OdeJacobian,
) -> Simulation {
    let steps = random_steps(1, -6.0, 0.0, 1.0, 2.0, 1);
    let t_out: Vec<f64> = (0..=200).map(|k| k as f64 * 0.01).collect();
    let options = IntegratorOptions {
        method: Method::Ndf(NdfOptions::default()),
        jacobian,
    };
    let initial = InitialState::Equilibrium {
        u: vec![0.0],
        loads: loads.clone(),
    };
    let s = simulate(m, &steps, loads, None, &initial, &t_out, &options).expect("simulate");
    assert!(s.error.is_none(), "{:?}", s.error);
    s
}

fn rom_model<P: StrainParam>(built: &gvsrom::Built, param: P) -> Model<P> {
    let m = &built.model;
    Model::new(m.rod.clone(), m.disc.clone(), param, m.tendons.clone())
        .expect("model")
        .with_base(m.base)
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50);
    targets = reduction
}
criterion_main!(benches);
