//! Reduction commands and reduced models on a scenario (issue 7, paper Sections III–IV):
//!
//! - [`pod`]: `gvsrom pod DATASET --modes K --out MODEL`;
//! - [`train`]: `gvsrom train DATASET --latent R --hidden-layers 3|5|7 --out MODEL`;
//! - [`attach`]: `--model MODEL` on `statics` and `simulate`: the scenario's engine with the model's
//!   strain parameterization in place of its basis (no physics re-implemented).
//!
//! POD and decoders alike act on the HOM's own basis through the least-squares projection `P` of
//! point strains onto its coefficients (`rom::reduced`): `Ψ_s(q_r) = Φ_s P V q_r` (POD, a constant
//! linear basis) or `Φ_s P D(q_r)` (autoencoder).

use crate::build::{build, Built};
use crate::dataset::{Dataset, Layout};
use crate::error::ScenarioError;
use crate::output::OutputDir;
use crate::reduced_model::{
    fnv1a64, DatasetRef, ModelLayout, ModelMeta, ModelWeights, ReducedModel, TrainingMeta,
};
use crate::scenario::Scenario;
use gvs::model::Model;
use gvs::solve::statics::{StaticsOptions, StaticsSolver};
use gvs::strain::{LinearBasis, StrainParam};
use nalgebra::{DMatrix, DVector};
use rom::nn::{Autoencoder, TrainOptions, TrainReport};
use rom::pod::Pod;
use rom::reduced::{point_matrix, projection, projection_residual, PointLayout, ReducedParam};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

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
    /// The training encodings' range per coordinate (autoencoders).
    pub latent_range: Vec<[f64; 2]>,
}

impl Reduced {
    /// Errors if `q` lies outside the training encodings' range by more than half its width in
    /// some coordinate ([`Self::range_violation`]): the decoder is extrapolating there (tanh layers
    /// saturate, `Ψ_q → 0`, and spurious equilibria appear), so the result is not to be trusted.
    pub fn check_range(&self, q: &[f64]) -> Result<(), ScenarioError> {
        match self.range_violation(q) {
            None => Ok(()),
            Some(v) => Err(invalid(
                "--model",
                format!(
                    "the reduced solution {v}: the decoder is extrapolating (the load is outside the dataset, or the model is poor)"
                ),
            )),
        }
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
fn outside_range(range: &[[f64; 2]], q: &[f64]) -> Option<usize> {
    q.iter().zip(range).position(|(v, [lo, hi])| {
        let margin = 0.5 * (hi - lo).max(1e-12);
        !(*v >= lo - margin && *v <= hi + margin)
    })
}

/// The value of a dataset input `path` in the scenario being run: tensions from `built` (they
/// include `--tension`), anything else from the scenario table.
fn input_value(built: &Built, table: Option<&toml::Table>, path: &str) -> Option<f64> {
    if let Some(k) = tendon_input(path) {
        return built.u.get(k).copied();
    }
    let segs = crate::scenario::parse_path(path).ok()?;
    match crate::scenario::lookup(table?, &segs)? {
        toml::Value::Float(v) => Some(*v),
        toml::Value::Integer(v) => Some(*v as f64),
        _ => None,
    }
}

/// The initial guess of a reduced statics solve at the scenario's inputs, from the model's anchors
/// ([`anchor_guess`]).
fn initial_guess(
    built: &Built,
    table: Option<&toml::Table>,
    model: &ReducedModel,
) -> Option<DVector<f64>> {
    let a = model.anchors.as_ref()?;
    let names = &model.meta.anchor_parameters;
    let x: Vec<f64> = names
        .iter()
        .map(|p| input_value(built, table, p))
        .collect::<Option<_>>()?;
    anchor_guess(&a.inputs, &a.latent, names.len(), model.meta.latent, &x)
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
fn local_linear(
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

/// Index `K` of a dataset input `tendons.K.tension`; `None` for any other input.
fn tendon_input(path: &str) -> Option<usize> {
    let segs = crate::scenario::parse_path(path).ok()?;
    match segs.as_slice() {
        [crate::scenario::Seg::Key(t), crate::scenario::Seg::Index(k), crate::scenario::Seg::Key(f)]
            if t == "tendons" && f == "tension" =>
        {
            Some(*k)
        }
        _ => None,
    }
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
/// [`ANCHOR_MAX_ITERATIONS`] iterations. A solution is kept if `accept` takes it (e.g. inside the
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

fn invalid(field: &str, message: impl Into<String>) -> ScenarioError {
    ScenarioError::invalid(field, message)
}

/// The HOM a dataset was generated on (its scenario TOML, as stored).
pub fn dataset_scenario(ds: &Dataset) -> Result<Built, ScenarioError> {
    let s = Scenario::from_toml(&ds.meta.scenario, &ds.meta.scenario_toml, &[])?;
    build(&s)
}

/// The point layout of `built` in `rom`'s terms, and `Φ̄` and `P` of its basis.
fn projection_of(
    built: &Built,
) -> Result<(PointLayout, DMatrix<f64>, DMatrix<f64>), ScenarioError> {
    let layout = PointLayout::active_in(&built.model.param, &built.model.disc);
    let pm = point_matrix(&built.model.param, &layout);
    let p = projection(&pm).map_err(|e| invalid("basis", e.to_string()))?;
    Ok((layout, pm, p))
}

/// The usable rows of a dataset (status ok), row-major, and their count; an error if none.
fn snapshot_rows(ds: &Dataset, option: &str) -> Result<(Vec<f64>, usize), ScenarioError> {
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
    Ok((x, rows.len()))
}

fn model_layout(ds: &Dataset, built: &Built) -> ModelLayout {
    ModelLayout {
        scenario: ds.meta.scenario.clone(),
        scenario_toml: ds.meta.scenario_toml.clone(),
        strain_x: ds.meta.strain_x.clone(),
        active: ds.meta.components.clone(),
        hom_dof: built.model.n_dof(),
    }
}

fn dataset_ref(dir: &Path, rows: usize) -> Result<DatasetRef, ScenarioError> {
    let bytes = std::fs::read(dir.join("strain.npy"))
        .map_err(|e| invalid("DATASET", format!("cannot read strain.npy: {e}")))?;
    Ok(DatasetRef {
        path: dir.display().to_string(),
        strain_hash: fnv1a64(&bytes),
        rows,
    })
}

/// What `gvsrom pod` reports.
pub struct PodSummary {
    pub path: PathBuf,
    pub rows: usize,
    pub features: usize,
    pub modes: usize,
    pub captured_energy: f64,
    pub singular_values: Vec<f64>,
    pub numerical_rank: usize,
    /// As [`TrainSummary::anchor_equilibria`] and [`TrainSummary::anchor_time_s`].
    pub anchor_equilibria: usize,
    pub anchor_time_s: f64,
}

/// POD of a dataset's strain snapshots, `modes` modes, saved as a model at `out`.
pub fn pod(
    dataset: &Path,
    modes: usize,
    out: &Path,
    force: bool,
) -> Result<PodSummary, anyhow::Error> {
    let ds = Dataset::load(dataset)?;
    let built = dataset_scenario(&ds)?;
    projection_of(&built)?; // the HOM basis must be recoverable from point strains
    let (x, rows) = snapshot_rows(&ds, "DATASET")?;
    let features = ds.row_len();
    let dir = OutputDir::create("--out", out, crate::reduced_model::MODEL_FORMAT, force)?;
    let pod = Pod::compute(&x, features, modes).map_err(|e| invalid("--modes", e.to_string()))?;
    let energy = pod.captured_energy();
    // anchors: each sample's POD coordinates Vᵀx, then the POD-ROM's own equilibria
    let latent = pod.encode_rows(&x);
    let meta = ModelMeta {
        kind: "pod".into(),
        latent: modes,
        layout: model_layout(&ds, &built),
        dataset: dataset_ref(dataset, rows)?,
        rest: vec![0.0; modes],
        latent_range: vec![],
        anchor_parameters: ds.meta.parameters.clone(),
        anchor_equilibria: 0,
        captured_energy: Some(energy[modes - 1]),
        training: None,
        projection_residual: 0.0,
        crate_version: env!("CARGO_PKG_VERSION").into(),
    };
    let mut model = ReducedModel {
        meta,
        weights: ModelWeights::Pod {
            modes: pod.modes.clone(),
            singular_values: pod.singular_values.clone(),
        },
        anchors: Some(crate::reduced_model::Anchors {
            n: rows,
            inputs: sample_inputs(&ds),
            latent,
        }),
    };
    let t_anchors = std::time::Instant::now();
    model.meta.anchor_equilibria = equilibrium_anchors(&built, &ds, &mut model)?;
    let anchor_time_s = t_anchors.elapsed().as_secs_f64();
    let path = model.save(
        dir,
        &[
            ("singular_values", &pod.singular_values),
            ("captured_energy", &energy),
        ],
    )?;
    Ok(PodSummary {
        path,
        rows,
        features,
        modes,
        captured_energy: energy[modes - 1],
        numerical_rank: pod.rank(1e-12),
        singular_values: pod.singular_values,
        anchor_equilibria: model.meta.anchor_equilibria,
        anchor_time_s,
    })
}

/// What `gvsrom train` reports.
pub struct TrainSummary {
    pub path: PathBuf,
    pub rows: usize,
    pub features: usize,
    pub report: TrainReport,
    pub encoder_sizes: Vec<usize>,
    /// The rest coordinates: the encoding of the straight rod (`ξ = ξ*`) when it was trained in
    /// ([`zero_anchor_rows`]), else of the sample closest to it.
    pub rest: Vec<f64>,
    /// `‖D(rest)‖`: how far the rest coordinates decode from the straight rod (all points and
    /// components, strain units).
    pub rest_residual: f64,
    /// Copies of the zero-strain snapshot among the training rows.
    pub zero_anchor_rows: usize,
    pub projection_residual: f64,
    /// How many of the `rows` anchors are the reduced model's own equilibria, and the time their
    /// solves took.
    pub anchor_equilibria: usize,
    pub anchor_time_s: f64,
}

/// How a snapshot feature's error weighs in the autoencoder's training loss (`gvsrom train --loss`).
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Default,
    serde::Serialize,
    serde::Deserialize,
    clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Loss {
    /// Each feature standardized by its own spread: every point and component weighs the same
    /// relative to its own variation, whatever its physical magnitude.
    Standardized,
    /// The physical mean squared error, every feature with weight 1 (the RMSE of Table I).
    Physical,
    /// The strain-energy norm: feature (point j, component a) weighted by the section stiffness
    /// `Σ_s,aa` at point j (not by the quadrature weight, under which the kinematic points would
    /// weigh nothing). Errors in stiff shear and elongation weigh what they cost in elastic force.
    /// The default: the reduced model feels strain errors through exactly this norm.
    #[default]
    Energy,
}

impl Loss {
    /// The name used on the command line and in `meta.json`.
    pub fn name(self) -> &'static str {
        match self {
            Loss::Standardized => "standardized",
            Loss::Physical => "physical",
            Loss::Energy => "energy",
        }
    }

    /// The per-feature weighting of the point layout `layout` of `built`.
    fn weighting(self, built: &Built, layout: &PointLayout) -> rom::nn::Weighting {
        use rom::nn::Weighting;
        match self {
            Loss::Standardized => Weighting::Standardize,
            Loss::Physical => Weighting::Physical(vec![1.0; layout.len()]),
            Loss::Energy => Weighting::Physical(
                (0..layout.n_points)
                    .flat_map(|i| {
                        let es = built.model.section(i).es;
                        layout.active.iter().map(move |&a| es[a])
                    })
                    .collect(),
            ),
        }
    }
}

/// Trains an autoencoder on a dataset's snapshots and saves it at `out`. `progress(epoch, train,
/// validation)` is called after every epoch; `Break` stops training early (the best weights so far
/// are kept and saved, marked by the stop reason).
pub fn train(
    dataset: &Path,
    options: &TrainOptions,
    loss: Loss,
    out: &Path,
    force: bool,
    progress: &mut dyn FnMut(usize, f64, Option<f64>) -> ControlFlow<()>,
) -> Result<TrainSummary, anyhow::Error> {
    let ds = Dataset::load(dataset)?;
    let built = dataset_scenario(&ds)?;
    let (layout, pm, p) = projection_of(&built)?;
    let (x, rows) = snapshot_rows(&ds, "DATASET")?;
    let features = ds.row_len();
    let options = &TrainOptions {
        weighting: loss.weighting(&built, &layout),
        ..options.clone()
    };
    let dir = OutputDir::create("--out", out, crate::reduced_model::MODEL_FORMAT, force)?;
    // the zero-strain anchor of trajectory data: the straight rod, where simulations from rest
    // start, joins the training rows so that a latent point decodes to it
    let anchor_rows = zero_anchor_rows(rows, ds.meta.dynamic.is_some());
    let training: std::borrow::Cow<[f64]> = match anchor_rows {
        0 => (&x[..]).into(),
        k => {
            let mut t = Vec::with_capacity((rows + k) * features);
            t.extend_from_slice(&x);
            t.resize((rows + k) * features, 0.0);
            t.into()
        }
    };
    let (ae, report) =
        Autoencoder::train(&training, features, options, progress).map_err(|e| train_error(&e))?;
    drop(training);
    // one encoding per usable sample: its range, the anchors, and what the HOM basis cannot
    // represent of the reconstructions
    let mut worst = 0.0f64;
    let r = options.latent;
    let mut latent = Vec::with_capacity(rows * r);
    let mut range = vec![[f64::INFINITY, f64::NEG_INFINITY]; r];
    for row in x.chunks_exact(features) {
        let z = ae
            .encode(row)
            .map_err(|e| invalid("train", e.to_string()))?;
        let rec = ae.decode(&z).map_err(|e| invalid("train", e.to_string()))?;
        worst = worst.max(projection_residual(&pm, &p, &DVector::from_vec(rec)));
        for (d, v) in z.iter().enumerate() {
            range[d][0] = range[d][0].min(*v);
            range[d][1] = range[d][1].max(*v);
        }
        latent.extend_from_slice(&z);
    }
    // the rest coordinates: with the zero-strain anchor the encoding of the straight rod, else
    // that of the sample closest to it (equilibria under gravity: the straight rod is off their
    // manifold and its encoding may lie outside the data's range); and how far they decode from it
    let zero = vec![0.0; features];
    let straightest = || {
        x.chunks_exact(features)
            .min_by(|a, b| {
                let n = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
                n(a).total_cmp(&n(b))
            })
            .expect("at least one usable row")
    };
    let rest = ae
        .encode(if anchor_rows > 0 {
            &zero
        } else {
            straightest()
        })
        .map_err(|e| invalid("train", e.to_string()))?;
    let rest_decoded = ae
        .decode(&rest)
        .map_err(|e| invalid("train", e.to_string()))?;
    let rest_residual = rest_decoded.iter().map(|v| v * v).sum::<f64>().sqrt();
    let rest = DVector::from_vec(rest);
    let meta = ModelMeta {
        kind: "autoencoder".into(),
        latent: options.latent,
        layout: model_layout(&ds, &built),
        dataset: dataset_ref(dataset, rows)?,
        rest: rest.iter().copied().collect(),
        latent_range: range,
        anchor_parameters: ds.meta.parameters.clone(),
        anchor_equilibria: 0,
        captured_energy: None,
        training: Some(TrainingMeta {
            hidden_layers: options.hidden_layers,
            encoder_sizes: ae.encoder().layer_sizes().to_vec(),
            decoder_sizes: ae.decoder().layer_sizes().to_vec(),
            lambda: options.lambda,
            epochs: options.epochs,
            batch_size: options.batch_size,
            learning_rate: options.learning_rate,
            validation_fraction: options.validation_fraction,
            patience: options.patience,
            seed: options.seed,
            loss: Some(loss.name().into()),
            lr_reductions: Some(options.lr_reductions),
            zero_anchor_rows: Some(anchor_rows),
            lbfgs_iterations: Some(options.fine_tune.lbfgs_iterations()),
            epochs_run: report.epochs_run,
            best_epoch: report.best_epoch,
            stop: format!("{:?}", report.stop),
            final_train_loss: report.final_train_loss,
            final_val_loss: report.final_val_loss,
            final_train_rmse: report.final_train_rmse,
            final_val_rmse: report.final_val_rmse,
            wall_time_s: report.wall_time.as_secs_f64(),
        }),
        projection_residual: worst,
        crate_version: env!("CARGO_PKG_VERSION").into(),
    };
    let encoder_sizes = ae.encoder().layer_sizes().to_vec();
    let mut model = ReducedModel {
        meta,
        weights: ModelWeights::Autoencoder(ae),
        anchors: Some(crate::reduced_model::Anchors {
            n: rows,
            inputs: sample_inputs(&ds),
            latent,
        }),
    };
    let t_anchors = std::time::Instant::now();
    // (an interrupted run is saved at once, with the encodings)
    if report.stop != rom::nn::StopReason::Interrupted {
        model.meta.anchor_equilibria = equilibrium_anchors(&built, &ds, &mut model)?;
    }
    let anchor_time_s = t_anchors.elapsed().as_secs_f64();
    let anchor_equilibria = model.meta.anchor_equilibria;
    let path = model.save(
        dir,
        &[
            ("train_loss", &report.train_loss),
            ("val_loss", &report.val_loss),
        ],
    )?;
    Ok(TrainSummary {
        path,
        rows,
        features,
        report,
        encoder_sizes,
        rest: rest.iter().copied().collect(),
        rest_residual,
        zero_anchor_rows: anchor_rows,
        projection_residual: worst,
        anchor_equilibria,
        anchor_time_s,
    })
}

/// Copies of the zero-strain snapshot added to `rows` training rows: for trajectory data (which
/// start from the straight rod at rest, as every simulation from rest does) 1 % of the rows and at
/// least 10, so that the straight rod is a point of the learned manifold and not just one sample
/// among thousands; none for equilibria, whose manifold need not contain the straight rod (under
/// gravity no equilibrium is straight, and a 1-D decoder forced through it bends away from the data).
pub fn zero_anchor_rows(rows: usize, dynamic: bool) -> usize {
    if dynamic {
        (rows / 100).max(10)
    } else {
        0
    }
}

/// The inputs of the usable samples (status ok), row-major (`n × k`): the anchors' inputs.
fn sample_inputs(ds: &Dataset) -> Vec<f64> {
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
fn equilibrium_anchors(
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

/// A training error named by the command-line option it comes from.
fn train_error(e: &rom::nn::NnError) -> ScenarioError {
    use rom::nn::NnError;
    let option = match e {
        NnError::InvalidLatent { .. } => "--latent".to_string(),
        NnError::InvalidHiddenLayers { .. } => "--hidden-layers".to_string(),
        NnError::InvalidOption { field, .. } => format!("--{}", field.replace('_', "-")),
        NnError::EmptyData | NnError::NonFiniteData { .. } => "DATASET".to_string(),
        _ => "train".to_string(),
    };
    invalid(&option, e.to_string())
}

/// Checks that `model` was learned on the layout of `built` (points, active components, HOM size).
fn check_layout(built: &Built, model: &ReducedModel, path: &Path) -> Result<(), ScenarioError> {
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
fn reduced_model(
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
/// for the initial guess.
pub fn attach(
    built: &mut Built,
    table: Option<&toml::Table>,
    dir: &Path,
) -> Result<(), anyhow::Error> {
    let model = ReducedModel::load(dir)?;
    check_layout(built, &model, dir)?;
    let reduced = reduced_model(built, &model)?;
    let initial = initial_guess(built, table, &model);
    built.reduced = Some(Reduced {
        model: reduced,
        kind: model.meta.kind.clone(),
        path: dir.to_path_buf(),
        initial,
        latent_range: model.meta.latent_range.clone(),
    });
    Ok(())
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
