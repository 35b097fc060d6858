//! The steps the cases are made of, each one call of the library function a command also calls:
//! a dataset (`gvsrom dataset`), a POD model (`gvsrom pod`), an autoencoder (`gvsrom train`); the
//! reconstruction errors of a model over a dataset; and [`parallel`], which runs such steps on the
//! run's threads. The statics of the HOM and reduced models at test inputs (`gvsrom statics
//! [--model]`) are in the `evaluation` module.

use super::step::{Interrupted, Run, Step};
use crate::dataset::{Dataset, DatasetRequest};
use crate::reduced_model::ReducedModel;
use crate::{build, presets, reduce, scenario, Built};
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::Ordering;

/// A scenario: a preset (or file) with `--set` overrides.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ScenarioSpec {
    pub preset: String,
    pub set: Vec<String>,
}

impl ScenarioSpec {
    pub fn new(preset: &str, set: &[&str]) -> ScenarioSpec {
        ScenarioSpec {
            preset: preset.into(),
            set: set.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// The same scenario with more overrides.
    pub fn with(&self, more: &[String]) -> ScenarioSpec {
        let mut s = self.clone();
        s.set.extend(more.iter().cloned());
        s
    }

    /// The built scenario and its TOML table after the overrides (the table supplies non-tension
    /// inputs to a reduced model's initial guess, as `--set` does on the command line).
    pub fn build(&self) -> anyhow::Result<(Built, toml::Table)> {
        let s = presets::load(&self.preset, &self.set)?;
        let built = build(&s)?;
        let src = presets::source(&self.preset)?;
        let mut table = scenario::parse_table(&src.origin, &src.text)?;
        for spec in &self.set {
            scenario::apply_override(&mut table, spec)?;
        }
        Ok((built, table))
    }

    /// The provenance of a run of this scenario ([`crate::provenance`]), started now.
    pub fn provenance(&self) -> anyhow::Result<crate::provenance::Provenance> {
        let src = presets::source(&self.preset)?;
        let s = presets::load_from(&src, &self.set)?;
        Ok(src.provenance(&self.set, s.to_toml()?))
    }
}

/// A sampling plan of `gvsrom dataset` (static: sweep/grid/random; dynamic: babbling).
#[derive(Debug, Clone, Serialize, Deserialize, Default)]
pub struct DatasetSpec {
    pub sweep: Vec<String>,
    pub grid: Vec<String>,
    pub random: Vec<String>,
    pub samples: Option<usize>,
    pub seed: u64,
    pub duration: Option<f64>,
    pub babble: Option<Vec<f64>>,
    pub sample_rate: Option<f64>,
}

/// What a dataset step reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DatasetInfo {
    pub samples: usize,
    pub ok: usize,
    pub failed: usize,
    pub features: usize,
    pub parameters: Vec<String>,
}

/// `gvsrom dataset` on `scenario` with `plan`, at `<out>/steps/<name>`.
pub fn dataset(
    run: &Run,
    name: &str,
    scenario: &ScenarioSpec,
    plan: &DatasetSpec,
    jobs: usize,
) -> anyhow::Result<Step<DatasetInfo>> {
    let config = serde_json::json!({ "scenario": scenario, "plan": plan });
    run.step(
        name,
        &config,
        |p| Dataset::load(p).is_ok_and(|d| d.meta.complete),
        |path| {
            let args = DatasetRequest {
                scenario: scenario.preset.clone(),
                set: scenario.set.clone(),
                sweep: plan.sweep.clone(),
                grid: plan.grid.clone(),
                random: plan.random.clone(),
                samples: plan.samples,
                // a sweep or grid draws nothing, and a seed with it is refused
                seed: (!plan.random.is_empty() || plan.babble.is_some()).then_some(plan.seed),
                chunk_size: crate::dataset::DEFAULT_CHUNK_SIZE,
                threads: Some(jobs),
                out: path.to_path_buf(),
                force: true,
                resume: false,
                duration: plan.duration,
                sample_rate: plan.sample_rate,
                input: None,
                interpolate: false,
                steps: None,
                babble: plan.babble.clone(),
                from_equilibrium: false,
                rtol: None,
                atol: 1e-6,
                stop_after_chunks: None,
            };
            let outcome = crate::dataset::run(&args, run.interrupt())?;
            if outcome.interrupted.is_some() {
                run.check_interrupt()?;
                anyhow::bail!("the dataset `{}` stopped early", path.display());
            }
            let m = &outcome.meta;
            Ok(DatasetInfo {
                samples: m.samples,
                ok: m.counts.ok,
                failed: m.counts.failed,
                features: m.strain_x.len() * m.components.len(),
                parameters: m.parameters.clone(),
            })
        },
    )
}

/// What a model step reports.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModelInfo {
    pub latent: usize,
    /// RMS reconstruction error over every solved sample of the dataset (Table I), strain units.
    #[serde(with = "nan_as_null")]
    pub rmse_full: f64,
    /// POD: captured energy of the kept modes.
    pub captured_energy: Option<f64>,
    /// Autoencoder: training and validation RMSE, epochs, wall time of the training alone.
    pub train_rmse: Option<f64>,
    pub val_rmse: Option<f64>,
    pub epochs_run: Option<usize>,
    pub anchor_equilibria: usize,
}

/// `gvsrom pod DATASET --modes K` at `<out>/steps/<name>`.
pub fn pod(
    run: &Run,
    name: &str,
    data: &Step<DatasetInfo>,
    modes: usize,
) -> anyhow::Result<Step<ModelInfo>> {
    pod_in(run, name, data, modes, reduce::PodNorm::Plain)
}

/// `gvsrom pod DATASET --modes K --norm N` at `<out>/steps/<name>` (the plain norm's step is
/// [`pod`]'s, with the same key).
pub fn pod_in(
    run: &Run,
    name: &str,
    data: &Step<DatasetInfo>,
    modes: usize,
    norm: reduce::PodNorm,
) -> anyhow::Result<Step<ModelInfo>> {
    let mut config = serde_json::json!({ "dataset": data.key(), "modes": modes });
    if norm != reduce::PodNorm::Plain {
        config["norm"] = serde_json::json!(norm);
    }
    run.step(
        name,
        &config,
        // (a model without a recorded validity range is from an earlier build: made again)
        |p| ReducedModel::load(p).is_ok_and(|m| !m.meta.input_range.is_empty()),
        |path| {
            let s = reduce::pod(&[&data.path], modes, norm, path, true)?;
            let model = ReducedModel::load(path)?;
            Ok(ModelInfo {
                latent: modes,
                rmse_full: reconstruction_rmse(&data.path, &model)?,
                captured_energy: Some(s.captured_energy),
                train_rmse: None,
                val_rmse: None,
                epochs_run: None,
                anchor_equilibria: s.anchor_equilibria,
            })
        },
    )
}

/// The settings of one autoencoder (`gvsrom train` options).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AeConfig {
    pub latent: usize,
    pub hidden_layers: usize,
    pub epochs: usize,
    pub patience: usize,
    pub lambda: f64,
    pub batch_size: usize,
    pub learning_rate: f64,
    pub seed: u64,
    /// Iterations of the final full-batch L-BFGS phase (0: none).
    pub lbfgs_iterations: usize,
    /// The loss weighting (`gvsrom train --loss`).
    pub loss: reduce::Loss,
    /// Learning-rate reductions at plateaus (`--lr-reductions`).
    pub lr_reductions: usize,
    /// The decoder's form (`--decoder`); absent: `plain`, the paper's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decoder: Option<String>,
    /// The weight of the strain-rate term (`--rate-weight`); absent: 0, eq. (15) alone (the
    /// paper's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_weight: Option<f64>,
    /// The final factor of the exponential rate decay (`--lr-decay`); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lr_decay: Option<f64>,
    /// The weight of the kinetic-energy norm (`--kinetic-weight`); absent: 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kinetic_weight: Option<f64>,
}

impl AeConfig {
    /// `gvsrom train`'s defaults (λ = 1e-4 as in the paper) with `epochs`.
    pub fn new(latent: usize, hidden_layers: usize, epochs: usize) -> AeConfig {
        let d = rom::nn::TrainOptions::default();
        AeConfig {
            latent,
            hidden_layers,
            epochs,
            patience: d.patience.unwrap_or(0),
            lambda: d.lambda,
            batch_size: d.batch_size,
            learning_rate: d.learning_rate,
            seed: d.seed,
            lbfgs_iterations: d.fine_tune.lbfgs_iterations(),
            loss: reduce::Loss::default(),
            lr_reductions: d.lr_reductions,
            decoder: None,
            rate_weight: None,
            lr_decay: None,
            kinetic_weight: None,
        }
    }
}

/// `gvsrom train DATASET …` at `<out>/steps/<name>`; Ctrl-C stops the training and the run (the
/// partial model is not recorded as a finished step).
pub fn train(
    run: &Run,
    name: &str,
    data: &Step<DatasetInfo>,
    c: &AeConfig,
) -> anyhow::Result<Step<ModelInfo>> {
    let config = serde_json::json!({ "dataset": data.key(), "ae": c });
    run.step(
        name,
        &config,
        // (a model without a recorded validity range is from an earlier build: made again)
        |p| ReducedModel::load(p).is_ok_and(|m| !m.meta.input_range.is_empty()),
        |path| {
            let options = rom::nn::TrainOptions {
                latent: c.latent,
                hidden_layers: c.hidden_layers,
                lambda: c.lambda,
                epochs: c.epochs,
                batch_size: c.batch_size,
                learning_rate: c.learning_rate,
                patience: (c.patience > 0).then_some(c.patience),
                seed: c.seed,
                lr_reductions: c.lr_reductions,
                lr_decay: c.lr_decay,
                fine_tune: rom::nn::FineTune::lbfgs(c.lbfgs_iterations),
                decoder: reduce::decoder_form(c.decoder.as_deref().unwrap_or("plain"))?,
                rate_weight: c.rate_weight.unwrap_or(0.0),
                ..rom::nn::TrainOptions::default()
            };
            let interrupt = run.interrupt().clone();
            let mut progress =
                |_: usize, _: f64, _: Option<f64>| match interrupt.load(Ordering::SeqCst) {
                    0 => ControlFlow::Continue(()),
                    _ => ControlFlow::Break(()),
                };
            let kinetic = c.kinetic_weight.unwrap_or(0.0);
            let s = reduce::train(
                &[&data.path],
                None,
                &options,
                c.loss,
                kinetic,
                path,
                true,
                &mut progress,
            )?;
            run.check_interrupt()?;
            let model = ReducedModel::load(path)?;
            Ok(ModelInfo {
                latent: c.latent,
                rmse_full: reconstruction_rmse(&data.path, &model)?,
                captured_energy: None,
                train_rmse: Some(s.report.final_train_rmse),
                val_rmse: s.report.final_val_rmse,
                epochs_run: Some(s.report.epochs_run),
                anchor_equilibria: s.anchor_equilibria,
            })
        },
    )
}

/// Table I's measure: `sqrt(mean (x̂ − x)²)` over every entry of every solved snapshot of the
/// dataset (training and validation rows alike), x̂ the model's reconstruction (AE: `D(E(x))`; POD:
/// `V Vᵀ x`), in the snapshots' units (1/m for curvatures): [`reduce::reconstruction`].
pub fn reconstruction_rmse(dataset: &Path, model: &ReducedModel) -> anyhow::Result<f64> {
    Ok(reduce::reconstruction(model, &Dataset::load(dataset)?)?.rmse)
}

/// For every solved sample of `ds`: its value of the input `parameter` and each of `models`'
/// reconstruction error in the strain-error measure of the accuracy tables, mean `|x̂ − x|` over the
/// row in % of the row's largest `|x|` (for an autoencoder through its encoder; the best point of
/// the decoder's manifold, which a reduced equilibrium of a linear-elastic problem reaches, is at
/// most this far). Rows with no strain are skipped.
pub fn relative_errors(
    ds: &Dataset,
    models: &[&ReducedModel],
    parameter: &str,
) -> anyhow::Result<Vec<(f64, Vec<f64>)>> {
    let d = ds.meta.parameters.len();
    let column = ds
        .meta
        .parameters
        .iter()
        .position(|p| p == parameter)
        .ok_or_else(|| anyhow::anyhow!("the dataset varies no `{parameter}`"))?;
    let mut out = vec![];
    for k in ds.ok_rows() {
        let x = ds.strain_row(k);
        let peak = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if peak == 0.0 {
            continue;
        }
        let errors = models
            .iter()
            .map(|m| {
                let rec = m.reconstruct(x, true)?;
                let mae = x.iter().zip(&rec).map(|(a, b)| (a - b).abs()).sum::<f64>();
                Ok(100.0 * mae / x.len() as f64 / peak)
            })
            .collect::<anyhow::Result<Vec<f64>>>()?;
        out.push((ds.inputs[k * d + column], errors));
    }
    Ok(out)
}

/// NaN (a failed solve's numbers) as JSON `null` and back: JSON has no NaN, and a step record must
/// read back exactly what it stored.
pub(super) mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        v.is_finite().then_some(*v).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }

    pub mod array3 {
        use serde::{Deserialize, Deserializer, Serialize, Serializer};

        pub fn serialize<S: Serializer>(v: &[f64; 3], s: S) -> Result<S::Ok, S::Error> {
            v.map(|x| x.is_finite().then_some(x)).serialize(s)
        }

        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
            Ok(<[Option<f64>; 3]>::deserialize(d)?.map(|x| x.unwrap_or(f64::NAN)))
        }
    }
}

/// Runs `f` over `items` on the run's thread pool (in parallel), keeping the order, with its
/// progress on stderr ([`crate::progress::bar`]: a bar on a terminal, plain lines elsewhere); the
/// first interrupt or error wins.
pub fn parallel<I: Sync, T: Send>(
    items: &[I],
    f: impl Fn(&I) -> anyhow::Result<T> + Sync + Send,
) -> anyhow::Result<Vec<T>> {
    use rayon::prelude::*;
    let bar = crate::progress::bar(items.len() as u64, "models");
    let results: Vec<anyhow::Result<T>> = items
        .par_iter()
        .map(|i| {
            let r = f(i);
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    // an interrupt anywhere is reported as the interrupt, not as the error it caused elsewhere
    if let Some(i) = results.iter().find_map(|r| {
        r.as_ref()
            .err()
            .and_then(|e| e.downcast_ref::<Interrupted>())
    }) {
        return Err(Interrupted {
            signal: i.signal,
            out: i.out.clone(),
        }
        .into());
    }
    results.into_iter().collect()
}
