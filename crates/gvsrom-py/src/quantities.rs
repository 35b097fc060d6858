//! Model quantities at a given state, for the model that runs (the HOM, or the reduced model
//! attached): forward kinematics, the geometric Jacobians, the point velocities, `M(q)`, the
//! static residual `R(q) = −K₁(q) + F(q) + B(q)u` and its Jacobian. Each is one engine call.

use gvs::model::{Model, Workspace};
use gvs::strain::StrainParam;
use gvsrom::{Built, ScenarioError};
use nalgebra::{DMatrix, DVector};
use std::sync::Mutex;

/// `$body` with `$m` bound to the model that runs (generic over its parameterization).
macro_rules! on_model {
    ($built:expr, $m:ident => $body:expr) => {
        match &$built.reduced {
            Some(r) => {
                let $m = &r.model;
                $body
            }
            None => {
                let $m = &$built.model;
                $body
            }
        }
    };
}

pub(crate) use on_model;

/// `$body` with `$m` bound to the model that runs and `$ws` to its workspace from `$cache`.
macro_rules! with_model {
    ($built:expr, $cache:expr, $m:ident, $ws:ident => $body:expr) => {
        crate::quantities::on_model!($built, $m => $cache.with(|| $m.workspace(), |$ws| $body))
    };
}

pub(crate) use with_model;

/// The engine workspace of the model a `Robot` runs, kept between calls: allocating one costs
/// about as much as an elastic force (7 µs against 5 µs on `six-tendon`, 127 µs against 48 µs on
/// `single-tendon`). A call takes it and puts it back; a call while another thread holds it gets
/// a new one, and the first to return is kept.
#[derive(Default)]
pub struct WorkspaceCache(Mutex<Option<Workspace>>);

impl WorkspaceCache {
    /// `f` with the kept workspace, or one from `make` (the first call, or another thread holds it).
    pub fn with<R>(
        &self,
        make: impl FnOnce() -> Workspace,
        f: impl FnOnce(&mut Workspace) -> R,
    ) -> R {
        let kept = self.0.try_lock().ok().and_then(|mut slot| slot.take());
        let mut ws = kept.unwrap_or_else(make);
        let out = f(&mut ws);
        if let Ok(mut slot) = self.0.try_lock() {
            if slot.is_none() {
                *slot = Some(ws);
            }
        }
        out
    }
}

/// Poses at the points: positions (p × 3, row-major) and rotations (p × 3 × 3, row-major).
pub fn forward(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> (Vec<f64>, Vec<f64>) {
    with_model!(built, cache, m, ws => {
        m.forward_pose(q, ws);
        poses(ws)
    })
}

/// Why `q` is no state of an elastic rod (a strain past the bounds that end a simulation,
/// [`gvsrom::plausibility::state_violation`], or not finite), as a phrase; `None` for a physical
/// state. The model's quantities there mean nothing, and overflow to NaN far beyond.
/// Only the strains are evaluated, without the kinematics ([`Model::strains_at`]).
pub fn state_violation(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> Option<String> {
    with_model!(built, cache, m, ws => gvsrom::plausibility::model_state_violation(m, q, ws))
}

fn poses(ws: &Workspace) -> (Vec<f64>, Vec<f64>) {
    let pos =
        ws.g.iter()
            .flat_map(|g| [g.pos[0], g.pos[1], g.pos[2]])
            .collect();
    let rot =
        ws.g.iter()
            .flat_map(|g| (0..3).flat_map(move |i| (0..3).map(move |j| g.rot[(i, j)])))
            .collect();
    (pos, rot)
}

/// The geometric (body) Jacobians `J_i` (`η_i = J_i q̇`) at the points `which`, each 6 × n,
/// stacked row-major into (points × 6 × n).
pub fn jacobians(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    which: &[usize],
) -> Vec<f64> {
    with_model!(built, cache, m, ws => {
        let n = m.n_dof();
        m.forward(q, ws, true);
        let mut out = Vec::with_capacity(which.len() * 6 * n);
        for &i in which {
            let j = ws.jac.columns(i * n, n);
            for a in 0..6 {
                out.extend(j.row(a).iter().copied());
            }
        }
        out
    })
}

/// The centreline's world positions at the abscissae `xs` (k × 3) and their derivatives in `q`
/// (k × 3 × n), row-major: [`gvs::model::Model::position_jacobian_at`].
pub fn position_jacobians(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    xs: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    with_model!(built, cache, m, ws => {
        let n = m.n_dof();
        m.forward(q, ws, true);
        let (mut pos, mut jac) = (Vec::with_capacity(3 * xs.len()), Vec::with_capacity(3 * n * xs.len()));
        for &x in xs {
            let (p, d) = m.position_jacobian_at(ws, x);
            pos.extend(p.iter().copied());
            for a in 0..3 {
                jac.extend(d.row(a).iter().copied());
            }
        }
        (pos, jac)
    })
}

/// Body twists `η_i` (p × 6, row-major) at `(q, q̇)` by the engine's velocity recursion.
pub fn velocities(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    qd: &DVector<f64>,
) -> Vec<f64> {
    with_model!(built, cache, m, ws => {
        m.forward(q, ws, false);
        m.velocities(q, qd, ws);
        ws.eta.iter().flat_map(|e| e.iter().copied().collect::<Vec<_>>()).collect()
    })
}

/// The mass matrix `M(q)`.
pub fn mass_matrix(built: &Built, cache: &WorkspaceCache, q: &DVector<f64>) -> DMatrix<f64> {
    with_model!(built, cache, m, ws => m.mass_matrix(q, ws))
}

/// `R(q)` under tensions `u` and the scenario's loads.
pub fn statics_residual(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    u: &[f64],
) -> Result<DVector<f64>, ScenarioError> {
    with_model!(built, cache, m, ws => residual_on(m, built, ws, q, u))
}

fn residual_on<P: StrainParam>(
    m: &Model<P>,
    built: &Built,
    ws: &mut Workspace,
    q: &DVector<f64>,
    u: &[f64],
) -> Result<DVector<f64>, ScenarioError> {
    let loads = m.prepare_loads(&built.loads)?;
    let mut r = DVector::zeros(m.n_dof());
    m.statics_residual(q, u, &loads, ws, &mut r);
    Ok(r)
}

/// `∂R/∂q` under tensions `u` and the scenario's loads (the analytic Jacobian of the solver).
pub fn statics_jacobian(
    built: &Built,
    cache: &WorkspaceCache,
    q: &DVector<f64>,
    u: &[f64],
) -> Result<DMatrix<f64>, ScenarioError> {
    with_model!(built, cache, m, ws => jacobian_on(m, built, ws, q, u))
}

fn jacobian_on<P: StrainParam>(
    m: &Model<P>,
    built: &Built,
    ws: &mut Workspace,
    q: &DVector<f64>,
    u: &[f64],
) -> Result<DMatrix<f64>, ScenarioError> {
    let loads = m.prepare_loads(&built.loads)?;
    let n = m.n_dof();
    let mut jac = DMatrix::zeros(n, n);
    m.statics_jacobian(q, u, &loads, ws, &mut jac);
    Ok(jac)
}
