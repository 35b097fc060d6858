//! Computational points and Magnus collocation (gvs-spec §5).
//!
//! Per division the points are either
//! * **global quadrature** — `N` Gauss–Legendre nodes on `X̄ ∈ [0,1]` plus the two ends (weight 0),
//!   `n_ip = N + 2` points (spec §5.1; the paper's "102 points" are N = 100), or
//! * **per-element quadrature** for FEM-like bases — for each element its left end (weight 0) and
//!   `N_e` Gauss points, then the final `X̄ = 1`: `n_ip = n_e (N_e + 1) + 1` points.
//!
//! Extra points (e.g. where a point load acts) are inserted with weight 0. Consecutive divisions
//! share a duplicated physical location (no Magnus step between them).
//!
//! Between consecutive points of a division the pose advances by `g_s = exp(Ω̂)`, with `Ω` from
//! 2nd-order (midpoint) or 4th-order (Zanna, two Gauss sub-points) Magnus collocation (spec §5.3).
//! The strain is therefore needed at *sites*: every computational point (sites `0..n_points`, same
//! index) and every Magnus sub-point (sites `n_points..`).
//!
//! **Snapshot layout (paper eq. 13).** A strain snapshot is the point-major vector
//! `[ξ₀ − ξ*₀; ξ₁ − ξ*₁; …; ξ_{p−1} − ξ*_{p−1}]` over the computational points in the order of
//! [`Discretization::points`] (base to tip, junction points duplicated), each block ordered
//! `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]`; a planar model may keep only its active
//! components, in the same order.

use crate::error::{fmt_rounded, ModelError};
use crate::rod::Rod;
use serde::{Deserialize, Serialize};

/// Order of the Magnus expansion used between consecutive points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MagnusOrder {
    /// Midpoint rule, `Ω = h ξ(X + h/2)`: 2nd order.
    #[serde(alias = "Z2")]
    Z2,
    /// Zanna / two-point Gauss Magnus, `Ω = h/2 (ξ₁+ξ₂) + (√3/12) h² ad_{ξ₁} ξ₂`: 4th order.
    #[default]
    #[serde(alias = "Z4")]
    Z4,
}

/// Quadrature (computational points) of one division.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Quadrature {
    /// `n` Gauss points over the whole division plus the two ends.
    Gauss { n: usize },
    /// `gauss_per_element` Gauss points in each of `elements` equal elements plus element ends.
    Elements {
        elements: usize,
        gauss_per_element: usize,
    },
}

/// One computational point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Physical abscissa X ∈ [0, L].
    pub x: f64,
    /// Normalized division coordinate X̄ ∈ [0, 1].
    pub x_bar: f64,
    /// Quadrature weight W (physical, \[m\]); 0 at boundaries and extra points.
    pub weight: f64,
    /// Division index.
    pub div: usize,
}

/// A place where the strain is evaluated: a point or a Magnus sub-point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Site {
    pub x: f64,
    pub x_bar: f64,
    pub div: usize,
}

/// The Magnus step from point `from` to `from + 1` inside a division.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    pub from: usize,
    /// Physical step length h.
    pub h: f64,
    pub div: usize,
    /// Strain sites of the step: Z4 uses both, Z2 only `sites[0]` (the midpoint).
    pub sites: [usize; 2],
}

/// Zanna sub-point positions `z₁,₂ = ½ ∓ √3/6`.
pub const ZANNA: [f64; 2] = [0.5 - 0.288_675_134_594_812_9, 0.5 + 0.288_675_134_594_812_9];

/// Points, sites and steps of a whole rod.
#[derive(Debug, Clone, PartialEq)]
pub struct Discretization {
    pub points: Vec<Point>,
    pub sites: Vec<Site>,
    /// `steps[i]` joins point i and i+1; `None` at a junction between divisions.
    pub steps: Vec<Option<Step>>,
    pub order: MagnusOrder,
    /// Start abscissa and length of each division.
    pub div_start: Vec<f64>,
    pub div_length: Vec<f64>,
}

/// Gauss–Legendre nodes and weights on [0, 1] (ascending), by Newton iteration on `P_n`.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        // initial guess (Tricomi), root i of P_n on [-1,1] in descending order
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre_and_derivative(n, z);
            dp = d;
            let dz = p / d;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre_and_derivative(n, z);
        dp = if d.is_finite() { d } else { dp };
        // map to [0,1], ascending
        x[n - 1 - i] = 0.5 * (z + 1.0);
        w[n - 1 - i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// `(P_n(z), P_n'(z))` by the three-term recurrence.
fn legendre_and_derivative(n: usize, z: f64) -> (f64, f64) {
    let mut p0 = 1.0;
    let mut p1 = z;
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 1..n {
        let p2 = ((2 * k + 1) as f64 * z * p1 - k as f64 * p0) / (k + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (z * p1 - p0) / (z * z - 1.0);
    (p1, d)
}

impl Discretization {
    /// Builds the points of `rod` with one [`Quadrature`] per division, inserting `extra_x` (physical
    /// abscissae, e.g. point-load locations) as zero-weight points where not already present.
    pub fn new(
        rod: &Rod,
        quadrature: &[Quadrature],
        order: MagnusOrder,
        extra_x: &[f64],
    ) -> Result<Self, ModelError> {
        if quadrature.len() != rod.divisions.len() {
            return Err(ModelError::invalid(
                "discretization.quadrature",
                format!(
                    "{} entries for {} divisions",
                    quadrature.len(),
                    rod.divisions.len()
                ),
            ));
        }
        let length = rod.length();
        for (k, &x) in extra_x.iter().enumerate() {
            if crate::rod::abscissa_on(length, x).is_none() {
                return Err(ModelError::value(
                    format!("discretization.extra_points[{k}]"),
                    x,
                    format!("an abscissa in [0, {}] m", fmt_rounded(length)),
                ));
            }
        }
        let div_start = rod.division_starts();
        let div_length: Vec<f64> = rod.divisions.iter().map(|d| d.length).collect();
        let mut points = Vec::new();
        for (j, q) in quadrature.iter().enumerate() {
            let (xb, wb) = match *q {
                Quadrature::Gauss { n } => {
                    if n == 0 {
                        return Err(ModelError::invalid(
                            format!("discretization.divisions[{j}].gauss_points"),
                            "at least 1 Gauss point is required",
                        ));
                    }
                    let (x, w) = gauss_legendre(n);
                    let mut xb = vec![0.0];
                    xb.extend(x);
                    xb.push(1.0);
                    let mut wb = vec![0.0];
                    wb.extend(w);
                    wb.push(0.0);
                    (xb, wb)
                }
                Quadrature::Elements {
                    elements,
                    gauss_per_element,
                } => {
                    if elements == 0 || gauss_per_element == 0 {
                        return Err(ModelError::invalid(
                            format!("discretization.divisions[{j}]"),
                            format!(
                                "elements ({elements}) and gauss_per_element ({gauss_per_element}) must be >= 1"
                            ),
                        ));
                    }
                    let (x, w) = gauss_legendre(gauss_per_element);
                    let ne = elements as f64;
                    let mut xb = Vec::new();
                    let mut wb = Vec::new();
                    for e in 0..elements {
                        xb.push(e as f64 / ne);
                        wb.push(0.0);
                        for (xi, wi) in x.iter().zip(&w) {
                            xb.push((e as f64 + xi) / ne);
                            wb.push(wi / ne);
                        }
                    }
                    xb.push(1.0);
                    wb.push(0.0);
                    (xb, wb)
                }
            };
            let l = div_length[j];
            let x0 = div_start[j];
            let mut pts: Vec<Point> = xb
                .iter()
                .zip(&wb)
                .map(|(&b, &w)| Point {
                    x: x0 + b * l,
                    x_bar: b,
                    weight: w * l,
                    div: j,
                })
                .collect();
            // extra points strictly inside this division
            for &x in extra_x {
                let b = (x - x0) / l;
                if b <= 1e-12 || b >= 1.0 - 1e-12 {
                    continue;
                }
                if pts.iter().any(|p| (p.x_bar - b).abs() < 1e-12) {
                    continue;
                }
                let pos = pts.iter().position(|p| p.x_bar > b).unwrap_or(pts.len());
                pts.insert(
                    pos,
                    Point {
                        x,
                        x_bar: b,
                        weight: 0.0,
                        div: j,
                    },
                );
            }
            points.extend(pts);
        }
        let np = points.len();
        let mut sites: Vec<Site> = points
            .iter()
            .map(|p| Site {
                x: p.x,
                x_bar: p.x_bar,
                div: p.div,
            })
            .collect();
        let mut steps = Vec::with_capacity(np - 1);
        for i in 0..np - 1 {
            let (a, b) = (points[i], points[i + 1]);
            if a.div != b.div {
                steps.push(None);
                continue;
            }
            let l = div_length[a.div];
            let h = (b.x_bar - a.x_bar) * l;
            let subs: &[f64] = match order {
                MagnusOrder::Z2 => &[0.5],
                MagnusOrder::Z4 => &ZANNA,
            };
            let mut idx = [0usize; 2];
            for (k, z) in subs.iter().enumerate() {
                let xb = a.x_bar + z * (b.x_bar - a.x_bar);
                idx[k] = sites.len();
                sites.push(Site {
                    x: div_start[a.div] + xb * l,
                    x_bar: xb,
                    div: a.div,
                });
            }
            if order == MagnusOrder::Z2 {
                idx[1] = idx[0];
            }
            steps.push(Some(Step {
                from: i,
                h,
                div: a.div,
                sites: idx,
            }));
        }
        Ok(Discretization {
            points,
            sites,
            steps,
            order,
            div_start,
            div_length,
        })
    }

    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    pub fn n_sites(&self) -> usize {
        self.sites.len()
    }

    /// Total length.
    pub fn length(&self) -> f64 {
        self.div_start.last().unwrap() + self.div_length.last().unwrap()
    }

    /// Index of the computational point at abscissa `x` (first match within 1e-9·L), if any.
    pub fn point_at(&self, x: f64) -> Option<usize> {
        let tol = 1e-9 * self.length();
        self.points.iter().position(|p| (p.x - x).abs() <= tol)
    }

    /// Index of the tip point.
    pub fn tip(&self) -> usize {
        self.points.len() - 1
    }

    /// The cell `[a_i, b_i]` of each point: the partition of each division by the cumulative
    /// quadrature weights, `b_i − a_i = W_i` (empty at the points of weight 0). The cells of an
    /// element's Gauss points tile the element, and each Gauss point lies inside its own (the
    /// Stieltjes separation of the nodes by the cumulative weights), so `Σ W_i s(X_i)` reads as each
    /// point standing for its cell: what a load with jumps inside a cell is applied over
    /// ([`crate::loads::DistributedWrench::Uniform`]).
    pub fn cells(&self) -> Vec<(f64, f64)> {
        let mut cells = Vec::with_capacity(self.points.len());
        let mut edge = self.div_start[0];
        let mut div = usize::MAX;
        for p in &self.points {
            if p.div != div {
                div = p.div;
                edge = self.div_start[div];
            }
            cells.push((edge, edge + p.weight));
            edge += p.weight;
        }
        cells
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::{DivisionGeometry, Material};

    fn rod(divs: &[f64]) -> Rod {
        Rod {
            material: Material {
                youngs_modulus: 1e6,
                poisson_ratio: 0.5,
                density: 1000.0,
                damping: 0.0,
            },
            divisions: divs
                .iter()
                .map(|&l| DivisionGeometry {
                    length: l,
                    radius_start: 0.01,
                    radius_end: 0.01,
                    material: None,
                    section: None,
                })
                .collect(),
        }
    }

    #[test]
    fn gauss_legendre_five_points_match_spec() {
        // gvs-spec §5.1
        let (x, w) = gauss_legendre(5);
        let xr = [0.0469100770, 0.2307653449, 0.5, 0.7692346551, 0.9530899230];
        let wr = [
            0.1184634425,
            0.2393143352,
            0.2844444444,
            0.2393143352,
            0.1184634425,
        ];
        for i in 0..5 {
            assert!((x[i] - xr[i]).abs() < 1e-10 && (w[i] - wr[i]).abs() < 1e-10);
        }
    }

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in [1usize, 2, 7, 50, 100] {
            let (x, w) = gauss_legendre(n);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-13, "n = {n}");
            // ∫₀¹ x^k = 1/(k+1) exact for k ≤ 2n−1
            for k in [1usize, 2 * n - 1] {
                let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!(
                    (s - 1.0 / (k as f64 + 1.0)).abs() < 1e-13,
                    "n = {n}, k = {k}: {s}"
                );
            }
            assert!(x.windows(2).all(|p| p[0] < p[1]));
        }
    }

    #[test]
    fn paper_single_tendon_has_102_points() {
        let d = Discretization::new(
            &rod(&[0.25]),
            &[Quadrature::Gauss { n: 100 }],
            MagnusOrder::Z4,
            &[],
        )
        .unwrap();
        assert_eq!(d.n_points(), 102);
        assert_eq!(d.n_sites(), 102 + 2 * 101);
        let wsum: f64 = d.points.iter().map(|p| p.weight).sum();
        assert!((wsum - 0.25).abs() < 1e-14);
    }

    #[test]
    fn fem_beam_has_148_points_and_extra_points_are_inserted() {
        let d = Discretization::new(
            &rod(&[0.8]),
            &[Quadrature::Elements {
                elements: 49,
                gauss_per_element: 2,
            }],
            MagnusOrder::Z4,
            &[0.123, 0.8],
        )
        .unwrap();
        assert_eq!(d.n_points(), 148 + 1);
        let p = d.point_at(0.123).unwrap();
        assert_eq!(d.points[p].weight, 0.0);
        assert!(d.points.windows(2).all(|w| w[0].x <= w[1].x));
    }

    #[test]
    fn the_cells_tile_each_element_and_hold_their_gauss_point() {
        let d = Discretization::new(
            &rod(&[0.5, 0.3]),
            &[
                Quadrature::Elements {
                    elements: 7,
                    gauss_per_element: 3,
                },
                Quadrature::Gauss { n: 11 },
            ],
            MagnusOrder::Z4,
            &[0.123, 0.6],
        )
        .unwrap();
        let cells = d.cells();
        let weighted: Vec<(usize, &Point)> = (d.points.iter().enumerate())
            .filter(|(_, p)| p.weight > 0.0)
            .collect();
        assert_eq!(weighted.len(), 7 * 3 + 11);
        for (i, p) in &weighted {
            let (a, b) = cells[*i];
            assert!(
                a < p.x && p.x < b,
                "point {i} at {} outside [{a}, {b}]",
                p.x
            );
        }
        // element ends, then the second division's ends, are cell edges
        let h = 0.5 / 7.0;
        for e in 0..7 {
            let (a, _) = cells[weighted[3 * e].0];
            let (_, b) = cells[weighted[3 * e + 2].0];
            assert!(
                (a - e as f64 * h).abs() < 1e-15,
                "element {e} starts at {a}"
            );
            assert!(
                (b - (e + 1) as f64 * h).abs() < 1e-15,
                "element {e} ends at {b}"
            );
        }
        assert!((cells[weighted[21].0].0 - 0.5).abs() < 1e-15);
        assert!((cells[weighted[31].0].1 - 0.8).abs() < 1e-15);
        for (i, p) in d.points.iter().enumerate().filter(|(_, p)| p.weight == 0.0) {
            assert_eq!(cells[i].0, cells[i].1, "point {i} at {} of weight 0", p.x);
        }
    }

    #[test]
    fn two_divisions_have_a_junction_without_step() {
        let d = Discretization::new(
            &rod(&[0.3, 0.3]),
            &[Quadrature::Gauss { n: 5 }, Quadrature::Gauss { n: 5 }],
            MagnusOrder::Z2,
            &[],
        )
        .unwrap();
        assert_eq!(d.n_points(), 14);
        assert!(d.steps[6].is_none());
        assert_eq!(d.points[6].x, d.points[7].x);
        assert_eq!(d.steps.iter().filter(|s| s.is_some()).count(), 12);
    }

    #[test]
    fn bad_extra_point_is_rejected_with_its_field() {
        let e = Discretization::new(
            &rod(&[0.5]),
            &[Quadrature::Gauss { n: 5 }],
            MagnusOrder::Z4,
            &[0.7],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("extra_points[0]") && e.contains("0.7"), "{e}");
    }
}
