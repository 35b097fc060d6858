//! A reduced model attached to a built scenario: its parameterization in place of the scenario's
//! basis, and what every run checks against what the model was trained on — the inputs' ranges
//! and the latent range. The reduction layer attaches one (its `attach`); the runs only read it.

use crate::error::ScenarioError;
use crate::reduced_model::{outside_range, InputRange};
use gvs::error::fmt_value;
use gvs::model::Model;
use gvs::strain::StrainParam;
use nalgebra::DVector;
use std::path::PathBuf;

/// The observed range of a training input is widened by this fraction of its width on each side:
/// a test signal drawn like the training one (IV-C2's babbling with another seed) reaches a little
/// beyond the extremes the training samples happened to hit.
pub const INPUT_MARGIN: f64 = 0.02;

/// Whether `v` lies in `r` widened by [`INPUT_MARGIN`] of its width (and at least a relative
/// 1e-9 of its magnitude, for a single-valued range).
pub fn inside(r: &InputRange, v: f64) -> bool {
    let slack = (INPUT_MARGIN * (r.max - r.min))
        .max(1e-9 * r.min.abs().max(r.max.abs()))
        .max(1e-12);
    v.is_finite() && v >= r.min - slack && v <= r.max + slack
}

/// Whether the tension `v` is the value `held` that training held a tendon at (to a relative 1e-12).
pub fn at_held(v: f64, held: f64) -> bool {
    (v - held).abs() <= 1e-12 * (1.0 + held.abs())
}

/// A reduced model bound to a scenario.
pub struct Reduced {
    /// The scenario's rod, points, tendons and loads with the reduced parameterization.
    pub model: Model<Box<dyn StrainParam>>,
    /// `"pod"` or `"autoencoder"`.
    pub kind: String,
    pub path: PathBuf,
    /// The model's directory by its manifest's hashes as it was loaded (what a run records).
    pub origin: crate::provenance::DirOrigin,
    /// Initial guess of a statics solve: the model's anchors at this scenario's inputs
    /// (`anchor_guess`; models whose dataset inputs the scenario defines).
    pub initial: Option<DVector<f64>>,
    /// The initial guesses at other tensions ([`Self::initial_at`]; the reduction layer's
    /// anchors).
    pub guess: Option<Box<dyn GuessAt>>,
    /// The training encodings' range per coordinate, for a decoder: beyond it (by half its width)
    /// a solve or a run is refused ([`Self::range_violation`]). Empty for POD.
    pub latent_range: Vec<[f64; 2]>,
    /// A POD model's training encodings' range: its basis is linear and defined everywhere, so a
    /// run that leaves it is only noted ([`Self::data_range_violation`]). Empty for a decoder.
    pub data_range: Vec<[f64; 2]>,
    /// How the scenario lies outside what the model was trained on, when used with
    /// `--extrapolate` (empty: inside; see [`InputRange`]).
    pub extrapolated: Vec<String>,
    /// What a front-end should tell the user about this model (an interrupted training, an
    /// extrapolation).
    pub warnings: Vec<String>,
    /// Whether any of its datasets holds a motion (a dynamic dataset's trajectory): `Some(false)`
    /// for a model made from equilibria only, `None` when a dataset's record predates the
    /// distinction ([`Self::motion_note`]).
    pub trained_on_motion: Option<bool>,
    /// The training inputs' ranges ([`InputRange`]).
    pub input_range: Vec<InputRange>,
    /// Per tendon, the tension training held it at (`None`: a training input, in `input_range`).
    pub held_tensions: Vec<Option<f64>>,
    /// `AttachOptions::extrapolate`, for the checks that come later (an input signal's).
    pub extrapolate: bool,
    /// The training inputs as a whole (the reduction layer's coverage): whether a combination of
    /// inputs lies near those training saw, beyond each input inside its range. `None` for a
    /// model without anchors or whose inputs do not vary.
    pub joint: Option<Box<dyn JointInputs>>,
}

/// Whether the tendon tensions `u`, with the scenario's other training inputs, lie near the
/// training inputs as a whole (the reduction layer's `reduce::coverage`).
pub trait JointInputs: Send + Sync {
    /// `None` near the training inputs (or when `u` has the wrong length, or is not finite: the
    /// range check reports those); else the distance to the nearest one, in units of each input's
    /// training range, and a sentence saying how far.
    fn outside(&self, u: &[f64]) -> Option<(f64, String)>;
}

/// Initial guesses of a reduced statics solve at any tendon tensions `u` (one per tendon): what
/// the reduction layer's anchors give (`reduce::InitialGuess`); `None` where they give none.
pub trait GuessAt: Send + Sync {
    fn at(&self, u: &[f64]) -> Option<DVector<f64>>;
}

impl Reduced {
    /// The initial guess of a statics solve under the tensions `u` in place of the scenario's: the
    /// [`Self::initial`] of the scenario built with them.
    pub fn initial_at(&self, u: &[f64]) -> Option<DVector<f64>> {
        self.guess.as_ref().and_then(|g| g.at(u))
    }

    /// Whether the model, attached to a scenario with the tensions `u0`, may answer at the tensions
    /// `u` as it was checked to when attached: it is not extrapolating, and every tension that
    /// differs from `u0` is a training input inside its range ([`covers`]), and the inputs together
    /// lie near the training inputs ([`JointInputs`]). If not, attaching it to the scenario with the
    /// tensions `u` gives the verdict and its reasons.
    pub fn covers_tensions(&self, u0: &[f64], u: &[f64]) -> bool {
        self.extrapolated.is_empty()
            && covers(&self.input_range, u0, u)
            && self.joint.as_ref().is_none_or(|j| j.outside(u).is_none())
    }

    /// How the tensions `u` a solve found for the displacement drives (`driven[k]`) lie outside
    /// what training saw, one sentence each (empty: inside): a found tension outside its training
    /// range, or one training held at another value; or, every tension inside (the given ones
    /// too, which were checked as inputs), their combination far from the training inputs.
    pub fn found_tensions_outside(&self, u: &[f64], driven: &[bool]) -> Vec<String> {
        let mut outside = vec![];
        let mut given_inside = true;
        for (k, &v) in u.iter().enumerate() {
            let param = tension_param(k);
            let found = driven.get(k).copied().unwrap_or(false);
            let sentence = match (self.input_range.iter()).find(|r| r.parameter == param) {
                Some(r) if !inside(r, v) => format!(
                    "{param} = {} (found) lies outside the training inputs [{}, {}]",
                    super::significant(v),
                    super::significant(r.min),
                    super::significant(r.max)
                ),
                Some(_) => continue,
                None => match self.held_tensions.get(k) {
                    Some(Some(h)) if !at_held(v, *h) => format!(
                        "{param} = {} (found), but training held it at {}",
                        super::significant(v),
                        fmt_value(*h)
                    ),
                    _ => continue,
                },
            };
            match found {
                true => outside.push(sentence),
                false => given_inside = false,
            }
        }
        if let (true, true, Some(joint)) = (outside.is_empty(), given_inside, &self.joint) {
            outside.extend(joint.outside(u).map(|(_, why)| why));
        }
        outside
    }

    /// Checks an input signal's tensions (`u_at(t)` at `times`) against the training ranges
    /// ([`signal_outside`]) and, if each tension lies in its range, against the training inputs as
    /// a whole ([`JointInputs`], the farthest time named): an error listing how it lies outside, or
    /// with `--extrapolate` those sentences, to be printed and recorded with the run.
    ///
    /// A channel `k` with `driven[k]` is the displacement of a tendon driven by it, no tension:
    /// it is not checked here, nor are the inputs as a whole when one is — the tensions such a
    /// tendon pulls with are known only as the run finds them, and are checked then
    /// ([`Self::found_tensions_outside`]). An empty `driven` drives every tendon by its tension.
    pub fn check_signal(
        &self,
        times: &[f64],
        driven: &[bool],
        mut u_at: impl FnMut(f64) -> Vec<f64>,
    ) -> Result<Vec<String>, ScenarioError> {
        let is_driven = |k: usize| driven.get(k).copied().unwrap_or(false);
        let ranges: Vec<InputRange> = (self.input_range.iter())
            .filter(|r| !(0..driven.len()).any(|k| is_driven(k) && r.parameter == tension_param(k)))
            .cloned()
            .collect();
        let held: Vec<Option<f64>> = (self.held_tensions.iter().enumerate())
            .map(|(k, h)| if is_driven(k) { None } else { *h })
            .collect();
        let mut outside = signal_outside(&ranges, &held, times, &mut u_at);
        let any_driven = driven.iter().any(|&d| d);
        if let (true, false, Some(joint)) = (outside.is_empty(), any_driven, &self.joint) {
            let farthest = (times.iter())
                .filter_map(|&t| joint.outside(&u_at(t)).map(|(d, why)| (d, t, why)))
                // the first time of the largest distance
                .reduce(|a, b| if b.0 > a.0 { b } else { a });
            if let Some((_, t, why)) = farthest {
                outside.push(format!("at t = {} s {why}", shown_time(t)));
            }
        }
        if outside.is_empty() {
            return Ok(vec![]);
        }
        if !self.extrapolate {
            return Err(ScenarioError::invalid(
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
        Err(ScenarioError::invalid(
            "--model",
            format!("the reduced solution {v}: {cause}"),
        ))
    }

    /// What a motion of this model should say when it was made from equilibria only: its
    /// coordinates span the static responses, and its dynamics were never compared with the
    /// full model's (an AE-1 of IV-A's equilibria vibrates at 2.36 Hz where the arm does at
    /// 1.79 Hz, docs/linearize.md; a review's POD-8 of 1500 equilibria drifted to 11.6 % L in 3 s
    /// of random steps, 0.14 % with 30 s of babbling added to its data).
    pub fn motion_note(&self) -> Option<String> {
        (self.trained_on_motion == Some(false)).then(|| {
            format!(
                "`{}` was made from equilibria only: its coordinates span the static responses, not the motions between them, so its dynamics may differ from the full model's (its frequencies, what a step excites); a dataset of motions (`gvsrom dataset --duration … --babble …`) covers them",
                self.path.display()
            )
        })
    }

    /// How far the rest coordinates ([`StrainParam::rest_coordinates`], where a simulation from
    /// rest starts) are from the straight rod: the largest `|ξ − ξ*|` over the computational points
    /// and strain components. Zero for POD (`q_r = 0`); for an autoencoder, its reconstruction error
    /// of the straight rod, large when the training data lack it (e.g. all sag under gravity).
    pub fn rest_strain_offset(&self) -> f64 {
        let m = &self.model;
        let mut ws = m.workspace();
        m.forward_pose(&m.param.rest_coordinates(), &mut ws);
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
        self.violation_of(&self.latent_range, q)
    }

    /// [`Self::range_violation`] for a POD model's [`Self::data_range`]: where its run has left the
    /// snapshots it was made from (the mechanics are the projection's there, unchecked by data).
    pub fn data_range_violation(&self, q: &[f64]) -> Option<String> {
        self.violation_of(&self.data_range, q)
    }

    fn violation_of(&self, range: &[[f64; 2]], q: &[f64]) -> Option<String> {
        outside_range(range, q).map(|d| {
            let (v, [lo, hi]) = (q[d], range[d]);
            // six decimals as the range, in exponent form far from it (not 300 digits for 1e300)
            let v = match v.abs() < 1e15 {
                true => format!("{v:.6}"),
                false => gvs::error::fmt_value(v),
            };
            format!(
                "q_r[{d}] = {v} lies far outside the range of the training data [{lo:.6}, {hi:.6}] of `{}`",
                self.path.display()
            )
        })
    }
}

/// The name of tendon `k`'s tension as a training input ([`InputRange::parameter`]).
fn tension_param(k: usize) -> String {
    format!("tendons.{k}.tension")
}

/// The tendon tensions of an input signal against the model's training ranges: `u_at(t)` gives
/// the tensions at time `t`, sampled at `times`. One sentence per tendon whose signal leaves its
/// range (its extreme value and when), or whose training held it fixed (`held[k]`, a tendon
/// without a range) at another value.
pub fn signal_outside(
    ranges: &[InputRange],
    held: &[Option<f64>],
    times: &[f64],
    mut u_at: impl FnMut(f64) -> Vec<f64>,
) -> Vec<String> {
    let range_of = |k: usize| {
        ranges
            .iter()
            .find(|r| r.parameter == format!("tendons.{k}.tension"))
    };
    let mut worst: Vec<Option<(f64, f64)>> = vec![];
    for &t in times {
        let u = u_at(t);
        worst.resize(worst.len().max(u.len()), None);
        for (k, &v) in u.iter().enumerate() {
            // distance outside the range, or from the held value (0 inside); keep the farthest
            let d = match (range_of(k), held.get(k).copied().flatten()) {
                (Some(r), _) if inside(r, v) => 0.0,
                (Some(r), _) => (r.min - v).max(v - r.max).max(f64::MIN_POSITIVE),
                (None, Some(h)) if at_held(v, h) => 0.0,
                (None, Some(h)) => (v - h).abs().max(f64::MIN_POSITIVE),
                (None, None) => continue,
            };
            let d = if v.is_finite() { d } else { f64::INFINITY };
            if d > 0.0 && worst[k].is_none_or(|(dw, _)| d > dw) {
                worst[k] = Some((d, t));
            }
        }
    }
    let mut out = vec![];
    for (k, w) in worst.iter().enumerate() {
        if let Some((_, t)) = w {
            let v = u_at(*t)[k];
            let how = match range_of(k) {
                Some(r) => format!("outside the training inputs [{}, {}]", r.min, r.max),
                None => format!(
                    "but training held it at {}",
                    held.get(k).copied().flatten().unwrap_or(f64::NAN)
                ),
            };
            out.push(format!(
                "the input signal's tendons.{k}.tension reaches {v} at t = {} s, {how}",
                shown_time(*t)
            ));
        }
    }
    out
}

/// A time of an input check as printed: to the picosecond, since a left limit is checked at the
/// float just below its knot (0.09999999999999999 for 0.1).
fn shown_time(t: f64) -> f64 {
    (t * 1e12).round() / 1e12
}

/// Whether the tensions `u` lie where the attach check passed the scenario's own tensions `u0`:
/// every tension that differs from `u0` is a training input (`tendons.K.tension`) inside its range.
pub fn covers(ranges: &[InputRange], u0: &[f64], u: &[f64]) -> bool {
    u.len() == u0.len()
        && u.iter().zip(u0).enumerate().all(|(k, (&v, &v0))| {
            v.to_bits() == v0.to_bits()
                || ranges
                    .iter()
                    .find(|r| tendon_input(&r.parameter) == Some(k))
                    .is_some_and(|r| inside(r, v))
        })
}

/// Index `K` of a dataset input `tendons.K.tension`; `None` for any other input.
pub fn tendon_input(path: &str) -> Option<usize> {
    use crate::scenario::{parse_path, Seg};
    let segs = parse_path(path).ok()?;
    match segs.as_slice() {
        [Seg::Key(t), Seg::Index(k), Seg::Key(f)] if t == "tendons" && f == "tension" => Some(*k),
        _ => None,
    }
}
