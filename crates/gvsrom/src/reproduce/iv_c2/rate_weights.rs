//! The loss weights of a rate-term autoencoder (`gvsrom train --rate-weight β`, with the
//! kinetic-energy norm `--kinetic-weight κ`) and their choice: every candidate of [`RATE_WEIGHTS`]
//! (× [`KINETIC_WEIGHTS`]) trained and run on validation inputs of their own seeds, the one with
//! the lowest mean tip error kept — never chosen on the test inputs.

use super::super::report::Cell;
use super::super::sim_test::{simulate_test, SimRun, Test};
use super::super::step::Step;
use super::super::tasks::{self, AeConfig, DatasetInfo, ModelInfo, ScenarioSpec};
use super::super::Run;

/// The rate-term variants' candidate `--rate-weight`s.
pub(super) const RATE_WEIGHTS: [f64; 3] = [0.1, 0.3, 1.0];
/// The kinetic-energy-norm variants' candidate `--kinetic-weight`s.
pub(super) const KINETIC_WEIGHTS: [f64; 2] = [1.0, 3.0];

/// The loss weights of a rate-term AE: `--rate-weight β` and, with the kinetic-energy norm,
/// `--kinetic-weight κ`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub(super) struct LossWeights {
    pub(super) beta: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) kappa: Option<f64>,
}

impl LossWeights {
    /// `β = 0.3` or `β = 0.3, κ = 3`.
    fn label(&self) -> String {
        match self.kappa {
            Some(k) => format!("β = {}, κ = {k}", self.beta),
            None => format!("β = {}", self.beta),
        }
    }

    /// The step names' suffix: `beta0.3` or `kappa3-beta0.3`.
    pub(super) fn step_suffix(&self) -> String {
        match self.kappa {
            Some(k) => format!("kappa{k}-beta{}", self.beta),
            None => format!("beta{}", self.beta),
        }
    }

    /// `ae` trained with these weights (the reproduce steps' one definition of a weighted AE, so
    /// that the same weights on the same data make the same step).
    pub(super) fn config(&self, ae: &AeConfig) -> AeConfig {
        AeConfig {
            rate_weight: Some(self.beta),
            kinetic_weight: self.kappa,
            ..ae.clone()
        }
    }

    /// The `gvsrom train` options.
    pub(super) fn options(&self) -> String {
        match self.kappa {
            Some(k) => format!("--rate-weight {} --kinetic-weight {k}", self.beta),
            None => format!("--rate-weight {}", self.beta),
        }
    }
}

/// How the rate-term variants chose `β` among [`RATE_WEIGHTS`] (and `κ` among
/// [`KINETIC_WEIGHTS`]).
#[derive(Debug, Clone, serde::Serialize)]
pub(super) struct RateSelection {
    pub(super) validation_seeds: Vec<u64>,
    /// Per candidate: its weights and the AE's mean tip error on each validation input (`None`:
    /// the run stopped early).
    pub(super) candidates: Vec<(LossWeights, Vec<Option<f64>>)>,
    pub(super) chosen: LossWeights,
}

impl RateSelection {
    /// The mean of a candidate's validation errors, infinite if a run stopped early.
    fn score(errors: &[Option<f64>]) -> f64 {
        let sum: Option<f64> = errors.iter().copied().sum();
        sum.map_or(f64::INFINITY, |s| s / errors.len().max(1) as f64)
    }

    /// One sentence for the reports: every candidate's validation errors and the β kept.
    pub(super) fn describe(&self) -> String {
        let seeds: Vec<String> = self.validation_seeds.iter().map(u64::to_string).collect();
        let cands: Vec<String> = self
            .candidates
            .iter()
            .map(|(w, e)| {
                let errs: Vec<String> = e
                    .iter()
                    .map(|v| v.map_or("stopped".into(), |v| Cell::sig(v, 3).render()))
                    .collect();
                format!("{}: {} % L", w.label(), errs.join(", "))
            })
            .collect();
        match seeds.is_empty() {
            true => format!("{} (no validation inputs in this run)", self.chosen.label()),
            false => format!(
                "{} kept, the lowest mean tip error of the AE on validation inputs of seeds {} (not among the tests): {}",
                self.chosen.label(),
                seeds.join(", "),
                cands.join("; ")
            ),
        }
    }
}

/// The step name of the rate-term variant `name`'s AE with `r` coordinates and weights `w`.
pub(super) fn ae_step_name(r: usize, name: &str, w: &LossWeights) -> String {
    format!("iv-c2/ae-r{r}-{name}-{}", w.step_suffix())
}

/// The candidate weights: every β of [`RATE_WEIGHTS`] with every κ of `kappas` (none: β alone);
/// with no validation inputs, only the first.
fn candidates(kappas: &[f64], validation: bool) -> Vec<LossWeights> {
    let kappas: Vec<Option<f64>> = match kappas.is_empty() {
        true => vec![None],
        false => kappas.iter().copied().map(Some).collect(),
    };
    let all = kappas.iter().flat_map(|&kappa| {
        RATE_WEIGHTS
            .iter()
            .map(move |&beta| LossWeights { beta, kappa })
    });
    all.take(if validation { usize::MAX } else { 1 }).collect()
}

/// Trains the rate-term variant's AE with each candidate β (and κ among `kappas`, the
/// kinetic-energy norm's) and keeps the one with the lowest mean tip error on the `validation`
/// inputs (a run that stops early scores infinity); with no validation inputs, the first
/// candidate.
pub(super) fn select_rate_weight(
    run: &Run,
    (name, sc, data): (&str, &ScenarioSpec, &Step<DatasetInfo>),
    (ae, kappas): (&AeConfig, &[f64]),
    test: &Test,
    validation: &[u64],
    hom_of: &dyn Fn(u64) -> anyhow::Result<Step<SimRun>>,
) -> anyhow::Result<(Step<ModelInfo>, RateSelection)> {
    let r = ae.latent;
    let mut best: Option<(f64, Step<ModelInfo>, LossWeights)> = None;
    let mut table = vec![];
    for w in candidates(kappas, !validation.is_empty()) {
        let suffix = w.step_suffix();
        let model = tasks::train(run, &ae_step_name(r, name, &w), data, &w.config(ae))?;
        let mut errors = vec![];
        for &seed in validation {
            let t = Test {
                seed,
                ..test.clone()
            };
            let hom = hom_of(seed)?;
            let v = simulate_test(
                run,
                &format!("iv-c2/val-ae-r{r}-{name}-{suffix}-seed{seed}"),
                &format!(
                    "AE-{r} ({name} data, {}, validation seed {seed})",
                    w.label()
                ),
                sc,
                &t,
                Some(&model),
                Some(&hom),
            )?;
            errors.push(v.value.complete.then(|| v.value.tip_mean()));
        }
        let score = RateSelection::score(&errors);
        if best.as_ref().is_none_or(|(s, _, _)| score < *s) {
            best = Some((score, model, w));
        }
        table.push((w, errors));
    }
    let (_, model, chosen) = best.expect("at least one candidate");
    let selection = RateSelection {
        validation_seeds: validation.to_vec(),
        candidates: table,
        chosen,
    };
    Ok((model, selection))
}

#[cfg(test)]
mod tests {
    use super::{candidates, LossWeights, RateSelection};

    #[test]
    fn a_rate_weight_is_scored_by_its_mean_validation_error_and_a_stopped_run_never_wins() {
        assert_eq!(
            RateSelection::score(&[Some(1.0), Some(2.0), Some(4.5)]),
            2.5
        );
        assert_eq!(RateSelection::score(&[Some(0.1), None]), f64::INFINITY);
        let w = |beta, kappa| LossWeights { beta, kappa };
        let s = RateSelection {
            validation_seeds: vec![7, 8],
            candidates: vec![
                (w(0.1, None), vec![Some(2.0), None]),
                (w(1.0, None), vec![Some(1.25), Some(1.5)]),
            ],
            chosen: w(1.0, None),
        };
        let d = s.describe();
        assert!(d.starts_with("β = 1 kept"), "{d}");
        assert!(
            d.contains("seeds 7, 8") && d.contains("β = 0.1: 2.00, stopped % L"),
            "{d}"
        );
        let k = RateSelection {
            chosen: w(0.3, Some(3.0)),
            candidates: vec![(w(0.3, Some(3.0)), vec![Some(1.5), Some(1.75)])],
            ..s
        };
        let d = k.describe();
        assert!(d.starts_with("β = 0.3, κ = 3 kept"), "{d}");
        assert!(d.contains("β = 0.3, κ = 3: 1.50, 1.75 % L"), "{d}");
        assert_eq!(k.chosen.options(), "--rate-weight 0.3 --kinetic-weight 3");
        assert_eq!(k.chosen.step_suffix(), "kappa3-beta0.3");
    }

    #[test]
    fn the_kinetic_variants_try_every_rate_weight_with_every_kinetic_weight() {
        let all = candidates(&[1.0, 3.0], true);
        assert_eq!(all.len(), 6);
        for kappa in [1.0, 3.0] {
            for beta in [0.1, 0.3, 1.0] {
                let w = LossWeights {
                    beta,
                    kappa: Some(kappa),
                };
                assert!(all.contains(&w), "{w:?} missing");
            }
        }
        assert_eq!(candidates(&[], true).len(), 3);
        assert!(candidates(&[], true).iter().all(|w| w.kappa.is_none()));
        assert_eq!(candidates(&[1.0, 3.0], false).len(), 1);
    }
}
