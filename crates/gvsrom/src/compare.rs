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
//!   per wall time, which is fair to a partial run.
//!
//! `L` is the rod length the trajectories record (`length` in `meta.json`; for files written before
//! it was recorded, the abscissa of the last computational point, the tip). Both trajectories must
//! have the same sample times (the same `--duration` and `--sample-rate`) and computational points;
//! a partial run is compared over the samples it has.

use crate::error::ScenarioError;
use crate::npy::read_checked;
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
}

impl Trajectory {
    /// Loads and checks the trajectory in `dir`; `field` names it in errors (`REFERENCE`, `RUN`).
    pub fn load(dir: &Path, field: &str) -> Result<Trajectory, ScenarioError> {
        let bad = |message: String| ScenarioError::invalid(field, message);
        let meta_path = dir.join("meta.json");
        let text = std::fs::read_to_string(&meta_path)
            .map_err(|e| bad(format!("cannot read {}: {e}", meta_path.display())))?;
        let meta: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| bad(format!("{} is not valid JSON: {e}", meta_path.display())))?;
        if meta["gvsrom"]["format"] != "trajectory" {
            return Err(bad(format!(
                "{} is not a trajectory (a directory written by `gvsrom simulate --out`)",
                dir.display()
            )));
        }
        let count = |key: &str| {
            meta[key]
                .as_u64()
                .map(|v| v as usize)
                .ok_or_else(|| bad(format!("{}: `{key}` is missing", meta_path.display())))
        };
        let (n, points) = (count("samples")?, count("n_points")?);
        let f8 = "<f8";
        let read = |name: &str, shape: &[usize]| {
            read_checked::<f64>(dir, name, f8, shape).map_err(|e| bad(e.to_string()))
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
        })
    }

    pub fn samples(&self) -> usize {
        self.t.len()
    }
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
}
