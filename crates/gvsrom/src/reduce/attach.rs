//! `--model MODEL`: a reduced model bound to a scenario: its parameterization in place of the
//! scenario's basis, the layout check, and the latent range the model may be trusted in.

use super::{anchors::InitialGuess, invalid, projection_of};
use crate::build::reduced::{GuessAt, JointInputs};
use crate::build::{Built, Reduced, Resolved};
use crate::dataset::Layout;
use crate::error::ScenarioError;
use crate::reduced_model::{same_abscissae, ModelWeights, ReducedModel};
use gvs::error::fmt_rounded;
use gvs::model::Model;
use gvs::strain::{LinearBasis, StrainParam};
use nalgebra::DVector;
use rom::reduced::ReducedParam;
use std::path::Path;

/// How [`attach`] checks the scenario against what the model was trained for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AttachOptions {
    /// Use the model outside its training inputs or physics, recording how (`--extrapolate`).
    pub extrapolate: bool,
    /// The tendon tensions come from an input signal (a simulation): the scenario's static
    /// tensions are not checked, the signal is ([`Reduced::check_signal`]).
    pub tensions_from_signal: bool,
}

/// Checks that `model` (given as option `field`) was learned on the layout of `built` (points,
/// active components, HOM size).
pub(super) fn check_layout(
    field: &str,
    built: &Built,
    model: &ReducedModel,
    path: &Path,
) -> Result<(), ScenarioError> {
    let l = Layout::of(built);
    let ml = &model.meta.layout;
    let names = l.component_names();
    let same_points = same_abscissae(&ml.strain_x, &l.strain_x);
    if !same_points || ml.active != names || ml.hom_dof != built.model.n_dof() {
        return Err(invalid(
            field,
            format!(
                "`{}` was learned on {} points × [{}] with a {}-DOF basis (scenario `{}`); this scenario has {} points × [{}] with {} DOF{}",
                path.display(),
                ml.strain_x.len(),
                ml.active.join(", "),
                ml.hom_dof,
                ml.scenario,
                l.strain_x.len(),
                names.join(", "),
                built.model.n_dof(),
                match point_difference(built, &ml.strain_x, &l.strain_x) {
                    Some(why) => format!(" ({why})"),
                    None if ml.strain_x.len() == l.strain_x.len() && !same_points => {
                        " (the points are at other abscissae)".to_string()
                    }
                    None => String::new(),
                }
            ),
        ));
    }
    Ok(())
}

/// Which points one layout has and the other lacks, with the scenario value that put each of
/// this scenario's there (a point load's or a body's `x`): `this scenario has a point at X =
/// 0.3 m (bodies[1].x) that the model's lacks`. `None` when the two differ otherwise.
fn point_difference(built: &Built, model_x: &[f64], x: &[f64]) -> Option<String> {
    let scale = model_x.iter().chain(x).fold(1.0f64, |m, v| m.max(v.abs()));
    let missing_in = |a: &[f64], b: &[f64]| -> Vec<f64> {
        (a.iter().copied())
            .filter(|v| !b.iter().any(|w| (v - w).abs() <= 1e-12 * scale))
            .collect()
    };
    let sources = |v: f64| -> Vec<String> {
        let near = |w: f64| (v - w).abs() <= 1e-12 * scale;
        let loads = (built.loads.point.iter().enumerate())
            .filter(|(_, p)| near(p.x))
            .map(|(k, _)| format!("loads.point[{k}].x"));
        let bodies = (built.model.bodies().enumerate())
            .filter(|(_, b)| near(b.x))
            .map(|(k, _)| format!("bodies[{k}].x"));
        loads.chain(bodies).collect()
    };
    // a few points named; of another discretization (148 points against 102) the first ones
    let list = |xs: &[f64], named: bool| -> String {
        const SHOWN: usize = 4;
        let mut items: Vec<String> = (xs.iter().take(SHOWN))
            .map(|&v| match (named, sources(v)) {
                (true, s) if !s.is_empty() => format!("{} m ({})", fmt_rounded(v), s.join(", ")),
                _ => format!("{} m", fmt_rounded(v)),
            })
            .collect();
        if xs.len() > SHOWN {
            items.push(format!("… ({} in all)", xs.len()));
        }
        format!(
            "{} at X = {}",
            if xs.len() == 1 { "a point" } else { "points" },
            items.join(", ")
        )
    };
    let (extra, lacking) = (missing_in(x, model_x), missing_in(model_x, x));
    let mut parts = vec![];
    if !extra.is_empty() {
        parts.push(format!(
            "this scenario has {} that the model's lacks",
            list(&extra, true)
        ));
    }
    if !lacking.is_empty() {
        parts.push(format!(
            "the model's has {} that this scenario lacks (a point load or body moved or removed?)",
            list(&lacking, false)
        ));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// The reduced parameterization of `model` on the sites of `built`.
pub fn parameterization(
    built: &Built,
    model: &ReducedModel,
) -> Result<Box<dyn StrainParam>, ScenarioError> {
    let (_, _, p) = projection_of(built)?;
    let basis: &LinearBasis = &built.model.param;
    Ok(match &model.weights {
        ModelWeights::Pod { modes, .. } => {
            let b = &p * modes;
            Box::new(basis.compose(&b)?)
        }
        ModelWeights::Autoencoder(ae) => {
            let map = ae
                .decoder_map(p.as_slice(), p.nrows())
                .map_err(|e| invalid("--model", e.to_string()))?;
            let rest = DVector::from_vec(model.meta.rest.clone());
            Box::new(
                ReducedParam::new(basis, map, rest)
                    .map_err(|e| invalid("--model", e.to_string()))?,
            )
        }
    })
}

/// The scenario's rod, points and tendons with the parameterization of `model` ([`parameterization`]).
pub(super) fn reduced_model(
    built: &Built,
    model: &ReducedModel,
) -> Result<Model<Box<dyn StrainParam>>, ScenarioError> {
    let param = parameterization(built, model)?;
    let m = &built.model;
    Ok(
        Model::new(m.rod.clone(), m.disc.clone(), param, m.tendons.clone())
            .map_err(ScenarioError::from)?
            .with_base(m.base)
            .with_reference_strain_of(m)
            .with_bodies_of(m),
    )
}

/// `--model DIR`: loads the model, checks it against the scenario and attaches it to `built`.
/// `table` (the scenario's TOML after `--set`) supplies the values of non-tension dataset inputs
/// (for the initial guess and the validity check) and the physics compared with the model's.
///
/// A scenario outside what the model was trained on ([`super::validity::check`]) is refused with
/// every reason, unless `extrapolate`: then the reasons become [`Reduced::extrapolated`] and
/// warnings. A model whose training was interrupted is used with a warning.
pub fn attach(
    built: &mut Built,
    table: &toml::Table,
    dir: &Path,
    options: AttachOptions,
) -> Result<(), anyhow::Error> {
    let AttachOptions {
        extrapolate,
        tensions_from_signal,
    } = options;
    let model = ReducedModel::load(dir)?;
    check_layout("--model", built, &model, dir)?;
    let joint = super::coverage::Coverage::of(built, Some(table), &model);
    let outside = super::validity::check(
        built,
        table,
        &model,
        tensions_from_signal,
        joint.as_ref().map(|j| j as &dyn JointInputs),
    )?;
    if !outside.is_empty() && !extrapolate {
        return Err(invalid(
            "--model",
            format!(
                "`{}` was not trained for this scenario: {}; pass --extrapolate to use it anyway (its answer is then an extrapolation, and is marked so)",
                dir.display(),
                outside.join("; ")
            ),
        )
        .into());
    }
    let mut warnings = vec![];
    if model.integrity == crate::output::Integrity::Unhashed {
        warnings.push(format!(
            "`{}` was written before gvsrom recorded content hashes: its files could not be checked for edits",
            dir.display()
        ));
    }
    if let Some(t) = &model.meta.training {
        if t.stop == format!("{:?}", rom::nn::StopReason::Interrupted) {
            warnings.push(format!(
                "`{}` holds the best weights of an interrupted training ({} of up to {} epochs)",
                dir.display(),
                t.epochs_run,
                t.epochs
            ));
        }
    }
    warnings.extend(
        outside
            .iter()
            .map(|o| format!("extrapolating (--extrapolate): {o}")),
    );
    let reduced = reduced_model(built, &model)?;
    let guess = InitialGuess::of(built, Some(table), &model);
    built.reduced = Some(Reduced {
        model: reduced,
        kind: model.meta.kind.clone(),
        path: dir.to_path_buf(),
        origin: (model.origin()).unwrap_or_else(|| crate::provenance::DirOrigin::unhashed(dir)),
        initial: guess.as_ref().and_then(|g| g.at(&built.u)),
        guess: guess.map(|g| Box::new(g) as Box<dyn GuessAt>),
        // a decoder saturates outside its training encodings; a POD basis is linear and is
        // bounded by its training inputs only
        latent_range: match &model.weights {
            ModelWeights::Autoencoder(_) => model.meta.latent_range.clone(),
            ModelWeights::Pod { .. } => vec![],
        },
        data_range: match &model.weights {
            ModelWeights::Autoencoder(_) => vec![],
            ModelWeights::Pod { .. } => model.meta.latent_range.clone(),
        },
        extrapolated: outside,
        warnings,
        trained_on_motion: trained_on_motion(&model.meta),
        input_range: model.meta.input_range.clone(),
        held_tensions: super::validity::held_tensions(&model)?,
        extrapolate,
        joint: joint.map(|j| Box::new(j) as Box<dyn JointInputs>),
    });
    Ok(())
}

/// [`Reduced::trained_on_motion`] of a model: whether one of its datasets is a trajectory, or
/// `None` if a dataset's record does not say.
fn trained_on_motion(meta: &crate::reduced_model::ModelMeta) -> Option<bool> {
    let all = std::iter::once(&meta.dataset).chain(&meta.more_datasets);
    let mut known = true;
    for d in all {
        match d.trajectory {
            Some(true) => return Some(true),
            Some(false) => {}
            None => known = false,
        }
    }
    known.then_some(false)
}

/// [`attach`] for a scenario given as its source and `--set` overrides (the table the command line
/// reads): parses the source's TOML, applies the overrides and attaches the model in `dir`.
pub fn attach_source(
    built: &mut Built,
    src: &crate::presets::Source,
    overrides: &[String],
    dir: &Path,
    options: AttachOptions,
) -> Result<(), anyhow::Error> {
    let mut table = crate::scenario::parse_table(&src.origin, &src.text)?;
    for spec in overrides {
        crate::scenario::apply_override(&mut table, spec)?;
    }
    attach(built, &table, dir, options)
}

/// `--model DIR` on a resolved scenario: attaches the model in `dir` to its built scenario
/// ([`attach_source`]) and records the model in the run's provenance.
pub fn attach_resolved(
    r: &mut Resolved,
    dir: &Path,
    options: AttachOptions,
) -> Result<(), anyhow::Error> {
    attach_source(&mut r.built, &r.source, &r.overrides, dir, options)?;
    if let Some(reduced) = &r.built.reduced {
        r.provenance = r.provenance.clone().model(&reduced.origin);
    }
    Ok(())
}
