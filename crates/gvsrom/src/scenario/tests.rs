//! Tests of the scenario format: presets round-trip, documented defaults, overrides and their
//! errors, non-finite numbers, syntax errors.

use super::*;
use crate::error::ScenarioError;
use gvs::discretize::MagnusOrder;
use gvs::solve::statics::StaticsOptions;

#[test]
fn every_preset_round_trips_through_its_resolved_toml() {
    for p in crate::presets::PRESETS {
        let s = crate::presets::load(p.name, &[]).unwrap();
        let text = s.to_toml().unwrap();
        let back = Scenario::from_toml(p.name, &text, &[]).unwrap();
        assert_eq!(
            back.to_table().unwrap(),
            s.to_table().unwrap(),
            "{}",
            p.name
        );
        // every default is written out: the resolved text names the solver and the output
        let table = s.to_table().unwrap();
        for key in [
            "material",
            "divisions",
            "loads",
            "solver",
            "output",
            "magnus",
        ] {
            assert!(table.contains_key(key), "{}: no `{key}` in\n{text}", p.name);
        }
        assert_eq!(format!("{back:?}"), format!("{s:?}"), "{}", p.name);
    }
}

const MINIMAL: &str = r#"
    [material]
    youngs_modulus = 1e6
    poisson_ratio = 0.5
    density = 1000
    [[divisions]]
    length = 0.5
    radius = 0.01
    basis = { kind = "legendre", modes = ["bend_y"], order = 3 }
    [[tendons]]
    offset_start = [0.0, 0.005]
    offset_end = [0.0, 0.005]
    tension = -1
"#;

#[test]
fn minimal_scenario_takes_documented_defaults() {
    let s = Scenario::from_toml("t", MINIMAL, &[]).unwrap();
    assert_eq!(s.loads.gravity, [0.0, 0.0, -9.81]);
    assert_eq!(s.material.damping, 1e4);
    assert_eq!(s.magnus, MagnusOrder::Z4);
    assert_eq!(s.output.centerline_points, 21);
    assert_eq!(s.tendons[0].x_end, None);
    assert_eq!(s.solver.ramp_steps, StaticsOptions::default().ramp_steps);
}

#[test]
fn overrides_reach_nested_keys_by_dotted_or_bracket_paths() {
    let s = Scenario::from_toml(
        "t",
        MINIMAL,
        &[
            "tendons.0.tension=-2.5".into(),
            "divisions[0].basis.order=6".into(),
            "solver.ramp_steps=3".into(),
            "loads.gravity=[0, 0, 0]".into(),
            "magnus=z2".into(),
            "tendons.1.offset_start=[0, -0.005]".into(),
            "tendons[1].offset_end=[0, -0.005]".into(),
        ],
    )
    .unwrap();
    assert_eq!(s.tendons[0].tension, -2.5);
    assert_eq!(s.tendons.len(), 2);
    assert_eq!(s.solver.ramp_steps, 3);
    assert_eq!(s.loads.gravity, [0.0; 3]);
    assert_eq!(s.magnus, MagnusOrder::Z2);
    assert_eq!(s.divisions[0].basis.order, Some(6));
}

#[test]
fn unknown_override_path_names_the_path() {
    let e = Scenario::from_toml("t", MINIMAL, &["divisions.0.basis.ordr=6".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("divisions[0].basis.ordr") && e.contains("unknown field"),
        "{e}"
    );
    let e = Scenario::from_toml("t", MINIMAL, &["tendons.5.tension=1".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tendons.5.tension") && e.contains("out of range"),
        "{e}"
    );
    let e = Scenario::from_toml("t", MINIMAL, &["material.youngs_modulus.x=1".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("`material.youngs_modulus` is a float"), "{e}");
    let e = Scenario::from_toml("t", MINIMAL, &["tension".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("path=value"), "{e}");
}

#[test]
fn negative_override_index_is_named_as_invalid_with_the_list_size() {
    for path in ["tendons.-1.tension=1", "tendons.-0.tension=1"] {
        let e = Scenario::from_toml("t", MINIMAL, &[path.into()])
            .unwrap_err()
            .to_string();
        let seg = &path[8..10];
        assert!(
            e.contains(&format!("`{seg}` is not a valid index of `tendons`"))
                && e.contains("0-based non-negative integers")
                && e.contains("the list has 1 entries"),
            "{e}"
        );
        assert!(!e.contains("tendons.0."), "{e}");
    }
    let e = Scenario::from_toml("t", MINIMAL, &["tendons[-1].tension=1".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`-1` is not a list index") && e.contains("non-negative"),
        "{e}"
    );
    // a list the scenario does not have yet: 0 entries
    let e = Scenario::from_toml("t", MINIMAL, &["loads.point.-1.x=0.1".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`-1` is not a valid index of `loads.point`") && e.contains("0 entries"),
        "{e}"
    );
}

#[test]
fn override_path_of_thousands_of_segments_is_rejected_not_a_stack_overflow() {
    // Found by tests/scenario_fuzz.rs: 12 000 segments overflowed the stack (an abort, not a
    // panic) in the recursive walks of the tree the path builds.
    for spec in [
        format!("{}=1", vec!["a"; 100_001].join(".")),
        format!("tendons{}=1", "[0]".repeat(100_000)),
    ] {
        let e = Scenario::from_toml("t", MINIMAL, &[spec])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("100001 segments") && e.contains("at most 16"),
            "{}",
            &e[e.len() - 80..]
        );
    }
    // The deepest keys of the format stay well inside the limit.
    let s =
        Scenario::from_toml("t", MINIMAL, &["divisions[0].basis.orders.bend_y=4".into()]).unwrap();
    assert_eq!(s.divisions[0].basis.orders.bend_y, Some(4));
}

#[test]
fn non_finite_numbers_are_named() {
    let e = Scenario::from_toml("t", MINIMAL, &["tendons.0.offset_end=[0, nan]".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tendons[0].offset_end[1]") && e.contains("NaN") && e.contains("finite"),
        "{e}"
    );
    let text = MINIMAL.replace("density = 1000", "density = inf");
    let e = Scenario::from_toml("t", &text, &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("material.density") && e.contains("inf"), "{e}");
}

#[test]
fn syntax_error_is_one_line_with_position() {
    let e = Scenario::from_toml("bad.toml", "[material\nyoungs_modulus = 1", &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("bad.toml: not valid TOML") && e.contains("line 1"),
        "{e}"
    );
    assert!(!e.contains('\n'), "{e}");
}

#[test]
fn a_star_in_an_override_stands_for_every_entry_of_the_list() {
    let two = format!(
        "{MINIMAL}\n[[tendons]]\noffset_start = [0, 0.002]\noffset_end = [0, 0.002]\ntension = -1\n"
    );
    for star in ["tendons.*.tension=-2.5", "tendons[*].tension=-2.5"] {
        let s = Scenario::from_toml("t", &two, &[star.into()]).unwrap();
        assert_eq!(s.tendons.len(), 2);
        assert!(s.tendons.iter().all(|t| t.tension == -2.5), "{star}");
    }
    for (spec, named) in [
        ("material.*.x=1", "`material` is not a list"),
        ("bodies.*.mass=1", "no list `bodies`"),
        ("*.x=1", "must follow the path of a list"),
    ] {
        let e = Scenario::from_toml("t", &two, &[spec.into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains(spec) && e.contains(named), "{spec}: {e}");
    }
    // one entry refused refuses the override, naming the entry's path
    let e = Scenario::from_toml("t", &two, &["tendons.*.tension.x=1".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("tendons.0.tension"), "{e}");
}

#[test]
fn a_key_given_twice_is_named_with_its_line() {
    let text = "[solver]\nramp_steps = 1\nramp_steps = 2\n";
    let e = Scenario::from_toml("twice.toml", text, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 3") && e.contains("duplicate key `ramp_steps`"),
        "{e}"
    );
}

#[test]
fn override_numbers_toml_does_not_write_are_read_as_numbers() {
    // `1e999` overflows: it is refused as not finite, not as "invalid type: string"
    let e = Scenario::from_toml("t", MINIMAL, &["tendons.0.tension=1e999".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tendons[0].tension") && e.contains("inf") && !e.contains("string"),
        "{e}"
    );
    let s = Scenario::from_toml(
        "t",
        MINIMAL,
        &[
            "tendons.0.tension=-.5".into(),
            "material.density=900.".into(),
        ],
    )
    .unwrap();
    assert_eq!(s.tendons[0].tension, -0.5);
    assert_eq!(s.material.density, 900.0);
    // bare words stay strings, the Magnus order in either case as the summary prints it
    for (spelled, order) in [("Z2", MagnusOrder::Z2), ("z4", MagnusOrder::Z4)] {
        let s = Scenario::from_toml("t", MINIMAL, &[format!("magnus={spelled}")]).unwrap();
        assert_eq!(s.magnus, order);
    }
}

#[test]
fn a_required_key_missing_at_the_top_level_is_named_not_the_path_dot() {
    let e = Scenario::from_toml("t", "name = \"x\"\n", &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`material`") && e.contains("top level") && !e.contains("`.`"),
        "{e}"
    );
}

#[test]
fn a_key_taking_a_name_given_another_value_names_the_value_and_the_names() {
    // toml's own message ("invalid type: unit variant, expected string only") names neither
    let cases = [
        (
            "divisions.0.section=3",
            "divisions[0].section",
            "the integer 3 given; expected a name in quotes, one of `circle`, `rectangle`, `ellipse`",
        ),
        (
            "divisions.0.basis.kind=true",
            "divisions[0].basis.kind",
            "`true` given; expected a name in quotes, `legendre` or `fem`",
        ),
        (
            "divisions.0.basis.modes=[[1]]",
            "divisions[0].basis.modes[0]",
            "a list given; expected a name in quotes, one of `torsion`, `bend_y`, `bend_z`, `elongation`, `shear_y`, `shear_z`",
        ),
    ];
    for (set, key, expected) in cases {
        match Scenario::from_toml("t", MINIMAL, &[set.into()]) {
            Err(ScenarioError::Format { field, message }) => {
                assert_eq!((field.as_str(), message.as_str()), (key, expected), "{set}")
            }
            other => panic!("{set}: {other:?}"),
        }
    }
    // a value where a table belongs: no Rust type name
    match Scenario::from_toml("t", MINIMAL, &["divisions.0.basis=3".into()]) {
        Err(ScenarioError::Format { field, message }) => assert_eq!(
            (field.as_str(), message.as_str()),
            (
                "divisions[0].basis",
                "invalid type: integer `3`, expected a table (`[…]` or `{ key = value, … }`)"
            )
        ),
        other => panic!("{other:?}"),
    }
    // a misspelt name keeps serde's message, which lists the names
    let e = Scenario::from_toml("t", MINIMAL, &["divisions.0.section=\"square\"".into()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unknown variant `square`, expected one of `circle`"),
        "{e}"
    );
}
