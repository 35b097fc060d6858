//! Reduction commands and reduced models on a scenario (paper Sections III–IV):
//!
//! - [`pod`]: `gvsrom pod DATASET… --modes K --out MODEL`;
//! - [`train`]: `gvsrom train DATASET… --latent R --hidden-layers 3|5|7 --out MODEL`;
//! - [`attach`]: `--model MODEL` on `statics` and `simulate`: the scenario's engine with the model's
//!   strain parameterization in place of its basis (no physics re-implemented).
//!
//! POD and decoders alike act on the HOM's own basis through the least-squares projection `P` of
//! point strains onto its coefficients (`rom::reduced`): `Ψ_s(q_r) = Φ_s P V q_r` (POD, a constant
//! linear basis) or `Φ_s P D(q_r)` (autoencoder).
//!
//! Files: [`pod`](pod()) and [`train`](train()) build models from one or more datasets (`pod.rs`,
//! `train.rs`, `start.rs`: a training from a model's weights, and `request.rs`: a training's options as
//! every front-end is given them); `sources.rs` gathers and checks their snapshots; `anchors.rs` holds the training
//! samples kept as initial guesses; `coverage.rs` judges a combination of inputs against them; `kinetic.rs` the mass matrices of `train --kinetic-weight`;
//! `attach.rs` binds a model to a scenario; this file the steps
//! both commands share.

mod anchors;
mod attach;
pub mod coverage;
mod evaluate;
mod kinetic;
mod loss;
mod pod;
mod request;
mod sources;
mod start;
mod train;
pub mod validity;

pub use crate::build::Reduced;
pub use crate::reduced_model::PodNorm;
pub use anchors::{anchor_guess, solve_anchors, AnchorInput, AnchorProblem, InitialGuess};
pub use attach::{attach, attach_resolved, attach_source, parameterization, AttachOptions};
pub use evaluate::{reconstruction, Reconstruction};
pub use loss::Loss;
pub use pod::{pod, PodSummary};
pub use request::{named, TrainRequest};
pub use start::{start_model, train_settings, StartModel, TrainChoices};
pub use train::{
    decoder_form, sample_weighting, train, zero_anchor_rows, TrainSummary, SAMPLE_WEIGHTINGS,
};

use crate::build::{build, Built};
use crate::dataset::Dataset;
use crate::error::ScenarioError;
use crate::reduced_model::{outside_range, same_abscissae, DatasetRef, ModelLayout, ReducedModel};
use crate::scenario::Scenario;
use attach::reduced_model;
use nalgebra::DMatrix;
use rom::reduced::{point_matrix, projection, PointLayout};
use std::path::Path;

pub(super) fn invalid(field: &str, message: impl Into<String>) -> ScenarioError {
    ScenarioError::invalid(field, message)
}

/// Refuses no reduced coordinates, or more (`--modes`, `--latent`) than the full model has: the reduced
/// model runs in the full model's basis (`Ψ = Φ P D(q_r)`), so coordinates beyond its DOF are
/// redundant, its mass matrix singular, and its statics and dynamics fail.
fn at_most_the_full_models_dof(field: &str, r: usize, built: &Built) -> Result<(), ScenarioError> {
    let n = built.n_dof();
    if r == 0 {
        return Err(invalid(
            field,
            format!(
                "0: an integer in [1, {n}] (at most the {n} DOF of the full model `{}`)",
                built.name
            ),
        ));
    }
    if r > n {
        return Err(invalid(
            field,
            format!(
                "{r}: more than the {n} DOF of the full model `{}` (a reduced model has at most as many coordinates as the model it reduces; beyond them its mass matrix is singular)",
                built.name
            ),
        ));
    }
    Ok(())
}

/// Refuses an `--out` that is, or contains, one of the command's inputs — a `DATASET` or the
/// `--init` model — which `--force` would otherwise replace ([`crate::output::refuse_overlap`]).
fn refuse_input_overlap<P: AsRef<Path>>(
    out: &Path,
    datasets: &[P],
    init: Option<&Path>,
) -> Result<(), crate::output::OutputError> {
    let mut inputs: Vec<(&str, &Path)> = datasets.iter().map(|d| ("DATASET", d.as_ref())).collect();
    inputs.extend(init.map(|m| ("--init", m)));
    crate::output::refuse_overlap("--out", out, &inputs)
}

/// The HOM a dataset was generated on (its scenario TOML, as stored), checked against the dataset's
/// arrays: the points, active components and coordinates that scenario has must be the dataset's
/// (metadata naming another scenario would otherwise fail deep inside a matrix product).
pub fn dataset_scenario(ds: &Dataset) -> Result<Built, ScenarioError> {
    let s = Scenario::from_toml(&ds.meta.scenario, &ds.meta.scenario_toml, &[])?;
    let built = build(&s)?;
    let l = crate::dataset::Layout::of(&built);
    let m = &ds.meta;
    let same_x = same_abscissae(&l.strain_x, &m.strain_x);
    if !same_x || l.component_names() != m.components || l.n_dof != m.n_dof {
        return Err(invalid(
            "DATASET",
            format!(
                "its meta.json is inconsistent: the scenario it names (`{}`) has {} points × [{}] and {} coordinates, the dataset records {} points × [{}] and {} coordinates{}",
                m.scenario,
                l.strain_x.len(),
                l.component_names().join(", "),
                l.n_dof,
                m.strain_x.len(),
                m.components.join(", "),
                m.n_dof,
                if l.strain_x.len() == m.strain_x.len() && !same_x {
                    " (at other abscissae)"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(built)
}

/// The point layout of `built` in `rom`'s terms, and `Φ̄` and `P` of its basis.
pub(super) fn projection_of(
    built: &Built,
) -> Result<(PointLayout, DMatrix<f64>, DMatrix<f64>), ScenarioError> {
    let layout = PointLayout::active_in(&built.model.param, &built.model.disc);
    let pm = point_matrix(&built.model.param, &layout);
    let p = projection(&pm).map_err(|e| invalid("basis", e.to_string()))?;
    Ok((layout, pm, p))
}

/// Bound on a snapshot value times the rod length (see [`snapshot_rows`]).
const MAX_STRAIN_TIMES_LENGTH: f64 = 1e6;

/// The usable rows of a dataset (status ok), row-major, and their count; an error if none, if the
/// dataset is incomplete, or if a value is beyond any strain a rod of `length` can hold.
pub(super) fn snapshot_rows(
    ds: &Dataset,
    option: &str,
    length: f64,
) -> Result<(Vec<f64>, usize), ScenarioError> {
    let c = &ds.meta.counts;
    if c.not_computed > 0 {
        return Err(invalid(
            option,
            format!(
                "the dataset is incomplete: {} of its {} samples were not computed (its run was interrupted); finish it first by running the same `gvsrom dataset` command again with `--resume`",
                c.not_computed,
                ds.samples()
            ),
        ));
    }
    let rows = ds.ok_rows();
    if rows.is_empty() {
        return Err(invalid(
            option,
            "the dataset has no solved samples (every status is failed or not computed)",
        ));
    }
    let mut x = Vec::with_capacity(rows.len() * ds.row_len());
    for &k in &rows {
        x.extend_from_slice(ds.strain_row(k));
    }
    // a value no rod of this length can hold: a bent rod of curvature κ turns κL/2π times, a
    // stretched one by a factor of its elongation; 10⁶ of either is a corrupt sample, not physics
    let (i, v) = x
        .iter()
        .enumerate()
        .map(|(i, v)| (i, v.abs()))
        .fold((0, 0.0f64), |a, b| if b.1 > a.1 { b } else { a });
    if v * length.max(1.0) > MAX_STRAIN_TIMES_LENGTH {
        let sample = rows[i / ds.row_len().max(1)];
        return Err(invalid(
            option,
            format!(
                "sample {sample} holds the strain value {:e}, which no rod of length {length} m can hold (|ξ − ξ*| · max(L, 1 m) > {MAX_STRAIN_TIMES_LENGTH:e}): a corrupt sample; remove it or re-create the dataset",
                x[i]
            ),
        ));
    }
    Ok((x, rows.len()))
}

pub(super) fn model_layout(ds: &Dataset, built: &Built) -> ModelLayout {
    ModelLayout {
        scenario: ds.meta.scenario.clone(),
        scenario_toml: ds.meta.scenario_toml.clone(),
        strain_x: ds.meta.strain_x.clone(),
        active: ds.meta.components.clone(),
        hom_dof: built.model.n_dof(),
    }
}

/// What a model records of the dataset `ds` loaded from `dir`, `rows` of it used: the hash of the
/// very `strain.npy` bytes the snapshots were read from ([`Dataset::strain_sha256`]).
pub(super) fn dataset_ref(dir: &Path, ds: &Dataset, rows: usize) -> DatasetRef {
    DatasetRef {
        path: dir.display().to_string(),
        strain_hash: ds.strain_sha256.clone(),
        rows,
        trajectory: Some(ds.meta.dynamic.is_some()),
    }
}

/// The inputs of the usable samples (status ok), row-major (`n × k`): the anchors' inputs.
pub(super) fn sample_inputs(ds: &Dataset) -> Vec<f64> {
    let k = ds.meta.parameters.len();
    ds.ok_rows()
        .iter()
        .flat_map(|&i| ds.inputs[i * k..(i + 1) * k].iter().copied())
        .collect()
}

/// For a static dataset whose inputs are all tendon tensions or loads ([`AnchorInput`]): the reduced
/// model's own equilibria in place of the anchors' encodings where found ([`solve_anchors`], inside
/// the training encodings' range); returns their number (0 for other datasets, whose anchors keep
/// the encodings).
pub(super) fn equilibrium_anchors(
    built: &Built,
    ds: &Dataset,
    model: &mut ReducedModel,
) -> Result<usize, ScenarioError> {
    let inputs: Option<Vec<AnchorInput>> = model
        .meta
        .anchor_parameters
        .iter()
        .map(|p| AnchorInput::of(p))
        .collect();
    let (Some(inputs), None) = (inputs, &ds.meta.dynamic) else {
        return Ok(0);
    };
    if inputs.is_empty() || model.anchors.is_none() {
        return Ok(0);
    }
    let table = match inputs.iter().any(|i| matches!(i, AnchorInput::Load(_))) {
        true => Some(crate::scenario::parse_table(
            &ds.meta.scenario,
            &ds.meta.scenario_toml,
        )?),
        false => None,
    };
    let reduced = reduced_model(built, model)?;
    let range = model.meta.latent_range.clone();
    let Some(a) = model.anchors.as_mut() else {
        return Ok(0);
    };
    let problem = AnchorProblem {
        u: &built.u,
        loads: &built.loads,
        inputs: &inputs,
        table: table.as_ref(),
        length: built.model.rod.length(),
    };
    Ok(solve_anchors(
        &reduced,
        &built.options,
        &problem,
        &a.inputs,
        &mut a.latent,
        &|q| outside_range(&range, q.as_slice()).is_none(),
    ))
}

/// The largest Euclidean norm of the row-major snapshots `x` of `features` values
/// ([`ModelMeta::snapshot_norm_max`](crate::reduced_model::ModelMeta::snapshot_norm_max)).
pub(super) fn largest_norm(x: &[f64], features: usize) -> f64 {
    (x.chunks_exact(features))
        .map(crate::reduced_model::row_norm)
        .fold(0.0, f64::max)
}

/// Per coordinate, the `[min, max]` of `latent` (`n × r`, row-major).
pub(super) fn latent_range(latent: &[f64], r: usize) -> Vec<[f64; 2]> {
    let mut range = vec![[f64::INFINITY, f64::NEG_INFINITY]; r];
    for z in latent.chunks_exact(r.max(1)) {
        for (d, v) in z.iter().enumerate() {
            range[d] = [range[d][0].min(*v), range[d][1].max(*v)];
        }
    }
    range
}

/// What a front-end should tell the user about the dataset `ds` read from `dir`: the samples left
/// out (failed or not computed: their rows are NaN), and that one written before content hashes
/// could not be checked for edits.
pub(super) fn dataset_warnings(ds: &Dataset, dir: &Path) -> Vec<String> {
    let mut warnings = vec![];
    let problems = ds.problems();
    if let Some(first) = problems.first() {
        warnings.push(format!(
            "dataset `{}`: {} of its {} samples are left out, failed or not computed ({first}{})",
            dir.display(),
            problems.len(),
            ds.samples(),
            match problems.len() - 1 {
                0 => String::new(),
                more => format!("; {more} more in its meta.json"),
            }
        ));
    }
    if let crate::output::Integrity::Unhashed = ds.integrity {
        warnings.push(format!(
            "dataset `{}` was written before gvsrom recorded content hashes: its files could not be checked for edits",
            dir.display()
        ));
    }
    warnings
}

/// The strain-energy norm's weight of every snapshot feature of `layout` (point `j`, active
/// component `a`, point-major): the section stiffness `Σ_s,aa` at the point (`E J`-, `E I`-, `E A`-
/// and `G A`-type entries). `‖x‖²_W = Σ w x²` is twice the strain energy per unit length, summed
/// over the points without their quadrature weights, under which the kinematic points would weigh
/// nothing.
pub(crate) fn stiffness_weights(built: &Built, layout: &PointLayout) -> Vec<f64> {
    (0..layout.n_points)
        .flat_map(|i| {
            let es = built.model.section(i).es;
            layout.active.iter().map(move |&a| es[a])
        })
        .collect()
}
