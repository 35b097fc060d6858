//! Scenario files → engine: closed-form statics (gvs-spec §10.3) reached through the TOML format, so
//! the conversions of point and distributed loads, frames, base pose and quadrature defaults are
//! checked against physics rather than against the code.

use gvsrom::presets;
use gvsrom::statics::{solve, StaticsReport};
use gvsrom::Scenario;

/// A uniform rod, r = 0.01 m, L = 0.5 m, E = 1e6, no gravity (gvs-spec §10.3 prototype data).
const UNIFORM_ROD: &str = r#"
    name = "uniform"
    [material]
    youngs_modulus = 1e6
    poisson_ratio = 0.5
    density = 1000
    [[divisions]]
    length = 0.5
    radius = 0.01
    basis = { kind = "legendre", modes = ["bend_y", "elongation", "shear_z"], order = 2 }
    [loads]
    gravity = [0, 0, 0]
"#;

fn run_text(text: &str, overrides: &[&str]) -> StaticsReport {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let s = Scenario::from_toml("test", text, &overrides).expect("scenario parses");
    solve(&gvsrom::build(&s).expect("scenario builds")).expect("statics converges")
}

fn run_preset(name: &str, overrides: &[&str]) -> StaticsReport {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let s = presets::load(name, &overrides).expect("preset loads");
    solve(&gvsrom::build(&s).expect("preset builds")).expect("statics converges")
}

#[test]
fn pure_end_moment_bends_rod_into_exact_circle() {
    // κ = M/EI; tip = (sin κL/κ, 0, −(1 − cos κL)/κ)   (gvs-spec §10.3.1), M = 0.01 N·m about local y
    let ei = 1e6 * std::f64::consts::PI * 0.01f64.powi(4) / 4.0;
    let kappa = 0.01 / ei;
    let expected = [
        (kappa * 0.5).sin() / kappa,
        0.0,
        -(1.0 - (kappa * 0.5).cos()) / kappa,
    ];
    for frame in ["local", "global"] {
        let r = run_text(
            UNIFORM_ROD,
            &[
                "loads.point.0.x=0.5",
                "loads.point.0.moment=[0, 0.01, 0]",
                &format!("loads.point.0.frame={frame}"),
            ],
        );
        for i in 0..3 {
            // exact up to the solver tolerance (‖R‖∞ ≤ 1e-10 relative)
            assert!(
                (r.tip_position[i] - expected[i]).abs() < 1e-9,
                "{frame}: {:?} vs {expected:?}",
                r.tip_position
            );
        }
    }
}

#[test]
fn small_global_tip_force_gives_timoshenko_deflection() {
    // δ = PL³/(3EI) + PL/(GA), shear factor 1 (gvs-spec §10.3.2): −5.309939e-4 m for P = 1e-4 N
    let r = run_text(
        UNIFORM_ROD,
        &[
            "loads.point.0.x=0.5",
            "loads.point.0.force=[0, 0, -1e-4]",
            "loads.point.0.frame=\"global\"",
        ],
    );
    let (a, i) = (
        std::f64::consts::PI * 1e-4,
        std::f64::consts::PI * 1e-8 / 4.0,
    );
    let (e, g) = (1e6, 1e6 / 3.0);
    let delta = -(1e-4 * 0.125 / (3.0 * e * i) + 1e-4 * 0.5 / (g * a));
    // geometric nonlinearity is relative O((δ/L)²) ≈ 1e-6, i.e. ≈ 5e-10 m; order 2 and 5 Gauss
    // points integrate the linear moment and constant shear of this load exactly
    assert!(
        (r.tip_position[2] - delta).abs() < 5e-9,
        "{} vs {delta}",
        r.tip_position[2]
    );
    assert_eq!(r.strain_x.iter().filter(|&&x| x == 0.5).count(), 1);
}

#[test]
fn uniform_distributed_force_matches_gravity_of_same_weight() {
    // ρ A g as a world-fixed uniform force density is gravity itself
    let w = 1000.0 * std::f64::consts::PI * 1e-4 * 9.81;
    let g = run_text(UNIFORM_ROD, &["loads.gravity=[0, 0, -9.81]"]);
    let d = run_text(
        UNIFORM_ROD,
        &[
            "loads.distributed.0.kind=uniform",
            &format!("loads.distributed.0.force=[0, 0, {}]", -w),
            "loads.distributed.0.frame=global",
        ],
    );
    for i in 0..3 {
        assert!((g.tip_position[i] - d.tip_position[i]).abs() < 1e-12);
    }
}

#[test]
fn pulse_total_convention_equals_peak_of_twice_the_mean() {
    // total = peak · w/2: 4 N·m/m peak over w = 0.08 m is 0.16 N·m in total
    let peak = run_preset("soft-beam-peak", &[]);
    let total = run_preset(
        "soft-beam-peak",
        &[
            "loads.distributed.0.magnitude=0.16",
            "loads.distributed.0.convention=total",
        ],
    );
    for i in 0..3 {
        assert!((peak.tip_position[i] - total.tip_position[i]).abs() < 1e-12);
    }
}

#[test]
fn rotating_the_base_rotates_the_equilibrium() {
    // no gravity: a rigid motion of the base moves the whole solution with it
    let a = run_preset("six-tendon-no-gravity", &["tendons.1.tension=-4"]);
    let b = run_preset(
        "six-tendon-no-gravity",
        &[
            "tendons.1.tension=-4",
            "base.axis=[1, 1, 0]",
            "base.angle_deg=30",
            "base.position=[0.1, -0.2, 0.3]",
        ],
    );
    let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(1.0, 1.0, 0.0));
    let rot = nalgebra::Rotation3::from_axis_angle(&axis, 30f64.to_radians());
    let p = rot * nalgebra::Vector3::from_row_slice(&a.tip_position)
        + nalgebra::Vector3::new(0.1, -0.2, 0.3);
    for i in 0..3 {
        assert!(
            (p[i] - b.tip_position[i]).abs() < 1e-9,
            "{p:?} vs {:?}",
            b.tip_position
        );
    }
    // the same rotation given as a matrix
    let m = rot.matrix();
    let rows = format!(
        "base.rotation=[[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]]",
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)]
    );
    let c = run_preset(
        "six-tendon-no-gravity",
        &[
            "tendons.1.tension=-4",
            &rows,
            "base.position=[0.1, -0.2, 0.3]",
        ],
    );
    for i in 0..3 {
        assert!((c.tip_position[i] - b.tip_position[i]).abs() < 1e-12);
    }
}

#[test]
fn a_quadrature_that_does_not_resolve_the_basis_is_refused() {
    // fewer points than functions per strain make the stiffness singular (gvs's
    // `stiffness_is_singular_with_fewer_gauss_points_than_legendre_functions`), and FEM points
    // that miss a combination of the functions nearly so: refused, naming the field and what is
    // accepted; one more point, or points that resolve the basis, are accepted
    let build = |overrides: &[&str]| {
        let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        gvsrom::build(&Scenario::from_toml("t", UNIFORM_ROD, &o).unwrap())
    };
    let fem = |degree: &str| {
        format!("divisions.0.basis={{ kind = \"fem\", modes = [\"bend_y\"], elements = 4, degree = \"{degree}\" }}")
    };
    let cases: [(Vec<String>, &str, &str); 7] = [
        (
            vec![
                "divisions.0.basis.order=10".into(),
                "divisions.0.quadrature={gauss=10}".into(),
            ],
            "divisions[0].quadrature.gauss",
            "at least 11",
        ),
        (
            vec![
                "divisions.0.basis.order=10".into(),
                "divisions.0.quadrature={gauss_per_element=2, elements=5}".into(),
            ],
            "divisions[0].quadrature.gauss_per_element",
            "at least 11",
        ),
        (
            vec![
                fem("linear"),
                "divisions.0.quadrature={gauss_per_element=1}".into(),
            ],
            "divisions[0].quadrature`",
            "`gauss_per_element` ≥ 2",
        ),
        (
            vec![
                fem("quadratic"),
                "divisions.0.quadrature={gauss_per_element=2}".into(),
            ],
            "divisions[0].quadrature`",
            "`gauss_per_element` ≥ 3",
        ),
        // enough points in all, but not where the functions are: a 10-element basis on 5
        // quadrature elements (2 points per pair of its elements), or 12 Gauss points over the
        // division (a combination of the 11 functions keeps 3e-7 of its stiffness): each once gave
        // an equilibrium with the tip a rod's length off
        (
            vec![
                fem("linear").replace("elements = 4", "elements = 10"),
                "divisions.0.quadrature={gauss_per_element=2, elements=5}".into(),
            ],
            "divisions[0].quadrature`",
            "`elements` = 10 (the basis's)",
        ),
        (
            vec![
                fem("linear").replace("elements = 4", "elements = 10"),
                "divisions.0.quadrature={gauss=12}".into(),
            ],
            "divisions[0].quadrature`",
            "`elements` = 10 (the basis's)",
        ),
        (
            vec![
                fem("quadratic").replace("elements = 4", "elements = 10"),
                "divisions.0.quadrature={gauss=25}".into(),
            ],
            "divisions[0].quadrature`",
            "`gauss_per_element` ≥ 3",
        ),
    ];
    for (overrides, field, accepted) in cases {
        let o: Vec<&str> = overrides.iter().map(String::as_str).collect();
        let e = build(&o).err().expect("refused").to_string();
        assert!(
            e.contains(field) && e.contains(accepted) && e.contains("zero-energy"),
            "{e}"
        );
    }
    for ok in [
        vec![
            "divisions.0.basis.order=10".to_string(),
            "divisions.0.quadrature={gauss=11}".into(),
        ],
        vec![
            "divisions.0.basis.order=10".into(),
            "divisions.0.quadrature={gauss_per_element=3, elements=4}".into(),
        ],
        vec![
            fem("linear"),
            "divisions.0.quadrature={gauss_per_element=2}".into(),
        ],
        vec![
            fem("quadratic"),
            "divisions.0.quadrature={gauss_per_element=3}".into(),
        ],
        // quadrature elements that straddle the basis's, or Gauss points over the division,
        // that resolve it (every combination keeps 85 % and 35 % of its stiffness)
        vec![
            fem("linear").replace("elements = 4", "elements = 10"),
            "divisions.0.quadrature={gauss_per_element=3, elements=7}".into(),
        ],
        vec![
            fem("linear").replace("elements = 4", "elements = 10"),
            "divisions.0.quadrature={gauss=16}".into(),
        ],
    ] {
        let o: Vec<&str> = ok.iter().map(String::as_str).collect();
        assert!(build(&o).is_ok(), "{ok:?}");
    }
}

#[test]
fn quadrature_defaults_follow_sorosim_up_to_order_3() {
    // Legendre order 2 → max(2 + 1, 5) = 5 Gauss points + 2 ends; order 3 → 5 + 2 as well;
    // above order 3, 3(p + 1) (order 10: 33 + 2), what the Z4 kinematics needs; FEM linear → 2
    // per element
    let points = |order: &str| {
        let s = Scenario::from_toml("t", UNIFORM_ROD, &[order.into()]).unwrap();
        gvsrom::build(&s).unwrap().model.disc.n_points()
    };
    assert_eq!(points("divisions.0.basis.order=2"), 7);
    assert_eq!(points("divisions.0.basis.order=3"), 7);
    assert_eq!(points("divisions.0.basis.order=4"), 17);
    assert_eq!(points("divisions.0.basis.order=10"), 35);
    let s = Scenario::from_toml(
        "t",
        UNIFORM_ROD,
        &["divisions.0.basis={ kind = \"fem\", modes = [\"bend_y\"], elements = 4 }".into()],
    )
    .unwrap();
    let b = gvsrom::build(&s).unwrap();
    assert_eq!(b.model.disc.n_points(), 4 * 3 + 1);
    assert_eq!(b.model.n_dof(), 5);
}

#[test]
fn a_tendon_given_both_ways_names_the_polar_key_it_was_given() {
    // `single-tendon` gives offset_start/offset_end; the conflict names the key the user added
    for (key, set) in [
        ("radial_fraction", "tendons.0.radial_fraction=0.5"),
        ("angle_deg", "tendons.0.angle_deg=30"),
    ] {
        let s = presets::load("single-tendon", &[set.to_string()]).expect("preset loads");
        let e = gvsrom::build(&s).err().expect("refused").to_string();
        assert!(
            e.contains(&format!("tendons[0].{key}")) && e.contains("not both"),
            "{set}: {e}"
        );
    }
}

#[test]
fn a_helical_tendon_twists_the_rod_and_too_many_turns_are_refused() {
    // the uniform rod with a surface tendon of one turn: pulling it twists the rod, which the
    // oblique routing (turns = 0) does not
    let tendon = r#"
    [[tendons]]
    angle_deg = 90
    radial_fraction = 0.6
    tension = -0.002
    "#;
    let text = format!("{UNIFORM_ROD}{tendon}").replace(
        r#"modes = ["bend_y", "elongation", "shear_z"], order = 2"#,
        r#"modes = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 6"#,
    );
    let twist = |turns: &str| {
        let r = run_text(&text, &[&format!("tendons.0.turns={turns}")]);
        r.strain.iter().map(|xi| xi[0].abs()).fold(0.0, f64::max)
    };
    assert!(twist("1") > 1e-4, "twist {}", twist("1"));
    assert!(twist("0") < 1e-12, "twist {}", twist("0"));
    let s = Scenario::from_toml("t", &text, &["tendons.0.turns=1e3".into()]).unwrap();
    let e = gvsrom::build(&s).err().expect("refused").to_string();
    assert!(
        e.contains("tendons[0].turns") && e.contains("[-100, 100]"),
        "{e}"
    );
}

#[test]
fn a_tendon_loading_components_the_basis_lacks_is_named() {
    let warnings = |set: &[&str]| {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let s = presets::load("single-tendon", &set).expect("preset loads");
        gvsrom::build::uncovered_tendon_components(&gvsrom::build(&s).unwrap().model)
    };
    // the preset's tendon lies in the x-z plane of its planar basis
    assert!(warnings(&[]).is_empty());
    // moved sideways it bends the rod out of that plane too
    let w = warnings(&["tendons.0.offset_start=[0.004, 0.008]"]);
    assert_eq!(w.len(), 1);
    assert!(
        w[0].starts_with("tendons[0] also loads torsion, bend_z, shear_y,"),
        "{w:?}"
    );
    // helical: the same; with every mode in the basis nothing is dropped
    assert_eq!(warnings(&["tendons.0.turns=0.5"]), w);
    let all = r#"divisions.0.basis.modes=["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"]"#;
    assert!(warnings(&["tendons.0.turns=0.5", "divisions.0.basis.order=4", all]).is_empty());
    // divisions lacking different components are named each with its own (the six-tendon arm's
    // tendon 0 on the surface at 0°, tapered: bend_z, elongation and shear_y at rest)
    let set: Vec<String> = [
        r#"divisions.0.basis.modes=["torsion", "bend_y", "bend_z", "elongation", "shear_z"]"#,
        r#"divisions.1.basis.modes=["torsion", "bend_y", "bend_z", "shear_z"]"#,
    ]
    .map(String::from)
    .to_vec();
    let s = presets::load("six-tendon", &set).expect("preset loads");
    let w = gvsrom::build::uncovered_tendon_components(&gvsrom::build(&s).unwrap().model);
    assert!(
        w[0].starts_with(
            "tendons[0] also loads shear_y in division 0; elongation, shear_y in division 1, which those bases lack"
        ),
        "{w:?}"
    );
}

#[test]
fn a_tendon_ending_inside_a_division_is_named_with_the_split() {
    let warnings = |set: &[&str]| {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let s = presets::load("single-tendon", &set).expect("preset loads");
        gvsrom::build::model_warnings(&gvsrom::build(&s).unwrap().model)
    };
    // the preset's tendon spans its one division
    assert!(warnings(&[]).is_empty());
    let w = warnings(&["tendons.0.x_start=0.05", "tendons.0.x_end=0.1"]);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].starts_with("tendons[0].x_start = 0.05 m lies inside divisions[0] ([0, 0.25] m)")
            && w[0].contains("lengths 0.05 and 0.2 m"),
        "{w:?}"
    );
    assert!(
        w[1].starts_with("tendons[0].x_end = 0.1 m lies inside divisions[0]")
            && w[1].contains(
                "split the division at 0.1 m (two [[divisions]] of lengths 0.1 and 0.15 m)"
            ),
        "{w:?}"
    );
}

#[test]
fn a_precurved_division_rests_on_its_arc_and_is_bounded() {
    // reference_strain bends the unloaded rod into the arc of curvature κ*: tip (sin κL/κ, 0,
    // −(1 − cos κL)/κ) for a curvature about y (gvs-spec §10.3.1's circle, here with no load)
    let kappa: f64 = 4.0;
    let r = run_text(
        UNIFORM_ROD,
        &[&format!(
            "divisions.0.reference_strain=[0, {kappa}, 0, 1, 0, 0]"
        )],
    );
    let l = 0.5;
    let exact = [
        (kappa * l).sin() / kappa,
        0.0,
        -(1.0 - (kappa * l).cos()) / kappa,
    ];
    for (a, b) in r.tip_position.iter().zip(exact) {
        assert!(
            (a - b).abs() < 1e-12,
            "tip {:?} vs {exact:?}",
            r.tip_position
        );
    }
    assert!(r.q.iter().all(|v| v.abs() < 1e-14));
    // the report records ξ* at every point, and the strain equals it
    assert_eq!(r.strain_reference.len(), r.strain.len());
    for (xi, star) in r.strain.iter().zip(&r.strain_reference) {
        assert_eq!(*star, [0.0, kappa, 0.0, 1.0, 0.0, 0.0]);
        assert!(xi.iter().zip(star).all(|(a, b)| (a - b).abs() < 1e-12));
    }
    // out-of-range values name their entry
    for (set, field) in [
        ("[0, 0, 0, 0, 0, 0]", "reference_strain[3]"),
        ("[0, 0, 0, 1e-300, 0, 0]", "reference_strain[3]"),
        ("[0, 0, 0, 0.09, 0, 0]", "reference_strain[3]"),
        ("[0, 1000, 0, 1, 0, 0]", "reference_strain[1]"),
        ("[0, 0, 0, 1, 2, 0]", "reference_strain[4]"),
    ] {
        let s = Scenario::from_toml(
            "t",
            UNIFORM_ROD,
            &[format!("divisions.0.reference_strain={set}")],
        )
        .unwrap();
        let e = gvsrom::build(&s).err().expect("refused").to_string();
        assert!(e.contains(&format!("divisions[0].{field}")), "{set}: {e}");
    }
}

#[test]
fn a_tendon_on_a_custom_path_is_routed_through_its_knots() {
    let with = |routing: &str| format!("{UNIFORM_ROD}\n[[tendons]]\n{routing}\ntension = -0.5\n");
    let tip = |routing: &str| run_text(&with(routing), &[]).tip_position;
    let oblique = tip("offset_start = [0.0, 0.004]\noffset_end = [0.0, 0.001]");
    // two knots, or uneven knots on the same line, are the oblique tendon
    for path in [
        "path = [[0.0, 0.0, 0.004], [0.5, 0.0, 0.001]]",
        "path = [[0.0, 0.0, 0.004], [0.1, 0.0, 0.0034], [0.4, 0.0, 0.0016], [0.5, 0.0, 0.001]]",
    ] {
        let t = tip(path);
        for (a, b) in t.iter().zip(&oblique) {
            assert!((a - b).abs() < 1e-14, "{path}: {t:?} vs {oblique:?}");
        }
    }
    // a knot moved off that line bows the path, and the rod bends otherwise
    let bowed = tip("path = [[0.0, 0.0, 0.004], [0.25, 0.0, 0.0045], [0.5, 0.0, 0.001]]");
    assert!(
        (bowed[2] - oblique[2]).abs() > 1e-4,
        "{bowed:?} vs {oblique:?}"
    );
    let s = Scenario::from_toml(
        "t",
        &with("path = [[0.0, 0.0, 0.004], [0.25, 0.0, 0.0045], [0.5, 0.0, 0.001]]"),
        &[],
    )
    .unwrap();
    let summary = gvsrom::build::describe(&s, &gvsrom::build(&s).unwrap());
    assert!(
        summary.contains("1 tendon (friction 0, on a custom path)"),
        "{summary}"
    );
    // refused, naming the key: the end offsets given too, a span that is not the path's, knots
    // out of order, a path that leaves the rod at a knot or between knots
    let refused = |routing: &str, needles: &[&str]| {
        let s = Scenario::from_toml("t", &with(routing), &[]).unwrap();
        let e = gvsrom::build(&s).err().expect("refused").to_string();
        assert!(needles.iter().all(|n| e.contains(n)), "{routing}: {e}");
    };
    let path = "path = [[0.0, 0.0, 0.004], [0.5, 0.0, 0.001]]";
    refused(
        &format!("{path}\noffset_end = [0.0, 0.001]"),
        &["tendons[0].offset_end", "not both"],
    );
    refused(
        &format!("{path}\nturns = 1"),
        &["tendons[0].turns", "not both"],
    );
    refused(
        &format!("{path}\nx_end = 0.4"),
        &["tendons[0].x_end", "last abscissa 0.5 m"],
    );
    refused(
        "path = [[0.0, 0.0, 0.004]]",
        &["tendons[0].path", "1 knots"],
    );
    refused(
        "path = [[0.0, 0.0, 0.004], [0.3, 0.0, 0.0], [0.2, 0.0, 0.0], [0.5, 0.0, 0.0]]",
        &["tendons[0].path[2]", "strictly increase"],
    );
    refused(
        "path = [[0.0, 0.0, 0.004], [0.2, 0.0, 0.012], [0.5, 0.0, 0.0]]",
        &["tendons[0].path[1]", "radius 0.01 m", "at this knot"],
    );
    refused(
        "path = [[0.0, 0.0, 0.0], [0.05, 0.0, 0.009], [0.1, 0.0, 0.0], [0.15, 0.0, -0.009], [0.5, 0.0, 0.0]]",
        &["tendons[0].path", "between path[", "bulges"],
    );
    refused(
        "path = [[0.0, 0.0, 0.004], [0.6, 0.0, 0.001]]",
        &["tendons[0].path[1][0]", "0.5 m"],
    );
}

/// The strain field of the end-moment rod (exact: `k_y ≡ M/EI` everywhere) with a Legendre basis
/// of order `p`: the largest relative error of `k_y` over the points, and the build warnings.
fn end_moment_strain_error(p: usize, overrides: &[&str]) -> (f64, Vec<String>) {
    let ei = 1e6 * std::f64::consts::PI * 0.01f64.powi(4) / 4.0;
    let kappa = 0.01 / ei;
    let order = format!("divisions.0.basis.order={p}");
    let mut set = vec![
        "loads.point.0.x=0.5",
        "loads.point.0.moment=[0, 0.01, 0]",
        order.as_str(),
    ];
    set.extend_from_slice(overrides);
    let owned: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let s = Scenario::from_toml("test", UNIFORM_ROD, &owned).expect("scenario parses");
    let built = gvsrom::build(&s).expect("scenario builds");
    let warnings = gvsrom::build::warnings(&s, &built);
    let r = solve(&built).expect("statics converges");
    let err = (r.strain.iter())
        .map(|xi| (xi[1] - kappa).abs() / kappa)
        .fold(0.0, f64::max);
    (err, warnings)
}

#[test]
fn a_basis_the_magnus_rule_under_integrates_is_warned_about_and_its_remedy_converges() {
    // Z4 integrates strains of degree ≤ 3 between points exactly: order 2 is exact and quiet
    let (e2, w2) = end_moment_strain_error(2, &[]);
    assert!(e2 < 1e-9 && w2.is_empty(), "{e2:e} {w2:?}");
    // order 10 on SoRoSim's 11 points: the end moment's constant strain comes out wavy, and
    // the build says so, with the remedy ...
    let (e10, w10) = end_moment_strain_error(10, &["divisions.0.quadrature.gauss=11"]);
    assert!(e10 > 1e-2, "{e10:e}");
    assert_eq!(w10.len(), 1, "{w10:?}");
    assert!(
        w10[0].starts_with("divisions[0]: the poses and loads integrate the strain between its 11 Gauss points with the Magnus Z4")
            && w10[0].contains("degree 10")
            && w10[0].contains("quadrature = { gauss = 33 }"),
        "{w10:?}"
    );
    // ... which brings it within 1e-3 and silences the warning
    let (e33, w33) = end_moment_strain_error(10, &["divisions.0.quadrature.gauss=33"]);
    assert!(e33 < 1e-3 && w33.is_empty(), "{e33:e} {w33:?}");
    // and which is the default above order 3 (orders 4 and 10 without a quadrature: quiet, and
    // as accurate as the remedy)
    let (e_default, w_default) = end_moment_strain_error(10, &[]);
    assert!(
        e_default == e33 && w_default.is_empty(),
        "{e_default:e} {w_default:?}"
    );
    let (e4, w4) = end_moment_strain_error(4, &[]);
    assert!(e4 < 1e-3 && w4.is_empty(), "{e4:e} {w4:?}");
    let (e4_sorosim, w4_sorosim) = end_moment_strain_error(4, &["divisions.0.quadrature.gauss=5"]);
    assert!(
        e4_sorosim > e4 && w4_sorosim.len() == 1,
        "{e4_sorosim:e} {e4:e} {w4_sorosim:?}"
    );
    // Z2 (midpoint) integrates only linear strains exactly: warned even on many points
    let (_, wz2) =
        end_moment_strain_error(4, &["magnus=\"z2\"", "divisions.0.quadrature.gauss=100"]);
    assert!(
        wz2.len() == 1 && wz2[0].contains("use `magnus = \"z4\"`"),
        "{wz2:?}"
    );
    // the presets are quiet
    for p in [
        "single-tendon",
        "six-tendon",
        "six-tendon-hanging",
        "soft-beam",
    ] {
        let s = presets::load(p, &[]).unwrap();
        assert!(
            gvsrom::build::under_integrated_divisions(&s).is_empty(),
            "{p}"
        );
    }
}

#[test]
fn a_fem_basis_under_points_that_straddle_its_elements_is_warned_about_and_less_accurate() {
    // a cantilever under a small world-fixed tip force on 16 linear elements: δ = PL³/3EI + PL/GA
    // (ν = ½, G = E/3; the section's shear area taken as its area, as the model does)
    let (e, r, l, p): (f64, f64, f64, f64) = (1e6, 0.01, 0.5, 1e-4);
    let (area, inertia) = (
        std::f64::consts::PI * r * r,
        std::f64::consts::PI * r.powi(4) / 4.0,
    );
    let exact = p * l.powi(3) / (3.0 * e * inertia) + p * l / (e / 3.0 * area);
    let deflection_error = |quadrature: Option<&str>| {
        let mut set = vec![
            "divisions.0.basis={ kind = \"fem\", modes = [\"bend_y\", \"elongation\", \"shear_z\"], elements = 16 }".to_string(),
            "loads.point=[{x=0.5,force=[0,0,-1e-4],frame=\"global\"}]".to_string(),
        ];
        set.extend(quadrature.map(|q| format!("divisions.0.quadrature={q}")));
        let s = Scenario::from_toml("t", UNIFORM_ROD, &set).unwrap();
        let built = gvsrom::build(&s).unwrap();
        let tip = solve(&built).unwrap().tip_position;
        (
            (-tip[2] - exact).abs() / exact,
            gvsrom::build::warnings(&s, &built),
        )
    };
    // the default: 2 Gauss points per element of the basis, quiet and exact to the discretization
    let (aligned, quiet) = deflection_error(None);
    assert!(aligned < 1e-3 && quiet.is_empty(), "{aligned:e} {quiet:?}");
    let (subdivided, quiet) = deflection_error(Some("{ elements = 32, gauss_per_element = 2 }"));
    assert!(
        subdivided < 1e-3 && quiet.is_empty(),
        "{subdivided:e} {quiet:?}"
    );
    // one element has no kink inside the division: a Gauss rule over it is quiet
    let s = Scenario::from_toml(
        "t",
        UNIFORM_ROD,
        &[
            "divisions.0.basis={ kind = \"fem\", modes = [\"bend_y\"], elements = 1 }".into(),
            "divisions.0.quadrature={ gauss = 7 }".into(),
        ],
    )
    .unwrap();
    assert!(gvsrom::build::warnings(&s, &gvsrom::build(&s).unwrap()).is_empty());
    // 30 points over the division, or 24 elements over 16: warned, and further off
    for q in ["{ gauss = 30 }", "{ elements = 24, gauss_per_element = 2 }"] {
        let (straddled, warned) = deflection_error(Some(q));
        assert!(
            straddled > 3.0 * aligned,
            "{q}: {straddled:e} against {aligned:e}"
        );
        assert!(
            warned.len() == 1
                && warned[0].starts_with("divisions[0]: its fem basis of 16 elements")
                && warned[0].contains("straddle the elements' ends"),
            "{q}: {warned:?}"
        );
    }
}

/// [`UNIFORM_ROD`] in two divisions, 0.2 m of the rod's material (E = 1 MPa) then 0.3 m of its own
/// `material` (a table of overrides, TOML inline; `""`: no `material` key), both order 2; no
/// gravity.
fn two_material_rod(material: &str) -> String {
    let material = match material {
        "" => String::new(),
        table => format!("material = {table}"),
    };
    format!(
        r#"
    name = "two materials"
    [material]
    youngs_modulus = 1e6
    poisson_ratio = 0.5
    density = 1000
    [[divisions]]
    length = 0.2
    radius = 0.01
    basis = {{ kind = "legendre", modes = ["bend_y", "elongation", "shear_z"], order = 2 }}
    [[divisions]]
    length = 0.3
    radius = 0.01
    basis = {{ kind = "legendre", modes = ["bend_y", "elongation", "shear_z"], order = 2 }}
    {material}
    [loads]
    gravity = [0, 0, 0]
"#
    )
}

#[test]
fn a_two_material_rod_bends_as_its_closed_forms() {
    let i = std::f64::consts::PI * 1e-8 / 4.0;
    let a = std::f64::consts::PI * 1e-4;
    let (e1, e2) = (1e6, 4e6);
    let text = two_material_rod("{ youngs_modulus = 4e6 }");
    // an end moment: two circular arcs, κ_k = M / E_k I, joined with a common tangent
    let m = 0.01;
    let (k1, k2) = (m / (e1 * i), m / (e2 * i));
    let (t1, t2) = (k1 * 0.2, k1 * 0.2 + k2 * 0.3);
    let expected = [
        t1.sin() / k1 + (t2.sin() - t1.sin()) / k2,
        0.0,
        -(1.0 - t1.cos()) / k1 - (t1.cos() - t2.cos()) / k2,
    ];
    let r = run_text(
        &text,
        &["loads.point.0.x=0.5", "loads.point.0.moment=[0, 0.01, 0]"],
    );
    for c in 0..3 {
        assert!(
            (r.tip_position[c] - expected[c]).abs() < 1e-9,
            "{:?} vs {expected:?}",
            r.tip_position
        );
    }
    // the stiff division bends a quarter as much: strain per division against M / E_k I
    for (x, xi) in r.strain_x.iter().zip(&r.strain) {
        let k = if *x < 0.2 - 1e-12 {
            k1
        } else if *x > 0.2 + 1e-12 {
            k2
        } else {
            continue;
        };
        assert!((xi[1] - k).abs() < 1e-9 * k, "at {x}: {} vs {k}", xi[1]);
    }
    // a small world-fixed tip force: δ = P ∫ (L − x)²/EI(x) dx + P ∫ dx/GA(x), G = E/3 (ν = ½)
    let p = 1e-4;
    let bending =
        |e: f64, x0: f64, x1: f64| ((0.5 - x0).powi(3) - (0.5 - x1).powi(3)) / (3.0 * e * i);
    let shear = |e: f64, len: f64| len / (e / 3.0 * a);
    let delta =
        -p * (bending(e1, 0.0, 0.2) + bending(e2, 0.2, 0.5) + shear(e1, 0.2) + shear(e2, 0.3));
    let r = run_text(
        &text,
        &[
            "loads.point.0.x=0.5",
            "loads.point.0.force=[0, 0, -1e-4]",
            "loads.point.0.frame=\"global\"",
        ],
    );
    // the uniform rod's tolerance (geometric nonlinearity O((δ/L)²), here smaller still)
    assert!(
        (r.tip_position[2] - delta).abs() < 5e-9,
        "{} vs {delta}",
        r.tip_position[2]
    );
    // 2.5× stiffer in bending over 0.3 m of 0.5: well apart from the uniform rod's deflection
    let uniform = -p * (bending(e1, 0.0, 0.5) + shear(e1, 0.5));
    assert!(
        (delta - uniform).abs() > 0.1 * delta.abs(),
        "{delta} {uniform}"
    );
}

#[test]
fn a_division_material_equal_to_the_rods_changes_nothing_and_a_bad_one_names_its_division() {
    let loads = ["loads.point.0.x=0.5", "loads.point.0.force=[0, 0.3, -0.2]"];
    let none = run_text(&two_material_rod(""), &loads);
    for same in ["{ youngs_modulus = 1e6, density = 1000 }", "{}"] {
        let text = two_material_rod(same);
        let s = Scenario::from_toml("t", &text, &[]).unwrap();
        // the rod's values are the rod's material: no division material, recorded or compared
        assert!(gvsrom::build(&s).unwrap().model.rod.divisions[1]
            .material
            .is_none());
        let same = run_text(&text, &loads);
        assert_eq!(same.q, none.q);
        assert_eq!(same.tip_position, none.tip_position);
    }
    let stiffer = run_text(&two_material_rod("{ youngs_modulus = 1.1e6 }"), &loads);
    assert!((stiffer.tip_position[2] - none.tip_position[2]).abs() > 1e-6);
    // a division's density weighs its own length: a weak gravity (small deflection) on a tip
    // division three times as dense, against δ = ∫ M(x)(L − x)/EI dx + ∫ V(x)/GA dx with the
    // piecewise weight q(x) = ρ(x) A g, integrated here by the midpoint rule
    let (g, area) = (9.81e-4, std::f64::consts::PI * 1e-4);
    let inertia = area * 1e-4 / 4.0;
    let q = |x: f64| if x < 0.2 { 1000.0 } else { 3000.0 } * area * g;
    let n = 4000;
    let h = 0.5 / n as f64;
    let mid = |k: usize| (k as f64 + 0.5) * h;
    let (mut delta, mut shear_part) = (0.0, 0.0);
    for k in 0..n {
        let x = mid(k);
        // shear force and bending moment of the weight beyond x
        let (mut v, mut m) = (0.0, 0.0);
        for kk in k..n {
            let s = mid(kk).max(x);
            let w = if kk == k { 0.5 * h } else { h };
            v += q(s) * w;
            m += q(s) * (s - x) * w;
        }
        delta += m * (0.5 - x) / (1e6 * inertia) * h;
        shear_part += v / (1e6 / 3.0 * area) * h;
    }
    let expected = -(delta + shear_part);
    let heavy = run_text(
        &two_material_rod("{ density = 3000 }"),
        &["loads.gravity=[0, 0, -9.81e-4]"],
    );
    let light = run_text(&two_material_rod(""), &["loads.gravity=[0, 0, -9.81e-4]"]);
    assert!(
        // measured 2.5e-6 relative (the midpoint rule's O(h²) and the O((δ/L)²) nonlinearity)
        (heavy.tip_position[2] - expected).abs() < 2e-5 * expected.abs(),
        "{} vs {expected}",
        heavy.tip_position[2]
    );
    assert!(heavy.tip_position[2] < 1.5 * light.tip_position[2]);
    // each value checked as [material]'s, named by its division
    for (material, field) in [
        (
            "{ youngs_modulus = -1 }",
            "divisions[1].material.youngs_modulus",
        ),
        (
            "{ poisson_ratio = 0.7 }",
            "divisions[1].material.poisson_ratio",
        ),
        ("{ density = -5 }", "divisions[1].material.density"),
        ("{ stiffness = 3 }", "divisions[1].material.stiffness"),
    ] {
        let s = Scenario::from_toml("t", &two_material_rod(material), &[])
            .and_then(|s| gvsrom::build(&s).map(|_| ()));
        let e = s.expect_err(material).to_string();
        assert!(e.contains(field), "{material}: {e}");
    }
}

/// A tendon placed on the surface (`angle_deg`) that ends where its division ends is fixed to
/// that division's end face: a next division of a smaller radius is no limit to it (the
/// six-tendon arm's short tendons end at X = 0.3 m, where a base of end radius 16 mm would meet
/// the tip's 15 mm). A tendon that runs on across the step must fit the smaller side.
#[test]
fn a_tendon_ending_at_a_step_is_held_to_its_own_division_only() {
    let build = |set: &str| {
        let s = presets::load("six-tendon", &[set.to_string()]).expect("preset loads");
        gvsrom::build(&s).map(|_| ()).map_err(|e| e.to_string())
    };
    build("divisions.0.radius_end=0.016").expect("the short tendons end on the 16 mm face");
    // the long ones run from 20 mm at X = 0 to 10 mm at X = 0.6: 15 mm at the junction
    let e = build("divisions.1.radius_start=0.01").unwrap_err();
    assert!(
        e.contains("tendons[0].angle_deg")
            && e.contains("X = 0.3 m")
            && e.contains("offset norm 0.015 m > radius 0.01 m"),
        "{e}"
    );
}

/// A helix sampled by too few quadrature points per turn is warned about, with the points that
/// resolve it: 5 turns of the six-tendon arm's tendon 0 on its 5-point divisions (2 per turn)
/// put the tip 11 mm off the converged one; the 10 points the warning names, 0.03 mm.
#[test]
fn a_helix_sampled_by_too_few_points_is_named_with_the_points_that_resolve_it() {
    let built = |set: &[&str]| {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        let s = presets::load("six-tendon-no-gravity", &set).expect("preset loads");
        gvsrom::build(&s).expect("preset builds")
    };
    let tip = |set: &[&str]| nalgebra::Vector3::from(solve(&built(set)).unwrap().tip_position);
    let coarse = ["tendons.0.turns=5"];
    let w = gvsrom::build::under_resolved_helices(&built(&coarse).model);
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].starts_with("tendons[0] makes 2.5 turns along divisions[0], where 5 quadrature points sample its load (2.0 per turn")
            && w[0].ends_with("give divisions[0].quadrature = { gauss = 10 } or more"),
        "{w:?}"
    );
    let named = [
        "tendons.0.turns=5",
        "divisions.0.quadrature.gauss=10",
        "divisions.1.quadrature.gauss=10",
    ];
    assert!(gvsrom::build::under_resolved_helices(&built(&named).model).is_empty());
    let fine = [
        "tendons.0.turns=5",
        "divisions.0.quadrature.gauss=60",
        "divisions.1.quadrature.gauss=60",
    ];
    let converged = tip(&fine);
    let off = |set: &[&str]| (tip(set) - converged).norm();
    assert!(off(&coarse) > 0.01, "{}", off(&coarse));
    assert!(off(&named) < 5e-5, "{}", off(&named));
    // a straight tendon is never warned about
    assert!(gvsrom::build::under_resolved_helices(&built(&[]).model).is_empty());
}

/// Divisions of 0.7 + 0.2 m sum to 0.8999999999999999 m in floating point: the tip is still 0.9 m for
/// every key that takes an abscissa (a point load, a distributed load's end, a body, a tendon's end,
/// a linearization's output), and the messages and summary print 0.9, not the sum's last bit.
#[test]
fn a_rod_whose_division_lengths_sum_below_their_decimal_takes_loads_at_its_tip() {
    // the uniform rod as two divisions of its section
    let division = UNIFORM_ROD.split("[[divisions]]").nth(1).unwrap();
    let division = division.split("[loads]").next().unwrap();
    let rod = &format!(
        "{}\n[[divisions]]{}",
        UNIFORM_ROD.replace("length = 0.5", "length = 0.7"),
        division.replace("length = 0.5", "length = 0.2")
    );
    let sum: f64 = [0.7, 0.2].iter().sum();
    assert!(sum < 0.9, "the premise: the sum rounds below 0.9");
    // an end moment at x = 0.9 bends both divisions onto one circle, κ = M/EI, tip at L = 0.9
    let ei = 1e6 * std::f64::consts::PI * 0.01f64.powi(4) / 4.0;
    let kappa = 0.01 / ei;
    let r = run_text(
        rod,
        &["loads.point.0.x=0.9", "loads.point.0.moment=[0, 0.01, 0]"],
    );
    let expected = [
        (kappa * 0.9).sin() / kappa,
        0.0,
        -(1.0 - (kappa * 0.9).cos()) / kappa,
    ];
    for i in 0..3 {
        assert!(
            (r.tip_position[i] - expected[i]).abs() < 1e-9,
            "{:?} vs {expected:?}",
            r.tip_position
        );
    }
    let build = |overrides: &[&str]| {
        let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        let s = Scenario::from_toml("test", rod, &overrides).expect("scenario parses");
        gvsrom::build(&s).map(|b| (gvsrom::build::describe(&s, &b), b))
    };
    let (summary, built) = build(&[
        "loads.distributed.0.kind=uniform",
        "loads.distributed.0.x_start=0.5",
        "loads.distributed.0.x_end=0.9",
        "loads.distributed.0.force=[0, 0, -1]",
        "bodies.0.x=0.9",
        "bodies.0.mass=0.01",
        "tendons.0.offset_start=[0, 0.005]",
        "tendons.0.offset_end=[0, 0.005]",
        "tendons.0.x_end=0.9",
    ])
    .expect("every abscissa 0.9 is the tip");
    assert!(summary.contains("0.9 m uniform"), "{summary}");
    if let Err(e) = gvsrom::linearize::Outputs::at(&built, &[0.9]) {
        panic!("the tip is a linearization's output: {e}");
    }
    // past the tip is still refused, naming the rod's length as 0.9 m
    let e = build(&["loads.point.0.x=0.91", "loads.point.0.force=[0, 0, 1]"])
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("loads.point[0].x") && e.contains("[0, 0.9] m"),
        "{e}"
    );
}
