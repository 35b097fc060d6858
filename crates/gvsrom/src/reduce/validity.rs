//! What a reduced model may answer. A model learned the strains of one scenario's physics at the
//! inputs of its dataset; outside them it extrapolates, and a decoder that extrapolates answers
//! wrongly without a sign (tanh layers saturate; IV-C2 models left their data and put the tip tens
//! of per cent of the length off). So every model records
//!
//! - the **range of each training input** (`tendons.K.tension`, `loads.…`): the usable samples'
//!   `[min, max]`, widened by [`INPUT_MARGIN`](crate::build::reduced::INPUT_MARGIN) of its width on each side;
//! - the **scenario it was trained on** (its TOML, in the layout), whose physics — everything but
//!   the inputs, the tendon tensions, `name`, `description`, `solver` and `output` — must be the
//!   scenario's it is used on;
//! - the **latent range** of the training encodings, checked on every reduced solution
//!   ([`super::Reduced::check_range`]).
//!
//! [`check`] lists every way a scenario lies outside the first two; `--model` refuses such a
//! scenario unless `--extrapolate` is given, which is then printed and recorded.

use super::anchors::input_value;
use crate::build::reduced::{at_held, inside, JointInputs};
use crate::build::Built;
use crate::dataset::Dataset;
use crate::error::ScenarioError;
use crate::reduced_model::{InputRange, ReducedModel};
use crate::scenario::{parse_path, Scenario, Seg};
use toml::{Table, Value};

/// Keys of a scenario that are not physics: a model may be used whatever their value.
const NOT_PHYSICS: &[&str] = &["name", "description", "solver", "output"];

/// Per dataset input, the `[min, max]` over the usable samples (status ok).
pub fn input_ranges(ds: &Dataset) -> Vec<InputRange> {
    let k = ds.meta.parameters.len();
    let rows = ds.ok_rows();
    ds.meta
        .parameters
        .iter()
        .enumerate()
        .map(|(d, p)| {
            let (min, max) = rows
                .iter()
                .map(|&i| ds.inputs[i * k + d])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                });
            InputRange {
                parameter: p.clone(),
                min,
                max,
            }
        })
        .collect()
}

/// The scenario the model was trained on, as its meta.json records it.
pub(super) fn trained_scenario(model: &ReducedModel) -> Result<Scenario, ScenarioError> {
    let layout = &model.meta.layout;
    Scenario::from_toml(&layout.scenario, &layout.scenario_toml, &[]).map_err(|e| {
        ScenarioError::invalid(
            "--model",
            format!("the model's recorded scenario cannot be read: {e}"),
        )
    })
}

/// Per tendon of the model's training scenario, the tension training held it at, or `None` for
/// a tendon whose tension was a training input (it has a range instead).
pub fn held_tensions(model: &ReducedModel) -> Result<Vec<Option<f64>>, ScenarioError> {
    Ok(held_in(&trained_scenario(model)?, &model.meta.input_range))
}

/// [`held_tensions`] of the training scenario `trained` with the training inputs `inputs`.
fn held_in(trained: &Scenario, inputs: &[InputRange]) -> Vec<Option<f64>> {
    let is_input = |p: &str| inputs.iter().any(|r| r.parameter == p);
    trained
        .tendons
        .iter()
        .enumerate()
        .map(|(k, t)| (!is_input(&format!("tendons.{k}.tension"))).then_some(t.tension))
        .collect()
}

/// Every way the scenario of `built` (its TOML `table`, after `--set`) lies outside what `model`
/// was trained on, one sentence each: an input outside its training range, inputs each in range
/// whose combination lies far from the training inputs (`joint`, [`super::coverage`]), a tendon
/// tension that training held fixed at another value, a physics field that differs. Empty: the
/// model may answer. An error only if the model's own scenario cannot be read.
///
/// With `tensions_from_signal` (a simulation driven by an input signal) the scenario's own
/// tensions are not checked: the signal's are, by `Reduced::check_signal`.
pub fn check(
    built: &Built,
    table: &Table,
    model: &ReducedModel,
    tensions_from_signal: bool,
    joint: Option<&dyn JointInputs>,
) -> Result<Vec<String>, ScenarioError> {
    let meta = &model.meta;
    let mut outside = vec![];
    if meta.input_range.is_empty() {
        outside.push(
            "it records no range of training inputs (it was written before gvsrom recorded them): re-create it with `gvsrom pod` or `gvsrom train` from its dataset".to_string(),
        );
    }
    // a tendon driven by displacement has no tension to check here: its tension is found by the
    // solve, and checked after it (`statics::check_reduced`)
    let by_displacement = |k: usize| built.displacement.get(k).is_some_and(Option::is_some);
    let tendon_of = |p: &str| -> Option<usize> {
        p.strip_prefix("tendons.")?
            .strip_suffix(".tension")?
            .parse()
            .ok()
    };
    let signal_driven = |p: &str| match tendon_of(p) {
        Some(k) => tensions_from_signal || by_displacement(k),
        None => false,
    };
    for r in &meta.input_range {
        if signal_driven(&r.parameter) {
            continue;
        }
        match input_value(built, Some(table), &r.parameter) {
            Some(v) if inside(r, v) => {}
            Some(v) => outside.push(format!(
                "{} = {v} lies outside the training inputs [{}, {}]",
                r.parameter, r.min, r.max
            )),
            None => outside.push(format!(
                "{} (a training input) has no numeric value in this scenario",
                r.parameter
            )),
        }
    }
    // each input in its range: their combination against the training inputs as a whole
    let found = built.displacement_driven();
    if let (true, false, false, Some(joint)) =
        (outside.is_empty(), tensions_from_signal, found, joint)
    {
        outside.extend(joint.outside(&built.u).map(|(_, why)| why));
    }
    let trained = trained_scenario(model)?;
    // tensions training held fixed (not inputs) must be the trained ones
    for (k, held) in held_in(&trained, &meta.input_range).into_iter().enumerate() {
        let (Some(h), false, false) = (held, tensions_from_signal, by_displacement(k)) else {
            continue;
        };
        match built.u.get(k) {
            Some(&u) if at_held(u, h) => {}
            Some(&u) => outside.push(format!(
                "tendons.{k}.tension = {u}, but training held it at {h}"
            )),
            None => {} // the tendon count is physics, reported below
        }
    }
    let current = crate::scenario::from_table(table.clone())?;
    let mut skip: Vec<Vec<Seg>> = meta
        .input_range
        .iter()
        .filter_map(|r| parse_path(&r.parameter).ok())
        .collect();
    for k in 0..trained.tendons.len().max(current.tendons.len()) {
        // how a tendon is driven is an input, not physics (its thread's axial stiffness acts
        // only through a displacement drive, whose tensions are checked as found)
        for key in ["tension", "displacement", "axial_stiffness"] {
            skip.push(vec![
                Seg::Key("tendons".into()),
                Seg::Index(k),
                Seg::Key(key.into()),
            ]);
        }
    }
    let diffs = physics_differences(&trained, &current, &skip)?;
    outside.extend(diffs.into_iter().map(|(path, there, here)| {
        format!(
            "{path} differs: {there} in the model's scenario `{}`, {here} here",
            meta.layout.scenario
        )
    }));
    Ok(outside)
}

/// Every leaf where the physics of scenario `b` differs from `a`'s, as `(path, in a, in b)`:
/// the keys that are not physics ([`NOT_PHYSICS`]) and the paths `skip` (inputs) are left out.
fn physics_differences(
    a: &Scenario,
    b: &Scenario,
    skip: &[Vec<Seg>],
) -> Result<Vec<(String, String, String)>, ScenarioError> {
    let mut a = a.to_table()?;
    let mut b = b.to_table()?;
    for key in NOT_PHYSICS {
        a.remove(*key);
        b.remove(*key);
    }
    for path in skip {
        remove(&mut a, path);
        remove(&mut b, path);
    }
    let mut diffs = vec![];
    diff(&Value::Table(a), &Value::Table(b), &mut vec![], &mut diffs);
    Ok(diffs)
}

/// The first leaf where the physics of `b` differs from `a`'s, the scenario paths `inputs` (sampled
/// by either side) aside ([`physics_differences`]), as `"P is B, … A"` worded by `say(path, in a,
/// in b)` with `" (and N more differences)"` when there are more; `None` when they agree.
pub(super) fn first_physics_difference<'p>(
    a: &Scenario,
    b: &Scenario,
    inputs: impl IntoIterator<Item = &'p str>,
    say: impl Fn(&str, &str, &str) -> String,
) -> Result<Option<String>, ScenarioError> {
    let skip: Vec<Vec<Seg>> = inputs
        .into_iter()
        .filter_map(|p| parse_path(p).ok())
        .collect();
    let diffs = physics_differences(a, b, &skip)?;
    Ok(diffs.first().map(|(path, in_a, in_b)| {
        let more = match diffs.len() {
            1 => String::new(),
            n => format!(" (and {} more differences)", n - 1),
        };
        format!("{}{more}", say(path, in_a, in_b))
    }))
}

/// Removes the value at `path` from `table`, if present (an array entry is replaced by a marker,
/// so the other entries keep their indices).
fn remove(table: &mut Table, path: &[Seg]) {
    let Some((Seg::Key(first), rest)) = path.split_first() else {
        return;
    };
    let Some((last, middle)) = rest.split_last() else {
        table.remove(first);
        return;
    };
    let Some(mut node) = table.get_mut(first) else {
        return;
    };
    for seg in middle {
        let next = match (seg, node) {
            (Seg::Key(k), Value::Table(t)) => t.get_mut(k),
            (Seg::Index(i), Value::Array(a)) => a.get_mut(*i),
            _ => None,
        };
        let Some(next) = next else {
            return;
        };
        node = next;
    }
    match (last, node) {
        (Seg::Key(k), Value::Table(t)) => {
            t.remove(k);
        }
        (Seg::Index(i), Value::Array(a)) if *i < a.len() => {
            a[*i] = Value::String("(input)".into());
        }
        _ => {}
    }
}

/// Appends `(path, value in a, value in b)` for every leaf where `a` and `b` differ (numbers to a
/// relative 1e-12); a key or array entry present on one side only is a difference of its own.
fn diff(a: &Value, b: &Value, path: &mut Vec<Seg>, out: &mut Vec<(String, String, String)>) {
    let render = |path: &[Seg]| crate::scenario::render_path(path);
    match (a, b) {
        (Value::Table(x), Value::Table(y)) => {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                path.push(Seg::Key(k.clone()));
                match (x.get(k), y.get(k)) {
                    (Some(va), Some(vb)) => diff(va, vb, path, out),
                    (va, vb) => out.push((render(path), shown(va), shown(vb))),
                }
                path.pop();
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (va, vb)) in x.iter().zip(y).enumerate() {
                path.push(Seg::Index(i));
                diff(va, vb, path, out);
                path.pop();
            }
        }
        _ if same(a, b) => {}
        _ => out.push((render(path), shown(Some(a)), shown(Some(b)))),
    }
}

fn same(a: &Value, b: &Value) -> bool {
    let num = |v: &Value| match v {
        Value::Float(f) => Some(*f),
        Value::Integer(i) => Some(*i as f64),
        _ => None,
    };
    match (num(a), num(b)) {
        (Some(x), Some(y)) => (x - y).abs() <= 1e-12 * x.abs().max(y.abs()),
        _ => a == b,
    }
}

fn shown(v: Option<&Value>) -> String {
    match v {
        None => "absent".into(),
        Some(Value::Array(a)) if a.iter().all(|v| !v.is_table()) => {
            let items: Vec<String> = a.iter().map(|v| v.to_string()).collect();
            format!("[{}]", items.join(", "))
        }
        Some(Value::Array(a)) => format!("{} entries", a.len()),
        Some(Value::Table(_)) => "a table".into(),
        Some(v) => v.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(min: f64, max: f64) -> InputRange {
        InputRange {
            parameter: "p".into(),
            min,
            max,
        }
    }

    #[test]
    fn an_input_is_inside_its_range_widened_by_the_margin_only() {
        let r = range(-6.0, 3.0);
        assert!(inside(&r, -6.0) && inside(&r, 3.0) && inside(&r, 0.0));
        // 2 % of the width 9 is 0.18
        assert!(inside(&r, 3.17) && inside(&r, -6.17));
        assert!(!inside(&r, 3.19) && !inside(&r, -6.19));
        assert!(!inside(&r, f64::NAN) && !inside(&r, f64::INFINITY));
        // a single value: only itself (to rounding)
        let r = range(2.0, 2.0);
        assert!(inside(&r, 2.0) && !inside(&r, 2.001));
    }

    #[test]
    fn the_diff_names_each_differing_leaf_and_ignores_equal_numbers() {
        let a: Table = toml::from_str(
            "[loads]\ngravity = [0.0, 0.0, -9.81]\n[material]\ndensity = 1000\nyoungs_modulus = 1e6",
        )
        .unwrap();
        let b: Table = toml::from_str(
            "[loads]\ngravity = [0.0, 0.0, 0.0]\n[material]\ndensity = 1000.0\nyoungs_modulus = 1e6\nextra = 1",
        )
        .unwrap();
        let mut out = vec![];
        diff(&Value::Table(a), &Value::Table(b), &mut vec![], &mut out);
        let paths: Vec<&str> = out.iter().map(|d| d.0.as_str()).collect();
        assert_eq!(paths, ["loads.gravity[2]", "material.extra"], "{out:?}");
        assert_eq!(out[0].1, "-9.81");
        assert_eq!(out[1].1, "absent");
    }

    #[test]
    fn removing_a_path_leaves_the_rest() {
        let mut t: Table = toml::from_str(
            "[[tendons]]\ntension = 1.0\nfriction = 0.5\n[[tendons]]\ntension = 2.0",
        )
        .unwrap();
        remove(&mut t, &parse_path("tendons.1.tension").unwrap());
        remove(&mut t, &parse_path("tendons.0.tension").unwrap());
        remove(&mut t, &parse_path("no.such.path").unwrap());
        let tendons = t["tendons"].as_array().unwrap();
        assert_eq!(tendons[0].as_table().unwrap().len(), 1);
        assert!(tendons[1].as_table().unwrap().is_empty());
    }
}
