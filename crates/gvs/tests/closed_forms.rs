//! Statics against closed forms and independent solutions (gvs-spec §10.2–10.3), each test named
//! after the case it checks. Expected values come from formulas or from independent integrations
//! written here, never from the code under test.

use gvs::actuation::{Tendon, DEFAULT_FRICTION_SMOOTHING};
use gvs::discretize::{Discretization, MagnusOrder, Quadrature};
use gvs::lie::{exp_se3, hat, Pose, V3, V6};
use gvs::loads::{DistributedWrench, Frame, Loads, PointWrench, PulseMagnitude};
use gvs::model::Model;
use gvs::rod::{Material, Rod, SectionProps};
use gvs::solve::statics::{solve_statics, StaticsOptions, StaticsSolution};
use gvs::strain::{DivisionBasis, FemDegree, LinearBasis};
use nalgebra::{DVector, Matrix3, Matrix4};
use std::f64::consts::PI;

fn mat(e: f64, rho: f64) -> Material {
    Material {
        youngs_modulus: e,
        poisson_ratio: 0.5,
        density: rho,
        damping: 0.0,
    }
}

/// Legendre modes: `orders[i] = None` for inactive modes.
fn legendre(orders: [Option<usize>; 6]) -> DivisionBasis {
    DivisionBasis::Legendre {
        modes: orders.map(|o| o.is_some()),
        orders: orders.map(|o| o.unwrap_or(0)),
    }
}

fn model(
    rod: Rod,
    n_gauss: usize,
    basis: DivisionBasis,
    tendons: Vec<Tendon>,
    extra: &[f64],
) -> Model<LinearBasis> {
    let disc = Discretization::new(
        &rod,
        &[Quadrature::Gauss { n: n_gauss }],
        MagnusOrder::Z4,
        extra,
    )
    .unwrap();
    let b = LinearBasis::per_division(&disc, &[basis]).unwrap();
    Model::new(rod, disc, b, tendons).unwrap()
}

fn solve(
    m: &Model<LinearBasis>,
    u: &[f64],
    loads: &Loads,
) -> (StaticsSolution, gvs::model::Workspace) {
    let sol = solve_statics(m, u, loads, None, &StaticsOptions::default()).unwrap();
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    (sol, ws)
}

fn no_loads() -> Loads {
    Loads::default()
}

fn tip_load(w: [f64; 6], frame: Frame, x: f64) -> Loads {
    Loads {
        gravity: [0.0; 3],
        point: vec![PointWrench {
            x,
            wrench: w,
            frame,
        }],
        distributed: vec![],
    }
}

/// A tendon at the constant offset `d` (`[d_y, d_z]`) over the whole rod `[0, l]`, friction `mu`.
fn straight_tendon(d: [f64; 2], l: f64, mu: f64) -> Tendon {
    Tendon {
        offset_start: d,
        offset_end: d,
        x_start: 0.0,
        x_end: l,
        friction: mu,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    }
}

const PLANAR: [Option<usize>; 6] = [None, Some(4), None, Some(2), None, Some(2)];

#[test]
fn pure_end_moment_bends_rod_into_exact_circle() {
    // κ = M/EI; tip = (sin κL/κ, 0, −(1 − cos κL)/κ)   (gvs-spec §10.3.1)
    let (r, l, e, mom) = (0.01, 0.5, 1e6, 0.01);
    for frame in [Frame::Local, Frame::Global] {
        let m = model(
            Rod::tapered(mat(e, 0.0), l, r, r),
            8,
            legendre([Some(1), Some(2), Some(2), Some(1), Some(1), Some(1)]),
            vec![],
            &[],
        );
        let (sol, ws) = solve(&m, &[], &tip_load([0.0, mom, 0.0, 0.0, 0.0, 0.0], frame, l));
        let kappa = mom / (e * PI * r.powi(4) / 4.0);
        assert!((kappa - 1.2732395447).abs() < 1e-9);
        let tip = ws.g.last().unwrap().pos;
        let exact = V3::new(
            (kappa * l).sin() / kappa,
            0.0,
            -(1.0 - (kappa * l).cos()) / kappa,
        );
        assert!(
            (tip - exact).norm() < 1e-10,
            "{frame:?}: tip {tip} vs {exact}"
        );
        // the bending coordinate of P0 equals κℓ (angular rows scaled by 1/ℓ)
        assert!((sol.q[2] - kappa * l).abs() < 1e-10, "q = {}", sol.q);
    }
}

#[test]
fn a_tendon_on_the_exact_circle_lies_at_its_offset_from_the_arc() {
    // the end-moment circle above with a slack tendon at the constant offset d = (0, d_y, d_z):
    // the section at X is turned by θ = κX about y, so the thread is at
    // p(X) = (sin θ/κ + d_z sin θ, d_y, −(1 − cos θ)/κ + d_z cos θ); interpolated between the
    // points (cubic Hermite with the tangent R t_u) it is exact at them and O(h⁴) between
    let (r, l, e, mom, dy, dz) = (0.01, 0.5, 1e6, 0.01, 0.006, 0.004);
    let tendon = straight_tendon([dy, dz], l, 0.0);
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        8,
        legendre([Some(1), Some(2), Some(2), Some(1), Some(1), Some(1)]),
        vec![tendon],
        &[],
    );
    let loads = tip_load([0.0, mom, 0.0, 0.0, 0.0, 0.0], Frame::Local, l);
    let (_, ws) = solve(&m, &[0.0], &loads);
    let kappa = mom / (e * PI * r.powi(4) / 4.0);
    let exact = |x: f64| {
        let th = kappa * x;
        V3::new(
            th.sin() / kappa + dz * th.sin(),
            dy,
            -(1.0 - th.cos()) / kappa + dz * th.cos(),
        )
    };
    for &i in m.tendon_points(0) {
        let x = m.disc.points[i].x;
        let p = m.tendon_position_at(&ws, 0, x);
        assert!(
            (p - exact(x)).norm() < 1e-10,
            "X = {x}: {p} vs {}",
            exact(x)
        );
    }
    let worst = (0..=500)
        .map(|k| {
            let x = l * k as f64 / 500.0;
            (m.tendon_position_at(&ws, 0, x) - exact(x)).norm()
        })
        .fold(0.0, f64::max);
    // 10 points, gaps up to h ≈ 0.08 m on a circle of radius 0.79 m: h⁴κ³/384 ≈ 2e-7 m
    assert!(worst < 1e-6, "worst {worst:e} m");
}

#[test]
fn small_tip_force_deflection_matches_bending_plus_shear_formula() {
    // δ = PL³/3EI + PL/GA (shear factor 1), gvs-spec §10.3.2
    let (r, l, e, p) = (0.01, 0.5, 1e6, 1e-4);
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        10,
        legendre(PLANAR),
        vec![],
        &[],
    );
    let (_, ws) = solve(
        &m,
        &[],
        &tip_load([0.0, 0.0, 0.0, 0.0, 0.0, -p], Frame::Global, l),
    );
    let s = SectionProps::circular(&mat(e, 0.0), r);
    let exact = -(p * l.powi(3) / (3.0 * s.es[1]) + p * l / s.es[4]);
    let tip = ws.g.last().unwrap().pos[2];
    // geometric nonlinearity at δ/L ≈ 1e-3 changes δ by O((δ/L)²) ≈ 1e-6 relative
    assert!(
        ((tip - exact) / exact).abs() < 5e-6,
        "tip {tip:e} vs {exact:e}"
    );
    assert!((exact + 5.309939e-4).abs() < 1e-9);
}

#[test]
fn tapered_cantilever_compliance_matches_integral() {
    // δ/P = ∫(L−X)²/EI(X) dX + ∫ dX/GA(X) (gvs-spec §10.3.3), single-tendon geometry, 33 DOF
    let (l, r0, r1, e) = (0.25, 0.0125, 0.005, 0.617e6);
    let m = model(
        Rod::tapered(mat(e, 1121.0), l, r0, r1),
        100,
        legendre([None, Some(10), None, Some(10), None, Some(10)]),
        vec![],
        &[],
    );
    assert_eq!(m.n_dof(), 33);
    let p = 1e-6;
    let (_, ws) = solve(
        &m,
        &[],
        &tip_load([0.0, 0.0, 0.0, 0.0, 0.0, -p], Frame::Global, l),
    );
    // independent quadrature of the compliance integral (composite Simpson, 20000 intervals)
    let mt = mat(e, 0.0);
    let nq = 20000;
    let mut c = 0.0;
    for k in 0..=nq {
        let x = l * k as f64 / nq as f64;
        let s = SectionProps::circular(&mt, r0 + (r1 - r0) * x / l);
        let wgt = if k == 0 || k == nq {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        c += wgt * ((l - x).powi(2) / s.es[1] + 1.0 / s.es[4]);
    }
    c *= l / nq as f64 / 3.0;
    assert!((c - 1.106776).abs() < 1e-6, "compliance integral {c}");
    let compliance = -ws.g.last().unwrap().pos[2] / p;
    assert!(
        ((compliance - c) / c).abs() < 1e-5,
        "GVS {compliance} vs {c}"
    );
}

#[test]
fn gravity_sag_of_stiff_cantilever_matches_formula() {
    // δ = wL⁴/8EI + wL²/2GA, w = ρAg (gvs-spec §10.3.4)
    let (r, l, e, rho) = (0.005, 0.5, 1e10, 1000.0);
    let m = model(
        Rod::tapered(mat(e, rho), l, r, r),
        10,
        legendre(PLANAR),
        vec![],
        &[],
    );
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    let (_, ws) = solve(&m, &[], &loads);
    let s = SectionProps::circular(&mat(e, rho), r);
    let w = rho * s.area * 9.81;
    let exact = -(w * l.powi(4) / (8.0 * s.es[1]) + w * l * l / (2.0 * s.es[4]));
    assert!((exact + 1.2266179e-3).abs() < 1e-9);
    let tip = ws.g.last().unwrap().pos[2];
    assert!(
        ((tip - exact) / exact).abs() < 1e-5,
        "tip {tip:e} vs {exact:e}"
    );
}

#[test]
fn hanging_rod_stretches_by_rho_g_l2_over_2e() {
    // gravity along +x: ν₁(X) = 1 + ρg(L−X)/E, tip extension ρgL²/(2E)  (gvs-spec §10.3.5)
    let (r, l, e, rho) = (0.01, 0.5, 1e5, 1000.0);
    let m = model(
        Rod::tapered(mat(e, rho), l, r, r),
        6,
        legendre([None, None, None, Some(1), None, None]),
        vec![],
        &[],
    );
    let loads = Loads {
        gravity: [9.81, 0.0, 0.0],
        ..Loads::default()
    };
    let (_, ws) = solve(&m, &[], &loads);
    let ext = ws.g.last().unwrap().pos[0] - l;
    assert!((ext - 0.0122625).abs() < 1e-12, "extension {ext}");
    for (i, p) in m.disc.points.iter().enumerate() {
        let xi = m.point_strains(&ws)[i];
        assert!((xi[3] - (1.0 + rho * 9.81 * (l - p.x) / e)).abs() < 1e-12);
    }
}

#[test]
fn constant_offset_tendon_gives_uniform_curvature_and_contraction() {
    // k₂ = u d/EI, ν₁ = 1 + u/EA, all else 0 (gvs-spec §10.3.6)
    let (r, l, e, d, t) = (0.01, 0.5, 1e6, 0.008, 0.5);
    let tendon = straight_tendon([0.0, d], l, 0.0);
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        8,
        legendre([Some(1), Some(2), Some(2), Some(1), Some(1), Some(1)]),
        vec![tendon],
        &[],
    );
    let (_, ws) = solve(&m, &[-t], &no_loads());
    let s = SectionProps::circular(&mat(e, 0.0), r);
    let (k2, nu1) = (-t * d / s.es[1], 1.0 - t / s.es[3]);
    assert!((k2 + 0.5092958179).abs() < 1e-9 && (nu1 - 0.9984084506).abs() < 1e-10);
    for xi in m.point_strains(&ws) {
        let expected = V6::new(0.0, k2, 0.0, nu1, 0.0, 0.0);
        assert!((xi - expected).amax() < 1e-10, "ξ = {xi}");
    }
}

#[test]
fn constant_offset_tendon_with_friction_follows_capstan_curvature() {
    // k₂(X) = (u d/EI)/(1 + μ|u| d X/EI): Θ' = |k₂|, α = e^{−μΘ} (gvs-spec §10.3.7)
    let (r, l, e, d, t, mu) = (0.01, 0.5, 1e6, 0.008, 0.5, 0.5);
    let tendon = straight_tendon([0.0, d], l, mu);
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        60,
        legendre([None, Some(8), None, Some(8), None, Some(2)]),
        vec![tendon],
        &[],
    );
    let (_, ws) = solve(&m, &[-t], &no_loads());
    let ei = SectionProps::circular(&mat(e, 0.0), r).es[1];
    let mut worst: f64 = 0.0;
    for (xi, p) in m.point_strains(&ws).iter().zip(&m.disc.points) {
        let exact = (-t * d / ei) / (1.0 + mu * t * d * p.x / ei);
        worst = worst.max(((xi[1] - exact) / exact).abs());
    }
    // discrete tangent rule and order-8 basis: the prototype reaches ~2e-6 relative
    assert!(worst < 2e-5, "worst relative curvature error {worst:e}");
}

#[test]
fn capstan_curvature_holds_across_a_division_junction() {
    // the capstan case above on the same rod cut into two divisions at X = 0.2 m, the tendon over
    // both: the friction angle Θ runs on through the junction's coincident pair of points (their
    // ε = 0 angle is the tangent's kink, here none), so k₂(X) keeps the one closed form
    let (r, l, e, d, t, mu, cut) = (0.01, 0.5, 1e6, 0.008, 0.5, 0.5, 0.2);
    let part = |length: f64| gvs::rod::DivisionGeometry {
        length,
        radius_start: r,
        radius_end: r,
        material: None,
        section: None,
    };
    let rod = Rod {
        material: mat(e, 0.0),
        divisions: vec![part(cut), part(l - cut)],
    };
    let tendon = straight_tendon([0.0, d], l, mu);
    let (g1, g2) = (Quadrature::Gauss { n: 30 }, Quadrature::Gauss { n: 40 });
    let disc = Discretization::new(&rod, &[g1, g2], MagnusOrder::Z4, &[]).unwrap();
    let b = legendre([None, Some(8), None, Some(8), None, Some(2)]);
    let basis = LinearBasis::per_division(&disc, &[b.clone(), b]).unwrap();
    let m = Model::new(rod, disc, basis, vec![tendon]).unwrap();
    let (_, ws) = solve(&m, &[-t], &no_loads());
    let ei = SectionProps::circular(&mat(e, 0.0), r).es[1];
    let (mut worst, mut beyond): (f64, usize) = (0.0, 0);
    for (xi, p) in m.point_strains(&ws).iter().zip(&m.disc.points) {
        let exact = (-t * d / ei) / (1.0 + mu * t * d * p.x / ei);
        worst = worst.max(((xi[1] - exact) / exact).abs());
        beyond += usize::from(p.x > cut);
    }
    assert!(beyond > 30, "points past the junction: {beyond}");
    // a friction angle restarted at the junction would put the second division's curvature
    // (1 + cX)/(1 + c(X − 0.2)) − 1 off, c = μ|u|d/EI = 0.25 1/m: 5 % just past it
    assert!(worst < 2e-5, "worst relative curvature error {worst:e}");
}

#[test]
fn triangular_pulse_moment_matches_continuum_sigmoid_and_converges() {
    // k₂(X) = (1/EI) ∫_X^L m(s) ds (gvs-spec §10.3.8): the sigmoid of the IV-B beam
    let (l, r, e, me, x0) = (0.8, 0.015, 1e6, 4.0, 0.2);
    let w = 0.1 * l;
    let ei = SectionProps::circular(&mat(e, 0.0), r).es[1];
    let cont = |x: f64| {
        let (a, b) = (x0 - w / 2.0, x0 + w / 2.0);
        let int = if x <= a {
            w / 2.0
        } else if x <= x0 {
            w / 2.0 - (x - a).powi(2) / w
        } else if x <= b {
            (b - x).powi(2) / w
        } else {
            0.0
        };
        me * int / ei
    };
    let mut errs = vec![];
    for elements in [49usize, 196] {
        let rod = Rod::tapered(mat(e, 1000.0), l, r, r);
        let disc = Discretization::new(
            &rod,
            &[Quadrature::Elements {
                elements,
                gauss_per_element: 2,
            }],
            MagnusOrder::Z4,
            &[],
        )
        .unwrap();
        let b = LinearBasis::per_division(
            &disc,
            &[DivisionBasis::Fem {
                modes: [false, true, false, false, false, false],
                elements,
                degree: FemDegree::Linear,
            }],
        )
        .unwrap();
        let m = Model::new(rod, disc, b, vec![]).unwrap();
        let loads = Loads {
            gravity: [0.0; 3],
            point: vec![],
            distributed: vec![DistributedWrench::TriangularPulse {
                center: x0,
                width: w,
                magnitude: me,
                axis: [0.0, 1.0, 0.0],
                convention: PulseMagnitude::Peak,
            }],
        };
        let (_, ws) = solve(&m, &[], &loads);
        let err = m
            .point_strains(&ws)
            .iter()
            .zip(&m.disc.points)
            .map(|(xi, p)| (xi[1] - cont(p.x)).abs())
            .fold(0.0, f64::max);
        errs.push(err);
    }
    // 49 elements put ~5 elements in the pulse: the prototype's max error is 0.093 rad/m (peak 4.02)
    assert!(
        errs[0] < 0.1,
        "max |k₂ − continuum| with 49 elements: {}",
        errs[0]
    );
    // linear elements converge at least linearly in the element size at the kinks
    assert!(errs[1] < errs[0] / 3.0, "errors {errs:?}");
}

/// Independent planar Cosserat (extensible, shearable elastica) solution for a uniform cantilever with
/// a world-fixed tip force `F = (0, 0, fz)`: integrate from the tip (θ = θ_L, M = 0) to the base and
/// shoot on θ_L so that θ(0) = 0. Returns the tip position relative to the base.
fn elastica_tip(l: f64, ei: f64, ea: f64, ga: f64, fz: f64) -> V3 {
    // state: [θ, x, z] with r measured from the tip; M_y(X) = −(x_L − x) f_z = x f_z (x relative to tip)
    let rhs = |s: &[f64; 3]| -> [f64; 3] {
        let (th, x) = (s[0], s[1]);
        let my = x * fz; // (r_L − r) × F, y-component, with r_L = 0
        let (c, sn) = (th.cos(), th.sin());
        let (nx, nz) = (-sn * fz, c * fz); // Rᵀ F
        let (nu1, nu3) = (1.0 + nx / ea, nz / ga);
        [my / ei, c * nu1 + sn * nu3, -sn * nu1 + c * nu3]
    };
    let integrate = |th_l: f64| -> [f64; 3] {
        let n = 20000;
        let h = -l / n as f64;
        let mut s = [th_l, 0.0, 0.0];
        for _ in 0..n {
            let k1 = rhs(&s);
            let a = |k: &[f64; 3], f: f64| [s[0] + f * k[0], s[1] + f * k[1], s[2] + f * k[2]];
            let k2 = rhs(&a(&k1, h / 2.0));
            let k3 = rhs(&a(&k2, h / 2.0));
            let k4 = rhs(&a(&k3, h));
            for i in 0..3 {
                s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        s
    };
    // secant iteration on θ_L
    let (mut a, mut b) = (0.0, 1.0);
    let (mut fa, mut fb) = (integrate(a)[0], integrate(b)[0]);
    for _ in 0..60 {
        let c = b - fb * (b - a) / (fb - fa);
        a = b;
        fa = fb;
        b = c;
        fb = integrate(b)[0];
        if fb.abs() < 1e-14 {
            break;
        }
    }
    let s = integrate(b);
    V3::new(-s[1], 0.0, -s[2])
}

#[test]
fn large_deflection_elastica_with_tip_force_matches_shooting_solution() {
    let (r, l, e) = (0.01, 0.5, 1e6);
    let fz = -0.1; // PL²/EI ≈ 3.2: the tip turns by ~70°
    let s = SectionProps::circular(&mat(e, 0.0), r);
    let reference = elastica_tip(l, s.es[1], s.es[3], s.es[4], fz);
    assert!(
        reference[2] < -0.2,
        "reference is a large deflection: {reference}"
    );
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        40,
        legendre([None, Some(10), None, Some(6), None, Some(6)]),
        vec![],
        &[],
    );
    let sol = solve_statics(
        &m,
        &[],
        &tip_load([0.0, 0.0, 0.0, 0.0, 0.0, fz], Frame::Global, l),
        None,
        &StaticsOptions {
            ramp_steps: 2,
            ..Default::default()
        },
    )
    .unwrap();
    let mut ws = m.workspace();
    m.forward(&sol.q, &mut ws, false);
    let tip = ws.g.last().unwrap().pos;
    let err = (tip - reference).norm() / l;
    // issue target ≤ 0.1 % L; an order-10 basis is much closer
    assert!(
        err < 1e-5,
        "GVS tip {tip} vs shooting {reference}: {:.2e} L",
        err
    );
}

/// RK4 integration of g' = g ξ̂(X) on [0, 1] (test oracle for the Magnus orders).
fn reference_pose(xi: impl Fn(f64) -> V6, steps: usize) -> Matrix4<f64> {
    let mut g = Matrix4::identity();
    let h = 1.0 / steps as f64;
    for k in 0..steps {
        let x = k as f64 * h;
        let f = |g: &Matrix4<f64>, x: f64| g * hat(&xi(x));
        let k1 = f(&g, x);
        let k2 = f(&(g + k1 * (h / 2.0)), x + h / 2.0);
        let k3 = f(&(g + k2 * (h / 2.0)), x + h / 2.0);
        let k4 = f(&(g + k3 * h), x + h);
        g += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
    }
    g
}

#[test]
fn magnus_z2_and_z4_converge_with_orders_two_and_four() {
    // ξ(X) = [2, 3+4X, −1+2X², 1.1, 0.1, 0] on L = 1 (gvs-spec §10.2)
    let field = |x: f64| V6::new(2.0, 3.0 + 4.0 * x, -1.0 + 2.0 * x * x, 1.1, 0.1, 0.0);
    let reference = reference_pose(field, 20000)
        .fixed_view::<3, 1>(0, 3)
        .into_owned();
    assert!((reference - V3::new(0.2749517, 0.4698774, -0.2090092)).amax() < 1e-7);
    // Legendre coefficients of the field in x = 2X − 1: bend-y 5 + 2x, bend-z −1/3 + P₁ + P₂/3
    let q = DVector::from_vec(vec![
        2.0,
        5.0,
        2.0,
        -1.0 / 3.0,
        1.0,
        1.0 / 3.0,
        0.1,
        0.1,
        0.0,
    ]);
    let basis = legendre([Some(0), Some(1), Some(2), Some(0), Some(0), Some(0)]);
    for (order, expected) in [
        (MagnusOrder::Z2, [1.04e-3, 2.60e-4, 6.51e-5]),
        (MagnusOrder::Z4, [6.23e-6, 3.88e-7, 2.42e-8]),
    ] {
        let mut errs = vec![];
        for steps in [10usize, 20, 40] {
            let rod = Rod::tapered(mat(1e6, 0.0), 1.0, 0.01, 0.01);
            // one Gauss point (at X = 1/2) plus a uniform grid: uniform steps of 1/steps
            let extra: Vec<f64> = (1..steps).map(|k| k as f64 / steps as f64).collect();
            let disc =
                Discretization::new(&rod, &[Quadrature::Gauss { n: 1 }], order, &extra).unwrap();
            assert_eq!(disc.n_points(), steps + 1);
            let b = LinearBasis::per_division(&disc, std::slice::from_ref(&basis)).unwrap();
            let m = Model::new(rod, disc, b, vec![]).unwrap();
            let mut ws = m.workspace();
            m.forward(&q, &mut ws, false);
            errs.push((ws.g.last().unwrap().pos - reference).norm());
        }
        for k in 0..3 {
            assert!(
                (errs[k] - expected[k]).abs() < 0.02 * expected[k],
                "{order:?}: errors {errs:?} vs {expected:?}"
            );
        }
    }
}

#[test]
fn constant_strain_is_integrated_exactly() {
    let xi = V6::new(0.4, -1.3, 0.8, 1.05, 0.1, -0.05);
    for order in [MagnusOrder::Z2, MagnusOrder::Z4] {
        let rod = Rod::tapered(mat(1e6, 0.0), 0.7, 0.01, 0.01);
        let disc = Discretization::new(&rod, &[Quadrature::Gauss { n: 7 }], order, &[]).unwrap();
        let b = LinearBasis::per_division(&disc, &[legendre([Some(0); 6])]).unwrap();
        let m = Model::new(rod, disc, b, vec![]).unwrap();
        let l = 0.7;
        let q = DVector::from_vec(vec![
            xi[0] * l,
            xi[1] * l,
            xi[2] * l,
            xi[3] - 1.0,
            xi[4],
            xi[5],
        ]);
        let mut ws = m.workspace();
        m.forward(&q, &mut ws, false);
        let exact = exp_se3(&(xi * l));
        let tip = ws.g.last().unwrap();
        assert!((tip.pos - exact.pos).amax() < 1e-14 && (tip.rot - exact.rot).amax() < 1e-14);
    }
}

#[test]
fn rotating_base_and_gravity_together_leaves_equilibrium_unchanged() {
    // frame invariance (gvs-spec §10.2)
    let rod = Rod::tapered(mat(0.617e6, 1121.0), 0.25, 0.0125, 0.005);
    let tendon = Tendon {
        offset_start: [0.004, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.88,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    let m = model(
        rod.clone(),
        20,
        legendre([Some(2), Some(4), Some(4), Some(2), Some(2), Some(2)]),
        vec![tendon.clone()],
        &[0.25],
    );
    let rot = nalgebra::Rotation3::from_euler_angles(0.4, -0.9, 1.3);
    let g = V3::new(0.0, 0.0, -9.81);
    let loads = |g: V3, f: V3| Loads {
        gravity: [g[0], g[1], g[2]],
        point: vec![PointWrench {
            x: 0.25,
            wrench: [0.0, 0.0, 0.0, f[0], f[1], f[2]],
            frame: Frame::Global,
        }],
        distributed: vec![],
    };
    let f = V3::new(0.05, -0.1, 0.02);
    let a = solve_statics(&m, &[-2.0], &loads(g, f), None, &StaticsOptions::default()).unwrap();
    let m2 = model(
        rod,
        20,
        legendre([Some(2), Some(4), Some(4), Some(2), Some(2), Some(2)]),
        vec![tendon],
        &[0.25],
    )
    .with_base(Pose::new(rot.into_inner(), V3::new(1.0, -2.0, 0.5)));
    let b = solve_statics(
        &m2,
        &[-2.0],
        &loads(rot * g, rot * f),
        None,
        &StaticsOptions::default(),
    )
    .unwrap();
    assert!(
        (&a.q - &b.q).amax() < 1e-9 * (1.0 + a.q.amax()),
        "q differs by {:e}",
        (&a.q - &b.q).amax()
    );
    // and the geometric Jacobians are identical (body-frame quantities)
    let (mut wa, mut wb) = (m.workspace(), m2.workspace());
    m.forward(&a.q, &mut wa, true);
    m2.forward(&a.q, &mut wb, true);
    assert!((&wa.jac - &wb.jac).amax() < 1e-12);
    let _ = Matrix3::<f64>::identity();
}

#[test]
fn planar_loading_keeps_out_of_plane_coordinates_exactly_zero() {
    // IV-A symmetry: tendon in the x–z plane and gravity −z excite no torsion, bend-z or shear-y
    let rod = Rod::tapered(mat(0.617e6, 1121.0), 0.25, 0.0125, 0.005);
    let tendon = Tendon {
        offset_start: [0.0, 0.01],
        offset_end: [0.0, 0.003],
        x_start: 0.0,
        x_end: 0.25,
        friction: 0.88,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: 0.0,
        path: Vec::new(),
        axial_stiffness: None,
    };
    let m = model(rod, 30, legendre([Some(3); 6]), vec![tendon], &[]);
    let loads = Loads {
        gravity: [0.0, 0.0, -9.81],
        ..Loads::default()
    };
    let sol = solve_statics(&m, &[-3.0], &loads, None, &StaticsOptions::default()).unwrap();
    // modes: torsion 0..4, bend-y 4..8, bend-z 8..12, elongation 12..16, shear-y 16..20, shear-z 20..24
    for j in (0..4).chain(8..12).chain(16..20) {
        assert!(sol.q[j].abs() < 1e-12, "q[{j}] = {:e}", sol.q[j]);
    }
    assert!(sol.q.rows(4, 4).amax() > 0.1);
}

#[test]
fn strains_at_equals_the_forward_pass_strains_and_leaves_the_poses() {
    // `Model::strains_at` evaluates Ψ(q) + ξ* alone; the forward pass computes the same strains on
    // its way to the poses
    let m = model(
        Rod::tapered(mat(1e6, 1000.0), 0.5, 0.01, 0.008),
        6,
        legendre([Some(1), Some(2), Some(2), Some(1), Some(1), Some(1)]),
        vec![],
        &[],
    );
    let q = DVector::from_fn(m.n_dof(), |i, _| 0.3 * (i as f64 + 1.0).sin());
    let mut ws = m.workspace();
    m.forward_pose(&q, &mut ws);
    let expected = m.point_strains(&ws);
    let tip = ws.g.last().unwrap().pos;
    let mut other = m.workspace();
    m.forward_pose(&DVector::zeros(m.n_dof()), &mut other);
    let got = m.strains_at(&q, &mut other).to_vec();
    assert_eq!(got.len(), m.disc.n_points());
    for (g, e) in got.iter().zip(&expected) {
        assert!(
            (g - e).amax() <= 1e-14 * (1.0 + e.amax()),
            "{g} against {e}"
        );
    }
    // non-trivial: the strains differ from the rest strain
    assert!((got[1] - m.xi_star(1)).amax() > 0.1);
    // the poses stay those of the last forward pass (the straight rod), not q's
    assert!((other.g.last().unwrap().pos - V3::new(0.5, 0.0, 0.0)).norm() < 1e-12);
    assert!((tip - V3::new(0.5, 0.0, 0.0)).norm() > 1e-3);
}

#[test]
fn stiffness_is_singular_with_fewer_gauss_points_than_legendre_functions() {
    // K = Σ W Φᵀ Es Φ has rank at most the number of points: a Legendre basis of order p (p + 1
    // functions per strain) needs p + 1 Gauss points (the rule gvsrom's scenario check applies)
    let p = 6;
    let smallest = |n: usize| {
        let m = model(
            Rod::tapered(mat(1e6, 0.0), 0.5, 0.01, 0.01),
            n,
            legendre([None, Some(p), None, None, None, None]),
            vec![],
            &[],
        );
        let k = m
            .stiffness()
            .expect("a linear basis has a constant stiffness")
            .clone();
        let eig = k.symmetric_eigenvalues();
        eig.min() / eig.max()
    };
    assert!(smallest(p).abs() < 1e-12, "{}", smallest(p));
    assert!(smallest(p + 1) > 1e-6, "{}", smallest(p + 1));
}

#[test]
fn follower_axial_load_stretches_a_rotated_rod_by_f_l2_over_2ea() {
    // A uniform follower (local) density f along the section's own x axis on a rod whose base is
    // rotated: it stays straight along its base axis and stretches with ν(X) = 1 + f (L − X)/EA, so
    // the tip moves by f L²/(2EA) along that axis. Read in the world frame the same density would
    // bend it; with the sign flipped it would shorten it.
    let (l, r, e) = (0.4, 0.01, 1e6);
    let rot = nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 0.7);
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        8,
        legendre([Some(1), Some(2), Some(2), Some(2), Some(1), Some(1)]),
        vec![],
        &[],
    )
    .with_base(Pose::new(rot.into_inner(), V3::zeros()));
    let f = 20.0;
    let loads = |frame: Frame| Loads {
        gravity: [0.0; 3],
        point: vec![],
        distributed: vec![DistributedWrench::Uniform {
            x_start: 0.0,
            x_end: l,
            density: [0.0, 0.0, 0.0, f, 0.0, 0.0],
            frame,
        }],
    };
    let (_, ws) = solve(&m, &[], &loads(Frame::Local));
    let ea = e * PI * r * r;
    for (xi, p) in m.point_strains(&ws).iter().zip(&m.disc.points) {
        let nu = 1.0 + f * (l - p.x) / ea;
        assert!(
            (xi[3] - nu).abs() < 1e-10,
            "ν({}) = {} against {nu}",
            p.x,
            xi[3]
        );
        assert!(
            xi[1].abs() + xi[2].abs() + xi[4].abs() + xi[5].abs() < 1e-10,
            "{xi}"
        );
    }
    let axis = rot * V3::x();
    let tip = ws.g.last().unwrap().pos;
    let expected = axis * (l + f * l * l / (2.0 * ea));
    assert!((tip - expected).norm() < 1e-10, "{tip} against {expected}");
    // the same numbers in the world frame are another load: they bend the rotated rod
    let (_, ws) = solve(&m, &[], &loads(Frame::Global));
    assert!((ws.g.last().unwrap().pos - expected).norm() > 1e-3);
}

/// The strain at `x` of a straight rod (section stiffness `es`) whose cut there balances a
/// helical tendon (radius `rho`, turning at `phi_rate` rad/m) pulling with `u`, to first order in
/// `u` (see the test below): `t = (e_x + φ' e_x × d)/n_t`, `n_t = √(1 + (φ'ρ)²)`.
fn helix_cut_strain(u: f64, x: f64, phi_rate: f64, rho: f64, es: &V6) -> V6 {
    let nt = (1.0 + (phi_rate * rho).powi(2)).sqrt();
    let (s, c) = (phi_rate * x).sin_cos();
    V6::new(
        u * phi_rate * rho * rho / (nt * es[0]),
        u * rho * s / (nt * es[1]),
        -u * rho * c / (nt * es[2]),
        1.0 + u / (nt * es[3]),
        -u * phi_rate * rho * s / (nt * es[4]),
        u * phi_rate * rho * c / (nt * es[5]),
    )
}

#[test]
fn helical_tendon_twists_and_bends_a_straight_rod_as_its_cut_wrench_says() {
    // A frictionless tendon on a helix of radius ρ and n turns over a uniform rod,
    // d(X) = ρ[0, cos φ, sin φ], φ = 2π n X/L, pulls with u. Cutting the rod and tendon at X, the
    // rod's stress resultant balances the tendon's force u t at d (gvs-spec §7.6): to first order
    // in u, about the straight rod, t = (e_x + φ' e_x × d)/n_t with n_t = √(1 + (φ'ρ)²), so
    //   κ_x = u φ' ρ²/(n_t GJ),  (κ_y, κ_z) = u ρ (sin φ, −cos φ)/(n_t EI),
    //   ν_x − 1 = u/(n_t EA),    (ν_y, ν_z) = u φ' ρ (−sin φ, cos φ)/(n_t GA):
    // a uniform twist, a bending moment that turns with the tendon, and shears.
    let (r, l, e, rho, n) = (0.01, 0.5, 1e6, 0.006, 1.0);
    let u = -1e-4;
    let tendon = Tendon {
        offset_start: [rho, 0.0],
        offset_end: [rho, 0.0],
        x_start: 0.0,
        x_end: l,
        friction: 0.0,
        friction_smoothing: DEFAULT_FRICTION_SMOOTHING,
        turns: n,
        path: Vec::new(),
        axial_stiffness: None,
    };
    let m = model(
        Rod::tapered(mat(e, 0.0), l, r, r),
        24,
        legendre([Some(2), Some(12), Some(12), Some(2), Some(12), Some(12)]),
        vec![tendon],
        &[],
    );
    let (_, ws) = solve(&m, &[u], &no_loads());
    let es = SectionProps::circular(&mat(e, 0.0), r).es;
    let phi_rate = 2.0 * PI * n / l;
    let nt = (1.0 + (phi_rate * rho).powi(2)).sqrt();
    let strains = m.point_strains(&ws);
    let peak = u.abs() * rho / (nt * es[1]);
    for (p, xi) in m.disc.points.iter().zip(&strains) {
        let expected = helix_cut_strain(u, p.x, phi_rate, rho, &es);
        // second-order terms are O(u²): relative 1e-6 of the peak curvature
        assert!(
            (xi - expected).amax() < 1e-6 * peak,
            "X = {}: ξ = {xi}, expected {expected}",
            p.x
        );
    }
    // the twist is a real share of the response, not round-off
    assert!(strains[strains.len() / 2][0].abs() > 0.1 * peak);
}

#[test]
fn helical_tendon_with_friction_loses_tension_by_the_capstan_law_of_its_helix() {
    // The helical tendon above with Coulomb friction μ (the exact tangent rule, no smoothing) on a
    // rod of ν = 0.3. Friction acts between tendon and rod, inside any cut: the cut at X balances
    // the tension there, u α(X), so every strain is the frictionless one times
    //   α(X) = exp(−μ Θ(X)),  Θ(X) = φ'² ρ X / n_t,
    // the turning angle of the tendon's tangent τ = (e_x + φ' e_x × d)/n_t, which on the straight
    // rod sweeps a cone at |τ'| = φ'² ρ / n_t (gvs-spec §7.7), to first order in u. The section's
    // stiffness is written out here (G = E/(2(1 + ν)), shear factor 1), not taken from the code.
    // A friction angle taken from the curvature of one bending plane, or one that misses the
    // helix's own turning, would leave α = 1 here.
    let (r, l, e, nu, rho, n, mu) = (0.01, 0.5, 1e6, 0.3, 0.006, 1.0, 0.5);
    let u = -1e-4;
    let tendon = Tendon {
        offset_start: [rho, 0.0],
        offset_end: [rho, 0.0],
        x_start: 0.0,
        x_end: l,
        friction: mu,
        friction_smoothing: 0.0,
        turns: n,
        path: Vec::new(),
        axial_stiffness: None,
    };
    let material = Material {
        youngs_modulus: e,
        poisson_ratio: nu,
        density: 0.0,
        damping: 0.0,
    };
    let m = model(
        Rod::tapered(material, l, r, r),
        96,
        legendre([Some(2), Some(12), Some(12), Some(2), Some(12), Some(12)]),
        vec![tendon],
        &[],
    );
    let (_, ws) = solve(&m, &[u], &no_loads());
    let g = e / (2.0 * (1.0 + nu));
    let (area, inertia) = (PI * r * r, PI * r.powi(4) / 4.0);
    let es = [
        g * 2.0 * inertia,
        e * inertia,
        e * inertia,
        e * area,
        g * area,
        g * area,
    ];
    let phi_rate = 2.0 * PI * n / l;
    let nt = (1.0 + (phi_rate * rho).powi(2)).sqrt();
    let strains = m.point_strains(&ws);
    let peak = u.abs() * rho / (nt * es[1]);
    let mut worst = 0.0f64;
    for (p, xi) in m.disc.points.iter().zip(&strains) {
        let ua = u * (-mu * phi_rate * phi_rate * rho * p.x / nt).exp();
        let expected = helix_cut_strain(ua, p.x, phi_rate, rho, &V6::from(es));
        worst = worst.max((xi - expected).amax() / peak);
    }
    // the tangent rule sums the angles between the tangents at consecutive points, chords of the
    // cone's arc: measured 2.3e-4 of the peak with 48 Gauss points, 6.7e-5 with 96 (converging);
    // second-order terms in u are 1e-6
    assert!(
        worst < 2e-4,
        "largest strain error {worst:e} of the peak curvature"
    );
    // the friction is a real share of the response: the tip holds e^(−μΘ(L)) ≈ 0.79 of it
    let tip = strains.last().unwrap();
    let frictionless = -u * rho / (nt * es[2]);
    assert!(
        tip[2].abs() < 0.85 * frictionless.abs(),
        "{tip} vs {frictionless}"
    );
}

#[test]
fn a_rod_precurved_as_a_clothoid_rests_on_its_fresnel_integrals_at_fourth_order() {
    // ξ*(X) = [0, a X, 0, 1, 0, 0]: unloaded, the rod rests at q = 0 on the clothoid whose tangent
    // turns about y by θ(X) = a X²/2, p(L) = ∫₀ᴸ (cos θ, 0, −sin θ) dX (Fresnel integrals, by
    // Simpson's rule here). The reference strain varies along the rod, so the Z4 integrator must
    // take it at its two Magnus sub-points of each step: the tip error falls as N⁻⁴ (a midpoint
    // or point-wise evaluation would leave second order).
    let (r, l, e, a) = (0.01, 0.5, 1e6, 12.0);
    let theta = |x: f64| a * x * x / 2.0;
    let n = 20_000;
    let h = l / n as f64;
    let mut exact = V3::zeros();
    for k in 0..=n {
        let w = match k {
            0 => 1.0,
            k if k == n => 1.0,
            k if k % 2 == 1 => 4.0,
            _ => 2.0,
        };
        let t = theta(k as f64 * h);
        exact += V3::new(t.cos(), 0.0, -t.sin()) * (w * h / 3.0);
    }
    let tip_error = |points: usize| {
        let m = model(
            Rod::tapered(mat(e, 0.0), l, r, r),
            points,
            legendre([Some(1), Some(2), Some(2), Some(1), Some(1), Some(1)]),
            vec![],
            &[],
        )
        .with_reference_strain(move |x, _| V6::new(0.0, a * x, 0.0, 1.0, 0.0, 0.0));
        let (sol, ws) = solve(&m, &[], &no_loads());
        assert!(sol.q.amax() < 1e-12, "q = {}", sol.q);
        let tip = ws.g.last().unwrap();
        let rot = Matrix3::new(
            theta(l).cos(),
            0.0,
            theta(l).sin(),
            0.0,
            1.0,
            0.0,
            -theta(l).sin(),
            0.0,
            theta(l).cos(),
        );
        (tip.pos - exact).norm().max((tip.rot - rot).amax() * l)
    };
    let (coarse, fine, finer) = (tip_error(8), tip_error(16), tip_error(32));
    // measured 1.1e-5, 7.7e-7 and 5.1e-8 m: ratios 13.8 and 15.0 (N⁻⁴ gives 16)
    assert!(finer < 1e-7, "tip error {finer:e} m with 32 points");
    assert!(
        coarse / fine > 10.0 && fine / finer > 10.0,
        "order: {coarse:e} → {fine:e} → {finer:e}"
    );
}

#[test]
fn precurved_rod_is_stress_free_on_its_helix_and_an_end_moment_adds_m_over_ei() {
    // reference strain ξ* = [τ*, κ*, 0, 1, 0, 0] (gvs-spec §3.3): unloaded, the rod rests on the
    // helix exp(L ξ*̂) at q = 0 with no elastic force (constant strain, integrated exactly)
    let (r, l, e, mom) = (0.01, 0.5, 1e6, 0.004);
    let rod_with = |xi_star: V6| {
        model(
            Rod::tapered(mat(e, 0.0), l, r, r),
            8,
            legendre([Some(1), Some(2), Some(2), Some(1), Some(1), Some(1)]),
            vec![],
            &[],
        )
        .with_reference_strain(move |_, _| xi_star)
    };
    let helix = V6::new(0.8, 3.0, 0.0, 1.0, 0.0, 0.0);
    let m = rod_with(helix);
    let mut ws = m.workspace();
    let q0 = DVector::zeros(m.n_dof());
    assert_eq!(m.elastic_force(&q0, &mut ws).amax(), 0.0);
    let (sol, ws) = solve(&m, &[], &no_loads());
    assert!(sol.q.amax() < 1e-14, "q = {}", sol.q);
    let (tip, exact) = (ws.g.last().unwrap(), exp_se3(&(helix * l)));
    assert!((tip.pos - exact.pos).amax() < 1e-13 && (tip.rot - exact.rot).amax() < 1e-13);

    // without twist the arc stays planar and a follower end moment M about y adds M/EI to its
    // curvature everywhere: the tip is exp(L [0, κ* + M/EI, 0, 1, 0, 0]̂)
    let m = rod_with(V6::new(0.0, 3.0, 0.0, 1.0, 0.0, 0.0));
    let (_, ws) = solve(
        &m,
        &[],
        &tip_load([0.0, mom, 0.0, 0.0, 0.0, 0.0], Frame::Local, l),
    );
    let ei = e * PI * r.powi(4) / 4.0;
    let bent = V6::new(0.0, 3.0 + mom / ei, 0.0, 1.0, 0.0, 0.0);
    let (tip, exact) = (ws.g.last().unwrap(), exp_se3(&(bent * l)));
    assert!(
        (tip.pos - exact.pos).norm() < 1e-10 && (tip.rot - exact.rot).amax() < 1e-10,
        "tip {} vs {}",
        tip.pos,
        exact.pos
    );
    for xi in m.point_strains(&ws) {
        assert!((xi - bent).amax() < 1e-10, "ξ = {xi}");
    }
}
