//! `gvsrom pod`, `gvsrom train` and `gvsrom reconstruct`.

use super::*;
use gvs::error::fmt_sci;

#[derive(Debug, Args)]
pub struct PodArgs {
    /// One or more dataset directories (from `gvsrom dataset`); several must share one scenario
    /// (points, components, sampled inputs and physics), and their snapshots are combined in order.
    #[arg(value_name = "DATASET", required = true)]
    pub datasets: Vec<PathBuf>,
    /// Number of POD modes kept (reduced coordinates).
    #[arg(value_parser = super::whole::<usize>, long, value_name = "K")]
    pub modes: usize,
    /// The norm the modes are optimal in: `plain` (every strain value weighs 1: the paper's POD) or
    /// `energy` (each value weighted by the section stiffness, as `train --loss energy`: stiff
    /// elongation and shear weigh what they cost in elastic force).
    #[arg(long, value_enum, default_value_t)]
    pub norm: reduce::PodNorm,
    /// The new model directory.
    #[arg(long, value_name = "MODEL")]
    pub out: PathBuf,
    /// Replace MODEL if it is an earlier gvsrom output.
    #[arg(long)]
    pub force: bool,
}

#[derive(Debug, Args)]
pub struct ReconstructArgs {
    /// A reduced model directory (from `gvsrom pod` or `gvsrom train`).
    pub model: PathBuf,
    /// One or more dataset directories of the model's layout (from `gvsrom dataset`), each
    /// judged on its own (e.g. the training data and data the model did not see).
    #[arg(value_name = "DATASET", required = true)]
    pub datasets: Vec<PathBuf>,
}

#[derive(Debug, Args)]
pub struct TrainArgs {
    /// One or more dataset directories (from `gvsrom dataset`); several must share one scenario
    /// (points, components, sampled inputs and physics), and their snapshots are combined in order
    /// (e.g. a babbling trajectory and static equilibria of the same input range).
    #[arg(value_name = "DATASET", required = true)]
    pub datasets: Vec<PathBuf>,
    /// Start from this autoencoder model's weights and scaling instead of random weights: more
    /// epochs for a model that was still improving or was interrupted, or a fine-tuning on new
    /// snapshots of its scenario. Its latent size, hidden layers, decoder and loss are kept (give
    /// none of them, or the model's); the new model records its start in `provenance.model`.
    #[arg(long, value_name = "MODEL")]
    pub init: Option<PathBuf>,
    /// Latent size r (reduced coordinates) [default: 1; with `--init`, the model's].
    #[arg(value_parser = super::whole::<usize>, long, value_name = "R")]
    pub latent: Option<usize>,
    /// Hidden layers of the whole autoencoder (odd: 1, 3, 5, 7…, at most 63); layer sizes halve from the snapshot
    /// size towards the latent size (paper Section III) [default: 7; with `--init`, the model's].
    #[arg(value_parser = super::whole::<usize>, long, value_name = "N")]
    pub hidden_layers: Option<usize>,
    /// Maximum Adam epochs.
    #[arg(value_parser = super::whole::<usize>, long, default_value_t = reduce::TrainRequest::DEFAULT.epochs)]
    pub epochs: usize,
    /// Mini-batch size.
    #[arg(value_parser = super::whole::<usize>, long, default_value_t = reduce::TrainRequest::DEFAULT.batch_size)]
    pub batch_size: usize,
    /// Adam learning rate, in (0, 1].
    #[arg(long, default_value_t = reduce::TrainRequest::DEFAULT.learning_rate)]
    pub learning_rate: f64,
    /// L2 weight regularization λ of eq. (15), in [0, 1] (paper: 1e-4).
    #[arg(long, default_value_t = reduce::TrainRequest::DEFAULT.lambda)]
    pub lambda: f64,
    /// Fraction of the snapshots held out for validation and early stopping [default: 0.1; with
    /// `--init`, the model's].
    #[arg(long, value_name = "F")]
    pub validation_fraction: Option<f64>,
    /// Epochs without a better validation loss before stopping (0: never stop early).
    #[arg(value_parser = super::whole::<usize>, long, default_value_t = reduce::TrainRequest::DEFAULT.patience)]
    pub patience: usize,
    /// Learning-rate reductions (× 0.3 each, from the best weights so far) at validation plateaus of
    /// `--patience` epochs before Adam stops.
    #[arg(value_parser = super::whole::<usize>, long, default_value_t = reduce::TrainRequest::DEFAULT.lr_reductions)]
    pub lr_reductions: usize,
    /// An exponential decay of the Adam rate to this factor of it over `--epochs` (epoch e of E at
    /// rate × F^(e/E)), in (0, 1]; with `--patience 0 --lbfgs-iterations 0` it is the JAX reference
    /// scripts' schedule. Unset: a constant rate between plateaus.
    #[arg(long, value_name = "F")]
    pub lr_decay: Option<f64>,
    /// Iterations of the full-batch L-BFGS phase that follows Adam from its best weights (0: none).
    #[arg(value_parser = super::whole::<usize>, long, default_value_t = reduce::TrainRequest::DEFAULT.lbfgs_iterations)]
    pub lbfgs_iterations: usize,
    /// Seed of the initialization, the split and the shuffles (same seed, same model) [default: 0;
    /// with `--init`, the model's, so that a continuation holds out the same rows].
    #[arg(value_parser = super::whole::<u64>, long, value_name = "SEED")]
    pub seed: Option<u64>,
    /// How each strain value's error weighs in the loss: `standardized` (each point and component
    /// by its own spread), `physical` (plain squared error, the RMSE of Table I) or `energy`
    /// (weighted by the section stiffness: the strain-energy norm, which the reduced model's
    /// elastic force feels) [default: energy; with `--init`, the model's].
    #[arg(long, value_enum)]
    pub loss: Option<reduce::Loss>,
    /// How each snapshot's error weighs: `uniform` (eq. 15 as the paper writes it) or `relative`
    /// (each snapshot by the inverse of its own squared norm, floored at `--relative-floor` of the
    /// largest: the relative error, so that small loads are fitted as closely as large ones).
    #[arg(long, default_value = "uniform", value_parser = reduce::SAMPLE_WEIGHTINGS)]
    pub sample_weighting: String,
    /// The floor of `--sample-weighting relative`, as a fraction of the largest snapshot norm, in
    /// (0, 1] [default: 0.1].
    #[arg(long)]
    pub relative_floor: Option<f64>,
    /// The decoder's form: `plain` (the paper's, x̂ = D(z)) or `scaled` (x̂ = z₁ D(z): every code with
    /// z₁ = 0 decodes to the straight rod, for snapshot families that shrink to rest as their load
    /// vanishes, such as a load of varying magnitude and position) [default: plain; with `--init`,
    /// the model's].
    #[arg(long, value_parser = rom::nn::DecoderForm::NAMES)]
    pub decoder: Option<String>,
    /// Weight β of the strain-rate term (beyond the paper): the autoencoder's tangent map must carry
    /// each trajectory sample's strain rate, `‖J(x) ẋ − ẋ‖²` added to the loss with weight β (rates
    /// by central differences of the trajectory's samples; equilibria are at rest). It gives the
    /// decoder the tangent space a dynamic model moves in. 0: eq. (15) alone (the paper's); with
    /// 0.1–1 the IV-C2 AE-7 is about half as far off (`reproduce iv-c2` chooses among 0.1, 0.3 and 1
    /// on validation inputs; docs/assumptions.md).
    #[arg(long, default_value_t = reduce::TrainRequest::DEFAULT.rate_weight)]
    pub rate_weight: f64,
    /// Weight κ of the kinetic-energy norm (beyond the paper): the reconstruction and rate errors
    /// are also measured as coefficient errors weighed by the mass matrix M(q) of each snapshot's
    /// own configuration (the norm the reduced Lagrangian model feels them in), κ relative to the
    /// energy norm (scaled so that the rates weigh alike in both). Needs `--rate-weight` > 0.
    /// 0: none.
    #[arg(long, default_value_t = 0.0)]
    pub kinetic_weight: f64,
    /// The new model directory.
    #[arg(long, value_name = "MODEL")]
    pub out: PathBuf,
    /// Replace MODEL if it is an earlier gvsrom output.
    #[arg(long)]
    pub force: bool,
}

pub(super) fn pod_cmd(args: &PodArgs, out: &mut impl Write) -> Result<()> {
    let s = reduce::pod(&args.datasets, args.modes, args.norm, &args.out, args.force)?;
    for w in &s.warnings {
        gvsrom::progress::stderr_line(format_args!("warning: {w}"));
    }
    datasets_line(out, &s.datasets)?;
    writeln!(
        out,
        "snapshots  {} × {} (failed samples skipped), numerical rank {}",
        s.rows, s.features, s.numerical_rank
    )?;
    let shown: Vec<String> = s
        .singular_values
        .iter()
        .take(10)
        .map(|v| fmt_sci(*v, 4))
        .collect();
    writeln!(
        out,
        "σ          {}{}",
        shown.join(" "),
        if s.singular_values.len() > 10 {
            " …"
        } else {
            ""
        }
    )?;
    writeln!(
        out,
        "modes      {} capture {:.8} of the snapshot energy{}",
        s.modes,
        s.captured_energy,
        match s.norm {
            reduce::PodNorm::Plain => "",
            reduce::PodNorm::Energy => " in the strain-energy norm",
        }
    )?;
    anchors_line(out, s.anchor_equilibria, s.rows, s.anchor_time_s)?;
    writeln!(out, "model      {}", s.path.display())?;
    Ok(())
}

/// With several datasets, each one's usable rows (one dataset needs no line).
fn datasets_line(out: &mut impl Write, datasets: &[(PathBuf, usize)]) -> Result<()> {
    if datasets.len() > 1 {
        let each: Vec<String> = datasets
            .iter()
            .map(|(p, n)| format!("{} ({n} rows)", p.display()))
            .collect();
        writeln!(out, "datasets   {}", each.join(" + "))?;
    }
    Ok(())
}

pub(super) fn train_cmd(args: &TrainArgs, out: &mut impl Write) -> Result<()> {
    let init = args.init.as_deref().map(reduce::start_model).transpose()?;
    let request = reduce::TrainRequest {
        choices: reduce::TrainChoices {
            latent: args.latent,
            hidden_layers: args.hidden_layers,
            decoder: args
                .decoder
                .as_deref()
                .map(reduce::decoder_form)
                .transpose()?,
            loss: args.loss,
            seed: args.seed,
            validation_fraction: args.validation_fraction,
        },
        lambda: args.lambda,
        epochs: args.epochs,
        batch_size: args.batch_size,
        learning_rate: args.learning_rate,
        patience: args.patience,
        lr_reductions: args.lr_reductions,
        lr_decay: args.lr_decay,
        lbfgs_iterations: args.lbfgs_iterations,
        sample_weighting: reduce::sample_weighting(&args.sample_weighting, args.relative_floor)?,
        rate_weight: args.rate_weight,
    };
    let (options, loss) = request.resolve(init.as_ref());
    let signal = interrupt_flag();
    // the L-BFGS fine-tuning runs past --epochs: the bar counts both phases to their limits, so
    // that its ETA is the time to those limits (an upper bound when a phase stops early) rather
    // than zero all through the fine-tuning
    let limit = args.epochs + options.fine_tune.lbfgs_iterations();
    let bar = gvsrom::progress::bar(limit as u64, "epochs + L-BFGS iterations");
    let mut progress = |epoch: usize, train: f64, val: Option<f64>| {
        if epoch as u64 > bar.length().unwrap_or(0) {
            bar.set_length(epoch as u64);
        }
        // the message first: each call may draw, and a line must carry this epoch's loss
        bar.set_message(match val {
            Some(v) => format!("loss {train:.3e} / validation {v:.3e}"),
            None => format!("loss {train:.3e}"),
        });
        bar.set_position(epoch as u64);
        match signal.load(Ordering::SeqCst) {
            0 => ControlFlow::Continue(()),
            _ => ControlFlow::Break(()),
        }
    };
    let s = reduce::train(
        &args.datasets,
        init.as_ref(),
        &options,
        loss,
        args.kinetic_weight,
        &args.out,
        args.force,
        &mut progress,
    )?;
    bar.finish_and_clear();
    for w in &s.warnings {
        gvsrom::progress::stderr_line(format_args!("warning: {w}"));
    }
    let r = &s.report;
    datasets_line(out, &s.datasets)?;
    let zero_rows = match s.zero_anchor_rows {
        0 => String::new(),
        k => format!(" + {k} zero-strain rows"),
    };
    writeln!(
        out,
        "snapshots  {} × {}{zero_rows} ({} training, {} validation)",
        s.rows, s.features, r.n_train, r.n_val
    )?;
    writeln!(
        out,
        "network    {} (encoder; the decoder mirrors it), tanh hidden layers, linear output",
        s.encoder_sizes
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join("-")
    )?;
    writeln!(
        out,
        "trained    {} Adam epochs + {} fine-tuning iterations in {:.1} s (best at {} of {}; the last phase ended {})",
        r.epochs_run - r.fine_tune_epochs_run,
        r.fine_tune_epochs_run,
        r.wall_time.as_secs_f64(),
        r.best_epoch,
        r.epochs_run,
        r.stop.describe(r.n_val > 0)
    )?;
    writeln!(
        out,
        "RMSE       {} training{}",
        fmt_sci(r.final_train_rmse, 4),
        r.final_val_rmse
            .map(|v| format!(", {} validation", fmt_sci(v, 4)))
            .unwrap_or_default()
    )?;
    writeln!(
        out,
        "rest       q_r = {} ({}; it decodes to ‖ξ − ξ*‖ = {:.3e}); projection residual ≤ {:.1e}",
        fmt_vec(&s.rest, 6),
        match s.zero_anchor_rows {
            0 => "the encoding of the sample closest to the straight rod".to_string(),
            k => format!("the encoding of the straight rod, trained in as {k} zero-strain rows"),
        },
        s.rest_residual,
        s.projection_residual
    )?;
    anchors_line(out, s.anchor_equilibria, s.rows, s.anchor_time_s)?;
    writeln!(out, "model      {}", s.path.display())?;
    if signal.load(Ordering::SeqCst) != 0 {
        return Err(Interrupted {
            signal: signal.load(Ordering::SeqCst) as i32,
            message: format!(
                "training interrupted; the best weights so far were saved to `{}`",
                s.path.display()
            ),
        }
        .into());
    }
    Ok(())
}

pub(super) fn reconstruct_cmd(args: &ReconstructArgs, out: &mut impl Write) -> Result<()> {
    let model = gvsrom::reduced_model::ReducedModel::load(&args.model)?;
    writeln!(
        out,
        "model      {} ({}, r = {})",
        args.model.display(),
        model.meta.kind,
        model.meta.latent
    )?;
    // (squared error, entries) over every dataset, for the combined RMSE
    let (mut err2, mut entries) = (0.0, 0usize);
    for path in &args.datasets {
        let ds = gvsrom::dataset::Dataset::load(path)?;
        let r = reduce::reconstruction(&model, &ds).map_err(|e| e.naming(path))?;
        reconstruction_lines(out, path, &r, model.features())?;
        let n = r.rows * model.features();
        (err2, entries) = (err2 + r.rmse * r.rmse * n as f64, entries + n);
    }
    if args.datasets.len() > 1 {
        writeln!(
            out,
            "all        RMSE {} over the {} datasets' {entries} values",
            fmt_sci((err2 / entries as f64).sqrt(), 4),
            args.datasets.len()
        )?;
    }
    Ok(())
}

fn reconstruction_lines(
    out: &mut impl Write,
    path: &std::path::Path,
    r: &reduce::Reconstruction,
    features: usize,
) -> Result<()> {
    writeln!(
        out,
        "dataset    {} ({} solved snapshots × {features} values)",
        path.display(),
        r.rows,
    )?;
    writeln!(
        out,
        "RMSE       {} (every entry of every snapshot, Table I's measure)",
        fmt_sci(r.rmse, 4)
    )?;
    if r.relative.is_finite() {
        writeln!(
            out,
            "relative   {:.4} % (‖X̂ − X‖ / ‖X‖)",
            100.0 * r.relative
        )?;
    } else {
        writeln!(
            out,
            "relative   none: every snapshot is zero (‖X‖ = 0) and the reconstruction is not; the RMSE above is its absolute error"
        )?;
    }
    if let Some((row, e, norm)) = r.worst {
        writeln!(
            out,
            "worst      row {row}: {:.4} % of its norm ‖x‖ = {} (the largest ‖x‖ is {})",
            100.0 * e,
            fmt_sci(norm, 4),
            fmt_sci(r.largest_norm, 4)
        )?;
    }
    writeln!(
        out,
        "outside    {} of {} snapshots lie outside the training data (a code far outside the training encodings, or a norm over twice the largest training snapshot's){}",
        r.outside,
        r.rows,
        if r.outside > 0 {
            " (the model extrapolates there)"
        } else {
            ""
        }
    )?;
    match (r.unseen_inputs, &r.inputs_note) {
        (Some(n), _) => writeln!(
            out,
            "inputs     {n} of {} snapshots have inputs the model was not trained on (outside a training range, far from the training inputs together, or off a value training held){}",
            r.rows,
            if n > 0 { ": its errors there are an extrapolation's" } else { "" }
        )?,
        (None, Some(why)) => writeln!(out, "inputs     not compared with the training inputs: {why}")?,
        (None, None) => {}
    }
    if let Some(what) = &r.other_physics {
        writeln!(
            out,
            "physics    differs from the model's training: {what}; every snapshot is an extrapolation"
        )?;
    }
    Ok(())
}
