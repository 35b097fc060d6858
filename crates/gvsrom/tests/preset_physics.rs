//! Physics checks on the built-in presets: the analytic statics Jacobian against central finite
//! differences at each preset's equilibrium (gvs-spec §10.3.9, relative error ≤ 1e-6), the
//! six-tendon symmetry without gravity (gvs-spec §10.2): pulling a tendon or the one 120° away gives
//! configurations related by a 120° rotation about the rod axis, and the loads the paper's setups
//! state: the soft beam's pulse integrates to its total moment, the six-tendon arm hangs in gravity,
//! and the hanging variant at 0 N stretches by its own weight as the closed form says.

use gvs::loads::DistributedWrench;
use gvs::solve::statics::solve_statics;
use nalgebra::{DMatrix, DVector, Rotation3, Vector3};

fn built(preset: &str, overrides: &[&str]) -> gvsrom::Built {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    gvsrom::build(&gvsrom::presets::load(preset, &o).unwrap()).unwrap()
}

fn jacobian_error(b: &gvsrom::Built) -> f64 {
    let m = &b.model;
    let n = m.n_dof();
    let q = solve_statics(m, &b.u, &b.loads, None, &b.options)
        .unwrap()
        .q;
    let pl = m.prepare_loads(&b.loads).unwrap();
    let mut ws = m.workspace();
    let mut an = DMatrix::zeros(n, n);
    m.statics_jacobian(&q, &b.u, &pl, &mut ws, &mut an);
    let mut fd = DMatrix::zeros(n, n);
    let (mut rp, mut rm) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let h = 1e-6 * (1.0 + q[j].abs());
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        m.statics_residual(&qp, &b.u, &pl, &mut ws, &mut rp);
        m.statics_residual(&qm, &b.u, &pl, &mut ws, &mut rm);
        fd.set_column(j, &((&rp - &rm) / (2.0 * h)));
    }
    (&an - &fd).norm() / fd.norm()
}

#[test]
fn statics_jacobian_matches_finite_differences_for_every_preset() {
    for (preset, overrides) in [
        ("single-tendon", vec!["tendons.0.tension=-3"]),
        ("single-tendon", vec!["tendons.0.tension=-6"]),
        ("soft-beam", vec![]),
        ("soft-beam-peak", vec![]),
        ("six-tendon", vec![]),
        (
            "six-tendon",
            vec!["tendons.1.tension=-8", "tendons.4.tension=-3"],
        ),
        ("six-tendon-no-gravity", vec![]),
        (
            "six-tendon-no-gravity",
            vec!["tendons.1.tension=-8", "tendons.4.tension=-3"],
        ),
        ("six-tendon-hanging", vec![]),
        (
            "six-tendon-hanging",
            vec!["tendons.1.tension=-8", "tendons.4.tension=-3"],
        ),
    ] {
        let err = jacobian_error(&built(preset, &overrides));
        assert!(
            err < 1e-6,
            "{preset} {overrides:?}: relative Jacobian error {err:e}"
        );
    }
}

fn tip(b: &gvsrom::Built) -> Vector3<f64> {
    let q = solve_statics(&b.model, &b.u, &b.loads, None, &b.options)
        .unwrap()
        .q;
    let mut ws = b.model.workspace();
    b.model.forward(&q, &mut ws, false);
    ws.g[b.model.disc.tip()].pos
}

#[test]
fn six_tendon_pulls_120_degrees_apart_give_rotated_configurations() {
    // gravity along −z would break the rotational symmetry: the preset without it
    let rot = Rotation3::from_axis_angle(&Vector3::x_axis(), 120f64.to_radians());
    for (a, b) in [(0usize, 2usize), (1, 3), (2, 4)] {
        let ta = tip(&built(
            "six-tendon-no-gravity",
            &["tendons.0.tension=0", &format!("tendons.{a}.tension=-10")],
        ));
        let tb = tip(&built(
            "six-tendon-no-gravity",
            &["tendons.0.tension=0", &format!("tendons.{b}.tension=-10")],
        ));
        let err = (rot * ta - tb).norm();
        assert!(
            err < 1e-9,
            "tendon {a} vs {b}: |R(120°) tip_a − tip_b| = {err:e}"
        );
        assert!(ta.y.abs() + ta.z.abs() > 0.05, "the pull bends the arm");
    }
}

/// `(∫₀ᴸ ‖m(X)‖ dX, X₀/L)` of the built scenario's single distributed load, a triangular pulse
/// centred at `X₀`: the trapezoid rule on the pulse's breakpoints `0, X₀ − w/2, X₀, X₀ + w/2, L`
/// (clipped to `[0, L]`), exact for a density linear between them; each piece is split in 64 so
/// that a density that is not would differ.
fn pulse_total_moment(b: &gvsrom::Built) -> (f64, f64) {
    assert_eq!(b.loads.distributed.len(), 1, "one distributed load");
    let (center, width) = match b.loads.distributed[0] {
        DistributedWrench::TriangularPulse { center, width, .. } => (center, width),
        other => panic!("not a triangular pulse: {other:?}"),
    };
    let l = b.model.disc.length();
    let mut breaks: Vec<f64> = [0.0, center - width / 2.0, center, center + width / 2.0, l]
        .into_iter()
        .map(|x| x.clamp(0.0, l))
        .collect();
    breaks.sort_by(f64::total_cmp);
    let density = |x: f64| {
        b.loads.distributed[0]
            .density_at(x)
            .0
            .fixed_rows::<3>(0)
            .norm()
    };
    let mut total = 0.0;
    for w in breaks.windows(2) {
        let h = (w[1] - w[0]) / 64.0;
        for i in 0..64 {
            let (a, c) = (w[0] + i as f64 * h, w[0] + (i + 1) as f64 * h);
            total += 0.5 * h * (density(a) + density(c));
        }
    }
    (total, center / l)
}

#[test]
fn soft_beam_pulse_integrates_to_the_papers_4_newton_metres() {
    // the paper's first IV-B load: 4 N·m in total at X/L = 0.25 (the preset reads it as the total)
    let (total, at) = pulse_total_moment(&built("soft-beam", &[]));
    assert!((total - 4.0).abs() < 1e-12 * 4.0, "∫ m dX = {total} N·m");
    assert!((at - 0.25).abs() < 1e-12, "X₀/L = {at}");
}

#[test]
fn soft_beam_peak_pulse_integrates_to_peak_times_half_width() {
    // peak 4 N·m/m over a base of w = 0.1 L = 0.08 m: ∫ m dX = 4 · 0.5 · 0.08 = 0.16 N·m
    let (total, _) = pulse_total_moment(&built("soft-beam-peak", &[]));
    assert!(
        (total - 4.0 * 0.5 * 0.08).abs() < 1e-12 * 0.16,
        "∫ m dX = {total} N·m"
    );
}

#[test]
fn six_tendon_hangs_in_gravity_along_minus_z_and_its_variant_has_none() {
    assert_eq!(built("six-tendon", &[]).loads.gravity, [0.0, 0.0, -9.81]);
    assert_eq!(
        built("six-tendon-no-gravity", &[]).loads.gravity,
        [0.0, 0.0, 0.0]
    );
}

/// `∫_a^b f` by 40-point Gauss–Legendre (nodes from Newton on `P₄₀`; exact for degree ≤ 79).
fn gauss40(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    const N: usize = 40;
    let (mut sum, (h, c)) = (0.0, ((b - a) / 2.0, (a + b) / 2.0));
    for i in 0..N {
        // Newton on P_N from the Chebyshev-like guess; P_N and P_N' by the three-term recurrence
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (N as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=N {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                (p0, p1) = (p1, p2);
            }
            dp = N as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        sum += w * f(c + h * x);
    }
    h * sum
}

#[test]
fn six_tendon_hanging_at_rest_stretches_by_its_own_weight() {
    // The arm hangs along −z, the direction of gravity: at 0 N it stays straight and only stretches.
    // Closed form: the axial force N(X) = ρ g ∫_X^L A, the strain ε = N / (E A). The model's strain
    // is linear per division (Legendre order 1 in elongation), and the statics is its Galerkin
    // solution: on each division ε_h is the E A-weighted projection of ε onto {1, ξ}
    // (∫ E A ε_h φ = ∫ N φ for every basis function φ), so the tip lies at −(L + ∫ ε_h), which the
    // model's 5 Gauss points and z4 Magnus steps integrate exactly (polynomials of degree ≤ 6).
    let b = built("six-tendon-hanging", &["tendons.0.tension=0"]);
    let (rho, g, e) = (1000.0, 9.81, 1e6);
    let radius = |x: f64| 0.02 - 0.01 * x / 0.6;
    let area = |x: f64| std::f64::consts::PI * radius(x).powi(2);
    let axial = |x: f64| rho * g * gauss40(area, x, 0.6);
    let mut stretch = 0.0;
    for (a, c) in [(0.0, 0.3), (0.3, 0.6)] {
        let phi = |k: usize, x: f64| {
            if k == 0 {
                1.0
            } else {
                (2.0 * x - a - c) / (c - a)
            }
        };
        let k = |i: usize, j: usize| gauss40(|x| e * area(x) * phi(i, x) * phi(j, x), a, c);
        let f = |i: usize| gauss40(|x| axial(x) * phi(i, x), a, c);
        let (k00, k01, k11) = (k(0, 0), k(0, 1), k(1, 1));
        let det = k00 * k11 - k01 * k01;
        let c0 = (k11 * f(0) - k01 * f(1)) / det;
        // ∫ φ₁ = 0 on the division: only the constant coefficient adds length
        stretch += c0 * (c - a);
    }
    let exact = gauss40(|x| axial(x) / (e * area(x)), 0.0, 0.3)
        + gauss40(|x| axial(x) / (e * area(x)), 0.3, 0.6);
    // the projection is not the exact strain, but close (here 0.05 % of the stretch)
    assert!(
        (stretch - exact).abs() < 1e-3 * exact,
        "{stretch} vs {exact}"
    );
    let tip = tip(&b);
    assert!(tip.x.abs() < 1e-12 && tip.y.abs() < 1e-12, "{tip}");
    assert!(
        (tip.z + 0.6 + stretch).abs() < 1e-9 * stretch,
        "tip z = {} against −(L + {stretch}) (closed-form stretch {exact})",
        tip.z
    );
}
