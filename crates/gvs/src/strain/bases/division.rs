//! The basis of one division (gvs-spec §4.1–4.3): Legendre polynomials or FEM-like local shape
//! functions per strain mode, and the order of their columns in `q`.
//!
//! Per division j, `Φ_j(X) = S_j Φ̄(X̄)` with `S_j = diag(1/ℓ_j, 1/ℓ_j, 1/ℓ_j, 1, 1, 1)`: angular
//! coordinates are angles, linear coordinates dimensionless strains (spec §4.1). Legendre columns are
//! ordered mode by mode (torsion, bend-y, bend-z, elongation, shear-y, shear-z), by increasing degree
//! inside a mode (spec §4.1). FEM-like columns are ordered **node by node**, the active modes in that
//! order inside a node (column `k·m + a` is node `k` of the `a`-th of the `m` active modes; with one
//! active mode this is spec §4.1's order), so that the support of a site — the nodes of its element,
//! every mode — is one contiguous range of `(p + 1)·m` columns
//! ([`StrainParam::columns`](crate::strain::StrainParam::columns)). Divisions follow each other in
//! `q`.

use crate::error::ModelError;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Names the order of the generalized coordinates `q` (module docs): files that store `q` record it,
/// so that coordinates written under another order are never mixed with these. Before it, FEM-like
/// bases with several modes were ordered mode by mode (`"fem-mode-major"`).
pub const COORDINATE_ORDER: &str = "fem-node-major";

/// Polynomial degree of a FEM-like local basis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FemDegree {
    Linear,
    Quadratic,
}

/// The basis of one division. `modes[i]` says whether strain component i is active.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum DivisionBasis {
    /// Unnormalized Legendre polynomials `P_0..P_k` of `x = 2X̄ − 1`, order `k = orders[i]` per mode.
    Legendre {
        modes: [bool; 6],
        orders: [usize; 6],
    },
    /// Local (nodal) basis on `elements` equal elements: `elements·p + 1` columns per active mode.
    Fem {
        modes: [bool; 6],
        elements: usize,
        degree: FemDegree,
    },
}

impl DivisionBasis {
    /// Number of coordinates of the division.
    pub fn dofs(&self) -> usize {
        (0..6).map(|i| self.mode_dofs(i)).sum()
    }

    fn mode_dofs(&self, i: usize) -> usize {
        match self {
            DivisionBasis::Legendre { modes, orders } => {
                if modes[i] {
                    orders[i] + 1
                } else {
                    0
                }
            }
            DivisionBasis::Fem {
                modes,
                elements,
                degree,
            } => {
                if modes[i] {
                    elements * degree_of(*degree) + 1
                } else {
                    0
                }
            }
        }
    }

    pub fn validate(&self, field: &str) -> Result<(), ModelError> {
        if self.dofs() == 0 {
            return Err(ModelError::invalid(
                field,
                "the basis is empty: activate at least one strain mode",
            ));
        }
        if let DivisionBasis::Fem { elements, .. } = self {
            if *elements == 0 {
                return Err(ModelError::value(
                    format!("{field}.elements"),
                    0.0,
                    "an integer >= 1",
                ));
            }
        }
        Ok(())
    }

    /// Writes `Φ̄(X̄)` scaled by `S_j` (6 × dofs) into `out` (which must be zeroed).
    pub fn fill(&self, x_bar: f64, length: f64, out: &mut nalgebra::DMatrixViewMut<'_, f64>) {
        let scale = |i: usize| if i < 3 { 1.0 / length } else { 1.0 };
        match self {
            DivisionBasis::Legendre { .. } => {
                let x = 2.0 * x_bar - 1.0;
                let mut col = 0;
                for i in 0..6 {
                    let nd = self.mode_dofs(i);
                    let (mut p0, mut p1) = (1.0, x);
                    for m in 0..nd {
                        let v = match m {
                            0 => 1.0,
                            1 => x,
                            _ => {
                                let k = (m - 1) as f64;
                                let p2 = ((2.0 * k + 1.0) * x * p1 - k * p0) / (k + 1.0);
                                p0 = p1;
                                p1 = p2;
                                p2
                            }
                        };
                        out[(i, col + m)] = v * scale(i);
                    }
                    col += nd;
                }
            }
            DivisionBasis::Fem {
                modes,
                elements,
                degree,
            } => {
                let m = modes.iter().filter(|&&a| a).count();
                let (first, values) = fem_shape(x_bar, *elements, *degree);
                let active = (0..6).filter(|&i| modes[i]);
                for (slot, i) in active.enumerate() {
                    for (k, v) in values.iter().enumerate().take(degree_of(*degree) + 1) {
                        out[(i, (first + k) * m + slot)] += v * scale(i);
                    }
                }
            }
        }
    }

    /// The columns (relative to the division's first) on which `Φ̄(X̄)` may be non-zero: all of them
    /// for Legendre; the nodes of the element holding `X̄`, every active mode, for FEM-like bases.
    pub fn support(&self, x_bar: f64) -> Range<usize> {
        match self {
            DivisionBasis::Legendre { .. } => 0..self.dofs(),
            DivisionBasis::Fem {
                modes,
                elements,
                degree,
            } => {
                let m = modes.iter().filter(|&&a| a).count();
                let (first, _) = fem_shape(x_bar, *elements, *degree);
                first * m..(first + degree_of(*degree) + 1) * m
            }
        }
    }
}

/// The FEM-like shape functions at `X̄` (spec §4.3): the first node of the element holding `X̄` and
/// the values of its `p + 1` nodal functions (element `e = ⌊n_e X̄⌋`, `χ = n_e X̄ − e`; linear
/// `1 − χ, χ`; quadratic `2(χ − ½)(χ − 1), −4χ(χ − 1), 2χ(χ − ½)`).
pub fn fem_shape(x_bar: f64, ne: usize, degree: FemDegree) -> (usize, [f64; 3]) {
    let e = ((x_bar * ne as f64 + 1e-12).floor() as usize).min(ne - 1);
    let chi = x_bar * ne as f64 - e as f64;
    match degree {
        FemDegree::Linear => (e, [1.0 - chi, chi, 0.0]),
        FemDegree::Quadratic => (
            2 * e,
            [
                2.0 * (chi - 0.5) * (chi - 1.0),
                -4.0 * chi * (chi - 1.0),
                2.0 * chi * (chi - 0.5),
            ],
        ),
    }
}

fn degree_of(d: FemDegree) -> usize {
    match d {
        FemDegree::Linear => 1,
        FemDegree::Quadratic => 2,
    }
}
