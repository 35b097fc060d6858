//! Static stability of an equilibrium: does it diverge?
//!
//! About an equilibrium `q*` the undamped motion obeys `M δq̈ + K_T δq = 0`, with the tangent
//! stiffness `K_T = −∂R/∂q` (elastic, load and tendon stiffness; gvs-spec §8.2). A real eigenvalue
//! `ω² < 0` of `M⁻¹ K_T` is a *divergence*: a direction in which the rod leaves the equilibrium as
//! `e^{√(−ω²) t}` (an upside-down pendulum; a soft cantilever curled up against gravity). A full
//! Newton or dogleg step from the straight rod can converge onto such an equilibrium: it solves
//! `R(q) = 0`, which holds at stable and unstable equilibria alike.
//!
//! The test, cheap first:
//! 1. `sym(K_T) = −(J + Jᵀ)/2` positive definite (a Cholesky factorization succeeds) ⇒ no
//!    eigenvalue of `M⁻¹ K_T` has a negative real part (`xᴴ K_T x = ω² xᴴ M x` with
//!    `Re xᴴ K_T x > 0`): stable. This decides every conservative load (symmetric `K_T`) and almost
//!    every other equilibrium.
//! 2. For a symmetric `K_T` (conservative loads: gravity, bodies, world-fixed forces) the
//!    eigenvalues of `L⁻¹ K_T L⁻ᵀ` are those of a symmetric matrix, exact to round-off
//!    (`~n ε max |ω²|`): divergent if one is below `−SYMMETRIC_TOLERANCE · max |ω²|` (1e-13). The
//!    looser threshold of step 3 missed a heavy payload on a light rod, whose divergent `ω²`
//!    (−12.3 1/s²) is 2e-11 of the rod's stiffest mode (6e11 1/s²); a neutral direction (a buckled
//!    column turning about the vertical, −5e-6 1/s² there) stays at round-off, 1e-17 of it.
//! 3. Otherwise (friction and follower loads make `K_T` non-symmetric, and its symmetric part may be
//!    indefinite at a stable equilibrium) the eigenvalues of `L⁻¹ K_T L⁻ᵀ`, `M = L Lᵀ` (similar to
//!    `M⁻¹ K_T`): divergent if one is real and below `−DIVERGENCE_TOLERANCE · max |ω²|`. Complex
//!    pairs (flutter of the undamped linearization, e.g. Beck's column) are not divergence; their
//!    static equilibrium is the one a damped rod settles on or oscillates about.

use crate::dynamics::cholesky::cholesky_factor_in_place;
use crate::dynamics::{mass_similar, SYMMETRY_TOLERANCE};
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::DMatrix;

/// Relative size of a negative eigenvalue of `M⁻¹ K_T` (against the largest `|ω²|`, the stiffest
/// mode's) below which it counts as divergence; above it, round-off of the eigensolver
/// (`~ε max |ω²|`) and neutral directions.
pub const DIVERGENCE_TOLERANCE: f64 = 1e-10;

/// [`DIVERGENCE_TOLERANCE`] of a symmetric `K_T`, whose eigenvalues are exact to round-off
/// (the module documentation, step 2).
pub const SYMMETRIC_TOLERANCE: f64 = 1e-13;

/// Largest imaginary part, relative to the largest `|ω²|`, of an eigenvalue taken as real (a double
/// real eigenvalue splits by `~√ε` into a complex pair).
const REAL_TOLERANCE: f64 = 1e-6;

/// The most negative real eigenvalue `ω²` \[1/s²\] of `M⁻¹ K_T` at the equilibrium `q`, `K_T = −jac`
/// (`jac = ∂R/∂q` there), if the equilibrium diverges; `None` if it is stable against divergence
/// (the module documentation). `ws` is left with the forward pass at `q`.
pub fn divergence<P: StrainParam>(
    model: &Model<P>,
    q: &nalgebra::DVector<f64>,
    jac: &DMatrix<f64>,
    ws: &mut Workspace,
) -> Option<f64> {
    let n = jac.nrows();
    if n == 0 {
        return None;
    }
    // a non-finite Jacobian is no equilibrium to judge: the solver reports non-finite values itself
    if jac.iter().any(|v| !v.is_finite()) || surely_stable(jac) {
        return None;
    }
    let mut l = model.mass_matrix(q, ws);
    let eig = pencil_eigenvalues(jac, &mut l)?;
    let scale = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let threshold = divergence_threshold(jac, scale);
    eig.iter()
        .filter(|z| z.im.abs() <= REAL_TOLERANCE * scale && z.re < threshold)
        .map(|z| z.re)
        .min_by(f64::total_cmp)
}

/// Below which a real eigenvalue `ω²` of `M⁻¹ K_T` counts as divergence, after step 1 failed
/// (the module documentation): `−SYMMETRIC_TOLERANCE · scale` for a symmetric `K_T` (step 2),
/// `−DIVERGENCE_TOLERANCE · scale` otherwise (step 3; `scale` the largest `|ω²|`).
fn divergence_threshold(jac: &DMatrix<f64>, scale: f64) -> f64 {
    match is_symmetric(jac) {
        true => -SYMMETRIC_TOLERANCE * scale,
        false => -DIVERGENCE_TOLERANCE * scale,
    }
}

/// `‖J − Jᵀ‖ ≤ SYMMETRY_TOLERANCE ‖J‖` (Frobenius), as [`Model::linearized_modes`] decides.
fn is_symmetric(jac: &DMatrix<f64>) -> bool {
    (jac - jac.transpose()).norm() <= SYMMETRY_TOLERANCE * jac.norm()
}

/// The divergent mode at the equilibrium `q` (tensions `u`, `loads`): the most negative real
/// eigenvalue `ω²` of `M⁻¹ K_T` and its eigenvector in `q` (of [`Model::linearized_modes`], scaled
/// to `‖φ‖∞ = 1`), the direction along which the rod leaves the equilibrium; `None` if it does not
/// diverge or the modes cannot be computed. A bifurcation (a compressed straight column) is left
/// along it onto the buckled branch.
pub fn divergent_mode<P: StrainParam>(
    model: &Model<P>,
    q: &nalgebra::DVector<f64>,
    u: &[f64],
    loads: &PreparedLoads,
    ws: &mut Workspace,
) -> Option<(f64, nalgebra::DVector<f64>)> {
    let modes = model.linearized_modes(q, u, loads, ws).ok()?;
    let scale = (modes.iter())
        .map(|m| m.omega_squared.hypot(m.omega_squared_imag))
        .fold(0.0, f64::max);
    let n = model.n_dof();
    let mut jac = DMatrix::zeros(n, n);
    model.statics_jacobian(q, u, loads, ws, &mut jac);
    let threshold = match surely_stable(&jac) {
        true => return None,
        false => divergence_threshold(&jac, scale),
    };
    let mode = (modes.iter())
        .filter(|m| {
            m.omega_squared_imag.abs() <= REAL_TOLERANCE * scale && m.omega_squared < threshold
        })
        .min_by(|a, b| a.omega_squared.total_cmp(&b.omega_squared))?;
    let size = mode.shape.amax();
    (size.is_finite() && size > 0.0).then(|| (mode.omega_squared, &mode.shape / size))
}

/// The eigenvalues of `M⁻¹ K_T`, `K_T = −jac`, as those of the similar `A = L⁻¹ K_T L⁻ᵀ`
/// (`M = L Lᵀ`, factored in place in `m`), or of `K_T` itself if `M` cannot be factored (the same
/// signs of real eigenvalues for a symmetric `K_T`, the best available otherwise). faer's blocked
/// triangular solves and eigenvalue solver: on an 1806-coordinate rod they take a few seconds
/// where nalgebra's unblocked ones took 35 s. `None` if the eigenvalue solver fails.
fn pencil_eigenvalues(jac: &DMatrix<f64>, m: &mut DMatrix<f64>) -> Option<Vec<faer::c64>> {
    let k = -jac;
    let a = match cholesky_factor_in_place(m) {
        Ok(()) => mass_similar(&k, m),
        Err(_) => faer::Mat::<f64>::from_fn(k.nrows(), k.ncols(), |i, j| k[(i, j)]),
    };
    a.eigenvalues().ok()
}

/// Whether `jac`'s tangent stiffness `K_T = −jac` has a positive definite symmetric part: the
/// first, sufficient test of [`divergence`] alone, for a screen with an approximate `∂R/∂q` (a
/// solver's last, Broyden-updated Jacobian) before an exact one is evaluated.
pub fn surely_stable(jac: &DMatrix<f64>) -> bool {
    let mut ks = (jac + jac.transpose()) * -0.5;
    ks.iter().all(|v| v.is_finite()) && positive_definite(&mut ks)
}

/// [`divergence`] at the equilibrium `q` under tensions `u` and `loads`: evaluates `∂R/∂q` there.
pub fn divergence_at<P: StrainParam>(
    model: &Model<P>,
    q: &nalgebra::DVector<f64>,
    u: &[f64],
    loads: &PreparedLoads,
    ws: &mut Workspace,
) -> Option<f64> {
    let n = model.n_dof();
    let mut jac = DMatrix::zeros(n, n);
    model.statics_jacobian(q, u, loads, ws, &mut jac);
    divergence(model, q, &jac, ws)
}

/// Whether the symmetric `a` is positive definite: scaled to a unit diagonal (`D^{-1/2} a D^{-1/2}`,
/// so that a soft bending coordinate is judged against its own stiffness, not the axial one's),
/// its Cholesky factorization (in place) meets no pivot clearly below zero
/// ([`cholesky_factor_in_place`]: pivots within `1e-8` of zero, neutral to round-off, pass).
pub(crate) fn positive_definite(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    if !(0..n).all(|j| a[(j, j)] > 0.0) {
        return false;
    }
    let d: Vec<f64> = (0..n).map(|j| a[(j, j)].sqrt().recip()).collect();
    for j in 0..n {
        for i in 0..n {
            a[(i, j)] *= d[i] * d[j];
        }
    }
    cholesky_factor_in_place(a).is_ok()
}
