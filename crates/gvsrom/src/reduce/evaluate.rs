//! `gvsrom reconstruct MODEL DATASET`: how closely a reduced model reconstructs the snapshots of a
//! dataset, `x̂ = D(E(x))` ([`ReducedModel::reconstruct`]) — Table I's measure on any dataset of the
//! model's layout, so that a model can be judged on data it was not trained on — and says where
//! that data lies outside what the model was trained on (inputs, physics), where its errors are
//! an extrapolation's.

use super::coverage::InputCloud;
use super::invalid;
use crate::build::reduced::{at_held, inside};
use crate::dataset::Dataset;
use crate::error::ScenarioError;
use crate::reduced_model::{outside_range, oversized_row, same_abscissae, ReducedModel};
use crate::scenario::{number_at, Scenario};

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
    /// Snapshots whose code lies far outside the training encodings, or whose norm is more than
    /// [`SNAPSHOT_NORM_MARGIN`](crate::reduced_model::SNAPSHOT_NORM_MARGIN) times the largest
    /// training snapshot's (the model extrapolates there; their errors are included above).
    pub outside: usize,
    /// Snapshots whose inputs lie outside what the model was trained on — an input outside its
    /// training range, a combination far from the training inputs (`reduce::coverage`), or an
    /// input the dataset varies that training held at another value — as `--model` would refuse
    /// them; `None` when a training input has no value in the dataset (then
    /// [`Self::inputs_note`] says so).
    pub unseen_inputs: Option<usize>,
    /// Why [`Self::unseen_inputs`] could not be counted.
    pub inputs_note: Option<String>,
    /// The first way the dataset's physics differs from the model's training scenario (its inputs
    /// aside), and how many more; `None` when they agree. Every snapshot is then an extrapolation.
    pub other_physics: Option<String>,
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
    let unseen = unseen_inputs(model, ds);
    let other_physics = other_physics(model, ds)?;
    let (mut err2, mut norm2, mut entries) = (0.0, 0.0, 0usize);
    let (mut worst, mut outside, mut largest) = (None::<(usize, f64, f64)>, 0, 0.0f64);
    let rows = ds.ok_rows();
    for &k in &rows {
        let x = ds.strain_row(k);
        let q = model
            .encode(x, true)
            .map_err(|e| invalid("MODEL", e.to_string()))?;
        if outside_range(&model.meta.latent_range, &q).is_some()
            || oversized_row(model.meta.snapshot_norm_max, x, x.len()).is_some()
        {
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
        unseen_inputs: unseen.as_ref().ok().copied(),
        inputs_note: unseen.err(),
        other_physics,
    })
}

/// How many solved snapshots of `ds` have inputs outside what `model` was trained on: one of the
/// model's inputs outside its range, their combination far from the training inputs, or an input
/// the dataset varies that training held at another value (a tension or a material constant). A
/// model input the dataset does not vary takes the dataset scenario's value. An explanation
/// instead when a model input has no value in the dataset.
fn unseen_inputs(model: &ReducedModel, ds: &Dataset) -> Result<usize, String> {
    let ranges = &model.meta.input_range;
    if ranges.is_empty() {
        return Err(
            "the model records no training inputs (it was written before gvsrom recorded them)"
                .into(),
        );
    }
    let trained = super::validity::trained_scenario(model)
        .and_then(|s| s.to_table())
        .map_err(|e| e.to_string())?;
    let here = Scenario::from_toml(&ds.meta.scenario, &ds.meta.scenario_toml, &[])
        .and_then(|s| s.to_table())
        .map_err(|e| e.to_string())?;
    let column = |name: &str| ds.meta.parameters.iter().position(|p| p == name);
    // where each model input's value comes from: a dataset column, or the dataset's scenario
    let source = |name: &str| {
        match column(name) {
        Some(c) => Ok(Err(c)),
        None => number_at(&here, name).map(Ok).ok_or_else(|| {
            format!("the dataset neither samples {name} (a training input) nor gives it a numeric value")
        }),
    }
    };
    let sources: Vec<Result<f64, usize>> = ranges
        .iter()
        .map(|r| source(&r.parameter))
        .collect::<Result<_, _>>()?;
    let cloud = InputCloud::of_model(model);
    let cloud_sources: Option<Vec<Result<f64, usize>>> = cloud
        .as_ref()
        .and_then(|c| c.names().iter().map(|n| source(n).ok()).collect());
    // the dataset's own inputs that training held fixed: their trained values
    let is_input = |p: &str| ranges.iter().any(|r| r.parameter == p);
    let held: Vec<(usize, Option<f64>)> = (ds.meta.parameters.iter().enumerate())
        .filter(|(_, p)| !is_input(p))
        .map(|(c, p)| (c, number_at(&trained, p)))
        .collect();
    let k = ds.meta.parameters.len();
    let mut x = vec![];
    let count = ds
        .ok_rows()
        .iter()
        .filter(|&&i| {
            let row = &ds.inputs[i * k..(i + 1) * k];
            let value = |s: &Result<f64, usize>| match *s {
                Ok(v) => v,
                Err(c) => row[c],
            };
            let in_ranges = ranges
                .iter()
                .zip(&sources)
                .all(|(r, s)| inside(r, value(s)));
            let near = match (&cloud, &cloud_sources) {
                (Some(cloud), Some(sources)) => {
                    x.clear();
                    x.extend(sources.iter().map(value));
                    cloud.outside(&x).is_none()
                }
                _ => true,
            };
            let as_held = held
                .iter()
                .all(|&(c, v)| v.is_some_and(|v| at_held(row[c], v)));
            !(in_ranges && near && as_held)
        })
        .count();
    Ok(count)
}

/// The first way the physics of `ds`'s scenario differs from `model`'s training scenario, the
/// inputs of either aside ([`super::validity::physics_differences`]).
fn other_physics(model: &ReducedModel, ds: &Dataset) -> Result<Option<String>, ScenarioError> {
    let trained = super::validity::trained_scenario(model)?;
    let here = Scenario::from_toml(&ds.meta.scenario, &ds.meta.scenario_toml, &[])
        .map_err(|e| invalid("DATASET", format!("its scenario cannot be read: {e}")))?;
    let inputs = (model.meta.input_range.iter().map(|r| r.parameter.as_str()))
        .chain(ds.meta.parameters.iter().map(String::as_str));
    super::validity::first_physics_difference(&trained, &here, inputs, |at, there, value| {
        format!(
            "{at} is {value} in the dataset's scenario `{}`, {there} in the model's `{}`",
            ds.meta.scenario, model.meta.layout.scenario
        )
    })
}
