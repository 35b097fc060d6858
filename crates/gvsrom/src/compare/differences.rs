//! How two trajectories differ besides what a comparison measures: what both must share for one
//! to approximate the other.

use super::Trajectory;
use serde_json::Value;

/// How two trajectories differ besides what a comparison measures ([`differences`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Differences {
    /// One sentence per aspect that differs, naming the fields and both values: "the runs have
    /// different inputs: `tendons[0].tension` = -10 in REFERENCE, -5 in RUN".
    pub differ: Vec<String>,
    /// One sentence per aspect that cannot be decided because a `meta.json` does not record it.
    pub unknown: Vec<String>,
}

impl Differences {
    /// Both lists empty: the runs are known to have run the same scenario, input and sample times.
    pub fn none(&self) -> bool {
        self.differ.is_empty() && self.unknown.is_empty()
    }
}

/// Listed differences per aspect before "and N more".
const SHOWN: usize = 4;

/// How `run` differs from `reference` in what both must share for one to approximate the other:
/// the scenario's name, its physics, the input and the requested duration and sample rate (see
/// the module documentation).
pub fn differences(reference: &Trajectory, run: &Trajectory) -> Differences {
    let mut d = Differences::default();
    let old = |tr: &Trajectory, label: &str, what: &str| {
        format!(
            "{label}'s meta.json ({}) does not record {what} (written by an earlier gvsrom; simulate again to record it)",
            tr.dir.display()
        )
    };
    let (r, u) = ("REFERENCE", "RUN");
    if reference.scenario == "?" || run.scenario == "?" {
        d.unknown.push(format!(
            "the scenario names: {}",
            if reference.scenario == "?" {
                old(reference, r, "it")
            } else {
                old(run, u, "it")
            }
        ));
    } else if reference.scenario != run.scenario {
        d.differ.push(format!(
            "the runs are of different scenarios: `{}` in REFERENCE, `{}` in RUN",
            reference.scenario, run.scenario
        ));
    }
    // the unloaded rods (a trajectory that does not record ξ* was of a straight one)
    if reference.strain_reference.len() == run.strain_reference.len() {
        let worst = (reference.strain_reference.iter())
            .zip(&run.strain_reference)
            .enumerate()
            .map(|(i, (a, b))| (i, (a - b).abs()))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((i, e)) = worst.filter(|w| w.1 > 1e-12) {
            let (j, c) = (i / 6, i % 6);
            d.differ.push(format!(
                "the rods have different reference strains ξ*: component {c} at point {j} (X = {} m) is {} in REFERENCE, {} in RUN (largest of the differences, {e:.3e})",
                reference.strain_x.get(j).copied().unwrap_or(f64::NAN),
                reference.strain_reference[i],
                run.strain_reference[i]
            ));
        }
    }
    let mut aspect = |what: &str,
                      differ: &str,
                      a: &Option<Value>,
                      b: &Option<Value>,
                      name: fn(&str) -> String| {
        match (a, b) {
            (Some(a), Some(b)) => {
                let mut out = vec![];
                diff(a, b, &mut String::new(), &mut out);
                if !out.is_empty() {
                    d.differ.push(format!("{differ}: {}", listed(&out, name)));
                }
            }
            (None, _) => d.unknown.push(format!(
                "whether the {what} are the same: {}",
                old(reference, r, &format!("its {what}"))
            )),
            (_, None) => d.unknown.push(format!(
                "whether the {what} are the same: {}",
                old(run, u, &format!("its {what}"))
            )),
        }
    };
    aspect(
        "physics",
        "the runs have different physics",
        &reference.physics,
        &run.physics,
        |p| p.to_string(),
    );
    // signals of different kinds: the kind, not each parameter one of them lacks
    let (mut a, mut b) = (reference.input.clone(), run.input.clone());
    if let (Some(Value::Object(x)), Some(Value::Object(y))) = (&mut a, &mut b) {
        if x.get("signal") != y.get("signal") {
            let shared = [
                "signal",
                "start",
                "start_tensions",
                "start_displacements",
                "displacement_channels",
                "start_q",
                "start_qd",
                "load_schedule",
            ];
            x.retain(|k, _| shared.contains(&k.as_str()));
            y.retain(|k, _| shared.contains(&k.as_str()));
        }
    }
    aspect(
        "inputs",
        "the runs have different inputs",
        &a,
        &b,
        input_name,
    );
    let mut times = vec![];
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
    match (reference.t_requested, run.t_requested) {
        (Some(a), Some(b)) if !near(a, b) => {
            times.push(("--duration".to_string(), format!("{a} s"), format!("{b} s")))
        }
        (Some(_), Some(_)) => {}
        (None, _) => d.unknown.push(format!(
            "whether the durations are the same: {}",
            old(reference, r, "its requested duration")
        )),
        (_, None) => d.unknown.push(format!(
            "whether the durations are the same: {}",
            old(run, u, "its requested duration")
        )),
    }
    if let (Some(a), Some(b)) = (reference.sample_rate, run.sample_rate) {
        if !near(a, b) {
            times.push((
                "--sample-rate".to_string(),
                format!("{a} Hz"),
                format!("{b} Hz"),
            ));
        }
    }
    if !times.is_empty() {
        d.differ.push(format!(
            "the runs have different sample times: {}",
            listed(&times, |p| p.to_string())
        ));
    }
    d
}

/// `` `name` = a in REFERENCE, b in RUN; … `` for the first [`SHOWN`] differences, then how many
/// more; `name` renders a path.
fn listed(items: &[(String, String, String)], name: fn(&str) -> String) -> String {
    let mut parts: Vec<String> = items
        .iter()
        .take(SHOWN)
        .map(|(path, a, b)| format!("`{}` = {a} in REFERENCE, {b} in RUN", name(path)))
        .collect();
    if items.len() > SHOWN {
        parts.push(format!("and {} more", items.len() - SHOWN));
    }
    parts.join("; ")
}

/// An input record's path as the user knows it: the tensions as the scenario's
/// `tendons[k].tension`, the rest under `input`.
fn input_name(path: &str) -> String {
    let index = |rest: &str| {
        rest.strip_prefix('[')
            .and_then(|r| r.strip_suffix(']'))
            .map(str::to_string)
    };
    if let Some(k) = path.strip_prefix("tensions").and_then(index) {
        return format!("tendons[{k}].tension");
    }
    if let Some(k) = path.strip_prefix("start_tensions").and_then(index) {
        return format!("tendons[{k}].tension (the starting equilibrium's)");
    }
    if let Some(k) = path.strip_prefix("displacements").and_then(index) {
        return format!("tendons[{k}].displacement");
    }
    if let Some(k) = path.strip_prefix("start_displacements").and_then(index) {
        return format!("tendons[{k}].displacement (the starting equilibrium's)");
    }
    format!("input.{path}")
}

/// Appends `(path, a, b)` for every leaf where the JSON values `a` and `b` differ (numbers to a
/// relative 1e-12); a key, or a list of another length, on one side only is a difference of its own.
fn diff(a: &Value, b: &Value, path: &mut String, out: &mut Vec<(String, String, String)>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let mut keys: Vec<&String> = x.keys().chain(y.keys()).collect();
            keys.sort();
            keys.dedup();
            for k in keys {
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                match (x.get(k), y.get(k)) {
                    (Some(va), Some(vb)) => diff(va, vb, path, out),
                    (va, vb) => out.push((path.clone(), shown(va), shown(vb))),
                }
                path.truncate(len);
            }
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            for (i, (va, vb)) in x.iter().zip(y).enumerate() {
                let len = path.len();
                path.push_str(&format!("[{i}]"));
                diff(va, vb, path, out);
                path.truncate(len);
            }
        }
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (
                x.as_f64().unwrap_or(f64::NAN),
                y.as_f64().unwrap_or(f64::NAN),
            );
            let same = (x - y).abs() <= 1e-12 * x.abs().max(y.abs()); // false for NaN
            if !same {
                out.push((path.clone(), shown(Some(a)), shown(Some(b))));
            }
        }
        _ if a == b => {}
        _ => out.push((path.clone(), shown(Some(a)), shown(Some(b)))),
    }
}

fn shown(v: Option<&Value>) -> String {
    match v {
        None => "absent".into(),
        Some(Value::Array(a)) => format!("a list of {}", a.len()),
        Some(Value::Object(_)) => "a table".into(),
        Some(v) => v.to_string(),
    }
}
