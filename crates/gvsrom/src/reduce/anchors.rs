//! Anchors: training samples kept in a model as (inputs, reduced coordinates) pairs, the initial
//! guesses of reduced statics solves, and their replacement by the reduced model's own equilibria.

use crate::build::reduced::{tendon_input, GuessAt};
use crate::build::Built;
use crate::reduced_model::ReducedModel;
use gvs::model::Model;
use gvs::solve::statics::{StaticsOptions, StaticsSolver};
use gvs::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// The value of a dataset input `path` in the scenario being run: tensions from `built` (they
/// include `--tension`), anything else from the scenario table.
pub(super) fn input_value(built: &Built, table: Option<&toml::Table>, path: &str) -> Option<f64> {
    if let Some(k) = tendon_input(path) {
        return built.u.get(k).copied();
    }
    crate::scenario::number_at(table?, path)
}

/// The initial guesses of a reduced statics solve at any tendon tensions: the model's anchors
/// ([`anchor_guess`]) with the scenario's values of their inputs other than tensions.
#[derive(Debug, Clone)]
pub struct InitialGuess {
    anchors: crate::reduced_model::Anchors,
    /// Per anchor input: the tendon whose tension it is, or its value in the scenario.
    inputs: Vec<GuessInput>,
    /// Reduced coordinates r.
    r: usize,
}

/// Where the value of one anchor input comes from in a run: a tendon's tension (which may vary,
/// `--tension` or a signal) or the scenario's fixed value.
#[derive(Debug, Clone, Copy)]
pub(super) enum GuessInput {
    Tension(usize),
    Value(f64),
}

impl GuessInput {
    /// Per anchor parameter of `model`, where its value comes from in the scenario of `built`
    /// (its TOML `table`, for inputs other than tensions); `None` if such an input has no
    /// numeric value there.
    pub(super) fn of_model(
        built: &Built,
        table: Option<&toml::Table>,
        model: &ReducedModel,
    ) -> Option<Vec<GuessInput>> {
        model
            .meta
            .anchor_parameters
            .iter()
            .map(|p| match tendon_input(p) {
                Some(k) => Some(GuessInput::Tension(k)),
                None => input_value(built, table, p).map(GuessInput::Value),
            })
            .collect()
    }

    /// The values of `inputs` at the tensions `u` (one per tendon); `None` if a tendon has none.
    pub(super) fn values(inputs: &[GuessInput], u: &[f64]) -> Option<Vec<f64>> {
        inputs
            .iter()
            .map(|i| match *i {
                GuessInput::Tension(k) => u.get(k).copied(),
                GuessInput::Value(v) => Some(v),
            })
            .collect()
    }
}

impl InitialGuess {
    /// The guesses of `model` in the scenario of `built` (its TOML `table`, for inputs other than
    /// tensions); `None` without anchors or if such an input has no numeric value in the scenario.
    pub(super) fn of(
        built: &Built,
        table: Option<&toml::Table>,
        model: &ReducedModel,
    ) -> Option<InitialGuess> {
        let inputs = GuessInput::of_model(built, table, model)?;
        Some(InitialGuess {
            anchors: model.anchors.clone()?,
            inputs,
            r: model.meta.latent,
        })
    }
}

impl GuessAt for InitialGuess {
    /// The guess at the tensions `u` (one per tendon); `None` if an input's tendon has none.
    fn at(&self, u: &[f64]) -> Option<DVector<f64>> {
        let x = GuessInput::values(&self.inputs, u)?;
        let a = &self.anchors;
        anchor_guess(&a.inputs, &a.latent, self.inputs.len(), self.r, &x)
    }
}

/// An initial guess at the inputs `x` (k values) from anchors: `inputs` (`n × k`) and their reduced
/// coordinates `latent` (`n × r`), both row-major.
///
/// With one input and anchors on both sides of `x`, the linear interpolation between the nearest
/// anchor below and the nearest above: for anchors that are the reduced model's own equilibria
/// (see [`solve_anchors`]) its error is second order in their spacing, where the nearest anchor's
/// is first order, and one Newton step usually reaches the tolerance (IV-A: 3 residuals instead of
/// 4). With several inputs, the local linear fit to the nearest anchors where it is defined
/// (`local_linear`), else the nearest anchor; distances with each input scaled by its largest
/// magnitude. `None` without anchors or inputs.
pub fn anchor_guess(
    inputs: &[f64],
    latent: &[f64],
    k: usize,
    r: usize,
    x: &[f64],
) -> Option<DVector<f64>> {
    let n = inputs.len().checked_div(k).unwrap_or(0);
    if n == 0 || x.len() != k || latent.len() != n * r {
        return None;
    }
    let row = |i: usize| DVector::from_column_slice(&latent[i * r..(i + 1) * r]);
    if k == 1 {
        let x = x[0];
        // nearest anchor at or below x, nearest at or above (first of equal inputs)
        let below = (0..n)
            .filter(|&i| inputs[i] <= x)
            .min_by(|&a, &b| (x - inputs[a]).total_cmp(&(x - inputs[b])).then(a.cmp(&b)));
        let above = (0..n)
            .filter(|&i| inputs[i] >= x)
            .min_by(|&a, &b| (inputs[a] - x).total_cmp(&(inputs[b] - x)).then(a.cmp(&b)));
        if let (Some(lo), Some(hi)) = (below, above) {
            let (xl, xh) = (inputs[lo], inputs[hi]);
            if xh > xl {
                let w = (x - xl) / (xh - xl);
                return Some(row(lo) * (1.0 - w) + row(hi) * w);
            }
            return Some(row(lo));
        }
    }
    let mut scale = vec![0.0f64; k];
    for a in inputs.chunks_exact(k) {
        for (d, v) in a.iter().enumerate() {
            scale[d] = scale[d].max(v.abs()).max(1e-300);
        }
    }
    let dist: Vec<f64> = inputs
        .chunks_exact(k)
        .map(|a| {
            a.iter()
                .zip(x)
                .zip(&scale)
                .map(|((v, w), s)| ((v - w) / s).powi(2))
                .sum::<f64>()
        })
        .collect();
    // the 2(k + 1) nearest anchors in order (local_linear's), without sorting all n
    let by_dist = |a: &usize, b: &usize| dist[*a].total_cmp(&dist[*b]).then(a.cmp(b));
    let mut order: Vec<usize> = (0..n).collect();
    let m = (2 * (k + 1)).min(n);
    if m < n {
        order.select_nth_unstable_by(m, by_dist);
        order.truncate(m);
    }
    order.sort_by(by_dist);
    let nearest = *order.first()?;
    if k > 1 {
        if let Some(z) = local_linear(inputs, latent, k, r, x, &scale, &order) {
            return Some(z);
        }
    }
    Some(row(nearest))
}

/// The value at `x` of the least-squares linear fit `z ≈ z₀ + G (x' − x)` to the `2(k + 1)`
/// anchors nearest to `x` (`order`: anchors by distance): a first-order prediction, as the
/// one-input interpolation. `None` if there are too few anchors, if `x` lies outside their bounding
/// box (no extrapolation) or if they do not span the inputs (rank < k + 1).
pub(super) fn local_linear(
    inputs: &[f64],
    latent: &[f64],
    k: usize,
    r: usize,
    x: &[f64],
    scale: &[f64],
    order: &[usize],
) -> Option<DVector<f64>> {
    let m = 2 * (k + 1);
    let near = order.get(..m)?;
    for d in 0..k {
        let (lo, hi) = near
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &i| {
                (lo.min(inputs[i * k + d]), hi.max(inputs[i * k + d]))
            });
        if !(lo <= x[d] && x[d] <= hi) {
            return None;
        }
    }
    let a = DMatrix::from_fn(m, k + 1, |row, col| match col {
        0 => 1.0,
        _ => (inputs[near[row] * k + col - 1] - x[col - 1]) / scale[col - 1],
    });
    let z = DMatrix::from_fn(m, r, |row, col| latent[near[row] * r + col]);
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    if svd.rank(1e-8 * smax) < k + 1 {
        return None;
    }
    let beta = svd.solve(&z, 1e-8 * smax).ok()?;
    let z0 = beta.row(0).transpose();
    z0.iter().all(|v| v.is_finite()).then_some(z0)
}

/// How a dataset input enters an anchor's statics problem ([`solve_anchors`]).
#[derive(Debug, Clone, PartialEq)]
pub enum AnchorInput {
    /// `tendons.K.tension`: the tension of tendon `K`.
    Tension(usize),
    /// A load value that does not move computational points (`loads.…`, except a point load's
    /// abscissa `loads.point.K.x`): set in the scenario table, whose loads are built again.
    Load(String),
}

impl AnchorInput {
    /// The kind of the dataset input `path`; `None` for inputs that change the model itself
    /// (geometry, material, basis, a point load's abscissa).
    pub fn of(path: &str) -> Option<AnchorInput> {
        if let Some(k) = tendon_input(path) {
            return Some(AnchorInput::Tension(k));
        }
        let moves_points = path.starts_with("loads.point.") && path.ends_with(".x");
        (path.starts_with("loads.") && !moves_points).then(|| AnchorInput::Load(path.to_string()))
    }
}

/// The statics problem of the anchors: the scenario's tensions `u` and `loads`, changed at each
/// anchor by its inputs ([`AnchorInput`], one per input column). `table` (the scenario's TOML) and
/// `length` (the rod's) are needed for load inputs only.
pub struct AnchorProblem<'a> {
    pub u: &'a [f64],
    pub loads: &'a gvs::loads::Loads,
    pub inputs: &'a [AnchorInput],
    pub table: Option<&'a toml::Table>,
    pub length: f64,
}

impl AnchorProblem<'_> {
    /// Tensions and (if load inputs change them) loads at the inputs `x`; `None` if the loads
    /// cannot be built from these values.
    fn at(&self, x: &[f64]) -> Option<(Vec<f64>, Option<gvs::loads::Loads>)> {
        let mut u = self.u.to_vec();
        let mut table = None;
        for (input, &v) in self.inputs.iter().zip(x) {
            match input {
                AnchorInput::Tension(t) => *u.get_mut(*t)? = v,
                AnchorInput::Load(path) => {
                    let t = table.get_or_insert_with(|| self.table.cloned().unwrap_or_default());
                    crate::scenario::apply_override(t, &format!("{path}={v}")).ok()?;
                }
            }
        }
        let loads = match table {
            None => None,
            Some(t) => {
                let scenario = crate::scenario::from_table(t).ok()?;
                Some(crate::build::loads(&scenario, self.length).ok()?)
            }
        };
        Some((u, loads))
    }
}

/// Largest number of dogleg iterations of an anchor's solve ([`solve_anchors`]).
const ANCHOR_MAX_ITERATIONS: usize = 50;

/// Replaces anchors' reduced coordinates by the reduced model's own statics equilibria at their
/// inputs, where one is found; returns how many were replaced (none if the lengths do not match
/// the problem's inputs).
///
/// Anchor `i` has the inputs `inputs[i·k..(i+1)·k]` (`k = problem.inputs.len()`), and its solve
/// starts from `latent[i·r..(i+1)·r]` (the training sample's encoding) at the full load, at most
/// `ANCHOR_MAX_ITERATIONS` iterations. A solution is kept if `accept` takes it (e.g. inside the
/// training encodings' range); otherwise the encoding stays. An encoding lies off the reduced
/// model's equilibrium by the encoder's error (IV-A: 2e-3 in `q_r`, twice what a 1.5e-3 N
/// change of tension moves it), so equilibria are the better starts, and between two of them
/// [`anchor_guess`] interpolates to second order.
///
/// The anchors are solved in parallel (rayon), each from its own encoding: the result does not
/// depend on the thread count.
pub fn solve_anchors<P: StrainParam>(
    model: &Model<P>,
    options: &StaticsOptions,
    problem: &AnchorProblem<'_>,
    inputs: &[f64],
    latent: &mut [f64],
    accept: &(dyn Fn(&DVector<f64>) -> bool + Sync),
) -> usize {
    use rayon::prelude::*;
    let (k, r) = (problem.inputs.len(), model.n_dof());
    if k == 0 || r == 0 || inputs.len() / k != latent.len() / r {
        return 0;
    }
    let options = StaticsOptions {
        ramp_steps: 1,
        min_increment: 1.0,
        max_iterations: options.max_iterations.min(ANCHOR_MAX_ITERATIONS),
        ..options.clone()
    };
    const CHUNK: usize = 32;
    latent
        .par_chunks_mut(CHUNK * r)
        .zip(inputs.par_chunks(CHUNK * k))
        .map(|(z, x)| {
            let mut solver = StaticsSolver::new(model, options.clone());
            let mut replaced = 0;
            for (z, x) in z.chunks_exact_mut(r).zip(x.chunks_exact(k)) {
                let Some((u, loads)) = problem.at(x) else {
                    continue;
                };
                let z0 = DVector::from_column_slice(z);
                let loads = loads.as_ref().unwrap_or(problem.loads);
                if let Ok(sol) = solver.solve(&u, loads, Some(&z0)) {
                    if sol.q.iter().all(|v| v.is_finite()) && accept(&sol.q) {
                        z.copy_from_slice(sol.q.as_slice());
                        replaced += 1;
                    }
                }
            }
            replaced
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anchor_guess_interpolates_between_the_bracketing_anchors_of_one_input() {
        // unsorted anchors; latent r = 2
        let inputs = [1.0, -1.0, 0.0, 3.0];
        let latent = [10.0, 1.0, -10.0, -1.0, 0.0, 0.0, 30.0, 3.0];
        let g = anchor_guess(&inputs, &latent, 1, 2, &[0.25]).unwrap();
        assert_eq!(g.as_slice(), &[2.5, 0.25]);
        // between 1 and 3: w = 0.5
        let g = anchor_guess(&inputs, &latent, 1, 2, &[2.0]).unwrap();
        assert_eq!(g.as_slice(), &[20.0, 2.0]);
        // on an anchor: that anchor, exactly
        let g = anchor_guess(&inputs, &latent, 1, 2, &[-1.0]).unwrap();
        assert_eq!(g.as_slice(), &[-10.0, -1.0]);
    }

    #[test]
    fn anchor_guess_takes_the_nearest_anchor_outside_the_span_and_for_several_inputs() {
        let inputs = [1.0, -1.0, 0.0, 3.0];
        let latent = [10.0, -10.0, 0.0, 30.0];
        assert_eq!(
            anchor_guess(&inputs, &latent, 1, 1, &[5.0]).unwrap()[0],
            30.0
        );
        assert_eq!(
            anchor_guess(&inputs, &latent, 1, 1, &[-7.0]).unwrap()[0],
            -10.0
        );
        // two inputs, the second 100× larger: distances are taken in units of each input's scale
        let inputs = [0.0, 0.0, 1.0, 0.0, 0.0, 100.0];
        let latent = [1.0, 2.0, 3.0];
        // (0.6, 0) is 0.6 from anchor 1 in input 0; (0, 40) is 0.4 of the scale from anchor 0
        assert_eq!(
            anchor_guess(&inputs, &latent, 2, 1, &[0.6, 0.0]).unwrap()[0],
            2.0
        );
        assert_eq!(
            anchor_guess(&inputs, &latent, 2, 1, &[0.0, 40.0]).unwrap()[0],
            1.0
        );
    }

    #[test]
    fn anchor_guess_fits_several_inputs_linearly_inside_the_nearest_anchors() {
        // a 5 × 5 grid of two inputs, latent (r = 2) linear in them: the fit reproduces it
        let (mut inputs, mut latent) = (vec![], vec![]);
        let f = |a: f64, b: f64| [1.0 + 2.0 * a - 0.5 * b, -3.0 + 0.25 * a + 4.0 * b];
        for i in 0..5 {
            for j in 0..5 {
                let (a, b) = (i as f64, 10.0 * j as f64);
                inputs.extend([a, b]);
                latent.extend(f(a, b));
            }
        }
        let g = anchor_guess(&inputs, &latent, 2, 2, &[1.3, 27.0]).unwrap();
        let e = f(1.3, 27.0);
        assert!(
            (g[0] - e[0]).abs() < 1e-12 && (g[1] - e[1]).abs() < 1e-12,
            "{g} vs {e:?}"
        );
        // outside the anchors: the nearest one, no extrapolation
        let g = anchor_guess(&inputs, &latent, 2, 2, &[6.0, 45.0]).unwrap();
        assert_eq!(g.as_slice(), &f(4.0, 40.0));
    }

    #[test]
    fn anchor_guess_without_usable_anchors_is_none() {
        assert!(anchor_guess(&[], &[], 1, 1, &[0.0]).is_none());
        assert!(anchor_guess(&[1.0, 2.0], &[1.0], 1, 1, &[0.0]).is_none());
        assert!(anchor_guess(&[1.0, 2.0], &[1.0, 2.0], 1, 1, &[0.0, 1.0]).is_none());
        assert!(anchor_guess(&[1.0, 2.0], &[1.0, 2.0], 0, 1, &[]).is_none());
    }

    #[test]
    fn anchor_inputs_are_recognised_by_their_path() {
        assert_eq!(
            AnchorInput::of("tendons.3.tension"),
            Some(AnchorInput::Tension(3))
        );
        assert_eq!(AnchorInput::of("tendons.0.friction"), None);
        assert_eq!(
            AnchorInput::of("loads.distributed.0.magnitude"),
            Some(AnchorInput::Load("loads.distributed.0.magnitude".into()))
        );
        assert_eq!(
            AnchorInput::of("loads.point.0.force.2"),
            Some(AnchorInput::Load("loads.point.0.force.2".into()))
        );
        // a point load's abscissa moves the computational points; geometry changes the model
        assert_eq!(AnchorInput::of("loads.point.0.x"), None);
        assert_eq!(AnchorInput::of("divisions.0.length"), None);
    }
}
