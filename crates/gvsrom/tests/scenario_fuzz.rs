//! Property tests of the scenario reader (issue 6): whatever the input — random text, a built-in
//! preset (or one of two scenarios here that use every key) with extreme or wrong-typed values, or
//! random `--set` overrides — reading, building and a short statics solve return `Ok` or a typed
//! error, never panic nor overflow the stack, and an `Ok` solve holds no NaN.
//!
//! The runs are deterministic: a fixed ChaCha seed and no failure persistence, so CI replays exactly
//! the same cases (`PROPTEST_CASES` still scales the number of cases for a longer local run).

use gvsrom::presets::PRESETS;
use gvsrom::scenario::{from_table, parse_table};
use gvsrom::statics::solve;
use gvsrom::Scenario;
use proptest::prelude::*;
use proptest::sample::{select, Index};
use proptest::test_runner::{RngAlgorithm, RngSeed};
use toml::{Table, Value};

/// Deterministic configuration: `cases` cases (or `PROPTEST_CASES`) from a fixed seed, nothing
/// written to disk.
fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(cases);
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x6776_7372_6f6d),
        ..ProptestConfig::default()
    }
}

/// A scenario that uses every key of the format (the presets leave out point and uniform loads, the
/// base rotation, per-element quadrature, quadratic FEM, partial and polar tendons...), so that
/// mutations reach their checks too.
const ALL_KEYS: &str = r#"
name = "all-keys"
description = "every key of the format"
magnus = "z2"
[material]
youngs_modulus = 1e6
poisson_ratio = 0.45
density = 1000.0
damping = 1e4
[base]
position = [0.1, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
angle_deg = 30.0
[[divisions]]
length = 0.2
radius = 0.01
basis = { kind = "legendre", modes = ["torsion", "bend_y", "bend_z", "elongation"], order = 1, orders = { bend_y = 3 } }
quadrature = { elements = 2, gauss_per_element = 3 }
[[divisions]]
length = 0.3
radius_start = 0.01
radius_end = 0.005
basis = { kind = "fem", modes = ["bend_y", "bend_z", "shear_z"], elements = 3, degree = "quadratic" }
[[tendons]]
offset_start = [0.0, 0.005]
offset_end = [0.0, 0.002]
x_start = 0.1
x_end = 0.4
friction = 0.2
friction_smoothing = 0.2
tension = -0.5
[[tendons]]
angle_deg = 90.0
radial_fraction = 0.5
tension = -0.2
[loads]
gravity = [0.0, 0.0, -9.81]
[[loads.point]]
x = 0.5
force = [0.0, 0.0, -0.01]
moment = [0.0, 0.001, 0.0]
frame = "global"
[[loads.distributed]]
kind = "uniform"
x_start = 0.1
x_end = 0.3
force = [0.0, 0.0, -0.1]
moment = [0.0, 0.0, 0.0]
frame = "local"
[[loads.distributed]]
kind = "triangular_pulse"
center = 0.25
width = 0.2
magnitude = 0.01
axis = [0.0, 0.0, 1.0]
convention = "total"
[solver]
ramp_steps = 2
min_increment = 0.25
ftol = 1e-10
xtol = 1e-12
max_iterations = 50
[output]
centerline_points = 11
"#;

/// The same with a rotation matrix for the base, a uniform Legendre division with Gauss points, and
/// a point load in the middle.
const ALL_KEYS_ROTATION: &str = r#"
magnus = "z4"
[material]
youngs_modulus = 2e6
poisson_ratio = 0.3
density = 1100.0
[base]
rotation = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
[[divisions]]
length = 0.4
radius = 0.02
basis = { kind = "legendre", modes = ["bend_y", "bend_z", "torsion", "elongation", "shear_y", "shear_z"], order = 2 }
quadrature = { gauss = 7 }
[[tendons]]
offset_start = [0.01, 0.0]
offset_end = [0.01, 0.0]
tension = -1.0
[[loads.point]]
x = 0.2
force = [0.0, 0.1, 0.0]
"#;

/// The scenarios the mutations start from: the presets and the two above.
fn bases() -> Vec<(&'static str, &'static str)> {
    let mut b: Vec<_> = PRESETS.iter().map(|p| (p.name, p.toml)).collect();
    b.push(("all-keys", ALL_KEYS));
    b.push(("all-keys-rotation", ALL_KEYS_ROTATION));
    b
}

/// Every key of the scenario format (docs/scenario-format.md), at any depth.
const KEYS: &[&str] = &[
    "name",
    "description",
    "magnus",
    "material",
    "youngs_modulus",
    "poisson_ratio",
    "density",
    "damping",
    "base",
    "position",
    "rotation",
    "axis",
    "angle_deg",
    "divisions",
    "length",
    "radius",
    "radius_start",
    "radius_end",
    "inner_radius",
    "inner_radius_start",
    "inner_radius_end",
    "section",
    "width_start",
    "width_end",
    "height",
    "height_start",
    "height_end",
    "basis",
    "kind",
    "modes",
    "order",
    "orders",
    "torsion",
    "bend_y",
    "bend_z",
    "elongation",
    "shear_y",
    "shear_z",
    "elements",
    "degree",
    "quadrature",
    "gauss",
    "gauss_per_element",
    "tendons",
    "offset_start",
    "offset_end",
    "radial_fraction",
    "x_start",
    "x_end",
    "friction",
    "friction_smoothing",
    "tension",
    "loads",
    "gravity",
    "point",
    "distributed",
    "x",
    "force",
    "moment",
    "frame",
    "center",
    "width",
    "magnitude",
    "convention",
    "solver",
    "ramp_steps",
    "min_increment",
    "ftol",
    "xtol",
    "max_iterations",
    "output",
    "centerline_points",
];

/// TOML literals: extreme numbers, wrong types and the format's own enum strings.
const LITERALS: &[&str] = &[
    "0",
    "1",
    "-1",
    "2",
    "5000",
    "1000000000000000000",
    "9223372036854775807",
    "-9223372036854775808",
    "0.0",
    "-0.0",
    "1e-300",
    "-1e-300",
    "1e308",
    "-1e308",
    "inf",
    "-inf",
    "nan",
    "0.5",
    "\"\"",
    "\"z2\"",
    "\"legendre\"",
    "\"fem\"",
    "\"quadratic\"",
    "\"global\"",
    "\"total\"",
    "\"bend_y\"",
    "\"triangular_pulse\"",
    "\"rectangle\"",
    "\"ellipse\"",
    "0.0149999999",
    "true",
    "[]",
    "[0, 0, 0]",
    "[1e308, 1e308, 1e308]",
    "[\"bend_y\", \"bend_y\"]",
    "[[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
    "{}",
    "{ kind = \"fem\", modes = [\"bend_y\"], elements = 1 }",
    "1979-05-27T07:32:00Z",
];

/// Headers of the format's tables, and a few that are not.
const HEADERS: &[&str] = &[
    "[material]",
    "[base]",
    "[[divisions]]",
    "[divisions.basis]",
    "[divisions.quadrature]",
    "[[tendons]]",
    "[loads]",
    "[[loads.point]]",
    "[[loads.distributed]]",
    "[solver]",
    "[output]",
    "[[material]]",
    "[divisions]",
    "[]",
    "[[",
];

/// Reads `text` and, if it is a scenario, builds it: must return, not panic.
fn read_and_build(text: &str, overrides: &[String]) {
    if let Ok(s) = Scenario::from_toml("fuzz", text, overrides) {
        let _ = gvsrom::build(&s);
    }
}

fn toml_line() -> impl Strategy<Value = String> {
    prop_oneof![
        select(HEADERS).prop_map(str::to_string),
        (select(KEYS), select(LITERALS)).prop_map(|(k, v)| format!("{k} = {v}")),
        (
            select(KEYS),
            select(KEYS),
            select(LITERALS),
            select(LITERALS)
        )
            .prop_map(|(k, k2, v, v2)| format!("{k} = {{ {k2} = {v}, kind = {v2} }}")),
        (select(KEYS), "\\PC{0,12}").prop_map(|(k, v)| format!("{k} = {v}")),
        "\\PC{0,24}",
    ]
}

/// Arrays, inline tables, dotted keys and table headers nested up to 20 000 deep (the TOML parser
/// must stop them before they reach the recursive walks of the reader).
fn nested_text() -> impl Strategy<Value = String> {
    (0..4usize, 1..20_000usize).prop_map(|(kind, n)| match kind {
        0 => format!("v = {}{}", "[".repeat(n), "]".repeat(n)),
        1 => format!("v = {}1{}", "{ a = ".repeat(n), " }".repeat(n)),
        2 => format!("{}b = 1", "a.".repeat(n)),
        _ => format!("[{}b]", "a.".repeat(n)),
    })
}

// ---------------------------------------------------------------------------------------------
// Structured mutations of a preset's table.

#[derive(Debug, Clone, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

/// Path of every node below `v` (excluding `v` itself), in document order.
fn node_paths(v: &Value, path: &mut Vec<Step>, out: &mut Vec<Vec<Step>>) {
    match v {
        Value::Table(t) => {
            for (k, c) in t {
                path.push(Step::Key(k.clone()));
                out.push(path.clone());
                node_paths(c, path, out);
                path.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                path.push(Step::Index(i));
                out.push(path.clone());
                node_paths(c, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(mut v: &'a mut Value, path: &[Step]) -> &'a mut Value {
    for s in path {
        v = match (s, v) {
            (Step::Key(k), Value::Table(t)) => t.get_mut(k).expect("path from node_paths"),
            (Step::Index(i), Value::Array(a)) => &mut a[*i],
            _ => unreachable!("path from node_paths"),
        };
    }
    v
}

/// One random edit of a scenario tree; `Index` picks among the nodes the edit applies to when it is
/// applied, so that edits compose.
#[derive(Debug, Clone)]
enum Mutation {
    /// Replace a leaf or an array (not a table) by `value`.
    Replace(Index, Value),
    /// Replace a number or string leaf by an extreme value of the same type (these reach the
    /// build and the solver; wrong types mostly stop at the reader).
    Extreme(Index, Extreme),
    /// Replace a leaf by a copy of another leaf of the same scenario (a length as a position, a
    /// junction abscissa as a load position...).
    Swap(Index, Index),
    /// Remove a key, or an entry of an array.
    Delete(Index),
    /// Insert a copy of one entry of an array (an array of tables: one more `[[divisions]]`).
    Duplicate(Index, Index),
    /// Add `key = value` to a table (a key of the format in the wrong place, or garbage).
    AddKey(Index, String, Value),
}

fn apply(root: &mut Value, m: &Mutation) {
    let mut all = Vec::new();
    node_paths(root, &mut Vec::new(), &mut all);
    match m {
        Mutation::Replace(sel, value) => {
            let c: Vec<_> = all
                .iter()
                .filter(|p| !node_mut(root, p).is_table())
                .collect();
            if !c.is_empty() {
                *node_mut(root, c[sel.index(c.len())]) = value.clone();
            }
        }
        Mutation::Extreme(sel, x) => {
            let c: Vec<_> = all
                .iter()
                .filter(|p| {
                    matches!(
                        node_mut(root, p),
                        Value::Float(_) | Value::Integer(_) | Value::String(_)
                    )
                })
                .collect();
            if c.is_empty() {
                return;
            }
            let node = node_mut(root, c[sel.index(c.len())]);
            *node = match node {
                Value::Float(_) => Value::Float(x.float),
                Value::Integer(_) => Value::Integer(x.integer),
                _ => Value::String(x.string.to_string()),
            };
        }
        Mutation::Swap(to, from) => {
            let c: Vec<_> = all
                .iter()
                .filter(|p| !matches!(node_mut(root, p), Value::Table(_) | Value::Array(_)))
                .collect();
            if c.is_empty() {
                return;
            }
            let v = node_mut(root, c[from.index(c.len())]).clone();
            *node_mut(root, c[to.index(c.len())]) = v;
        }
        Mutation::Delete(sel) => {
            if all.is_empty() {
                return;
            }
            let p = &all[sel.index(all.len())];
            let (last, parent) = p.split_last().unwrap();
            match (node_mut(root, parent), last) {
                (Value::Table(t), Step::Key(k)) => {
                    t.remove(k);
                }
                (Value::Array(a), Step::Index(i)) => {
                    a.remove(*i);
                }
                _ => unreachable!(),
            }
        }
        Mutation::Duplicate(sel, at) => {
            let c: Vec<_> = all
                .iter()
                .filter(|p| matches!(node_mut(root, p), Value::Array(a) if !a.is_empty()))
                .collect();
            if c.is_empty() {
                return;
            }
            let Value::Array(a) = node_mut(root, c[sel.index(c.len())]) else {
                unreachable!()
            };
            let i = at.index(a.len());
            a.insert(i, a[i].clone());
        }
        Mutation::AddKey(sel, key, value) => {
            let mut c: Vec<Vec<Step>> = vec![Vec::new()];
            c.extend(all.into_iter().filter(|p| node_mut(root, p).is_table()));
            if let Value::Table(t) = node_mut(root, &c[sel.index(c.len())]) {
                t.insert(key.clone(), value.clone());
            }
        }
    }
}

/// One extreme value per type; [`Mutation::Extreme`] takes the one of the leaf's type.
#[derive(Debug, Clone)]
struct Extreme {
    float: f64,
    integer: i64,
    string: &'static str,
}

fn extreme() -> impl Strategy<Value = Extreme> {
    let float = prop_oneof![
        3 => select(vec![
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            5e-324,
            1e308,
            -1e308,
            f64::MAX,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -1.0,
            0.5,
            1e-9,
            1e9,
        ]),
        1 => any::<f64>(),
    ];
    let integer = select(vec![
        0,
        1,
        2,
        -1,
        50,
        51,
        5000,
        5001,
        1_000_000_000_000_000_000,
        i64::MAX,
        i64::MIN,
    ]);
    let string = select(vec![
        "",
        "z2",
        "z4",
        "legendre",
        "fem",
        "linear",
        "quadratic",
        "local",
        "global",
        "peak",
        "total",
        "uniform",
        "triangular_pulse",
        "bend_y",
        "torsion",
        "shear_z",
    ]);
    (float, integer, string).prop_map(|(float, integer, string)| Extreme {
        float,
        integer,
        string,
    })
}

/// Extreme and wrong-typed values.
fn value() -> impl Strategy<Value = Value> {
    let lit = select(LITERALS).prop_map(|s| {
        format!("v = {s}")
            .parse::<Table>()
            .expect("LITERALS are TOML")
            .remove("v")
            .unwrap()
    });
    prop_oneof![
        4 => lit,
        1 => select(vec![5e-324, 1e-9, 0.01, 0.3, -0.3, 1.0]).prop_map(Value::Float),
        1 => any::<f64>().prop_map(Value::Float),
        1 => (-3i64..60).prop_map(Value::Integer),
        1 => "\\PC{0,8}".prop_map(Value::String),
        1 => select(KEYS).prop_map(|k| Value::String(k.to_string())),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        6 => (any::<Index>(), extreme()).prop_map(|(i, x)| Mutation::Extreme(i, x)),
        2 => (any::<Index>(), value()).prop_map(|(i, v)| Mutation::Replace(i, v)),
        2 => (any::<Index>(), any::<Index>()).prop_map(|(i, j)| Mutation::Swap(i, j)),
        1 => any::<Index>().prop_map(Mutation::Delete),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(i, j)| Mutation::Duplicate(i, j)),
        1 => (any::<Index>(), prop_oneof![select(KEYS).prop_map(str::to_string), "\\PC{0,6}"], value())
            .prop_map(|(i, k, v)| Mutation::AddKey(i, k, v)),
    ]
}

/// Largest model solved per case: keeps one case within a few milliseconds to tens of
/// milliseconds (the Jacobian costs about `n_dof² × n_points`).
const MAX_SOLVE_DOF: usize = 200;
const MAX_SOLVE_POINTS: usize = 1000;

/// How far [`run_full_path`] got.
#[derive(Debug, PartialEq)]
enum Outcome {
    Rejected,
    TooLarge,
    NotConverged,
    Solved,
}

/// Reads, builds and (if small) solves `table`; panics only on a NaN in an `Ok` result.
fn run_full_path(table: Table) -> Outcome {
    let Ok(s) = from_table(table) else {
        return Outcome::Rejected;
    };
    let Ok(mut built) = gvsrom::build(&s) else {
        return Outcome::Rejected;
    };
    if built.model.n_dof() > MAX_SOLVE_DOF || built.model.disc.n_points() > MAX_SOLVE_POINTS {
        return Outcome::TooLarge;
    }
    // A short solve: at most 30 dogleg iterations per stage, at most two load stages and two halvings.
    // (ramp_steps and min_increment are bounded by the physical-range checks of issue 6; an absurd
    // but valid ramp_steps = 1e18 would otherwise run 1e18 stages.)
    let o = &mut built.options;
    o.max_iterations = o.max_iterations.min(30);
    o.ramp_steps = o.ramp_steps.min(2);
    o.min_increment = o.min_increment.max(0.25);
    let Ok(r) = solve(&built) else {
        return Outcome::NotConverged;
    };
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    assert!(finite(&r.q), "NaN/inf in q: {:?}", r.q);
    assert!(finite(&r.tip_position), "NaN/inf tip: {:?}", r.tip_position);
    assert!(
        r.centerline.iter().all(|p| finite(p)),
        "NaN/inf in the centreline"
    );
    assert!(r.strain.iter().all(|p| finite(p)), "NaN/inf in the strain");
    assert!(r.residual_norm.is_finite(), "residual {}", r.residual_norm);
    Outcome::Solved
}

// ---------------------------------------------------------------------------------------------
// `--set` overrides.

/// A path segment: a key of the format, garbage, or an index in dotted or bracket form.
fn segment() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => select(KEYS).prop_map(str::to_string),
        2 => select(vec![
            "0", "1", "5", "-1", "99999999999999999999", "[0]", "[1]", "[-1]", "[]", "[",
            "]", "[0][1]", "[99999999999999999999]", "", " ", "a[0]x", "[0]]", "é", "x[0",
        ])
        .prop_map(str::to_string),
        1 => "\\PC{0,6}",
    ]
}

fn override_spec() -> impl Strategy<Value = String> {
    let path = prop::collection::vec((segment(), any::<bool>()), 1..5).prop_map(|segs| {
        let mut p = String::new();
        for (k, (s, glue)) in segs.into_iter().enumerate() {
            if k > 0 && !(glue && s.starts_with('[')) {
                p.push('.');
            }
            p.push_str(&s);
        }
        p
    });
    // Now and then a path of thousands of segments (12 000 overflowed the stack before the
    // length limit of `apply_override`).
    let path = prop_oneof![
        20 => path,
        1 => (select(vec!["a", "tendons", "[0]", "0"]), 1..30_000usize)
            .prop_map(|(s, n)| vec![s; n].join(".")),
    ];
    let value = prop_oneof![
        3 => select(LITERALS).prop_map(str::to_string),
        1 => "\\PC{0,12}",
    ];
    let sep = select(vec!["=", "=", "=", " = ", "", "=="]);
    (path, sep, value).prop_map(|(p, s, v)| format!("{p}{s}{v}"))
}

proptest! {
    #![proptest_config(config(1024))]

    #[test]
    fn arbitrary_unicode_text_never_panics(text in "\\PC{0,200}") {
        read_and_build(&text, &[]);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        read_and_build(&String::from_utf8_lossy(&bytes), &[]);
    }

    #[test]
    fn deeply_nested_text_never_overflows(text in nested_text()) {
        read_and_build(&text, &[]);
    }

    #[test]
    fn toml_fragments_never_panic(lines in prop::collection::vec(toml_line(), 0..24)) {
        read_and_build(&lines.join("\n"), &[]);
    }

    #[test]
    fn random_overrides_never_panic(
        base in select(bases()),
        overrides in prop::collection::vec(override_spec(), 1..4),
    ) {
        read_and_build(base.1, &overrides);
    }
}

proptest! {
    // The important one: a few seconds for 2048 cases (most stop in the reader or the build).
    #![proptest_config(config(2048))]

    #[test]
    fn mutated_scenarios_never_panic_nor_solve_to_nan(
        base in select(bases()),
        mutations in prop::collection::vec(mutation(), 1..5),
    ) {
        let mut root = Value::Table(parse_table(base.0, base.1).expect("bases parse"));
        for m in &mutations {
            apply(&mut root, m);
        }
        let Value::Table(table) = root else { unreachable!() };
        run_full_path(table);
    }
}

/// The unmutated bases build, are small enough to be solved, and converge within the short solve
/// of [`run_full_path`] (so that the mutated cases do reach statics).
#[test]
fn unmutated_bases_take_the_full_path() {
    for (name, text) in bases() {
        let s = Scenario::from_toml(name, text, &[]).expect("base reads");
        let built = gvsrom::build(&s).expect("base builds");
        assert!(built.model.n_dof() <= MAX_SOLVE_DOF, "{name}");
        assert!(built.model.disc.n_points() <= MAX_SOLVE_POINTS, "{name}");
        assert_eq!(
            run_full_path(parse_table(name, text).unwrap()),
            Outcome::Solved,
            "{name}"
        );
    }
}
