//! Strain parameterizations (gvs-spec §4, architecture "the one idea").
//!
//! A parameterization maps the generalized coordinates `q ∈ Rⁿ` to the strain deviation
//! `Ψ_s(q) = ξ_s(q) − ξ*_s` at every strain *site* `s` of a [`Discretization`](crate::discretize::Discretization)
//! (its computational points and Magnus sub-points), and supplies what the engine needs from it:
//!
//! | what | linear basis (Legendre, FEM-like, POD) | nonlinear (AE decoder, analytic) |
//! |---|---|---|
//! | `Ψ_s` | `Φ_s q` | `Ψ_s(q)` |
//! | `Ψ_q,s = ∂Ψ_s/∂q` (6×n) | `Φ_s` (constant) | Jacobian |
//! | `Ψ̇_q,s = (∂²Ψ_s/∂q² q̇)` (paper eq. 17) | 0 | directional second derivative |
//! | `Σ_s Σ_a w_{s,a} ∇²Ψ_{s,a}` (statics Jacobian) | 0 | contraction with per-site weights |
//!
//! A parameterization whose `Ψ_q` costs `n` directional derivatives (a decoder) may also offer the
//! *motion* evaluation of a dynamics residual pass, which needs no `Ψ_q`: `Ψ_s`, `ξ̇_s = Ψ_q,s q̇` and
//! `Ψ̇_q,s q̇ + Ψ_q,s q̈` ([`StrainParam::eval_motion`], two directional derivatives instead of `n`),
//! and the projection `Σ_s Ψ_q,sᵀ y_s` as one reverse pass ([`StrainParam::project`]).
//!
//! Every model quantity (kinematics, M, C, K, forces) is computed by the engine from these, so a reduced
//! model keeps the Lagrangian structure by construction.

mod bases;
mod sigmoid;

pub use bases::{fem_shape, DivisionBasis, FemDegree, LinearBasis, COORDINATE_ORDER};
pub use sigmoid::SigmoidBend;

use crate::lie::V6;
use nalgebra::{DMatrix, DVector, Dyn, Matrix6xX, ViewStorage, U1, U6};
use std::ops::Range;

/// A view of `Ψ_q` at one site: 6 × (column range) block.
pub type SiteJacobian<'a> = nalgebra::Matrix<f64, U6, Dyn, ViewStorage<'a, f64, U6, Dyn, U1, U6>>;

/// Values of a parameterization at all sites for one `q` (and optionally `q̇`).
///
/// `psi_q` stores the 6×|cols_s| blocks of all sites side by side: site `s` holds the columns
/// `cols_s` of `Ψ_q,s` (its [`StrainParam::columns`]) from `offsets[s]` on. Only those columns may be
/// non-zero and only those are read by the engine. [`StrainEval::zeros`] gives every site all `n`
/// columns (`offsets[s] = s·n`, the layout nonlinear parameterizations write into);
/// [`StrainEval::with_columns`] stores local-support bases compactly.
#[derive(Debug, Clone)]
pub struct StrainEval {
    pub n: usize,
    pub psi: Vec<V6>,
    pub psi_q: Matrix6xX<f64>,
    pub psi_q_dot: Matrix6xX<f64>,
    /// Set by the engine after [`StrainParam::eval_motion`], cleared after [`StrainParam::eval`]:
    /// `xi_dot` and `xi_acc` hold, and the engine takes the strain rates from them.
    pub motion: bool,
    /// Set by the engine after [`StrainParam::eval_motion`] without [`StrainParam::eval`] at the
    /// same `q`: `psi_q` and `psi_q_dot` must not be read.
    pub psi_q_stale: bool,
    /// `ξ̇_s = Ψ_q,s q̇` per site (after [`StrainParam::eval_motion`]).
    pub xi_dot: Vec<V6>,
    /// `Ψ̇_q,s q̇ + Ψ_q,s q̈` per site (after [`StrainParam::eval_motion`]; `q̈ = 0` if not given).
    pub xi_acc: Vec<V6>,
    /// The parameterization's own scratch: what [`StrainParam::eval`] computes once and
    /// [`StrainParam::eval_rate`] and [`StrainParam::add_weighted_hessian`] reuse at the same `q`
    /// (e.g. a network's activations). Sized by [`StrainParam::new_eval`]; never resized after.
    pub scratch: Vec<f64>,
    /// Per site: the stored columns and where they start in `psi_q`.
    cols: Vec<Range<usize>>,
    offsets: Vec<usize>,
}

impl StrainEval {
    /// Every site stores all `n` columns (`6 × n·n_sites`).
    pub fn zeros(n: usize, n_sites: usize) -> Self {
        let cols = vec![0..n; n_sites];
        Self::with_columns(n, &cols)
    }

    /// Site `s` stores the columns `cols[s]` only (`6 × Σ_s |cols[s]|`).
    pub fn with_columns(n: usize, cols: &[Range<usize>]) -> Self {
        let mut offsets = Vec::with_capacity(cols.len());
        let mut total = 0;
        for c in cols {
            offsets.push(total);
            total += c.len();
        }
        StrainEval {
            n,
            psi: vec![V6::zeros(); cols.len()],
            psi_q: crate::model::zeros6_lazy(total),
            psi_q_dot: crate::model::zeros6_lazy(total),
            motion: false,
            psi_q_stale: false,
            xi_dot: vec![V6::zeros(); cols.len()],
            xi_acc: vec![V6::zeros(); cols.len()],
            scratch: Vec::new(),
            cols: cols.to_vec(),
            offsets,
        }
    }

    /// The columns stored for `site`.
    #[inline]
    pub fn stored_columns(&self, site: usize) -> Range<usize> {
        self.cols[site].clone()
    }

    /// Where `Ψ_q` at `site`, column `col` (a stored column), sits in `psi_q`.
    #[inline]
    fn index(&self, site: usize, col: usize) -> usize {
        debug_assert!(self.cols[site].start <= col && col <= self.cols[site].end);
        self.offsets[site] + col - self.cols[site].start
    }

    /// `Ψ_q` at `site`, restricted to `cols` (within the stored columns).
    #[inline]
    pub fn psi_q_at(&self, site: usize, cols: &Range<usize>) -> SiteJacobian<'_> {
        debug_assert!(cols.end <= self.cols[site].end);
        debug_assert!(!self.psi_q_stale, "Ψ_q is stale after a motion evaluation");
        self.psi_q.columns(self.index(site, cols.start), cols.len())
    }

    /// `Ψ̇_q` at `site`, restricted to `cols` (within the stored columns).
    #[inline]
    pub fn psi_q_dot_at(&self, site: usize, cols: &Range<usize>) -> SiteJacobian<'_> {
        debug_assert!(cols.end <= self.cols[site].end);
        debug_assert!(!self.psi_q_stale, "Ψ̇_q is stale after a motion evaluation");
        self.psi_q_dot
            .columns(self.index(site, cols.start), cols.len())
    }

    /// Column `col` of `Ψ_q` at `site` (zero outside the stored columns).
    pub fn psi_q_column(&self, site: usize, col: usize) -> V6 {
        if self.cols[site].contains(&col) {
            self.psi_q.column(self.index(site, col)).into_owned()
        } else {
            V6::zeros()
        }
    }
}

/// The interface between a strain parameterization and the GVS engine.
///
/// Implementations are bound to one discretization (its site list) when they are built.
pub trait StrainParam: Send + Sync {
    /// Number of generalized coordinates n.
    fn n_dof(&self) -> usize;

    /// Number of sites the parameterization was built for.
    fn n_sites(&self) -> usize;

    /// `true` if `Ψ(q) = Φ q` with constant `Φ` (then `Ψ̇_q = 0` and all Hessians vanish).
    fn is_linear(&self) -> bool;

    /// The contiguous range of coordinates that may influence the strain at `site`: its true support
    /// for a local (FEM-like) basis, the division's columns for a multi-division basis, everything
    /// for a global basis. The two Magnus sub-points of one step report the same range.
    fn columns(&self, site: usize) -> Range<usize> {
        let _ = site;
        0..self.n_dof()
    }

    /// Allocates an evaluation buffer. Linear bases store their constant `Φ` in it here.
    fn new_eval(&self) -> StrainEval;

    /// Fills `ev.psi` (and, for nonlinear parameterizations, `ev.psi_q`) at `q`.
    fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval);

    /// Fills `ev.psi_q_dot = (∂²Ψ/∂q² q̇)` at `(q, q̇)` (paper eq. 17). Called after [`StrainParam::eval`]
    /// at the same `q` with the same `ev`. Linear bases: nothing to do.
    fn eval_rate(&self, q: &DVector<f64>, qd: &DVector<f64>, ev: &mut StrainEval);

    /// `out += Σ_s Σ_a w[s]_a ∇²_q Ψ_{s,a}(q)` (n×n, symmetric); `w` has one 6-vector per site and
    /// zero vectors may be skipped. Called after [`StrainParam::eval`] at the same `q` with the same
    /// `ev` (whose scratch may be reused). Linear bases: nothing to add.
    fn add_weighted_hessian(
        &self,
        q: &DVector<f64>,
        w: &[V6],
        ev: &mut StrainEval,
        out: &mut DMatrix<f64>,
    );

    /// The coordinates of the straight, unstrained rod (`Ψ(q) ≈ 0`): where statics and dynamics start
    /// "from rest". Zero for linear bases; a decoder's is the encoder of the zero strain, refined.
    fn rest_coordinates(&self) -> DVector<f64> {
        DVector::zeros(self.n_dof())
    }

    /// The motion evaluation of a dynamics residual pass, if this parameterization has one cheaper
    /// than [`StrainParam::eval`] + [`StrainParam::eval_rate`]: fills `ev.psi`, `ev.xi_dot`
    /// (`Ψ_q,s q̇`) and `ev.xi_acc` (`Ψ̇_q,s q̇ + Ψ_q,s q̈`, with `q̈ = 0` if `None`) at every site,
    /// and returns `true`; the engine then sets `ev.motion`. It may leave `ev.psi_q` and
    /// `ev.psi_q_dot` stale (then the engine sets `ev.psi_q_stale`), but must keep what
    /// [`StrainParam::eval`] stored at the same `q` for [`StrainParam::add_weighted_hessian`] valid.
    /// The default returns `false` and touches nothing (linear bases: their `Ψ_q` is a constant,
    /// nothing to save).
    fn eval_motion(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: Option<&DVector<f64>>,
        ev: &mut StrainEval,
    ) -> bool {
        let _ = (q, qd, qdd, ev);
        false
    }

    /// The strains alone, for a pose (positions, output): fills `ev.psi` at `q` and returns `true`
    /// if this parameterization can do so more cheaply than [`StrainParam::eval`] (a decoder: its
    /// value without the `r` tangents); `ev.psi_q` is then stale (the engine sets
    /// `ev.psi_q_stale`). The default returns `false` and touches nothing.
    fn eval_strains(&self, q: &DVector<f64>, ev: &mut StrainEval) -> bool {
        let _ = (q, ev);
        false
    }

    /// `r += Σ_s Ψ_q,sᵀ y_s` (`y` one 6-vector per site, zeros skipped), after [`StrainParam::eval`]
    /// or (if it returned `true`) [`StrainParam::eval_motion`] at the same `q` with the same `ev`.
    /// The default reads `ev.psi_q` ([`project_with_psi_q`]); a parameterization with a motion
    /// evaluation must override it for `ev.motion`.
    fn project(&self, y: &[V6], ev: &mut StrainEval, r: &mut DVector<f64>) {
        project_with_psi_q(self, y, ev, r);
    }
}

/// `r += Σ_s Ψ_q,sᵀ y_s` from the stored `ev.psi_q`, site by site on the site's
/// [`StrainParam::columns`] (zero `y_s` skipped).
pub fn project_with_psi_q<P: StrainParam + ?Sized>(
    param: &P,
    y: &[V6],
    ev: &StrainEval,
    r: &mut DVector<f64>,
) {
    debug_assert!(!ev.psi_q_stale, "Ψ_q is stale after a motion evaluation");
    for (s, ys) in y.iter().enumerate() {
        if *ys == V6::zeros() {
            continue;
        }
        let c = param.columns(s);
        r.rows_mut(c.start, c.len())
            .gemv_tr(1.0, &ev.psi_q_at(s, &c), ys, 1.0);
    }
}

/// A boxed parameterization is one too, so a program can choose the HOM basis or a reduced one at run
/// time (`Model<Box<dyn StrainParam>>`); the cost is one indirect call per evaluation.
impl<P: StrainParam + ?Sized> StrainParam for Box<P> {
    fn n_dof(&self) -> usize {
        (**self).n_dof()
    }
    fn n_sites(&self) -> usize {
        (**self).n_sites()
    }
    fn is_linear(&self) -> bool {
        (**self).is_linear()
    }
    fn columns(&self, site: usize) -> Range<usize> {
        (**self).columns(site)
    }
    fn new_eval(&self) -> StrainEval {
        (**self).new_eval()
    }
    fn eval(&self, q: &DVector<f64>, ev: &mut StrainEval) {
        (**self).eval(q, ev)
    }
    fn eval_rate(&self, q: &DVector<f64>, qd: &DVector<f64>, ev: &mut StrainEval) {
        (**self).eval_rate(q, qd, ev)
    }
    fn add_weighted_hessian(
        &self,
        q: &DVector<f64>,
        w: &[V6],
        ev: &mut StrainEval,
        out: &mut DMatrix<f64>,
    ) {
        (**self).add_weighted_hessian(q, w, ev, out)
    }
    fn rest_coordinates(&self) -> DVector<f64> {
        (**self).rest_coordinates()
    }
    fn eval_motion(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: Option<&DVector<f64>>,
        ev: &mut StrainEval,
    ) -> bool {
        (**self).eval_motion(q, qd, qdd, ev)
    }
    fn eval_strains(&self, q: &DVector<f64>, ev: &mut StrainEval) -> bool {
        (**self).eval_strains(q, ev)
    }
    fn project(&self, y: &[V6], ev: &mut StrainEval, r: &mut DVector<f64>) {
        (**self).project(y, ev, r)
    }
}

/// Derivative checks of a parameterization against central differences, for this crate's tests and
/// for parameterizations defined elsewhere (POD, decoders).
pub mod testing {
    use super::*;

    /// Largest errors of the analytic derivatives of a parameterization against central differences,
    /// each relative to the largest entry of the quantity (or 1 if that is smaller).
    #[derive(Debug, Clone, Copy)]
    pub struct DerivativeErrors {
        /// `Ψ_q` vs `(Ψ(q + h e_j) − Ψ(q − h e_j)) / 2h`.
        pub psi_q: f64,
        /// `Ψ̇_q` (eq. 17) vs `(Ψ_q(q + h q̇) − Ψ_q(q − h q̇)) / 2h`.
        pub psi_q_dot: f64,
        /// `Σ_s Σ_a w_{s,a} ∇²Ψ_{s,a}` vs central differences of `Σ_s Ψ_q,sᵀ w_s`.
        pub weighted_hessian: f64,
    }

    impl DerivativeErrors {
        pub fn max(&self) -> f64 {
            self.psi_q.max(self.psi_q_dot).max(self.weighted_hessian)
        }
    }

    fn relative(max_diff: f64, max_ref: f64) -> f64 {
        max_diff / max_ref.max(1.0)
    }

    /// Measures the derivatives of `p` at `(q, q̇)` against central differences with step `h`
    /// (weights of the Hessian contraction: a fixed pattern of small integers per site and axis).
    pub fn derivative_errors<P: StrainParam + ?Sized>(
        p: &P,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        h: f64,
    ) -> DerivativeErrors {
        let n = p.n_dof();
        let ns = p.n_sites();
        let mut ev = p.new_eval();
        p.eval(q, &mut ev);
        p.eval_rate(q, qd, &mut ev);
        let mut ep = p.new_eval();
        let mut em = p.new_eval();
        let eval_at = |x: &DVector<f64>, e: &mut StrainEval| p.eval(x, e);
        // Ψ_q, column by column
        let (mut d_psi_q, mut m_psi_q) = (0.0f64, 0.0f64);
        for j in 0..n {
            let mut qp = q.clone();
            qp[j] += h;
            let mut qm = q.clone();
            qm[j] -= h;
            eval_at(&qp, &mut ep);
            eval_at(&qm, &mut em);
            for s in 0..ns {
                let fd = (ep.psi[s] - em.psi[s]) / (2.0 * h);
                let an = ev.psi_q_column(s, j);
                d_psi_q = d_psi_q.max((fd - an).amax());
                m_psi_q = m_psi_q.max(fd.amax());
            }
        }
        // Ψ̇_q = d/dε Ψ_q(q + ε q̇)
        eval_at(&(q + qd * h), &mut ep);
        eval_at(&(q - qd * h), &mut em);
        let fd = (&ep.psi_q - &em.psi_q) / (2.0 * h);
        let psi_q_dot = relative((&fd - &ev.psi_q_dot).amax(), fd.amax());
        // weighted Hessian: ∂/∂q (Σ_s Ψ_q,sᵀ w_s)
        let w: Vec<V6> = (0..ns)
            .map(|s| V6::from_fn(|a, _| ((s * 7 + a * 3) % 5) as f64 - 2.0))
            .collect();
        let g = |e: &StrainEval| {
            let mut out = DVector::zeros(n);
            for s in 0..ns {
                let c = e.stored_columns(s);
                let mut o = out.rows_mut(c.start, c.len());
                o += e.psi_q_at(s, &c).transpose() * w[s];
            }
            out
        };
        let mut hess = DMatrix::zeros(n, n);
        p.eval(q, &mut ev);
        p.add_weighted_hessian(q, &w, &mut ev, &mut hess);
        let (mut d_h, mut m_h) = (0.0f64, 0.0f64);
        for j in 0..n {
            let mut qp = q.clone();
            qp[j] += h;
            let mut qm = q.clone();
            qm[j] -= h;
            eval_at(&qp, &mut ep);
            eval_at(&qm, &mut em);
            let col = (g(&ep) - g(&em)) / (2.0 * h);
            d_h = d_h.max((&col - hess.column(j)).amax());
            m_h = m_h.max(col.amax());
        }
        DerivativeErrors {
            psi_q: relative(d_psi_q, m_psi_q),
            psi_q_dot,
            weighted_hessian: relative(d_h, m_h),
        }
    }

    /// Panics unless every derivative of `p` at `(q, q̇)` matches central differences (step 1e-6) to
    /// `tol`, relative to the largest entry of each quantity (or absolute below 1).
    pub fn check_derivatives<P: StrainParam + ?Sized>(
        p: &P,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        tol: f64,
    ) {
        let e = derivative_errors(p, q, qd, 1e-6);
        assert!(
            e.max() <= tol,
            "derivatives vs central differences: {e:?} > {tol}"
        );
    }
}
