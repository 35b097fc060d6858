//! `gvsrom modes` end to end: the natural frequencies of a uniform cantilever against their closed
//! forms (axial, torsional, Euler–Bernoulli bending), convergence as the basis grows, the shapes'
//! M-orthonormality and K_T-orthogonality (checked with the engine's own M and ∂R/∂q, not the
//! command's), unstable equilibria, a reduced model, and one-line errors for bad input.

mod common;

use common::{expect_error, f64s, gvsrom, json as json_file, run_json, run_ok, s, scratch};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;
use std::path::PathBuf;

/// A uniform clamped–free rod, L = 0.5 m, r = 5 mm (L/r = 100), E = 1 MPa, ν = 0.5, ρ = 1000 kg/m³,
/// no gravity and no loads (gvs-spec §10.5), all six strain components in Legendre order 6 with 12
/// Gauss points: 42 DOF.
const ROD: &str = r#"
name = "uniform-cantilever"
magnus = "z4"
[material]
youngs_modulus = 1e6
poisson_ratio = 0.5
density = 1000.0
[[divisions]]
length = 0.5
radius = 0.005
basis = { kind = "legendre", modes = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 6 }
quadrature = { gauss = 12 }
[loads]
gravity = [0.0, 0.0, 0.0]
"#;
const L: f64 = 0.5;
const R: f64 = 0.005;
const E: f64 = 1e6;
const NU: f64 = 0.5;
const RHO: f64 = 1000.0;

fn rod_file(name: &str, text: &str) -> PathBuf {
    let path = scratch(&format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs `gvsrom modes ARGS --json FILE`, expects success; returns stdout and the JSON.
fn modes_json(name: &str, args: &[&str]) -> (String, serde_json::Value) {
    run_json("modes", name, args)
}

/// Frequencies [Hz] of the modes whose dominant strain component is `component`, ascending.
fn frequencies_of(json: &serde_json::Value, component: &str) -> Vec<f64> {
    json["modes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["dominant_strain"] == component)
        .map(|m| m["frequency_hz"].as_f64().unwrap())
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn uniform_cantilever_axial_and_torsional_modes_match_their_closed_forms() {
    // f_k = (2k − 1)/(4L) √(E/ρ) (axial), (2k − 1)/(4L) √(G/ρ) (torsion), G = E/(2(1 + ν)): exact
    // for a uniform rod, so what is left is the convergence of the order-6 strain polynomial to
    // cos((2k − 1)πX/2L): ~1e-7 for k = 1 and ~2e-5 for k = 2 (measured), bounded here by 1e-6 and
    // 1e-4. Both are Ritz upper bounds.
    let path = rod_file("modes-rod", ROD);
    let (_, json) = modes_json("modes-rod", &[s(&path), "--count", "42"]);
    let g = E / (2.0 * (1.0 + NU));
    for (component, wave_speed) in [
        ("elongation", (E / RHO).sqrt()),
        ("torsion", (g / RHO).sqrt()),
    ] {
        let f = frequencies_of(&json, component);
        assert!(f.len() >= 2, "{component}: {f:?}");
        for (k, tol) in [(1, 1e-6), (2, 1e-4)] {
            let exact = (2 * k - 1) as f64 / (4.0 * L) * wave_speed;
            let got = f[k - 1];
            assert!(
                rel(got, exact) < tol && got >= exact * (1.0 - 1e-12),
                "{component} mode {k}: {got} Hz vs closed form {exact} Hz"
            );
        }
    }
    // the axial and torsional shapes move the tip along and about the rod's axis only
    for m in json["modes"].as_array().unwrap() {
        let (t, r) = (f64s(&m["tip_displacement"]), f64s(&m["tip_rotation"]));
        match m["dominant_strain"].as_str().unwrap() {
            "elongation" => assert!(
                t[1].abs() + t[2].abs() + r.iter().map(|x| x.abs()).sum::<f64>()
                    < 1e-9 * t[0].abs()
            ),
            "torsion" => assert!(
                t.iter().map(|x| x.abs()).sum::<f64>() + r[1].abs() + r[2].abs()
                    < 1e-9 * r[0].abs()
            ),
            _ => {}
        }
    }
}

#[test]
fn uniform_cantilever_bending_modes_approach_euler_bernoulli() {
    // f_k = (β_k L)²/(2π L²) √(EI/ρA). The rod is a Timoshenko beam (shear, shear factor 1, and
    // rotary inertia), which lowers the frequency by about ½ (β_k L)² (r_g/L)² (1 + E/G),
    // r_g² = I/A = r²/4: 0.018 % for k = 1 and 0.11 % for k = 2 at L/r = 100. So the first mode must
    // lie below Euler–Bernoulli by less than 0.1 %, the second by less than 0.5 %; each is doubly
    // degenerate (about y and z) for the round section.
    let path = rod_file("modes-rod-bending", ROD);
    let (stdout, json) = modes_json("modes-rod-bending", &[s(&path), "--count", "4"]);
    let (area, inertia) = (PI * R * R, PI * R.powi(4) / 4.0);
    let eb =
        |beta_l: f64| beta_l * beta_l / (2.0 * PI * L * L) * (E * inertia / (RHO * area)).sqrt();
    for (k, beta_l, tol) in [
        (1, 1.875_104_068_711_96, 1e-3),
        (2, 4.694_091_132_974_17, 5e-3),
    ] {
        let exact = eb(beta_l);
        for component in ["bend_y", "bend_z"] {
            let got = frequencies_of(&json, component)[k - 1];
            assert!(
                got < exact && rel(got, exact) < tol,
                "{component} mode {k}: {got} Hz vs Euler–Bernoulli {exact} Hz"
            );
        }
    }
    // the degenerate pair is split into pure bending about y (tip along z) and about z (tip along y)
    let row = |k: &str| {
        stdout
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{k} ")))
            .unwrap_or_else(|| panic!("no mode {k}: {stdout}"))
            .to_string()
    };
    for (k, strain, tip) in [
        ("1", "bend_y 100.0 %", "translation z, rotation y"),
        ("2", "bend_z 100.0 %", "translation y, rotation z"),
    ] {
        assert!(row(k).contains(strain) && row(k).ends_with(tip), "{stdout}");
    }
    let modes = json["modes"].as_array().unwrap();
    let (t1, r1) = (
        f64s(&modes[0]["tip_displacement"]),
        f64s(&modes[0]["tip_rotation"]),
    );
    assert!(
        t1[0].abs() + t1[1].abs() + r1[0].abs() + r1[2].abs() < 1e-9 * t1[2].abs(),
        "{t1:?} {r1:?}"
    );
    // sign convention: the largest tip component (rotation × L here, ~1.4× the translation) is
    // positive; bending about +y moves the tip towards −z
    assert!(r1[1] * L > t1[2].abs() && t1[2] < 0.0, "{t1:?} {r1:?}");
}

#[test]
fn first_bending_frequency_converges_as_the_elements_double() {
    // Linear FEM-like bend-y elements: each doubling of the element count changes the first
    // frequency at least 4× less than the previous one (~15× measured: 4.9e-5, 3.6e-6, 2.3e-7 Hz),
    // and from above (Ritz).
    let path = rod_file("modes-rod-fem", ROD);
    let f: Vec<f64> = [2, 4, 8, 16]
        .iter()
        .map(|n| {
            let basis =
                format!("divisions.0.basis={{kind=\"fem\",modes=[\"bend_y\"],elements={n}}}");
            let (_, json) = modes_json(
                &format!("modes-fem-{n}"),
                &[
                    s(&path),
                    "--count",
                    "1",
                    "--set",
                    &basis,
                    "--set",
                    "divisions.0.quadrature={gauss_per_element=2}",
                ],
            );
            json["modes"][0]["frequency_hz"].as_f64().unwrap()
        })
        .collect();
    let changes: Vec<f64> = f.windows(2).map(|w| w[0] - w[1]).collect();
    assert!(changes.iter().all(|&d| d > 0.0), "not decreasing: {f:?}");
    for w in changes.windows(2) {
        assert!(w[1] < w[0] / 4.0, "changes {changes:?} of {f:?}");
    }
}

#[test]
fn fem_bases_give_the_closed_form_frequencies_at_a_poisson_ratio_other_than_one_half() {
    // The FEM mass and stiffness are assembled on each function's support (not the dense path the
    // Legendre tests take), and at ν = ½ a shear modulus taken as E/3 whatever ν would pass every
    // other test: here ν = 0.3 (G = E/2.6, torsion 7 % off at E/3) with linear and quadratic
    // elements. Axial and torsion: f₁ = √(E/ρ)/(4L), √(G/ρ)/(4L) exactly for the uniform rod;
    // bending: Euler–Bernoulli lowered by the rotary inertia of a Rayleigh beam,
    // ½ (β₁L)² (r_g/L)² ≈ 4.4e-5 at L/r = 100 (bend_y alone: no shear).
    let text = ROD.replace("poisson_ratio = 0.5", "poisson_ratio = 0.3");
    let path = rod_file("modes-rod-fem-nu", &text);
    let nu = 0.3;
    let g = E / (2.0 * (1.0 + nu));
    let (area, inertia) = (PI * R * R, PI * R.powi(4) / 4.0);
    let beta_l: f64 = 1.875_104_068_711_96;
    let bending = beta_l * beta_l / (2.0 * PI * L * L) * (E * inertia / (RHO * area)).sqrt();
    // measured: axial and torsion 1.3e-7 above (linear, 16 elements) and 1.1e-9 (quadratic, 8),
    // bending 5.8e-5 below with either
    for (degree, gauss, elements, tol) in [("linear", 2, 16, 1e-6), ("quadratic", 3, 8, 1e-8)] {
        let basis = format!(
            "divisions.0.basis={{kind=\"fem\",modes=[\"torsion\",\"bend_y\",\"elongation\"],elements={elements},degree=\"{degree}\"}}"
        );
        let quadrature = format!("divisions.0.quadrature={{gauss_per_element={gauss}}}");
        let (_, json) = modes_json(
            &format!("modes-fem-nu-{degree}"),
            &[
                s(&path),
                "--count",
                "12",
                "--set",
                &basis,
                "--set",
                &quadrature,
            ],
        );
        for (component, exact) in [
            ("elongation", (E / RHO).sqrt() / (4.0 * L)),
            ("torsion", (g / RHO).sqrt() / (4.0 * L)),
            ("bend_y", bending),
        ] {
            let got = frequencies_of(&json, component)[0];
            let ok = match component {
                // a Ritz upper bound of an exact closed form
                "elongation" | "torsion" => got >= exact * (1.0 - 1e-12) && rel(got, exact) < tol,
                _ => got < exact && rel(got, exact) < 1e-4,
            };
            assert!(
                ok,
                "{degree} fem, ν = {nu}, {component}: {got} Hz vs closed form {exact} Hz"
            );
        }
    }
}

/// The engine's `M(q₀)` and `K_T = −∂R/∂q(q₀)` of a scenario (computed here, not by the command).
fn mass_and_tangent_stiffness(scenario: &str, q0: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
    let built = gvsrom::build(&gvsrom::presets::load(scenario, &[]).unwrap()).unwrap();
    let m = &built.model;
    let q0 = DVector::from_column_slice(q0);
    let mut ws = m.workspace();
    let mass = m.mass_matrix(&q0, &mut ws);
    let loads = m.prepare_loads(&built.loads).unwrap();
    let mut dr = DMatrix::zeros(m.n_dof(), m.n_dof());
    m.statics_jacobian(&q0, &built.u, &loads, &mut ws, &mut dr);
    (mass, -dr)
}

#[test]
fn modes_are_ascending_m_orthonormal_and_k_orthogonal() {
    // φᵢᵀ M φⱼ = δᵢⱼ and φᵢᵀ K_T φⱼ = ω²ᵢ δᵢⱼ with M and K_T from the engine: on the straight rod
    // (degenerate pairs, rotated by the command) and under tendon loads and gravity in 3-D
    // (six-tendon, frictionless: a symmetric K_T).
    let rod = rod_file("modes-rod-ortho", ROD);
    for scenario in [s(&rod), "six-tendon"] {
        let (_, json) = modes_json("modes-ortho", &[scenario, "--count", "1000"]);
        let n = json["n_dof"].as_u64().unwrap() as usize;
        let modes = json["modes"].as_array().unwrap();
        assert_eq!(
            modes.len(),
            n,
            "{scenario}: --count above the DOF count gives all modes"
        );
        let f = f64s(&json["all_frequencies_hz"]);
        assert!(f.windows(2).all(|w| w[0] <= w[1]), "{scenario}: {f:?}");
        let (mass, kt) = mass_and_tangent_stiffness(scenario, &f64s(&json["q0"]));
        assert!(json["stiffness_asymmetry"].as_f64().unwrap() < 1e-10);
        let kt = (&kt + kt.transpose()) * 0.5;
        let phi = DMatrix::from_fn(n, n, |r, c| modes[c]["shape"][r].as_f64().unwrap());
        let m = phi.transpose() * &mass * &phi;
        let k = phi.transpose() * &kt * &phi;
        let w2: Vec<f64> = modes
            .iter()
            .map(|md| md["omega_squared"].as_f64().unwrap())
            .collect();
        let w2_max = w2.iter().cloned().fold(0.0, f64::max);
        for i in 0..n {
            assert!(
                rel((2.0 * PI * f[i]).powi(2), w2[i]) < 1e-9,
                "{scenario} mode {i}: f {} vs ω² {}",
                f[i],
                w2[i]
            );
            for j in 0..n {
                let delta = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (m[(i, j)] - delta).abs() < 1e-9,
                    "{scenario}: φ{i}ᵀ M φ{j} = {}",
                    m[(i, j)]
                );
                // round-off of the eigensolver scales with the largest eigenvalue
                assert!(
                    (k[(i, j)] - delta * w2[i]).abs() < 1e-9 * w2_max,
                    "{scenario}: φ{i}ᵀ K_T φ{j} = {} (ω² = {})",
                    k[(i, j)],
                    w2[i]
                );
            }
        }
    }
}

#[test]
fn a_non_symmetric_tangent_stiffness_gives_the_eigenpairs_of_m_inv_k_and_linearizes_poles() {
    // single-tendon: friction makes K_T non-symmetric (‖K − Kᵀ‖/‖K‖ ≈ 5e-2); each mode solves
    // K_T φ = ω² M φ with the unsymmetrized K_T, φᵀ M φ = 1, and its frequency is an undamped pole
    // of `linearize` (computed by another path: the eigenvalues of the state matrix A)
    let (stdout, json) = modes_json("modes-friction", &["single-tendon", "--count", "1000"]);
    assert!(
        stdout.contains("the tangent stiffness is not symmetric"),
        "{stdout}"
    );
    let asymmetry = json["stiffness_asymmetry"].as_f64().unwrap();
    assert!(asymmetry > 1e-3, "{asymmetry}");
    let n = json["n_dof"].as_u64().unwrap() as usize;
    let modes = json["modes"].as_array().unwrap();
    let (mass, kt) = mass_and_tangent_stiffness("single-tendon", &f64s(&json["q0"]));
    let w2_max = modes
        .iter()
        .map(|m| m["omega_squared"].as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    for (i, md) in modes.iter().enumerate() {
        assert!(
            md.get("omega_squared_imag").is_none(),
            "mode {i} is complex"
        );
        let phi = DVector::from_iterator(n, (0..n).map(|r| md["shape"][r].as_f64().unwrap()));
        let w2 = md["omega_squared"].as_f64().unwrap();
        let residual = (&kt * &phi - w2 * (&mass * &phi)).norm();
        let scale = w2_max * (&mass * &phi).norm();
        assert!(
            residual < 1e-8 * scale,
            "mode {i}: ‖Kφ − ω²Mφ‖ = {residual:e} ({scale:e})"
        );
        assert!((phi.dot(&(&mass * &phi)) - 1.0).abs() < 1e-9, "mode {i}");
    }
    // the lowest two against linearize's undamped poles
    let lin = scratch("modes-friction-lin.json");
    run_ok(&[
        "linearize",
        "single-tendon",
        "--set",
        "material.damping=0",
        "--json",
        s(&lin),
    ]);
    let lin = json_file(&lin);
    for k in 0..2 {
        let pole = lin["poles"][k]["natural_frequency_hz"].as_f64().unwrap();
        let mode = modes[k]["frequency_hz"].as_f64().unwrap();
        assert!(
            rel(pole, mode) < 1e-6,
            "mode {k}: {mode} Hz against the pole's {pole} Hz"
        );
    }
}

#[test]
fn upright_rod_beyond_self_weight_buckling_reports_unstable_modes() {
    // Gravity along −x compresses the rod standing on its base; L = 0.5 m is 2.9× the critical
    // length (7.837 EI/(ρ A g))^(1/3) = 0.171 m of self-weight buckling, so the straight equilibrium
    // is unstable: its lowest bending pairs have ω² < 0, shown at 0 Hz and flagged.
    let path = rod_file(
        "modes-upright",
        &ROD.replace("gravity = [0.0, 0.0, 0.0]", "gravity = [-9.81, 0.0, 0.0]"),
    );
    let (stdout, json) = modes_json("modes-upright", &[s(&path), "--count", "8"]);
    let modes = json["modes"].as_array().unwrap();
    let unstable: Vec<_> = modes
        .iter()
        .filter(|m| m["omega_squared"].as_f64().unwrap() < 0.0)
        .collect();
    assert!(unstable.len() >= 2 && unstable.len() % 2 == 0, "{stdout}");
    for m in &unstable {
        assert_eq!(m["frequency_hz"].as_f64(), Some(0.0));
        assert!(m["period_s"].is_null());
        assert!(m["dominant_strain"].as_str().unwrap().starts_with("bend"));
    }
    let w2: Vec<f64> = modes
        .iter()
        .map(|m| m["omega_squared"].as_f64().unwrap())
        .collect();
    assert!(
        w2.windows(2).all(|w| w[0] <= w[1] + 1e-9 * w[1].abs()),
        "{w2:?}"
    );
    assert!(
        stdout.contains("< 0: unstable")
            && stdout.contains(&format!("note       {} modes with ω² < 0", unstable.len())),
        "{stdout}"
    );
    // the same rod hanging (gravity along +x, tension) is stiffer than without gravity
    let hanging = rod_file(
        "modes-hanging",
        &ROD.replace("gravity = [0.0, 0.0, 0.0]", "gravity = [9.81, 0.0, 0.0]"),
    );
    let (_, hung) = modes_json("modes-hanging", &[s(&hanging), "--count", "1"]);
    assert!(hung["modes"][0]["frequency_hz"].as_f64().unwrap() > 0.177);
}

#[test]
fn a_pod_model_spanning_the_basis_has_the_full_models_frequencies() {
    // 40 single-tendon equilibria span the 33-DOF coefficient space, so POD with 33 modes is a
    // change of coordinates: same equilibrium, same frequencies (to the solver's tolerance).
    let ds = scratch("modes-ds");
    let ok = |args: &[&str]| {
        let out = gvsrom(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    ok(&[
        "dataset",
        "single-tendon",
        "--sweep",
        "tendons.0.tension=-6:3",
        "--samples",
        "40",
        "--out",
        s(&ds),
    ]);
    let pod = scratch("modes-pod33");
    ok(&["pod", s(&ds), "--modes", "33", "--out", s(&pod)]);
    let (_, hom) = modes_json("modes-hom", &["single-tendon", "--count", "6"]);
    let (stdout, rom) = modes_json(
        "modes-rom",
        &["single-tendon", "--count", "6", "--model", s(&pod)],
    );
    assert!(stdout.contains("reduced    pod model"), "{stdout}");
    assert_eq!(rom["model"].as_str(), Some(s(&pod)));
    for k in 0..6 {
        let (a, b) = (
            hom["modes"][k]["frequency_hz"].as_f64().unwrap(),
            rom["modes"][k]["frequency_hz"].as_f64().unwrap(),
        );
        assert!(rel(b, a) < 1e-6, "mode {k}: ROM {b} Hz vs HOM {a} Hz");
    }
}

#[test]
fn json_holds_the_shapes_with_the_manifest_and_is_never_overwritten_without_force() {
    let (_, json) = modes_json("modes-six", &["six-tendon", "--count", "3"]);
    assert_eq!(json["gvsrom"]["format"], "modes");
    let (n, np) = (
        json["n_dof"].as_u64().unwrap() as usize,
        json["n_points"].as_u64().unwrap() as usize,
    );
    assert_eq!((n, np), (28, 14));
    assert_eq!(json["all_frequencies_hz"].as_array().unwrap().len(), n);
    assert_eq!(json["strain_x"].as_array().unwrap().len(), np);
    let modes = json["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 3);
    for (k, m) in modes.iter().enumerate() {
        assert_eq!(m["mode"].as_u64(), Some(k as u64 + 1));
        assert_eq!(m["shape"].as_array().unwrap().len(), n);
        assert_eq!(m["strain"].as_array().unwrap().len(), np);
        assert_eq!(m["strain"][0].as_array().unwrap().len(), 6);
        let share: f64 = f64s(&m["strain_energy_share"]).iter().sum();
        assert!((share - 1.0).abs() < 1e-12);
        let f = m["frequency_hz"].as_f64().unwrap();
        assert!(rel(m["period_s"].as_f64().unwrap(), 1.0 / f) < 1e-12);
        // the centreline's modal displacement: zero at the clamp, the tip's (another path: the
        // tip Jacobian) at the last sample, L
        let shape = m["centerline_shape"].as_array().unwrap();
        assert_eq!(shape.len(), json["centerline_x"].as_array().unwrap().len());
        let (base, end, tip) = (
            f64s(&shape[0]),
            f64s(shape.last().unwrap()),
            f64s(&m["tip_displacement"]),
        );
        let scale = tip.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        for a in 0..3 {
            assert!(
                base[a].abs() <= 1e-12 * scale,
                "mode {k}: base moves {base:?}"
            );
            assert!(
                (end[a] - tip[a]).abs() <= 1e-12 * scale,
                "mode {k}: {end:?} vs {tip:?}"
            );
        }
    }
    assert_eq!(json["centerline"].as_array().unwrap().len(), 21);
    // a second run to the same file needs --force; a file gvsrom did not write is never replaced
    let file = scratch("modes-six.json");
    std::fs::write(&file, "{}").unwrap();
    expect_error(
        &["modes", "six-tendon", "--json", s(&file)],
        &["--json", "not a gvsrom output"],
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "{}");
    std::fs::remove_file(&file).unwrap();
    modes_json("modes-six", &["six-tendon", "--count", "1"]);
    expect_error(
        &["modes", "six-tendon", "--json", s(&file)],
        &["--json", "--force"],
    );
    assert!(
        gvsrom(&["modes", "six-tendon", "--json", s(&file), "--force"])
            .status
            .success()
    );
}

#[test]
fn bad_count_scenario_and_values_are_one_line_errors() {
    for bad in ["0", "-1", "2.5", "many"] {
        expect_error(
            &["modes", "six-tendon", "--count", bad],
            &[&format!("--count `{bad}`"), "integer ≥ 1", "28 DOF"],
        );
    }
    expect_error(
        &["modes", "two-tendon"],
        &[
            "two-tendon",
            "single-tendon, soft-beam, six-tendon, soft-beam-peak, six-tendon-no-gravity",
        ],
    );
    expect_error(
        &["modes", "six-tendon", "--set", "material.density=-1"],
        &["material.density", "-1"],
    );
    expect_error(&["modes", "six-tendon", "--tension=-1,0"], &["--tension"]);
    // above the DOF count: all modes, with a note
    let out = gvsrom(&["modes", "six-tendon", "--count", "100"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        stdout
            .contains("note       --count 100 exceeds the model's 28 DOF: reporting all 28 modes"),
        "{stdout}"
    );
    assert!(stdout.contains("\n  28  "), "{stdout}");
}

#[test]
fn the_undamped_modes_ignore_a_damping_a_motion_refuses() {
    // modes are undamped: a damping beyond what a motion accepts does not change them, and they
    // are computed (they were refused with the motion's bound); a simulation still refuses it
    let (_, plain) = modes_json("modes-damped-0", &["single-tendon", "--count", "3"]);
    let (_, heavy) = modes_json(
        "modes-damped-1e12",
        &[
            "single-tendon",
            "--count",
            "3",
            "--set",
            "material.damping=1e12",
        ],
    );
    let bending = frequencies_of(&plain, "bend_y");
    assert!(!bending.is_empty(), "{plain}");
    assert_eq!(bending, frequencies_of(&heavy, "bend_y"));
    let out = scratch("modes-damped-sim");
    expect_error(
        &[
            "simulate",
            "single-tendon",
            "--set",
            "material.damping=1e12",
            "--duration",
            "0.01",
            "--out",
            s(&out),
        ],
        &["material.damping", "in a motion"],
    );
}
