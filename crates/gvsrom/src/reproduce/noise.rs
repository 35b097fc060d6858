//! The IV-A and IV-B autoencoders retrained on noisy snapshots (paper Section IV-B, last
//! paragraph: noise "locally introduces an additional dimension to the manifold" but "the
//! performance of the AE as a strain parameterization remains almost unaffected").
//!
//! For each study: Gaussian noise of `--noise` times each strain component's RMS is added to its dataset
//! ([`crate::dataset::noise::with_noise`]); the ROM autoencoder (IV-A r = 1, IV-B r = 2, 7 hidden
//! layers) and the visualisation autoencoders (r = 2 and 3, 3 hidden layers) are trained again on
//! it with the same settings; the reconstruction error is measured against the clean snapshots and
//! the ROM's strain error at the study's test inputs against the HOM.

use super::evaluation::{statics_eval, EvalModel, Evaluation};
use super::report::{figure, CaseReport, Cell, Finding, RenderedFigure, Table};
use super::step::Step;
use super::tasks::{self, DatasetInfo, ModelInfo, ScenarioSpec};
use super::{iv_a, iv_b, iv_common, new_report, Case, Options, Run};
use crate::plot::Figure;
use serde_json::json;

/// The seed of the noise.
const NOISE_SEED: u64 = 11;

/// A noisy copy of `data` (step `<name>`).
fn noisy(
    run: &Run,
    name: &str,
    data: &Step<DatasetInfo>,
    level: f64,
) -> anyhow::Result<Step<DatasetInfo>> {
    let config =
        json!({ "dataset": data.key(), "level": level, "per_component": true, "seed": NOISE_SEED });
    run.step(
        name,
        &config,
        |p| crate::dataset::Dataset::load(p).is_ok_and(|d| d.meta.noise.is_some()),
        |path| {
            crate::dataset::noise::with_noise(&data.path, level, NOISE_SEED, path, true)?;
            Ok(data.value.clone())
        },
    )
}

/// Trains the study's autoencoder `(data, r, hidden layers, step-name prefix)`: an empty prefix
/// names the study's own (clean) step, so it is shared with the study's case.
type TrainFn<'a> =
    dyn Fn(&Step<DatasetInfo>, usize, usize, &str) -> anyhow::Result<Step<ModelInfo>> + Sync + 'a;

/// One study's clean and noisy models, measured.
struct Study {
    label: &'static str,
    rom_label: String,
    clean: Step<ModelInfo>,
    noisy: Step<ModelInfo>,
    /// RMSE of the noisy model against the clean snapshots.
    noisy_vs_clean: f64,
    ev: Evaluation,
    latent_clean: iv_common::Latent,
    latent_noisy: iv_common::Latent,
}

#[allow(clippy::too_many_arguments)]
fn study(
    run: &Run,
    label: &'static str,
    prefix: &str,
    data: &Step<DatasetInfo>,
    level: f64,
    rom: (usize, usize),
    train: &TrainFn<'_>,
    scenario: &ScenarioSpec,
    inputs: &[Vec<String>],
    color: (usize, &str),
) -> anyhow::Result<Study> {
    let noisy_data = noisy(run, &format!("noise/{prefix}-dataset"), data, level)?;
    let (r, h) = rom;
    let clean = train(data, r, h, "")?;
    let vis_clean = [train(data, 2, 3, "")?, train(data, 3, 3, "")?];
    let noisy_models = tasks::parallel(&[(r, h), (2, 3), (3, 3)], |&(r, h)| {
        train(&noisy_data, r, h, &format!("noise/{prefix}-"))
    })?;
    let model = crate::reduced_model::ReducedModel::load(&noisy_models[0].path)?;
    let noisy_vs_clean = tasks::reconstruction_rmse(&data.path, &model)?;
    let rom_label = format!("AE-{r}");
    let models = [
        EvalModel::hom(),
        EvalModel::of(&rom_label, &clean),
        EvalModel::of(&format!("{rom_label} noisy"), &noisy_models[0]),
    ];
    let ev = statics_eval(
        run,
        &format!("noise/{prefix}-eval"),
        scenario,
        inputs,
        &models,
        1,
    )?;
    let latent_clean = iv_common::latent_and_dimension(
        &data.path,
        &[&vis_clean[0], &vis_clean[1]],
        &[],
        color.0,
        color.1,
    )?;
    let latent_noisy = iv_common::latent_and_dimension(
        &noisy_data.path,
        &[&noisy_models[1], &noisy_models[2]],
        &[],
        color.0,
        color.1,
    )?;
    Ok(Study {
        label,
        rom_label,
        clean,
        noisy: noisy_models[0].clone(),
        noisy_vs_clean,
        ev: ev.value,
        latent_clean,
        latent_noisy,
    })
}

/// Runs the noise study.
pub fn run(run: &Run, opts: &Options) -> anyhow::Result<(CaseReport, Vec<RenderedFigure>)> {
    let level = opts.noise;
    let a_data = iv_a::dataset(run, opts)?;
    let train_a = |d: &Step<DatasetInfo>, r: usize, h: usize, prefix: &str| {
        let c = iv_a::ae_config(opts, r, h);
        if prefix.is_empty() {
            iv_a::ae_step(run, d, &c)
        } else {
            tasks::train(run, &format!("{prefix}ae-r{r}-h{h}"), d, &c)
        }
    };
    let a_inputs: Vec<Vec<String>> = iv_a::test_tensions()
        .iter()
        .map(|u| vec![format!("tendons.0.tension={u}")])
        .collect();
    let a = study(
        run,
        "IV-A",
        "iv-a",
        &a_data,
        level,
        (1, 7),
        &train_a,
        &iv_a::scenario(),
        &a_inputs,
        (0, "tension u [N]"),
    )?;
    let b_data = iv_b::dataset(run, opts)?;
    let train_b = |d: &Step<DatasetInfo>, r: usize, h: usize, prefix: &str| {
        let c = iv_b::ae_config(opts, r, h);
        if prefix.is_empty() {
            iv_b::ae_step(run, d, &c)
        } else {
            tasks::train(run, &format!("{prefix}ae-r{r}-h{h}"), d, &c)
        }
    };
    let b = study(
        run,
        "IV-B",
        "iv-b",
        &b_data,
        level,
        (2, 7),
        &train_b,
        &iv_b::scenario(),
        &iv_b::test_inputs(),
        (1, "magnitude [N·m]"),
    )?;

    let mut report = new_report(
        Case::Noise,
        "autoencoders trained on noisy snapshots (paper Section IV-B, last paragraph)",
    );
    report.setup = vec![
        format!("noise: Gaussian, independent per snapshot entry, σ_c = {} × the RMS of each strain component c of the clean snapshots (`--noise`; the paper does not give its level), seed {NOISE_SEED}", gvs::error::fmt_value(level)),
        "IV-A: its dataset and test tensions; ROM autoencoder r = 1, 7 hidden layers; latent plots r = 2 and 3, 3 hidden layers — trained again on the noisy snapshots with the same settings".into(),
        "IV-B: its dataset (total moment in N·m) and the two Fig. 6 loads; ROM autoencoder r = 2, 7 hidden layers; latent plots as IV-A".into(),
    ];
    let mut rows = vec![];
    let mut findings = vec![];
    for s in [&a, &b] {
        let (clean_err, clean_max) = s.ev.stats(&s.rom_label, |x| x.strain_error_percent);
        let noisy_label = format!("{} noisy", s.rom_label);
        let (noisy_err, noisy_max) = s.ev.stats(&noisy_label, |x| x.strain_error_percent);
        rows.push(vec![
            Cell::text(s.label),
            Cell::text(format!("{} clean", s.rom_label)),
            Cell::sig(s.clean.value.rmse_full, 3),
            Cell::sig(s.clean.value.rmse_full, 3),
            Cell::sig(clean_err, 3),
            Cell::sig(clean_max, 3),
        ]);
        rows.push(vec![
            Cell::text(s.label),
            Cell::text(noisy_label),
            Cell::sig(s.noisy_vs_clean, 3),
            Cell::sig(s.noisy.value.rmse_full, 3),
            Cell::sig(noisy_err, 3),
            Cell::sig(noisy_max, 3),
        ]);
        findings.push(Finding {
            claim: format!("{}: the AE-ROM trained on noisy data stays as accurate (its mean strain error within 1.5× the clean one's)", s.label),
            holds: noisy_err <= 1.5 * clean_err,
            evidence: format!("mean strain error {} % (noisy) against {} % (clean)", Cell::sig(noisy_err, 3).render(), Cell::sig(clean_err, 3).render()),
        });
    }
    report.tables.push(Table {
        id: "noise".into(),
        title: "Reconstruction and ROM accuracy with and without noise".into(),
        columns: ["study", "model", "RMSE vs the clean snapshots", "RMSE vs its training snapshots", "ROM strain error mean [%]", "ROM strain error max [%]"].map(String::from).to_vec(),
        rows,
        note: "RMSE over every entry of every solved snapshot, strain units. A model reconstructing the clean snapshots better than its noisy training data has denoised them. ROM strain error: against the HOM at the study's test inputs.".into(),
    });
    report.findings = findings;
    report.settings = json!({ "noise_level": level, "noise_seed": NOISE_SEED });
    report.values = json!({
        "iv_a": { "clean": a.clean.value, "noisy": a.noisy.value, "noisy_vs_clean": a.noisy_vs_clean, "latent_clean": a.latent_clean.values, "latent_noisy": a.latent_noisy.values },
        "iv_b": { "clean": b.clean.value, "noisy": b.noisy.value, "noisy_vs_clean": b.noisy_vs_clean, "latent_clean": b.latent_clean.values, "latent_noisy": b.latent_noisy.values },
    });
    let mut figures = vec![];
    for (s, stem) in [(&a, "latent-iv-a"), (&b, "latent-iv-b")] {
        let fig = Figure::Grid {
            title: format!(
                "{}: latent coordinates, clean (top) and noisy (bottom) training data",
                s.label
            ),
            cols: 1,
            panels: vec![s.latent_clean.figure.clone(), s.latent_noisy.figure.clone()],
        };
        figures.push(figure(stem, &format!("{}: the training samples' latent coordinates (r = 2 and 3, 3 hidden layers) with clean and with noisy snapshots", s.label), &fig, 1400, 1240)?);
    }
    Ok((report, figures))
}
