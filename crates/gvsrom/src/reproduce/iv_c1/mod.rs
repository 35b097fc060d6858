//! Case IV-C1: the six-tendon manipulator's statics under gravity (paper Section IV-C1, Figs. 7–8,
//! Table III same-DOF row).
//!
//! Data: 20 000 equilibria at uniform random tensions in [−30, 30] N on all six tendons (seed 0).
//! Models: an autoencoder with r = 6 latent coordinates and 7 hidden layers, and POD with 6 modes.
//! Test: five random tension vectors (fixed seed), where the HOM, the AE-ROM and the POD-ROM are
//! solved as `gvsrom statics [--model]` solves them (Fig. 7, Table III). Fig. 8: two more r = 6
//! autoencoders, trained on equal counts of grid and random samples, and the first three principal
//! components of their training codes. Beyond the paper, `hanging`: the same study on the arm
//! hanging along gravity, the other reading of its orientation.
//!
//! This module runs the case and writes its report's text; `report` builds its tables and figures.

mod hanging;
mod report;

use super::evaluation::{statics_eval, EvalModel};
use super::iv_a::accuracy_table;
use super::latent::{encodings, occupied_fraction, principal_components};
use super::report::{CaseReport, Cell, Finding, RenderedFigure};
use super::step::Step;
use super::tasks::{self, AeConfig, DatasetInfo, DatasetSpec, ModelInfo, ScenarioSpec};
use super::{new_report, paper, Case, Options, Run};
use crate::dataset::Dataset;
use report::{
    datasets_table, fig7, fig8_figure, fig8_table, inputs_table, models_table, table_iii,
};
use serde_json::json;
use std::path::Path;

/// The reduced models' size: one coordinate per tendon (paper: r = 6, POD with 6 modes).
const R: usize = 6;
/// Hidden layers of every autoencoder of the case (the paper's deepest, as in Table I).
const HIDDEN_LAYERS: usize = 7;
/// Tension range of the data and of the test inputs [N].
const U_RANGE: (f64, f64) = (-30.0, 30.0);
/// Seed of the five test tension vectors (the datasets use seed 0: other draws).
const TEST_SEED: u64 = 7;
/// Number of test inputs (Fig. 7).
const TESTS: usize = 5;
/// Fig. 8's finding: how much larger the random-trained codes' occupied share of their PC box must
/// be than the grid-trained codes' to count as "more evenly charted" (a difference of a few % is
/// within what another seed or bin count changes).
const CLEARLY_MORE: f64 = 1.1;
/// Centreline samples of the evaluation's solutions (the preset's 21 draw the bent arm as a
/// polygon; output only, the computational points and the solve are unchanged).
const CENTERLINE_POINTS: usize = 61;

/// Sizes of the full, the quick and the tiny run.
struct Sizes {
    samples: usize,
    /// Grid values per tendon of Fig. 8's grid dataset (samples: `per_axis⁶`).
    per_axis: usize,
    epochs: usize,
    /// Solves per model and input, whose mean time is kept: an equilibrium takes well under a
    /// millisecond here, so one preemption by another process would dominate a mean of few.
    repeat: u32,
}

fn sizes(opts: &Options) -> Sizes {
    if opts.tiny {
        Sizes {
            samples: 100,
            per_axis: 2,
            epochs: 15,
            repeat: 1,
        }
    } else if opts.quick {
        Sizes {
            samples: 2000,
            per_axis: 3,
            epochs: 300,
            repeat: 20,
        }
    } else {
        Sizes {
            samples: 20_000,
            per_axis: 4,
            epochs: 1000,
            repeat: 100,
        }
    }
}

/// The five test tension vectors \[N\]: uniform in [−30, 30) N from SplitMix64 with `TEST_SEED`,
/// rounded to 0.1 N so that the inputs print exactly.
pub fn test_tensions() -> Vec<[f64; 6]> {
    let mut rng = gvs::inputs::SplitMix64::new(TEST_SEED);
    (0..TESTS)
        .map(|_| std::array::from_fn(|_| (rng.range(U_RANGE.0, U_RANGE.1) * 10.0).round() / 10.0))
        .collect()
}

fn tension_spec() -> String {
    format!("tendons.*.tension={}:{}", U_RANGE.0, U_RANGE.1)
}

/// Runs case IV-C1.
pub fn run(run: &Run, opts: &Options) -> anyhow::Result<(CaseReport, Vec<RenderedFigure>)> {
    let s = sizes(opts);
    let scenario = ScenarioSpec::new("six-tendon", &[]);
    let plan = DatasetSpec {
        random: vec![tension_spec()],
        samples: Some(s.samples),
        seed: 0,
        ..DatasetSpec::default()
    };
    let fig8_samples = s.per_axis.pow(6);
    let grid_plan = DatasetSpec {
        grid: vec![tension_spec()],
        samples: Some(fig8_samples),
        ..DatasetSpec::default()
    };
    let random_plan = DatasetSpec {
        random: vec![tension_spec()],
        samples: Some(fig8_samples),
        seed: 0,
        ..DatasetSpec::default()
    };
    let data = tasks::dataset(run, "iv-c1/dataset", &scenario, &plan, opts.jobs)?;
    let grid = tasks::dataset(run, "iv-c1/fig8-grid", &scenario, &grid_plan, opts.jobs)?;
    let random = tasks::dataset(run, "iv-c1/fig8-random", &scenario, &random_plan, opts.jobs)?;

    // the three autoencoders at once (the big one first: rayon gives it a thread of its own)
    let ae_config = AeConfig::new(R, HIDDEN_LAYERS, s.epochs);
    let jobs: [(&str, &Step<DatasetInfo>); 3] = [
        ("iv-c1/ae-6", &data),
        ("iv-c1/fig8-ae-grid", &grid),
        ("iv-c1/fig8-ae-random", &random),
    ];
    let trained = tasks::parallel(&jobs, |(name, d)| tasks::train(run, name, d, &ae_config))?;
    let Ok([ae, ae_grid, ae_random]) = <[Step<ModelInfo>; 3]>::try_from(trained) else {
        anyhow::bail!("expected three trained autoencoders");
    };
    let pod = tasks::pod(run, "iv-c1/pod-6", &data, R)?;
    // beyond the paper: the POD of the autoencoders' norm
    let pod_energy = tasks::pod_in(
        run,
        "iv-c1/pod-6-energy",
        &data,
        R,
        crate::reduce::PodNorm::Energy,
    )?;

    let tensions = test_tensions();
    let inputs: Vec<Vec<String>> = tensions
        .iter()
        .map(|u| {
            u.iter()
                .enumerate()
                .map(|(k, v)| format!("tendons.{k}.tension={v}"))
                .collect()
        })
        .collect();
    let models = [
        EvalModel::hom(),
        EvalModel::of("AE-6", &ae),
        EvalModel::of("POD-6", &pod),
        EvalModel::of("POD-6 (energy norm)", &pod_energy),
    ];
    let eval_scenario = scenario.with(&[format!("output.centerline_points={CENTERLINE_POINTS}")]);
    let ev = statics_eval(
        run,
        "iv-c1/eval",
        &eval_scenario,
        &inputs,
        &models,
        s.repeat,
    )?;
    let ev = &ev.value;
    // beyond the paper: the same study on the arm hanging along gravity
    let hanging = hanging::run_hanging(
        run,
        &plan,
        &ae_config,
        R,
        &inputs,
        CENTERLINE_POINTS,
        s.repeat,
        opts.jobs,
    )?;

    let fig8 = [
        Sampling::measure("grid", &grid, &ae_grid)?,
        Sampling::measure("random", &random, &ae_random)?,
    ];

    let mut report = new_report(
        Case::IvC1,
        "six-tendon multisection manipulator, statics (paper Section IV-C1)",
    );
    let hom_dof = ev.of("HOM").next().map_or(0, |h| h.dof);
    report.setup = vec![
        format!("scenario: preset `six-tendon` ({} m arm in two equal divisions, radius 2 → 1 cm, E = 1 MPa; base along +x, gravity along −z: a horizontal cantilever that sags under its own weight, as IV-A; six frictionless tendons 60° apart on the surface, alternating full and half length; {hom_dof}-DOF Legendre basis, {} computational points, 6 active strain components)", Cell::sig(ev.length, 3).render(), ev.strain_x.len()),
        format!("data: {} equilibria at uniform random tensions in [−30, 30] N on all six tendons, seed 0 (`gvsrom dataset six-tendon --random 'tendons.*.tension=-30:30' --samples {} --seed 0`); solved and failed counts in the table below", s.samples, s.samples),
        format!("autoencoder: r = {R}, {HIDDEN_LAYERS} hidden layers, tanh, λ = 1e-4 against a whole snapshot's squared error (eq. 15), loss in the strain-energy norm, Adam ≤ {} epochs with learning-rate reductions at plateaus and early stopping (patience {}), then L-BFGS (`gvsrom train` defaults)", s.epochs, ae_config.patience),
        format!("POD: {R} modes of the uncentred snapshots; beyond the paper also in the strain-energy norm, the autoencoder's (`gvsrom pod --norm energy`: each strain value weighted by its section stiffness)"),
        format!("test: {TESTS} tension vectors uniform in [−30, 30) N (SplitMix64, seed {TEST_SEED}, rounded to 0.1 N; listed below); each equilibrium solved {} times, mean time, one thread; the HOM from the straight rod, the ROMs from their anchors (as `gvsrom statics [--model]`); centrelines sampled at {CENTERLINE_POINTS} points for Fig. 7", s.repeat),
        format!("Fig. 8: two more r = {R} autoencoders (same settings) trained on {} equilibria each: a grid of {}⁶ tensions over [−30, 30] N (`--grid 'tendons.*.tension=-30:30' --samples {}`) and uniform random tensions (`--random … --samples {} --seed 0`)", fig8_samples, s.per_axis, fig8_samples, fig8_samples),
    ];

    report.tables.push(datasets_table([
        ("training (random)", &data.value),
        ("Fig. 8 grid", &grid.value),
        ("Fig. 8 random", &random.value),
    ]));
    report.tables.push(models_table(&ae, &pod));
    let mut accuracy = accuracy_table(ev, &models);
    accuracy.title = "Accuracy and time at the five test inputs (Fig. 7's models)".into();
    report.tables.push(accuracy);
    report.tables.push(inputs_table(ev, &tensions));
    let (ae_tip, _) = ev.stats("AE-6", |s| s.tip_error_percent);
    let (pod_tip, _) = ev.stats("POD-6", |s| s.tip_error_percent);
    let (ae_strain, _) = ev.stats("AE-6", |s| s.strain_error_percent);
    let (pod_strain, _) = ev.stats("POD-6", |s| s.strain_error_percent);
    let (hom_t, _) = ev.stats("HOM", |s| s.time_s);
    let (ae_t, _) = ev.stats("AE-6", |s| s.time_s);
    let (pod_t, _) = ev.stats("POD-6", |s| s.time_s);
    let times = Times {
        hom: hom_t,
        ae: ae_t,
        pod: pod_t,
    };
    report
        .tables
        .push(table_iii(hom_dof, ae_tip, pod_tip, ev.length, &times));
    report.tables.push(fig8_table(&fig8));
    report.tables.push(hanging.table());

    let ms = |t: f64| Cell::sig(t * 1e3, 3).render();
    let failed = |label: &str| ev.of(label).filter(|s| s.error.is_some()).count();
    let failures = match (failed("AE-6"), failed("POD-6")) {
        (0, 0) => String::new(),
        (a, p) => format!(
            " (failed solves, which make a mean –: AE-6 at {a}, POD-6 at {p} of the {TESTS} inputs)"
        ),
    };
    report.findings = vec![
        Finding {
            claim: "at equal DOF (6) the AE-ROM is more accurate than the POD-ROM".into(),
            holds: ae_tip < pod_tip,
            evidence: format!(
                "mean tip error {} % L (AE-6) against {} % L (POD-6); mean strain error {} % against {} %{failures}",
                Cell::sig(ae_tip, 3).render(),
                Cell::sig(pod_tip, 3).render(),
                Cell::sig(ae_strain, 3).render(),
                Cell::sig(pod_strain, 3).render()
            ),
        },
        Finding {
            claim: "both ROMs are faster than the HOM".into(),
            holds: ae_t < hom_t && pod_t < hom_t,
            evidence: format!(
                "HOM {} ms, AE-6 {} ms, POD-6 {} ms per equilibrium{failures}",
                ms(hom_t),
                ms(ae_t),
                ms(pod_t)
            ),
        },
        Finding {
            claim: "at equal DOF the POD-ROM is faster than the AE-ROM".into(),
            holds: pod_t < ae_t,
            evidence: format!(
                "POD-6 {} ms against AE-6 {} ms{failures}",
                ms(pod_t),
                ms(ae_t)
            ),
        },
        Finding {
            claim: format!("random sampling charts the latent space more evenly than grid sampling (Fig. 8); measured: the random-trained codes occupy at least {}× the share of their PC₁–PC₃ box that the grid-trained codes occupy", Cell::sig(CLEARLY_MORE, 2).render()),
            holds: fig8[1].occupied >= CLEARLY_MORE * fig8[0].occupied,
            evidence: format!(
                "occupied cells: {} % (random) against {} % (grid), ratio {}",
                Cell::sig(fig8[1].occupied * 100.0, 3).render(),
                Cell::sig(fig8[0].occupied * 100.0, 3).render(),
                Cell::sig(fig8[1].occupied / fig8[0].occupied, 3).render()
            ),
        },
        hanging.finding(R),
    ];
    report.notes = vec![
        "Gravity: the paper's IV-C text does not say whether gravity acts. The preset `six-tendon` has it along −z with the base along +x, as in IV-A, so the unloaded arm is a sagging horizontal cantilever (`six-tendon-no-gravity` is the variant without). A few random inputs (7 of 20 000) are then beyond the HOM's load ramp: its large increments converge onto another branch of equilibria (five; loops that fold back and forth below full load) or stall near a fold of the arm's own branch (two). For these the statics follows the branch from the straight rod by pseudo-arc-length continuation, through its folds, to full load; samples that still fail would be counted in the dataset table, listed in results.json and left out of the training.".into(),
        format!(
            "The HOM has {hom_dof} DOF as the paper's, but only {} computational points (two divisions of 5 Gauss points, and the ends): one HOM equilibrium takes {} ms here against the paper's {} ms ({}× less), so the ROMs have little to save and their speed-ups hang on fractions of a millisecond (and on the machine's load while the evaluation ran). Compare the ratios between models, not the absolute times.",
            ev.strain_x.len(),
            ms(hom_t),
            ms(paper::TABLE_III_IV_C1.hom_time_s),
            Cell::sig(paper::TABLE_III_IV_C1.hom_time_s / hom_t, 2).render()
        ),
        "The five test inputs are random draws from a fixed seed; the paper's five \"arbitrary actuation inputs\" are not listed, so per-input errors are not comparable one by one, only their mean.".into(),
        "Fig. 8's coverage number is ours, a crude proxy of the paper's visual reading: the fraction of the cells of an n × n × n grid over the bounding box of the codes' first three principal components that hold at least one code (n = round((N/4)^(1/3)), 4 codes per cell if spread evenly).".into(),
    ];
    if ae.value.rmse_full > pod.value.rmse_full && ae_tip < pod_tip {
        report.notes.push(format!(
            "The autoencoder reconstructs the training snapshots worse than POD-6 (RMS {} against {}, table \"Reduced models\"), yet its ROM is the more accurate at the test inputs: the ROM's error is that of the equilibrium found on the decoder's manifold, not of the reconstruction D(E(x)) of the HOM's strain.",
            Cell::sig(ae.value.rmse_full, 3).render(),
            Cell::sig(pod.value.rmse_full, 3).render()
        ));
    }
    report.settings = json!({
        "scenario": scenario,
        "eval_scenario": eval_scenario,
        "plan": plan,
        "fig8_grid_plan": grid_plan,
        "fig8_random_plan": random_plan,
        "autoencoder": ae_config,
        "pod_modes": R,
        "test_seed": TEST_SEED,
        "test_tensions": tensions,
        "repeat": s.repeat,
    });
    report.values = json!({
        "datasets": {
            "training": &data.value,
            "fig8_grid": &grid.value,
            "fig8_random": &random.value,
            "training_failures": failed_samples(&data.path),
        },
        "models": { "ae": &ae.value, "pod": &pod.value, "pod_energy": &pod_energy.value, "fig8_ae_grid": &ae_grid.value, "fig8_ae_random": &ae_random.value },
        "tip_error_mean_percent": { "ae": ae_tip, "pod": pod_tip },
        "time_mean_s": { "hom": hom_t, "ae": ae_t, "pod": pod_t },
        "fig8": fig8.iter().map(Sampling::values).collect::<Vec<_>>(),
        "evaluation": ev,
        "hanging": {
            "preset": hanging::PRESET,
            "dataset": &hanging.data.value,
            "models": { "ae": &hanging.ae.value, "pod": &hanging.pod.value },
            "evaluation": &hanging.ev,
        },
    });
    let figures = vec![fig7(ev, &tensions)?, fig8_figure(&fig8)?];
    Ok((report, figures))
}

/// Mean times per equilibrium [s].
struct Times {
    hom: f64,
    ae: f64,
    pod: f64,
}

/// The indices of the failed training samples and why each failed (at most 50).
fn failed_samples(data: &Path) -> serde_json::Value {
    match Dataset::load(data) {
        Ok(d) => json!(d.meta.failures.iter().take(50).collect::<Vec<_>>()),
        Err(e) => json!(format!("{e}")),
    }
}

/// One sampling strategy of Fig. 8: its training codes on their first three principal components.
struct Sampling {
    name: &'static str,
    samples: usize,
    val_rmse: f64,
    /// PC₁–PC₃ of each solved sample's code.
    pcs: Vec<[f64; 3]>,
    /// Share of the codes' variance on PC₁–PC₃.
    explained: f64,
    /// Occupied share of the cells of an n³ grid over the PC₁–PC₃ bounding box.
    occupied: f64,
    bins: usize,
}

impl Sampling {
    fn measure(
        name: &'static str,
        data: &Step<DatasetInfo>,
        ae: &Step<ModelInfo>,
    ) -> anyhow::Result<Sampling> {
        let z = encodings(&data.path, &ae.path)?;
        let (pcs, explained) = principal_components(&z)?;
        let bins = ((pcs.len() as f64 / 4.0).cbrt().round() as usize).max(2);
        Ok(Sampling {
            name,
            samples: data.value.samples,
            val_rmse: ae.value.val_rmse.unwrap_or(f64::NAN),
            occupied: occupied_fraction(&pcs, bins),
            explained,
            pcs,
            bins,
        })
    }

    fn values(&self) -> serde_json::Value {
        json!({
            "sampling": self.name, "samples": self.samples, "val_rmse": self.val_rmse,
            "explained_variance_pc1_3": self.explained, "occupied_fraction": self.occupied,
            "bins": self.bins,
        })
    }
}
