//! `gvsrom train DATASET… --latent R --hidden-layers N --out MODEL`: a tanh autoencoder learned
//! from the strain snapshots of one or more datasets, whose decoder becomes a nonlinear reduced
//! model.

use super::loss::Loss;
use super::sources::Sources;
use super::start::StartModel;
use super::{equilibrium_anchors, invalid, model_layout, projection_of};
use crate::error::ScenarioError;
use crate::output::OutputDir;
use crate::reduced_model::{ModelMeta, ModelWeights, ReducedModel, TrainingMeta};
use nalgebra::DVector;
use rom::nn::{Autoencoder, DecoderForm, SampleWeighting, TrainOptions, TrainReport};
use rom::reduced::projection_residual;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What `gvsrom train` reports.
pub struct TrainSummary {
    pub path: PathBuf,
    pub rows: usize,
    /// Each dataset and its usable rows, in order (the rows are `rows` in all).
    pub datasets: Vec<(PathBuf, usize)>,
    pub features: usize,
    pub report: TrainReport,
    pub encoder_sizes: Vec<usize>,
    /// The rest coordinates: the encoding of the straight rod (`ξ = ξ*`) when it was trained in
    /// ([`zero_anchor_rows`]), else of the sample closest to it.
    pub rest: Vec<f64>,
    /// `‖D(rest)‖`: how far the rest coordinates decode from the straight rod (all points and
    /// components, strain units).
    pub rest_residual: f64,
    /// Copies of the zero-strain snapshot among the training rows.
    pub zero_anchor_rows: usize,
    pub projection_residual: f64,
    /// How many of the `rows` anchors are the reduced model's own equilibria, and the time their
    /// solves took.
    pub anchor_equilibria: usize,
    pub anchor_time_s: f64,
    /// Warnings for the user (a dataset without content hashes).
    pub warnings: Vec<String>,
}

/// Snapshots that do not differ (a sweep of one value, `LO:LO`) give an autoencoder nothing to
/// learn: its standardization divides by a spread of 0 and the model trained on them is no
/// model (on the IV-A arm, an unstable reduced statics and a run that fails at once). Refused,
/// naming the datasets, when every feature's spread over the rows `x` (`rows × features`) is
/// within 1e-12 of the snapshots' size.
fn refuse_constant_snapshots<P: AsRef<Path>>(
    x: &[f64],
    rows: usize,
    features: usize,
    datasets: &[P],
) -> Result<(), anyhow::Error> {
    if rows == 0 || features == 0 {
        return Ok(());
    }
    let size = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let spread = (0..features)
        .map(|f| {
            let column = (0..rows).map(|r| x[r * features + f]);
            let (lo, hi) = column.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            hi - lo
        })
        .fold(0.0f64, f64::max);
    if spread > 1e-12 * size && spread > 0.0 {
        return Ok(());
    }
    let names: Vec<String> = (datasets.iter())
        .map(|d| format!("`{}`", d.as_ref().display()))
        .collect();
    Err(invalid(
        "DATASET",
        format!(
            "{}: the {rows} usable snapshots do not differ (largest spread {spread:.3e} against their size {size:.3e}), so an autoencoder has nothing to learn from them; sample the inputs over a range (e.g. `--sweep tendons.0.tension=-6:0`)",
            names.join(", ")
        ),
    )
    .into())
}

/// Trains an autoencoder on the snapshots of `datasets` (one, or several of one scenario: their
/// rows in order) and saves it at `out`. `progress(epoch, train, validation)` is called after every
/// epoch; `Break` stops training early (the best weights so far are kept and saved, marked by the
/// stop reason). With `kinetic_weight` κ > 0 (and a rate term) the errors are also measured in
/// the kinetic-energy norm of each row's own mass matrix (`reduce::kinetic`, [`rom::nn::metric`]).
/// With `init` the training starts from that model's weights and scaling (`--init`, [`StartModel`]):
/// its architecture, decoder form and loss must be `options`' and `loss`.
#[allow(clippy::too_many_arguments)]
pub fn train<P: AsRef<Path>>(
    datasets: &[P],
    init: Option<&StartModel>,
    options: &TrainOptions,
    loss: Loss,
    kinetic_weight: f64,
    out: &Path,
    force: bool,
    progress: &mut dyn FnMut(usize, f64, Option<f64>) -> ControlFlow<()>,
) -> Result<TrainSummary, anyhow::Error> {
    super::refuse_input_overlap(out, datasets, init.map(|s| s.dir.as_path()))?;
    let mut provenance = crate::provenance::Provenance::of_command();
    if let Some(start) = init {
        provenance = provenance.start_model(&start.origin());
    }
    let src = Sources::load(datasets)?;
    let provenance = src.record(provenance).seed("training", options.seed);
    let built = &src.built;
    let start_warnings = match init {
        Some(start) => start.check(&src, options, loss)?,
        None => vec![],
    };
    super::at_most_the_full_models_dof("--latent", options.latent, built)?;
    let (layout, pm, p) = projection_of(built)?;
    let (x, rows, features) = (&src.x, src.rows(), src.features);
    let options = &TrainOptions {
        weighting: loss.weighting(built, &layout),
        ..options.clone()
    };
    if options.rate_weight > 0.0 && src.dynamic_rows() == 0 {
        return Err(invalid(
            "--rate-weight",
            format!(
                "{}: every dataset holds static equilibria, whose strain rates are 0, so the rate term has nothing to fit; it needs a trajectory dataset (`gvsrom dataset … --duration`)",
                options.rate_weight
            ),
        )
        .into());
    }
    if !(kinetic_weight.is_finite() && kinetic_weight >= 0.0) {
        return Err(invalid(
            "--kinetic-weight",
            format!("{kinetic_weight}: expected finite and ≥ 0"),
        )
        .into());
    }
    if kinetic_weight > 0.0 && options.rate_weight == 0.0 {
        return Err(invalid(
            "--kinetic-weight",
            format!(
                "{kinetic_weight} without a rate term: the kinetic-energy norm is scaled on the strain rates of trajectory data, so it needs `--rate-weight` > 0"
            ),
        )
        .into());
    }
    refuse_constant_snapshots(x, rows, features, datasets)?;
    let dir = OutputDir::create("--out", out, crate::reduced_model::MODEL_FORMAT, force)?;
    // the zero-strain anchor of trajectory data: the straight rod, where simulations from rest
    // start, joins the training rows so that a latent point decodes to it
    let anchor_rows = zero_anchor_rows(src.dynamic_rows());
    let training: std::borrow::Cow<[f64]> = match anchor_rows {
        0 => (&x[..]).into(),
        k => {
            let mut t = Vec::with_capacity((rows + k) * features);
            t.extend_from_slice(x);
            t.resize((rows + k) * features, 0.0);
            t.into()
        }
    };
    // the strain-rate term: the rates of the usable rows, and the straight rod's anchor at rest
    let rates = (options.rate_weight > 0.0).then(|| {
        let mut v = src.strain_rates();
        v.resize(training.len(), 0.0);
        v
    });
    let metric = match kinetic_weight > 0.0 {
        true => Some(Arc::new(super::kinetic::kinetic_metric(
            built,
            &p,
            &training,
            features,
            kinetic_weight,
        )?)),
        false => None,
    };
    let (ae, report) = match init {
        Some(start) => {
            start
                .autoencoder()
                .train_on(&training, rates.as_deref(), metric, options, progress)
        }
        None => Autoencoder::train_with_metric(
            &training,
            rates.as_deref(),
            metric,
            features,
            options,
            progress,
        ),
    }
    .map_err(|e| match (init, &e) {
        // a start already at its best for these options: say so, naming it
        (Some(start), rom::nn::NnError::NoProgress { epochs, initial }) => invalid(
            "--init",
            format!(
                "the start model `{}` was not improved on: its loss {initial:.3e} was not beaten in {epochs} epochs with these options, so nothing was written; keep the start model, or try another --learning-rate or --lambda{}",
                start.dir.display(),
                match options.seed != start.seed
                    || options.validation_fraction != start.validation_fraction
                {
                    true => " (with another --seed or --validation-fraction than the start's, its validation rows may be rows it was trained on, a loss hard to beat: leave both out to keep its split)",
                    false => "",
                }
            ),
        ),
        _ => train_error(&e),
    })?;
    drop((training, rates));
    // one encoding per usable sample: its range, the anchors, and what the HOM basis cannot
    // represent of the reconstructions
    let mut worst = 0.0f64;
    let r = options.latent;
    let mut latent = Vec::with_capacity(rows * r);
    let mut range = vec![[f64::INFINITY, f64::NEG_INFINITY]; r];
    for row in x.chunks_exact(features) {
        let z = ae
            .encode(row)
            .map_err(|e| invalid("train", e.to_string()))?;
        let rec = ae.decode(&z).map_err(|e| invalid("train", e.to_string()))?;
        worst = worst.max(projection_residual(&pm, &p, &DVector::from_vec(rec)));
        for (d, v) in z.iter().enumerate() {
            range[d][0] = range[d][0].min(*v);
            range[d][1] = range[d][1].max(*v);
        }
        latent.extend_from_slice(&z);
    }
    // the rest coordinates: with the zero-strain anchor the encoding of the straight rod, else
    // that of the sample closest to it (equilibria under gravity: the straight rod is off their
    // manifold and its encoding may lie outside the data's range); and how far they decode from it
    let zero = vec![0.0; features];
    let straightest = || {
        x.chunks_exact(features)
            .min_by(|a, b| {
                let n = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
                n(a).total_cmp(&n(b))
            })
            .expect("at least one usable row")
    };
    let mut rest = ae
        .encode(if anchor_rows > 0 {
            &zero
        } else {
            straightest()
        })
        .map_err(|e| invalid("train", e.to_string()))?;
    if ae.form() == DecoderForm::Scaled {
        // z₁ = 0 decodes to the straight rod exactly
        rest[0] = 0.0;
    }
    let rest_decoded = ae
        .decode(&rest)
        .map_err(|e| invalid("train", e.to_string()))?;
    let rest_residual = rest_decoded.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rest = DVector::from_vec(rest);
    let mut warnings = src.warnings();
    warnings.extend(start_warnings);
    let refs = src.refs();
    warnings.extend(scaled_basin_warning(ae.form(), range[0]));
    let meta = ModelMeta {
        kind: "autoencoder".into(),
        latent: options.latent,
        layout: model_layout(src.first(), built),
        dataset: refs.0,
        more_datasets: refs.1,
        rest: rest.iter().copied().collect(),
        latent_range: range,
        snapshot_norm_max: Some(super::largest_norm(x, features)),
        input_range: src.input_ranges(),
        anchor_parameters: src.first().meta.parameters.clone(),
        anchor_equilibria: 0,
        captured_energy: None,
        pod_norm: None,
        training: Some(TrainingMeta {
            hidden_layers: options.hidden_layers,
            encoder_sizes: ae.encoder().layer_sizes().to_vec(),
            decoder_sizes: ae.decoder().layer_sizes().to_vec(),
            lambda: options.lambda,
            epochs: options.epochs,
            batch_size: options.batch_size,
            learning_rate: options.learning_rate,
            validation_fraction: options.validation_fraction,
            patience: options.patience,
            seed: options.seed,
            loss: Some(loss.name().into()),
            lr_reductions: Some(options.lr_reductions),
            lr_decay: options.lr_decay,
            zero_anchor_rows: Some(anchor_rows),
            lbfgs_iterations: Some(options.fine_tune.lbfgs_iterations()),
            sample_weighting: Some(
                match options.sample_weighting {
                    SampleWeighting::Uniform => "uniform",
                    SampleWeighting::Relative { .. } => "relative",
                }
                .into(),
            ),
            relative_floor: match options.sample_weighting {
                SampleWeighting::Relative { floor } => Some(floor),
                SampleWeighting::Uniform => None,
            },
            decoder: Some(ae.form().name().into()),
            rate_weight: Some(options.rate_weight),
            kinetic_weight: (kinetic_weight > 0.0).then_some(kinetic_weight),
            epochs_run: report.epochs_run,
            fine_tune_iterations_run: Some(report.fine_tune_epochs_run),
            best_epoch: report.best_epoch,
            stop: format!("{:?}", report.stop),
            final_train_loss: report.final_train_loss,
            final_val_loss: report.final_val_loss,
            final_train_rmse: report.final_train_rmse,
            final_val_rmse: report.final_val_rmse,
            wall_time_s: report.wall_time.as_secs_f64(),
        }),
        projection_residual: worst,
        crate_version: env!("CARGO_PKG_VERSION").into(),
        provenance: Some(provenance),
    };
    let encoder_sizes = ae.encoder().layer_sizes().to_vec();
    let mut model = ReducedModel {
        meta,
        weights: ModelWeights::Autoencoder(ae),
        // written by this run: as its files will be hashed
        integrity: crate::output::Integrity::Checked,
        dir: None,
        anchors: Some(crate::reduced_model::Anchors {
            n: rows,
            inputs: src.sample_inputs(),
            latent,
        }),
    };
    let t_anchors = std::time::Instant::now();
    // (an interrupted run is saved at once, with the encodings)
    if let (Some(ds), false) = (
        src.all_static(),
        report.stop == rom::nn::StopReason::Interrupted,
    ) {
        model.meta.anchor_equilibria = equilibrium_anchors(built, ds, &mut model)?;
    }
    let anchor_time_s = t_anchors.elapsed().as_secs_f64();
    let anchor_equilibria = model.meta.anchor_equilibria;
    let path = model.save(
        dir,
        &[
            ("train_loss", &report.train_loss),
            ("val_loss", &report.val_loss),
        ],
    )?;
    Ok(TrainSummary {
        warnings,
        datasets: src.listing(),
        path,
        rows,
        features,
        report,
        encoder_sizes,
        rest: rest.iter().copied().collect(),
        rest_residual,
        zero_anchor_rows: anchor_rows,
        projection_residual: worst,
        anchor_equilibria,
        anchor_time_s,
    })
}

/// The names of the snapshot weightings (`gvsrom train --sample-weighting`).
pub const SAMPLE_WEIGHTINGS: [&str; 2] = ["uniform", "relative"];

/// The snapshot weighting named `name` ([`SAMPLE_WEIGHTINGS`]); `floor` (a fraction of the largest
/// snapshot norm, in (0, 1]; default [`SampleWeighting::DEFAULT_FLOOR`]) bounds the relative
/// weighting's weights. The name is checked first; a floor given with the uniform weighting, which
/// would ignore it, is refused.
pub fn sample_weighting(name: &str, floor: Option<f64>) -> Result<SampleWeighting, ScenarioError> {
    let relative = match name {
        "uniform" => false,
        "relative" => true,
        _ => {
            return Err(invalid(
                "--sample-weighting",
                format!("`{name}` (accepted: {})", SAMPLE_WEIGHTINGS.join(", ")),
            ))
        }
    };
    if floor.is_some() && !relative {
        return Err(invalid(
            "--relative-floor",
            "applies to the relative weighting only (accepted: with --sample-weighting relative, or not given)",
        ));
    }
    let floor = floor.unwrap_or(SampleWeighting::DEFAULT_FLOOR);
    if !(floor > 0.0 && floor <= 1.0) {
        return Err(invalid(
            "--relative-floor",
            format!("{floor} (accepted: a fraction of the largest snapshot norm in (0, 1])"),
        ));
    }
    Ok(match relative {
        true => SampleWeighting::Relative { floor },
        false => SampleWeighting::Uniform,
    })
}

/// A scaled decoder whose first coordinate keeps one sign over the training encodings (`z₁` in
/// `[lo, hi]`, not containing 0) scales every snapshot by a factor that never vanishes: the apex
/// `z₁ = 0` lies outside the data and the decoder is a plain one in effect (IV-B: 1 of 3 seeds, at
/// 2.6× the RMSE). A warning for the user, `None` otherwise.
fn scaled_basin_warning(form: DecoderForm, [lo, hi]: [f64; 2]) -> Option<String> {
    (form == DecoderForm::Scaled && (lo > 0.0 || hi < 0.0)).then(|| {
        format!(
            "the scaled decoder's z₁ keeps one sign over the training data ([{lo:.3}, {hi:.3}]): z₁ = 0, the straight rod, lies outside them and the scaling does not follow the load; another --seed usually finds the basin where z₁ follows the load's sign (compare the validation RMSE)"
        )
    })
}

/// The decoder form named `name` (`gvsrom train --decoder`: [`DecoderForm::NAMES`]).
pub fn decoder_form(name: &str) -> Result<DecoderForm, ScenarioError> {
    DecoderForm::from_name(name).ok_or_else(|| {
        invalid(
            "--decoder",
            format!("`{name}` (accepted: {})", DecoderForm::NAMES.join(", ")),
        )
    })
}

/// Copies of the zero-strain snapshot added for `trajectory_rows` training rows of trajectories
/// (the rows of the datasets that are trajectories): trajectories start from the straight rod at
/// rest, as every simulation from rest does, so 1 % of their rows and at least 10 make it a point of
/// the learned manifold and not just one sample among thousands; none without trajectory rows, since
/// the manifold of equilibria need not contain the straight rod (under gravity no equilibrium is
/// straight, and a 1-D decoder forced through it bends away from the data).
pub fn zero_anchor_rows(trajectory_rows: usize) -> usize {
    match trajectory_rows {
        0 => 0,
        n => (n / 100).max(10),
    }
}

/// A training error named by the command-line option it comes from.
pub(super) fn train_error(e: &rom::nn::NnError) -> ScenarioError {
    use rom::nn::NnError;
    let option = match e {
        NnError::InvalidLatent { .. } => "--latent".to_string(),
        NnError::InvalidHiddenLayers { .. } => "--hidden-layers".to_string(),
        NnError::InvalidOption { field, .. } if field.starts_with("metric") => {
            "--kinetic-weight".to_string()
        }
        NnError::InvalidOption { field, .. } => format!("--{}", field.replace('_', "-")),
        NnError::TooFewTrainingRows { .. } => "--validation-fraction".to_string(),
        NnError::EmptyData | NnError::NonFiniteData { .. } | NnError::TooFewRows { .. } => {
            "DATASET".to_string()
        }
        NnError::Diverged { .. } => "--learning-rate".to_string(),
        _ => "train".to_string(),
    };
    match e {
        // named once, by the option: "invalid `--lambda`: NaN: expected …"
        NnError::InvalidOption {
            value, expected, ..
        } => invalid(
            &option,
            format!("{}: expected {expected}", gvs::error::fmt_value(*value)),
        ),
        _ => invalid(&option, e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scaled_decoder_whose_z1_keeps_one_sign_is_warned_about() {
        let w = |form, r| scaled_basin_warning(form, r);
        assert!(
            w(DecoderForm::Scaled, [-5.7, -2.0]).is_some_and(|m| m.contains("[-5.700, -2.000]"))
        );
        assert!(w(DecoderForm::Scaled, [0.5, 3.0]).is_some());
        assert!(w(DecoderForm::Scaled, [-4.3, 4.2]).is_none());
        assert!(w(DecoderForm::Scaled, [0.0, 4.2]).is_none());
        assert!(w(DecoderForm::Plain, [-5.7, -2.0]).is_none());
    }

    #[test]
    fn sample_weightings_are_named_and_a_bad_name_or_floor_is_refused_by_its_option() {
        assert_eq!(
            sample_weighting("uniform", None).unwrap(),
            SampleWeighting::Uniform
        );
        assert_eq!(
            sample_weighting("relative", Some(0.25)).unwrap(),
            SampleWeighting::Relative { floor: 0.25 }
        );
        assert_eq!(
            sample_weighting("relative", None).unwrap(),
            SampleWeighting::Relative {
                floor: SampleWeighting::DEFAULT_FLOOR
            }
        );
        for (name, floor, field) in [
            ("relative", Some(0.0), "--relative-floor"),
            ("relative", Some(1.5), "--relative-floor"),
            ("relative", Some(f64::NAN), "--relative-floor"),
            // a floor without the weighting it belongs to would be ignored
            ("uniform", Some(0.1), "--relative-floor"),
            ("uniform", Some(f64::NAN), "--relative-floor"),
            ("per-row", None, "--sample-weighting"),
            ("per-row", Some(5.0), "--sample-weighting"),
        ] {
            let e = sample_weighting(name, floor).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("invalid `{field}`")),
                "{name} {floor:?}: {e}"
            );
            assert!(e.contains("accepted"), "{e}");
        }
    }
}
