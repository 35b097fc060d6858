//! Whether a division's quadrature points resolve its FEM strain basis: the stiffness they
//! integrate, `K = Σ W Φᵀ Es Φ`, must hold every function of the basis. Where the points miss a
//! combination of the functions (it nearly vanishes at each of them), that combination is a
//! zero- or near-zero-energy mode, and the equilibrium is one of many, silently wrong (a
//! 10-element linear basis under 12 Gauss points over the division: a mode with 3e-7 of its
//! stiffness, and the tip of a 0.5 m rod under a tip force 0.5 m off, at the base).
//!
//! The basis of `n_e` elements of degree `p` on `X̄ ∈ [0, 1]` has `p n_e + 1` functions per strain.
//! With `G = Σ_k W_k φ(X̄_k) φ(X̄_k)ᵀ` (φ the functions, spec §4.3) and `M = ∫ φ φᵀ dX̄` (the same
//! sum over `p + 1` Gauss points per basis element, which is exact), a uniform section's stiffness
//! is `Es ⊗ G` against the exactly integrated `Es ⊗ M`, and the points resolve the basis when
//!
//! ```text
//!   λ_min(G, M) ≥ τ = 0.1      ⇔      G − τ M positive definite,
//! ```
//!
//! every combination keeping at least a tenth of its exact stiffness. `G` and `M` are banded
//! (bandwidth `p`: functions `i`, `j` share an element only if `|i − j| ≤ p`), so a banded Cholesky
//! factorization of `O(p² n_e)` decides it. Measured `λ_min` on a 10-element basis (numpy's
//! generalized eigenvalues): 1 for the engine's defaults (`p + 1` points per basis element) and any
//! finer per-element quadrature; 0.75–0.89 for quadrature elements that straddle the basis's (7 × 3,
//! 15 × 1 and 20 × 1 points, linear); 0.35 (16), 0.66 (18) and up to 0.98 (40) for Gauss points
//! over a linear division; 0.015, 2.7e-7 and 0.032 for 11, 12 and 14 of them; 0 (singular) with
//! fewer points than functions per element. The check takes the section uniform: on a tapered
//! division the stiffness `Es(X)` weighs the points unevenly, which it does not see.

use gvs::discretize::{gauss_legendre, Quadrature};
use gvs::strain::{fem_shape, FemDegree};

/// The least fraction of its exactly integrated stiffness a combination of the basis's functions
/// must keep under the division's points.
pub(super) const TAU: f64 = 0.1;

/// The abscissae `X̄ ∈ [0, 1]` and weights (summing to 1) of a division's weighted quadrature
/// points, as the engine lays them out (Gauss–Legendre per quadrature element or over the
/// division).
pub(super) fn points(quadrature: &Quadrature) -> Vec<(f64, f64)> {
    match *quadrature {
        Quadrature::Gauss { n } => {
            let (x, w) = gauss_legendre(n);
            x.into_iter().zip(w).collect()
        }
        Quadrature::Elements {
            elements,
            gauss_per_element,
        } => {
            let (x, w) = gauss_legendre(gauss_per_element);
            let ne = elements as f64;
            (0..elements)
                .flat_map(|e| {
                    x.iter()
                        .zip(&w)
                        .map(move |(xi, wi)| ((e as f64 + xi) / ne, wi / ne))
                })
                .collect()
        }
    }
}

/// The polynomial degree of a FEM basis.
fn degree(d: FemDegree) -> usize {
    match d {
        FemDegree::Linear => 1,
        FemDegree::Quadratic => 2,
    }
}

/// Adds `c Σ_k W_k φ(X̄_k) φ(X̄_k)ᵀ` to the band `band[i][k] = A[i][i + k]` (`k ≤ p`).
fn add_gram(band: &mut [[f64; 3]], elements: usize, d: FemDegree, points: &[(f64, f64)], c: f64) {
    let p = degree(d);
    for &(x, w) in points {
        let (first, v) = fem_shape(x, elements, d);
        for a in 0..=p {
            for b in a..=p {
                band[first + a][b - a] += c * w * v[a] * v[b];
            }
        }
    }
}

/// The first function (node, `0 … p n_e`) of the basis of `elements` elements of `degree` at
/// which `G − τ M` of the module doc fails to be positive definite (the points under-resolve the
/// basis there), or `None` if they resolve it.
pub(super) fn under_resolved(
    elements: usize,
    degree_: FemDegree,
    points: &[(f64, f64)],
) -> Option<usize> {
    let p = degree(degree_);
    let n = p * elements + 1;
    let mut band = vec![[0.0f64; 3]; n];
    add_gram(&mut band, elements, degree_, points, 1.0);
    let exact = self::points(&Quadrature::Elements {
        elements,
        gauss_per_element: p + 1,
    });
    add_gram(&mut band, elements, degree_, &exact, -TAU);
    // A = Rᵀ R, R upper triangular with the same band, overwriting it row by row
    for i in 0..n {
        let pivot = band[i][0];
        // (NaN is not positive either)
        if pivot.is_nan() || pivot <= 0.0 {
            return Some(i);
        }
        let r = pivot.sqrt();
        band[i][0] = r;
        let last = p.min(n - 1 - i);
        for k in 1..=last {
            band[i][k] /= r;
        }
        for k in 1..=last {
            for l in k..=last {
                band[i + k][l - k] -= band[i][k] * band[i][l];
            }
        }
    }
    None
}

/// How many of the points lie in basis element `e` of `elements` (its closed interval).
pub(super) fn points_in_element(e: usize, elements: usize, points: &[(f64, f64)]) -> usize {
    let (a, b) = (e as f64 / elements as f64, (e + 1) as f64 / elements as f64);
    let tol = 1e-12;
    points
        .iter()
        .filter(|&&(x, _)| x >= a - tol && x <= b + tol)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn elements(elements: usize, gauss_per_element: usize) -> Vec<(f64, f64)> {
        points(&Quadrature::Elements {
            elements,
            gauss_per_element,
        })
    }

    fn gauss(n: usize) -> Vec<(f64, f64)> {
        points(&Quadrature::Gauss { n })
    }

    #[test]
    fn the_points_weights_sum_to_the_division() {
        for pts in [elements(7, 3), gauss(12)] {
            let sum: f64 = pts.iter().map(|(_, w)| w).sum();
            assert!((sum - 1.0).abs() < 1e-14, "{sum}");
            assert!(pts.iter().all(|&(x, _)| (0.0..=1.0).contains(&x)));
        }
    }

    #[test]
    fn the_engines_default_points_and_finer_ones_resolve_the_basis() {
        // as many quadrature elements as basis elements, p + 1 Gauss points each (the defaults:
        // exact, λ = 1), a finer quadrature, or one whose elements straddle the basis's
        for (degree, g) in [(FemDegree::Linear, 2), (FemDegree::Quadratic, 3)] {
            for ne in [1, 2, 5, 12, 160] {
                assert_eq!(under_resolved(ne, degree, &elements(ne, g)), None, "{ne}");
                assert_eq!(under_resolved(ne, degree, &elements(2 * ne, g)), None);
            }
        }
        // λ_min 0.85, 0.89, 0.75 (numpy, generalized eigenvalues of G and M)
        assert_eq!(under_resolved(10, FemDegree::Linear, &elements(7, 3)), None);
        assert_eq!(
            under_resolved(10, FemDegree::Linear, &elements(15, 1)),
            None
        );
        assert_eq!(
            under_resolved(10, FemDegree::Linear, &elements(20, 1)),
            None
        );
        // 13 and 16 Gauss points over the division: λ_min 0.85 and 0.35
        assert_eq!(under_resolved(10, FemDegree::Linear, &gauss(13)), None);
        assert_eq!(under_resolved(10, FemDegree::Linear, &gauss(16)), None);
    }

    #[test]
    fn too_few_points_or_points_that_miss_a_combination_are_caught() {
        // p points per element: p n_e points for p n_e + 1 functions (exactly singular)
        assert!(under_resolved(10, FemDegree::Linear, &elements(10, 1)).is_some());
        assert!(under_resolved(10, FemDegree::Quadratic, &elements(10, 2)).is_some());
        // half as many quadrature elements: 2 points per pair of basis elements
        let x = elements(5, 2);
        assert!(under_resolved(10, FemDegree::Linear, &x).is_some());
        assert!(points_in_element(1, 10, &x) < 2);
        // more points than functions, yet a combination nearly vanishes at all of them: 11, 12
        // and 14 Gauss points over the division for 11 linear functions (λ_min 0.015, 2.7e-7,
        // 0.032)
        for n in [11, 12, 14] {
            assert!(
                under_resolved(10, FemDegree::Linear, &gauss(n)).is_some(),
                "{n}"
            );
        }
        // quadratic, 25 Gauss points for 21 functions (λ_min 6.6e-4); 29 resolve it (0.82)
        assert!(under_resolved(10, FemDegree::Quadratic, &gauss(25)).is_some());
        assert_eq!(under_resolved(10, FemDegree::Quadratic, &gauss(29)), None);
    }

    #[test]
    fn a_neighbours_points_can_fix_a_shared_node() {
        // linear, 3 elements: 2 points in the first and last, none in the middle one, whose two
        // nodes its neighbours fix: every function is resolved, although a count of points per
        // element would refuse it
        let w = 0.25;
        let x = [(0.1, w), (0.2, w), (0.8, w), (0.9, w)];
        assert_eq!(points_in_element(1, 3, &x), 0);
        assert_eq!(under_resolved(3, FemDegree::Linear, &x), None);
        // a quadratic middle element has a function of its own, at its midpoint: unresolved
        let w = 1.0 / 6.0;
        let x = [0.05, 0.15, 0.3, 0.7, 0.85, 0.95].map(|x| (x, w));
        assert!(under_resolved(3, FemDegree::Quadratic, &x).is_some());
    }
}
