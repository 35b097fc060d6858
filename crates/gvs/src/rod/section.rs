//! Cross-sections (gvs-spec §3.2): their shapes — the solid circle, the rectangle, the ellipse and
//! the circular tube — tapering over a division, and the diagonals of `Es`, `Ms`, `Ds` at a point.

use super::Material;
use crate::lie::V6;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The shape of a section other than the solid circle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    /// A solid `w × h` rectangle.
    Rectangle,
    /// A solid ellipse of full axes `w` and `h`.
    Ellipse,
    /// A circular tube of outer diameter `w = h` and inner radius `inner_radius` `[start, end]`
    /// \[m\], tapering linearly like the outer one.
    Tube { inner_radius: [f64; 2] },
}

/// A rectangular, elliptical or tubular section whose width `w` (along the section's `y` axis)
/// and height `h` (along `z`) taper linearly over the division, `[start, end]` \[m\] (a tube's
/// outer diameter, `w = h`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Section {
    pub shape: Shape,
    pub width: [f64; 2],
    pub height: [f64; 2],
}

impl Section {
    /// `(w, h)` at `X̄`.
    pub fn extents_at(&self, x_bar: f64) -> (f64, f64) {
        let at = |[a, b]: [f64; 2]| a + x_bar * (b - a);
        (at(self.width), at(self.height))
    }

    /// A tube's inner radius at `X̄` (0 for a solid section).
    pub fn inner_radius_at(&self, x_bar: f64) -> f64 {
        match self.shape {
            Shape::Tube {
                inner_radius: [a, b],
            } => a + x_bar * (b - a),
            _ => 0.0,
        }
    }

    /// The farthest the section at `X̄` reaches from the axis: the rectangle's half diagonal,
    /// the ellipse's larger half axis, the tube's outer radius. At `X̄ = 0` or 1 exactly; between
    /// them the linear interpolation of these bounds the section (the distance is convex in the
    /// extents).
    pub fn circumradius(&self, x_bar: f64) -> f64 {
        let (w, h) = self.extents_at(x_bar);
        match self.shape {
            Shape::Rectangle => 0.5 * w.hypot(h),
            Shape::Ellipse | Shape::Tube { .. } => 0.5 * w.max(h),
        }
    }

    /// The section's properties at `X̄` for `material`.
    pub fn props_at(&self, material: &Material, x_bar: f64) -> SectionProps {
        let (w, h) = self.extents_at(x_bar);
        match self.shape {
            Shape::Rectangle => SectionProps::rectangle(material, w, h),
            Shape::Ellipse => SectionProps::ellipse(material, w, h),
            Shape::Tube { .. } => {
                SectionProps::tube(material, 0.5 * w, self.inner_radius_at(x_bar))
            }
        }
    }
}

/// Diagonals of the cross-section matrices at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionProps {
    /// The farthest the section reaches from its axis \[m\] (a circle's radius).
    pub radius: f64,
    pub area: f64,
    /// diag of `Es` [N·m², N·m², N·m², N, N, N].
    pub es: V6,
    /// diag of `Ms` per unit length.
    pub ms: V6,
    /// diag of `Ds`.
    pub ds: V6,
}

impl SectionProps {
    /// Circular section of radius r: `A = πr²`, `I = πr⁴/4`, `J = J_t = 2I` (spec §3.1–3.2).
    pub fn circular(material: &Material, r: f64) -> Self {
        let a = PI * r * r;
        let i = PI * r.powi(4) / 4.0;
        Self::from_moments(material, r, a, i, i, 2.0 * i)
    }

    /// A solid rectangle of width `w` (along `y`) and height `h` (along `z`): `A = wh`,
    /// `I_y = ∫z² dA = wh³/12`, `I_z = hw³/12`, and the Saint-Venant torsion constant
    /// `J_t = a b³ [1/3 − (64/π⁵)(b/a) Σ_{n odd} tanh(nπa/2b)/n⁵]`, `a ≥ b` the longer and
    /// shorter side ([`rectangle_torsion_constant`]; Timoshenko & Goodier §109: 0.1406 a⁴ for a
    /// square, against the polar moment's 0.1667 a⁴; `a b³/3` for a thin strip).
    ///
    /// The rotary inertia of torsion is the polar moment `J = I_y + I_z`; its stiffness and damping
    /// take `J_t` (SoRoSim takes `J` for both, which overrates a flat section's torsional stiffness:
    /// 1.19× for a square, 3.2× for 3:1, 7.4× for a 5:1 strip).
    pub fn rectangle(material: &Material, w: f64, h: f64) -> Self {
        let (area, iy, iz) = (w * h, w * h.powi(3) / 12.0, h * w.powi(3) / 12.0);
        let jt = rectangle_torsion_constant(w, h);
        Self::from_moments(material, 0.5 * w.hypot(h), area, iy, iz, jt)
    }

    /// A solid ellipse of full axes `w` (along `y`) and `h` (along `z`), half axes `a = w/2`,
    /// `b = h/2`: `A = πab`, `I_y = πab³/4`, `I_z = πa³b/4`, `J_t = πa³b³/(a² + b²)` (exact; the
    /// circle's `πr⁴/2` for `a = b`), the polar moment in the rotary inertia as for
    /// [`SectionProps::rectangle`].
    pub fn ellipse(material: &Material, w: f64, h: f64) -> Self {
        let (a, b) = (0.5 * w, 0.5 * h);
        let area = PI * a * b;
        let (iy, iz) = (PI * a * b.powi(3) / 4.0, PI * a.powi(3) * b / 4.0);
        let jt = PI * a.powi(3) * b.powi(3) / (a * a + b * b);
        Self::from_moments(material, a.max(b), area, iy, iz, jt)
    }

    /// A circular tube of outer radius `r` and inner radius `r_i < r`: `A = π(r² − r_i²)`,
    /// `I = π(r⁴ − r_i⁴)/4`, `J = J_t = 2I` (the Saint-Venant torsion constant of a concentric
    /// tube is its polar moment, exactly: its sections stay plane). `r_i = 0` is the solid circle.
    /// (Factored as `π(r − r_i)(r + r_i)` and `π(r − r_i)(r + r_i)(r² + r_i²)/4`, which keep their
    /// precision for a thin wall, where `r² − r_i²` cancels.)
    pub fn tube(material: &Material, r: f64, r_i: f64) -> Self {
        let wall = (r - r_i) * (r + r_i);
        let a = PI * wall;
        let i = PI * wall * (r * r + r_i * r_i) / 4.0;
        Self::from_moments(material, r, a, i, i, 2.0 * i)
    }

    /// `Es`, `Ms`, `Ds` of a section of area `a`, second moments `iy = ∫z² dA`, `iz = ∫y² dA` and
    /// torsion constant `jt` (spec §3.2; the polar moment `iy + iz` in `Ms`).
    fn from_moments(material: &Material, reach: f64, a: f64, iy: f64, iz: f64, jt: f64) -> Self {
        let e = material.youngs_modulus;
        let g = material.shear_modulus();
        let rho = material.density;
        let eta = material.damping;
        SectionProps {
            radius: reach,
            area: a,
            es: V6::new(g * jt, e * iy, e * iz, e * a, g * a, g * a),
            ms: V6::new(iy + iz, iy, iz, a, a, a) * rho,
            ds: V6::new(jt, 3.0 * iy, 3.0 * iz, 3.0 * a, a, a) * eta,
        }
    }
}

/// The Saint-Venant torsion constant of a solid `w × h` rectangle: with `a ≥ b` its sides,
/// `J_t = a b³ [1/3 − (64/π⁵)(b/a) Σ_{n = 1, 3, 5, …} tanh(nπa/(2b))/n⁵]` (the series'
/// terms fall as `n⁻⁵`: 400 of them leave < 1e-13 of the sum).
pub fn rectangle_torsion_constant(w: f64, h: f64) -> f64 {
    let (a, b) = (w.max(h), w.min(h));
    let sum: f64 = (0..400)
        .map(|i| (2 * i + 1) as f64)
        .map(|n| (n * PI * a / (2.0 * b)).tanh() / n.powi(5))
        .sum();
    a * b.powi(3) * (1.0 / 3.0 - 64.0 / PI.powi(5) * (b / a) * sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    /// E = 2 MPa, ν = 0.3 (G = E/2.6), ρ = 1200 kg/m³, η = 3 kPa·s: every factor of `Es`, `Ms`
    /// and `Ds` distinct from 1 and from each other.
    fn stiff_material() -> Material {
        Material {
            youngs_modulus: 2e6,
            poisson_ratio: 0.3,
            density: 1200.0,
            damping: 3e3,
        }
    }

    #[test]
    fn section_values_match_spec_table() {
        // gvs-spec §3.4, single-actuator base and tip, six-actuator base.
        let m = Material {
            youngs_modulus: 0.617e6,
            poisson_ratio: 0.5,
            density: 1121.0,
            damping: 1e4,
        };
        let s = SectionProps::circular(&m, 0.0125);
        assert!(rel(s.area, 4.9087e-4) < 1e-4);
        assert!(rel(s.es[1], 1.1831e-2) < 1e-4);
        assert!(rel(s.es[3], 302.87) < 1e-4);
        assert!(rel(s.es[4], 100.96) < 1e-4);
        assert!(rel(s.es[0], 7.8872e-3) < 1e-4);
        let s = SectionProps::circular(&m, 0.005);
        assert!(rel(s.es[1], 3.0287e-4) < 1e-4);
        assert!(rel(s.es[5], 16.153) < 1e-4);
        let m6 = Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 1e4,
        };
        let s = SectionProps::circular(&m6, 0.02);
        assert!(rel(s.es[1], 0.12566) < 1e-4);
        assert!(rel(s.es[0], 8.3776e-2) < 1e-4);
        // damping uses the factor 3 on bending/extension regardless of ν
        assert!(rel(s.ds[1], 3.0 * 1e4 * PI * 0.02f64.powi(4) / 4.0) < 1e-12);
        assert!(rel(s.ds[4], 1e4 * s.area) < 1e-12);
    }

    #[test]
    fn every_stiffness_inertia_and_damping_entry_matches_its_closed_form() {
        // gvs-spec §3.4 for a solid circle of radius r: A = πr², I = πr⁴/4, J = 2I;
        // Ms = ρ diag(J, I, I, A, A, A), Ds = η diag(J, 3I, 3I, 3A, A, A) (§3.4), entry by entry
        let m = stiff_material();
        let r = 0.015;
        let s = SectionProps::circular(&m, r);
        let a = PI * r * r;
        let i = PI * r.powi(4) / 4.0;
        let j = 2.0 * i;
        let ms = [j, i, i, a, a, a].map(|x| 1200.0 * x);
        let ds = [j, 3.0 * i, 3.0 * i, 3.0 * a, a, a].map(|x| 3e3 * x);
        // Es = diag(GJ, EI, EI, EA, GA, GA), G = E/(2(1 + ν)) = E/2.6 here (shear factor 1)
        let g = 2e6 / 2.6;
        let es = [g * j, 2e6 * i, 2e6 * i, 2e6 * a, g * a, g * a];
        for k in 0..6 {
            assert!(
                rel(s.es[k], es[k]) < 1e-14,
                "es[{k}] = {} against {}",
                s.es[k],
                es[k]
            );
            assert!(
                rel(s.ms[k], ms[k]) < 1e-14,
                "ms[{k}] = {} against {}",
                s.ms[k],
                ms[k]
            );
            assert!(
                rel(s.ds[k], ds[k]) < 1e-14,
                "ds[{k}] = {} against {}",
                s.ds[k],
                ds[k]
            );
        }
        // for ν = 1/2 (G = E/3) the damping is the stiffness times 3η/E, entry by entry
        let half = Material {
            poisson_ratio: 0.5,
            ..m
        };
        let s = SectionProps::circular(&half, r);
        for k in 0..6 {
            assert!(rel(s.ds[k], 3.0 * 3e3 / 2e6 * s.es[k]) < 1e-14, "ds[{k}]");
        }
    }

    /// The Saint-Venant torsion constant of a `w × h` rectangle from Prandtl's stress function,
    /// independently of the series: `∇²φ = −2` inside, `φ = 0` on the boundary, `J_t = 2∫φ dA`,
    /// by second-order finite differences on `n × n` cells solved by conjugate gradients, then
    /// Richardson-extrapolated from `n` and `2n` (error `O(h⁴)`).
    fn prandtl_torsion_constant(w: f64, h: f64, n: usize) -> f64 {
        let solve = |n: usize| {
            let (hx, hy) = (w / n as f64, h / n as f64);
            let m = n - 1; // interior nodes per side
            let apply = |x: &[f64], out: &mut [f64]| {
                for i in 0..m {
                    for j in 0..m {
                        let at = |a: isize, b: isize| {
                            if a < 0 || b < 0 || a >= m as isize || b >= m as isize {
                                0.0
                            } else {
                                x[a as usize * m + b as usize]
                            }
                        };
                        let (a, b) = (i as isize, j as isize);
                        let c = x[i * m + j];
                        // −∇²: symmetric positive definite
                        out[i * m + j] = (2.0 * c - at(a - 1, b) - at(a + 1, b)) / (hx * hx)
                            + (2.0 * c - at(a, b - 1) - at(a, b + 1)) / (hy * hy);
                    }
                }
            };
            let rhs = vec![2.0; m * m];
            let mut x = vec![0.0; m * m];
            let (mut r, mut p, mut ap) = (rhs.clone(), rhs.clone(), vec![0.0; m * m]);
            let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
            let mut rr = dot(&r, &r);
            for _ in 0..10 * m * m {
                apply(&p, &mut ap);
                let alpha = rr / dot(&p, &ap);
                for k in 0..m * m {
                    x[k] += alpha * p[k];
                    r[k] -= alpha * ap[k];
                }
                let next = dot(&r, &r);
                if next < 1e-26 * dot(&rhs, &rhs) {
                    break;
                }
                for k in 0..m * m {
                    p[k] = r[k] + next / rr * p[k];
                }
                rr = next;
            }
            2.0 * x.iter().sum::<f64>() * hx * hy
        };
        let (coarse, fine) = (solve(n), solve(2 * n));
        fine + (fine - coarse) / 3.0
    }

    #[test]
    fn rectangle_torsion_constant_matches_prandtls_stress_function_and_the_tables() {
        // the series against an independent solution of the Poisson problem, square to strip
        for (w, h) in [(1.0, 1.0), (2.0, 1.0), (0.3, 1.5)] {
            let series = rectangle_torsion_constant(w, h);
            let prandtl = prandtl_torsion_constant(w, h, 40);
            assert!(
                rel(series, prandtl) < 2e-4,
                "{w} × {h}: series {series}, Prandtl {prandtl}"
            );
        }
        // Timoshenko & Goodier's table of J_t / (a b³), a/b = 1, 2, 5, 10, to its three digits
        for (ratio, k) in [(1.0, 0.141), (2.0, 0.229), (5.0, 0.291), (10.0, 0.312)] {
            let j = rectangle_torsion_constant(ratio, 1.0) / ratio;
            assert!((j - k).abs() < 6e-4, "a/b = {ratio}: {j} against {k}");
        }
        // the thin strip: a b³/3 (1 − 0.630 b/a)
        let j = rectangle_torsion_constant(100.0, 1.0) / 100.0;
        assert!(rel(j, (1.0 - 0.630 / 100.0) / 3.0) < 1e-4, "{j}");
        // symmetric in its sides
        assert_eq!(
            rectangle_torsion_constant(0.3, 0.1),
            rectangle_torsion_constant(0.1, 0.3)
        );
    }

    #[test]
    fn rectangle_and_ellipse_moments_match_quadrature_of_their_areas() {
        let m = stiff_material();
        let (e, g) = (2e6, 2e6 / 2.6);
        let (w, h) = (0.04, 0.01);
        // area, ∫z² dA, ∫y² dA by the midpoint rule on a fine grid over the bounding box
        let moments = |inside: &dyn Fn(f64, f64) -> bool| {
            let n = 2000;
            let (dy, dz) = (w / n as f64, h / n as f64);
            let mut a = [0.0; 3];
            for i in 0..n {
                for j in 0..n {
                    let (y, z) = (
                        -w / 2.0 + (i as f64 + 0.5) * dy,
                        -h / 2.0 + (j as f64 + 0.5) * dz,
                    );
                    if inside(y, z) {
                        a[0] += dy * dz;
                        a[1] += z * z * dy * dz;
                        a[2] += y * y * dy * dz;
                    }
                }
            }
            a
        };
        let rect = SectionProps::rectangle(&m, w, h);
        let [a, iy, iz] = moments(&|_, _| true);
        let got = [rect.area, rect.es[1] / e, rect.es[2] / e];
        for (k, (x, y)) in got.iter().zip([a, iy, iz]).enumerate() {
            assert!(rel(*x, y) < 1e-6, "[A, I_y, I_z][{k}] = {x} against {y}");
        }
        assert!(rect.es[1] < rect.es[2], "flat along y: stiffer about z");
        assert!(
            rel(rect.ms[0], 1200.0 * (iy + iz)) < 1e-6,
            "rotary inertia: the polar moment"
        );
        let jt = rectangle_torsion_constant(w, h);
        assert!(rel(rect.es[0], g * jt) < 1e-14 && rel(rect.ds[0], 3e3 * jt) < 1e-14);
        assert!(
            jt < 0.5 * (iy + iz),
            "a 4:1 strip twists far more easily than its polar moment says"
        );
        assert!(rel(rect.radius, 0.5 * w.hypot(h)) < 1e-14);
        let ell = SectionProps::ellipse(&m, w, h);
        let [a, iy, iz] = moments(&|y, z| (2.0 * y / w).powi(2) + (2.0 * z / h).powi(2) <= 1.0);
        assert!(
            rel(ell.area, a) < 1e-3
                && rel(ell.es[1], e * iy) < 1e-3
                && rel(ell.es[2], e * iz) < 1e-3
        );
        assert!(rel(ell.ms[1], 1200.0 * iy) < 1e-3 && rel(ell.ds[2], 3.0 * 3e3 * iz) < 1e-3);
        // an ellipse of equal axes is the circle, torsion included
        let r = 0.013;
        let (circle, round) = (
            SectionProps::circular(&m, r),
            SectionProps::ellipse(&m, 2.0 * r, 2.0 * r),
        );
        for k in 0..6 {
            assert!(rel(round.es[k], circle.es[k]) < 1e-14, "es[{k}]");
            assert!(rel(round.ms[k], circle.ms[k]) < 1e-14, "ms[{k}]");
            assert!(rel(round.ds[k], circle.ds[k]) < 1e-14, "ds[{k}]");
        }
    }

    #[test]
    fn tube_moments_match_quadrature_of_the_annulus_and_the_thin_wall_limit() {
        let m = stiff_material();
        let (e, g) = (2e6, 2e6 / 2.6);
        let (r, r_i) = (0.01, 0.006);
        // area and ∫z² dA over the annulus by the midpoint rule in polar coordinates
        // (∫∫ ρ³ sin²θ dρ dθ), independent of the closed form's π(r⁴ − r_i⁴)/4
        let (n_r, n_t) = (400, 400);
        let (dr, dt) = ((r - r_i) / n_r as f64, 2.0 * PI / n_t as f64);
        let (mut a, mut iy) = (0.0, 0.0);
        for i in 0..n_r {
            let rho = r_i + (i as f64 + 0.5) * dr;
            for k in 0..n_t {
                let th = (k as f64 + 0.5) * dt;
                a += rho * dr * dt;
                iy += (rho * th.sin()).powi(2) * rho * dr * dt;
            }
        }
        let t = SectionProps::tube(&m, r, r_i);
        assert!(rel(t.area, a) < 1e-5, "A = {} against {a}", t.area);
        assert!(rel(t.es[1], e * iy) < 1e-5 && rel(t.es[2], e * iy) < 1e-5);
        // torsion: the polar moment, in stiffness, inertia and damping
        assert!(rel(t.es[0], g * 2.0 * iy) < 1e-5 && rel(t.ms[0], 1200.0 * 2.0 * iy) < 1e-5);
        assert!(rel(t.ds[0], 3e3 * 2.0 * iy) < 1e-5 && rel(t.ds[1], 3.0 * 3e3 * iy) < 1e-5);
        assert!(rel(t.es[3], e * a) < 1e-5 && rel(t.ms[4], 1200.0 * a) < 1e-5);
        assert_eq!(t.radius, r);
        // the bore removes the stiffness of the core: (r⁴ − r_i⁴)/r⁴ of the solid circle's
        let solid = SectionProps::circular(&m, r);
        assert!(rel(t.es[1] / solid.es[1], 1.0 - (r_i / r).powi(4)) < 1e-14);
        // r_i = 0 is the solid circle, entry by entry
        let zero = SectionProps::tube(&m, r, 0.0);
        for k in 0..6 {
            assert!(rel(zero.es[k], solid.es[k]) < 1e-14, "es[{k}]");
            assert!(rel(zero.ms[k], solid.ms[k]) < 1e-14, "ms[{k}]");
            assert!(rel(zero.ds[k], solid.ds[k]) < 1e-14, "ds[{k}]");
        }
        // a thin wall of thickness w around the mean radius R: A → 2πRw, I → πR³w, J → 2πR³w
        let (big_r, w) = (0.01, 1e-5);
        let thin = SectionProps::tube(&m, big_r + w / 2.0, big_r - w / 2.0);
        assert!(rel(thin.area, 2.0 * PI * big_r * w) < 1e-9);
        assert!(rel(thin.es[1], e * PI * big_r.powi(3) * w) < 1e-6);
        assert!(rel(thin.es[0], g * 2.0 * PI * big_r.powi(3) * w) < 1e-6);
    }

    #[test]
    fn a_tube_tapers_its_bore_and_reaches_its_outer_radius() {
        let m = Material {
            youngs_modulus: 1e6,
            poisson_ratio: 0.5,
            density: 1000.0,
            damping: 0.0,
        };
        let s = Section {
            shape: Shape::Tube {
                inner_radius: [0.008, 0.002],
            },
            width: [0.02, 0.01],
            height: [0.02, 0.01],
        };
        assert_eq!(s.circumradius(0.0), 0.01);
        assert_eq!(s.circumradius(1.0), 0.005);
        assert!(rel(s.inner_radius_at(0.5), 0.005) < 1e-14);
        let mid = s.props_at(&m, 0.5);
        let expected = SectionProps::tube(&m, 0.0075, 0.005);
        assert!(rel(mid.es[1], expected.es[1]) < 1e-14 && rel(mid.area, expected.area) < 1e-14);
        // a solid section has no bore
        let solid = Section {
            shape: Shape::Ellipse,
            ..s
        };
        assert_eq!(solid.inner_radius_at(0.5), 0.0);
    }
}
