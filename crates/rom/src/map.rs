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
//!
//! Matrices are column-major slices (`m × r`: element `(i, j)` at `i + j·m`). `eval` stores whatever
//! the later calls reuse (activations, their derivatives) in `scratch`, so a network's forward pass
//! runs once per evaluation; `eval_rate` and `add_weighted_hessian` are called after `eval` at the
//! same `z` with the same `scratch`, may use the rest of it as work space but must keep what `eval`
//! stored. No call allocates.

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
    /// `c_z_dot = (∂²c/∂z² ż)` (m × r): the derivative of `C_z` along `ż` (paper eq. 17).
    fn eval_rate(&self, z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]);
    /// `out += Σ_k g_k ∇²_z c_k` (r × r, column-major, symmetric).
    fn add_weighted_hessian(&self, z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]);
}
