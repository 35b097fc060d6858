//! Rectangular and elliptical sections (`divisions[j].section`) and circular tubes
//! (`inner_radius`) against the closed forms of a slender cantilever: tip deflections under a small tip force along each section axis
//! (`FL³/3EI + FL/GA`, shear factor 1 as the model's), the twist under a tip torque (`TL/GJ_t`,
//! the Saint-Venant torsion constant, not the polar moment), and the vibration frequencies —
//! Euler–Bernoulli bending about each axis and the fixed-free shaft's torsion
//! `ω = (π/2L) √(G J_t / (ρ I_p))`, whose rotary inertia is the polar moment.

mod common;

use common::{expect_error, f64s, run_json, s as path_str, scratch};
use std::f64::consts::PI;

const E: f64 = 1e6;
const G: f64 = E / 3.0; // ν = 1/2
const RHO: f64 = 1000.0;
const L: f64 = 0.5;
/// The tip force and torque: small enough for linear theory (tip deflection ≈ 3e-5 L).
const F: f64 = 1e-6;
const T: f64 = 1e-7;

fn scenario(name: &str, section: &str, order: usize) -> std::path::PathBuf {
    let path = scratch(&format!("{name}.toml"));
    let toml = format!(
        r#"name = "{name}"
[material]
youngs_modulus = {E}
poisson_ratio = 0.5
density = {RHO}
damping = 1e4

[[divisions]]
length = {L}
{section}
basis = {{ kind = "legendre", modes = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = {order} }}

[loads]
gravity = [0.0, 0.0, 0.0]

[[loads.point]]
x = {L}
force = [0.0, {F}, {F}]
moment = [{T}, 0.0, 0.0]
frame = "global"
"#
    );
    std::fs::write(&path, toml).unwrap();
    path
}

/// [`scenario`] `name` of `section` (order 4) with a tendon of `tendon`'s keys (tension −1e-4 N).
fn with_tendon(name: &str, section: &str, tendon: &str) -> std::path::PathBuf {
    let path = scenario(name, section, 4);
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str(&format!("\n[[tendons]]\ntension = -1e-4\n{tendon}\n"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Each `(section, needles)`: `gvsrom check` of [`scenario`] `{prefix}-{i}` fails naming them.
fn expect_section_errors(prefix: &str, cases: &[(&str, &[&str])]) {
    for (i, (section, needles)) in cases.iter().enumerate() {
        let toml = scenario(&format!("{prefix}-{i}"), section, 4);
        expect_error(&["check", path_str(&toml)], needles);
    }
}

/// `(A, I_y = ∫z² dA, I_z = ∫y² dA, J_t)` of the section, from the textbook formulas (the
/// rectangle's torsion constant from Timoshenko & Goodier's series, written out here again).
struct Moments {
    a: f64,
    iy: f64,
    iz: f64,
    jt: f64,
}

fn rectangle(w: f64, h: f64) -> Moments {
    let (a, b) = (w.max(h), w.min(h));
    let sum: f64 = (0..200)
        .map(|i| (2 * i + 1) as f64)
        .map(|n| (n * PI * a / (2.0 * b)).tanh() / n.powi(5))
        .sum();
    Moments {
        a: w * h,
        iy: w * h.powi(3) / 12.0,
        iz: h * w.powi(3) / 12.0,
        jt: a * b.powi(3) * (1.0 / 3.0 - 64.0 / PI.powi(5) * b / a * sum),
    }
}

fn ellipse(w: f64, h: f64) -> Moments {
    let (a, b) = (w / 2.0, h / 2.0);
    Moments {
        a: PI * a * b,
        iy: PI * a * b.powi(3) / 4.0,
        iz: PI * a.powi(3) * b / 4.0,
        jt: PI * a.powi(3) * b.powi(3) / (a * a + b * b),
    }
}

/// A circular tube of outer radius `r` and inner radius `r_i`: `A = π(r² − r_i²)`,
/// `I = π(r⁴ − r_i⁴)/4`, `J_t = 2I`.
fn tube(r: f64, r_i: f64) -> Moments {
    let i = PI * (r.powi(4) - r_i.powi(4)) / 4.0;
    Moments {
        a: PI * (r * r - r_i * r_i),
        iy: i,
        iz: i,
        jt: 2.0 * i,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// The tip of the cantilever of `section` under the tip force `[0, F, F]` and torque `T` about
/// x: its deflections along z and y and its twist against the closed forms.
fn check_statics(name: &str, shape: &str, section: &str, m: &Moments) {
    let toml = scenario(name, section, 4);
    let (stdout, eq) = run_json("statics", name, &[path_str(&toml)]);
    let tip = f64s(&eq["tip_position"]);
    let r = &eq["tip_rotation"];
    let twist = r[2][1].as_f64().unwrap();
    let shear = F * L / (G * m.a);
    let z = F * L.powi(3) / (3.0 * E * m.iy) + shear;
    let y = F * L.powi(3) / (3.0 * E * m.iz) + shear;
    assert!(
        rel(tip[2], z) < 1e-4,
        "{name}: tip z {} against {z}",
        tip[2]
    );
    assert!(
        rel(tip[1], y) < 2e-4,
        "{name}: tip y {} against {y}",
        tip[1]
    );
    let phi = T * L / (G * m.jt);
    assert!(
        rel(twist, phi) < 2e-4,
        "{name}: twist {twist} against {phi}"
    );
    let described = format!("0.5 m uniform {shape} rod");
    assert!(stdout.contains(&described), "{stdout}");
}

#[test]
fn a_rectangular_cantilever_bends_about_each_axis_and_twists_as_its_closed_forms() {
    let m = rectangle(0.03, 0.01);
    check_statics(
        "rect-statics",
        "rectangular",
        "section = \"rectangle\"\nwidth = 0.03\nheight = 0.01",
        &m,
    );
}

#[test]
fn an_elliptical_cantilever_bends_about_each_axis_and_twists_as_its_closed_forms() {
    let m = ellipse(0.01, 0.03);
    check_statics(
        "ellipse-statics",
        "elliptical",
        "section = \"ellipse\"\nwidth = 0.01\nheight = 0.03",
        &m,
    );
}

/// The modes of the rectangular cantilever: the first bending mode about each axis
/// (Euler–Bernoulli, `β₁L = 1.8751`; the model is a Timoshenko rod, lower by its rotary inertia
/// and shear: 3e-4 for the thin side, 3e-3 for the wide one at w/L = 0.06) and the first
/// torsional one, which only a torsion constant in the stiffness and the polar moment in the
/// inertia give (SoRoSim's polar moment in both would put it 1.78× higher here).
#[test]
fn a_rectangular_cantilever_vibrates_at_its_bending_and_torsion_frequencies() {
    let (w, h) = (0.03, 0.01);
    let m = rectangle(w, h);
    let toml = scenario(
        "rect-modes",
        "section = \"rectangle\"\nwidth = 0.03\nheight = 0.01",
        8,
    );
    let (_, modes) = run_json("modes", "rect-modes", &[path_str(&toml), "--count", "8"]);
    let list = modes["modes"].as_array().unwrap();
    let freq = |energy: &str, nth: usize| {
        list.iter()
            .filter(|m| m["dominant_strain"].as_str() == Some(energy))
            .map(|m| m["frequency_hz"].as_f64().unwrap())
            .nth(nth)
            .unwrap_or_else(|| panic!("no mode {nth} of {energy} in {list:?}"))
    };
    let bend =
        |i: f64| 1.875_104_068_7f64.powi(2) / (2.0 * PI) * (E * i / (RHO * m.a * L.powi(4))).sqrt();
    let (fy, fz) = (freq("bend_y", 0), freq("bend_z", 0));
    assert!(
        rel(fy, bend(m.iy)) < 1e-3,
        "bend_y {fy} against {}",
        bend(m.iy)
    );
    assert!(
        rel(fz, bend(m.iz)) < 5e-3,
        "bend_z {fz} against {}",
        bend(m.iz)
    );
    let torsion = (PI / (2.0 * L)) * (G * m.jt / (RHO * (m.iy + m.iz))).sqrt() / (2.0 * PI);
    let ft = freq("torsion", 0);
    assert!(rel(ft, torsion) < 1e-4, "torsion {ft} against {torsion}");
    let polar = torsion * ((m.iy + m.iz) / m.jt).sqrt();
    assert!(
        polar > 1.7 * ft,
        "the torsion constant, not the polar moment: {ft} vs {polar}"
    );
}

/// What a section takes and refuses, naming the field; a tendon placed by angle sits on the
/// section's surface, and one outside the rectangle is refused.
#[test]
fn sections_are_checked_and_hold_their_tendons() {
    let cases: [(&str, &[&str]); 5] = [
        (
            "section = \"rectangle\"\nwidth = 0.03",
            &["divisions[0].height", "missing", "width", "height"],
        ),
        (
            "section = \"rectangle\"\nradius = 0.01\nwidth = 0.03\nheight = 0.01",
            &["divisions[0].radius", "no radius"],
        ),
        (
            "radius = 0.01\nwidth = 0.03",
            &["divisions[0].width", "a circular section has a radius"],
        ),
        (
            "section = \"ellipse\"\nwidth_start = 0.03\nheight = 0.01",
            &["divisions[0].width_end", "missing"],
        ),
        (
            "section = \"square\"\nwidth = 0.03\nheight = 0.01",
            &["section", "square"],
        ),
    ];
    expect_section_errors("bad-section", &cases);
    let tendon = |name: &str, tendon: &str| {
        with_tendon(
            name,
            "section = \"rectangle\"\nwidth = 0.03\nheight = 0.01",
            tendon,
        )
    };
    // at 90° on the surface: the rectangle's half height, not its circumscribed radius
    let on_top = tendon("rect-tendon-top", "angle_deg = 90.0");
    let (_, eq) = run_json("statics", "rect-tendon-top", &[path_str(&on_top)]);
    let start = &eq["tendon_paths"][0][0];
    let z = start[2].as_f64().unwrap();
    assert!((z - 0.005).abs() < 1e-15, "{start}");
    // at 45°: the ray meets the short side first
    let oblique = tendon("rect-tendon-45", "angle_deg = 45.0");
    let (_, eq) = run_json("statics", "rect-tendon-45", &[path_str(&oblique)]);
    let start = f64s(&eq["tendon_paths"][0][0]);
    assert!(
        (start[1] - 0.005).abs() < 1e-15 && (start[2] - 0.005).abs() < 1e-15,
        "{start:?}"
    );
    // inside the circumscribed circle but above the rectangle
    let outside = tendon(
        "rect-tendon-out",
        "offset_start = [0.0, 0.006]\noffset_end = [0.0, 0.004]",
    );
    expect_error(
        &["check", path_str(&outside)],
        &[
            "tendons[0].offset_start",
            "leaves the cross-section at X = 0 m",
            "0.03 × 0.01 m rectangle",
        ],
    );
    // a helix of 14 mm radius leaves the 10 mm height however its turns fall on the samples
    // (16 per division's 32: commensurate), and the error names where it reaches farthest
    for turns in ["1.0", "16.0", "32.0", "-16.0"] {
        let helix = tendon(
            &format!("rect-tendon-helix-{turns}"),
            &format!("offset_start = [0.014, 0.0]\noffset_end = [0.014, 0.0]\nturns = {turns}"),
        );
        expect_error(
            &["check", path_str(&helix)],
            &[
                "tendons[0].offset_end",
                "leaves the cross-section",
                "where the path reaches farthest",
                "rectangle",
            ],
        );
    }
    // one of 4 mm fits at any number of turns
    let fits = tendon(
        "rect-tendon-helix-fits",
        "offset_start = [0.004, 0.0]\noffset_end = [0.004, 0.0]\nturns = 16.0",
    );
    common::run_ok(&["check", path_str(&fits)]);
}

/// `--set divisions.j.section=…` replaces the section a preset describes: a rectangle drops the
/// circle's radius (else every preset would refuse the new shape for its radius), and the record
/// of the run holds the rectangle alone.
#[test]
fn a_preset_takes_another_section_by_overrides() {
    let (stdout, eq) = run_json(
        "statics",
        "soft-beam-rectangle",
        &[
            "soft-beam",
            "--set",
            "divisions.0.section=rectangle",
            "--set",
            "divisions.0.width=0.03",
            "--set",
            "divisions.0.height=0.02",
        ],
    );
    assert!(stdout.contains("0.8 m uniform rectangular rod"), "{stdout}");
    let toml = eq["provenance"]["scenario_toml"].as_str().unwrap();
    assert!(
        toml.contains("section = \"rectangle\"") && !toml.contains("radius"),
        "{toml}"
    );
    // back to a circle: the widths are dropped, and the radius is then missing
    expect_error(
        &[
            "check",
            "soft-beam",
            "--set",
            "divisions.0.section=ellipse",
            "--set",
            "divisions.0.width=0.03",
            "--set",
            "divisions.0.height=0.02",
            "--set",
            "divisions.0.section=circle",
        ],
        &["divisions[0].radius", "missing"],
    );
}

#[test]
fn a_tubular_cantilever_bends_and_twists_as_its_closed_forms() {
    check_statics(
        "tube-statics",
        "tubular",
        "radius = 0.01\ninner_radius = 0.008",
        &tube(0.01, 0.008),
    );
}

/// The tube's modes: its first bending frequency `(β₁L)² √(EI/(ρAL⁴))` rises above the solid
/// rod's by `√((r² + r_i²)/r²)` (the bore takes more mass than stiffness: 1.28× here), and its first
/// torsional one `(π/2L) √(G/ρ)` is the solid rod's (stiffness and rotary inertia both scale
/// with the polar moment).
#[test]
fn a_tubular_cantilever_vibrates_at_its_bending_and_torsion_frequencies() {
    let (r, r_i) = (0.01, 0.008);
    let m = tube(r, r_i);
    let toml = scenario("tube-modes", "radius = 0.01\ninner_radius = 0.008", 8);
    let (_, modes) = run_json("modes", "tube-modes", &[path_str(&toml), "--count", "8"]);
    let list = modes["modes"].as_array().unwrap();
    let freq = |energy: &str| {
        list.iter()
            .find(|m| m["dominant_strain"].as_str() == Some(energy))
            .map(|m| m["frequency_hz"].as_f64().unwrap())
            .unwrap_or_else(|| panic!("no {energy} mode in {list:?}"))
    };
    let bend =
        1.875_104_068_7f64.powi(2) / (2.0 * PI) * (E * m.iy / (RHO * m.a * L.powi(4))).sqrt();
    // the model is a Timoshenko rod: below Euler–Bernoulli by its rotary inertia and shear,
    // 1.5e-3 at this radius of gyration (k/L = 0.013; 3e-3 for the rectangle's wide side above)
    for axis in ["bend_y", "bend_z"] {
        let f = freq(axis);
        assert!(f < bend && rel(f, bend) < 3e-3, "{axis} {f} against {bend}");
    }
    let torsion = (PI / (2.0 * L)) * (G / RHO).sqrt() / (2.0 * PI);
    let ft = freq("torsion");
    assert!(rel(ft, torsion) < 1e-4, "torsion {ft} against {torsion}");
    // against the solid rod of the same radius, computed too: bending 1.28× faster (the
    // Timoshenko corrections of the two nearly cancel in the ratio), torsion the same
    let solid = scenario("tube-modes-solid", "radius = 0.01", 8);
    let (_, modes) = run_json(
        "modes",
        "tube-modes-solid",
        &[path_str(&solid), "--count", "8"],
    );
    let solid_list = modes["modes"].as_array().unwrap();
    let solid_freq = |energy: &str| {
        (solid_list.iter())
            .find(|m| m["dominant_strain"].as_str() == Some(energy))
            .map(|m| m["frequency_hz"].as_f64().unwrap())
            .unwrap()
    };
    let ratio = freq("bend_y") / solid_freq("bend_y");
    let expected = ((r * r + r_i * r_i) / (r * r)).sqrt();
    assert!(
        rel(ratio, expected) < 2e-3,
        "bending {ratio} against {expected}"
    );
    assert!(
        rel(ft, solid_freq("torsion")) < 1e-6,
        "torsion {ft} against the solid rod's"
    );
}

/// A tube's bore: refused outside its outer radius, in a rectangle, negative, half tapered; a
/// tendon may run through it; `--set divisions.0.section=rectangle` drops it with the radii.
#[test]
fn a_tube_is_checked_and_a_preset_takes_one_by_overrides() {
    let cases: [(&str, &[&str]); 5] = [
        (
            "radius = 0.01\ninner_radius = 0.01",
            &[
                "divisions[0].inner_radius",
                "0.01",
                "[0, 0.0099999] m: a wall of at least 1e-7 m inside `radius` = 0.01 m",
            ],
        ),
        (
            "radius_start = 0.01\nradius_end = 0.005\ninner_radius_start = 0.004\ninner_radius_end = 0.006",
            &[
                "divisions[0].inner_radius_end",
                "0.006",
                "[0, 0.0049999] m: a wall of at least 1e-7 m inside the outer radius 0.005 m at the division's end",
            ],
        ),
        (
            "radius = 0.01\ninner_radius = -0.001",
            &["divisions[0].inner_radius", "-0.001", ">= 0"],
        ),
        (
            "section = \"rectangle\"\nwidth = 0.03\nheight = 0.01\ninner_radius = 0.002",
            &["divisions[0].inner_radius", "a rectangle is solid"],
        ),
        (
            "radius = 0.01\ninner_radius_start = 0.002",
            &["divisions[0].inner_radius_end", "missing"],
        ),
    ];
    expect_section_errors("bad-tube", &cases);
    // a tendon through the bore (on spacer discs) is inside the section
    let path = with_tendon(
        "tube-tendon-bore",
        "radius = 0.01\ninner_radius = 0.008",
        "offset_start = [0.0, 0.004]\noffset_end = [0.0, 0.004]",
    );
    common::run_ok(&["check", path_str(&path)]);
    // a preset's circle becomes a tube, written in the record; an override of the shape drops it
    let (stdout, eq) = run_json(
        "statics",
        "soft-beam-tube",
        &["soft-beam", "--set", "divisions.0.inner_radius=0.005"],
    );
    assert!(stdout.contains("0.8 m uniform tubular rod"), "{stdout}");
    let toml = eq["provenance"]["scenario_toml"].as_str().unwrap();
    assert!(toml.contains("inner_radius = 0.005"), "{toml}");
    let (stdout, eq) = run_json(
        "statics",
        "soft-beam-tube-to-rectangle",
        &[
            "soft-beam",
            "--set",
            "divisions.0.inner_radius=0.005",
            "--set",
            "divisions.0.section=rectangle",
            "--set",
            "divisions.0.width=0.03",
            "--set",
            "divisions.0.height=0.02",
        ],
    );
    assert!(stdout.contains("0.8 m uniform rectangular rod"), "{stdout}");
    let toml = eq["provenance"]["scenario_toml"].as_str().unwrap();
    assert!(!toml.contains("radius"), "{toml}");
}
