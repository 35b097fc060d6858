//! Beyond the paper: the inset's AE and POD trained again on other data and run on every test input,
//! to find what sets IV-C2's errors. Three variants:
//!
//! - [`DataVariant::Spread`]: the same number of snapshots over a [`SPREAD`]× longer babbling sampled
//!   [`SPREAD`]× less often (more varied states for the same budget), against the same HOM runs:
//!   whether the test inputs' states, which leave the paper's data on some inputs, are covered;
//! - [`DataVariant::Damped`]: the arm with [`DAMPING_FACTOR`]× the material damping (data, HOM and ROM
//!   runs alike): how much of the error the arm's swinging makes (the paper gives the damping
//!   constant, not how its model damps);
//! - [`DataVariant::Hanging`]: the arm hanging along gravity (preset [`HANGING_PRESET`]; data, HOM
//!   and ROM runs alike) instead of the horizontal cantilever: the orientation the paper leaves open;
//! - [`DataVariant::Rates`] and [`DataVariant::HangingRates`]: the paper's data of either arm, the
//!   AE trained with the strain-rate term (`gvsrom train --rate-weight β`, `rom::nn::rates`):
//!   whether a decoder whose tangents carry the babbling's strain rates tracks the swinging arm.
//!   β is chosen among [`RATE_WEIGHTS`](super::rate_weights::RATE_WEIGHTS) by the mean tip error
//!   on validation inputs of their own seeds (`validation`), never on the test inputs;
//! - [`DataVariant::Kinetic`] and [`DataVariant::HangingKinetic`]: the same with the errors also in
//!   the kinetic-energy norm of each snapshot's mass matrix (`gvsrom train --kinetic-weight κ`,
//!   `rom::nn::metric`) and the JAX reference's schedule (a rate decaying to
//!   [`KINETIC_LR_DECAY`] of itself, no plateaus, no L-BFGS phase), β and κ chosen together among
//!   [`RATE_WEIGHTS`](super::rate_weights::RATE_WEIGHTS) × [`KINETIC_WEIGHTS`] the same way;
//! - [`DataVariant::SpreadKinetic`]: the kinetic variant's training on the spread variant's data
//!   (the paper's budget of snapshots over a [`SPREAD`]× longer babbling), β and κ chosen the same
//!   way.

use super::super::paper;
use super::super::report::{Cell, Finding, Table};
use super::super::sim_test::{simulate_test, time_pairs, SimRun, Test};
use super::super::step::Step;
use super::super::tasks::{self, AeConfig, DatasetInfo, DatasetSpec, ModelInfo, ScenarioSpec};
use super::super::Run;
use super::more_tests::{hom_run, more_tests_table, TestRuns};
use super::rate_weights::{select_rate_weight, RateSelection, KINETIC_WEIGHTS};
use std::path::PathBuf;

/// How many times longer the spread babbling is, and how many times less often it is sampled.
pub(super) const SPREAD: f64 = 2.0;
/// The damped variant's material damping, as a multiple of the preset's (the paper's 10⁴ Pa·s).
pub(super) const DAMPING_FACTOR: f64 = 3.0;
/// The hanging variant's preset: `six-tendon` with the base along −z, the direction of gravity.
pub(super) const HANGING_PRESET: &str = "six-tendon-hanging";
/// The kinetic-energy-norm variants' `--lr-decay` (with `--patience 0 --lbfgs-iterations 0`: the
/// JAX reference's schedule). Measured on 2026-11-27 (`gvsrom train … --rate-weight β
/// --kinetic-weight κ`, training seed 0, mean tip error of the five tests): hanging arm, β = 1,
/// κ = 1, 1.07 % L in 40 s against 1.20 % L in 83–133 s with the plateau schedule and 300 L-BFGS
/// iterations; horizontal arm, β = 0.3, κ = 1, 1.97 against 2.04.
pub(super) const KINETIC_LR_DECAY: f64 = 0.03;

/// A variant of the data (and, for [`DataVariant::Damped`], [`DataVariant::Hanging`] and
/// [`DataVariant::HangingRates`], of the arm; for the rate-term variants, of the AE's training).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum DataVariant {
    Spread,
    Damped,
    Hanging,
    Rates,
    HangingRates,
    Kinetic,
    HangingKinetic,
    SpreadKinetic,
}

/// A variant's data, its two models and their runs on each test input.
pub(super) struct VariantRuns {
    pub(super) variant: DataVariant,
    /// What the variant changes, for the reports.
    pub(super) description: String,
    pub(super) data: Step<DatasetInfo>,
    pub(super) ae: Step<ModelInfo>,
    pub(super) pod: Step<ModelInfo>,
    pub(super) tests: Vec<TestRuns>,
    /// The trajectory directories of the HOM, AE and POD runs of the first test input.
    pub(super) first_runs: Option<[PathBuf; 3]>,
    /// For the rate-term variants: how β (and κ) was chosen.
    pub(super) selection: Option<RateSelection>,
}

impl DataVariant {
    /// The step names' suffix.
    pub(super) fn name(self) -> &'static str {
        match self {
            DataVariant::Spread => "spread",
            DataVariant::Damped => "damped",
            DataVariant::Hanging => "hanging",
            DataVariant::Rates => "rates",
            DataVariant::HangingRates => "hanging-rates",
            DataVariant::Kinetic => "kinetic",
            DataVariant::HangingKinetic => "hanging-kinetic",
            DataVariant::SpreadKinetic => "spread-kinetic",
        }
    }

    /// The name of the variant whose data, HOM runs and POD it shares (the rate-term variants
    /// change the AE alone), or `None` for the paper's data and HOM runs.
    fn data_name(self) -> Option<&'static str> {
        match self {
            DataVariant::Rates | DataVariant::Kinetic => None,
            DataVariant::HangingRates | DataVariant::HangingKinetic => {
                Some(DataVariant::Hanging.name())
            }
            DataVariant::SpreadKinetic => Some(DataVariant::Spread.name()),
            v => Some(v.name()),
        }
    }

    /// How the variant's data differ from the paper's, for a figure's caption (empty if not).
    pub(super) fn data_note(self) -> String {
        match self {
            DataVariant::Spread | DataVariant::SpreadKinetic => {
                format!(", on the paper's number of snapshots over a {SPREAD}× longer babbling")
            }
            _ => String::new(),
        }
    }

    /// Whether the variant trains its AE with the strain-rate term.
    fn rates(self) -> bool {
        matches!(
            self,
            DataVariant::Rates
                | DataVariant::HangingRates
                | DataVariant::Kinetic
                | DataVariant::HangingKinetic
                | DataVariant::SpreadKinetic
        )
    }

    /// Whether the variant also measures the errors in the kinetic-energy norm (`--kinetic-weight`).
    pub(super) fn kinetic(self) -> bool {
        matches!(
            self,
            DataVariant::Kinetic | DataVariant::HangingKinetic | DataVariant::SpreadKinetic
        )
    }

    /// The variant's scenario: for [`DataVariant::Damped`] the material damping of `scenario`
    /// times [`DAMPING_FACTOR`], for [`DataVariant::Hanging`] [`HANGING_PRESET`] with `scenario`'s
    /// overrides.
    fn scenario(self, scenario: &ScenarioSpec) -> anyhow::Result<ScenarioSpec> {
        Ok(match self {
            DataVariant::Spread
            | DataVariant::Rates
            | DataVariant::Kinetic
            | DataVariant::SpreadKinetic => scenario.clone(),
            DataVariant::Damped => {
                let eta = crate::presets::load(&scenario.preset, &scenario.set)?
                    .material
                    .damping;
                scenario.with(&[format!("material.damping={:e}", eta * DAMPING_FACTOR)])
            }
            DataVariant::Hanging | DataVariant::HangingRates | DataVariant::HangingKinetic => {
                ScenarioSpec {
                    preset: HANGING_PRESET.into(),
                    ..scenario.clone()
                }
            }
        })
    }

    /// The variant's data plan.
    fn plan(self, plan: &DatasetSpec) -> DatasetSpec {
        match self {
            DataVariant::Spread | DataVariant::SpreadKinetic => DatasetSpec {
                duration: plan.duration.map(|d| d * SPREAD),
                sample_rate: plan.sample_rate.map(|f| f / SPREAD),
                ..plan.clone()
            },
            _ => plan.clone(),
        }
    }

    /// What the variant changes (its plan and scenario as [`DataVariant::plan`] and
    /// [`DataVariant::scenario`] make them), for the reports.
    fn describe(self, plan: &DatasetSpec, scenario: &ScenarioSpec) -> String {
        match self {
            DataVariant::Spread => format!(
                "the same number of snapshots over a {SPREAD}× longer babbling ({} s at {} Hz)",
                plan.duration.unwrap_or(f64::NAN),
                plan.sample_rate.unwrap_or(f64::NAN)
            ),
            DataVariant::Damped => format!(
                "{DAMPING_FACTOR}× the material damping (`--set {}`), in the data and in every run",
                scenario.set.last().map_or("", String::as_str)
            ),
            DataVariant::Hanging => format!(
                "the arm hanging along gravity (preset `{}`), in the data and in every run",
                scenario.preset
            ),
            DataVariant::Rates => {
                "the strain-rate term in the AE's training, on the paper's data".into()
            }
            DataVariant::HangingRates => format!(
                "the arm hanging along gravity (preset `{}`) and the strain-rate term in the AE's training",
                scenario.preset
            ),
            DataVariant::Kinetic => format!(
                "the strain-rate term and the kinetic-energy norm in the AE's training with a decaying rate (`--lr-decay {KINETIC_LR_DECAY} --patience 0 --lbfgs-iterations 0`), on the paper's data"
            ),
            DataVariant::HangingKinetic => format!(
                "the arm hanging along gravity (preset `{}`), the strain-rate term and the kinetic-energy norm in the AE's training with a decaying rate (`--lr-decay {KINETIC_LR_DECAY} --patience 0 --lbfgs-iterations 0`)",
                scenario.preset
            ),
            DataVariant::SpreadKinetic => format!(
                "the strain-rate term and the kinetic-energy norm in the AE's training with a decaying rate (`--lr-decay {KINETIC_LR_DECAY} --patience 0 --lbfgs-iterations 0`), on the same number of snapshots over a {SPREAD}× longer babbling ({} s at {} Hz)",
                plan.duration.unwrap_or(f64::NAN),
                plan.sample_rate.unwrap_or(f64::NAN)
            ),
        }
    }
}

/// Trains the AE (`ae`'s settings) and POD of size `r` on `variant`'s data and runs both on `test`
/// with each of `seeds` (the paper's seed first, whose HOM run is `paper_hom`), against the HOM
/// runs of the same inputs (the variant's own for [`DataVariant::Damped`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn run_variant(
    run: &Run,
    variant: DataVariant,
    scenario: &ScenarioSpec,
    plan: &DatasetSpec,
    jobs: usize,
    ae: &AeConfig,
    test: &Test,
    paper_hom: &Step<SimRun>,
    (seeds, validation, rounds): (&[u64], &[u64], usize),
) -> anyhow::Result<VariantRuns> {
    let (r, name) = (ae.latent, variant.name());
    let (sc, data_plan) = (variant.scenario(scenario)?, variant.plan(plan));
    let mut description = variant.describe(&data_plan, &sc);
    let data_name = variant.data_name();
    let data_step = match data_name {
        Some(d) => format!("iv-c2/dataset-{d}"),
        None => "iv-c2/dataset".into(),
    };
    let data = tasks::dataset(run, &data_step, &sc, &data_plan, jobs)?;
    let pod_name = data_name.unwrap_or(name);
    // the HOM run of test input `seed`: the paper's arm's for the variants of its arm, else the
    // variant's own
    let hom_of = |seed: u64| -> anyhow::Result<Step<SimRun>> {
        let t = Test {
            seed,
            ..test.clone()
        };
        match variant {
            DataVariant::Spread
            | DataVariant::Rates
            | DataVariant::Kinetic
            | DataVariant::SpreadKinetic
                if seed == test.seed =>
            {
                Ok(paper_hom.clone())
            }
            DataVariant::Spread
            | DataVariant::Rates
            | DataVariant::Kinetic
            | DataVariant::SpreadKinetic => hom_run(run, scenario, &t),
            DataVariant::Damped
            | DataVariant::Hanging
            | DataVariant::HangingRates
            | DataVariant::HangingKinetic => simulate_test(
                run,
                &format!("iv-c2/test-hom-{pod_name}-seed{seed}"),
                &format!("HOM ({pod_name} data, test seed {seed})"),
                &sc,
                &t,
                None,
                None,
            ),
        }
    };
    let (model, selection) = match variant.rates() {
        false => (
            tasks::train(run, &format!("iv-c2/ae-r{r}-{name}"), &data, ae)?,
            None,
        ),
        true => {
            let (ae, kappas): (&AeConfig, &[f64]) = match variant.kinetic() {
                true => (&kinetic_schedule(ae), &KINETIC_WEIGHTS),
                false => (ae, &[]),
            };
            let (model, selection) = select_rate_weight(
                run,
                (name, &sc, &data),
                (ae, kappas),
                test,
                validation,
                &hom_of,
            )?;
            description = format!("{description}, kept: `{}`", selection.chosen.options());
            (model, Some(selection))
        }
    };
    let pod = tasks::pod(run, &format!("iv-c2/pod-{r}-{pod_name}"), &data, r)?;
    let mut tests = vec![];
    let mut first_runs = None;
    for &seed in seeds {
        let t = Test {
            seed,
            ..test.clone()
        };
        let hom = hom_of(seed)?;
        let rom_run = |m: &Step<ModelInfo>, step: &str, label: &str, name: &str| {
            let (step, label) = test_step(step, label, r, name, seed);
            simulate_test(run, &step, &label, &sc, &t, Some(m), Some(&hom))
        };
        let ae_run = rom_run(&model, "ae-r", "AE-", name)?;
        let pod_run = rom_run(&pod, "pod-", "POD-", pod_name)?;
        if first_runs.is_none() {
            first_runs = Some([hom.path.clone(), ae_run.path.clone(), pod_run.path.clone()]);
        }
        // the rate-term AE's wall time against the HOM's in interleaved pairs (the others are
        // compared one after the other only)
        let ae_timing = match variant.rates() && rounds > 0 {
            true => {
                let step = format!("iv-c2/time-ae-r{r}-{name}-test-seed{seed}");
                Some(time_pairs(run, &step, &sc, &t, &model, rounds)?.value)
            }
            false => None,
        };
        tests.push(TestRuns {
            seed,
            hom: hom.value,
            ae: ae_run.value,
            pod: pod_run.value,
            ae_timing,
        });
    }
    Ok(VariantRuns {
        variant,
        description,
        data,
        ae: model,
        pod,
        tests,
        first_runs,
        selection,
    })
}

/// `ae` with the kinetic variants' schedule: the rate decaying to [`KINETIC_LR_DECAY`] of itself,
/// no plateaus, no L-BFGS phase.
pub(super) fn kinetic_schedule(ae: &AeConfig) -> AeConfig {
    AeConfig {
        lr_decay: Some(KINETIC_LR_DECAY),
        patience: 0,
        lbfgs_iterations: 0,
        ..ae.clone()
    }
}

/// The step name and label of a variant's ROM run (`kind` "ae-r" or "pod-", `label` "AE-" or
/// "POD-") of size `r` and data `name` on test input `seed`.
pub(super) fn test_step(
    kind: &str,
    label: &str,
    r: usize,
    name: &str,
    seed: u64,
) -> (String, String) {
    (
        format!("iv-c2/test-{kind}{r}-{name}-test-seed{seed}"),
        format!("{label}{r} ({name} data, test seed {seed})"),
    )
}

/// The table of a variant's models on every test input.
pub(super) fn variant_table(r: usize, v: &VariantRuns) -> Table {
    let mut t = more_tests_table(r, &v.tests);
    let what = &v.description;
    t.id = format!("{}-data", v.variant.name());
    t.title = format!("AE-{r} and POD-{r} with {what} (not in the paper)");
    t.note = format!(
        "As the table of test inputs above, with models trained on {} snapshots of the variant's data ({what}); {}",
        v.data.value.samples,
        match v.variant {
            DataVariant::Spread => "the HOM runs are the same. The runs of a row are not one after the other: compare the errors, and the times only roughly.",
            DataVariant::Damped => "the HOM runs are the damped arm's, one after the other with its ROMs.",
            DataVariant::Hanging => "the HOM runs are the hanging arm's, one after the other with its ROMs.",
            DataVariant::Rates | DataVariant::Kinetic => "the HOM runs and the POD are those of the paper's data; only the AE's training differs.",
            DataVariant::HangingRates | DataVariant::HangingKinetic => "the HOM runs and the POD are the hanging variant's; only the AE's training differs.",
            DataVariant::SpreadKinetic => "the HOM runs are the paper's and the POD the spread variant's; only the AE's training differs from that variant's.",
        }
    );
    if let Some(sel) = &v.selection {
        t.note = format!("{} {}.", t.note, sel.describe());
    }
    t
}

/// The variant's findings: for [`DataVariant::Spread`] whether every run stays inside its training
/// region, for [`DataVariant::Damped`] whether AE-r reaches the paper's error on every input, for
/// the others both, and whether AE-r is ahead of POD-r on every input (with the rate term, also
/// whether the AE-ROM is no slower than the HOM).
pub(super) fn variant_findings(r: usize, v: &VariantRuns) -> Vec<Finding> {
    let n = v.tests.len();
    let mean = |f: &dyn Fn(&TestRuns) -> f64| v.tests.iter().map(f).sum::<f64>() / n.max(1) as f64;
    let (ae, pod) = (mean(&|t| t.ae.tip_mean()), mean(&|t| t.pod.tip_mean()));
    let render = |f: &dyn Fn(&TestRuns) -> f64| {
        v.tests
            .iter()
            .map(|t| Cell::sig(f(t), 3).render())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let what = &v.description;
    let left: Vec<String> = v
        .tests
        .iter()
        .filter(|t| t.ae.left_training_region || t.pod.left_training_region)
        .map(|t| t.seed.to_string())
        .collect();
    let left_text = match left.is_empty() {
        true => "0 inputs had a run that left".to_string(),
        false => format!(
            "{} had a run that left (seeds {})",
            left.len(),
            left.join(", ")
        ),
    };
    let summary = format!(
        "AE-{r} {} % L (mean {}), POD-{r} mean {} % L over the {n} inputs; {left_text}",
        render(&|t| t.ae.tip_mean()),
        Cell::sig(ae, 3).render(),
        Cell::sig(pod, 3).render()
    );
    let stays = Finding {
        claim: format!(
            "with {what} (beyond the paper), no AE-{r} or POD-{r} run leaves its training region"
        ),
        holds: n > 0 && left.is_empty(),
        evidence: summary.clone(),
    };
    let target = paper::TABLE_III_IV_C2.ae_error.unwrap_or(f64::NAN);
    let reaches = Finding {
        claim: format!("with {what} (beyond the paper), AE-{r}'s mean tip error is at most the paper's {target} % L on every test input"),
        holds: n > 0 && v.tests.iter().all(|t| t.ae.complete && t.ae.tip_mean() <= target),
        evidence: summary,
    };
    let fast = v.variant.rates().then(|| {
        let timed: Vec<f64> = v
            .tests
            .iter()
            .filter(|t| t.ae.complete)
            .filter_map(|t| t.ae_timing.as_ref().map(|p| p.median_ratio))
            .collect();
        let k = timed.iter().filter(|&&x| x <= 1.0).count();
        let ratios: Vec<String> = timed.iter().map(|x| Cell::sig(*x, 2).render()).collect();
        Finding {
            claim: format!("with {what} (beyond the paper), the AE-{r}-ROM takes no more wall time than the HOM on every test input"),
            holds: n > 0 && timed.len() == n && k == n,
            evidence: format!(
                "{k} of {n} inputs; AE-ROM / HOM time {} (the median of each input's interleaved pairs)",
                ratios.join(", ")
            ),
        }
    });
    let mut findings = match v.variant {
        DataVariant::Spread => vec![stays],
        DataVariant::Damped => vec![reaches],
        DataVariant::Hanging
        | DataVariant::Rates
        | DataVariant::HangingRates
        | DataVariant::Kinetic
        | DataVariant::HangingKinetic
        | DataVariant::SpreadKinetic => {
            let ahead = v
                .tests
                .iter()
                .filter(|t| t.ae.complete && t.ae.tip_mean() < t.pod.tip_mean())
                .count();
            vec![
                reaches,
                Finding {
                    claim: format!("with {what} (beyond the paper), AE-{r} is more accurate than POD-{r} on every test input"),
                    holds: n > 0 && ahead == n,
                    evidence: format!(
                        "ahead on {ahead} of {n}: AE-{r} {} against POD-{r} {} % L",
                        render(&|t| t.ae.tip_mean()),
                        render(&|t| t.pod.tip_mean())
                    ),
                },
                stays,
            ]
        }
    };
    findings.extend(fast);
    findings
}

#[cfg(test)]
mod tests {
    use super::{DataVariant, DatasetSpec, SPREAD};

    #[test]
    fn the_spread_kinetic_variant_trains_like_the_kinetic_one_on_the_spread_data() {
        let paper = DatasetSpec {
            duration: Some(180.0),
            sample_rate: Some(100.0),
            babble: Some(vec![-15.0, 0.0, 0.5, 1.0]),
            ..DatasetSpec::default()
        };
        let v = DataVariant::SpreadKinetic;
        let plan = v.plan(&paper);
        // the same budget of snapshots: twice as long, half as often
        assert_eq!(plan.duration, Some(180.0 * SPREAD));
        assert_eq!(plan.sample_rate, Some(100.0 / SPREAD));
        assert_eq!(plan.babble, paper.babble);
        // its data, HOM runs and POD are the spread variant's; its AE trains as the kinetic one's
        assert_eq!(v.data_name(), Some(DataVariant::Spread.name()));
        assert!(v.rates() && v.kinetic());
        assert_ne!(v.name(), DataVariant::Spread.name());
        assert_ne!(v.name(), DataVariant::Kinetic.name());
    }
}
