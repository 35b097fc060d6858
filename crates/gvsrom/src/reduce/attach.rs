//! `--model MODEL`: a reduced model bound to a scenario: its parameterization in place of the
//! scenario's basis, the layout check, and the latent range the model may be trusted in.

use super::{anchors::InitialGuess, invalid, projection_of};
use crate::build::Built;
use crate::dataset::Layout;
use crate::error::ScenarioError;
use crate::reduced_model::{ModelWeights, ReducedModel};
use gvs::model::Model;
use gvs::strain::{LinearBasis, StrainParam};
use nalgebra::DVector;
use rom::reduced::ReducedParam;
use std::path::{Path, PathBuf};

/// How [`attach`] checks the scenario against what the model was trained for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AttachOptions {
    /// Use the model outside its training inputs or physics, recording how (`--extrapolate`).
    pub extrapolate: bool,
    /// The tendon tensions come from an input signal (a simulation): the scenario's static
    /// tensions are not checked, the signal is ([`Reduced::check_signal`]).
    pub tensions_from_signal: bool,
}

/// A reduced model bound to a scenario.
pub struct Reduced {
    /// The scenario's rod, points, tendons and loads with the reduced parameterization.
    pub model: Model<Box<dyn StrainParam>>,
    /// `"pod"` or `"autoencoder"`.
    pub kind: String,
    pub path: PathBuf,
    /// Initial guess of a statics solve: the model's anchors at this scenario's inputs
    /// ([`anchor_guess`]; models whose dataset inputs the scenario defines).
    pub initial: Option<DVector<f64>>,
    /// The initial guesses at other tensions ([`Self::initial_at`]).
    pub guess: Option<InitialGuess>,
    /// The training encodings' range per coordinate.
    pub latent_range: Vec<[f64; 2]>,
    /// How the scenario lies outside what the model was trained on, when used with
    /// `--extrapolate` (empty: inside; see [`super::validity`]).
    pub extrapolated: Vec<String>,
    /// What a front-end should tell the user about this model (an interrupted training, an
    /// extrapolation).
    pub warnings: Vec<String>,
    /// The training inputs' ranges ([`super::validity`]).
    pub input_range: Vec<crate::reduced_model::InputRange>,
    /// [`AttachOptions::extrapolate`], for the checks that come later (an input signal's).
    pub extrapolate: bool,
}

impl Reduced {
    /// Checks an input signal's tensions (`u_at(t)` at `times`) against the training ranges
    /// ([`super::validity::check_signal`]): an error listing how it lies outside, or with
    /// `--extrapolate` those sentences, to be printed and recorded with the run.
    pub fn check_signal(
        &self,
        times: &[f64],
        u_at: impl FnMut(f64) -> Vec<f64>,
    ) -> Result<Vec<String>, ScenarioError> {
        let outside = super::validity::check_signal(&self.input_range, times, u_at);
        if outside.is_empty() {
            return Ok(vec![]);
        }
        if !self.extrapolate {
            return Err(invalid(
                "--model",
                format!(
                    "`{}` was not trained for this input: {}; pass --extrapolate to use it anyway (its answer is then an extrapolation, and is marked so)",
                    self.path.display(),
                    outside.join("; ")
                ),
            ));
        }
        Ok(outside)
    }

    /// The initial guess of a statics solve under the tensions `u` in place of the scenario's: the
    /// [`Self::initial`] of the scenario built with them.
    pub fn initial_at(&self, u: &[f64]) -> Option<DVector<f64>> {
        self.guess.as_ref().and_then(|g| g.at(u))
    }

    /// Whether the model, attached to a scenario with the tensions `u0`, may answer at the tensions
    /// `u` as it was checked to ([`attach`]): it is not extrapolating, and every tension that
    /// differs from `u0` is a training input inside its range ([`super::validity::covers`]).
    /// If not, attaching it to the scenario with the tensions `u` gives the verdict and its reasons.
    pub fn covers_tensions(&self, u0: &[f64], u: &[f64]) -> bool {
        self.extrapolated.is_empty() && super::validity::covers(&self.input_range, u0, u)
    }

    /// Errors if `q` lies outside the training encodings' range by more than half its width in
    /// some coordinate ([`Self::range_violation`]): the decoder is extrapolating there (tanh layers
    /// saturate, `Ψ_q → 0`, and spurious equilibria appear), so the result is not to be trusted.
    /// The message names the likely cause: the inputs were checked when the model was attached.
    pub fn check_range(&self, q: &[f64]) -> Result<(), ScenarioError> {
        let Some(v) = self.range_violation(q) else {
            return Ok(());
        };
        let cause = if !self.extrapolated.is_empty() {
            "the model is extrapolating (--extrapolate) and its decoder has left its data"
        } else if self.initial.is_none() {
            "the inputs lie inside the training range, but the model has no anchors to start the solve from, and from its rest coordinates the solve reached a spurious equilibrium off the learned manifold: re-create the model with this build (it stores anchors)"
        } else {
            "the inputs lie inside the training range, yet the solve reached a spurious equilibrium off the learned manifold: the model is poor here (more data, or more training)"
        };
        Err(invalid(
            "--model",
            format!("the reduced solution {v}: {cause}"),
        ))
    }

    /// How far the rest coordinates ([`StrainParam::rest_coordinates`], where a simulation from
    /// rest starts) are from the straight rod: the largest `|ξ − ξ*|` over the computational points
    /// and strain components. Zero for POD (`q_r = 0`); for an autoencoder, its reconstruction error
    /// of the straight rod, large when the training data lack it (e.g. all sag under gravity).
    pub fn rest_strain_offset(&self) -> f64 {
        let m = &self.model;
        let mut ws = m.workspace();
        m.forward(&m.param.rest_coordinates(), &mut ws, false);
        m.point_strains(&ws)
            .iter()
            .enumerate()
            .map(|(j, xi)| (xi - m.xi_star(j)).amax())
            .fold(0.0, f64::max)
    }

    /// The first coordinate of `q` outside the training encodings' range widened by half its
    /// width on each side (or not finite), described as "`q_r[d] = v` lies far outside the range
    /// of the training data `[lo, hi]` of `MODEL`"; `None` inside (always, for models without a
    /// recorded range).
    pub fn range_violation(&self, q: &[f64]) -> Option<String> {
        outside_range(&self.latent_range, q).map(|d| {
            let (v, [lo, hi]) = (q[d], self.latent_range[d]);
            format!(
                "q_r[{d}] = {v:.6} lies far outside the range of the training data [{lo:.6}, {hi:.6}] of `{}`",
                self.path.display()
            )
        })
    }
}

/// The first coordinate of `q` outside `range` widened by half its width on each side, or not
/// finite (see [`Reduced::range_violation`]).
pub(super) fn outside_range(range: &[[f64; 2]], q: &[f64]) -> Option<usize> {
    q.iter().zip(range).position(|(v, [lo, hi])| {
        let margin = 0.5 * (hi - lo).max(1e-12);
        !(*v >= lo - margin && *v <= hi + margin)
    })
}

/// Checks that `model` was learned on the layout of `built` (points, active components, HOM size).
pub(super) fn check_layout(
    built: &Built,
    model: &ReducedModel,
    path: &Path,
) -> Result<(), ScenarioError> {
    let l = Layout::of(built);
    let ml = &model.meta.layout;
    let names = l.component_names();
    let length = built.model.disc.length();
    let same_points = ml.strain_x.len() == l.strain_x.len()
        && ml
            .strain_x
            .iter()
            .zip(&l.strain_x)
            .all(|(a, b)| (a - b).abs() <= 1e-12 * length.max(1.0));
    if !same_points || ml.active != names || ml.hom_dof != built.model.n_dof() {
        return Err(invalid(
            "--model",
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
                if ml.strain_x.len() == l.strain_x.len() && !same_points {
                    " (the points are at other abscissae)"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(())
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
            .with_base(m.base),
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
    check_layout(built, &model, dir)?;
    let outside = super::validity::check(built, table, &model, tensions_from_signal)?;
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
        initial: guess.as_ref().and_then(|g| g.at(&built.u)),
        guess,
        // a decoder saturates outside its training encodings; a POD basis is linear and is
        // bounded by its training inputs only
        latent_range: match &model.weights {
            ModelWeights::Autoencoder(_) => model.meta.latent_range.clone(),
            ModelWeights::Pod { .. } => vec![],
        },
        extrapolated: outside,
        warnings,
        input_range: model.meta.input_range.clone(),
        extrapolate,
    });
    Ok(())
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
