//! A map scaled by its first input: `c(z) = z₁ c̃(z)` — the decoder of a
//! [`crate::nn::DecoderForm::Scaled`] autoencoder.
//!
//! Every `z` with `z₁ = 0` maps to `c = 0`, the rest state, whatever the other coordinates: the
//! apex of a family of snapshots that shrink to rest as their load vanishes (paper §IV-B, the
//! moment pulse: `ξ = M g(X)`), which a plain smooth decoder can only approximate. Any smooth map
//! that vanishes on `z₁ = 0` has this form (Hadamard's lemma), so nothing else is given up.
//!
//! With `c̃`, `C̃ = ∂c̃/∂z` and `e₁` the first unit vector, the derivatives follow from the product
//! rule:
//!
//! - `C_z = z₁ C̃ + c̃ e₁ᵀ`;
//! - `Ċ_z = ż₁ C̃ + z₁ (∂²c̃/∂z² ż) + (C̃ ż) e₁ᵀ` (eq. 17);
//! - `Σ_k g_k ∇²c_k = z₁ Σ_k g_k ∇²c̃_k + e₁ vᵀ + v e₁ᵀ` with `v = C̃ᵀ g`;
//! - `ċ = ż₁ c̃ + z₁ (C̃ ż)`, `c̈ = z̈₁ c̃ + 2 ż₁ (C̃ ż) + z₁ ((∂²c̃/∂z² ż) ż + C̃ z̈)`;
//! - `C_zᵀ g = z₁ C̃ᵀ g + (c̃ · g) e₁`.
//!
//! The inner map's scratch comes first; after it this map keeps `z₁`, `c̃`, `C̃` (or `ċ̃`, `c̈̃`
//! after [`CoefficientMap::eval_motion`]) and a work vector of `m`.

use crate::map::CoefficientMap;

/// `c(z) = z₁ c̃(z)` for an inner map `c̃` (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ScaledMap<M> {
    inner: M,
}

impl<M: CoefficientMap> ScaledMap<M> {
    /// The map `z₁ · inner(z)`.
    pub fn new(inner: M) -> Self {
        ScaledMap { inner }
    }

    /// The unscaled map `c̃`.
    pub fn inner(&self) -> &M {
        &self.inner
    }

    /// `(inner scratch, z₁, c̃, C̃ (m × r), work (m))`.
    #[allow(clippy::type_complexity)]
    fn parts<'s>(
        &self,
        scratch: &'s mut [f64],
    ) -> (
        &'s mut [f64],
        &'s mut f64,
        &'s mut [f64],
        &'s mut [f64],
        &'s mut [f64],
    ) {
        let (m, r) = (self.inner.n_out(), self.inner.n_in());
        let (inner, own) = scratch.split_at_mut(self.inner.scratch_len());
        let (z1, own) = own.split_first_mut().expect("scratch_len covers z₁");
        let (c, own) = own.split_at_mut(m);
        let (c_z, work) = own.split_at_mut(m * r);
        (inner, z1, c, c_z, &mut work[..m])
    }
}

impl<M: CoefficientMap> CoefficientMap for ScaledMap<M> {
    fn n_in(&self) -> usize {
        self.inner.n_in()
    }

    fn n_out(&self) -> usize {
        self.inner.n_out()
    }

    fn scratch_len(&self) -> usize {
        let (m, r) = (self.inner.n_out(), self.inner.n_in());
        self.inner.scratch_len() + 1 + m * (2 + r)
    }

    fn eval(&self, z: &[f64], c: &mut [f64], c_z: &mut [f64], scratch: &mut [f64]) {
        let m = self.inner.n_out();
        let (inner, z1, c_t, c_z_t, _) = self.parts(scratch);
        self.inner.eval(z, c_t, c_z_t, inner);
        *z1 = z[0];
        for (o, v) in c.iter_mut().zip(c_t.iter()) {
            *o = z[0] * v;
        }
        for (o, v) in c_z.iter_mut().zip(c_z_t.iter()) {
            *o = z[0] * v;
        }
        for (o, v) in c_z[..m].iter_mut().zip(c_t.iter()) {
            *o += v;
        }
    }

    fn eval_value(&self, z: &[f64], c: &mut [f64], scratch: &mut [f64]) {
        let (inner, ..) = self.parts(scratch);
        self.inner.eval_value(z, c, inner);
        c.iter_mut().for_each(|v| *v *= z[0]);
    }

    fn eval_rate(&self, z: &[f64], zd: &[f64], c_z_dot: &mut [f64], scratch: &mut [f64]) {
        let (m, r) = (self.inner.n_out(), self.inner.n_in());
        let (inner, z1, _, c_z_t, work) = self.parts(scratch);
        self.inner.eval_rate(z, zd, c_z_dot, inner);
        // C̃ ż into `work`
        work.fill(0.0);
        for (col, &v) in c_z_t.chunks_exact(m).zip(zd) {
            work.iter_mut().zip(col).for_each(|(w, c)| *w += v * c);
        }
        for (o, c) in c_z_dot.iter_mut().zip(c_z_t.iter()) {
            *o = zd[0] * c + *z1 * *o;
        }
        for (o, w) in c_z_dot[..m].iter_mut().zip(work.iter()) {
            *o += w;
        }
        debug_assert_eq!(c_z_dot.len(), m * r);
    }

    fn add_weighted_hessian(&self, z: &[f64], g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let (m, r) = (self.inner.n_out(), self.inner.n_in());
        let (inner, z1, _, c_z_t, work) = self.parts(scratch);
        // z₁ Σ g_k ∇²c̃_k as the inner Hessian weighted by z₁ g
        work.iter_mut().zip(g).for_each(|(w, g)| *w = *z1 * g);
        self.inner.add_weighted_hessian(z, work, out, inner);
        // + e₁ vᵀ + v e₁ᵀ, v = C̃ᵀ g
        for (j, col) in c_z_t.chunks_exact(m).enumerate() {
            let v: f64 = col.iter().zip(g).map(|(c, g)| c * g).sum();
            out[r * j] += v;
            out[j] += v;
        }
    }

    fn eval_motion(
        &self,
        z: &[f64],
        zd: &[f64],
        zdd: Option<&[f64]>,
        c: &mut [f64],
        c_dot: &mut [f64],
        c_acc: &mut [f64],
        scratch: &mut [f64],
    ) {
        let (inner, z1, c_t, ..) = self.parts(scratch);
        self.inner.eval_motion(z, zd, zdd, c_t, c_dot, c_acc, inner);
        *z1 = z[0];
        let (zd1, zdd1) = (zd[0], zdd.map_or(0.0, |a| a[0]));
        for (((c, cd), ca), ct) in c
            .iter_mut()
            .zip(c_dot.iter_mut())
            .zip(c_acc.iter_mut())
            .zip(c_t.iter())
        {
            *ca = zdd1 * ct + 2.0 * zd1 * *cd + z[0] * *ca;
            *cd = zd1 * ct + z[0] * *cd;
            *c = z[0] * ct;
        }
    }

    fn vjp(&self, g: &[f64], out: &mut [f64], scratch: &mut [f64]) {
        let (inner, z1, c_t, ..) = self.parts(scratch);
        self.inner.vjp(g, out, inner);
        out.iter_mut().for_each(|o| *o *= *z1);
        out[0] += c_t.iter().zip(g).map(|(c, g)| c * g).sum::<f64>();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::DecoderMap;
    use gvs::inputs::SplitMix64;

    /// A random decoder `r → 6 → 5 → 7` folded with a random scaling and a random 3 × 7 projection
    /// (the decoder map's own test map), scaled by `z₁`.
    fn random_map(r: usize, rng: &mut SplitMix64) -> ScaledMap<DecoderMap> {
        ScaledMap::new(crate::nn::decoder_map::tests::random_map(r, rng))
    }

    /// `z₁ c̃(z)` evaluated directly, from the inner map's value.
    fn value(map: &ScaledMap<DecoderMap>, z: &[f64]) -> Vec<f64> {
        let mut c = vec![0.0; map.n_out()];
        let mut s = vec![0.0; map.inner().scratch_len()];
        map.inner().eval_value(z, &mut c, &mut s);
        c.iter().map(|v| z[0] * v).collect()
    }

    fn central(z: &[f64], d: &[f64], f: impl Fn(&[f64]) -> Vec<f64>) -> Vec<f64> {
        const H: f64 = 1e-5;
        let at =
            |sign: f64| -> Vec<f64> { z.iter().zip(d).map(|(z, d)| z + sign * H * d).collect() };
        f(&at(1.0))
            .iter()
            .zip(f(&at(-1.0)))
            .map(|(p, m)| (p - m) / (2.0 * H))
            .collect()
    }

    fn assert_close(what: &str, got: &[f64], expected: &[f64], tol: f64) {
        assert_eq!(got.len(), expected.len(), "{what}: length");
        for (i, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!(
                (g - e).abs() <= tol * (1.0 + e.abs()),
                "{what}[{i}]: {g} vs {e}"
            );
        }
    }

    /// `(c, C_z, scratch)` through [`CoefficientMap::eval`].
    fn eval_at(map: &ScaledMap<DecoderMap>, z: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (m, r) = (map.n_out(), map.n_in());
        let (mut c, mut c_z, mut s) =
            (vec![0.0; m], vec![0.0; m * r], vec![0.0; map.scratch_len()]);
        map.eval(z, &mut c, &mut c_z, &mut s);
        (c, c_z, s)
    }

    #[test]
    fn z1_zero_maps_to_the_rest_state_whatever_the_other_coordinates() {
        let mut rng = SplitMix64::new(5);
        let map = random_map(3, &mut rng);
        for _ in 0..5 {
            let z = [0.0, rng.range(-2.0, 2.0), rng.range(-2.0, 2.0)];
            let (c, c_z, _) = eval_at(&map, &z);
            assert!(c.iter().all(|&v| v == 0.0), "c = {c:?}");
            // only ∂c/∂z₁ = c̃ survives
            assert!(c_z[3..].iter().all(|&v| v == 0.0));
            assert!(c_z[..3].iter().any(|&v| v != 0.0));
        }
    }

    #[test]
    fn derivatives_of_the_scaled_map_equal_central_differences() {
        let mut rng = SplitMix64::new(11);
        for r in [1, 2, 3] {
            let map = random_map(r, &mut rng);
            let m = map.n_out();
            let rv = |n: usize, rng: &mut SplitMix64| -> Vec<f64> {
                (0..n).map(|_| rng.range(-1.0, 1.0)).collect()
            };
            let (z, zd, zdd, g) = (
                rv(r, &mut rng),
                rv(r, &mut rng),
                rv(r, &mut rng),
                rv(m, &mut rng),
            );
            let (c, c_z, mut s) = eval_at(&map, &z);
            assert_close("c", &c, &value(&map, &z), 1e-14);
            // C_z column j against the central difference along e_j
            for j in 0..r {
                let mut e = vec![0.0; r];
                e[j] = 1.0;
                let fd = central(&z, &e, |z| value(&map, z));
                assert_close("C_z", &c_z[j * m..(j + 1) * m], &fd, 1e-8);
            }
            // Ċ_z against the difference of C_z along ż
            let mut c_z_dot = vec![0.0; m * r];
            map.eval_rate(&z, &zd, &mut c_z_dot, &mut s);
            let fd = central(&z, &zd, |z| eval_at(&map, z).1);
            assert_close("C_z_dot", &c_z_dot, &fd, 1e-7);
            // Σ g_k ∇²c_k against the difference of C_zᵀ g
            let mut h = vec![0.0; r * r];
            map.add_weighted_hessian(&z, &g, &mut h, &mut s);
            for j in 0..r {
                let mut e = vec![0.0; r];
                e[j] = 1.0;
                let fd = central(&z, &e, |z| {
                    let c_z = eval_at(&map, z).1;
                    c_z.chunks_exact(m)
                        .map(|col| col.iter().zip(&g).map(|(a, b)| a * b).sum())
                        .collect()
                });
                assert_close("Hessian", &h[j * r..(j + 1) * r], &fd, 1e-7);
            }
            // C_zᵀ g by the reverse pass, after eval
            let mut vjp = vec![0.0; r];
            map.vjp(&g, &mut vjp, &mut s);
            let expected: Vec<f64> = c_z
                .chunks_exact(m)
                .map(|col| col.iter().zip(&g).map(|(a, b)| a * b).sum())
                .collect();
            assert_close("vjp after eval", &vjp, &expected, 1e-13);
            // the motion: c, C_z ż, Ċ_z ż + C_z z̈; then the reverse pass again
            let (mut cm, mut cd, mut ca) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
            let mut s2 = vec![0.0; map.scratch_len()];
            map.eval_motion(&z, &zd, Some(&zdd), &mut cm, &mut cd, &mut ca, &mut s2);
            let mat = |a: &[f64], v: &[f64]| -> Vec<f64> {
                (0..m)
                    .map(|i| (0..r).map(|j| a[i + j * m] * v[j]).sum())
                    .collect()
            };
            let acc: Vec<f64> = mat(&c_z_dot, &zd)
                .iter()
                .zip(mat(&c_z, &zdd))
                .map(|(a, b)| a + b)
                .collect();
            assert_close("motion c", &cm, &c, 1e-14);
            assert_close("motion c_dot", &cd, &mat(&c_z, &zd), 1e-13);
            assert_close("motion c_acc", &ca, &acc, 1e-12);
            map.vjp(&g, &mut vjp, &mut s2);
            assert_close("vjp after eval_motion", &vjp, &expected, 1e-13);
        }
    }
}
