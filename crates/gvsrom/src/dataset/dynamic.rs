//! Dynamic datasets (paper IV-C2): one `simulate` run (its input options: constant, CSV, random steps,
//! babbling) whose every output sample becomes a snapshot row; the inputs are the tensions `u(t)` at
//! the sample and `t.npy` holds the times. An interrupted or failed run keeps the samples up to the
//! last one reached (`"complete": false`, like `simulate`); dynamic datasets are not resumable.

use super::generate::{Layout, SampleResult, STATUS_OK};
use super::{
    progress_bar, write::write_arrays, Counts, DatasetError, DatasetRequest, Meta, Outcome,
    MAX_DATASET_BYTES,
};
use crate::build::Built;
use crate::error::ScenarioError;
use crate::output::OutputDir;
use crate::simulate::{self, Failure, InputSource, SimulateOptions, Start};
use gvs::solve::dynamics::{
    simulate_streaming_interruptible, IntegratorOptions, OdeJacobian, SimulationError,
};
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// The run behind a dynamic dataset (in `meta.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DynamicInfo {
    pub duration: f64,
    pub sample_rate: f64,
    /// The input as given (`babble=-15,0,0.5,1`, `steps=…`, `csv FILE`, `constant`).
    pub input: String,
    pub from_equilibrium: bool,
    /// The integrator the rod's damping chose (`ndf` or `sdirk`; empty in files written before
    /// it was recorded, which used the NDF).
    #[serde(default)]
    pub method: String,
    pub rtol: f64,
    pub atol: f64,
    /// Time of the last sample stored.
    pub t_reached: Option<f64>,
    pub steps: usize,
    pub failed_steps: usize,
    pub rhs_evaluations: usize,
    pub jacobian_evaluations: usize,
}

fn join(v: &[f64]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// Runs the simulation of `args` and writes every output sample as a dataset row.
pub fn run(
    args: &DatasetRequest,
    built: &Built,
    scenario_toml: String,
    interrupt: &AtomicUsize,
    provenance: crate::provenance::Provenance,
    t0: Instant,
) -> Result<Outcome, DatasetError> {
    simulate::require_mass(built)?;
    let static_opts = [
        (!args.sweep.is_empty(), "--sweep"),
        (!args.grid.is_empty(), "--grid"),
        (!args.random.is_empty(), "--random"),
        (args.samples.is_some(), "--samples"),
        (args.resume, "--resume"),
    ];
    if let Some((_, opt)) = static_opts.iter().find(|(given, _)| *given) {
        return Err(DatasetError::Plan(format!(
            "{opt} cannot be combined with --duration: a dynamic dataset stores every sample of one simulation (use --sweep/--grid/--random without --duration for a static one)"
        )));
    }
    let input = InputSource::from_options(
        args.input.as_deref(),
        args.interpolate,
        args.steps.as_deref(),
        args.babble.as_deref(),
        args.seed.unwrap_or(0),
    )?;
    let input_text = match (&args.input, &args.steps, &args.babble) {
        (Some(p), _, _) => format!("csv {}", p.display()),
        (_, Some(v), _) => format!("steps={}", join(v)),
        (_, _, Some(v)) => format!("babble={}", join(v)),
        _ => "constant".into(),
    };
    let duration = args.duration.unwrap_or(0.0);
    // bad tolerances are refused here, with every other planning error, before the output is
    // created (or an earlier one replaced): not by the integrator after it
    simulate::check_tolerances(&simulate::IntegratorChoice {
        rtol: args.rtol,
        atol: Some(args.atol),
        ..Default::default()
    })?;
    // as `simulate`'s automatic choice: the NDF, or SDIRK4 for a lightly damped rod
    let (method, _) = gvs::solve::dynamics::method_for_rod(&built.model, args.rtol, args.atol)
        .map_err(|e| DatasetError::Plan(e.to_string()))?;
    let opts = SimulateOptions {
        duration,
        sample_rate: args.sample_rate.unwrap_or(100.0),
        input,
        start: Start::rest_or_equilibrium(args.from_equilibrium),
        integrator: IntegratorOptions {
            method: method.clone(),
            jacobian: OdeJacobian::Structured,
        },
        load_schedule: None,
    };
    let plan = simulate::plan(built, &opts)?;
    let layout = Layout::of(built);
    let model = &built.model;
    let na = model.n_actuators();
    let n_max = plan.t_out.len();
    let per_sample = (2 * na + 1 + layout.row_len() + layout.n_dof + 14) as f64 * 8.0;
    if n_max as f64 * per_sample > MAX_DATASET_BYTES {
        return Err(DatasetError::Plan(format!(
            "--duration {duration}: {n_max} samples would take {:.1} GB in memory (accepted <= {:.1} GB); lower --duration or --sample-rate",
            n_max as f64 * per_sample / 1e9,
            MAX_DATASET_BYTES / 1e9
        )));
    }
    let mut dir = OutputDir::create("--out", &args.out, "dataset", args.force)?;
    let bar = progress_bar(n_max as u64);
    let mut rows: Vec<SampleResult> = Vec::with_capacity(n_max);
    let mut inputs: Vec<f64> = Vec::with_capacity(n_max * na);
    let mut t: Vec<f64> = Vec::with_capacity(n_max);
    let mut stopped = None;
    let mut non_physical = None;
    let x = layout.strain_x.clone();
    let mut ws = model.workspace();
    // polled before every step attempt too, not only at samples: with tight tolerances the next
    // sample may be far away
    let stop = || match interrupt.load(Ordering::SeqCst) {
        0 => None,
        sig => Some(format!("interrupted by {}", super::signal_name(sig))),
    };
    let summary_run = simulate_streaming_interruptible(
        model,
        &plan.signal,
        &built.loads,
        plan.schedule.as_ref(),
        &plan.initial,
        &plan.t_out,
        &opts.integrator,
        &mut |s| {
            // a state no elastic rod holds ends the run before it becomes a snapshot
            if let Some(msg) = simulate::non_physical_state(built, &x, s) {
                non_physical = Some(msg.clone());
                return ControlFlow::Break(msg);
            }
            let mut strain = Vec::with_capacity(layout.row_len());
            let q = nalgebra::DVector::from_column_slice(s.q);
            let tendon_lengths = model.tendon_lengths(&q, &mut ws);
            for (j, xi) in s.strain.iter().enumerate() {
                let dev = xi - model.xi_star(j);
                strain.extend(layout.active.iter().map(|&a| dev[a]));
            }
            rows.push(SampleResult {
                status: STATUS_OK,
                strain,
                q: s.q.to_vec(),
                tip_position: [s.tip.pos[0], s.tip.pos[1], s.tip.pos[2]],
                tip_rotation: std::array::from_fn(|i| s.tip.rot[(i / 3, i % 3)]),
                tendon_lengths,
                iterations: 0,
                residual: f64::NAN,
                warm_started: false,
                reason: None,
            });
            inputs.extend_from_slice(s.u);
            t.push(s.t);
            bar.inc(1);
            match interrupt.load(Ordering::SeqCst) {
                0 => ControlFlow::Continue(()),
                sig => {
                    let r = format!("interrupted by {}", super::signal_name(sig));
                    stopped = Some(r.clone());
                    ControlFlow::Break(r)
                }
            }
        },
        &stop,
    )
    .map_err(|e| match e {
        SimulationError::Model(m) => DatasetError::Scenario(ScenarioError::from(m)),
        SimulationError::Initial(s) => DatasetError::Scenario(ScenarioError::invalid(
            "--from-equilibrium",
            format!("the initial equilibrium failed: {s}"),
        )),
    })?;
    bar.finish_and_clear();
    if stopped.is_none() {
        stopped = stop(); // stopped between samples
    }
    let n = rows.len();
    let failed = match (&summary_run.error, &stopped, non_physical) {
        (Some(_), None, Some(v)) => Some((v, Failure::LeftElasticRange)),
        (Some(e), None, None) => Some((e.to_string(), Failure::Integration)),
        _ => None,
    };
    let reason = (stopped.clone()).or_else(|| failed.as_ref().map(|(_, f)| f.reason().to_string()));
    // the error as printed: an integrator's message says where it failed; the elastic range's
    // check names its time itself
    let failed = failed.map(|(e, f)| match f {
        Failure::Integration => format!(
            "the integration failed at t = {}: {e}",
            summary_run.t_last.unwrap_or(0.0)
        ),
        _ => e,
    });
    let mut meta = Meta {
        kind: "dynamics".into(),
        scenario: built.name.clone(),
        scenario_toml,
        plan: None,
        dynamic: Some(DynamicInfo {
            duration,
            sample_rate: opts.sample_rate,
            input: input_text,
            from_equilibrium: args.from_equilibrium,
            method: method.name().into(),
            rtol: method
                .rtol()
                .unwrap_or(gvs::solve::ode::NdfOptions::default().rtol),
            atol: args.atol,
            t_reached: summary_run.t_last,
            steps: summary_run.stats.steps,
            failed_steps: summary_run.stats.failed_steps,
            rhs_evaluations: summary_run.stats.rhs_evals,
            jacobian_evaluations: summary_run.stats.jacobian_evals,
        }),
        seed: args.seed.unwrap_or(0),
        parameters: (0..na).map(|k| format!("tendons.{k}.tension")).collect(),
        samples: n,
        n_dof: layout.n_dof,
        n_points: layout.strain_x.len(),
        strain_x: layout.strain_x.clone(),
        components: layout.component_names(),
        strain_layout: super::STRAIN_LAYOUT.into(),
        chunk_size: n.max(1),
        chunk_done: vec![true; n.div_ceil(n.max(1))],
        complete: reason.is_none(),
        reason: reason.clone(),
        error: failed.clone(),
        counts: Counts::default(),
        failures: vec![],
        crate_version: env!("CARGO_PKG_VERSION").into(),
        q_order: gvs::strain::COORDINATE_ORDER.into(),
        n_tendons: Some(layout.n_tendons),
        wall_time_s: t0.elapsed().as_secs_f64(),
        threads: 1,
        noise: None,
        provenance: Some(
            provenance
                .input(plan.input.clone())
                .sampling(duration, opts.sample_rate)
                .integrator(simulate::integrator_record(
                    &opts.integrator,
                    &simulate::IntegratorChoice {
                        rtol: args.rtol,
                        atol: Some(args.atol),
                        ..simulate::IntegratorChoice::default()
                    },
                )),
        ),
    };
    write_arrays(&mut dir, &mut meta, &layout, &inputs, &rows, Some(&t))?;
    let path = dir.commit(&meta)?;
    if let Some(e) = failed {
        return Err(DatasetError::Plan(format!(
            "{e} (the {n} samples before it were written to `{}`, marked incomplete)",
            path.display()
        )));
    }
    Ok(Outcome {
        path,
        meta,
        interrupted: stopped,
        resumed_chunks: 0,
        warnings: vec![],
    })
}
