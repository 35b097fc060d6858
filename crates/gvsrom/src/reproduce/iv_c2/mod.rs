//! Case IV-C2: the six-tendon manipulator's dynamics (paper Section IV-C2, Fig. 9, Table III
//! same-DOF row).
//!
//! Data: 180 s of actuator babbling under gravity (each tendon holds a uniform tension in
//! [−15, 0] N for 0.5–1 s), sampled at 100 Hz: 18 001 snapshots (`gvsrom dataset --duration
//! --babble`). Models: for r = 1 … 8 an autoencoder with 7 hidden layers and POD with r modes; at
//! r = 7 more autoencoders (other seeds, the paper's λ) for the choice of λ. Test: a new 10 s input,
//! new random tensions in [−15, 0] N every second, sampled at 100 Hz; the HOM and every ROM
//! simulated with it one after the other (`gvsrom simulate [--model]`), each ROM's trajectory
//! compared with the HOM's (`gvsrom compare`: mean tip error in % of the length) and timed.

mod energy_pod;
mod figures;
mod frequencies;
mod kinetic_dofs;
mod more_tests;
mod rate_weights;
mod report;
mod variants;

use super::report::{CaseReport, RenderedFigure};
use super::sim_test::{simulate_test, SimRun, Test};
use super::step::Step;
use super::tasks::{self, AeConfig, DatasetSpec, ModelInfo, ScenarioSpec};
use super::{new_report, paper, Case, Options, Run};
use crate::compare::Trajectory;
use crate::simulate::IntegratorChoice;
use energy_pod::{
    energy_pod_finding, energy_pod_model, energy_pod_table, fig9_energy_finding, run_energy_pod,
};
use figures::{fig9, trace_figure, Arm, Inset};
use frequencies::{frequencies_notes, frequencies_table, natural_frequencies};
use kinetic_dofs::{kinetic_dofs_finding, kinetic_dofs_table, run_kinetic_dofs};
use more_tests::{ae_timing, more_tests_findings, more_tests_table, run_more_tests, TestRuns};
use rate_weights::LossWeights;
use report::{
    fig9_table, findings, lambda_table, models_table, notes, table_iii, tip_travel, Context,
};
use serde_json::json;
use variants::{run_variant, variant_findings, variant_table, DataVariant};

/// Hidden layers of every autoencoder (the paper's deepest, as in Table I).
const HIDDEN_LAYERS: usize = 7;
/// Weight decay of the autoencoders that become ROMs: the paper's, against the squared error of a
/// whole snapshot as in eq. (15) (`rom::nn::train`). (Applied against the per-entry error, as
/// `gvsrom train` did before, 1e-4 was hundreds of times stronger and its AE-ROMs left their
/// training region on this test.) The λ table compares it with [`LAMBDA_OTHER`] at the inset's r.
pub(super) const LAMBDA: f64 = 1e-4;
/// The other weight decay of the λ table: 100 times weaker.
pub(super) const LAMBDA_OTHER: f64 = 1e-6;
/// Babbling of the data: tensions in [lo, hi] N held for [hold_min, hold_max] s (paper IV-C2).
const BABBLE: [f64; 4] = [-15.0, 0.0, 0.5, 1.0];
/// Samples per second of the data and of the test trajectories (paper: 100 Hz).
const SAMPLE_RATE: f64 = 100.0;
/// Seed of the babbling (the test input draws with [`TEST_SEED`]: another signal).
const DATA_SEED: u64 = 0;
/// The test input: new tensions uniform in [lo, hi] N on every tendon every `period` s.
const TEST_STEPS: [f64; 3] = [-15.0, 0.0, 1.0];
const TEST_SEED: u64 = 2;
/// Interleaved HOM/AE-ROM timing pairs per repetition of a test run (9 in the full run).
const TIMING_ROUNDS_PER_REPEAT: usize = 3;

/// Sizes of the full, the quick and the tiny run.
struct Sizes {
    /// Babbling time [s].
    data_s: f64,
    /// The reduced sizes r (AE latent size = POD modes).
    dofs: Vec<usize>,
    epochs: usize,
    /// Test duration [s].
    test_s: f64,
    /// Runs of each test simulation; the smallest wall time is kept.
    repeat: usize,
    /// Training seeds of the λ comparison at the inset's r (the ROMs of every r use the first).
    seeds: Vec<u64>,
    /// Seeds of more test inputs for the inset's ROMs (besides [`TEST_SEED`]).
    more_tests: Vec<u64>,
    /// Seeds of the validation inputs that choose the rate-term variants' β (never tests).
    validation: Vec<u64>,
}

fn sizes(opts: &Options) -> Sizes {
    if opts.tiny {
        Sizes {
            data_s: 10.0,
            dofs: vec![2, 3],
            epochs: 5,
            test_s: 2.0,
            repeat: 1,
            seeds: vec![0],
            more_tests: vec![],
            validation: vec![],
        }
    } else if opts.quick {
        Sizes {
            data_s: 30.0,
            dofs: vec![2, 4, 7],
            epochs: 40,
            test_s: 10.0,
            repeat: 1,
            seeds: vec![0],
            more_tests: vec![3],
            validation: vec![7],
        }
    } else {
        Sizes {
            data_s: 180.0,
            dofs: (1..=8).collect(),
            epochs: 300,
            test_s: 10.0,
            repeat: 3,
            seeds: vec![0, 1, 2],
            more_tests: vec![3, 4, 5, 6],
            validation: vec![7, 8, 9],
        }
    }
}
/// One reduced size: its models and their test runs.
pub(super) struct Dof {
    pub(super) r: usize,
    pub(super) ae: Step<ModelInfo>,
    pub(super) pod: Step<ModelInfo>,
    pub(super) ae_run: SimRun,
    pub(super) pod_run: SimRun,
    /// Beyond the paper: the POD of the autoencoders' norm (`gvsrom pod --norm energy`).
    pub(super) pod_energy: Step<ModelInfo>,
    pub(super) pod_energy_run: SimRun,
}

/// An autoencoder of the λ comparison at the inset's r: its weight decay and seed, and its run.
pub(super) struct Variant {
    pub(super) lambda: f64,
    pub(super) seed: u64,
    pub(super) model: ModelInfo,
    pub(super) run: SimRun,
}

/// The step name of an AE (`ae-…`) or its test (`test-ae-…`) with r, λ and seed: `…-r7` for the
/// ROMs of Fig. 9 (λ = [`LAMBDA`], the first seed), `…-r7-lambda-1e-4-seed1` for another.
fn ae_name(prefix: &str, r: usize, lambda: f64, seed: u64, first_seed: u64) -> String {
    let mut name = format!("iv-c2/{prefix}-r{r}");
    if lambda != LAMBDA {
        name += &format!("-lambda-{lambda:e}");
    }
    if seed != first_seed {
        name += &format!("-seed{seed}");
    }
    name
}

/// Runs case IV-C2.
pub fn run(run: &Run, opts: &Options) -> anyhow::Result<(CaseReport, Vec<RenderedFigure>)> {
    let s = sizes(opts);
    let scenario = ScenarioSpec::new("six-tendon", &[]);
    let plan = DatasetSpec {
        duration: Some(s.data_s),
        babble: Some(BABBLE.to_vec()),
        sample_rate: Some(SAMPLE_RATE),
        seed: DATA_SEED,
        ..DatasetSpec::default()
    };
    let data = tasks::dataset(run, "iv-c2/dataset", &scenario, &plan, opts.jobs)?;

    // the inset's r: the paper's 7 when tried, else the largest
    let inset = if s.dofs.contains(&paper::TABLE_III_IV_C2.ae_dof) {
        paper::TABLE_III_IV_C2.ae_dof
    } else {
        *s.dofs.last().expect("at least one r")
    };
    let first_seed = s.seeds[0];
    let ae_config = |r: usize, lambda: f64, seed: u64| AeConfig {
        lambda,
        seed,
        ..AeConfig::new(r, HIDDEN_LAYERS, s.epochs)
    };
    // every autoencoder at once (they cost about the same: r changes only the innermost layers):
    // the ROMs of every r, then the other λ and seeds at the inset's r
    let mut jobs: Vec<(String, AeConfig)> = s
        .dofs
        .iter()
        .map(|&r| {
            let name = ae_name("ae", r, LAMBDA, first_seed, first_seed);
            (name, ae_config(r, LAMBDA, first_seed))
        })
        .collect();
    let variants: Vec<(f64, u64)> = [LAMBDA, LAMBDA_OTHER]
        .iter()
        .flat_map(|&l| s.seeds.iter().map(move |&seed| (l, seed)))
        .filter(|&(l, seed)| !(l == LAMBDA && seed == first_seed))
        .collect();
    for &(l, seed) in &variants {
        let name = ae_name("ae", inset, l, seed, first_seed);
        jobs.push((name, ae_config(inset, l, seed)));
    }
    let mut trained = tasks::parallel(&jobs, |(name, c)| tasks::train(run, name, &data, c))?;
    let variant_models = trained.split_off(s.dofs.len());
    let pods = tasks::parallel(&s.dofs, |&r| {
        tasks::pod(run, &format!("iv-c2/pod-{r}"), &data, r)
    })?;
    let energy_pods = tasks::parallel(&s.dofs, |&r| energy_pod_model(run, &data, r))?;

    // the test runs, one after the other so that their wall times compare
    let test = Test {
        duration: s.test_s,
        sample_rate: SAMPLE_RATE,
        steps: TEST_STEPS,
        seed: TEST_SEED,
        integrator: IntegratorChoice::default(),
        repeat: s.repeat,
    };
    let hom = simulate_test(run, "iv-c2/test-hom", "HOM", &scenario, &test, None, None)?;
    let mut dofs = vec![];
    let mut inset_runs = None;
    for (((&r, ae), pod), pod_energy) in s.dofs.iter().zip(trained).zip(pods).zip(energy_pods) {
        let ae_run = simulate_test(
            run,
            &format!("iv-c2/test-ae-r{r}"),
            &format!("AE-{r}"),
            &scenario,
            &test,
            Some(&ae),
            Some(&hom),
        )?;
        let pod_run = simulate_test(
            run,
            &format!("iv-c2/test-pod-{r}"),
            &format!("POD-{r}"),
            &scenario,
            &test,
            Some(&pod),
            Some(&hom),
        )?;
        let pod_energy_run = simulate_test(
            run,
            &format!("iv-c2/test-pod-{r}-energy"),
            &format!("POD-{r}, energy norm"),
            &scenario,
            &test,
            Some(&pod_energy),
            Some(&hom),
        )?;
        if r == inset {
            inset_runs = Some((
                Trajectory::load(&ae_run.path, "AE")?,
                Trajectory::load(&pod_run.path, "POD")?,
            ));
        }
        dofs.push(Dof {
            r,
            ae,
            pod,
            ae_run: ae_run.value,
            pod_run: pod_run.value,
            pod_energy,
            pod_energy_run: pod_energy_run.value,
        });
    }
    let mut lambdas = vec![];
    for (&(lambda, seed), model) in variants.iter().zip(variant_models) {
        let test_run = simulate_test(
            run,
            &ae_name("test-ae", inset, lambda, seed, first_seed),
            &format!("AE-{inset} (λ = {lambda:e}, seed {seed})"),
            &scenario,
            &test,
            Some(&model),
            Some(&hom),
        )?;
        lambdas.push(Variant {
            lambda,
            seed,
            model: model.value,
            run: test_run.value,
        });
    }
    let inset_dof = dofs
        .iter()
        .find(|d| d.r == inset)
        .expect("the inset's r is tried");
    lambdas.insert(
        0,
        Variant {
            lambda: LAMBDA,
            seed: first_seed,
            model: inset_dof.ae.value.clone(),
            run: inset_dof.ae_run.clone(),
        },
    );
    // the inset AE-ROM's wall time against the HOM's in interleaved pairs, on every test input
    let rounds = TIMING_ROUNDS_PER_REPEAT * s.repeat;
    let paper_timing = ae_timing(run, &scenario, &test, inset, &inset_dof.ae, rounds)?;
    let mut tests = vec![TestRuns {
        seed: TEST_SEED,
        hom: hom.value.clone(),
        ae: inset_dof.ae_run.clone(),
        pod: inset_dof.pod_run.clone(),
        ae_timing: Some(paper_timing),
    }];
    tests.extend(run_more_tests(
        run,
        &scenario,
        &test,
        &s.more_tests,
        inset,
        &inset_dof.ae,
        &inset_dof.pod,
        rounds,
    )?);
    // beyond the paper: the inset ROMs' lowest natural frequencies against the HOM's
    // (about the slack arm: where the tests start, and inside the full run's training inputs)
    let slack = 0.0;
    let frequencies = natural_frequencies(
        run,
        &scenario,
        slack,
        &[
            (format!("AE-{inset}"), &inset_dof.ae),
            (format!("POD-{inset}"), &inset_dof.pod),
            (format!("POD-{inset}, energy norm"), &inset_dof.pod_energy),
        ],
    )?;
    // beyond the paper: POD in the norm the autoencoders are trained in, on every test input (the
    // paper's test already ran for Fig. 9)
    let mut energy_runs = vec![inset_dof.pod_energy_run.clone()];
    energy_runs.extend(run_energy_pod(
        run,
        &scenario,
        &test,
        &inset_dof.pod_energy,
        inset,
        &s.more_tests,
    )?);
    // beyond the paper: the same budget over a longer babbling, a more damped arm and the arm
    // hanging along gravity, on the same inputs; a variant whose model the inputs lie outside of
    // (a short quick-run babbling may not reach the test's tensions) is left out, with the reason
    // in the notes
    let test_seeds: Vec<u64> = std::iter::once(TEST_SEED)
        .chain(s.more_tests.iter().copied())
        .collect();
    let mut variant_runs = vec![];
    let mut variants_skipped = vec![];
    for variant in [
        DataVariant::Spread,
        DataVariant::Damped,
        DataVariant::Hanging,
        DataVariant::Rates,
        DataVariant::HangingRates,
        DataVariant::Kinetic,
        DataVariant::HangingKinetic,
        DataVariant::SpreadKinetic,
    ] {
        let result = run_variant(
            run,
            variant,
            &scenario,
            &plan,
            opts.jobs,
            &ae_config(inset, LAMBDA, first_seed),
            &test,
            &hom,
            (&test_seeds, &s.validation, rounds),
        );
        run.check_interrupt()?;
        match result {
            Ok(v) => variant_runs.push(v),
            Err(e) => variants_skipped.push(format!(
                "The variant {variant:?} (beyond the paper) was left out: {e:#}"
            )),
        }
    }
    // beyond the paper: Fig. 9 with every r's AE trained as the kinetic variant's chosen one
    let kinetic_weights = variant_runs
        .iter()
        .find(|v| v.variant == DataVariant::Kinetic)
        .and_then(|v| v.selection.as_ref())
        .map(|sel| sel.chosen);
    let kinetic_dofs = match kinetic_weights {
        Some(w) => {
            let ae = |r: usize| ae_config(r, LAMBDA, first_seed);
            let runs = run_kinetic_dofs(run, (&data, &scenario), &ae, w, (&test, &hom), &s.dofs)?;
            Some((w, runs))
        }
        None => None,
    };
    run.check_interrupt()?;
    let (ae, pod) = inset_runs.expect("the inset's r is tried");
    let trajectories = Inset {
        r: inset,
        hom: Trajectory::load(&hom.path, "HOM")?,
        ae,
        pod,
    };
    let hom = hom.value;

    let mut report = new_report(
        Case::IvC2,
        "six-tendon multisection manipulator, dynamics (paper Section IV-C2)",
    );
    let dof_list = s
        .dofs
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    let [lo, hi, hmin, hmax] = BABBLE;
    let [tlo, thi, period] = TEST_STEPS;
    report.setup = vec![
        format!("scenario: `ScenarioSpec::new(\"six-tendon\", &[])`, as IV-C1: the preset `six-tendon`, with gravity along −z (0.6 m arm in two 0.3 m divisions, radius 2 → 1 cm, E = 1 MPa, Kelvin–Voigt damping η = 10 kPa·s; base along +x, so a horizontal cantilever that sags; six frictionless tendons 60° apart, alternating full and half length; {}-DOF Legendre basis, {} values per snapshot)", hom.dof, data.value.features),
        format!("data: {} s of actuator babbling, each tendon holding a uniform tension in [{lo}, {hi}] N for a uniform {hmin}–{hmax} s, from the straight rod at rest, sampled at {SAMPLE_RATE} Hz, seed {DATA_SEED} (`gvsrom dataset six-tendon --duration {} --babble={lo},{hi},{hmin},{hmax} --sample-rate {SAMPLE_RATE} --seed {DATA_SEED}`): {} snapshots, {} of them computed ({} failed)", s.data_s, s.data_s, data.value.samples, data.value.ok, data.value.failed),
        format!("autoencoders: one per r = {dof_list}, each with {HIDDEN_LAYERS} hidden layers, tanh, λ = {LAMBDA:e} (the paper's, against a whole snapshot's squared error), loss weighted by the section stiffness (strain-energy norm), 1 % zero-strain rows (the straight rod the simulations start from), Adam ≤ {} epochs with early stopping (patience {}) and learning-rate reductions, then L-BFGS, seed {first_seed}; at r = {inset} also λ = {LAMBDA:e} and {LAMBDA_OTHER:e} with seeds {}, otherwise the same", s.epochs, AeConfig::new(1, HIDDEN_LAYERS, s.epochs).patience, s.seeds.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")),
        format!("POD: r = {dof_list} modes of the uncentred snapshots"),
        format!("test: {} s of new uniform random tensions in [{tlo}, {thi}] N on every tendon every {period} s, seed {TEST_SEED}, sampled at {SAMPLE_RATE} Hz (`gvsrom simulate six-tendon --duration {} --steps={tlo},{thi},{period} --seed {TEST_SEED} [--model M] --out DIR`, then `gvsrom compare HOM-DIR DIR`); every model starts at rest (the HOM and POD from the straight rod, an AE from its rest point, the encoding of the straight rod, as the data start there), with `simulate`'s automatic integrator{}", s.test_s, s.test_s, if s.more_tests.is_empty() { String::new() } else { format!("; the r = {inset} ROMs also on {} more inputs of the same kind, seeds {}", s.more_tests.len(), s.more_tests.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")) }),
        format!("timing: the simulations run one after the other on one thread, each {} time(s) (the trajectory written once), the smallest wall time of the integration kept; the AE-{inset}-ROM against the HOM also in {} interleaved pairs per test input (HOM, then AE-ROM, without output), the median of the pairs' time ratios kept; error: mean over the samples of ‖p_ROM − p_HOM‖ / L (`gvsrom compare`'s tip mean)", s.repeat, TIMING_ROUNDS_PER_REPEAT * s.repeat),
    ];
    report.tables.push(fig9_table(&dofs, &hom));
    report.tables.push(table_iii(inset_dof, &hom));
    report.tables.push(more_tests_table(inset, &tests));
    report
        .tables
        .push(energy_pod_table(inset, &tests, &energy_runs));
    report
        .tables
        .push(frequencies_table(&frequencies.value, slack));
    for v in &variant_runs {
        report.tables.push(variant_table(inset, v));
    }
    if let Some((w, k)) = &kinetic_dofs {
        report.tables.push(kinetic_dofs_table(&dofs, k, w));
    }
    report.tables.push(lambda_table(inset, &lambdas));
    report.tables.push(models_table(&dofs));
    report.findings = findings(&dofs, &hom, inset_dof);
    report.findings.extend(more_tests_findings(inset, &tests));
    report.findings.push(fig9_energy_finding(&dofs));
    report
        .findings
        .push(energy_pod_finding(inset, &tests, &energy_runs));
    report
        .findings
        .extend(variant_runs.iter().flat_map(|v| variant_findings(inset, v)));
    if let Some((_, k)) = &kinetic_dofs {
        report.findings.push(kinetic_dofs_finding(&dofs, k));
    }
    let context = Context {
        data_s: s.data_s,
        swing: tip_travel(&trajectories.hom, 1.0),
        length: trajectories.hom.length,
        lambdas: &lambdas,
    };
    report.notes = notes(&dofs, &hom, inset_dof, &context);
    report.notes.extend(variants_skipped);
    report
        .notes
        .extend(frequencies_notes(&frequencies.value, slack));
    report.settings = json!({
        "scenario": scenario,
        "plan": plan,
        "autoencoders": jobs.iter().map(|(n, c)| json!({ "step": n, "config": c })).collect::<Vec<_>>(),
        "pod_modes": s.dofs,
        "test": test,
        "inset_r": inset,
    });
    report.values = json!({
        "dataset": data.value,
        "hom": hom,
        "hom_tip_travel_within_1s_m": context.swing,
        "kinetic_dofs": kinetic_dofs.as_ref().map(|(w, k)| json!({
            "weights": w,
            "runs": k.iter().map(|d| json!({ "r": d.r, "run": d.run })).collect::<Vec<_>>(),
        })),
        "dofs": dofs.iter().map(|d| json!({
            "r": d.r, "ae_model": d.ae.value, "pod_model": d.pod.value,
            "ae": d.ae_run, "pod": d.pod_run,
            "pod_energy_model": d.pod_energy.value, "pod_energy": d.pod_energy_run,
        })).collect::<Vec<_>>(),
        "more_tests": tests,
        "energy_pod": { "model": inset_dof.pod_energy.value, "tests": energy_runs },
        "frequencies": frequencies.value,
        "variants": variant_runs.iter().map(|v| json!({
            "variant": format!("{:?}", v.variant), "dataset": v.data.value,
            "ae_model": v.ae.value, "pod_model": v.pod.value, "tests": v.tests,
            "rate_selection": v.selection,
        })).collect::<Vec<_>>(),
        "lambda": lambdas.iter().map(|v| json!({
            "lambda": v.lambda, "seed": v.seed, "model": v.model, "run": v.run,
        })).collect::<Vec<_>>(),
    });
    let kinetic_runs = kinetic_dofs.as_ref().map(|(_, k)| k.as_slice());
    let mut figures = vec![fig9(&dofs, &hom, &trajectories, kinetic_runs)?];
    // beyond the paper: each arm's tip traces on the paper's test, with the AE of the strain-rate
    // term beside them (and the kinetic-energy norm, the best of them, when that variant ran)
    let rated =
        |wanted: &[DataVariant]| -> anyhow::Result<Option<(LossWeights, String, Trajectory)>> {
            let found = wanted
                .iter()
                .find_map(|&w| variant_runs.iter().find(|v| v.variant == w))
                .and_then(|v| {
                    let chosen = v.selection.as_ref()?.chosen;
                    Some((
                        v.first_runs.as_ref()?[1].clone(),
                        chosen,
                        v.variant.data_note(),
                    ))
                });
            Ok(match found {
                Some((path, w, note)) => Some((w, note, Trajectory::load(&path, "AE, rate term")?)),
                None => None,
            })
        };
    // the paper's arm: only with such an AE (else Fig. 9 shows the same traces); the spread
    // babbling's when it ran (the paper's budget, the lowest errors)
    let horizontal = [
        DataVariant::SpreadKinetic,
        DataVariant::Kinetic,
        DataVariant::Rates,
    ];
    if let Some(rated) = rated(&horizontal)? {
        figures.push(trace_figure(
            Arm::Horizontal,
            &trajectories,
            Some(&rated),
            s.test_s,
        )?);
    }
    let hanging = variant_runs
        .iter()
        .find(|v| v.variant == DataVariant::Hanging);
    if let Some([h, a, p]) = hanging.and_then(|v| v.first_runs.as_ref()) {
        let inset = Inset {
            r: inset,
            hom: Trajectory::load(h, "HOM")?,
            ae: Trajectory::load(a, "AE")?,
            pod: Trajectory::load(p, "POD")?,
        };
        let rated = rated(&[DataVariant::HangingKinetic, DataVariant::HangingRates])?;
        figures.push(trace_figure(
            Arm::Hanging,
            &inset,
            rated.as_ref(),
            s.test_s,
        )?);
    }
    Ok((report, figures))
}
