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
                start: simulate::Start::Rest,
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
    /// Time of the last sample \[s\].
    pub t_reached: f64,
    pub samples: usize,
    /// The smallest wall time of the integration over the repetitions \[s\].
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
            if let Some(reduced) = &built.reduced {
                provenance = provenance.model(&reduced.origin);
            }
            let written =
                simulate::run_to_dir(&built, &opts, path, true, Some(provenance), &mut control)?;
            run.check_interrupt()?;
            let mut outcome = written.outcome;
            let reason = match &outcome.ending {
                Ending::Complete => None,
                Ending::Failed { error, .. } => Some(error.clone()),
                Ending::Interrupted { reason } => Some(reason.clone()),
            };
            if let (None, Some(r)) = (model, &reason) {
                anyhow::bail!("the HOM's simulation of the test failed: {r}");
            }
            let plan = simulate::plan(&built, &opts)?;
            outcome.time_again(
                &built,
                &plan,
                &opts.integrator,
                test.repeat - 1,
                &mut control,
            )?;
            run.check_interrupt()?;
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
                wall_time_s: outcome.summary.wall_time_s,
                wall_times_s: outcome.wall_times_s.clone(),
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

/// The wall time of a reduced model against the HOM's on the same test, measured in interleaved
/// pairs: per round the HOM's integration, then the model's, without output; the median of the
/// rounds' ratios. A shared machine's speed drifts over seconds to minutes, which best-of-N times
/// taken one after the other turn into ratios off by 1.5× either way; a pair's two runs are
/// seconds apart, so the drift cancels in their ratio.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PairedTiming {
    pub rounds: usize,
    pub hom_s: Vec<f64>,
    pub rom_s: Vec<f64>,
    /// Median over the rounds of `rom_s / hom_s`.
    pub median_ratio: f64,
}

/// [`PairedTiming`] of `model` against the HOM on `test`, `rounds` pairs (a step of its own, so
/// a resumed run keeps it).
pub fn time_pairs(
    run: &Run,
    name: &str,
    scenario: &ScenarioSpec,
    test: &Test,
    model: &Step<ModelInfo>,
    rounds: usize,
) -> anyhow::Result<Step<PairedTiming>> {
    let config = json!({
        "scenario": scenario, "test": test, "model": model.key(), "rounds": rounds,
    });
    run.step(
        name,
        &config,
        |_| true,
        |_| {
            let (hom, table) = scenario.build()?;
            let (mut rom, _) = scenario.build()?;
            let options = reduce::AttachOptions {
                extrapolate: false,
                tensions_from_signal: true,
            };
            reduce::attach(&mut rom, &table, &model.path, options)?;
            let interrupt = run.interrupt().clone();
            let mut control = |_: f64| match interrupt.load(Ordering::SeqCst) {
                0 => ControlFlow::Continue(()),
                _ => ControlFlow::Break("interrupted".to_string()),
            };
            let mut once = |built: &Built| -> anyhow::Result<f64> {
                let (opts, _) = test.options(built)?;
                let plan = simulate::plan(built, &opts)?;
                let out = simulate::run(built, &plan, &opts.integrator, None, &mut control)?;
                run.check_interrupt()?;
                Ok(out.summary.wall_time_s)
            };
            let (mut hom_s, mut rom_s) = (vec![], vec![]);
            for _ in 0..rounds.max(1) {
                hom_s.push(once(&hom)?);
                rom_s.push(once(&rom)?);
            }
            let ratios: Vec<f64> = rom_s.iter().zip(&hom_s).map(|(r, h)| r / h).collect();
            Ok(PairedTiming {
                rounds: ratios.len(),
                median_ratio: median(ratios),
                hom_s,
                rom_s,
            })
        },
    )
}

/// The median of `v` (the mean of the two middle values for an even count; NaN if empty).
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let k = v.len();
    match k {
        0 => f64::NAN,
        _ if k % 2 == 1 => v[k / 2],
        _ => 0.5 * (v[k / 2 - 1] + v[k / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn the_median_of_odd_and_even_counts_and_of_none() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(vec![0.9]), 0.9);
        assert!(median(vec![]).is_nan());
    }
}
