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

use super::report::{figure, ratio, CaseReport, Cell, Finding, RenderedFigure, Table};
use super::step::Step;
use super::tasks::{self, AeConfig, DatasetSpec, ModelInfo, ScenarioSpec};
use super::{new_report, paper, Case, Options, Run};
use crate::compare::{compare, Trajectory};
use crate::plot::{palette, Figure, LineChart, Series, SeriesStyle};
use crate::simulate::{self, Ending, InputSource, IntegratorChoice, SimulateOptions};
use crate::{reduce, Built};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::ops::ControlFlow;
use std::sync::atomic::Ordering;

/// Hidden layers of every autoencoder (the paper's deepest, as in Table I).
const HIDDEN_LAYERS: usize = 7;
/// Weight decay of the autoencoders that become ROMs: the paper's, against the squared error of a
/// whole snapshot as in eq. (15) (`rom::nn::train`). (Applied against the per-entry error, as
/// `gvsrom train` did before, 1e-4 was hundreds of times stronger and its AE-ROMs left their
/// training region on this test.) The λ table compares it with [`LAMBDA_OTHER`] at the inset's r.
const LAMBDA: f64 = 1e-4;
/// The other weight decay of the λ table: 100 times weaker.
const LAMBDA_OTHER: f64 = 1e-6;
/// Babbling of the data: tensions in [lo, hi] N held for [hold_min, hold_max] s (paper IV-C2).
const BABBLE: [f64; 4] = [-15.0, 0.0, 0.5, 1.0];
/// Samples per second of the data and of the test trajectories (paper: 100 Hz).
const SAMPLE_RATE: f64 = 100.0;
/// Seed of the babbling (the test input draws with [`TEST_SEED`]: another signal).
const DATA_SEED: u64 = 0;
/// The test input: new tensions uniform in [lo, hi] N on every tendon every `period` s.
const TEST_STEPS: [f64; 3] = [-15.0, 0.0, 1.0];
const TEST_SEED: u64 = 2;

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
        }
    } else if opts.quick {
        Sizes {
            data_s: 30.0,
            dofs: vec![2, 4, 7],
            epochs: 40,
            test_s: 10.0,
            repeat: 1,
            seeds: vec![0],
        }
    } else {
        Sizes {
            data_s: 180.0,
            dofs: (1..=8).collect(),
            epochs: 300,
            test_s: 10.0,
            repeat: 3,
            seeds: vec![0, 1, 2],
        }
    }
}

/// The test of every model: the input, its length and the integrator (the CLI's automatic
/// choice).
#[derive(Debug, Clone, Serialize)]
struct Test {
    duration: f64,
    sample_rate: f64,
    steps: [f64; 3],
    seed: u64,
    integrator: IntegratorChoice,
    repeat: usize,
}

impl Test {
    fn options(&self, built: &Built) -> anyhow::Result<(SimulateOptions, Option<String>)> {
        let (integrator, note) = simulate::choose_integrator(built, &self.integrator)?;
        let [lo, hi, period] = self.steps;
        Ok((
            SimulateOptions {
                duration: self.duration,
                sample_rate: self.sample_rate,
                input: InputSource::Steps {
                    lo,
                    hi,
                    period,
                    seed: self.seed,
                },
                start_at_equilibrium: false,
                integrator,
                load_schedule: None,
            },
            note,
        ))
    }
}

/// A ROM's trajectory against the HOM's over their common samples (`gvsrom compare`), in %.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Errors {
    samples: usize,
    tip_mean: f64,
    tip_max: f64,
    tip_max_t: f64,
    tip_end: f64,
    strain_mean: Option<f64>,
    strain_max: Option<f64>,
}

/// One simulation of the test: how it ended, what it cost, and (for a ROM) its error against the
/// HOM.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct SimRun {
    label: String,
    dof: usize,
    complete: bool,
    /// Why the run ended early, in full.
    reason: Option<String>,
    /// The run ended early because it left the training region (else: the integrator failed).
    left_training_region: bool,
    /// Time of the last sample [s].
    t_reached: f64,
    samples: usize,
    /// The smallest wall time of the integration over the repetitions [s].
    wall_time_s: f64,
    wall_times_s: Vec<f64>,
    method: String,
    /// The integrator line `simulate` prints when the rod's damping chose the method.
    integrator_note: Option<String>,
    steps: usize,
    failed_steps: usize,
    rhs_evaluations: usize,
    jacobian_evaluations: usize,
    /// Largest `|ξ − ξ*|` at the points of the model's start (a decoder's rest point; 0 for the
    /// HOM and POD, which start from the straight rod).
    start_offset: f64,
    /// `None` for the HOM.
    error: Option<Errors>,
}

impl SimRun {
    fn tip_mean(&self) -> f64 {
        self.error.as_ref().map_or(f64::NAN, |e| e.tip_mean)
    }
    /// "complete", or where and why it stopped, in short (the full reason is in `reason`).
    fn status(&self) -> String {
        if self.complete {
            return "complete".into();
        }
        let why = if self.left_training_region {
            "left its training region"
        } else {
            "the integrator failed"
        };
        format!("stopped at t = {:.2} s ({why})", self.t_reached)
    }
}

/// The test simulated with the HOM (`model: None`) or a reduced model, written as a trajectory to
/// the step's path (`gvsrom simulate … [--model M] --out DIR`) and, for a ROM, compared with the
/// HOM's (`gvsrom compare`). The simulation is repeated `test.repeat` times without output and the
/// smallest wall time kept. A ROM run that ends early is recorded as partial with its reason; the
/// HOM's must complete.
fn simulate_test(
    run: &Run,
    name: &str,
    label: &str,
    scenario: &ScenarioSpec,
    test: &Test,
    model: Option<&Step<ModelInfo>>,
    hom: Option<&Step<SimRun>>,
) -> anyhow::Result<Step<SimRun>> {
    let config = json!({
        "label": label, "scenario": scenario, "test": test,
        "model": model.map(Step::key), "hom": hom.map(Step::key),
    });
    run.step(
        name,
        &config,
        |p| Trajectory::load(p, "RUN").is_ok(),
        |path| {
            let (mut built, table) = scenario.build()?;
            if let Some(m) = model {
                reduce::attach(&mut built, Some(&table), &m.path)?;
            }
            let (opts, note) = test.options(&built)?;
            let interrupt = run.interrupt().clone();
            let mut control = |_: f64| match interrupt.load(Ordering::SeqCst) {
                0 => ControlFlow::Continue(()),
                _ => ControlFlow::Break("interrupted".to_string()),
            };
            let written = simulate::run_to_dir(&built, &opts, path, true, &mut control)?;
            run.check_interrupt()?;
            let outcome = &written.outcome;
            let reason = match &outcome.ending {
                Ending::Complete => None,
                Ending::Failed { error } => Some(error.clone()),
                Ending::Interrupted { reason } => Some(reason.clone()),
            };
            if let (None, Some(r)) = (model, &reason) {
                anyhow::bail!("the HOM's simulation of the test failed: {r}");
            }
            let mut wall_times_s = vec![outcome.summary.wall_time_s];
            for _ in 1..test.repeat {
                let plan = simulate::plan(&built, &opts)?;
                let again = simulate::run(&built, &plan, &opts.integrator, None, &mut control)?;
                run.check_interrupt()?;
                wall_times_s.push(again.summary.wall_time_s);
            }
            let error = match hom {
                Some(h) => {
                    let c = compare(
                        &Trajectory::load(&h.path, "REFERENCE")?,
                        &Trajectory::load(&written.dir, "RUN")?,
                    )?;
                    Some(Errors {
                        samples: c.samples,
                        tip_mean: c.tip_mean,
                        tip_max: c.tip_max,
                        tip_max_t: c.tip_max_t,
                        tip_end: c.tip_end,
                        strain_mean: c.strain_mean,
                        strain_max: c.strain_max,
                    })
                }
                None => None,
            };
            let sm = &outcome.summary;
            Ok(SimRun {
                label: label.into(),
                dof: built.n_dof(),
                complete: outcome.ending == Ending::Complete,
                reason,
                left_training_region: outcome.left_training_region,
                t_reached: sm.t_last.unwrap_or(0.0),
                samples: written.samples,
                wall_time_s: wall_times_s.iter().copied().fold(f64::INFINITY, f64::min),
                wall_times_s,
                method: opts.integrator.method.name().into(),
                integrator_note: note,
                steps: sm.stats.steps,
                failed_steps: sm.stats.failed_steps,
                rhs_evaluations: sm.stats.rhs_evals,
                jacobian_evaluations: sm.stats.jacobian_evals,
                start_offset: built
                    .reduced
                    .as_ref()
                    .map_or(0.0, |r| r.rest_strain_offset()),
                error,
            })
        },
    )
}

/// One reduced size: its models and their test runs.
struct Dof {
    r: usize,
    ae: Step<ModelInfo>,
    pod: Step<ModelInfo>,
    ae_run: SimRun,
    pod_run: SimRun,
}

/// An autoencoder of the λ comparison at the inset's r: its weight decay and seed, and its run.
struct Variant {
    lambda: f64,
    seed: u64,
    model: ModelInfo,
    run: SimRun,
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
    for ((&r, ae), pod) in s.dofs.iter().zip(trained).zip(pods) {
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
        format!("test: {} s of new uniform random tensions in [{tlo}, {thi}] N on every tendon every {period} s, seed {TEST_SEED}, sampled at {SAMPLE_RATE} Hz (`gvsrom simulate six-tendon --duration {} --steps={tlo},{thi},{period} --seed {TEST_SEED} [--model M] --out DIR`, then `gvsrom compare HOM-DIR DIR`); every model starts at rest (the HOM and POD from the straight rod, an AE from its rest point, the encoding of the straight rod, as the data start there), with `simulate`'s automatic integrator", s.test_s, s.test_s),
        format!("timing: the simulations run one after the other on one thread, each {} time(s) (the trajectory written once), the smallest wall time of the integration kept; error: mean over the samples of ‖p_ROM − p_HOM‖ / L (`gvsrom compare`'s tip mean)", s.repeat),
    ];
    report.tables.push(fig9_table(&dofs, &hom));
    report.tables.push(table_iii(inset_dof, &hom));
    report.tables.push(lambda_table(inset, &lambdas));
    report.tables.push(models_table(&dofs));
    report.findings = findings(&dofs, &hom, inset_dof);
    let context = Context {
        data_s: s.data_s,
        swing: tip_travel(&trajectories.hom, 1.0),
        length: trajectories.hom.length,
        lambdas: &lambdas,
    };
    report.notes = notes(&dofs, &hom, inset_dof, &context);
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
        "dofs": dofs.iter().map(|d| json!({
            "r": d.r, "ae_model": d.ae.value, "pod_model": d.pod.value,
            "ae": d.ae_run, "pod": d.pod_run,
        })).collect::<Vec<_>>(),
        "lambda": lambdas.iter().map(|v| json!({
            "lambda": v.lambda, "seed": v.seed, "model": v.model, "run": v.run,
        })).collect::<Vec<_>>(),
    });
    let figures = vec![fig9(&dofs, &hom, &trajectories)?];
    Ok((report, figures))
}

/// Fig. 9's numbers: per r, both ROMs' mean tip error and wall time, and the HOM's time.
fn fig9_table(dofs: &[Dof], hom: &SimRun) -> Table {
    let reached = |x: &SimRun| Cell::sig(x.t_reached, 3);
    Table {
        id: "fig9".into(),
        title: format!(
            "Fig. 9: mean tip error and wall time of the {} s test per DOF",
            hom.t_reached
        ),
        columns: [
            "DOF r",
            "AE-ROM tip error [% L]",
            "AE-ROM time [s]",
            "AE-ROM reached [s]",
            "POD-ROM tip error [% L]",
            "POD-ROM time [s]",
            "POD-ROM reached [s]",
            "HOM time [s]",
        ]
        .map(String::from)
        .to_vec(),
        rows: dofs
            .iter()
            .map(|d| {
                vec![
                    Cell::int(d.r),
                    Cell::sig(d.ae_run.tip_mean(), 3),
                    Cell::sig(d.ae_run.wall_time_s, 3),
                    reached(&d.ae_run),
                    Cell::sig(d.pod_run.tip_mean(), 3),
                    Cell::sig(d.pod_run.wall_time_s, 3),
                    reached(&d.pod_run),
                    Cell::sig(hom.wall_time_s, 3),
                ]
            })
            .collect(),
        note: format!("Tip error: mean over the samples of ‖p_ROM − p_HOM‖ / L, L = 0.6 m. Time: wall time of the integration (smallest of the repetitions), one thread. Reached: the time of the last sample; a run that stopped before {} s (the decoder left its training region, or the integrator failed: reasons in results.json) is partial, and its error and time are up to where it stopped.", hom.t_reached),
    }
}

/// Table III's same-DOF row (r = 7 in the full run) beside the paper's.
fn table_iii(d: &Dof, hom: &SimRun) -> Table {
    let p = &paper::TABLE_III_IV_C2;
    let (p_pod, p_ae) = (
        p.pod_error.unwrap_or(f64::NAN),
        p.ae_error.unwrap_or(f64::NAN),
    );
    let (ae, pod) = (&d.ae_run, &d.pod_run);
    let num = |q: &str, ours: f64, paper: f64| {
        vec![
            Cell::text(q),
            Cell::sig(ours, 3),
            Cell::sig(paper, 3),
            ratio(ours, paper),
        ]
    };
    let rows = vec![
        vec![
            Cell::text("ROM DOF (POD modes = AE latent size)"),
            Cell::int(d.r),
            Cell::int(p.ae_dof),
            ratio(d.r as f64, p.ae_dof as f64),
        ],
        num("POD-ROM tip error [% L]", pod.tip_mean(), p_pod),
        num("POD-ROM time [s]", pod.wall_time_s, p.pod_time_s),
        num("AE-ROM tip error [% L]", ae.tip_mean(), p_ae),
        num("AE-ROM time [s]", ae.wall_time_s, p.ae_time_s),
        num("HOM time [s]", hom.wall_time_s, p.hom_time_s),
        num(
            "AE-ROM error reduction against POD [%]",
            (1.0 - ae.tip_mean() / pod.tip_mean()) * 100.0,
            (1.0 - p_ae / p_pod) * 100.0,
        ),
        num(
            "AE-ROM time / POD-ROM time",
            ae.wall_time_s / pod.wall_time_s,
            p.ae_time_s / p.pod_time_s,
        ),
        num(
            "AE-ROM speed-up over the HOM",
            hom.wall_time_s / ae.wall_time_s,
            p.hom_time_s / p.ae_time_s,
        ),
        num(
            "POD-ROM speed-up over the HOM",
            hom.wall_time_s / pod.wall_time_s,
            p.hom_time_s / p.pod_time_s,
        ),
    ];
    Table {
        id: "table-iii".into(),
        title: format!("Table III row (same DOF study: {} DOF)", d.r),
        columns: ["quantity", "ours", "paper", "ratio"].map(String::from).to_vec(),
        rows,
        note: format!(
            "Tip errors: mean over the {} s test of ‖p_ROM − p_HOM‖ / L. Times: wall time of the whole simulation. Ours: gvsrom, one thread, this machine; the paper's: MATLAB on an i9-13900HX. A run that stopped early has its error and time up to where it stopped: AE-{}: {}; POD-{}: {}. Other seeds of AE-{}: the λ table.",
            hom.t_reached,
            d.r,
            ae.status(),
            d.r,
            pod.status(),
            d.r
        ),
    }
}

/// The weight decay: the AE-ROMs at the inset's r with λ = 1e-6 (used) and 1e-4 (the paper's),
/// one row per training seed.
fn lambda_table(r: usize, lambdas: &[Variant]) -> Table {
    Table {
        id: "lambda".into(),
        title: format!("Weight decay λ and training seed of the AE-ROM with r = {r}"),
        columns: [
            "λ",
            "seed",
            "RMSE over the dataset",
            "validation RMSE",
            "reached [s]",
            "tip error [% L]",
            "time [s]",
            "run",
        ]
        .map(String::from)
        .to_vec(),
        rows: lambdas
            .iter()
            .map(|v| {
                vec![
                    Cell::sig(v.lambda, 1),
                    Cell::int(v.seed as usize),
                    Cell::sig(v.model.rmse_full, 3),
                    Cell::sig(v.model.val_rmse.unwrap_or(f64::NAN), 3),
                    Cell::sig(v.run.t_reached, 3),
                    Cell::sig(v.run.tip_mean(), 3),
                    Cell::sig(v.run.wall_time_s, 3),
                    Cell::text(v.run.status()),
                ]
            })
            .collect(),
        note: "Same data, architecture and epochs; λ and the seed (initial weights, train/validation split, mini-batch order) differ. The first row is the AE-ROM of Fig. 9 and Table III. RMSE: of the reconstruction D(E(x)) − x over every entry of every snapshot. A run that leaves the training region (q_r beyond the range of the training encodings by more than half its width) is stopped there: the decoder would extrapolate. Tip error and time up to where the run stopped.".into(),
    }
}

/// The models per r: the autoencoders' reconstruction and epochs, POD's captured energy.
fn models_table(dofs: &[Dof]) -> Table {
    Table {
        id: "models".into(),
        title: "The reduced models".into(),
        columns: [
            "r",
            "AE RMSE over the dataset",
            "AE validation RMSE",
            "AE epochs",
            "POD RMSE over the dataset",
            "POD captured energy",
            "AE start offset max |ξ − ξ*|",
        ]
        .map(String::from)
        .to_vec(),
        rows: dofs
            .iter()
            .map(|d| {
                let (a, p) = (&d.ae.value, &d.pod.value);
                vec![
                    Cell::int(d.r),
                    Cell::sig(a.rmse_full, 3),
                    Cell::sig(a.val_rmse.unwrap_or(f64::NAN), 3),
                    Cell::int(a.epochs_run.unwrap_or(0)),
                    Cell::sig(p.rmse_full, 3),
                    Cell::sig(p.captured_energy.unwrap_or(f64::NAN), 4),
                    Cell::sig(d.ae_run.start_offset, 3),
                ]
            })
            .collect(),
        note: "RMSE of x̂ − x over every entry of every snapshot, x = ξ − ξ* at the 14 points, six components (curvatures in 1/m, the others unitless). Epochs: Adam epochs plus L-BFGS iterations. Start offset: how far the AE's rest point (where its simulation starts) decodes from the straight rod the HOM starts from, largest |ξ − ξ*| over the points [1/m for curvatures].".into(),
    }
}

/// The paper's conclusions on Fig. 9, as measured.
fn findings(dofs: &[Dof], hom: &SimRun, inset: &Dof) -> Vec<Finding> {
    let list = |f: &dyn Fn(&Dof) -> bool| {
        let v: Vec<String> = dofs
            .iter()
            .filter(|d| f(d))
            .map(|d| d.r.to_string())
            .collect();
        (
            v.len(),
            if v.is_empty() {
                "none".into()
            } else {
                v.join(", ")
            },
        )
    };
    let n = dofs.len();
    // the AE is better at r when it completes and POD either stops or errs more
    let ae_better = |d: &Dof| {
        d.ae_run.complete && (!d.pod_run.complete || d.ae_run.tip_mean() < d.pod_run.tip_mean())
    };
    let (k_acc, acc_at) = list(&ae_better);
    let reduction = dofs
        .iter()
        .filter(|d| d.ae_run.complete && d.pod_run.complete)
        .map(|d| 1.0 - d.ae_run.tip_mean() / d.pod_run.tip_mean())
        .fold(f64::NAN, f64::max);
    // speed is known where a run that went through the test took less time than the other run
    // took (to its end, or to where it stopped): see `faster`
    let (k_ae_fast, ae_fast_at) = list(&|d| faster(&d.ae_run, hom) == Some(true));
    let (k_ae_slow, ae_slow_at) = list(&|d| faster(&d.ae_run, hom) == Some(false));
    let (k_pod_fast, pod_fast_at) = list(&|d| faster(&d.pod_run, hom) == Some(true));
    let (k_pod_slow, pod_slow_at) = list(&|d| faster(&d.pod_run, hom) == Some(false));
    let (k_pod_ae, pod_ae_at) = list(&|d| faster(&d.pod_run, &d.ae_run) == Some(true));
    let (k_ae_pod, ae_pod_at) = list(&|d| faster(&d.pod_run, &d.ae_run) == Some(false));
    let partial: Vec<String> = dofs
        .iter()
        .flat_map(|d| [&d.ae_run, &d.pod_run])
        .filter(|x| !x.complete)
        .map(|x| format!("{} at t = {:.2} s", x.label, x.t_reached))
        .collect();
    let partial = if partial.is_empty() {
        "every ROM run completed".to_string()
    } else {
        format!("stopped early: {}", partial.join(", "))
    };
    let (ae, pod) = (&inset.ae_run, &inset.pod_run);
    let p = &paper::TABLE_III_IV_C2;
    vec![
        Finding {
            claim: "the AE-ROM is more accurate than the POD-ROM at every tested DOF".into(),
            holds: k_acc == n,
            evidence: format!(
                "at {k_acc} of {n} DOFs (r = {acc_at}); the largest error reduction of a complete AE-ROM against a complete POD-ROM {} % (paper: up to {} %); {partial}",
                Cell::sig(reduction * 100.0, 3).render(),
                Cell::sig(paper::IV_C2_MAX_ERROR_REDUCTION * 100.0, 2).render(),
            ),
        },
        Finding {
            claim: format!("at {} DOF the AE-ROM is more accurate than the POD-ROM", inset.r),
            holds: ae_better(inset),
            evidence: format!(
                "mean tip error {} % L (AE-{}, {}) against {} % L (POD-{}, {}); paper {} % against {} %",
                Cell::sig(ae.tip_mean(), 3).render(),
                inset.r,
                ae.status(),
                Cell::sig(pod.tip_mean(), 3).render(),
                inset.r,
                pod.status(),
                Cell::sig(p.ae_error.unwrap_or(f64::NAN), 2).render(),
                Cell::sig(p.pod_error.unwrap_or(f64::NAN), 2).render(),
            ),
        },
        Finding {
            claim: "both ROMs are faster than the HOM (at every tested DOF)".into(),
            holds: k_ae_slow == 0 && k_pod_slow == 0 && k_ae_fast > 0 && k_pod_fast > 0,
            evidence: format!(
                "HOM {} s; the AE-ROM is faster at {k_ae_fast} of {n} DOFs (r = {ae_fast_at}) and slower at {k_ae_slow} (r = {ae_slow_at}), the POD-ROM faster at {k_pod_fast} (r = {pod_fast_at}) and slower at {k_pod_slow} (r = {pod_slow_at}); unknown at the others (stopped early, in less time than the HOM's whole run); at r = {}: AE {} s, POD {} s (paper at r = {}: {} s and {} s against {} s)",
                Cell::sig(hom.wall_time_s, 3).render(),
                inset.r,
                Cell::sig(ae.wall_time_s, 3).render(),
                Cell::sig(pod.wall_time_s, 3).render(),
                p.ae_dof,
                Cell::sig(p.ae_time_s, 3).render(),
                Cell::sig(p.pod_time_s, 3).render(),
                Cell::sig(p.hom_time_s, 4).render(),
            ),
        },
        Finding {
            claim: "at equal DOF the POD-ROM is faster than the AE-ROM".into(),
            holds: k_ae_pod == 0 && k_pod_ae > 0,
            evidence: format!(
                "POD faster at {k_pod_ae} of {n} DOFs (r = {pod_ae_at}), AE faster at {k_ae_pod} (r = {ae_pod_at}), unknown at the others (a run stopped early in less time than the other took); at r = {}: AE / POD time {} (paper at r = {}: {})",
                inset.r,
                Cell::sig(ae.wall_time_s / pod.wall_time_s, 3).render(),
                p.ae_dof,
                Cell::sig(p.ae_time_s / p.pod_time_s, 3).render()
            ),
        },
    ]
}

/// Whether run `a` is faster than run `b` over the whole test: `Some(true)` when `a` went through
/// it in less time than `b` took (to its end or to where it stopped), `Some(false)` the other way
/// round, `None` when neither did.
fn faster(a: &SimRun, b: &SimRun) -> Option<bool> {
    if a.complete && a.wall_time_s < b.wall_time_s {
        Some(true)
    } else if b.complete && b.wall_time_s <= a.wall_time_s {
        Some(false)
    } else {
        None
    }
}

/// The largest distance the tip travels within `window` seconds over the trajectory [m].
fn tip_travel(t: &Trajectory, window: f64) -> f64 {
    let p = |k: usize| [t.tip[3 * k], t.tip[3 * k + 1], t.tip[3 * k + 2]];
    let mut best = 0.0f64;
    for i in 0..t.samples() {
        for j in i + 1..t.samples() {
            if t.t[j] - t.t[i] > window + 1e-9 {
                break;
            }
            let (a, b) = (p(i), p(j));
            best = best.max((0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt());
        }
    }
    best
}

/// "ndf (r = 3, 4), sdirk (r = 1, 2)": the integrators `simulate` chose for a kind of ROM.
fn methods(dofs: &[Dof], run: impl Fn(&Dof) -> &SimRun) -> String {
    let mut by: Vec<(String, Vec<String>)> = vec![];
    for d in dofs {
        let m = &run(d).method;
        match by.iter_mut().find(|(name, _)| name == m) {
            Some((_, rs)) => rs.push(d.r.to_string()),
            None => by.push((m.clone(), vec![d.r.to_string()])),
        }
    }
    by.iter()
        .map(|(m, rs)| format!("{m} (r = {})", rs.join(", ")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// What the notes are made of besides the runs.
struct Context<'a> {
    data_s: f64,
    /// The HOM tip's largest travel within one second [m].
    swing: f64,
    /// Rod length [m].
    length: f64,
    lambdas: &'a [Variant],
}

/// Where and why the results differ from the paper's.
fn notes(dofs: &[Dof], hom: &SimRun, inset: &Dof, c: &Context) -> Vec<String> {
    let (ae, pod) = (&inset.ae_run, &inset.pod_run);
    let p = &paper::TABLE_III_IV_C2;
    let start = dofs
        .iter()
        .map(|d| d.ae_run.start_offset)
        .fold(0.0, f64::max);
    let slowest_ae = dofs
        .iter()
        .map(|d| &d.ae_run)
        .max_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s));
    vec![
        format!(
            "Accuracy: at r = {} the AE-ROM's mean tip error is {} % L and POD's {} % L; the paper's (r = {}) are {} % and {} %. The README measured 5.7 % (AE-7) against 15.5 % (POD-7) without gravity and with 720 s of babbling; here gravity acts (as in IV-C1) and the data are {} s of babbling. The arm swings under the steps (the HOM's tip travels up to {} m within a second of the test, the arm being {} m long), so the snapshots vary with the velocity as well as the position, and r coordinates hold less of them than in statics (POD's captured energy, models table).",
            inset.r,
            Cell::sig(ae.tip_mean(), 3).render(),
            Cell::sig(pod.tip_mean(), 3).render(),
            p.ae_dof,
            Cell::sig(p.ae_error.unwrap_or(f64::NAN), 2).render(),
            Cell::sig(p.pod_error.unwrap_or(f64::NAN), 2).render(),
            c.data_s,
            Cell::sig(c.swing, 2).render(),
            Cell::sig(c.length, 2).render(),
        ),
        format!(
            "Speed: our HOM runs the {} s test in {} s (the paper's MATLAB HOM: {} s): {} DOF, 14 computational points, integrated by `{}` in second-order form with its analytic iteration matrix. A ROM saves little on such a model. The POD-ROMs use the same structured Jacobian with fewer unknowns: {}. The AE-ROMs use the same second-order form, with the decoder's Hessian term in the tangent stiffness and the mass matrix renewed at every attempt (a decoder's M(q) varies fast): {}. Each of their residuals costs about as much as the HOM's (the 14 points' kinematics, plus the decoder and its first and second derivatives), and they take about as many steps (the same dynamics at the same tolerance), so they can be slower than the HOM{}. Compare the ratios between models, not the absolute times; on this shared 2-core machine times of runs under a second vary by tens of per cent.",
            hom.t_reached,
            Cell::sig(hom.wall_time_s, 3).render(),
            Cell::sig(p.hom_time_s, 4).render(),
            hom.dof,
            hom.method,
            methods(dofs, |d| &d.pod_run),
            methods(dofs, |d| &d.ae_run),
            slowest_ae.map_or(String::new(), |a| format!(
                " (the slowest AE-ROM here, {}, took {} s)",
                a.label,
                Cell::sig(a.wall_time_s, 3).render()
            )),
        ),
        format!(
            "Weight decay: the AE-ROMs use the paper's λ = {LAMBDA:e}, against the squared error of a whole snapshot as eq. (15) writes it; the λ table compares it with {LAMBDA_OTHER:e} at r = {}: {}. The training seed matters as much: an AE-ROM may run through or leave its region depending on it, and Fig. 9 shows one seed per r.",
            inset.r,
            [LAMBDA, LAMBDA_OTHER]
                .iter()
                .map(|&l| lambda_summary(l, c.lambdas))
                .collect::<Vec<_>>()
                .join("; "),
        ),
        format!(
            "Start: every model starts at rest, as the data do (the dataset starts from the straight rod, and the arm first falls under gravity): the HOM's start is no problem. An AE-ROM starts from its rest point, the encoding of the straight rod (trained in as 1 % zero-strain rows), which decodes to the straight rod only up to the autoencoder's error: up to max |ξ − ξ*| = {} here (models table), so the AE-ROMs do not start quite where the HOM does, and that offset counts in their mean error.",
            Cell::sig(start, 3).render()
        ),
        "A ROM run that stops early (its trajectory leaves the range of the training encodings, where the decoder extrapolates, or the integrator fails) is not an error of the case: it is recorded as partial, with its reason, and its error and time are those up to where it stopped (Fig. 9 table, \"reached\"); the accuracy findings count it as not more accurate; the speed findings as slower when it had taken longer than the other run by the time it stopped, else as unknown.".into(),
    ]
}

/// "λ = …: k of n runs complete (mean tip error …)" over the seeds of the λ table.
fn lambda_summary(lambda: f64, lambdas: &[Variant]) -> String {
    let of: Vec<&SimRun> = lambdas
        .iter()
        .filter(|v| v.lambda == lambda)
        .map(|v| &v.run)
        .collect();
    let complete: Vec<String> = of
        .iter()
        .filter(|x| x.complete)
        .map(|x| Cell::sig(x.tip_mean(), 3).render() + " % L")
        .collect();
    let stopped: Vec<String> = of
        .iter()
        .filter(|x| !x.complete)
        .map(|x| format!("{} s", Cell::sig(x.t_reached, 3).render()))
        .collect();
    format!(
        "λ = {lambda:e}: {} of {} runs complete{}{}",
        complete.len(),
        of.len(),
        if complete.is_empty() {
            String::new()
        } else {
            format!(" (mean tip error {})", complete.join(", "))
        },
        if stopped.is_empty() {
            String::new()
        } else {
            format!(", the others stopped at t = {}", stopped.join(", "))
        }
    )
}

/// The trajectories of the inset (HOM, AE-r, POD-r).
struct Inset {
    r: usize,
    hom: Trajectory,
    ae: Trajectory,
    pod: Trajectory,
}

/// Fig. 9: mean tip error and wall time against the DOF for both ROMs (and the HOM's time), and the
/// inset's tip traces: the tip's path seen along the arm (y–z) and its coordinates over time.
fn fig9(dofs: &[Dof], hom: &SimRun, inset: &Inset) -> anyhow::Result<RenderedFigure> {
    let r: Vec<f64> = dofs.iter().map(|d| d.r as f64).collect();
    let over_r = |label: &str, f: &dyn Fn(&Dof) -> f64, color, style| Series {
        label: label.into(),
        x: r.clone(),
        y: dofs.iter().map(f).collect(),
        style,
        color: Some(color),
    };
    // partial runs are drawn as separate black markers so that they are not read as complete
    let partial = |f: &dyn Fn(&SimRun) -> f64| {
        let (mut x, mut y) = (vec![], vec![]);
        for d in dofs {
            for run in [&d.ae_run, &d.pod_run] {
                if !run.complete {
                    x.push(d.r as f64);
                    y.push(f(run));
                }
            }
        }
        Series {
            label: "stopped early".into(),
            x,
            y,
            style: SeriesStyle::Markers,
            color: Some(crate::plot::Rgb(0, 0, 0)),
        }
    };
    let mut error_series = vec![
        over_r(
            "AE-ROM",
            &|d| d.ae_run.tip_mean(),
            palette::AE,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "POD-ROM",
            &|d| d.pod_run.tip_mean(),
            palette::POD,
            SeriesStyle::LineMarkers,
        ),
    ];
    let mut time_series = vec![
        over_r(
            "AE-ROM",
            &|d| d.ae_run.wall_time_s,
            palette::AE,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "POD-ROM",
            &|d| d.pod_run.wall_time_s,
            palette::POD,
            SeriesStyle::LineMarkers,
        ),
        over_r(
            "HOM",
            &|_| hom.wall_time_s,
            palette::HOM,
            SeriesStyle::Dashed,
        ),
    ];
    let stopped = partial(&SimRun::tip_mean);
    if !stopped.x.is_empty() {
        error_series.push(stopped);
        time_series.push(partial(&|x| x.wall_time_s));
    }
    let models = [
        (
            "HOM".to_string(),
            &inset.hom,
            palette::HOM,
            SeriesStyle::Line,
        ),
        (
            format!("AE-{}", inset.r),
            &inset.ae,
            palette::AE,
            SeriesStyle::Dashed,
        ),
        (
            format!("POD-{}", inset.r),
            &inset.pod,
            palette::POD,
            SeriesStyle::Dashed,
        ),
    ];
    let trace = |x_of: &dyn Fn(&Trajectory, usize) -> f64, axis: usize| -> Vec<Series> {
        models
            .iter()
            .map(|(label, t, color, style)| Series {
                label: label.clone(),
                x: (0..t.samples()).map(|k| x_of(t, k)).collect(),
                y: (0..t.samples()).map(|k| t.tip[3 * k + axis]).collect(),
                style: *style,
                color: Some(*color),
            })
            .collect()
    };
    let over_t = |axis: usize, name: &str| {
        Figure::Line(LineChart {
            title: format!("tip {name} over time, r = {}", inset.r),
            x_label: "t [s]".into(),
            y_label: format!("tip {name} [m]"),
            series: trace(&|t, k| t.t[k], axis),
            log_y: false,
            equal_aspect: false,
        })
    };
    // a log axis labels the powers of ten only: used when at least two lie within the values
    let spans_decade = |series: &[Series]| {
        let v = series.iter().flat_map(|s| s.y.iter().copied());
        let (lo, hi) = v
            .filter(|y| y.is_finite() && *y > 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), y| {
                (lo.min(y), hi.max(y))
            });
        hi.log10().floor() - lo.log10().ceil() >= 1.0
    };
    let (error_log, time_log) = (spans_decade(&error_series), spans_decade(&time_series));
    let panels = vec![
        Figure::Line(LineChart {
            title: "mean tip error over the test".into(),
            x_label: "DOF r".into(),
            y_label: "mean tip error [% L]".into(),
            series: error_series,
            log_y: error_log,
            equal_aspect: false,
        }),
        Figure::Line(LineChart {
            title: format!("wall time of the {} s test", hom.t_reached),
            x_label: "DOF r".into(),
            y_label: "wall time [s]".into(),
            series: time_series,
            log_y: time_log,
            equal_aspect: false,
        }),
        Figure::Line(LineChart {
            title: format!("tip path seen along the arm, r = {}", inset.r),
            x_label: "tip y [m]".into(),
            y_label: "tip z [m]".into(),
            series: trace(&|t, k| t.tip[3 * k + 1], 2),
            log_y: false,
            equal_aspect: true,
        }),
        over_t(0, "x"),
        over_t(1, "y"),
        over_t(2, "z"),
    ];
    figure(
        "fig9-dof",
        &format!("Fig. 9: mean tip error (% of the length) and wall time of the {d} s test against the number of DOFs for the AE-ROM (gold) and the POD-ROM (red), the HOM's time as the green dashed line (log scales where the values span two powers of ten; black dots: runs that stopped early, measured up to where they stopped); the tip traces of the HOM, AE-{r} and POD-{r} (r = {r}, the paper's inset): the path seen along the arm (y–z, gravity along −z) and the tip's x, y, z over time", r = inset.r, d = hom.t_reached),
        &Figure::Grid {
            title: "IV-C2: six-tendon manipulator dynamics, ROMs against the HOM".into(),
            cols: 3,
            panels,
        },
        1800,
        1050,
    )
}
