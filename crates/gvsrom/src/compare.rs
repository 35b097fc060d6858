//! `gvsrom compare REFERENCE RUN`: one trajectory (typically a reduced model's, `simulate --model`)
//! against another (typically the full model's) over their common samples, with the measures of
//! [`rom::metrics`] (paper Section IV-C2, Fig. 9):
//!
//! - **tip error** `100 · ‖p_run − p_ref‖ / L` per sample: mean, maximum (and when), and at the last
//!   common sample;
//! - **strain error** per sample: the mean absolute difference of `ξ − ξ*` over the computational
//!   points and the active components, as a percentage of the reference's largest `|ξ − ξ*|` at that
//!   sample; mean and maximum over the samples where the reference is not straight. A component is
//!   active if it is nonzero somewhere in either run (components that stay zero would only dilute
//!   the mean). `ξ* = [0, 0, 0, 1, 0, 0]`, the straight unstretched rod of every scenario;
//! - **wall times** of both runs (from their `meta.json`); the CLI prints the ratio of simulated time
//!   per wall time, which is fair to a partial run ([`speed_ratio`]; none when a wall time is zero
//!   or not recorded).
//!
//! `L` is the rod length the trajectories record (`length` in `meta.json`; for files written before
//! it was recorded, the abscissa of the last computational point, the tip). Both trajectories must
//! have the same sample times (the same `--duration` and `--sample-rate`) and computational points;
//! a partial run is compared over the samples it has.
//!
//! A run approximates a reference only if both ran the same thing: [`differences`] lists how two
//! trajectories' `meta.json` say they differ — the scenario's name, its physics (material,
//! geometry, base, tendon routing, loads: `"physics"`), the input (signal, start, load schedule:
//! `"input"`, see [`crate::simulate::input_record`]) and the requested duration and sample rate —
//! and what it cannot decide because a file written by an earlier gvsrom does not record it. The
//! strain basis and the reduced model are not compared: they are what a comparison measures.

use crate::error::ScenarioError;
use crate::npy::read_checked;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The straight, unstretched rod's strain.
const XI_STAR: [f64; 6] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0];

/// A trajectory directory written by `gvsrom simulate --out`.
#[derive(Debug, Clone)]
pub struct Trajectory {
    pub dir: PathBuf,
    pub scenario: String,
    pub n_dof: usize,
    pub complete: bool,
    pub wall_time_s: f64,
    /// Rod length [m].
    pub length: f64,
    pub t: Vec<f64>,
    /// `samples × 3`.
    pub tip: Vec<f64>,
    /// `samples × points × 6`: `ξ` at the computational points.
    pub strain: Vec<f64>,
    pub strain_x: Vec<f64>,
    /// The requested end time (`t_requested`), if recorded.
    pub t_requested: Option<f64>,
    /// Output samples per second (`sample_rate`), if recorded.
    pub sample_rate: Option<f64>,
    /// The input record (`input`), if recorded.
    pub input: Option<Value>,
    /// The physics record (`physics`), if recorded.
    pub physics: Option<Value>,
    /// Abscissae of the centreline samples [m] (`centerline_x`; trajectories written before the
    /// centreline was recorded have none).
    pub centerline_x: Option<Vec<f64>>,
    /// `samples × centerline_x.len() × 3`: the centreline positions [m] (`centerline.npy`), with
    /// `centerline_x`.
    pub centerline: Option<Vec<f64>>,
    /// How the run was made (`provenance`), if recorded.
    pub provenance: Option<Value>,
}

impl Trajectory {
    /// Loads and checks the trajectory in `dir`; `field` names it in errors (`REFERENCE`, `RUN`).
    pub fn load(dir: &Path, field: &str) -> Result<Trajectory, ScenarioError> {
        let bad = |message: String| ScenarioError::invalid(field, message);
        let meta_path = dir.join("meta.json");
        let text = crate::output::read::read_regular_to_string(&meta_path)
            .map_err(|e| bad(format!("cannot read {}: {e}", meta_path.display())))?;
        let meta: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| bad(format!("{} is not valid JSON: {e}", meta_path.display())))?;
        if meta["gvsrom"]["format"] != "trajectory" {
            return Err(bad(format!(
                "{} is not a trajectory (a directory written by `gvsrom simulate --out`)",
                dir.display()
            )));
        }
        // its files as written (an older trajectory without hashes is read unchecked)
        crate::output::verify_dir(dir, "trajectory").map_err(|e| {
            bad(format!(
                "{e}; an edited trajectory is not the run that was simulated"
            ))
        })?;
        let count = |key: &str| {
            meta[key]
                .as_u64()
                .map(|v| v as usize)
                .ok_or_else(|| bad(format!("{}: `{key}` is missing", meta_path.display())))
        };
        let (n, points) = (count("samples")?, count("n_points")?);
        let f8 = "<f8";
        let read = |name: &str, shape: &[usize]| {
            let v = read_checked::<f64>(dir, name, f8, shape).map_err(|e| bad(e.to_string()))?;
            match v.iter().position(|x| !x.is_finite()) {
                Some(i) => Err(bad(format!(
                    "{}: entry {i} is {}, not a finite number",
                    dir.join(name).display(),
                    v[i]
                ))),
                None => Ok(v),
            }
        };
        let strain_x = read("strain_x.npy", &[points])?;
        let length = match meta["length"].as_f64() {
            Some(l) => l,
            None => *strain_x.last().unwrap_or(&0.0),
        };
        if !(length > 0.0 && length.is_finite()) {
            return Err(bad(format!(
                "{}: rod length {length} (expected > 0)",
                meta_path.display()
            )));
        }
        let centerline_x = match meta.get("centerline_x") {
            None => None,
            Some(v) => Some(
                serde_json::from_value::<Vec<f64>>(v.clone())
                    .ok()
                    .filter(|x| x.len() >= 2 && x.iter().all(|x| x.is_finite()))
                    .ok_or_else(|| {
                        bad(format!(
                            "{}: `centerline_x` is not a list of at least 2 finite numbers",
                            meta_path.display()
                        ))
                    })?,
            ),
        };
        let centerline = match &centerline_x {
            Some(x) => Some(read("centerline.npy", &[n, x.len(), 3])?),
            None => None,
        };
        Ok(Trajectory {
            dir: dir.to_path_buf(),
            scenario: meta["scenario"].as_str().unwrap_or("?").to_string(),
            n_dof: count("n_dof")?,
            complete: meta["complete"].as_bool().unwrap_or(false),
            wall_time_s: meta["wall_time_s"].as_f64().unwrap_or(f64::NAN),
            length,
            t: read("t.npy", &[n])?,
            tip: read("tip_position.npy", &[n, 3])?,
            strain: read("strain.npy", &[n, points, 6])?,
            strain_x,
            t_requested: meta["t_requested"].as_f64(),
            sample_rate: meta["sample_rate"].as_f64(),
            input: meta.get("input").filter(|v| v.is_object()).cloned(),
            physics: meta.get("physics").filter(|v| v.is_object()).cloned(),
            centerline_x,
            centerline,
            provenance: meta.get("provenance").filter(|v| v.is_object()).cloned(),
        })
    }

    pub fn samples(&self) -> usize {
        self.t.len()
    }
}

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
            let shared = ["signal", "start", "start_tensions", "load_schedule"];
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

/// Simulated time per wall time of `run` over that of `reference` (> 1: `run` is faster), or
/// `None` when it cannot be told: a wall time that is zero, negative or not recorded, or a
/// trajectory that reached no time past its start.
pub fn speed_ratio(reference: &Trajectory, run: &Trajectory) -> Option<f64> {
    let rate = |tr: &Trajectory| {
        let span = tr.t.last()? - tr.t.first()?;
        let wall = tr.wall_time_s;
        (wall.is_finite() && wall > 0.0 && span > 0.0).then(|| span / wall)
    };
    let ratio = rate(run)? / rate(reference)?;
    (ratio.is_finite() && ratio > 0.0 && (1.0 / ratio).is_finite()).then_some(ratio)
}

/// What [`compare`] measures (percentages; see the module documentation).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Comparison {
    /// Common samples compared.
    pub samples: usize,
    pub tip_mean: f64,
    pub tip_max: f64,
    /// Time of the largest tip error.
    pub tip_max_t: f64,
    pub tip_end: f64,
    /// Over the samples where the reference is not straight (`None` if there are none).
    pub strain_mean: Option<f64>,
    pub strain_max: Option<f64>,
    /// Strain components (0 torsion … 5 shear z) compared.
    #[serde(default)]
    pub active: Vec<usize>,
}

/// One trajectory of a [`Report`], as `compare` describes it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Side {
    pub path: String,
    pub scenario: String,
    pub n_dof: usize,
    pub samples: usize,
    /// The last sample's time [s].
    pub t_last: Option<f64>,
    pub complete: bool,
    /// Wall time of the run [s], if recorded.
    pub wall_time_s: Option<f64>,
}

impl Side {
    pub fn of(tr: &Trajectory) -> Side {
        Side {
            path: tr.dir.display().to_string(),
            scenario: tr.scenario.clone(),
            n_dof: tr.n_dof,
            samples: tr.samples(),
            t_last: tr.t.last().copied(),
            complete: tr.complete,
            wall_time_s: (tr.wall_time_s.is_finite() && tr.wall_time_s > 0.0)
                .then_some(tr.wall_time_s),
        }
    }
}

/// What `gvsrom compare --json` writes: both runs, the measured errors, the speed ratio
/// ([`speed_ratio`], `null` if it cannot be told), the differences compared anyway
/// (`--allow-different`) and how the report was made.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    pub reference: Side,
    pub run: Side,
    pub comparison: Comparison,
    pub speed_ratio: Option<f64>,
    pub differ: Vec<String>,
    pub unknown: Vec<String>,
    pub provenance: crate::provenance::Provenance,
}

/// `run` against `reference` over their common samples.
pub fn compare(reference: &Trajectory, run: &Trajectory) -> Result<Comparison, ScenarioError> {
    let n = reference.samples().min(run.samples());
    if n == 0 {
        return Err(ScenarioError::invalid(
            if reference.samples() == 0 {
                "REFERENCE"
            } else {
                "RUN"
            },
            "the trajectory has no samples",
        ));
    }
    if let Some(k) = (0..n).find(|&k| {
        let (a, b) = (reference.t[k], run.t[k]);
        (a - b).abs() > 1e-9 * a.abs().max(1.0)
    }) {
        return Err(ScenarioError::invalid(
            "RUN",
            format!(
                "sample {k} is at t = {} s, the reference's at t = {} s: run both with the same --duration and --sample-rate",
                run.t[k], reference.t[k]
            ),
        ));
    }
    if reference.strain_x != run.strain_x {
        return Err(ScenarioError::invalid(
            "RUN",
            format!(
                "its {} computational points are not the reference's {}: compare runs of the same scenario",
                run.strain_x.len(),
                reference.strain_x.len()
            ),
        ));
    }
    let points = reference.strain_x.len();
    let deviation = |tr: &Trajectory, k: usize, j: usize, c: usize| {
        tr.strain[(k * points + j) * 6 + c] - XI_STAR[c]
    };
    let active: Vec<usize> = (0..6)
        .filter(|&c| {
            (0..n).any(|k| {
                (0..points)
                    .any(|j| deviation(reference, k, j, c) != 0.0 || deviation(run, k, j, c) != 0.0)
            })
        })
        .collect();
    let (mut tip_sum, mut tip_max, mut tip_max_t, mut tip_end) = (0.0, 0.0f64, 0.0, 0.0);
    let (mut strain_sum, mut strain_max, mut strained) = (0.0, 0.0f64, 0usize);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for k in 0..n {
        let p = |tr: &Trajectory| [tr.tip[3 * k], tr.tip[3 * k + 1], tr.tip[3 * k + 2]];
        let e = rom::metrics::tip_error_percent(&p(reference), &p(run), reference.length);
        tip_sum += e;
        if e > tip_max {
            (tip_max, tip_max_t) = (e, reference.t[k]);
        }
        tip_end = e;
        a.clear();
        b.clear();
        for j in 0..points {
            for &c in &active {
                a.push(deviation(reference, k, j, c));
                b.push(deviation(run, k, j, c));
            }
        }
        if a.iter().any(|v| *v != 0.0) {
            let e = rom::metrics::strain_error_percent(&a, &b);
            strain_sum += e;
            strain_max = strain_max.max(e);
            strained += 1;
        }
    }
    Ok(Comparison {
        samples: n,
        tip_mean: tip_sum / n as f64,
        tip_max,
        tip_max_t,
        tip_end,
        strain_mean: (strained > 0).then(|| strain_sum / strained as f64),
        strain_max: (strained > 0).then_some(strain_max),
        active,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two points, three samples at t = 0, 0.1, 0.2; `bend_y` at the points per sample.
    fn trajectory(tip_x: [f64; 3], bend_y: [[f64; 2]; 3]) -> Trajectory {
        let mut strain = vec![];
        for k in 0..3 {
            for j in 0..2 {
                strain.extend([0.0, bend_y[k][j], 0.0, 1.0, 0.0, 0.0]);
            }
        }
        Trajectory {
            dir: PathBuf::from("x"),
            scenario: "s".into(),
            n_dof: 2,
            complete: true,
            wall_time_s: 1.0,
            length: 0.5,
            t: vec![0.0, 0.1, 0.2],
            tip: tip_x.iter().flat_map(|&x| [x, 0.0, 0.0]).collect(),
            strain,
            strain_x: vec![0.0, 0.5],
            t_requested: Some(0.2),
            sample_rate: Some(10.0),
            input: Some(
                serde_json::json!({"signal": "constant", "tensions": [-1.0, 0.0], "start": "rest", "load_schedule": null}),
            ),
            physics: Some(
                serde_json::json!({"material": {"damping": 1e4}, "loads": {"gravity": [0.0, 0.0, -9.81]}}),
            ),
            centerline_x: None,
            centerline: None,
            provenance: None,
        }
    }

    #[test]
    fn errors_are_the_papers_measures_by_hand() {
        let reference = trajectory([0.5, 0.4, 0.3], [[0.0, 0.0], [2.0, 4.0], [1.0, 1.0]]);
        let run = trajectory([0.5, 0.41, 0.3], [[0.0, 0.0], [2.0, 3.0], [1.0, 1.5]]);
        let c = compare(&reference, &run).unwrap();
        assert_eq!(c.samples, 3);
        assert_eq!(c.active, vec![1]);
        // tip: 0.01 m of 0.5 m at t = 0.1 only
        assert!((c.tip_max - 2.0).abs() < 1e-12 && c.tip_max_t == 0.1);
        assert!((c.tip_mean - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(c.tip_end, 0.0);
        // strain (the straight first sample is skipped): t = 0.1: mean |Δ| 0.5 / peak 4 = 12.5 %;
        // t = 0.2: 0.25 / 1 = 25 %
        assert!((c.strain_mean.unwrap() - 18.75).abs() < 1e-12);
        assert!((c.strain_max.unwrap() - 25.0).abs() < 1e-12);
        // a run compared with itself
        let same = compare(&reference, &reference).unwrap();
        assert_eq!((same.tip_max, same.strain_max), (0.0, Some(0.0)));
    }

    #[test]
    fn other_sample_times_or_points_are_refused() {
        let reference = trajectory([0.5; 3], [[0.0; 2]; 3]);
        let mut run = reference.clone();
        run.t[2] = 0.25;
        let e = compare(&reference, &run).unwrap_err().to_string();
        assert!(e.contains("RUN") && e.contains("--sample-rate"), "{e}");
        let mut run = reference.clone();
        run.strain_x[1] = 0.4;
        let e = compare(&reference, &run).unwrap_err().to_string();
        assert!(e.contains("computational points"), "{e}");
        // a partial run is compared over the samples it has
        let mut run = reference.clone();
        run.t.truncate(2);
        assert_eq!(compare(&reference, &run).unwrap().samples, 2);
    }

    #[test]
    fn other_inputs_physics_scenarios_or_durations_are_named_with_both_values() {
        let reference = trajectory([0.5; 3], [[0.0; 2]; 3]);
        assert!(differences(&reference, &reference.clone()).none());
        let mut run = reference.clone();
        run.input.as_mut().unwrap()["tensions"][0] = serde_json::json!(-3.0);
        run.physics.as_mut().unwrap()["material"]["damping"] = serde_json::json!(5e3);
        run.scenario = "other".into();
        run.t_requested = Some(0.4);
        let d = differences(&reference, &run);
        assert!(d.unknown.is_empty(), "{d:?}");
        let all = d.differ.join("\n");
        assert_eq!(d.differ.len(), 4, "{all}");
        for needle in [
            "different scenarios: `s` in REFERENCE, `other` in RUN",
            "different physics: `material.damping` = 10000.0 in REFERENCE, 5000.0 in RUN",
            "different inputs: `tendons[0].tension` = -1.0 in REFERENCE, -3.0 in RUN",
            "different sample times: `--duration` = 0.2 s in REFERENCE, 0.4 s in RUN",
        ] {
            assert!(all.contains(needle), "{needle}\n{all}");
        }
        // another kind of signal: named under `input`
        let mut run = reference.clone();
        run.input = Some(
            serde_json::json!({"signal": "steps", "seed": 1, "start": "rest", "load_schedule": null}),
        );
        let d = differences(&reference, &run);
        assert_eq!(
            d.differ,
            ["the runs have different inputs: `input.signal` = \"constant\" in REFERENCE, \"steps\" in RUN"],
        );
        // numbers equal to rounding are equal
        let mut run = reference.clone();
        run.input.as_mut().unwrap()["tensions"][0] = serde_json::json!(-(1.0 + 1e-15));
        assert!(differences(&reference, &run).none());
    }

    #[test]
    fn a_trajectory_that_does_not_record_its_input_or_physics_is_undecided_not_equal() {
        let reference = trajectory([0.5; 3], [[0.0; 2]; 3]);
        let mut old = reference.clone();
        (old.input, old.physics, old.t_requested) = (None, None, None);
        let d = differences(&reference, &old);
        assert!(d.differ.is_empty(), "{d:?}");
        assert_eq!(d.unknown.len(), 3, "{d:?}");
        assert!(
            d.unknown
                .iter()
                .all(|u| u.contains("RUN's meta.json") && u.contains("does not record")),
            "{d:?}"
        );
        let d = differences(&old, &reference);
        assert!(
            d.unknown
                .iter()
                .all(|u| u.contains("REFERENCE's meta.json")),
            "{d:?}"
        );
    }

    #[test]
    fn the_speed_ratio_is_none_for_a_zero_or_missing_wall_time() {
        let reference = trajectory([0.5; 3], [[0.0; 2]; 3]);
        let mut run = reference.clone();
        run.wall_time_s = 0.25;
        assert_eq!(speed_ratio(&reference, &run), Some(4.0));
        for wall in [0.0, f64::NAN, -1.0, f64::INFINITY] {
            run.wall_time_s = wall;
            assert_eq!(speed_ratio(&reference, &run), None, "run wall {wall}");
            assert_eq!(speed_ratio(&run, &reference), None, "reference wall {wall}");
        }
        // a run that reached no time past its start
        let mut run = reference.clone();
        run.t.truncate(1);
        assert_eq!(speed_ratio(&reference, &run), None);
    }
}
