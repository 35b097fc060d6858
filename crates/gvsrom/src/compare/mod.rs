//! `gvsrom compare REFERENCE RUN`: one trajectory (typically a reduced model's, `simulate --model`)
//! against another (typically the full model's) over their common samples, with the measures of
//! [`rom::metrics`] (paper Section IV-C2, Fig. 9):
//!
//! - **tip error** `100 · ‖p_run − p_ref‖ / L` per sample: mean, maximum (and when), and at the first
//!   and last common samples (the first says how far apart the runs start: a reduced model whose
//!   rest decodes away from the straight rod starts elsewhere, and that offset is in every error);
//! - **strain error** per sample: the mean absolute difference of `ξ − ξ*` over the computational
//!   points and the active components, as a percentage of the reference's largest `|ξ − ξ*|` at that
//!   sample; mean and maximum over the samples where the reference is not straight. A component is
//!   active if it is nonzero somewhere in either run (components that stay zero would only dilute
//!   the mean). `ξ* = [0, 0, 0, 1, 0, 0]`, the straight unstretched rod of every scenario;
//! - **tendon length error** `|ℓ_run − ℓ_ref|` \[mm\] per sample and tendon, when both
//!   trajectories record the lengths (`tendon_lengths.npy`): mean, maximum (and when) — the error an
//!   actuator under position control would see;
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

mod differences;
mod trajectory;

pub use differences::{differences, Differences};
pub use trajectory::{Trajectory, STRAIGHT_STRAIN};

use crate::error::ScenarioError;
use std::path::Path;

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
    /// Tip error at the first common sample: how far apart the runs start (a reduced model's rest
    /// that decodes away from the full model's, or another start state); part of every error.
    #[serde(default)]
    pub tip_start: f64,
    /// Over the samples where the reference is not straight (`None` if there are none).
    pub strain_mean: Option<f64>,
    pub strain_max: Option<f64>,
    /// Strain components (0 torsion … 5 shear z) compared.
    #[serde(default)]
    pub active: Vec<usize>,
    /// Tendon length error `|ℓ_run − ℓ_ref|` \[mm\] over the samples and tendons: mean, maximum
    /// and the time of the maximum (`None` unless both trajectories record the lengths).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tendon_length_mm: Option<TendonLengthError>,
}

impl Comparison {
    /// Tip error at the first sample above which the runs are said to start apart, % of the
    /// length: a reduced model's rest within the decoder's training fit starts well below it.
    pub const START_APART_PERCENT: f64 = 0.1;

    /// The runs start apart (their first tips more than [`Self::START_APART_PERCENT`] of the
    /// length apart): every error then holds that offset.
    pub fn starts_apart(&self) -> bool {
        self.tip_start > Self::START_APART_PERCENT
    }
}

/// [`Comparison::tendon_length_mm`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TendonLengthError {
    pub mean: f64,
    pub max: f64,
    /// Time \[s\] of the largest error.
    pub max_t: f64,
}

/// One trajectory of a [`Report`], as `compare` describes it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Side {
    pub path: String,
    pub scenario: String,
    pub n_dof: usize,
    pub samples: usize,
    /// The last sample's time \[s\].
    pub t_last: Option<f64>,
    pub complete: bool,
    /// Wall time of the run \[s\], if recorded.
    pub wall_time_s: Option<f64>,
    /// How its reduced model was used outside what it was trained on (`--extrapolate`); empty
    /// otherwise.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub extrapolated: Vec<String>,
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
            extrapolated: tr.extrapolated.clone(),
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
    /// What could not be checked ([`Compared::warnings`]).
    pub warnings: Vec<String>,
    pub provenance: crate::provenance::Provenance,
}

/// Two trajectories compared as `gvsrom compare` compares them ([`run`]).
pub struct Compared {
    pub reference: Trajectory,
    pub run: Trajectory,
    /// How they differ (empty unless compared anyway, `allow_different`).
    pub differences: Differences,
    pub comparison: Comparison,
    /// [`speed_ratio`] of the run over the reference.
    pub speed_ratio: Option<f64>,
    /// What could not be checked: a run written before gvsrom recorded content hashes, whose
    /// files may have been edited since (`pod` and `--model` warn of such outputs alike).
    pub warnings: Vec<String>,
}

/// `gvsrom compare REFERENCE RUN`: loads both trajectories, refuses them unless they ran the same
/// scenario, input and sample times ([`differences`]; `allow_different` compares them anyway) and
/// measures the run against the reference ([`compare`]).
pub fn run(reference: &Path, run: &Path, allow_different: bool) -> Result<Compared, ScenarioError> {
    let reference = Trajectory::load(reference, "REFERENCE")?;
    let run = Trajectory::load(run, "RUN")?;
    let diffs = differences(&reference, &run);
    if !allow_different && !diffs.none() {
        let mut reasons = diffs.differ.clone();
        reasons.extend(diffs.unknown.iter().map(|u| format!("cannot tell {u}")));
        return Err(ScenarioError::invalid(
            "RUN",
            format!(
                "{}; a run approximates a reference only under the same scenario, input and sample times (--allow-different compares them anyway)",
                reasons.join("; ")
            ),
        ));
    }
    let comparison = compare(&reference, &run)?;
    let speed_ratio = speed_ratio(&reference, &run);
    let warnings = [("REFERENCE", &reference), ("RUN", &run)]
        .iter()
        .filter(|(_, t)| t.origin.sha256.is_empty())
        .map(|(field, t)| {
            format!(
                "{field} `{}` was written before gvsrom recorded content hashes: its files could not be checked for edits",
                t.dir.display()
            )
        })
        .collect();
    Ok(Compared {
        reference,
        run,
        differences: diffs,
        comparison,
        speed_ratio,
        warnings,
    })
}

impl Compared {
    /// The `--json` report of this comparison, its provenance made now.
    pub fn report(&self) -> Result<Report, ScenarioError> {
        Ok(Report {
            reference: Side::of(&self.reference),
            run: Side::of(&self.run),
            speed_ratio: self.speed_ratio,
            comparison: self.comparison.clone(),
            differ: self.differences.differ.clone(),
            unknown: self.differences.unknown.clone(),
            warnings: self.warnings.clone(),
            provenance: crate::provenance::Provenance::of_command()
                .compared(&self.reference.origin, &self.run.origin),
        })
    }
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
    // both measured from the reference's ξ*, so that `a − b` is the difference of the strains
    // themselves even where the two runs' reference strains differ (`differences` names that)
    let deviation = |tr: &Trajectory, k: usize, j: usize, c: usize| {
        tr.strain[(k * points + j) * 6 + c] - reference.strain_reference[j * 6 + c]
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
    let mut tip_start = 0.0;
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
        if k == 0 {
            tip_start = e;
        }
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
        tendon_length_mm: tendon_length_error(reference, run, n),
        samples: n,
        tip_mean: tip_sum / n as f64,
        tip_max,
        tip_max_t,
        tip_end,
        tip_start,
        strain_mean: (strained > 0).then(|| strain_sum / strained as f64),
        strain_max: (strained > 0).then_some(strain_max),
        active,
    })
}

/// [`Comparison::tendon_length_mm`] over the first `n` samples, if both record the same tendons'
/// lengths.
fn tendon_length_error(
    reference: &Trajectory,
    run: &Trajectory,
    n: usize,
) -> Option<TendonLengthError> {
    let ((na, a), (nb, b)) = (
        reference.tendon_lengths.as_ref()?,
        run.tendon_lengths.as_ref()?,
    );
    if na != nb || *na == 0 {
        return None;
    }
    let (mut sum, mut max, mut max_t) = (0.0, 0.0f64, reference.t[0]);
    for k in 0..n {
        for j in 0..*na {
            let e = 1e3 * (a[k * na + j] - b[k * na + j]).abs();
            sum += e;
            if e > max {
                (max, max_t) = (e, reference.t[k]);
            }
        }
    }
    Some(TendonLengthError {
        mean: sum / (n * na) as f64,
        max,
        max_t,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

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
            origin: crate::provenance::DirOrigin::unhashed(Path::new("x")),
            scenario: "s".into(),
            n_dof: 2,
            complete: true,
            wall_time_s: 1.0,
            length: 0.5,
            t: vec![0.0, 0.1, 0.2],
            tip: tip_x.iter().flat_map(|&x| [x, 0.0, 0.0]).collect(),
            strain,
            strain_x: vec![0.0, 0.5],
            strain_reference: STRAIGHT_STRAIN.repeat(2),
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
            tendon_paths: None,
            tendon_lengths: None,
            body_positions: None,
            tensions: None,
            tendon_rest_lengths: vec![],
            provenance: None,
            extrapolated: vec![],
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
        // no tendon lengths recorded: none compared
        assert_eq!(c.tendon_length_mm, None);
    }

    #[test]
    fn tendon_length_errors_are_the_absolute_differences_in_mm_by_hand() {
        // two tendons, three samples: |Δℓ| = 0, 0 | 1 mm, 3 mm | 0, 2 mm
        let with = |lengths: [f64; 6]| Trajectory {
            tendon_lengths: Some((2, lengths.to_vec())),
            ..trajectory([0.5, 0.4, 0.3], [[0.0, 0.0], [2.0, 4.0], [1.0, 1.0]])
        };
        let reference = with([0.3, 0.2, 0.299, 0.197, 0.298, 0.2]);
        let run = with([0.3, 0.2, 0.298, 0.2, 0.298, 0.198]);
        let e = compare(&reference, &run).unwrap().tendon_length_mm.unwrap();
        assert!((e.mean - 1.0).abs() < 1e-9, "mean {} mm", e.mean);
        assert!((e.max - 3.0).abs() < 1e-9 && e.max_t == 0.1, "{e:?}");
        // another tendon count, or lengths on one side only: not compared
        let three = Trajectory {
            tendon_lengths: Some((3, vec![0.3; 9])),
            ..run.clone()
        };
        assert_eq!(compare(&reference, &three).unwrap().tendon_length_mm, None);
        let bare = Trajectory {
            tendon_lengths: None,
            ..run
        };
        assert_eq!(compare(&reference, &bare).unwrap().tendon_length_mm, None);
    }

    /// `tr` as a rod pre-curved by `kappa` 1/m in bend-y: its reference strain and every strain
    /// shifted by it, so that its deviations `ξ − ξ*` are `tr`'s.
    fn precurved(mut tr: Trajectory, kappa: f64) -> Trajectory {
        for i in (1..tr.strain.len()).step_by(6) {
            tr.strain[i] += kappa;
        }
        for i in (1..tr.strain_reference.len()).step_by(6) {
            tr.strain_reference[i] += kappa;
        }
        tr
    }

    #[test]
    fn a_precurved_rods_errors_are_measured_from_its_reference_strain() {
        // the by-hand case above on a rod pre-curved by 20 1/m: the same errors, not errors
        // relative to the 20 1/m of the pre-curvature (0.5 / 24 = 2.1 % at t = 0.1)
        let reference = precurved(
            trajectory([0.5, 0.4, 0.3], [[0.0, 0.0], [2.0, 4.0], [1.0, 1.0]]),
            20.0,
        );
        let run = precurved(
            trajectory([0.5, 0.41, 0.3], [[0.0, 0.0], [2.0, 3.0], [1.0, 1.5]]),
            20.0,
        );
        let c = compare(&reference, &run).unwrap();
        assert_eq!(c.active, vec![1]);
        assert!((c.strain_mean.unwrap() - 18.75).abs() < 1e-12, "{c:?}");
        assert!((c.strain_max.unwrap() - 25.0).abs() < 1e-12, "{c:?}");
        assert!(differences(&reference, &run).none());
        // a run of a rod pre-curved otherwise is named, with both values
        let other = precurved(trajectory([0.5; 3], [[0.0; 2]; 3]), 10.0);
        let reference = precurved(trajectory([0.5; 3], [[0.0; 2]; 3]), 20.0);
        let d = differences(&reference, &other);
        assert!(
            d.differ.len() == 1
                && d.differ[0].contains("reference strains ξ*")
                && d.differ[0].contains("20 in REFERENCE, 10 in RUN"),
            "{d:?}"
        );
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
