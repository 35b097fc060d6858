//! `gvsrom linearize` end to end: the poles of a uniform cantilever against its undamped modes and
//! the Kelvin–Voigt damping ratio `ζ = t_d ω / 2` of each; the static gain `−C A⁻¹ B` against the
//! closed form of a straight tendon's uniform moment and against differences of `gvsrom statics`
//! under gravity and friction (another path: the nonlinear solver); a reduced model's 2r states; the
//! JSON and one-line errors.

mod common;

use common::{expect_error, f64s, gvsrom, run_json, s, scratch, sweep_dataset};
use std::f64::consts::PI;
use std::path::PathBuf;

/// The uniform clamped–free rod of `modes_cli.rs` (L = 0.5 m, r = 5 mm, E = 1 MPa, ν = ½,
/// ρ = 1000 kg/m³, no gravity; six components in Legendre order 6: 42 DOF) with material damping
/// `DAMPING` and a frictionless tendon at a constant offset `d = 3 mm` along +z, slack at 0 N.
const ROD: &str = r#"
name = "uniform-cantilever"
magnus = "z4"
[material]
youngs_modulus = 1e6
poisson_ratio = 0.5
density = 1000.0
damping = DAMPING
[[divisions]]
length = 0.5
radius = 0.005
basis = { kind = "legendre", modes = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 6 }
quadrature = { gauss = 21 }   # 3(p + 1): the Magnus rule resolves order 6
[[tendons]]
offset_start = [0.0, 0.003]
offset_end = [0.0, 0.003]
x_start = 0.0
x_end = 0.5
tension = 0.0
[loads]
gravity = [0.0, 0.0, 0.0]
"#;
const L: f64 = 0.5;
const R: f64 = 0.005;
const E: f64 = 1e6;
const D: f64 = 0.003;

fn rod_file(name: &str, damping: f64) -> PathBuf {
    let path = scratch(&format!("{name}.toml"));
    std::fs::write(&path, ROD.replace("DAMPING", &format!("{damping:e}"))).unwrap();
    path
}

fn matrix(v: &serde_json::Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(f64s).collect()
}

/// `(Re λ, Im λ)` of the listed poles.
fn poles(json: &serde_json::Value) -> Vec<(f64, f64)> {
    json["poles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p["re"].as_f64().unwrap(), p["im"].as_f64().unwrap()))
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn undamped_cantilever_poles_are_its_modes_frequencies() {
    // without damping A = [0 I; −M⁻¹K 0]: poles ±iω for every mode of `gvsrom modes`
    let path = rod_file("lin-undamped", 0.0);
    let (_, modes) = run_json("modes", "lin-undamped-modes", &[s(&path)]);
    let (stdout, lin) = run_json("linearize", "lin-undamped", &[s(&path)]);
    let freqs = f64s(&modes["all_frequencies_hz"]);
    let p = poles(&lin);
    assert_eq!(p.len(), freqs.len(), "one conjugate pair per mode");
    let scale = p.iter().fold(0.0_f64, |m, (re, im)| m.max(re.hypot(*im)));
    for (k, ((re, im), f)) in p.iter().zip(&freqs).enumerate().take(12) {
        assert!(re.abs() < 1e-9 * scale, "pole {k}: Re λ = {re:e}");
        assert!(
            rel(im / (2.0 * PI), *f) < 1e-7,
            "pole {k}: {im} rad/s vs mode {f} Hz"
        );
    }
    assert!(
        stdout.contains("(84 states)") && stdout.contains("1 tendon tension"),
        "{stdout}"
    );
    assert!(
        !stdout.contains("note"),
        "no relaxation cluster without damping: {stdout}"
    );
}

#[test]
fn kelvin_voigt_cantilever_poles_have_the_damping_ratio_t_d_omega_over_2() {
    // ν = ½: Ds = t_d Es in every component, t_d = 3η/E, so D = t_d K and each mode ω has the
    // poles of λ² + t_d ω² λ + ω² = 0: |λ| = ω and ζ = t_d ω / 2 while underdamped
    let eta = 2e3;
    let t_d = 3.0 * eta / E;
    let undamped = rod_file("lin-kv-undamped", 0.0);
    let (_, modes) = run_json("modes", "lin-kv-modes", &[s(&undamped)]);
    let path = rod_file("lin-kv", eta);
    let (stdout, lin) = run_json("linearize", "lin-kv", &[s(&path)]);
    assert!(rel(lin["damping_time_s"].as_f64().unwrap(), t_d) < 1e-12);
    let freqs = f64s(&modes["all_frequencies_hz"]);
    let listed = lin["poles"].as_array().unwrap();
    let mut checked = 0;
    for (k, f) in freqs.iter().enumerate() {
        let omega = 2.0 * PI * f;
        let zeta = t_d * omega / 2.0;
        if zeta >= 0.5 {
            break;
        }
        let pole = &listed[k];
        let (hz, z) = (
            pole["natural_frequency_hz"].as_f64().unwrap(),
            pole["damping_ratio"].as_f64().unwrap(),
        );
        assert!(rel(hz, *f) < 1e-7, "pole {k}: |λ|/2π = {hz} vs {f} Hz");
        assert!(rel(z, zeta) < 1e-6, "pole {k}: ζ = {z} vs t_d ω/2 = {zeta}");
        checked += 1;
    }
    assert!(checked >= 6, "only {checked} underdamped modes: {stdout}");
    // the overdamped modes' slow poles gather near −1/t_d, and the note says so
    assert!(lin["relaxation_poles"].as_u64().unwrap() > 10, "{stdout}");
    assert!(stdout.contains("−1/t_d = −166.6667 1/s"), "{stdout}");
}

#[test]
fn static_gain_of_a_straight_tendon_is_the_uniform_moments_closed_form() {
    // About the straight rod a tension u gives the uniform moment u d about y and the axial force
    // u: the tip moves by δz = −d L²/(2EI) u (a pull, u < 0, lifts it towards the tendon) and
    // δx = L/(EA) u; the basis holds uniform strains exactly, so only rounding separates them.
    let path = rod_file("lin-gain", 1e3);
    let (stdout, lin) = run_json("linearize", "lin-gain", &[s(&path)]);
    let g = matrix(&lin["static_gain"]);
    let (area, inertia) = (PI * R * R, PI * R.powi(4) / 4.0);
    let gz = -D * L * L / (2.0 * E * inertia);
    let gx = L / (E * area);
    assert!(rel(g[2][0], gz) < 1e-9, "δz/δu = {} vs {gz}", g[2][0]);
    assert!(rel(g[0][0], gx) < 1e-9, "δx/δu = {} vs {gx}", g[0][0]);
    assert!(g[1][0].abs() < 1e-12 * gz.abs(), "δy/δu = {}", g[1][0]);
    assert!(stdout.contains("  tendon 0"), "{stdout}");
}

#[test]
fn output_points_along_the_rod_have_the_uniform_moments_closed_form_gain() {
    // Along the rod the same uniform moment moves the section at X by δz = −d X²/(2EI) u and
    // δx = X/(EA) u; X between the computational points (21 Gauss points), at one and at the tip
    let path = rod_file("lin-outputs", 1e3);
    let xs = [0.1234, 0.25, 0.5];
    let (stdout, lin) = run_json(
        "linearize",
        "lin-outputs",
        &[s(&path), "--output-at", "0.1234,0.25,0.5"],
    );
    assert_eq!(f64s(&lin["outputs"]), xs.to_vec());
    let g = matrix(&lin["static_gain"]);
    let c = matrix(&lin["c"]);
    assert_eq!((g.len(), c.len()), (9, 9));
    let (area, inertia) = (PI * R * R, PI * R.powi(4) / 4.0);
    for (k, x) in xs.iter().enumerate() {
        let gz = -D * x * x / (2.0 * E * inertia);
        let gx = x / (E * area);
        assert!(
            rel(g[3 * k + 2][0], gz) < 1e-9,
            "X = {x}: δz/δu = {} vs {gz}",
            g[3 * k + 2][0]
        );
        assert!(
            rel(g[3 * k][0], gx) < 1e-9,
            "X = {x}: δx/δu = {} vs {gx}",
            g[3 * k][0]
        );
        assert!(g[3 * k + 1][0].abs() < 1e-12 * gz.abs());
        assert!(
            stdout.contains(&format!("gain       settled X = {x} m displacement")),
            "{stdout}"
        );
    }
    // the tip's rows are the default output's
    let (_, tip) = run_json("linearize", "lin-outputs-tip", &[s(&path)]);
    assert_eq!(matrix(&tip["c"]), c[6..].to_vec());
    assert_eq!(f64s(&tip["outputs"]), vec![L]);
    for bad in ["--output-at=-0.1", "--output-at=0.6", "--output-at=nan"] {
        expect_error(
            &["linearize", s(&path), bad],
            &["--output-at `", "within [0, 0.5] m"],
        );
    }
}

#[test]
fn tendon_length_output_gain_is_the_tendons_compliance_l_over_ea_plus_d2_l_over_ei() {
    // About the straight rod a tension u stretches the rod by u/EA and bends it by κ = u d/EI, so
    // the tendon at the constant offset d is ℓ = L (1 + u/EA + κ d): ∂ℓ/∂u = L (1/EA + d²/EI),
    // exactly (uniform strains); its row follows the tip's three
    let path = rod_file("lin-tendon", 1e3);
    let (stdout, lin) = run_json(
        "linearize",
        "lin-tendon",
        &[s(&path), "--output-tendon-lengths"],
    );
    let (area, inertia) = (PI * R * R, PI * R.powi(4) / 4.0);
    let compliance = L * (1.0 / (E * area) + D * D / (E * inertia));
    let g = matrix(&lin["static_gain"]);
    assert_eq!((g.len(), matrix(&lin["c"]).len()), (4, 4));
    assert!(
        rel(g[3][0], compliance) < 1e-9,
        "∂ℓ/∂u = {} vs {compliance}",
        g[3][0]
    );
    // at the straight equilibrium the tendon is as long as the rod (the Gauss weights' sum)
    let length = f64s(&lin["output_tendon_lengths"]);
    assert!(length.len() == 1 && rel(length[0], L) < 1e-14, "{length:?}");
    for needle in [
        "y the tip position (world) [m] and the tendon lengths [m];",
        "output     tendon lengths [0.500000] m",
        "gain       settled change of each tendon length per newton of tension",
    ] {
        assert!(stdout.contains(needle), "lacks `{needle}`:\n{stdout}");
    }
    // without tendons there is no length to output
    let bare = scratch("lin-bare.toml");
    let text = ROD.replace("DAMPING", "1e3");
    let cut = text.find("[[tendons]]").unwrap()..text.find("[loads]").unwrap();
    std::fs::write(&bare, text.replace(&text[cut], "")).unwrap();
    expect_error(
        &["linearize", s(&bare), "--output-tendon-lengths"],
        &["--output-tendon-lengths: the rod has no tendons"],
    );
}

#[test]
fn tip_orientation_output_gain_is_the_uniform_moments_turn_d_l_over_ei() {
    // the uniform moment u d about y turns the tip by κ L = u d L/EI about world y (positive θ
    // turns +x toward −z, as δz = −d L²/(2EI) u says); its 3 rows follow the tip's position
    // and precede the tendon length's
    let path = rod_file("lin-turn", 1e3);
    let (stdout, lin) = run_json(
        "linearize",
        "lin-turn",
        &[
            s(&path),
            "--output-tip-orientation",
            "--output-tendon-lengths",
        ],
    );
    let inertia = PI * R.powi(4) / 4.0;
    let turn = D * L / (E * inertia);
    let g = matrix(&lin["static_gain"]);
    assert_eq!(g.len(), 3 + 3 + 1);
    assert!(rel(g[4][0], turn) < 1e-9, "δθ_y/δu = {} vs {turn}", g[4][0]);
    assert!(g[3][0].abs() < 1e-12 * turn && g[5][0].abs() < 1e-12 * turn);
    // the position rows as without it, the length's last
    let gz = -D * L * L / (2.0 * E * inertia);
    assert!(rel(g[2][0], gz) < 1e-9);
    let area = PI * R * R;
    assert!(rel(g[6][0], L * (1.0 / (E * area) + D * D / (E * inertia))) < 1e-9);
    // at the straight equilibrium the tip's rotation is the identity
    let rot = matrix(&lin["output_tip_rotation"]);
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { 1.0 } else { 0.0 };
            assert!((rot[i][j] - id).abs() < 1e-12, "{rot:?}");
        }
    }
    assert!(
        stdout.contains("gain       settled tip rotation per newton of tension"),
        "{stdout}"
    );
}

#[test]
fn frictionless_tendons_compliance_is_symmetric_and_the_equilibriums_derivative() {
    // six-tendon under gravity, frictionless: the tendons' lengths are the gradients' potentials
    // of their tensions (B = (∂ℓ/∂q)ᵀ), so the compliance ∂ℓ_j/∂u_k = Bᵀ K_t⁻¹ B is symmetric
    // (Maxwell–Betti) with a positive diagonal; its first column against central differences of
    // the lengths `gvsrom statics --json` writes (another path: the nonlinear solver)
    let (_, lin) = run_json(
        "linearize",
        "lin-six-tendons",
        &["six-tendon", "--output-tendon-lengths"],
    );
    let g = matrix(&lin["static_gain"]);
    assert_eq!(g.len(), 3 + 6);
    let t = &g[3..];
    let scale = (0..6).map(|k| t[k][k]).fold(0.0, f64::max);
    for j in 0..6 {
        assert!(t[j][j] > 0.0, "∂ℓ_{j}/∂u_{j} = {}", t[j][j]);
        for k in 0..j {
            assert!(
                (t[j][k] - t[k][j]).abs() < 1e-9 * scale,
                "∂ℓ_{j}/∂u_{k} = {} vs ∂ℓ_{k}/∂u_{j} = {}",
                t[j][k],
                t[k][j]
            );
        }
    }
    // about the preset's tensions, [-10, 0, 0, 0, 0, 0] N
    assert_eq!(f64s(&lin["u"]), vec![-10.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let h = 0.01;
    let lengths = |u0: f64, tag: &str| {
        let tension = format!("--tension={u0},0,0,0,0,0");
        let (_, json) = run_json(
            "statics",
            &format!("lin-six-{tag}"),
            &["six-tendon", &tension],
        );
        f64s(&json["tendon_lengths"])
    };
    let (p, m) = (lengths(-10.0 + h, "plus"), lengths(-10.0 - h, "minus"));
    for j in 0..6 {
        let fd = (p[j] - m[j]) / (2.0 * h);
        assert!(
            (t[j][0] - fd).abs() < 1e-5 * scale,
            "∂ℓ_{j}/∂u_0 = {} vs statics {fd}",
            t[j][0]
        );
    }
}

#[test]
fn output_point_gain_under_gravity_and_friction_is_the_equilibriums_derivative() {
    // IV-A bent by gravity and friction, X = L/2 (between points): −C A⁻¹ B against central
    // differences of the centreline sample at L/2 of `gvsrom statics --json` (21 samples)
    let (_, lin) = run_json(
        "linearize",
        "lin-iva-mid",
        &["single-tendon", "--output-at", "0.125"],
    );
    let g = matrix(&lin["static_gain"]);
    let fd = statics_gain(&["single-tendon"], -3.0, 0.01, "lin-iva-mid", |json| {
        assert_eq!(json["centerline_x"][10].as_f64(), Some(0.125));
        f64s(&json["centerline"][10])
    });
    assert_gain_is(&g, fd);
}

/// `δy/δu` by central differences of the position that `read` takes from `gvsrom statics --json`
/// at `u ± h`.
fn statics_gain(
    scenario: &[&str],
    u: f64,
    h: f64,
    name: &str,
    read: impl Fn(&serde_json::Value) -> Vec<f64>,
) -> [f64; 3] {
    let at = |t: f64, tag: &str| {
        let mut args = scenario.to_vec();
        let tension = format!("--tension={t}");
        args.push(&tension);
        let (_, json) = run_json("statics", &format!("{name}-{tag}"), &args);
        read(&json)
    };
    let (p, m) = (at(u + h, "plus"), at(u - h, "minus"));
    [0, 1, 2].map(|i| (p[i] - m[i]) / (2.0 * h))
}

fn tip(json: &serde_json::Value) -> Vec<f64> {
    f64s(&json["tip_position"])
}

/// The first column of the gain rows `g` equals the differences `fd` within 1e-5 of their norm
/// (the differences' error O(h²) ≈ 1e-6).
fn assert_gain_is(g: &[Vec<f64>], fd: [f64; 3]) {
    let norm = fd.iter().map(|v| v * v).sum::<f64>().sqrt();
    assert!(norm > 0.0);
    for i in 0..3 {
        assert!(
            (g[i][0] - fd[i]).abs() < 1e-5 * norm,
            "axis {i}: gain {} vs statics {}",
            g[i][0],
            fd[i]
        );
    }
}

#[test]
fn static_gain_under_gravity_and_friction_is_the_equilibriums_derivative() {
    // IV-A: gravity, a tapered arm bent to 5 % of its length, friction 0.88; the equilibrium's tip
    // by the nonlinear solver at −3 ± 0.01 N against −C A⁻¹ B (difference error O(h²) ≈ 1e-6)
    let (_, lin) = run_json("linearize", "lin-iva", &["single-tendon"]);
    assert_eq!(lin["about"], "equilibrium");
    assert!(lin["equilibrium_residual_norm"].as_f64().unwrap() < 1e-8);
    let g = matrix(&lin["static_gain"]);
    assert_gain_is(
        &g,
        statics_gain(&["single-tendon"], -3.0, 0.01, "lin-iva-statics", tip),
    );
    // at the solved equilibrium q̇ = 0, and the residual's q̈ moves the tip by a tiny acceleration
    let xdot = f64s(&lin["xdot"]);
    let c = matrix(&lin["c"]);
    let n = xdot.len() / 2;
    assert!(xdot[..n].iter().all(|v| *v == 0.0));
    let tip_acc = (0..3)
        .map(|i| (0..n).map(|j| c[i][j] * xdot[n + j]).sum::<f64>().powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        tip_acc < 1e-6,
        "tip acceleration {tip_acc:e} m/s² at the equilibrium"
    );
}

#[test]
fn a_pod_models_linearization_has_2r_states_and_its_own_static_gain() {
    let ds = sweep_dataset("lin-pod-ds", "-6:0", 12);
    let pod = scratch("lin-pod3");
    let out = gvsrom(&["pod", s(&ds), "--modes", "3", "--out", s(&pod)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (stdout, lin) = run_json(
        "linearize",
        "lin-rom",
        &["single-tendon", "--model", s(&pod)],
    );
    assert_eq!(lin["n_dof"].as_u64(), Some(3));
    assert_eq!(matrix(&lin["a"]).len(), 6);
    assert_eq!(matrix(&lin["b"])[0].len(), 1);
    assert_eq!(matrix(&lin["c"]).len(), 3);
    assert_eq!(lin["model"].as_str(), Some(s(&pod)));
    assert!(stdout.contains("(6 states)"), "{stdout}");
    let g = matrix(&lin["static_gain"]);
    let fd = statics_gain(
        &["single-tendon", "--model", s(&pod)],
        -3.0,
        0.01,
        "lin-rom-statics",
        tip,
    );
    assert_gain_is(&g, fd);
    // an output point of the reduced model: 3 rows of its 6 states, its gain the derivative of
    // its own equilibria's centreline there
    let (_, mid) = run_json(
        "linearize",
        "lin-rom-mid",
        &["single-tendon", "--model", s(&pod), "--output-at", "0.125"],
    );
    let c = matrix(&mid["c"]);
    assert_eq!((c.len(), c[0].len()), (3, 6));
    let fd = statics_gain(
        &["single-tendon", "--model", s(&pod)],
        -3.0,
        0.01,
        "lin-rom-mid-statics",
        |json| f64s(&json["centerline"][10]),
    );
    assert_gain_is(&matrix(&mid["static_gain"]), fd);
}

#[test]
fn json_records_the_run_and_bad_input_is_a_one_line_error() {
    let (_, lin) = run_json("linearize", "lin-six", &["six-tendon"]);
    assert_eq!(lin["gvsrom"]["format"], "linearize");
    assert!(lin["provenance"].is_object(), "{lin}");
    let n = lin["n_dof"].as_u64().unwrap() as usize;
    assert_eq!(n, 28);
    let (a, b, c) = (matrix(&lin["a"]), matrix(&lin["b"]), matrix(&lin["c"]));
    assert_eq!((a.len(), a[0].len()), (2 * n, 2 * n));
    assert_eq!((b.len(), b[0].len()), (2 * n, 6));
    assert_eq!((c.len(), c[0].len()), (3, 2 * n));
    assert_eq!(matrix(&lin["static_gain"])[0].len(), 6);
    for bad in ["0", "-1", "2.5", "many"] {
        expect_error(
            &["linearize", "six-tendon", "--count", bad],
            &[&format!("--count `{bad}`"), "integer ≥ 1", "56 states"],
        );
    }
    expect_error(
        &["linearize", "six-tendon", "--set", "material.density=0"],
        &["material.density", "a motion needs a rod with mass"],
    );
    // the file the first run wrote (not cleared: `scratch` would remove it)
    let file = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gvsrom-cli-tests/lin-six.json");
    assert!(file.is_file());
    expect_error(
        &["linearize", "six-tendon", "--json", s(&file)],
        &["--json", "--force"],
    );
}

#[test]
fn upright_rod_beyond_self_weight_buckling_has_one_unstable_pole_per_buckling_mode() {
    // The rod of `modes_cli.rs` standing in gravity along −x, 2.9× the critical length of
    // self-weight buckling: each mode with ω² < 0 gives the real poles ±√(−ω²) undamped, so as
    // many unstable poles as `gvsrom modes` reports unstable modes; with damping they stay unstable
    // (a damper slows a divergence, it cannot stop one).
    for (name, damping) in [("lin-upright", 0.0), ("lin-upright-damped", 1e3)] {
        let path = scratch(&format!("{name}.toml"));
        let text = ROD
            .replace("DAMPING", &format!("{damping:e}"))
            .replace("gravity = [0.0, 0.0, 0.0]", "gravity = [-9.81, 0.0, 0.0]");
        std::fs::write(&path, text).unwrap();
        let (_, modes) = run_json(
            "modes",
            &format!("{name}-modes"),
            &[s(&path), "--count", "42"],
        );
        let negative = modes["modes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["omega_squared"].as_f64().unwrap() < 0.0)
            .count();
        assert!(negative >= 2, "{modes}");
        let (stdout, lin) = run_json("linearize", name, &[s(&path)]);
        assert_eq!(
            lin["unstable_poles"].as_u64(),
            Some(negative as u64),
            "{stdout}"
        );
        assert!(
            stdout.contains(&format!("note       {negative} poles with Re λ > 0")),
            "{stdout}"
        );
        // about an unstable equilibrium the static gain still exists (A is regular)
        assert!(lin["static_gain"].is_array());
        // a hold long enough for e^(λh) of an unstable pole to overflow is refused, with the
        // longest hold that stays finite, ln(f64::MAX)/λ
        let re = lin["poles"].as_array().unwrap()[0]["re"].as_f64().unwrap();
        let stderr = expect_error(
            &["linearize", s(&path), "--sample-time", "1e4"],
            &[
                "--sample-time `10000`",
                "not finite",
                "unstable pole",
                "a shorter hold, below about",
            ],
        );
        let most = f64::MAX.ln()
            / lin["poles"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| p["re"].as_f64().unwrap())
                .fold(re, f64::max);
        assert!(
            stderr.contains(&gvs::error::fmt_value(most)),
            "{stderr} (expected {most})"
        );
    }
}

#[test]
fn zero_order_hold_composes_as_two_half_samples_and_refuses_a_bad_sample_time() {
    // exact ZOH matrices compose: A_d(2h) = A_d(h)², B_d(2h) = A_d(h) B_d(h) + B_d(h) (the
    // prediction against the nonlinear simulation is in the Python tests)
    let one = |h: &str, name: &str| {
        let (stdout, lin) = run_json(
            "linearize",
            name,
            &["six-tendon", "--tension=-4,0,0,-1,0,0", "--sample-time", h],
        );
        assert!(
            stdout.contains(&format!("zero-order hold of {h} s")),
            "{stdout}"
        );
        let d = &lin["discrete"];
        (
            nalgebra::DMatrix::from_row_slice(56, 56, &matrix(&d["ad"]).concat()),
            nalgebra::DMatrix::from_row_slice(56, 6, &matrix(&d["bd"]).concat()),
            d["spectral_radius"].as_f64().unwrap(),
        )
    };
    let (ad1, bd1, rho1) = one("0.01", "lin-zoh-1");
    let (ad2, bd2, rho2) = one("0.02", "lin-zoh-2");
    let ea = (&ad1 * &ad1 - &ad2).norm() / ad2.norm();
    let eb = (&ad1 * &bd1 + &bd1 - &bd2).norm() / bd2.norm();
    assert!(ea < 1e-10 && eb < 1e-10, "A_d {ea:e}, B_d {eb:e}");
    assert!(
        rho1 < 1.0 && (rho2 - rho1 * rho1).abs() < 1e-12,
        "{rho1} {rho2}"
    );
    for bad in ["0", "-0.01", "nan", "inf", "1e300"] {
        expect_error(
            &["linearize", "six-tendon", "--sample-time", bad],
            &["--sample-time", "finite and > 0, at most 10000"],
        );
    }
}

/// The IV-A arm as a horizontal column (no gravity, no tension) compressed by a world-fixed end
/// force near its buckling load (0.14266 N, where `modes`' ω² changes sign): K_T nearly singular,
/// the slowest pole near 0 and the gain ∝ 1/|λ| ill-conditioned, which the output says; beyond
/// the load the gain is no settled displacement; at half the load neither is said.
#[test]
fn a_gain_near_the_buckling_load_is_said_to_be_ill_conditioned() {
    let run = |force: f64| -> String {
        let load =
            format!("loads.point=[{{x = 0.25, force = [{force}, 0, 0], frame = \"global\"}}]");
        let out = gvsrom(&[
            "linearize",
            "single-tendon",
            "--tension",
            "0",
            "--set",
            "loads.gravity=[0, 0, 0]",
            "--set",
            &load,
            "--set",
            "solver.check_stability=false",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let below = run(-0.1426);
    assert!(below.contains("A is nearly singular"), "{below}");
    assert!(
        below.contains("gain       settled tip displacement"),
        "{below}"
    );
    let beyond = run(-0.1427);
    assert!(beyond.contains("A is nearly singular"), "{beyond}");
    assert!(
        beyond.contains("gain       equilibrium's tip displacement")
            && beyond.contains("not a settled displacement"),
        "{beyond}"
    );
    let half = run(-0.0713);
    assert!(!half.contains("nearly singular"), "{half}");
    assert!(
        half.contains("gain       settled tip displacement"),
        "{half}"
    );
}
