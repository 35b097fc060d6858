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
//! 2. Otherwise the eigenvalues of `A = L⁻¹ K_T L⁻ᵀ`, `M = L Lᵀ` (similar to `M⁻¹ K_T`): none real
//!    and negative ⇒ stable. (Friction and follower loads make `K_T` non-symmetric, and its
//!    symmetric part may be indefinite at a stable equilibrium; complex pairs, the flutter of the
//!    undamped linearization as in Beck's column, are not divergence: their static equilibrium is
//!    the one a damped rod settles on or oscillates about.)
//! 3. Each real `ω² < 0` is judged by its mode `φ` (`K_T φ = ω² M φ`), against the stiffness
//!    itself rather than the other eigenvalues: divergent if `φᵀ K_T φ < −NEUTRAL_TOLERANCE
//!    |φ|ᵀ |K_T| |φ|` (the energy the direction releases, against the size of the terms that sum
//!    to it). This does not depend on how the mass is spread: a heavy payload on a light rod
//!    (a 10 g tip body on a 0.04 g column at twice Euler's load) diverges at `ω² = −12.3 1/s²`
//!    beside the rod's own modes near 6e11 1/s², which a threshold relative to the largest `|ω²|`
//!    missed; a neutral direction (the buckled column turning about the vertical) is round-off.
//!
//! Where `M` cannot be factored (a massless rod, `density = 0`, which statics accept) the signs of
//! `K_T`'s own eigenvalues are judged, relative to the largest (`DIVERGENCE_TOLERANCE`); the value
//! reported is then that eigenvalue, not an `ω²`.

use crate::dynamics::cholesky::cholesky_factor_in_place;
use crate::dynamics::{mass_similar, similar_modes, Mode};
use crate::model::{Model, PreparedLoads, Workspace};
use crate::strain::StrainParam;
use nalgebra::{DMatrix, DVector};

/// Relative size of a negative eigenvalue of `K_T` (against the largest), for a rod without mass,
/// below which it counts as divergence; above it, round-off and neutral directions.
pub const DIVERGENCE_TOLERANCE: f64 = 1e-10;

/// A real mode `φ` with `ω² < 0` diverges if `φᵀ K_T φ < −NEUTRAL_TOLERANCE |φ|ᵀ |K_T| |φ|`
/// (the module documentation, step 3); above it, round-off of `K_T` and of the equilibrium
/// (`ftol` 1e-10) along a neutral direction.
pub const NEUTRAL_TOLERANCE: f64 = 1e-8;

/// Largest imaginary part, relative to the largest `|ω²|`, of an eigenvalue taken as real (a double
/// real eigenvalue splits by `~√ε` into a complex pair).
const REAL_TOLERANCE: f64 = 1e-6;

/// The most negative real eigenvalue `ω²` \[1/s²\] of `M⁻¹ K_T` at the equilibrium `q`, `K_T = −jac`
/// (`jac = ∂R/∂q` there), if the equilibrium diverges; `None` if it is stable against divergence
/// (the module documentation). `ws` is left with the forward pass at `q`.
pub fn divergence<P: StrainParam>(
    model: &Model<P>,
    q: &DVector<f64>,
    jac: &DMatrix<f64>,
    ws: &mut Workspace,
) -> Option<f64> {
    match judge(model, q, jac, ws) {
        Verdict::Stable => None,
        Verdict::Diverges(mode) => Some(mode.omega_squared),
        Verdict::Massless(value) => Some(value),
    }
}

/// What [`judge`] finds at an equilibrium.
enum Verdict {
    Stable,
    /// The most negative divergent mode of `M⁻¹ K_T`.
    Diverges(Mode),
    /// `M` cannot be factored: the most negative eigenvalue of `K_T` itself.
    Massless(f64),
}

/// The test of the module documentation at the equilibrium `q` with `jac = ∂R/∂q` there.
fn judge<P: StrainParam>(
    model: &Model<P>,
    q: &DVector<f64>,
    jac: &DMatrix<f64>,
    ws: &mut Workspace,
) -> Verdict {
    // a non-finite Jacobian is no equilibrium to judge: the solver reports non-finite values itself
    if jac.nrows() == 0 || jac.iter().any(|v| !v.is_finite()) || surely_stable(jac) {
        return Verdict::Stable;
    }
    let k = -jac;
    let mut l = model.mass_matrix(q, ws);
    if cholesky_factor_in_place(&mut l).is_err() {
        return massless_divergence(&k).map_or(Verdict::Stable, Verdict::Massless);
    }
    let a = mass_similar(&k, &l);
    let Ok(eig) = a.eigenvalues() else {
        return Verdict::Stable;
    };
    let scale = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    if !(scale.is_finite() && scale > 0.0) {
        return Verdict::Stable;
    }
    let real_negative = |re: f64, im: f64| im.abs() <= REAL_TOLERANCE * scale && re < 0.0;
    if !eig.iter().any(|z| real_negative(z.re, z.im)) {
        return Verdict::Stable;
    }
    let Ok(modes) = similar_modes(&k, &a, &l) else {
        return Verdict::Stable;
    };
    (modes.into_iter())
        .filter(|m| real_negative(m.omega_squared, m.omega_squared_imag))
        .filter(|m| releases_energy(&k, &m.shape))
        .min_by(|a, b| a.omega_squared.total_cmp(&b.omega_squared))
        .map_or(Verdict::Stable, Verdict::Diverges)
}

/// `φᵀ K φ < −NEUTRAL_TOLERANCE |φ|ᵀ |K| |φ|`: the direction `φ` releases energy beyond round-off.
fn releases_energy(k: &DMatrix<f64>, phi: &DVector<f64>) -> bool {
    let (mut quad, mut size) = (0.0, 0.0);
    for j in 0..phi.len() {
        for i in 0..phi.len() {
            quad += phi[i] * k[(i, j)] * phi[j];
            size += (phi[i] * k[(i, j)] * phi[j]).abs();
        }
    }
    quad.is_finite() && quad < -NEUTRAL_TOLERANCE * size
}

/// A rod whose mass matrix cannot be factored: the most negative real eigenvalue of `K_T` itself
/// below `−DIVERGENCE_TOLERANCE` times the largest (the module documentation).
fn massless_divergence(k: &DMatrix<f64>) -> Option<f64> {
    let a = faer::Mat::<f64>::from_fn(k.nrows(), k.ncols(), |i, j| k[(i, j)]);
    let eig = a.eigenvalues().ok()?;
    let scale = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
    (eig.iter())
        .filter(|z| z.im.abs() <= REAL_TOLERANCE * scale && z.re < -DIVERGENCE_TOLERANCE * scale)
        .map(|z| z.re)
        .min_by(f64::total_cmp)
}

/// The divergent mode at the equilibrium `q` (tensions `u`, `loads`): the most negative real
/// eigenvalue `ω²` of `M⁻¹ K_T` that [`divergence`] counts and its eigenvector in `q` (as
/// [`Model::linearized_modes`] gives it, scaled to `‖φ‖∞ = 1`), the direction along which the rod
/// leaves the equilibrium; `None` if it does not diverge, or `M` cannot be factored. A bifurcation
/// (a compressed straight column) is left along it onto the buckled branch.
pub fn divergent_mode<P: StrainParam>(
    model: &Model<P>,
    q: &DVector<f64>,
    u: &[f64],
    loads: &PreparedLoads,
    ws: &mut Workspace,
) -> Option<(f64, DVector<f64>)> {
    let n = model.n_dof();
    let mut jac = DMatrix::zeros(n, n);
    model.statics_jacobian(q, u, loads, ws, &mut jac);
    let Verdict::Diverges(mode) = judge(model, q, &jac, ws) else {
        return None;
    };
    let size = mode.shape.amax();
    (size.is_finite() && size > 0.0).then(|| (mode.omega_squared, &mode.shape / size))
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
