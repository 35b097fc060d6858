//! Analysis of the equations of motion (not used by the integrators): linearized vibration modes
//! about an equilibrium (spec §10.5), the Coriolis *matrix* `C(q, q̇)` whose `Ṁ − 2C` is
//! skew-symmetric (§7.2), and the kinetic, elastic and gravitational energies of a state (§9.4).

use super::{cholesky_factor_in_place, DynamicsError};
use crate::discretize::MagnusOrder;
use crate::lie::{ad, M6, V3, V6};
use crate::model::{Model, PreparedLoads, Workspace, ZANNA_C};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector, Matrix6xX};

/// Energies of a state \[J\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    pub kinetic: f64,
    pub elastic: f64,
    pub gravitational: f64,
}

/// Relative asymmetry `‖K_T − K_Tᵀ‖_F / ‖K_T‖_F` of the tangent stiffness below which it is taken
/// as symmetric (the round-off of the analytic Jacobian of a conservative load, ~1e-15).
pub const SYMMETRY_TOLERANCE: f64 = 1e-10;

/// A linearized vibration mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// The eigenvalue `ω²` [rad²/s²], negative for a direction in which the equilibrium is unstable
    /// (its real part for a complex eigenvalue).
    pub omega_squared: f64,
    /// The imaginary part of the eigenvalue `ω²`: non-zero only for a complex pair of eigenvalues
    /// of a non-symmetric `M⁻¹ K_T` (flutter of the undamped linearization, e.g. a follower load
    /// beyond Beck's critical one).
    pub omega_squared_imag: f64,
    /// Natural frequency `√max(ω², 0) / 2π` \[Hz\] (0 for an unstable direction).
    pub frequency_hz: f64,
    /// Mode shape in `q`, mass-normalized.
    pub shape: DVector<f64>,
}

/// `A = L⁻¹ K L⁻ᵀ` for the lower-triangular `l` (`M = L Lᵀ`, as
/// [`cholesky_factor_in_place`] leaves it: its strictly upper part is not read), by two blocked
/// triangular solves of faer: `L⁻¹ K`, then `L⁻¹ (L⁻¹ K)ᵀ = Aᵀ`, transposed back. Similar to
/// `M⁻¹ K` (`A = Lᵀ (M⁻¹ K) L⁻ᵀ`), symmetric if `K` is.
pub(crate) fn mass_similar(k: &DMatrix<f64>, l: &DMatrix<f64>) -> faer::Mat<f64> {
    use faer::{Mat, MatRef, Par};
    let n = k.nrows();
    let l = MatRef::from_column_major_slice(l.as_slice(), n, n);
    let mut x = Mat::<f64>::from_fn(n, n, |i, j| k[(i, j)]);
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
    let mut at = x.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, at.as_mut(), Par::Seq);
    at.transpose().to_owned()
}

/// The modes of `M⁻¹ K` from `a = L⁻¹ K L⁻ᵀ` ([`mass_similar`]; `l` the factor of `M`): those of
/// the symmetric problem when `K` is symmetric (asymmetry ≤ [`SYMMETRY_TOLERANCE`]), of the
/// non-symmetric one otherwise ([`Model::linearized_modes`]); unstable directions (`ω² < 0`) first,
/// then by frequency.
pub(crate) fn similar_modes(
    k: &DMatrix<f64>,
    a: &faer::Mat<f64>,
    l: &DMatrix<f64>,
) -> Result<Vec<Mode>, DynamicsError> {
    let asymmetry = (k - k.transpose()).norm() / k.norm();
    let mut modes = if asymmetry > SYMMETRY_TOLERANCE {
        non_symmetric_modes(a, l)?
    } else {
        symmetric_modes(a, l)?
    };
    modes.sort_by(|a, b| a.omega_squared.total_cmp(&b.omega_squared));
    Ok(modes)
}

/// `L⁻ᵀ v` for every column `v` of `v` (the mode shapes in `q` of the eigenvectors of
/// [`mass_similar`]'s `A`), `l` as there.
fn shapes(l: &DMatrix<f64>, mut v: faer::Mat<f64>) -> faer::Mat<f64> {
    let n = l.nrows();
    let l = faer::MatRef::from_column_major_slice(l.as_slice(), n, n);
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        v.as_mut(),
        faer::Par::Seq,
    );
    v
}

/// The modes of the symmetric `a` ([`mass_similar`] of a symmetric `K_T`): faer's self-adjoint
/// eigendecomposition; shapes `L⁻ᵀ v`, `M`-orthonormal.
fn symmetric_modes(a: &faer::Mat<f64>, l: &DMatrix<f64>) -> Result<Vec<Mode>, DynamicsError> {
    let n = a.nrows();
    // the symmetric part, so that round-off cannot make the two triangles disagree
    let sym = faer::Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let eig = sym
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|_| DynamicsError::NonFinite {
            what: "eigendecomposition of M⁻¹K_T",
        })?;
    let phi = shapes(l, eig.U().to_owned());
    let s = eig.S().column_vector();
    let mut modes = Vec::with_capacity(n);
    for j in 0..n {
        let w2 = s[j];
        if !w2.is_finite() {
            return Err(DynamicsError::NonFinite {
                what: "eigendecomposition of M⁻¹K_T",
            });
        }
        modes.push(Mode {
            omega_squared: w2,
            omega_squared_imag: 0.0,
            frequency_hz: w2.max(0.0).sqrt() / (2.0 * std::f64::consts::PI),
            shape: DVector::from_fn(n, |i, _| phi[(i, j)]),
        });
    }
    Ok(modes)
}

/// The modes of the non-symmetric `a = L⁻¹ K_T L⁻ᵀ` ([`Model::linearized_modes`]): each
/// eigenvector `u` (complex) is turned so that its largest entry is real and positive, its real
/// part `v` (its imaginary part for the member of a complex pair with `Im ω² < 0`) normalized
/// (`|v| = 1`, so `φ = L⁻ᵀ v` has `φᵀ M φ = 1`).
fn non_symmetric_modes(a: &faer::Mat<f64>, l: &DMatrix<f64>) -> Result<Vec<Mode>, DynamicsError> {
    let n = a.nrows();
    let eig = a.eigen().map_err(|_| DynamicsError::NonFinite {
        what: "eigendecomposition of M⁻¹K_T",
    })?;
    let (u, s) = (eig.U(), eig.S().column_vector());
    let mut v = faer::Mat::<f64>::zeros(n, n);
    for j in 0..n {
        let (w2, col) = (s[j], u.col(j));
        let big = (0..n)
            .max_by(|&x, &y| col[x].norm().total_cmp(&col[y].norm()))
            .unwrap_or(0);
        let turn = col[big].conj() / col[big].norm();
        // the two members of a complex pair have conjugate vectors, whose turned real parts are
        // equal: the second (Im ω² < 0) takes the imaginary part, so that the pair spans the
        // plane of its motion
        let part = |z: faer::c64| match w2.im < 0.0 {
            true => z.im,
            false => z.re,
        };
        let norm = (0..n)
            .map(|i| part(col[i] * turn).powi(2))
            .sum::<f64>()
            .sqrt();
        if !(norm.is_finite() && norm > 0.0 && w2.re.is_finite() && w2.im.is_finite()) {
            return Err(DynamicsError::NonFinite {
                what: "eigendecomposition of M⁻¹K_T",
            });
        }
        for i in 0..n {
            v[(i, j)] = part(col[i] * turn) / norm;
        }
    }
    let phi = shapes(l, v);
    Ok((0..n)
        .map(|j| Mode {
            omega_squared: s[j].re,
            omega_squared_imag: s[j].im,
            frequency_hz: s[j].re.max(0.0).sqrt() / (2.0 * std::f64::consts::PI),
            shape: DVector::from_fn(n, |i, _| phi[(i, j)]),
        })
        .collect())
}

impl Energy {
    pub fn total(&self) -> f64 {
        self.kinetic + self.elastic + self.gravitational
    }
}

impl<P: StrainParam> Model<P> {
    /// Linearized undamped vibration modes about `q0` (spec §10.5): `(K_T − ω² M) φ = 0` with the
    /// tangent stiffness `K_T = −∂R/∂q` (elastic plus load and tendon stiffness). Returned in
    /// ascending `ω²` (directions in which the equilibrium is unstable, `ω² < 0`, first), shapes
    /// mass-normalized (`φᵀ M φ = 1`).
    ///
    /// A symmetric `K_T` (conservative loads: gravity, frictionless tendons, dead loads; relative
    /// asymmetry ≤ [`SYMMETRY_TOLERANCE`]) gives the symmetric problem `L⁻¹ K_T L⁻ᵀ`, `M = L Lᵀ`,
    /// with `M`-orthonormal shapes. Tendon friction and follower loads make `K_T` non-symmetric:
    /// the modes are then the eigenpairs of the non-symmetric `L⁻¹ K_T L⁻ᵀ` (faer's
    /// eigendecomposition), the poles of the undamped linearization that `linearize` computes,
    /// not those of its symmetric part (which put Beck's column's first frequency 21 % low, and
    /// moved it down under the follower load that raises it). Their shapes are not
    /// `M`-orthogonal; a complex pair (flutter) is reported with its real part in `omega_squared`,
    /// its imaginary part in `omega_squared_imag`, and the real part of its (phase-aligned) vector
    /// as the shape.
    pub fn linearized_modes(
        &self,
        q0: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
    ) -> Result<Vec<Mode>, DynamicsError> {
        let n = self.n_dof();
        let mut k = DMatrix::zeros(n, n);
        self.statics_jacobian(q0, u, loads, ws, &mut k);
        k.neg_mut();
        self.assemble_mass(ws);
        let mut l = ws.mass.clone();
        cholesky_factor_in_place(&mut l)?;
        similar_modes(&k, &mass_similar(&k, &l), &l)
    }

    /// Coriolis matrix `C(q, q̇) = Σ W Jᵀ (Ms J̇ˢ + coad_η Ms J)` (spec §7.2), the bodies' `Mb` added
    /// at their points ([`crate::bodies`]); for tests and analysis.
    pub fn coriolis_matrix(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        ws: &mut Workspace,
    ) -> DMatrix<f64> {
        let n = self.n_dof();
        self.forward(q, ws, true);
        self.velocities(q, qd, ws); // also fills Ψ̇_q for nonlinear parameterizations
        let np = self.disc.n_points();
        let mut jds = Matrix6xX::<f64>::zeros(n); // J̇ˢ_i
        let mut c = DMatrix::zeros(n, n);
        for i in 0..np {
            if i > 0 {
                if let Some(st) = self.disc.steps[i - 1] {
                    let s = i - 1;
                    let [s1, s2] = st.sites;
                    let cols = self.param.columns(s1);
                    let h = st.h;
                    let et = &ws.et[s];
                    let z = ws.z.columns(s * n + cols.start, cols.len()).into_owned();
                    let qdc = qd.rows(cols.start, cols.len());
                    // Ż (6×cols)
                    let mut zdot = DMatrix::zeros(6, cols.len());
                    let p1 = ws.ev.psi_q_at(s1, &cols).into_owned();
                    let p2 = ws.ev.psi_q_at(s2, &cols).into_owned();
                    match self.disc.order {
                        MagnusOrder::Z4 => {
                            let k = ZANNA_C * h * h;
                            let xd1: V6 = &p1 * qdc;
                            let xd2: V6 = &p2 * qdc;
                            zdot += (ad(&xd1) * &p2 - ad(&xd2) * &p1) * k;
                            if !self.param.is_linear() {
                                let d1 = ws.ev.psi_q_dot_at(s1, &cols).into_owned();
                                let d2 = ws.ev.psi_q_dot_at(s2, &cols).into_owned();
                                zdot += (&d1 + &d2) * (0.5 * h)
                                    + (ad(&ws.xi[s1]) * &d2 - ad(&ws.xi[s2]) * &d1) * k;
                            }
                        }
                        MagnusOrder::Z2 => {
                            if !self.param.is_linear() {
                                zdot += ws.ev.psi_q_dot_at(s1, &cols).into_owned() * h;
                            }
                        }
                    }
                    let om_dot: V6 = &z * qdc;
                    let sdot = et.t_dot(&om_dot) * &z + et.t * zdot;
                    let smat = et.t * &z;
                    let mut next = jds.clone();
                    {
                        let mut blk = next.columns_mut(cols.start, cols.len());
                        blk += ad(&ws.eta[s]) * &smat + sdot;
                    }
                    jds = et.g.adjoint_inv() * next;
                }
            }
            // the section's W Ms, plus the inertia of the bodies fixed here
            let w = self.disc.points[i].weight;
            let mut mi = M6::from_diagonal(&(self.props[i].ms * w));
            for b in self.bodies.iter().filter(|b| b.point == i) {
                mi += b.mb;
            }
            if mi == M6::zeros() {
                continue;
            }
            let j = ws.jac.columns(i * n, n).into_owned();
            let inner = mi * &jds + crate::lie::coad(&ws.eta[i]) * mi * &j;
            c += j.transpose() * inner;
        }
        c
    }

    /// Kinetic, elastic and gravitational energies at `(q, q̇)` (spec §9.4):
    /// `T = ½ q̇ᵀ M q̇`, `U_e = ½ Σ W Ψᵀ Es Ψ`, `U_g = −Σ W ρA g·r − Σ_b m_b g·(r_b + R_b c_b)` (the
    /// bodies' centres of mass, [`crate::bodies`]).
    pub fn energy(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        gravity: &[f64; 3],
        ws: &mut Workspace,
    ) -> Energy {
        self.forward(q, ws, true);
        self.assemble_mass(ws);
        let kinetic = 0.5 * qd.dot(&(&ws.mass * qd));
        let g = V3::from_row_slice(gravity);
        let mut elastic = 0.0;
        let mut gravitational = 0.0;
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight == 0.0 {
                continue;
            }
            let psi = ws.ev.psi[i];
            elastic += 0.5 * p.weight * psi.dot(&self.props[i].es.component_mul(&psi));
            gravitational -= p.weight * self.props[i].ms[3] * g.dot(&ws.g[i].pos);
        }
        for b in &self.bodies {
            let pose = &ws.g[b.point];
            let center = pose.pos + pose.rot * V3::from(b.body.center);
            gravitational -= b.body.mass * g.dot(&center);
        }
        Energy {
            kinetic,
            elastic,
            gravitational,
        }
    }
}
