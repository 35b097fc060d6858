//! Vibration modes about an equilibrium with tendons *held* at their lengths: motors that drive
//! tendons by displacement ([`crate::solve::tendon_drive`]) and are locked, so that each taut held
//! tendon `k` keeps `ℓ_k(q)` fixed while the rod vibrates.
//!
//! Linearized, a held tendon is the constraint `∇ℓ_kᵀ δq = 0` whose force is its tension's change
//! along its column of the actuation matrix, `B_k δu_k`:
//!
//! ```text
//! (K_T − ω² M) δq = B_H δu,   G_Hᵀ δq = 0,   G_H = ∂ℓ_H/∂q,   K_T = −∂R/∂q
//! ```
//!
//! With `N` an orthonormal basis of `null(G_Hᵀ)` (`δq = N z`) and `W` one of `null(B_Hᵀ)` (which
//! annihilates the unknown tension changes), `(Wᵀ K_T N) z = ω² (Wᵀ M N) z`. Frictionless tendons
//! have `B_H = G_H` ([`Model::tendon_length_jacobian`]), so `W = N` and `M_c = Nᵀ M N` is positive
//! definite: the modes of [`Model::linearized_modes`] on the constrained coordinates, shapes
//! `φ = N z` mass-normalized. Friction (`B_H ≠ G_H`) leaves `Wᵀ M N` non-symmetric: the modes are
//! the eigenpairs of `(Wᵀ M N)⁻¹ (Wᵀ K_T N)`, shapes scaled to `φᵀ M φ = 1`. A held tendon adds
//! no frequency below the free rod's: by Rayleigh's theorem (frictionless, symmetric `K_T`) each
//! constrained `ω²_j` lies between the free `ω²_j` and `ω²_{j+m}`.
//!
//! An elastic held tendon (axial stiffness `EA_k`, compliance `c_k = ℓ_k,rest / EA_k`,
//! [`Model::tendon_compliances`]) is no constraint but a spring: its tension changes by
//! `δu_k = −∇ℓ_kᵀ δq / c_k`, which adds `B_k ∇ℓ_kᵀ / c_k` to `K_T` (as in the dynamics,
//! [`crate::solve::dynamics::drive`]); only the inextensible held tendons constrain `δq`.

use super::{cholesky_factor_in_place, mass_similar, similar_modes, DynamicsError, Mode};
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// Relative difference `‖B_H − G_H‖ / ‖G_H‖` below which the held tendons are taken as
/// frictionless (`W = N`).
const FRICTIONLESS: f64 = 1e-12;

impl<P: StrainParam> Model<P> {
    /// Linearized undamped modes about `q0` under the tensions `u` with the tendons `held` at
    /// their lengths (the module documentation): ascending `ω²`, `n − m` of them (`m` the
    /// inextensible held tendons; an elastic one is a spring), shapes in `q` with `φᵀ M φ = 1`.
    /// Without held tendons, [`Model::linearized_modes`].
    pub fn held_modes(
        &self,
        q0: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        held: &[usize],
        ws: &mut Workspace,
    ) -> Result<Vec<Mode>, DynamicsError> {
        if held.is_empty() {
            return self.linearized_modes(q0, u, loads, ws);
        }
        let n = self.n_dof();
        let grad = self.tendon_length_jacobian(q0, ws);
        let b = self.actuation_matrix(q0, ws);
        let compliance = self.tendon_compliances();
        let (elastic, rigid): (Vec<usize>, Vec<usize>) =
            held.iter().partition(|&&k| compliance[k] > 0.0);
        let g_h = DMatrix::from_fn(n, rigid.len(), |i, j| grad[(i, rigid[j])]);
        let b_h = DMatrix::from_fn(n, rigid.len(), |i, j| b[(i, rigid[j])]);
        let mut k = DMatrix::zeros(n, n);
        self.statics_jacobian(q0, u, loads, ws, &mut k);
        k.neg_mut();
        for &e in &elastic {
            k.ger(1.0 / compliance[e], &b.column(e), &grad.column(e), 1.0);
        }
        self.assemble_mass(ws);
        let mass = ws.mass.clone();
        let big_n = null_basis(&g_h, "length gradients ∂ℓ/∂q")?;
        // every held column frictionless: the springs' share is symmetric, W = N
        let frictionless = held.iter().all(|&h| {
            (b.column(h) - grad.column(h)).norm() <= FRICTIONLESS * grad.column(h).norm()
        });
        let modes = if frictionless {
            let kc = big_n.transpose() * &k * &big_n;
            let mut l = big_n.transpose() * &mass * &big_n;
            cholesky_factor_in_place(&mut l)?;
            similar_modes(&kc, &mass_similar(&kc, &l), &l)?
        } else {
            let w = null_basis(&b_h, "actuation columns B")?;
            let kc = w.transpose() * &k * &big_n;
            let mc = w.transpose() * &mass * &big_n;
            let a = mc.lu().solve(&kc).ok_or(DynamicsError::NonFinite {
                what: "constrained mass matrix Wᵀ M N of the held tendons",
            })?;
            // `a` is no symmetric matrix: the non-symmetric path, with the identity as the factor
            let id = DMatrix::identity(a.nrows(), a.nrows());
            let af = faer::Mat::<f64>::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)]);
            similar_modes(&a, &af, &id)?
        };
        Ok(modes
            .into_iter()
            .map(|m| {
                let mut shape = &big_n * &m.shape;
                let scale = shape.dot(&(&mass * &shape)).sqrt();
                if scale > 0.0 {
                    shape /= scale;
                }
                Mode { shape, ..m }
            })
            .collect())
    }
}

/// An orthonormal basis (n × (n − m)) of `null(Aᵀ)`, the complement of the columns of `a`
/// (n × m; the identity for none): the eigenvectors of the projector `I − Q Qᵀ` of eigenvalue 1, `Q` the orthonormal
/// factor of `A`. Columns of `a` dependent to 1e-10 (a diagonal of `R` that small against the
/// largest), or more of them than rows, are [`DynamicsError::DependentConstraints`] (`what`).
fn null_basis(a: &DMatrix<f64>, what: &'static str) -> Result<DMatrix<f64>, DynamicsError> {
    let (n, m) = a.shape();
    if m == 0 {
        return Ok(DMatrix::identity(n, n));
    }
    let qr = a.clone().qr();
    let r = qr.r();
    let big = (0..m.min(n)).map(|i| r[(i, i)].abs()).fold(0.0, f64::max);
    let rank = (0..m.min(n))
        .filter(|&i| r[(i, i)].abs() > 1e-10 * big)
        .count();
    if rank < m || m >= n {
        return Err(DynamicsError::DependentConstraints {
            what,
            rank,
            count: m,
        });
    }
    let q = qr.q(); // n × m, orthonormal columns spanning range(A)
    let p = DMatrix::identity(n, n) - &q * q.transpose();
    let eig = nalgebra::SymmetricEigen::new(p);
    let cols: Vec<usize> = (0..n).filter(|&j| eig.eigenvalues[j] > 0.5).collect();
    Ok(DMatrix::from_fn(n, cols.len(), |i, j| {
        eig.eigenvectors[(i, cols[j])]
    }))
}
