//! Figures of a reduced model (`gvsrom pod` or `gvsrom train` directory): the POD spectrum
//! (`pod_spectrum`: singular values and the energy the first k modes leave out, log scales), the
//! autoencoder's training curves (`training_curves`: training and validation loss per epoch), and
//! the training snapshots' reduced coordinates (`latent`: against the first dataset input for one
//! coordinate, a 2-D or 3-D scatter coloured by it for more, inside the recorded `latent_range`).

use super::{input_error, FiguresError, Sink};
use crate::plot::{palette, Figure, LineChart, Scatter2, Scatter3, Series, SeriesStyle};
use crate::reduced_model::{ModelWeights, ReducedModel};
use std::path::Path;

/// All figures of the model in `dir`.
pub(crate) fn figures(dir: &Path, sink: &mut Sink) -> Result<(), FiguresError> {
    let model = ReducedModel::load(dir).map_err(|e| input_error(dir, e.to_string()))?;
    sink.origin = model.origin();
    let name = dir.file_name().map_or_else(
        || dir.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let caption = format!(
        "{} {name}, r = {} ({})",
        model.meta.kind, model.meta.latent, model.meta.layout.scenario
    );
    match &model.weights {
        ModelWeights::Pod {
            singular_values, ..
        } => pod_spectrum(dir, &model, singular_values, &caption, sink)?,
        ModelWeights::Autoencoder(_) => training_curves(&model, &caption, sink)?,
    }
    latent(&model, &caption, sink)
}

/// A 1-D curve `name` of the model's directory, if the model has it: read through the hash check of
/// the files the model was loaded with, not a second time unchecked.
pub fn curve(model: &ReducedModel, name: &str) -> Result<Option<Vec<f64>>, FiguresError> {
    let Some(dir) = &model.dir else {
        return Ok(None);
    };
    if !dir.files.lists(name) {
        return Ok(None);
    }
    let path = dir.path.join(name);
    let bytes = (dir.files.read(name)).map_err(|e| input_error(&path, e.problem.to_string()))?;
    crate::npy::parse_vector(&bytes, &path.display().to_string())
        .map(Some)
        .map_err(|e| input_error(&path, e.message))
}

/// `pod_spectrum`: σ_k/σ_1 and `1 − E_k`, the snapshot energy the first k modes leave out (from
/// `captured_energy.npy`, else `E_k = Σ_{i≤k} σ_i² / Σ σ_i²`), the kept modes marked.
fn pod_spectrum(
    dir: &Path,
    model: &ReducedModel,
    sigma: &[f64],
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let sigma = match curve(model, "singular_values.npy")? {
        Some(s) if !s.is_empty() => s,
        _ => sigma.to_vec(),
    };
    if sigma.first().is_none_or(|&s| s.is_nan() || s <= 0.0) {
        return Err(input_error(
            dir,
            "the POD model holds no positive singular value to plot",
        ));
    }
    let energy = match curve(model, "captured_energy.npy")? {
        Some(e) if e.len() == sigma.len() => e,
        _ => {
            let total: f64 = sigma.iter().map(|s| s * s).sum();
            sigma
                .iter()
                .scan(0.0, |acc, s| {
                    *acc += s * s;
                    Some(*acc / total)
                })
                .collect()
        }
    };
    let k: Vec<f64> = (1..=sigma.len()).map(|i| i as f64).collect();
    let kept = model.meta.latent.min(sigma.len());
    let rel: Vec<f64> = sigma.iter().map(|s| s / sigma[0]).collect();
    let left: Vec<f64> = energy.iter().map(|e| (1.0 - e).max(0.0)).collect();
    let panel = |title: &str, y_label: &str, y: Vec<f64>| {
        Figure::Line(LineChart {
            title: title.into(),
            x_label: "mode k".into(),
            y_label: y_label.into(),
            series: vec![
                Series::new("all modes", k.clone(), y.clone(), SeriesStyle::LineMarkers)
                    .with_color(palette::EXTRA[6]),
                Series::new(
                    format!("kept ({kept})"),
                    k[..kept].to_vec(),
                    y[..kept].to_vec(),
                    SeriesStyle::Markers,
                )
                .with_color(palette::POD),
            ],
            log_y: true,
            equal_aspect: false,
        })
    };
    let mut panels = vec![panel("Singular values", "σ_k / σ_1", rel)];
    if left.iter().any(|&e| e > 0.0) {
        panels.push(panel(
            match model.meta.pod_norm.unwrap_or_default() {
                crate::reduced_model::PodNorm::Plain => "Energy left out by the first k modes",
                crate::reduced_model::PodNorm::Energy => {
                    "Strain energy left out by the first k modes (energy norm)"
                }
            },
            "1 − E_k",
            left,
        ));
    } else {
        // a log axis has nothing to draw: one snapshot, or snapshots of rank 1
        sink.note("pod_spectrum: the first mode holds all the snapshot energy (one snapshot, or snapshots along one direction): the panel of the energy left out, 0 for every k, is left out");
    }
    let cols = panels.len();
    let fig = Figure::Grid {
        title: format!("POD spectrum — {caption}"),
        cols,
        panels,
    };
    sink.figure("pod_spectrum", &fig, (700 * cols as u32, 600))
}

/// `training_curves`: training and validation loss per epoch (log scale), the best epoch marked.
fn training_curves(
    model: &ReducedModel,
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let train = curve(model, "train_loss.npy")?.unwrap_or_default();
    let val = curve(model, "val_loss.npy")?.unwrap_or_default();
    if train.is_empty() && val.is_empty() {
        sink.note("training_curves: the model records no training curve");
        return Ok(());
    }
    let epochs = |v: &[f64]| (1..=v.len()).map(|i| i as f64).collect::<Vec<_>>();
    let mut series = vec![];
    if !train.is_empty() {
        series.push(
            Series::new("training", epochs(&train), train.clone(), SeriesStyle::Line)
                .with_color(palette::POD_ALT),
        );
    }
    if !val.is_empty() {
        series.push(
            Series::new("validation", epochs(&val), val.clone(), SeriesStyle::Line)
                .with_color(palette::AE),
        );
    }
    if let Some(t) = &model.meta.training {
        let best = if val.is_empty() { &train } else { &val };
        if let Some(&y) = t.best_epoch.checked_sub(1).and_then(|i| best.get(i)) {
            series.push(
                Series::new(
                    format!("best epoch ({})", t.best_epoch),
                    vec![t.best_epoch as f64],
                    vec![y],
                    SeriesStyle::Markers,
                )
                .with_color(palette::POD),
            );
        }
    }
    let loss = model
        .meta
        .training
        .as_ref()
        .and_then(|t| t.loss.clone())
        .unwrap_or_else(|| "loss".into());
    let fig = Figure::Line(LineChart {
        title: format!("Training curves — {caption}"),
        x_label: "epoch".into(),
        y_label: format!("{loss} loss"),
        series,
        log_y: true,
        equal_aspect: false,
    });
    sink.figure("training_curves", &fig, (1000, 600))
}

/// `latent`: the training snapshots' reduced coordinates (the model's anchors), with the recorded
/// `latent_range`; without anchors, the range alone.
fn latent(model: &ReducedModel, caption: &str, sink: &mut Sink) -> Result<(), FiguresError> {
    let r = model.meta.latent;
    let range = &model.meta.latent_range;
    let title = format!("Reduced coordinates of the training samples — {caption}");
    let anchors = model.anchors.as_ref().filter(|a| a.n > 0 && r > 0);
    let Some(a) = anchors else {
        if range.is_empty() {
            sink.note("latent: the model stores neither encodings nor latent_range");
            return Ok(());
        }
        // the range per coordinate, as a vertical bar from min to max
        let series = range
            .iter()
            .enumerate()
            .map(|(i, [lo, hi])| {
                Series::new(
                    if i == 0 { "latent_range" } else { "" },
                    vec![(i + 1) as f64; 2],
                    vec![*lo, *hi],
                    SeriesStyle::LineMarkers,
                )
                .with_color(palette::POD_ALT)
            })
            .collect();
        let fig = Figure::Line(LineChart {
            title: format!("Range of the reduced coordinates — {caption}"),
            x_label: "coordinate".into(),
            y_label: "q_r".into(),
            series,
            log_y: false,
            equal_aspect: false,
        });
        return sink.figure("latent", &fig, (900, 600));
    };
    let z = |k: usize, i: usize| a.latent[k * r + i];
    let k_in = model.meta.anchor_parameters.len();
    let (c_label, color): (String, Vec<f64>) = if k_in > 0 {
        (
            model.meta.anchor_parameters[0].clone(),
            (0..a.n).map(|k| a.inputs[k * k_in]).collect(),
        )
    } else {
        ("sample".into(), (0..a.n).map(|k| k as f64).collect())
    };
    let fig = match r {
        1 => {
            let x = color.clone();
            let what = if model.meta.anchor_equilibria >= a.n {
                "anchors (equilibria)"
            } else {
                "anchors"
            };
            let mut series = vec![Series::new(
                what,
                x.clone(),
                (0..a.n).map(|k| z(k, 0)).collect(),
                SeriesStyle::Markers,
            )
            .with_color(palette::POD_ALT)];
            if let (Some([lo, hi]), Some((x0, x1))) = (range.first(), crate::plot::extent(x)) {
                for (label, v) in [("latent_range", *lo), ("", *hi)] {
                    series.push(
                        Series::new(label, vec![x0, x1], vec![v, v], SeriesStyle::Dashed)
                            .with_color(palette::EXTRA[6]),
                    );
                }
            }
            Figure::Line(LineChart {
                title,
                x_label: c_label,
                y_label: "q_r,1".into(),
                series,
                log_y: false,
                equal_aspect: false,
            })
        }
        2 => Figure::Scatter2(Scatter2 {
            title,
            x_label: "q_r,1".into(),
            y_label: "q_r,2".into(),
            x: (0..a.n).map(|k| z(k, 0)).collect(),
            y: (0..a.n).map(|k| z(k, 1)).collect(),
            color: Some(color),
            color_label: c_label,
        }),
        _ => Figure::Scatter3(Scatter3 {
            title,
            labels: ["q_r,1".into(), "q_r,2".into(), "q_r,3".into()],
            points: (0..a.n).map(|k| [z(k, 0), z(k, 1), z(k, 2)]).collect(),
            color: Some(color),
            color_label: c_label,
        }),
    };
    if r > 3 {
        sink.note(format!(
            "latent: the first 3 of {r} reduced coordinates are drawn"
        ));
    }
    sink.figure("latent", &fig, (1000, 650))
}
