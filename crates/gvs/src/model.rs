//! The GVS model: forward kinematics `g(X)`, geometric Jacobian `J(X)`, and the static generalized
//! forces with their analytic Jacobian — generic over the [`StrainParam`].
//!
//! **Kinematics** (gvs-spec §5.3, §6). Between consecutive points of a division
//! `Ω = h/2 (ξ₁ + ξ₂) + c h² ad_{ξ₁} ξ₂` (Z4, `c = √3/12`; Z2: `Ω = h ξ_Z`), `g_{i+1} = g_i exp(Ω̂)`,
//! `Z = ∂Ω/∂q = h/2 (Ψ_q1 + Ψ_q2) + c h² (ad_{ξ₁} Ψ_q2 − ad_{ξ₂} Ψ_q1)`, `S = T(Ω) Z`,
//! `J_{i+1} = Ad⁻¹_{g_s} (J_i + S)`.
//!
//! **Statics residual** (paper eq. 9): `R(q) = −K₁(q) + F(q) + B(q)u`. Every term is written as
//! `R = Σ_s Ψ_q,sᵀ y_s` over the strain sites `s` with a 6-vector `y_s` per site:
//! * elastic, at points: `y_i −= W_i Es_i Ψ_i` (so `K₁ = Σ W Ψ_qᵀ Es Ψ`, spec §7.3);
//! * tendons, at points: `y_i += W_i Σ_k α_k Φ_a,k u_k` (paper eq. 11, spec §7.6–7.7);
//! * external `F = Σ_i J_iᵀ w_i` by the backward pass `F̄_s = coAd_{g_s}(F̄_{s+1} + w_{s+1})`,
//!   `S_sᵀ F̄_s = Zᵀ v`, `v = Tᵀ F̄`, which lands on the Magnus sub-points as
//!   `y₁ += h/2 v + c h² coad_{ξ₂} v`, `y₂ += h/2 v − c h² coad_{ξ₁} v` (spec §8.2).
//!
//! **Jacobian**: `∂R/∂q = Σ_s Ψ_q,sᵀ ∂y_s/∂q + Σ_s Σ_a y_{s,a} ∇²Ψ_{s,a}`; the second sum is the
//! parameterization's weighted Hessian (zero for linear bases). `∂F̄/∂q` follows the backward recursion
//! of spec §8.2; the friction factor's derivative `∂α/∂q` is included, so the Jacobian is exact.

use crate::actuation::{
    smoothed_turning_angle, smoothed_turning_angle_value, tangent_jacobian, tendon_local,
    wrench_jacobian, Tendon,
};
use crate::discretize::{Discretization, MagnusOrder};
use crate::error::ModelError;
use crate::lie::{
    ad_mul, coad, coad_mul, coadbar, exp_tangent, tilde, DTtf, ExpTangent, Pose, M6, V3, V6,
};
use crate::loads::{Frame, Loads};
use crate::rod::{Rod, SectionProps};
use crate::strain::{StrainEval, StrainParam};
use nalgebra::{DMatrix, DMatrixViewMut, DVector, Matrix3xX, Matrix6xX};
use std::ops::{AddAssign, Range};

#[cfg(test)]
#[path = "model_dense_reference.rs"]
mod dense_reference;
#[path = "model_forces.rs"]
mod forces;
#[path = "model_statics.rs"]
mod statics;

/// `c = √3/12` of the Zanna step.
pub const ZANNA_C: f64 = 0.144_337_567_297_406_43;

/// A rod, its discretization, a strain parameterization and its tendons.
pub struct Model<P: StrainParam> {
    pub rod: Rod,
    pub disc: Discretization,
    pub param: P,
    pub tendons: Vec<Tendon>,
    /// Base pose `g(0)`.
    pub base: Pose,
    pub(crate) props: Vec<SectionProps>,
    xi_star: Vec<V6>,
    tendon_points: Vec<Vec<usize>>,
    /// Per point: its block in the workspace's `dyp` (`∂y_i/∂q` of tendons), `usize::MAX` for the
    /// points no tendon acts on.
    dy_slot: Vec<usize>,
    k_lin: Option<DMatrix<f64>>,
}

/// Loads resolved onto the computational points.
#[derive(Debug, Clone)]
pub struct PreparedLoads {
    gravity: V3,
    /// Local (follower) wrench per point: point loads plus distributed densities × W.
    local: Vec<V6>,
    /// World-fixed wrench per point (world components).
    global: Vec<V6>,
}

impl PreparedLoads {
    /// `self = λ · base` without allocating (time-varying load schedules).
    pub fn scale_from(&mut self, base: &PreparedLoads, lambda: f64) {
        self.gravity = base.gravity * lambda;
        for (a, b) in self.local.iter_mut().zip(&base.local) {
            *a = b * lambda;
        }
        for (a, b) in self.global.iter_mut().zip(&base.global) {
            *a = b * lambda;
        }
    }
}

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
    gbuf: Vec<f64>,
    pub(crate) et: Vec<ExpTangent>,
    pub(crate) z: Matrix6xX<f64>,
    pub(crate) y: Vec<V6>,
    pub(crate) w: Vec<V6>,
    wg: Vec<V6>,
    dyp: Matrix6xX<f64>,
    ubar: Matrix6xX<f64>,
    pub(crate) t1: Matrix6xX<f64>,
    dtau: Matrix3xX<f64>,
    dtau_prev: Matrix3xX<f64>,
    dtheta: DVector<f64>,
    rtmp: DVector<f64>,
    /// Per site: the elastic and damping wrenches of a motion evaluation's residual, projected
    /// through [`StrainParam::project`].
    ye: Vec<V6>,
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
    fn set_jac_bound(&mut self, i: usize, hi: usize) {
        let n = self.ev.n;
        let old = self.jac_hi[i];
        if old > hi {
            self.jac.columns_mut(i * n + hi, old - hi).fill(0.0);
        }
        self.jac_hi[i] = hi;
    }
}

impl<P: StrainParam> Model<P> {
    /// Builds a model; validates the rod, the tendons and that `param` was built on `disc`.
    pub fn new(
        rod: Rod,
        disc: Discretization,
        param: P,
        tendons: Vec<Tendon>,
    ) -> Result<Self, ModelError> {
        rod.validate()?;
        if param.n_sites() != disc.n_sites() {
            return Err(ModelError::invalid(
                "basis",
                format!(
                    "built for {} sites, the discretization has {}",
                    param.n_sites(),
                    disc.n_sites()
                ),
            ));
        }
        if param.n_dof() == 0 {
            return Err(ModelError::invalid("basis", "no generalized coordinates"));
        }
        for (k, t) in tendons.iter().enumerate() {
            t.validate(&rod, k)?;
        }
        let props = disc
            .points
            .iter()
            .map(|p| SectionProps::circular(&rod.material, rod.divisions[p.div].radius_at(p.x_bar)))
            .collect::<Vec<_>>();
        let xi_star = vec![V6::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0); disc.n_sites()];
        let tendon_points: Vec<Vec<usize>> = tendons
            .iter()
            .map(|t| tendon_point_list(&disc, t))
            .collect();
        let mut dy_slot = vec![usize::MAX; disc.n_points()];
        let mut slots = 0;
        for &i in tendon_points.iter().flatten() {
            if dy_slot[i] == usize::MAX && disc.points[i].weight > 0.0 {
                (dy_slot[i], slots) = (slots, slots + 1);
            }
        }
        let mut m = Model {
            rod,
            disc,
            param,
            tendons,
            base: Pose::identity(),
            props,
            xi_star,
            tendon_points,
            dy_slot,
            k_lin: None,
        };
        if m.param.is_linear() {
            m.k_lin = Some(m.stiffness_linear());
        }
        Ok(m)
    }

    pub fn with_base(mut self, base: Pose) -> Self {
        self.base = base;
        self
    }

    pub fn n_dof(&self) -> usize {
        self.param.n_dof()
    }

    pub fn n_actuators(&self) -> usize {
        self.tendons.len()
    }

    pub fn section(&self, point: usize) -> &SectionProps {
        &self.props[point]
    }

    /// Reference strain `ξ*` at a site.
    pub fn xi_star(&self, site: usize) -> V6 {
        self.xi_star[site]
    }

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

    /// `K = Σ_i W_i Φ_iᵀ Es_i Φ_i` for a linear basis (spec §7.3).
    fn stiffness_linear(&self) -> DMatrix<f64> {
        let n = self.n_dof();
        let ev = self.param.new_eval();
        let mut k = DMatrix::zeros(n, n);
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight == 0.0 {
                continue;
            }
            let c = self.param.columns(i);
            let phi = ev.psi_q_at(i, &c);
            let ephi = DMatrix::from_fn(6, c.len(), |a, j| {
                self.props[i].es[a] * p.weight * phi[(a, j)]
            });
            let mut blk = k.view_mut((c.start, c.start), (c.len(), c.len()));
            blk.gemm_tr(1.0, &phi, &ephi, 1.0);
        }
        k
    }

    /// Constant stiffness matrix of a linear parameterization.
    pub fn stiffness(&self) -> Option<&DMatrix<f64>> {
        self.k_lin.as_ref()
    }

    /// Resolves loads onto the points. Point wrenches must sit on computational points (build the
    /// discretization with their abscissae as extra points).
    pub fn prepare_loads(&self, loads: &Loads) -> Result<PreparedLoads, ModelError> {
        loads.validate(self.disc.length())?;
        let np = self.disc.n_points();
        let mut local = vec![V6::zeros(); np];
        let mut global = vec![V6::zeros(); np];
        for (k, pw) in loads.point.iter().enumerate() {
            let i = self.disc.point_at(pw.x).ok_or_else(|| {
                ModelError::invalid(
                    format!("loads.point[{k}].x"),
                    format!("X = {} m is not a computational point; add it to the discretization's extra points", pw.x),
                )
            })?;
            let w = V6::from_row_slice(&pw.wrench);
            match pw.frame {
                Frame::Local => local[i] += w,
                Frame::Global => global[i] += w,
            }
        }
        for d in &loads.distributed {
            for (i, p) in self.disc.points.iter().enumerate() {
                if p.weight == 0.0 {
                    continue;
                }
                let (f, frame) = d.density_at(p.x);
                match frame {
                    Frame::Local => local[i] += f * p.weight,
                    Frame::Global => global[i] += f * p.weight,
                }
            }
        }
        Ok(PreparedLoads {
            gravity: V3::from_row_slice(&loads.gravity),
            local,
            global,
        })
    }

    /// Forward pass: strains at all sites, poses at all points, Magnus steps, and (if `jacobians`)
    /// `Z`, `J` at every point.
    pub fn forward(&self, q: &DVector<f64>, ws: &mut Workspace, jacobians: bool) {
        self.param.eval(q, &mut ws.ev);
        ws.ev.motion = false;
        ws.ev.psi_q_stale = false;
        self.forward_from_strains(ws, jacobians);
    }

    /// The poses `g_i` and strains `ξ_i` at `q` without Jacobians, for positions and output: as
    /// [`Self::forward`] with `jacobians = false`, but by [`StrainParam::eval_strains`] where the
    /// parameterization offers it (a decoder's value without its `r` tangents); `ws.ev.psi_q` is
    /// then stale.
    pub fn forward_pose(&self, q: &DVector<f64>, ws: &mut Workspace) {
        if self.param.eval_strains(q, &mut ws.ev) {
            ws.ev.motion = false;
            ws.ev.psi_q_stale = true;
            self.forward_from_strains(ws, false);
        } else {
            self.forward(q, ws, false);
        }
    }

    /// [`Self::forward`] after the strains `ws.ev.psi` were evaluated (by [`StrainParam::eval`], or
    /// by [`StrainParam::eval_motion`] for a residual pass without Jacobians).
    pub(crate) fn forward_from_strains(&self, ws: &mut Workspace, jacobians: bool) {
        debug_assert!(!(jacobians && ws.ev.psi_q_stale), "Jacobians need Ψ_q");
        for s in 0..ws.xi.len() {
            ws.xi[s] = ws.ev.psi[s] + self.xi_star[s];
        }
        ws.g[0] = self.base;
        for i in 0..self.disc.n_points() - 1 {
            let Some(st) = self.disc.steps[i] else {
                ws.g[i + 1] = ws.g[i];
                continue;
            };
            let h = st.h;
            let [s1, s2] = st.sites;
            let omega = match self.disc.order {
                MagnusOrder::Z4 => {
                    (ws.xi[s1] + ws.xi[s2]) * (0.5 * h)
                        + crate::lie::ad_mul(&ws.xi[s1], &ws.xi[s2]) * (ZANNA_C * h * h)
                }
                MagnusOrder::Z2 => ws.xi[s1] * h,
            };
            if jacobians {
                ws.et[i] = exp_tangent(&omega);
            } else {
                ws.et[i].set_lean(&omega);
            }
            ws.g[i + 1] = ws.g[i].compose(&ws.et[i].g);
        }
        if jacobians {
            self.forward_jacobians(ws);
        }
    }

    /// The Jacobian part of the forward pass, from the strains and Magnus steps already in `ws`:
    /// `Z_i = ∂Ω_i/∂q` and `J_{i+1} = Ad⁻¹_{exp Ω_i} (J_i + T(Ω_i) Z_i)` (spec §5).
    ///
    /// `Z_i` lives on the step's columns `c` only, and `J_{i+1}` is zero beyond `hi = max c.end` of
    /// the steps so far: the recursion costs `36·hi` per step, one pass over the columns.
    fn forward_jacobians(&self, ws: &mut Workspace) {
        let n = self.n_dof();
        ws.set_jac_bound(0, 0);
        let mut hi = 0;
        for i in 0..self.disc.n_points() - 1 {
            let Some(st) = self.disc.steps[i] else {
                let (a, mut b) = ws
                    .jac
                    .columns_range_pair_mut(i * n..i * n + hi, (i + 1) * n..(i + 1) * n + hi);
                b.copy_from(&a);
                ws.set_jac_bound(i + 1, hi);
                continue;
            };
            let h = st.h;
            let [s1, s2] = st.sites;
            let c = self.param.columns(s1);
            hi = hi.max(c.end);
            let wide = c.len() > STEP_MATRIX_COLUMNS;
            if wide {
                // after a residual-only forward pass: T and the powers, for the many products
                // with T on this step's columns here and in the backward pass
                ws.et[i].complete();
            }
            let mut z = ws.z.columns_mut(i * n + c.start, c.len());
            match self.disc.order {
                MagnusOrder::Z4 => {
                    let p1 = ws.ev.psi_q_at(s1, &c);
                    let p2 = ws.ev.psi_q_at(s2, &c);
                    let k = ZANNA_C * h * h;
                    // Z = h/2 (Ψ_q1 + Ψ_q2) + k (ad_ξ1 Ψ_q2 − ad_ξ2 Ψ_q1), column by column
                    // (6-vector products: no GEMM call and its packing buffers per step)
                    for j in 0..c.len() {
                        let (a, b): (V6, V6) =
                            (p1.column(j).into_owned(), p2.column(j).into_owned());
                        let zj = (a + b) * (0.5 * h)
                            + (ad_mul(&ws.xi[s1], &b) - ad_mul(&ws.xi[s2], &a)) * k;
                        z.column_mut(j).copy_from(&zj);
                    }
                }
                MagnusOrder::Z2 => {
                    z.copy_from(&ws.ev.psi_q_at(s1, &c));
                    z *= h;
                }
            }
            let et = &ws.et[i];
            // J_{i+1} = Ad⁻¹ (J_i + T Z) column by column (Z only on the step's columns)
            let zi = ws.z.columns(i * n, n);
            let (a, mut b) = ws
                .jac
                .columns_range_pair_mut(i * n..i * n + hi, (i + 1) * n..(i + 1) * n + hi);
            let adinv = (hi > STEP_MATRIX_COLUMNS).then(|| et.g.adjoint_inv());
            for j in 0..hi {
                let mut x: V6 = a.fixed_columns::<1>(j).into_owned();
                if c.contains(&j) {
                    let zj: V6 = zi.fixed_columns::<1>(j).into_owned();
                    x += if wide { et.t * zj } else { et.t_mul(&zj) };
                }
                let y = match &adinv {
                    Some(m) => m * x,
                    None => et.g.adjoint_inv_mul(&x),
                };
                b.fixed_columns_mut::<1>(j).copy_from(&y);
            }
            ws.set_jac_bound(i + 1, hi);
        }
    }

    /// Tip pose `g(L)` after a forward pass.
    pub fn tip_pose(&self, ws: &Workspace) -> Pose {
        ws.g[self.disc.tip()]
    }

    /// Strain `ξ_i` at every computational point after a forward pass.
    pub fn point_strains(&self, ws: &Workspace) -> Vec<V6> {
        ws.xi[..self.disc.n_points()].to_vec()
    }

    /// Position of the centreline at `x` by cubic Hermite interpolation between the neighbouring
    /// computational points (tangent `r' = R ν`), after a forward pass.
    pub fn position_at(&self, ws: &Workspace, x: f64) -> V3 {
        let pts = &self.disc.points;
        let i = match pts.iter().position(|p| p.x > x) {
            Some(0) => 0,
            Some(i) => i - 1,
            None => return ws.g[pts.len() - 1].pos,
        };
        let (a, b) = (pts[i], pts[i + 1]);
        let hx = b.x - a.x;
        if hx <= 0.0 {
            return ws.g[i].pos;
        }
        let t = ((x - a.x) / hx).clamp(0.0, 1.0);
        let ta = ws.g[i].rot * V3::new(ws.xi[i][3], ws.xi[i][4], ws.xi[i][5]);
        let tb = ws.g[i + 1].rot * V3::new(ws.xi[i + 1][3], ws.xi[i + 1][4], ws.xi[i + 1][5]);
        let (t2, t3) = (t * t, t * t * t);
        ws.g[i].pos * (2.0 * t3 - 3.0 * t2 + 1.0)
            + ta * ((t3 - 2.0 * t2 + t) * hx)
            + ws.g[i + 1].pos * (-2.0 * t3 + 3.0 * t2)
            + tb * ((t3 - t2) * hx)
    }

    /// Tendon points (indices) of tendon `k`.
    pub fn tendon_points(&self, k: usize) -> &[usize] {
        &self.tendon_points[k]
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

/// `C_w = coadbar(w) + [m̃_g 0; f̃_g 0]`: `∂w/∂J` of a point wrench, the second term from its
/// world-fixed part `wg = [m_g; f_g]` (gravity, global wrenches; spec §7.5).
fn load_derivative(w: &V6, wg: &V6) -> M6 {
    let mut c = coadbar(w);
    c.fixed_view_mut::<3, 3>(0, 0)
        .add_assign(&tilde(&V3::new(wg[0], wg[1], wg[2])));
    c.fixed_view_mut::<3, 3>(3, 0)
        .add_assign(&tilde(&V3::new(wg[3], wg[4], wg[5])));
    c
}

/// `C_w x` for `C_w = coadbar(w) + [m̃_g 0; f̃_g 0]`: `∂w/∂J` of a point wrench, the second term
/// from its world-fixed part `wg = [m_g; f_g]` (gravity, global wrenches; spec §7.5), applied to
/// a Jacobian column `x = [δθ; δp]`: `coad_x w + [m_g × δθ; f_g × δθ]`.
#[inline]
fn load_derivative_mul(w: &V6, wg: &V6, x: &V6) -> V6 {
    let dth = V3::new(x[0], x[1], x[2]);
    let m = V3::new(wg[0], wg[1], wg[2]).cross(&dth);
    let f = V3::new(wg[3], wg[4], wg[5]).cross(&dth);
    coad_mul(x, w) + V6::new(m[0], m[1], m[2], f[0], f[1], f[2])
}

/// The backward pass's maps of one step on its own columns: `A₁`, `A₂`, `k coadbar(v)` and
/// `D = ∂(TᵀF̄)/∂Ω` as matrices (wide steps), or `D` by its vectors and the rest by 6-vector
/// products (narrow steps; see [`STEP_MATRIX_COLUMNS`]). A stack value per step: boxing the large
/// variant would allocate in the pass.
#[allow(clippy::large_enum_variant)]
enum LocalMaps {
    Matrices { a1: M6, a2: M6, cbv: M6, d: M6 },
    Products(DTtf),
}

/// Columns of a step beyond which the Jacobian passes form its 6×6 maps as matrices rather than
/// applying them by 6-vector products: `T(Ω)` (completing a lean Magnus step: the powers of `ad_Ω`,
/// three 6×6 products) and `Ad⁻¹` in the forward pass; `coAd`, `coadbar(F̄)`, `C_w` for the sweep
/// over the columns and `A₁`, `A₂`, `coadbar(v)`, `∂(TᵀF̄)/∂Ω` for the step's own in the backward
/// pass. A matrix–vector product is the cheapest per column; a reduced model's step has one or two
/// columns, where forming the matrices would cost more than all the products.
const STEP_MATRIX_COLUMNS: usize = 4;

/// `out[c, j] += G t` for the `|c| × 6` column-major `g`: six axpys down column j of `out`.
#[inline]
fn add_g_times(out: &mut DMatrix<f64>, c: &Range<usize>, j: usize, g: &[f64], t: &V6) {
    let nr = out.nrows();
    let col = &mut out.as_mut_slice()[j * nr + c.start..j * nr + c.end];
    let k = c.len();
    for a in 0..6 {
        let ta = t[a];
        for (o, gv) in col.iter_mut().zip(&g[a * k..(a + 1) * k]) {
            *o += gv * ta;
        }
    }
}

/// `out[c, j] += H [t; x₁; x₂]` for the `|c| × 18` column-major `h`: eighteen axpys down column j.
#[inline]
fn add_h_times(
    out: &mut DMatrix<f64>,
    c: &Range<usize>,
    j: usize,
    h: &[f64],
    t: &V6,
    x1: &V6,
    x2: &V6,
) {
    let nr = out.nrows();
    let col = &mut out.as_mut_slice()[j * nr + c.start..j * nr + c.end];
    let k = c.len();
    for (b, x) in [t, x1, x2].into_iter().enumerate() {
        for a in 0..6 {
            let xa = x[a];
            let hb = &h[(6 * b + a) * k..(6 * b + a + 1) * k];
            for (o, hv) in col.iter_mut().zip(hb) {
                *o += hv * xa;
            }
        }
    }
}

/// The computational points on a tendon's span. At a termination (or start) on a division junction
/// the duplicated point on the far side is excluded; junctions inside the span keep both points so
/// that the tangent kink counts in the friction angle.
fn tendon_point_list(disc: &Discretization, t: &Tendon) -> Vec<usize> {
    let tol = 1e-12 * disc.length().max(1.0);
    let pts = &disc.points;
    (0..pts.len())
        .filter(|&i| {
            let x = pts[i].x;
            if x < t.x_start - tol || x > t.x_end + tol {
                return false;
            }
            if (x - t.x_end).abs() <= tol && i > 0 && (pts[i - 1].x - x).abs() <= tol {
                return false;
            }
            if (x - t.x_start).abs() <= tol && i + 1 < pts.len() && (pts[i + 1].x - x).abs() <= tol
            {
                return false;
            }
            true
        })
        .collect()
}
