//! Smooth maps from reduced coordinates to the HOM's basis coefficients, with the derivatives the
//! engine needs (architecture, "the one idea").
//!
//! A reduced parameterization of this crate is `Ψ_s(q_r) = Φ_s c(q_r)`: `Φ_s` is the high-order
//! model's own basis at strain site `s` and `c: Rʳ → Rᵐ` a smooth map (a decoder network followed by
//! a fixed least-squares projection onto the basis coefficients, or a constant matrix for POD). Every
//! derivative of `Ψ` is `Φ_s` times the same derivative of `c`, so a map only supplies:
//!
//! | quantity | shape | meaning |
//! |---|---|---|
//! | `c(z)` | m | value |
//! | `C_z = ∂c/∂z` | m × r | Jacobian |
//! | `Ċ_z = (∂²c/∂z² ż)` | m × r | directional second derivative (paper eq. 17) |
//! | `Σ_k g_k ∇²c_k` | r × r | Hessian contracted with output weights `g` (statics Jacobian) |
//! | `c`, `C_z ż`, `Ċ_z ż + C_z z̈` | m each | the motion of a dynamics residual pass: `c(z(t))` and its first two time derivatives |
//! | `C_zᵀ g` | r | the projection of forces (reverse mode) |
//!
//! Matrices are column-major slices (`m × r`: element `(i, j)` at `i + j·m`). `eval` stores whatever
//! the later calls reuse (activations, their derivatives) in `scratch`, so a network's forward pass
//! runs once per evaluation; `eval_rate` and `add_weighted_hessian` are called after `eval` at the
//! same `z` with the same `scratch`, may use the rest of it as work space but must keep what `eval`
//! stored. `vjp` is called after `eval` or `eval_motion` (which stores what `vjp` needs, no more).
//! No call allocates.

/// A smooth map `c: Rʳ → Rᵐ` with first derivatives, the eq. (17) term and weighted Hessians.
pub trait CoefficientMap: Send + Sync {
    /// Input size r (the reduced coordinates).
    fn n_in(&self) -> usize;
    /// Output size m.
    fn n_out(&self) -> usize;
    /// Length of the scratch buffer [`CoefficientMap::eval`] needs.
    fn scratch_len(&self) -> usize;
    /// `c = c(z)` and `c_z = ∂c/∂z` (m × r, column-major); fills `scratch` for the calls below.
    fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]);
    /// `c = c(z)` alone (a pose, output): no derivative, nothing kept in `scratch` for later calls.
    fn eval_value(&self, z: &[f64], c: &mut [f64], scratch: &mut [f64]);
    /// `c_z_dot = (∂²c/∂z² ż)` (m × r): the derivative of `C_z` along `ż` (paper eq. 17).
    fn eval_rate(&self, z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]);
    /// `out += Σ_k g_k ∇²_z c_k` (r × r, column-major, symmetric).
    fn add_weighted_hessian(&self, z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]);
    /// The motion of `c` along `z(t)` with `z(0) = z`, `ż(0) = zd`, `z̈(0) = zdd` (0 if `None`):
    /// `c = c(z)`, `c_dot = C_z ż`, `c_acc = (∂²c/∂z² ż) ż + C_z z̈` — two directional derivatives,
    /// not the `r` of [`CoefficientMap::eval`]. Fills `scratch` for [`CoefficientMap::vjp`].
    #[allow(clippy::too_many_arguments)]
    fn eval_motion(
        &self,
        z: &[f64],
        zd: &[f64],
        zdd: Option<&[f64]>,
        c: &mut [f64],
        c_dot: &mut [f64],
        c_acc: &mut [f64],
        scratch: &mut [f64],
    );
    /// `out = C_zᵀ g` (r) at the `z` of the last [`CoefficientMap::eval`] or
    /// [`CoefficientMap::eval_motion`] with the same `scratch`.
    fn vjp(&self, g: &[f64], out: &mut [f64], scratch: &mut [f64]);
}
