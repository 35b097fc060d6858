//! Large deflections of a uniform rod (L = 0.5 m, r = 5 mm, ν = ½, ρ = 1000 kg/m³) against closed
//! forms and against shooting solutions of the planar extensible, shearable elastica written here
//! (Reissner's equations, RK4): Euler's column under a dead tip load, before and after it buckles;
//! a 3-D end moment that twists and bends the rod onto a helix; a heavy horizontal cantilever.
//! Each test is named after the case it checks; no expected value comes from the code under test.

mod common;

use gvs::lie::V3;
use gvs::loads::{Frame, Loads, PointWrench};
use gvs::model::Model;
use gvs::rod::{Material, Rod, SectionProps};
use gvs::solve::statics::{solve_statics, StaticsOptions, StaticsSolution};
use gvs::strain::LinearBasis;
use nalgebra::{DVector, Matrix3, Rotation3};
use std::f64::consts::PI;

const L: f64 = 0.5;
const R: f64 = 0.005;
/// Bending, elongation and shear in the x–z plane.
const PLANAR: [bool; 6] = [false, true, false, true, false, true];

fn material(e: f64) -> Material {
    Material {
        youngs_modulus: e,
        poisson_ratio: 0.5,
        density: 1000.0,
        damping: 0.0,
    }
}

/// The uniform rod of Young's modulus `e`, Legendre order `order` on the active `modes`, `gauss`
/// Gauss points, Magnus Z4.
fn rod_model(e: f64, modes: [bool; 6], order: usize, gauss: usize) -> Model<LinearBasis> {
    common::legendre_model(Rod::tapered(material(e), L, R, R), gauss, modes, order)
}

/// A dead (global-frame) wrench `[m; f]` at the tip.
fn tip_wrench(wrench: [f64; 6]) -> Loads {
    Loads {
        point: vec![PointWrench {
            x: L,
            wrench,
            frame: Frame::Global,
        }],
        ..Loads::default()
    }
}

/// Statics with the residual tolerance `ftol` (the default 1e-10 relative stops the solve a few
/// 1e-9 L from the equilibrium when the forces are small).
fn solve(m: &Model<LinearBasis>, loads: &Loads, ftol: f64) -> StaticsSolution {
    let options = StaticsOptions {
        ftol,
        ..StaticsOptions::default()
    };
    solve_statics(m, &[], loads, None, &options).unwrap()
}

fn tip_pose(m: &Model<LinearBasis>, q: &DVector<f64>) -> (V3, Matrix3<f64>) {
    let mut ws = m.workspace();
    m.forward(q, &mut ws, false);
    let tip = ws.g.last().unwrap();
    (tip.pos, tip.rot)
}

/// The section stiffnesses `(EI, EA, GA)` of the rod of Young's modulus `e`.
fn stiffnesses(e: f64) -> (f64, f64, f64) {
    let es = SectionProps::circular(&material(e), R).es;
    (es[1], es[3], es[4])
}

/// The planar extensible, shearable elastica (Reissner 1972) of a cantilever clamped at the origin
/// along x, under a dead tip force `f_tip = (F_x, F_z)` and a dead distributed force `(0, −w)` per
/// unit reference length. The cut force at `s` is `n(s) = f_tip + (0, −w (L − s))`; with the
/// section angle θ (from x towards z):
///
/// `n₁ = n_x cos θ + n_z sin θ`, `n₂ = −n_x sin θ + n_z cos θ`, `ν₁ = 1 + n₁/EA`, `ν₂ = n₂/GA`,
/// `x' = ν₁ cos θ − ν₂ sin θ`, `z' = ν₁ sin θ + ν₂ cos θ`, `M' = −(x' n_z − z' n_x)`, `θ' = M/EI`.
///
/// Shooting from the free tip (`M(L) = 0`, θ(L) = θ_L) to the clamp with classical RK4, θ_L chosen
/// by bisection so that θ(0) = 0.
struct Elastica {
    ei: f64,
    ea: f64,
    ga: f64,
    f_tip: [f64; 2],
    w: f64,
}

impl Elastica {
    /// `[θ, M, a_x, a_z]` at the clamp, integrated from the tip with `steps` RK4 steps, where
    /// `a = p(s) − p(L)`.
    fn clamp_state(&self, theta_l: f64, steps: usize) -> [f64; 4] {
        let rhs = |s: f64, y: [f64; 4]| {
            let (c, sn) = (y[0].cos(), y[0].sin());
            let (nx, nz) = (self.f_tip[0], self.f_tip[1] - self.w * (L - s));
            let nu1 = 1.0 + (nx * c + nz * sn) / self.ea;
            let nu2 = (-nx * sn + nz * c) / self.ga;
            let (px, pz) = (nu1 * c - nu2 * sn, nu1 * sn + nu2 * c);
            [y[1] / self.ei, -(px * nz - pz * nx), px, pz]
        };
        let axpy = |y: [f64; 4], h: f64, k: [f64; 4]| std::array::from_fn(|i| y[i] + h * k[i]);
        let h = -L / steps as f64;
        let mut y = [theta_l, 0.0, 0.0, 0.0];
        for k in 0..steps {
            let s = L + k as f64 * h;
            let k1 = rhs(s, y);
            let k2 = rhs(s + h / 2.0, axpy(y, h / 2.0, k1));
            let k3 = rhs(s + h / 2.0, axpy(y, h / 2.0, k2));
            let k4 = rhs(s + h, axpy(y, h, k3));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        y
    }

    /// The tip angle θ_L in `bracket` (θ(0) changes sign across it) and the tip position `(x, z)`.
    fn solve(&self, bracket: (f64, f64), steps: usize) -> (f64, [f64; 2]) {
        let f = |t: f64| self.clamp_state(t, steps)[0];
        let (mut a, mut b) = bracket;
        let fa = f(a);
        assert!(fa * f(b) < 0.0, "no sign change of θ(0) over {bracket:?}");
        while (b - a).abs() > 1e-14 {
            let c = 0.5 * (a + b);
            if f(c) * fa > 0.0 {
                a = c;
            } else {
                b = c;
            }
        }
        let theta_l = 0.5 * (a + b);
        let y = self.clamp_state(theta_l, steps);
        (theta_l, [-y[2], -y[3]])
    }
}

/// Lowest ω² (= `m.linearized_modes(...)[0]`) at the equilibrium `q` under `loads`.
fn lowest_omega_squared(m: &Model<LinearBasis>, q: &DVector<f64>, loads: &Loads) -> f64 {
    let prepared = m.prepare_loads(loads).unwrap();
    let modes = m
        .linearized_modes(q, &[], &prepared, &mut m.workspace())
        .unwrap();
    modes[0].omega_squared
}

/// Lowest root `Ω = ρA ω² L⁴/EI` of the Euler–Bernoulli cantilever (clamped at 0, free at L)
/// compressed by a dead axial tip load `p = P L²/EI`: `EI w'''' + P w'' − ρA ω² w = 0`,
/// `w = C₁ cosh as + C₂ sinh as + C₃ cos bs + C₄ sin bs` with `a² = (−p + D)/2`, `b² = (p + D)/2`,
/// `D = √(p² + 4Ω)` (L = 1); `w(0) = w'(0) = 0`, `w''(1) = 0`, `w'''(1) + p w'(1) = 0` leave
/// `(a² ch + b² c)(a b² ch + a³ c) − (a² sh + a b s)(a b² sh − a² b s) = 0`
/// (`ch = cosh a`, `sh = sinh a`, `c = cos b`, `s = sin b`); at p = 0 it is `1 + cosh β cos β = 0`.
fn euler_bernoulli_lowest_omega(p: f64) -> f64 {
    let det = |om: f64| {
        let d = (p * p + 4.0 * om).sqrt();
        let (a, b) = (((d - p) / 2.0).sqrt(), ((d + p) / 2.0).sqrt());
        let (ch, sh, c, s) = (a.cosh(), a.sinh(), b.cos(), b.sin());
        (a * a * ch + b * b * c) * (a * b * b * ch + a.powi(3) * c)
            - (a * a * sh + a * b * s) * (a * b * b * sh - a * a * b * s)
    };
    // the first sign change on a grid, then bisection
    let (mut lo, mut hi) = (1e-9, 1e-9);
    for k in 1..=400 {
        hi = 13.0 * k as f64 / 400.0;
        if det(lo) * det(hi) <= 0.0 {
            break;
        }
        lo = hi;
    }
    assert!(det(lo) * det(hi) <= 0.0);
    while hi - lo > 1e-14 * hi {
        let mid = 0.5 * (lo + hi);
        if det(lo) * det(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Euler's column: a cantilever (clamped at X = 0 along x) under the dead compressive tip force
/// `[−P, 0, 0]`. Linearized about the straight, compressed rod, Reissner's equations (`Elastica`)
/// give `EI θ'' = −P (ν₁ + P/GA) θ`, `ν₁ = 1 − P/EA`, with θ(0) = 0 and θ'(L) = 0: the column
/// buckles at `P_cr (1 + P_cr/GA − P_cr/EA) = P_E = π² EI/4L²`, 1.23e-4 below Euler's load for this
/// rod (Engesser's shear softening, 1.85e-4, less the axial shortening, 0.62e-4). The lowest ω² of
/// the linearized modes at the straight equilibrium crosses zero there: found by secant iteration
/// at P_cr within 2.2e-7 relative (bound 2e-6; Euler's load itself is 1.2e-4 off). Below it,
/// ω²(P)/ω²(0) against the Euler–Bernoulli beam-column's closed form
/// (`euler_bernoulli_lowest_omega`): 0.519630 against 0.519641 at 0.5 P_E, 0.107490 against
/// 0.107588 at 0.9 P_E; bound 3e-4, the scale of the shear and shortening terms the
/// Euler–Bernoulli column leaves out (ω² falls by about ω₀² per P_E: they move its zero by
/// 1.2e-4 P_E). Planar modes (bending, elongation, shear), Legendre order 8, 30 Gauss points.
#[test]
fn euler_column_under_dead_tip_load_buckles_at_the_shear_corrected_euler_load() {
    let e = 1e6;
    let (ei, ea, ga) = stiffnesses(e);
    let p_e = PI * PI * ei / (4.0 * L * L);
    let c = 1.0 / ga - 1.0 / ea;
    let p_cr = (-1.0 + (1.0 + 4.0 * c * p_e).sqrt()) / (2.0 * c);
    assert!((p_cr / p_e - 0.999_877).abs() < 1e-6, "{}", p_cr / p_e);
    let m = rod_model(e, PLANAR, 8, 30);
    // the straight compressed rod, unjudged (past P_cr it diverges: the point of the test)
    let straight = StaticsOptions {
        ftol: 1e-14,
        check_stability: false,
        min_increment: 1.0,
        ..StaticsOptions::default()
    };
    let omega2 = |p: f64| {
        let loads = tip_wrench([0.0, 0.0, 0.0, -p, 0.0, 0.0]);
        let sol = solve_statics(&m, &[], &loads, None, &straight).unwrap();
        let (tip, _) = tip_pose(&m, &sol.q);
        assert!(tip[2].abs() < 1e-14, "P = {p}: the column bent, tip {tip}");
        lowest_omega_squared(&m, &sol.q, &loads)
    };
    // secant on ω²(P) from 0.99 and 1.01 P_E
    let (mut p0, mut p1) = (0.99 * p_e, 1.01 * p_e);
    let (mut w0, mut w1) = (omega2(p0), omega2(p1));
    assert!(
        w0 > 0.0 && w1 < 0.0,
        "ω² {w0} at 0.99 P_E, {w1} at 1.01 P_E"
    );
    for _ in 0..20 {
        let p2 = p1 - w1 * (p1 - p0) / (w1 - w0);
        (p0, w0) = (p1, w1);
        p1 = p2;
        w1 = omega2(p1);
        if (p1 - p0).abs() < 1e-12 * p_e {
            break;
        }
    }
    let crossing = (p1 - p_cr) / p_cr;
    eprintln!(
        "ω² = 0 at P/P_E = {:.8} against {:.8}: {crossing:+.2e}",
        p1 / p_e,
        p_cr / p_e
    );
    assert!(crossing.abs() < 2e-6, "crossing off by {crossing:e}");
    let w_free = omega2(0.0);
    for f in [0.5, 0.9] {
        let ratio = omega2(f * p_e) / w_free;
        let exact =
            euler_bernoulli_lowest_omega(f * p_e * L * L / ei) / euler_bernoulli_lowest_omega(0.0);
        eprintln!("ω²/ω₀² at {f} P_E: {ratio:.6} against {exact:.6}");
        assert!(
            (ratio - exact).abs() < 3e-4,
            "{f} P_E: {ratio} against {exact}"
        );
    }
    // the closed form's unloaded root: β⁴, 1 + cosh β cos β = 0
    let beta4 = 1.875_104_068_711_961f64.powi(4);
    assert!((euler_bernoulli_lowest_omega(0.0) / beta4 - 1.0).abs() < 1e-12);
}

/// Past P_cr the straight column diverges and the solver, displaced along its divergent mode,
/// settles on the buckled equilibrium ([`StaticsSolution::buckled`]). Its tip against the shooting
/// solution of Reissner's planar elastica (`Elastica`, 4000 RK4 steps, within 1e-14 L of 8000,
/// required within 1e-12 L)
/// under `f_tip = (−P, 0)`, at P/P_E = 1.152 (tip angle 60°), 1.5 (99°), 2.541 (140°) and 4
/// (160°); the side it buckles to is the solver's choice, so |z| is compared. Tip errors /L:
/// Legendre order 4 with 20 Gauss points 2.0e-6, 2.3e-6, 1.4e-5, 1.6e-4; order 8 with 30 points
/// 2.9e-7, 1.9e-7, 3.6e-7, 4.8e-7 (bound 2e-6, and at least 3× below order 4's); order 8 with 60
/// points 1.9e-8, 1.2e-8, 2.4e-8, 1.5e-8 (bound 1e-7, and at least 8× below 30 points': the Z4
/// Magnus error, N⁻⁴, dominates at order 8; order 12 leaves it unchanged).
#[test]
fn buckled_euler_column_matches_the_extensible_shearable_elastica() {
    let e = 1e6;
    let (ei, ea, ga) = stiffnesses(e);
    let p_e = PI * PI * ei / (4.0 * L * L);
    let models = [
        rod_model(e, PLANAR, 4, 20),
        rod_model(e, PLANAR, 8, 30),
        rod_model(e, PLANAR, 8, 60),
    ];
    for f in [1.152, 1.5, 2.541, 4.0] {
        let p = f * p_e;
        let elastica = Elastica {
            ei,
            ea,
            ga,
            f_tip: [-p, 0.0],
            w: 0.0,
        };
        let (theta_l, reference) = elastica.solve((1e-3, PI - 1e-3), 4000);
        let (_, check) = elastica.solve((1e-3, PI - 1e-3), 8000);
        assert!((reference[0] - check[0]).hypot(reference[1] - check[1]) < 1e-12 * L);
        let loads = tip_wrench([0.0, 0.0, 0.0, -p, 0.0, 0.0]);
        let errs: Vec<f64> = models
            .iter()
            .map(|m| {
                let sol = solve(m, &loads, 1e-13);
                assert!(
                    sol.buckled.is_some() && sol.divergence.is_none(),
                    "P = {f} P_E"
                );
                let (tip, _) = tip_pose(m, &sol.q);
                (tip[0] - reference[0]).hypot(tip[2].abs() - reference[1].abs()) / L
            })
            .collect();
        eprintln!(
            "P = {f} P_E: tip angle {:.1}°, tip errors {:.1e} {:.1e} {:.1e} L",
            theta_l.to_degrees(),
            errs[0],
            errs[1],
            errs[2]
        );
        assert!(
            errs[1] < 2e-6 && errs[1] < errs[0] / 3.0,
            "P = {f} P_E: {errs:?}"
        );
        assert!(
            errs[2] < 1e-7 && errs[2] < errs[1] / 8.0,
            "P = {f} P_E: {errs:?}"
        );
    }
}

/// A dead end moment `M` (global frame) on a rod of circular section: the cut moment is `M`
/// everywhere and no force acts, so ν = e₁ and the body curvature is `κ = C⁻¹ Rᵀ M`,
/// `C = diag(GJ, EI, EI)`. The twist `m₁ = M · t` is constant (`= M₁`, R(0) = I), and
/// `R(s) = exp(s M̂/EI) exp(s m₁ (1/GJ − 1/EI) ê₁)` solves `R' = R κ̂`: the tangent
/// `t = R e₁ = exp(s M̂/EI) e₁` precesses about M at the rate ω = |M|/EI, and the centreline is the
/// helix `p(s) = c u s + sin(ωs)/ω (e₁ − c u) + (1 − cos ωs)/ω u × e₁`, `u = M/|M|`, `c = e₁ · u`.
/// M = [3, −2, 1] mN·m, |M| L/EI = 3.81 rad, twist m₁ L (1/GJ − 1/EI) = 1.53 rad; all six strains
/// at Legendre order 8, Z4 Magnus, ftol 1e-14. Tip position error /L with 30, 60, 120, 240 Gauss
/// points: 9.3e-7, 6.0e-8, 3.8e-9, 2.4e-10 (rotation 2.5e-6 … 6.5e-10): Z4's N⁻⁴, each doubling
/// required to divide it by 12 to 20 (measured 15.4, 15.7, 15.9); bounds at 240 points 1e-9 L and
/// 3e-9.
#[test]
fn dead_end_moment_twists_and_bends_the_rod_onto_the_exact_helix() {
    let e = 1e6;
    let es = SectionProps::circular(&material(e), R).es;
    let (gj, ei) = (es[0], es[1]);
    let mom = V3::new(3e-3, -2e-3, 1e-3);
    let omega = mom.norm() / ei;
    assert!((omega * L - 3.8112).abs() < 1e-4, "{}", omega * L);
    let (u, e1) = (mom / mom.norm(), V3::x());
    let c = e1.dot(&u);
    let exact_pos = c * u * L
        + (omega * L).sin() / omega * (e1 - c * u)
        + (1.0 - (omega * L).cos()) / omega * u.cross(&e1);
    let twist = L * mom[0] * (1.0 / gj - 1.0 / ei);
    assert!((twist - 1.5279).abs() < 1e-4, "{twist}");
    let exact_rot = Rotation3::from_scaled_axis(mom * (L / ei)).into_inner()
        * Rotation3::from_scaled_axis(e1 * twist).into_inner();
    let loads = tip_wrench([mom[0], mom[1], mom[2], 0.0, 0.0, 0.0]);
    let errs: Vec<(f64, f64)> = [30, 60, 120, 240]
        .into_iter()
        .map(|gauss| {
            let m = rod_model(e, [true; 6], 8, gauss);
            let sol = solve(&m, &loads, 1e-14);
            let (pos, rot) = tip_pose(&m, &sol.q);
            ((pos - exact_pos).norm() / L, (rot - exact_rot).amax())
        })
        .collect();
    for (gauss, (dp, dr)) in [30, 60, 120, 240].iter().zip(&errs) {
        eprintln!("{gauss} Gauss points: tip position {dp:.2e} L, rotation {dr:.2e}");
    }
    for pair in errs.windows(2) {
        let ratio = pair[0].0 / pair[1].0;
        assert!((12.0..20.0).contains(&ratio), "{errs:?}");
    }
    let (dp, dr) = errs[3];
    assert!(dp < 1e-9 && dr < 3e-9, "{errs:?}");
}

/// A horizontal cantilever sagging under its own weight `w = ρ A g` (gravity −z), against the
/// shooting solution of Reissner's planar elastica (`Elastica`, distributed `(0, −w)`, 4000 RK4
/// steps, within 1e-13 L of 8000, required within 1e-12 L), at `w L³/EI` = 9.81 (E = 20 MPa, tip
/// angle −60°) and 98.1 (E = 2 MPa, −89.6°). Tip errors /L at Legendre order 6 (24 Gauss points): 2.6e-7 and 1.5e-5
/// (bounds 1e-6 and 6e-5); at order 10 (40 points): 4.2e-8 and 3.9e-7 (bounds 2e-7 and 2e-6, and
/// at least 3× below order 6's).
#[test]
fn heavy_cantilever_sags_as_the_extensible_shearable_elastica() {
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    for (e, bounds) in [(2e7, [1e-6, 2e-7]), (2e6, [6e-5, 2e-6])] {
        let (ei, ea, ga) = stiffnesses(e);
        let w = 1000.0 * PI * R * R * 9.81;
        let elastica = Elastica {
            ei,
            ea,
            ga,
            f_tip: [0.0, 0.0],
            w,
        };
        let (theta_l, reference) = elastica.solve((-PI / 2.0, -1e-6), 4000);
        let (_, check) = elastica.solve((-PI / 2.0, -1e-6), 8000);
        assert!((reference[0] - check[0]).hypot(reference[1] - check[1]) < 1e-12 * L);
        let errs: Vec<f64> = [6, 10]
            .into_iter()
            .map(|order| {
                let m = rod_model(e, PLANAR, order, 4 * order);
                let sol = solve(&m, &loads, 1e-13);
                let (tip, _) = tip_pose(&m, &sol.q);
                assert!(tip[1].abs() < 1e-14, "out of plane: {tip}");
                (tip[0] - reference[0]).hypot(tip[2] - reference[1]) / L
            })
            .collect();
        eprintln!(
            "w L³/EI = {:.2}: tip angle {:.1}°, tip errors {:.1e} (order 6), {:.1e} (order 10) L",
            w * L.powi(3) / ei,
            theta_l.to_degrees(),
            errs[0],
            errs[1]
        );
        assert!(errs[0] < bounds[0], "{errs:?}");
        assert!(errs[1] < bounds[1] && errs[1] < errs[0] / 3.0, "{errs:?}");
    }
}
