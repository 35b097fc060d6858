//! The scratch buffers of one model evaluation ([`Workspace`]), allocated once by
//! [`Model::workspace`] and reused by every pass; zero matrices from lazily zeroed memory.

use super::Model;
use crate::lie::{exp_tangent, ExpTangent, Pose, V6};
use crate::strain::{StrainEval, StrainParam};
use nalgebra::{DMatrix, DVector, Matrix3xX, Matrix6xX};

/// Scratch buffers of one model evaluation (allocated once, reused by every call).
pub struct Workspace {
    pub(crate) ev: StrainEval,
    /// `ξ_s` at every site.
    pub(crate) xi: Vec<V6>,
    /// Pose at every point.
    pub g: Vec<Pose>,
    /// `J_i` of every point side by side (6 × n·n_points); valid after a forward pass with Jacobians.
    /// `J_i` is zero from column [`Workspace::jac_bound`]`(i)` on (the coordinates of the sites
    /// beyond point i); the engine never writes those columns, so they must stay zero.
    pub jac: Matrix6xX<f64>,
    /// Per point: `J_i` is zero at columns `>= jac_hi[i]`.
    pub(crate) jac_hi: Vec<usize>,
    /// Per point: `∂y_i/∂q` in `dyp` is zero at columns `>= dy_hi[i]`.
    pub(crate) dy_hi: Vec<usize>,
    /// Scratch (up to n × 18, column-major) of the row updates `out[c, :] += G X`.
    pub(super) gbuf: Vec<f64>,
    pub(crate) et: Vec<ExpTangent>,
    pub(crate) z: Matrix6xX<f64>,
    pub(crate) y: Vec<V6>,
    pub(crate) w: Vec<V6>,
    pub(super) wg: Vec<V6>,
    pub(super) dyp: Matrix6xX<f64>,
    pub(super) ubar: Matrix6xX<f64>,
    pub(crate) t1: Matrix6xX<f64>,
    pub(super) dtau: Matrix3xX<f64>,
    pub(super) dtau_prev: Matrix3xX<f64>,
    pub(super) dtheta: DVector<f64>,
    pub(super) rtmp: DVector<f64>,
    /// Per site: the elastic and damping wrenches of a motion evaluation's residual, projected
    /// through [`StrainParam::project`].
    pub(super) ye: Vec<V6>,
    /// Body velocity `η_i` and `J̇ˢ_i q̇` at every point (dynamics).
    pub eta: Vec<V6>,
    pub(crate) zeta: Vec<V6>,
    /// Mass matrix of the last dynamics evaluation (empty until the first one).
    pub mass: DMatrix<f64>,
    /// Scratch of the mass matrix assembly (empty until the first one).
    pub(crate) mass_b: Vec<f64>,
    /// `max(1, ‖elastic‖∞, ‖external + actuation‖∞)` of the last residual.
    pub residual_scale: f64,
}

impl Workspace {
    /// The column from which `J_i` is zero (after a forward pass with Jacobians).
    pub fn jac_bound(&self, i: usize) -> usize {
        self.jac_hi[i]
    }

    /// Records that `J_i` is written on columns `< hi` only, zeroing what an earlier pass wrote
    /// beyond.
    pub(super) fn set_jac_bound(&mut self, i: usize, hi: usize) {
        let n = self.ev.n;
        let old = self.jac_hi[i];
        if old > hi {
            self.jac.columns_mut(i * n + hi, old - hi).fill(0.0);
        }
        self.jac_hi[i] = hi;
    }
}

impl<P: StrainParam> Model<P> {
    pub fn workspace(&self) -> Workspace {
        let n = self.n_dof();
        let np = self.disc.n_points();
        let ns = self.disc.n_sites();
        Workspace {
            ev: self.param.new_eval(),
            xi: vec![V6::zeros(); ns],
            g: vec![Pose::identity(); np],
            jac: zeros6_lazy(n * np),
            jac_hi: vec![0; np],
            dy_hi: vec![0; np],
            gbuf: vec![0.0; 18 * n],
            et: vec![exp_tangent(&V6::zeros()); np - 1],
            z: zeros6_lazy(n * (np - 1)),
            y: vec![V6::zeros(); ns],
            w: vec![V6::zeros(); np],
            wg: vec![V6::zeros(); np],
            dyp: zeros6_lazy(n * self.dy_slot.iter().filter(|s| **s != usize::MAX).count()),
            ubar: Matrix6xX::zeros(n),
            t1: Matrix6xX::zeros(n),
            dtau: Matrix3xX::zeros(n),
            dtau_prev: Matrix3xX::zeros(n),
            dtheta: DVector::zeros(n),
            rtmp: DVector::zeros(n),
            ye: vec![V6::zeros(); ns],
            eta: vec![V6::zeros(); np],
            zeta: vec![V6::zeros(); np],
            mass: DMatrix::zeros(0, 0),
            mass_b: Vec::new(),
            residual_scale: 1.0,
        }
    }
}

/// A zero `rows × cols` matrix from zeroed memory (`calloc`): the OS provides zero pages lazily, so
/// large workspace buffers of which a pass touches a part (`J_i` up to its column bound, `Z` on the
/// step's columns) cost nothing where untouched. (`DMatrix::zeros` writes every entry.)
pub(crate) fn zeros_lazy(rows: usize, cols: usize) -> DMatrix<f64> {
    DMatrix::from_vec(rows, cols, vec![0.0; rows * cols])
}

/// [`zeros_lazy`] for 6 × `cols`.
pub(crate) fn zeros6_lazy(cols: usize) -> Matrix6xX<f64> {
    Matrix6xX::from_vec(vec![0.0; 6 * cols])
}
