//! Value, Jacobian, eq. (17) term, weighted Hessian, motion and reverse pass of the folded decoder
//! against central differences and against `Autoencoder::decode`.

use super::*;
use crate::nn::{Autoencoder, DecoderForm};
use gvs::inputs::SplitMix64;

/// A random `sizes` network with weights of Glorot size ×1.5 (clearly nonlinear) and random biases.
fn random_mlp(sizes: &[usize], rng: &mut SplitMix64) -> Mlp {
    let base = Mlp::glorot(sizes, rng).unwrap();
    let weights = (0..base.n_layers())
        .map(|k| base.weights(k).iter().map(|w| 1.5 * w).collect())
        .collect();
    let biases = (0..base.n_layers())
        .map(|k| {
            base.biases(k)
                .iter()
                .map(|_| rng.range(-0.5, 0.5))
                .collect()
        })
        .collect();
    Mlp::new(sizes, weights, biases).unwrap()
}

fn random_vec(len: usize, lo: f64, hi: f64, rng: &mut SplitMix64) -> Vec<f64> {
    (0..len).map(|_| rng.range(lo, hi)).collect()
}

/// A random decoder `r → 6 → 5 → 7` folded with a random scaling and a random 3 × 7 `A`.
pub(crate) fn random_map(r: usize, rng: &mut SplitMix64) -> DecoderMap {
    let decoder = random_mlp(&[r, 6, 5, 7], rng);
    let scaling =
        Scaling::new(random_vec(7, -1.0, 1.0, rng), random_vec(7, 0.2, 2.0, rng)).unwrap();
    DecoderMap::new(&decoder, &scaling, &random_vec(3 * 7, -1.0, 1.0, rng), 3).unwrap()
}

/// `(c, C_z, scratch)` at `z`.
fn eval_at(map: &impl CoefficientMap, z: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (m, r) = (map.n_out(), map.n_in());
    let (mut c, mut c_z, mut scratch) =
        (vec![0.0; m], vec![0.0; m * r], vec![0.0; map.scratch_len()]);
    map.eval(z, &mut c, &mut c_z, &mut scratch);
    (c, c_z, scratch)
}

/// Central difference `(f(z + h d) − f(z − h d)) / 2h` of a vector function.
fn central(z: &[f64], d: &[f64], f: impl Fn(&[f64]) -> Vec<f64>) -> Vec<f64> {
    const H: f64 = 1e-5;
    let shifted = |sign: f64| {
        z.iter()
            .zip(d)
            .map(|(z, d)| z + sign * H * d)
            .collect::<Vec<_>>()
    };
    f(&shifted(1.0))
        .iter()
        .zip(f(&shifted(-1.0)))
        .map(|(p, m)| (p - m) / (2.0 * H))
        .collect()
}

/// `‖fd − exact‖∞ ≤ 1e-6 ‖exact‖∞`: central differences with h = 1e-5 have truncation error
/// ≈ h²·|c'''|/6 ≈ 1e-10 and rounding ≈ 1e-16/h ≈ 1e-11 on these O(1) networks.
fn assert_relative(fd: &[f64], exact: &[f64], what: &str) {
    let scale = exact.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let err = fd
        .iter()
        .zip(exact)
        .fold(0.0f64, |a, (f, e)| a.max((f - e).abs()));
    assert!(
        err <= 1e-6 * scale,
        "{what}: error {err:e} vs scale {scale:e}\nfd {fd:?}\nexact {exact:?}"
    );
}

#[test]
fn jacobian_matches_central_differences_for_r_1_2_3() {
    let mut rng = SplitMix64::new(11);
    for r in [1, 2, 3, 6] {
        let map = random_map(r, &mut rng);
        let z = random_vec(r, -1.0, 1.0, &mut rng);
        let (_, c_z, _) = eval_at(&map, &z);
        for l in 0..r {
            let e: Vec<f64> = (0..r).map(|j| if j == l { 1.0 } else { 0.0 }).collect();
            let fd = central(&z, &e, |z| eval_at(&map, z).0);
            assert_relative(
                &fd,
                &c_z[l * 3..(l + 1) * 3],
                &format!("r = {r}, column {l}"),
            );
        }
    }
}

#[test]
fn motion_is_the_first_and_second_time_derivative_of_c_along_a_parabola() {
    // z(t) = z + t ż + t²/2 z̈: ċ(0) and c̈(0) by central differences of c(z(t)) in t, h = 1e-4
    // (second difference: truncation h²·|c⁗|/12 ≈ 1e-9, rounding 4·1e-16/h² ≈ 4e-8 on O(1) values)
    let mut rng = SplitMix64::new(17);
    for r in [1, 2, 3, 6] {
        let map = random_map(r, &mut rng);
        let z = random_vec(r, -1.0, 1.0, &mut rng);
        let zd = random_vec(r, -2.0, 2.0, &mut rng);
        let zdd = random_vec(r, -3.0, 3.0, &mut rng);
        let m = map.n_out();
        let at = |t: f64| {
            let zt: Vec<f64> = (0..r)
                .map(|i| z[i] + t * zd[i] + 0.5 * t * t * zdd[i])
                .collect();
            eval_at(&map, &zt).0
        };
        const H: f64 = 1e-4;
        let (cp, c0, cm) = (at(H), at(0.0), at(-H));
        let fd_dot: Vec<f64> = (0..m).map(|i| (cp[i] - cm[i]) / (2.0 * H)).collect();
        let fd_acc: Vec<f64> = (0..m)
            .map(|i| (cp[i] - 2.0 * c0[i] + cm[i]) / (H * H))
            .collect();
        let mut scratch = vec![0.0; map.scratch_len()];
        let (mut c, mut c_dot, mut c_acc) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        map.eval_motion(
            &z,
            &zd,
            Some(&zdd),
            &mut c,
            &mut c_dot,
            &mut c_acc,
            &mut scratch,
        );
        assert_relative(&c0, &c, &format!("r = {r}: value"));
        assert_relative(&fd_dot, &c_dot, &format!("r = {r}: ċ"));
        let scale = c_acc.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let err = fd_acc
            .iter()
            .zip(&c_acc)
            .fold(0.0f64, |a, (f, e)| a.max((f - e).abs()));
        assert!(
            err <= 1e-5 * scale,
            "r = {r}: c̈ off by {err:e} (scale {scale:e})"
        );
        // without z̈: the curvature term alone, (∂²c/∂z² ż) ż = Ċ_z ż from eval_rate
        map.eval_motion(&z, &zd, None, &mut c, &mut c_dot, &mut c_acc, &mut scratch);
        let (_, _, mut full) = eval_at(&map, &z);
        let mut rate = vec![0.0; m * r];
        map.eval_rate(&z, &zd, &mut rate, &mut full);
        let curvature: Vec<f64> = (0..m)
            .map(|i| (0..r).map(|l| rate[i + l * m] * zd[l]).sum())
            .collect();
        assert_relative(&c_acc, &curvature, &format!("r = {r}: c̈ at z̈ = 0"));
    }
}

#[test]
fn reverse_pass_is_the_transposed_jacobian_after_either_evaluation() {
    let mut rng = SplitMix64::new(18);
    for r in [1, 2, 3, 6] {
        let map = random_map(r, &mut rng);
        let m = map.n_out();
        let z = random_vec(r, -1.0, 1.0, &mut rng);
        let g = random_vec(m, -1.0, 1.0, &mut rng);
        let (_, c_z, mut scratch) = eval_at(&map, &z);
        // C_zᵀ g from the Jacobian (checked against central differences above)
        let expected: Vec<f64> = (0..r)
            .map(|l| (0..m).map(|i| c_z[i + l * m] * g[i]).sum())
            .collect();
        let mut out = vec![f64::NAN; r];
        map.vjp(&g, &mut out, &mut scratch);
        assert_relative(&out, &expected, &format!("r = {r}: after eval"));
        let mut fresh = vec![0.0; map.scratch_len()];
        let zd = random_vec(r, -1.0, 1.0, &mut rng);
        let (mut c, mut c_dot, mut c_acc) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        map.eval_motion(&z, &zd, None, &mut c, &mut c_dot, &mut c_acc, &mut fresh);
        map.vjp(&g, &mut out, &mut fresh);
        assert_relative(&out, &expected, &format!("r = {r}: after eval_motion"));
    }
}

#[test]
fn eq17_rate_term_matches_derivative_of_jacobian_along_zdot() {
    let mut rng = SplitMix64::new(12);
    for r in [1, 2, 3, 6] {
        let map = random_map(r, &mut rng);
        let z = random_vec(r, -1.0, 1.0, &mut rng);
        let zd = random_vec(r, -2.0, 2.0, &mut rng);
        let (_, _, mut scratch) = eval_at(&map, &z);
        let mut rate = vec![0.0; 3 * r];
        map.eval_rate(&z, &zd, &mut rate, &mut scratch);
        let fd = central(&z, &zd, |z| eval_at(&map, z).1);
        assert_relative(&fd, &rate, &format!("r = {r}"));
    }
}

#[test]
fn weighted_hessian_matches_central_differences_and_accumulates() {
    let mut rng = SplitMix64::new(13);
    for r in [1, 2, 3, 6] {
        let map = random_map(r, &mut rng);
        let z = random_vec(r, -1.0, 1.0, &mut rng);
        let g = random_vec(3, -1.0, 1.0, &mut rng);
        let (_, _, mut scratch) = eval_at(&map, &z);
        let offset = random_vec(r * r, -1.0, 1.0, &mut rng);
        let mut out = offset.clone();
        map.add_weighted_hessian(&z, &g, &mut out, &mut scratch);
        let added: Vec<f64> = out.iter().zip(&offset).map(|(o, a)| o - a).collect();
        // Column j of Σ_i g_i ∇²c_i is ∂/∂z_j of gᵀ C_z (a row of length r).
        let g_c_z = |z: &[f64]| {
            let c_z = eval_at(&map, z).1;
            (0..r)
                .map(|l| (0..3).map(|i| g[i] * c_z[i + 3 * l]).sum())
                .collect::<Vec<f64>>()
        };
        for j in 0..r {
            let e: Vec<f64> = (0..r).map(|k| if k == j { 1.0 } else { 0.0 }).collect();
            let fd = central(&z, &e, g_c_z);
            assert_relative(
                &fd,
                &added[j * r..(j + 1) * r],
                &format!("r = {r}, column {j}"),
            );
        }
        // exactly symmetric as computed (from a zero start)
        let mut fresh = vec![0.0; r * r];
        map.add_weighted_hessian(&z, &g, &mut fresh, &mut scratch);
        for (l, j) in (0..r).flat_map(|l| (0..r).map(move |j| (l, j))) {
            assert_eq!(fresh[l + r * j], fresh[j + r * l], "symmetry");
        }
    }
}

#[test]
fn identity_projection_reproduces_autoencoder_decode_with_and_without_derivatives() {
    let mut rng = SplitMix64::new(14);
    let forms = [DecoderForm::Plain, DecoderForm::Scaled];
    for (r, form) in [1, 2, 3, 6].into_iter().flat_map(|r| forms.map(|f| (r, f))) {
        let encoder = random_mlp(&[7, 5, r], &mut rng);
        let decoder = random_mlp(&[r, 5, 7], &mut rng);
        let scaling = Scaling::new(
            random_vec(7, -1.0, 1.0, &mut rng),
            random_vec(7, 0.2, 2.0, &mut rng),
        )
        .unwrap();
        let ae = Autoencoder::new(encoder, decoder, scaling)
            .unwrap()
            .with_form(form);
        let identity: Vec<f64> = (0..49)
            .map(|k| if k % 8 == 0 { 1.0 } else { 0.0 })
            .collect();
        let map = ae.decoder_map(&identity, 7).unwrap();
        let z = random_vec(r, -1.5, 1.5, &mut rng);
        let (c, _, _) = eval_at(&map, &z);
        // the value-only pass, after a full one (its stored part must not matter)
        let mut value = vec![0.0; 7];
        let mut scratch = vec![0.0; map.scratch_len()];
        map.eval_value(&z, &mut value, &mut scratch);
        let decoded = ae.decode(&z).unwrap();
        // Folding s into W and the loop vs dgemm summation orders differ only by rounding.
        for ((c, v), d) in c.iter().zip(&value).zip(&decoded) {
            assert!((c - d).abs() <= 1e-13 * (1.0 + d.abs()), "{c} vs {d}");
            assert!(
                (v - d).abs() <= 1e-13 * (1.0 + d.abs()),
                "value pass {v} vs {d}"
            );
        }
    }
}

#[test]
fn new_rejects_projection_of_wrong_shape() {
    let mut rng = SplitMix64::new(15);
    let decoder = random_mlp(&[2, 4, 5], &mut rng);
    let scaling = Scaling::identity(5);
    assert!(matches!(
        DecoderMap::new(&decoder, &scaling, &[0.0; 9], 2),
        Err(NnError::DataShape { .. })
    ));
    assert!(matches!(
        DecoderMap::new(&decoder, &Scaling::identity(4), &[0.0; 10], 2),
        Err(NnError::Mismatch { .. })
    ));
}
