//! What IV-A and IV-B share besides the tables: the latent spaces of the training data (Figs. 3, 5)
//! and the intrinsic-dimension estimates reported in each summary.

use super::intrinsic;
use super::report::{Cell, Table};
use super::step::Step;
use super::tasks::ModelInfo;
use crate::dataset::Dataset;
use crate::plot::{Figure, Scatter2, Scatter3};
use serde_json::json;
use std::path::Path;

/// The latent figure, the intrinsic-dimension table and its values.
pub struct Latent {
    pub figure: Figure,
    pub table: Table,
    pub values: serde_json::Value,
}

/// The encodings of every solved sample of `dataset` by the autoencoder at `model`, and the
/// dataset input `color_input` of each.
fn encodings(
    dataset: &Dataset,
    data: &Path,
    model: &Path,
    color_input: usize,
) -> anyhow::Result<(Vec<Vec<f64>>, Vec<f64>)> {
    let k = dataset.meta.parameters.len();
    let c = dataset
        .ok_rows()
        .iter()
        .map(|&i| {
            dataset
                .inputs
                .get(i * k + color_input)
                .copied()
                .unwrap_or(f64::NAN)
        })
        .collect();
    Ok((super::latent::encodings(data, model)?, c))
}

/// The encodings of the training samples by `model` in the 2-D plane of its first two coordinates,
/// once coloured by each of the dataset inputs `inputs` (`(index, label)`), side by side.
pub fn latent_plane(
    data: &Path,
    model: &Step<ModelInfo>,
    title: &str,
    inputs: &[(usize, &str)],
) -> anyhow::Result<Figure> {
    let ds = Dataset::load(data)?;
    let mut panels = vec![];
    for &(k, label) in inputs {
        let (z, c) = encodings(&ds, data, &model.path, k)?;
        panels.push(Figure::Scatter2(Scatter2 {
            title: format!("coloured by {label}"),
            x_label: "q₁".into(),
            y_label: "q₂".into(),
            x: z.iter().map(|z| z[0]).collect(),
            y: z.iter().map(|z| z[1]).collect(),
            color: Some(c),
            color_label: label.into(),
        }));
    }
    Ok(Figure::Grid {
        title: title.into(),
        cols: inputs.len(),
        panels,
    })
}

/// Fig. 3 / Fig. 5: the training samples' encodings by `vis[0]` (r = 2) and `vis[1]` (r = 3),
/// coloured by dataset input `color_input`; the intrinsic dimension by the elbow of `depth_row`'s
/// RMSE over r = 1, 2, 3 and by the correlation dimension of the snapshots and encodings.
pub fn latent_and_dimension(
    data: &Path,
    vis: &[&Step<ModelInfo>; 2],
    depth_row: &[Step<ModelInfo>],
    color_input: usize,
    color_label: &str,
) -> anyhow::Result<Latent> {
    let ds = Dataset::load(data)?;
    let (z2, c2) = encodings(&ds, data, &vis[0].path, color_input)?;
    let (z3, c3) = encodings(&ds, data, &vis[1].path, color_input)?;
    let figure = Figure::Grid {
        title: "latent coordinates of the training samples".into(),
        cols: 2,
        panels: vec![
            Figure::Scatter2(Scatter2 {
                title: "r = 2".into(),
                x_label: "q₁".into(),
                y_label: "q₂".into(),
                x: z2.iter().map(|z| z[0]).collect(),
                y: z2.iter().map(|z| z[1]).collect(),
                color: Some(c2),
                color_label: color_label.into(),
            }),
            Figure::Scatter3(Scatter3 {
                title: "r = 3".into(),
                labels: ["q₁".into(), "q₂".into(), "q₃".into()],
                points: z3.iter().map(|z| [z[0], z[1], z[2]]).collect(),
                color: Some(c3),
                color_label: color_label.into(),
            }),
        ],
    };
    let rows: Vec<f64> = ds
        .ok_rows()
        .iter()
        .flat_map(|&i| ds.strain_row(i).to_vec())
        .collect();
    let corr = intrinsic::correlation_dimension(&rows, ds.row_len(), 1500).unwrap_or(f64::NAN);
    let rmse: Vec<f64> = depth_row.iter().map(|s| s.value.rmse_full).collect();
    let elbow = intrinsic::elbow(&rmse);
    let z3_rows: Vec<f64> = z3.iter().flatten().copied().collect();
    let corr_latent = intrinsic::correlation_dimension(&z3_rows, 3, 1500).unwrap_or(f64::NAN);
    let table = Table {
        id: "intrinsic-dimension".into(),
        title: "Intrinsic dimension".into(),
        columns: ["estimator", "estimate"].map(String::from).to_vec(),
        rows: vec![
            vec![Cell::text("elbow of the RMSE over r (7 hidden layers)"), Cell::int(elbow)],
            vec![Cell::text("correlation dimension of the strain snapshots"), Cell::sig(corr, 3)],
            vec![Cell::text("correlation dimension of the r = 3 encodings"), Cell::sig(corr_latent, 3)],
        ],
        note: "Elbow: the smallest r after which one more latent coordinate no longer halves the reconstruction error. Correlation dimension (Grassberger & Procaccia 1983): the growth C(ε) ∝ ε^d of the fraction of sample pairs closer than ε, between the 0.5 % and 5 % quantiles of the pair distances (at most 1500 samples, evenly taken). The paper reads the dimension off the latent plots.".into(),
    };
    Ok(Latent {
        figure,
        table,
        values: json!({ "elbow": elbow, "rmse_over_r": rmse, "correlation_dimension_snapshots": corr, "correlation_dimension_latent_r3": corr_latent }),
    })
}
