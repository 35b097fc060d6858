//! `gvsrom reconstruct MODEL DATASET`: how closely a reduced model reconstructs the snapshots of a
//! dataset, `x̂ = D(E(x))` ([`ReducedModel::reconstruct`]) — Table I's measure on any dataset of the
//! model's layout, so that a model can be judged on data it was not trained on.

use super::invalid;
use crate::dataset::Dataset;
use crate::error::ScenarioError;
use crate::reduced_model::{outside_range, same_abscissae, ReducedModel};

/// The reconstruction errors of a model on a dataset's solved snapshots.
#[derive(Debug, Clone, PartialEq)]
pub struct Reconstruction {
    /// Solved snapshots evaluated.
    pub rows: usize,
    /// `sqrt(mean (x̂ − x)²)` over every entry of every snapshot (Table I), in the snapshots' units.
    pub rmse: f64,
    /// `‖X̂ − X‖_F / ‖X‖_F` over the whole dataset (infinite if every snapshot is zero but not its
    /// reconstruction).
    pub relative: f64,
    /// The snapshot (dataset row) with the largest `‖x̂ − x‖ / ‖x‖`, that ratio and `‖x‖`; `None`
    /// if every snapshot is zero. (Near a load's zero the ratio of a tiny snapshot can be large.)
    pub worst: Option<(usize, f64, f64)>,
    /// The largest `‖x‖` of the snapshots, for scale.
    pub largest_norm: f64,
    /// Snapshots whose code lies far outside the training encodings (the model extrapolates
    /// there; their errors are included above).
    pub outside: usize,
}

/// The reconstruction of every solved snapshot of `ds` by `model`. The dataset must have the
/// model's layout (points and active components); otherwise an error names `DATASET`.
pub fn reconstruction(model: &ReducedModel, ds: &Dataset) -> Result<Reconstruction, ScenarioError> {
    let layout = &model.meta.layout;
    let same_points = same_abscissae(&layout.strain_x, &ds.meta.strain_x);
    if !same_points || layout.active != ds.meta.components {
        return Err(invalid(
            "DATASET",
            format!(
                "its snapshots ({} points, components [{}], scenario `{}`) are not in the model's layout ({} points, components [{}], scenario `{}`)",
                ds.meta.strain_x.len(),
                ds.meta.components.join(", "),
                ds.meta.scenario,
                layout.strain_x.len(),
                layout.active.join(", "),
                layout.scenario
            ),
        ));
    }
    let (mut err2, mut norm2, mut entries) = (0.0, 0.0, 0usize);
    let (mut worst, mut outside, mut largest) = (None::<(usize, f64, f64)>, 0, 0.0f64);
    let rows = ds.ok_rows();
    for &k in &rows {
        let x = ds.strain_row(k);
        let q = model
            .encode(x, true)
            .map_err(|e| invalid("MODEL", e.to_string()))?;
        if outside_range(&model.meta.latent_range, &q).is_some() {
            outside += 1;
        }
        let rec = model
            .decode(&q, true)
            .map_err(|e| invalid("MODEL", e.to_string()))?;
        let e2: f64 = x.iter().zip(&rec).map(|(a, b)| (a - b) * (a - b)).sum();
        let n2: f64 = x.iter().map(|a| a * a).sum();
        if n2 > 0.0 && worst.is_none_or(|(_, w, _)| (e2 / n2).sqrt() > w) {
            worst = Some((k, (e2 / n2).sqrt(), n2.sqrt()));
        }
        largest = largest.max(n2.sqrt());
        (err2, norm2, entries) = (err2 + e2, norm2 + n2, entries + x.len());
    }
    if entries == 0 {
        return Err(invalid("DATASET", "it has no solved snapshots"));
    }
    Ok(Reconstruction {
        rows: rows.len(),
        rmse: (err2 / entries as f64).sqrt(),
        relative: match (norm2 > 0.0, err2 > 0.0) {
            (true, _) => (err2 / norm2).sqrt(),
            (false, true) => f64::INFINITY,
            (false, false) => 0.0,
        },
        worst,
        largest_norm: largest,
        outside,
    })
}
