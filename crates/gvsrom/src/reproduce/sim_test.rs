//! One timed test simulation of a reproduce case, through the CLI's own paths: `gvsrom simulate
//! … [--model M] --out DIR`, repeated for its wall time, and `gvsrom compare HOM-DIR DIR`.

use super::step::Step;
use super::tasks::{ModelInfo, ScenarioSpec};
use super::Run;
use crate::compare::{compare, Comparison, Trajectory};
use crate::simulate::{self, Ending, InputSource, IntegratorChoice, SimulateOptions};
use crate::{reduce, Built};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::ops::ControlFlow;
use std::sync::atomic::Ordering;

/// The test of every model: the input, its length and the integrator (the CLI's automatic
/// choice).
#[derive(Debug, Clone, Serialize)]
pub struct Test {
    pub duration: f64,
    pub sample_rate: f64,
    pub steps: [f64; 3],
    pub seed: u64,
    pub integrator: IntegratorChoice,
    pub repeat: usize,
}

impl Test {
    pub fn options(&self, built: &Built) -> anyhow::Result<(SimulateOptions, Option<String>)> {
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

/// One simulation of the test: how it ended, what it cost, and (for a ROM) its error against the
/// HOM.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SimRun {
    pub label: String,
    pub dof: usize,
    pub complete: bool,
    /// Why the run ended early, in full.
    pub reason: Option<String>,
    /// The run ended early because it left the training region (else: the integrator failed).
    pub left_training_region: bool,
    /// Time of the last sample [s].
    pub t_reached: f64,
    pub samples: usize,
    /// The smallest wall time of the integration over the repetitions [s].
    pub wall_time_s: f64,
    pub wall_times_s: Vec<f64>,
    pub method: String,
    /// The integrator line `simulate` prints when the rod's damping chose the method.
    pub integrator_note: Option<String>,
    pub steps: usize,
    pub failed_steps: usize,
    pub rhs_evaluations: usize,
    pub jacobian_evaluations: usize,
    /// Largest `|ξ − ξ*|` at the points of the model's start (a decoder's rest point; 0 for the
    /// HOM and POD, which start from the straight rod).
    pub start_offset: f64,
    /// Against the HOM over their common samples (`gvsrom compare`, in %); `None` for the HOM.
    pub error: Option<Comparison>,
}

impl SimRun {
    pub fn tip_mean(&self) -> f64 {
        self.error.as_ref().map_or(f64::NAN, |e| e.tip_mean)
    }
    /// "complete", or where and why it stopped, in short (the full reason is in `reason`).
    pub fn status(&self) -> String {
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
pub fn simulate_test(
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
                let options = reduce::AttachOptions {
                    extrapolate: false,
                    tensions_from_signal: true,
                };
                reduce::attach(&mut built, &table, &m.path, options)?;
            }
            let (opts, note) = test.options(&built)?;
            let interrupt = run.interrupt().clone();
            let mut control = |_: f64| match interrupt.load(Ordering::SeqCst) {
                0 => ControlFlow::Continue(()),
                _ => ControlFlow::Break("interrupted".to_string()),
            };
            let mut provenance = scenario.provenance()?.seed("input", test.seed).integrator(
                simulate::integrator_record(&opts.integrator, &test.integrator),
            );
            if let Some(m) = model {
                provenance = provenance.model(&m.path)?;
            }
            let written =
                simulate::run_to_dir(&built, &opts, path, true, Some(provenance), &mut control)?;
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
                Some(h) => Some(compare(
                    &Trajectory::load(&h.path, "REFERENCE")?,
                    &Trajectory::load(&written.dir, "RUN")?,
                )?),
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
