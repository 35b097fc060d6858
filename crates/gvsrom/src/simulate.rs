//! A dynamics run of a built scenario: the actuation signal (the scenario's constant tensions, a CSV
//! file, the paper's random steps or actuator babbling), the initial state, the integrator, and the
//! trajectory written as NumPy arrays.
//!
//! Output directory (written as `DIR.partial` and renamed when complete; after a failed integration
//! the samples up to the failure are still written and `meta.json` says why it stopped):
//!
//! | file | shape | content |
//! |---|---|---|
//! | `t.npy` | (N,) | sample times [s] |
//! | `q.npy`, `qd.npy` | (N, n) | generalized coordinates and velocities |
//! | `u.npy` | (N, n_a) | tendon tensions [N] |
//! | `tip_position.npy` | (N, 3) | tip position [m] |
//! | `tip_rotation.npy` | (N, 3, 3) | tip rotation matrices (section → world) |
//! | `strain.npy` | (N, p, 6) | ξ at the p computational points, `[torsion, bend-y, bend-z, elongation, shear-y, shear-z]` |
//! | `strain_x.npy` | (p,) | abscissae of the computational points [m] |
//! | `meta.json` | | scenario, sizes, integrator statistics, wall time, real-time factor, error |

use crate::build::Built;
use crate::error::ScenarioError;
use crate::npy::write_npy;
use gvs::inputs::{babble, random_steps, Interpolation, Signal};
use gvs::solve::dynamics::{
    simulate_with_progress, InitialState, IntegratorOptions, Simulation, SimulationError,
};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Where the actuation comes from.
#[derive(Debug, Clone)]
pub enum InputSource {
    /// The scenario's tendon tensions, constant.
    Constant,
    /// A CSV file with columns `t, u_1, …, u_na` (a header line is allowed).
    Csv {
        path: PathBuf,
        interpolation: Interpolation,
    },
    /// New uniform random tensions in `[lo, hi]` for all actuators every `period` seconds.
    Steps {
        lo: f64,
        hi: f64,
        period: f64,
        seed: u64,
    },
    /// Actuator babbling: each actuator holds a uniform random value in `[lo, hi]` for a uniform random
    /// time in `[hold_min, hold_max]` (paper IV-C2).
    Babble {
        lo: f64,
        hi: f64,
        hold_min: f64,
        hold_max: f64,
        seed: u64,
    },
}

/// Options of a dynamics run.
#[derive(Debug, Clone)]
pub struct SimulateOptions {
    pub duration: f64,
    /// Output samples per second.
    pub sample_rate: f64,
    pub input: InputSource,
    /// Start at the static equilibrium under the scenario's tensions and loads (then switch to the
    /// input signal at t = 0) instead of straight at rest.
    pub start_at_equilibrium: bool,
    pub integrator: IntegratorOptions,
    /// A CSV file `t, λ` scaling all external loads and gravity over time (linear between rows).
    pub load_schedule: Option<PathBuf>,
}

fn positive(field: &str, v: f64, unit: &str) -> Result<f64, ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::value(
            field,
            v,
            format!("a finite number > 0 {unit}"),
        ))
    }
}

/// Builds the actuation signal of a run.
pub fn input_signal(built: &Built, opts: &SimulateOptions) -> Result<Signal, ScenarioError> {
    let na = built.model.n_actuators();
    let d = opts.duration;
    Ok(match &opts.input {
        InputSource::Constant => Signal::constant(&built.u),
        InputSource::Csv {
            path,
            interpolation,
        } => crate::csv_input::read_csv_signal(path, na, *interpolation)?,
        InputSource::Steps {
            lo,
            hi,
            period,
            seed,
        } => {
            range_check("--steps", *lo, *hi)?;
            random_steps(
                na,
                *lo,
                *hi,
                positive("--steps period", *period, "s")?,
                d,
                *seed,
            )
        }
        InputSource::Babble {
            lo,
            hi,
            hold_min,
            hold_max,
            seed,
        } => {
            range_check("--babble", *lo, *hi)?;
            positive("--babble hold_min", *hold_min, "s")?;
            if !(hold_max.is_finite() && hold_max >= hold_min) {
                return Err(ScenarioError::value(
                    "--babble hold_max",
                    *hold_max,
                    format!("a number >= hold_min = {hold_min} s"),
                ));
            }
            babble(na, *lo, *hi, *hold_min, *hold_max, d, *seed)
        }
    })
}

fn range_check(field: &str, lo: f64, hi: f64) -> Result<(), ScenarioError> {
    if lo.is_finite() && hi.is_finite() && lo <= hi {
        Ok(())
    } else {
        Err(ScenarioError::invalid(
            field,
            format!("range [{lo}, {hi}] must be finite with lo <= hi"),
        ))
    }
}

/// Runs the simulation; `progress(t)` is called at every sample.
pub fn run(
    built: &Built,
    opts: &SimulateOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<(Simulation, Signal), ScenarioError> {
    positive("--duration", opts.duration, "s")?;
    positive("--sample-rate", opts.sample_rate, "Hz")?;
    let n_samples = (opts.duration * opts.sample_rate).floor() as usize + 1;
    if n_samples > 10_000_000 {
        return Err(ScenarioError::value(
            "--sample-rate",
            opts.sample_rate,
            "at most 1e7 samples in all",
        ));
    }
    let t_out: Vec<f64> = (0..n_samples)
        .map(|k| k as f64 / opts.sample_rate)
        .collect();
    let signal = input_signal(built, opts)?;
    let initial = if opts.start_at_equilibrium {
        InitialState::Equilibrium {
            u: built.u.clone(),
            loads: built.loads.clone(),
        }
    } else {
        InitialState::Rest
    };
    let schedule = match &opts.load_schedule {
        Some(path) => Some(crate::csv_input::read_csv_signal(
            path,
            1,
            Interpolation::Linear,
        )?),
        None => None,
    };
    let sim = simulate_with_progress(
        &built.model,
        &signal,
        &built.loads,
        schedule.as_ref(),
        &initial,
        &t_out,
        &opts.integrator,
        progress,
    )
    .map_err(|e| match e {
        SimulationError::Model(m) => ScenarioError::from(m),
        SimulationError::Initial(s) => ScenarioError::invalid("initial equilibrium", s.to_string()),
    })?;
    Ok((sim, signal))
}

#[derive(Serialize)]
struct Meta<'a> {
    scenario: &'a str,
    n_dof: usize,
    n_points: usize,
    n_actuators: usize,
    samples: usize,
    t_end: f64,
    wall_time_s: f64,
    real_time_factor: f64,
    steps: usize,
    failed_steps: usize,
    rhs_evaluations: usize,
    jacobian_evaluations: usize,
    lu_decompositions: usize,
    /// `null` if the run completed; otherwise why it stopped (the arrays hold the samples before).
    error: Option<String>,
}

/// Writes the trajectory as `.npy` arrays plus `meta.json` into `dir` (atomically, via `dir.partial`).
pub fn write_trajectory(dir: &Path, built: &Built, sim: &Simulation) -> std::io::Result<()> {
    let tr = &sim.trajectory;
    let n = built.model.n_dof();
    let na = built.model.n_actuators();
    let np = built.model.disc.n_points();
    let ns = tr.t.len();
    let partial = dir.with_extension("partial");
    if partial.exists() {
        std::fs::remove_dir_all(&partial)?;
    }
    std::fs::create_dir_all(&partial)?;
    let save = |name: &str, shape: &[usize], data: Vec<f64>| -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(partial.join(name))?);
        write_npy(&mut f, shape, &data)?;
        std::io::Write::flush(&mut f)
    };
    save("t.npy", &[ns], tr.t.clone())?;
    save(
        "q.npy",
        &[ns, n],
        tr.q.iter().flat_map(|q| q.iter().copied()).collect(),
    )?;
    save(
        "qd.npy",
        &[ns, n],
        tr.qd.iter().flat_map(|q| q.iter().copied()).collect(),
    )?;
    save("u.npy", &[ns, na], tr.u.iter().flatten().copied().collect())?;
    save(
        "tip_position.npy",
        &[ns, 3],
        tr.tip
            .iter()
            .flat_map(|g| g.pos.iter().copied().collect::<Vec<_>>())
            .collect(),
    )?;
    save(
        "tip_rotation.npy",
        &[ns, 3, 3],
        tr.tip
            .iter()
            .flat_map(|g| (0..3).flat_map(move |i| (0..3).map(move |j| g.rot[(i, j)])))
            .collect(),
    )?;
    save(
        "strain.npy",
        &[ns, np, 6],
        tr.strain
            .iter()
            .flat_map(|s| s.iter().flat_map(|x| x.iter().copied().collect::<Vec<_>>()))
            .collect(),
    )?;
    save(
        "strain_x.npy",
        &[np],
        built.model.disc.points.iter().map(|p| p.x).collect(),
    )?;
    let meta = Meta {
        scenario: &built.name,
        n_dof: n,
        n_points: np,
        n_actuators: na,
        samples: ns,
        t_end: tr.t.last().copied().unwrap_or(0.0),
        wall_time_s: sim.wall_time_s,
        real_time_factor: sim.real_time_factor(),
        steps: sim.stats.steps,
        failed_steps: sim.stats.failed_steps,
        rhs_evaluations: sim.stats.rhs_evals,
        jacobian_evaluations: sim.stats.jacobian_evals,
        lu_decompositions: sim.stats.lu_decompositions,
        error: sim.error.as_ref().map(|e| e.to_string()),
    };
    std::fs::write(
        partial.join("meta.json"),
        serde_json::to_string_pretty(&meta)? + "\n",
    )?;
    if dir.exists() {
        std::fs::remove_dir_all(dir)?;
    }
    std::fs::rename(&partial, dir)
}
