//! Forward kinematics (gvs-spec §5.3, §6): the strains `ξ_s = Ψ_s + ξ*_s` at the sites, the Magnus
//! steps `g_{i+1} = g_i exp(Ω̂)`, the geometric Jacobian `J_{i+1} = Ad⁻¹_{exp Ω}(J_i + T(Ω) Z)`, and
//! what is read off the poses (tip, point strains, the centreline between the points).

use super::{Model, Workspace, STEP_MATRIX_COLUMNS};
use crate::discretize::MagnusOrder;
use crate::lie::{ad_mul, exp_tangent, Pose, V3, V6};
use crate::strain::StrainParam;
use nalgebra::{DVector, Matrix3xX};

/// `c = √3/12` of the Zanna step.
pub const ZANNA_C: f64 = 0.144_337_567_297_406_43;

impl<P: StrainParam> Model<P> {
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
    pub(super) fn forward_jacobians(&self, ws: &mut Workspace) {
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

    /// The strains `ξ_i = Ψ_i(q) + ξ*_i` at every computational point at `q`, without the
    /// kinematics: `Φ_i q` for a linear basis, a decoder's value without its tangents
    /// ([`StrainParam::eval_strains`]). The poses in `ws` are left as they were (stale); every
    /// other method evaluates again at its own `q`. Allocates nothing.
    pub fn strains_at<'w>(&self, q: &DVector<f64>, ws: &'w mut Workspace) -> &'w [V6] {
        if self.param.eval_strains(q, &mut ws.ev) {
            ws.ev.psi_q_stale = true;
        } else {
            self.param.eval(q, &mut ws.ev);
            ws.ev.psi_q_stale = false;
        }
        ws.ev.motion = false;
        for s in 0..ws.xi.len() {
            ws.xi[s] = ws.ev.psi[s] + self.xi_star[s];
        }
        &ws.xi[..self.disc.n_points()]
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

    /// [`Self::position_at`] and its derivative in `q`, `∂p/∂q` (3 × n, world axes), after a
    /// forward pass with Jacobians: the derivative of the same Hermite interpolant, whose nodes
    /// move as `δp_i = R_i J_v,i δq` and whose tangents `t_i = R_i ν_i` as
    /// `δt_i = R_i (∂ν_i/∂q − [ν_i]× J_ω,i) δq` (`δR = R [δθ]×`, `δθ = J_ω δq`). At a point it is
    /// `R_i J_v,i`, the output matrix of the tip's position.
    pub fn position_jacobian_at(&self, ws: &Workspace, x: f64) -> (V3, Matrix3xX<f64>) {
        let pts = &self.disc.points;
        let n = self.n_dof();
        // δp_i and δt_i of point i
        let node = |i: usize| {
            let rot = ws.g[i].rot;
            let j = ws.jac.columns(i * n, n);
            let dp = rot * j.fixed_rows::<3>(3);
            let nu = V3::new(ws.xi[i][3], ws.xi[i][4], ws.xi[i][5]);
            let mut dnu = Matrix3xX::zeros(n);
            let cols = ws.ev.stored_columns(i);
            dnu.columns_mut(cols.start, cols.len())
                .copy_from(&ws.ev.psi_q_at(i, &cols).fixed_rows::<3>(3));
            let dt = rot * (dnu - nu.cross_matrix() * j.fixed_rows::<3>(0));
            (dp, dt)
        };
        let i = match pts.iter().position(|p| p.x > x) {
            Some(0) => 0,
            Some(i) => i - 1,
            None => {
                let tip = pts.len() - 1;
                return (ws.g[tip].pos, node(tip).0);
            }
        };
        let (a, b) = (pts[i], pts[i + 1]);
        let hx = b.x - a.x;
        if hx <= 0.0 {
            return (ws.g[i].pos, node(i).0);
        }
        let t = ((x - a.x) / hx).clamp(0.0, 1.0);
        let (t2, t3) = (t * t, t * t * t);
        let (h00, h10, h01, h11) = (
            2.0 * t3 - 3.0 * t2 + 1.0,
            (t3 - 2.0 * t2 + t) * hx,
            -2.0 * t3 + 3.0 * t2,
            (t3 - t2) * hx,
        );
        let ((dpa, dta), (dpb, dtb)) = (node(i), node(i + 1));
        let d = dpa * h00 + dta * h10 + dpb * h01 + dtb * h11;
        (self.position_at(ws, x), d)
    }

    /// Position of tendon `k`'s thread at `x`, `p = r + R d(X)`, by cubic Hermite interpolation
    /// between its neighbouring computational points with the tangent `p' = R t_u`,
    /// `t_u = ν + k × d + d'` (gvs-spec §7.6), after a forward pass; `x` is clamped to the
    /// tendon's points. Exact at the points, `O(h⁴)` between them.
    pub fn tendon_position_at(&self, ws: &Workspace, k: usize, x: f64) -> V3 {
        let t = &self.tendons[k];
        let pts = &self.tendon_points[k];
        let node = |m: usize| {
            let i = pts[m];
            let xm = self.disc.points[i].x;
            let (d, dp) = t.offset_and_rate(xm);
            let (g, xi) = (&ws.g[i], &ws.xi[i]);
            let kv = V3::new(xi[0], xi[1], xi[2]);
            let nu = V3::new(xi[3], xi[4], xi[5]);
            (xm, g.pos + g.rot * d, g.rot * (nu + kv.cross(&d) + dp))
        };
        let m = pts
            .partition_point(|&i| self.disc.points[i].x <= x)
            .saturating_sub(1);
        if m + 1 >= pts.len() {
            return node(pts.len() - 1).1;
        }
        let ((xa, pa, ta), (xb, pb, tb)) = (node(m), node(m + 1));
        let hx = xb - xa;
        if hx <= 0.0 {
            return pa;
        }
        let s = ((x - xa) / hx).clamp(0.0, 1.0);
        let (s2, s3) = (s * s, s * s * s);
        pa * (2.0 * s3 - 3.0 * s2 + 1.0)
            + ta * ((s3 - 2.0 * s2 + s) * hx)
            + pb * (-2.0 * s3 + 3.0 * s2)
            + tb * ((s3 - s2) * hx)
    }
}
