//! Solving the samples of a static dataset, chunk by chunk.
//!
//! Samples are cut into chunks of `chunk_size` consecutive plan indices; the chunks are independent
//! (each starts from the straight configuration), so they run in parallel and the results do not
//! depend on the thread count. Within a chunk the samples are solved along a greedy nearest-neighbour
//! chain in normalised parameter space (starting from the sample closest to zero), and each solve is
//! warm-started from the nearest already solved sample of the chunk: one full-load dogleg solve from
//! its `q`, without ramping. If that fails, the sample is solved again from the straight
//! configuration with the scenario's own solver options (load ramping). A sample that fails both is
//! recorded with the reason. The chain and the warm starts are [`crate::statics`]'s, which solves a
//! batch of tensions (`statics_batch` in Python) the same way.

use super::plan::Plan;
use crate::build::Built;
pub use crate::layout::Layout;
use crate::scenario::{apply_override, from_table};
use crate::statics::{self, warm_or_ramp};
use gvs::model::Model;
use gvs::solve::statics::{StaticsError, StaticsSolution, StaticsSolver};
use gvs::solve::StopCheck;
use gvs::strain::LinearBasis;
use nalgebra::DVector;
use toml::Table;

/// Status of a sample in `status.npy`.
pub const STATUS_OK: u8 = 0;
pub const STATUS_FAILED: u8 = 1;
pub const STATUS_NOT_COMPUTED: u8 = 2;

/// One solved (or failed) sample.
#[derive(Debug, Clone)]
pub struct SampleResult {
    pub status: u8,
    /// ξ − ξ* at the points, active components, point-major (NaN if failed).
    pub strain: Vec<f64>,
    pub q: Vec<f64>,
    pub tip_position: [f64; 3],
    /// Row-major 3×3.
    pub tip_rotation: [f64; 9],
    /// The tendons' lengths ℓ_k(q) \[m\] ([`gvs::model::Model::tendon_lengths`]; NaN if failed).
    pub tendon_lengths: Vec<f64>,
    pub iterations: u32,
    pub residual: f64,
    pub warm_started: bool,
    pub reason: Option<String>,
}

impl SampleResult {
    pub fn missing(layout: &Layout, status: u8, reason: Option<String>) -> Self {
        SampleResult {
            status,
            strain: vec![f64::NAN; layout.row_len()],
            q: vec![f64::NAN; layout.n_dof],
            tip_position: [f64::NAN; 3],
            tip_rotation: [f64::NAN; 9],
            tendon_lengths: vec![f64::NAN; layout.n_tendons],
            iterations: 0,
            residual: f64::NAN,
            warm_started: false,
            reason,
        }
    }
}

/// Everything the chunks share (read-only).
pub struct Generator<'a> {
    pub base: &'a Built,
    /// The scenario table after `--set`, for parameters other than tensions.
    pub table: &'a Table,
    pub plan: &'a Plan,
    /// `samples × d` plan values.
    pub values: &'a [f64],
    pub layout: &'a Layout,
    pub chunk_size: usize,
}

/// The model a sample is solved on: the shared one with new tensions, or one rebuilt from the table.
enum Setup {
    /// New tensions on the scenario's model and loads.
    Shared(Vec<f64>),
    /// New tensions and loads on the scenario's model.
    Loads(Vec<f64>, gvs::loads::Loads),
    /// A model rebuilt from the scenario with the sample's values.
    Rebuilt(Box<Built>),
}

impl Generator<'_> {
    pub fn n_chunks(&self) -> usize {
        self.plan.samples.div_ceil(self.chunk_size)
    }

    pub fn chunk_range(&self, c: usize) -> std::ops::Range<usize> {
        c * self.chunk_size..((c + 1) * self.chunk_size).min(self.plan.samples)
    }

    fn row(&self, k: usize) -> &[f64] {
        let d = self.plan.parameters.len();
        &self.values[k * d..(k + 1) * d]
    }

    /// `true` when every parameter is a tendon tension (no rebuild needed).
    fn shared_model(&self) -> bool {
        self.plan.parameters.iter().all(|p| p.tendon.is_some())
    }

    /// `true` when every parameter is a tension or a load that does not move computational points
    /// (everything under `loads.` except point-load abscissae `loads.point.K.x`).
    fn loads_only(&self) -> bool {
        self.plan.parameters.iter().all(|p| {
            p.tendon.is_some()
                || (p.path.starts_with("loads.")
                    && !(p.path.starts_with("loads.point.") && p.path.ends_with(".x")))
        })
    }

    fn setup(&self, k: usize) -> Result<Setup, String> {
        let row = self.row(k);
        let mut u = self.base.u.clone();
        for (p, v) in self.plan.parameters.iter().zip(row) {
            if let Some(t) = p.tendon {
                u[t] = *v;
            }
        }
        if self.shared_model() {
            return Ok(Setup::Shared(u));
        }
        let mut table = self.table.clone();
        for (p, v) in self.plan.parameters.iter().zip(row) {
            if p.tendon.is_none() {
                apply_override(&mut table, &format!("{}={v}", p.path))
                    .map_err(|e| e.to_string())?;
            }
        }
        let mut scenario = from_table(table).map_err(|e| e.to_string())?;
        if self.loads_only() {
            let loads = crate::build::loads(&scenario, self.base.model.rod.length())
                .map_err(|e| e.to_string())?;
            return Ok(Setup::Loads(u, loads));
        }
        for (p, v) in self.plan.parameters.iter().zip(row) {
            if let Some(t) = p.tendon {
                scenario.tendons[t].tension = *v;
            }
        }
        scenario.name = Some(self.base.name.clone());
        let built = crate::build(&scenario).map_err(|e| e.to_string())?;
        let layout = Layout::of(&built);
        if layout.n_dof != self.layout.n_dof
            || layout.strain_x.len() != self.layout.strain_x.len()
            || layout
                .strain_x
                .iter()
                .zip(&self.layout.strain_x)
                .any(|(a, b)| a.to_bits() != b.to_bits())
        {
            return Err(
                "these values change the model's coordinates or computational points, so the sample would not fit the dataset's columns"
                    .into(),
            );
        }
        Ok(Setup::Rebuilt(Box::new(built)))
    }

    /// The tendons' lengths of sample `k` at its solution `q` (NaN unless `status` is ok): for a
    /// dataset resumed from one written before the lengths were recorded.
    pub fn tendon_lengths_at(&self, k: usize, status: u8, q: &[f64]) -> Vec<f64> {
        let q = DVector::from_column_slice(q);
        let at = |m: &Model<LinearBasis>| m.tendon_lengths(&q, &mut m.workspace());
        match (status, self.setup(k)) {
            (STATUS_OK, Ok(Setup::Shared(_) | Setup::Loads(..))) => at(&self.base.model),
            (STATUS_OK, Ok(Setup::Rebuilt(b))) => at(&b.model),
            _ => vec![f64::NAN; self.layout.n_tendons],
        }
    }

    /// Solves chunk `c`; results in plan order. `stop` is polled before every load stage of every
    /// solve: `None` if it asked to stop (the chunk is then not done and none of its results kept).
    /// The samples are solved along the chunk's warm-start chain ([`statics::along_chain`],
    /// [`statics::warm_or_ramp`]), as [`statics::solve_batch`] solves a batch of tensions.
    pub fn chunk(&self, c: usize, stop: &StopCheck<'_>) -> Option<Vec<SampleResult>> {
        let range = self.chunk_range(c);
        let d = self.plan.parameters.len();
        let ranges: Vec<[f64; 2]> = self.plan.parameters.iter().map(|p| [p.lo, p.hi]).collect();
        let base = &self.base.model;
        let mut shared = StaticsSolver::new(base, self.base.options.clone());
        let mut ws = base.workspace();
        let values = &self.values[range.start * d..range.end * d];
        statics::along_chain(values, &ranges, range.len(), |i, warm| {
            let k = range.start + i;
            let options = &self.base.options;
            let result = match self.setup(k) {
                Err(reason) => SampleResult::missing(self.layout, STATUS_FAILED, Some(reason)),
                Ok(Setup::Shared(u)) => {
                    let r = warm_or_ramp(&mut shared, options, &u, &self.base.loads, warm, stop)?;
                    record(base, &mut ws, self.layout, r)
                }
                Ok(Setup::Loads(u, loads)) => {
                    let r = warm_or_ramp(&mut shared, options, &u, &loads, warm, stop)?;
                    record(base, &mut ws, self.layout, r)
                }
                Ok(Setup::Rebuilt(b)) => {
                    let mut solver = StaticsSolver::new(&b.model, b.options.clone());
                    let r = warm_or_ramp(&mut solver, &b.options, &b.u, &b.loads, warm, stop)?;
                    let mut ws = b.model.workspace();
                    record(&b.model, &mut ws, self.layout, r)
                }
            };
            let q = (result.status == STATUS_OK).then(|| DVector::from_column_slice(&result.q));
            Some((result, q))
        })
    }
}

/// The sample's row values at a solution (forward kinematics at `q`).
fn record(
    model: &Model<LinearBasis>,
    ws: &mut gvs::model::Workspace,
    layout: &Layout,
    r: Result<(StaticsSolution, bool), StaticsError>,
) -> SampleResult {
    let (sol, warm) = match r {
        Ok(s) => s,
        Err(e) => return SampleResult::missing(layout, STATUS_FAILED, Some(e.to_string())),
    };
    // an equilibrium the rod cannot rest on is no snapshot of it
    if let Some(w2) = sol.divergence {
        return SampleResult::missing(layout, STATUS_FAILED, Some(unstable_reason(w2)));
    }
    model.forward_pose(&sol.q, ws);
    let xi = model.point_strains(ws);
    let mut strain = Vec::with_capacity(layout.row_len());
    for (j, x) in xi.iter().enumerate() {
        let dev = x - model.xi_star(j);
        strain.extend(layout.active.iter().map(|&a| dev[a]));
    }
    let tip = model.tip_pose(ws);
    let mut tendon_lengths = vec![0.0; model.n_actuators()];
    model.tendon_lengths_after_forward(ws, &mut tendon_lengths);
    SampleResult {
        status: STATUS_OK,
        strain,
        q: sol.q.iter().copied().collect(),
        tip_position: [tip.pos[0], tip.pos[1], tip.pos[2]],
        tip_rotation: std::array::from_fn(|i| tip.rot[(i / 3, i % 3)]),
        tendon_lengths,
        iterations: sol.iterations as u32,
        residual: sol.residual_norm,
        warm_started: warm,
        reason: None,
    }
}

/// Why a sample whose only equilibrium found diverges is failed.
pub fn unstable_reason(w2: f64) -> String {
    format!(
        "only an unstable equilibrium was found (M⁻¹K_T has the real eigenvalue ω² = {} 1/s² < 0: the rod moves away from it), none connected to the straight rod by a stable path",
        gvs::error::fmt_sci(w2, 3)
    )
}
