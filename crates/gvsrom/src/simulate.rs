//! A dynamics run of a built scenario: the actuation signal (the scenario's constant tensions, a CSV
//! file, the paper's random steps or actuator babbling), the initial state, the integrator, and the
//! trajectory written as NumPy arrays.
//!
//! The samples stream to disk as they are computed (memory does not grow with the run's length),
//! through [`crate::output`]: into a hidden staging directory beside `DIR`, moved into place at the
//! end. A run that fails or is interrupted (SIGINT/SIGTERM) still writes the samples computed so far,
//! with `"complete": false`, the reason and the last time reached in `meta.json`.
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
//! | `centerline.npy` | (N, c, 3) | centreline positions [m] at the `c` abscissae `centerline_x` of `meta.json`, equally spaced in arc length from base to tip (`output.centerline_points`, `--centerline-points`), in the world frame as `statics --json` |
//! | `meta.json` | | manifest (`gvsrom`: format, version, files), scenario, `complete`, `reason`, `t_reached`, `t_requested`, `sample_rate`, sizes, integrator statistics, wall time, real-time factor, error, `input` ([`input_record`]), `physics` (material, geometry, base, tendon routing, loads), `centerline_x`, `provenance` ([`crate::provenance`]) |
//!
//! The integrator is chosen here too ([`choose_integrator`]): by the rod's damping unless named,
//! as `gvsrom simulate` and `gvsrom reproduce` both do.

use crate::build::Built;
use crate::error::ScenarioError;
use crate::npy::NpyRows;
use crate::output::{OutputDir, OutputError};
use gvs::inputs::{babble, random_steps, Actuation, Interpolation, Signal};
use gvs::lie::Pose;
use gvs::solve::dynamics::{
    simulate_streaming_interruptible, InitialState, IntegratorOptions, Method, OdeJacobian,
    RunSummary, Sample, SimulationError,
};
use gvs::solve::ode::{
    ErrorNorm, FixedStepOptions, GeneralizedAlphaOptions, MassRenewal, NdfOptions, SdirkOptions,
};
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// An actuation given as a function of time (Python's `input=` callable): the integrator evaluates
/// it wherever it needs `u(t)`, in any order; it checks its own values (count, finiteness) and has
/// no breakpoints. Nothing about it is checked before the run (its extremes are unknown).
#[derive(Clone)]
pub struct InputFunction(pub Arc<dyn Actuation + Send + Sync>);

impl std::fmt::Debug for InputFunction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("InputFunction(..)")
    }
}

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
    /// A signal given in memory (Python's `input=` array of rows `t, u_1, …, u_na`), checked
    /// as a CSV file's rows are.
    Rows(Signal),
    /// Actuator babbling: each actuator holds a uniform random value in `[lo, hi]` for a uniform random
    /// time in `[hold_min, hold_max]` (paper IV-C2).
    Babble {
        lo: f64,
        hi: f64,
        hold_min: f64,
        hold_max: f64,
        seed: u64,
    },
    /// A function of time ([`InputFunction`]).
    Function(InputFunction),
}

impl InputSource {
    /// The input of the command-line options `--input FILE [--interpolate]`, `--steps LO,HI,PERIOD`
    /// or `--babble LO,HI,HOLD_MIN,HOLD_MAX` (at most one), else the scenario's constant tensions.
    pub fn from_options(
        input: Option<&Path>,
        interpolate: bool,
        steps: Option<&[f64]>,
        babble: Option<&[f64]>,
        seed: u64,
    ) -> Result<InputSource, ScenarioError> {
        let count = |opt: &str, v: &[f64], n: usize, names: &str| {
            if v.len() == n {
                Ok(())
            } else {
                Err(ScenarioError::invalid(
                    opt,
                    format!("takes {n} comma-separated values {names}, got {}", v.len()),
                ))
            }
        };
        Ok(match (input, steps, babble) {
            (Some(path), None, None) => InputSource::Csv {
                path: path.to_path_buf(),
                interpolation: if interpolate {
                    Interpolation::Linear
                } else {
                    Interpolation::Hold
                },
            },
            (None, Some(v), None) => {
                count("--steps", v, 3, "LO,HI,PERIOD")?;
                InputSource::Steps {
                    lo: v[0],
                    hi: v[1],
                    period: v[2],
                    seed,
                }
            }
            (None, None, Some(v)) => {
                count("--babble", v, 4, "LO,HI,HOLD_MIN,HOLD_MAX")?;
                InputSource::Babble {
                    lo: v[0],
                    hi: v[1],
                    hold_min: v[2],
                    hold_max: v[3],
                    seed,
                }
            }
            (None, None, None) => InputSource::Constant,
            _ => {
                return Err(ScenarioError::invalid(
                    "--input/--steps/--babble",
                    "give at most one input option",
                ))
            }
        })
    }
}

/// The adaptive integrator asked for (`simulate --method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum MethodChoice {
    Auto,
    Ndf,
    Galpha,
    Sdirk,
}

/// The error test asked for (`simulate --error-norm`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ErrorNormChoice {
    /// Every coordinate to its own tolerance (ode15s).
    Componentwise,
    /// Positions and velocities in the mass-matrix norm (mass-weighted displacement).
    Mass,
}

impl ErrorNormChoice {
    fn norm(self) -> ErrorNorm {
        match self {
            ErrorNormChoice::Componentwise => ErrorNorm::Componentwise,
            ErrorNormChoice::Mass => ErrorNorm::Mass,
        }
    }
}

/// What the user asked of the integrator (`simulate --method --rtol --atol --max-order
/// --error-norm --rho-inf --fixed-step --fd-jacobian`); `None` and `Auto` leave the choice to
/// [`choose_integrator`]. The default is the command's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IntegratorChoice {
    pub method: MethodChoice,
    /// Relative tolerance; default 1e-3 (ode15s), or [`gvs::solve::dynamics::LIGHT_DAMPING_RTOL`]
    /// when the automatic method is SDIRK4.
    pub rtol: Option<f64>,
    pub atol: f64,
    /// Highest NDF order (1–5); default 5, or 2 for a lightly damped rod.
    pub max_order: Option<usize>,
    pub error_norm: Option<ErrorNormChoice>,
    /// Generalized-α: spectral radius at infinite frequency.
    pub rho_inf: f64,
    /// A fixed step `h` [s]: the fixed-step BDF2 instead of an adaptive method.
    pub fixed_step: Option<f64>,
    /// Finite differences of the first-order right-hand side for the Jacobian (`--fd-jacobian`);
    /// else the structured iteration matrix.
    pub fd_jacobian: bool,
}

impl Default for IntegratorChoice {
    fn default() -> Self {
        IntegratorChoice {
            method: MethodChoice::Auto,
            rtol: None,
            atol: 1e-6,
            max_order: None,
            error_norm: None,
            rho_inf: 0.8,
            fixed_step: None,
            fd_jacobian: false,
        }
    }
}

/// The integrator for `built` (with its reduced model, if attached) under `choice`, and the note
/// to print when the rod's damping chose it (`integrator …` line), else `None`.
///
/// - Jacobian: finite differences with `fd_jacobian`, else the structured one. A decoder's `M(q)`
///   varies strongly, so for it the NDF renews `M` at every attempt ([`MassRenewal::EveryAttempt`];
///   measured on IV-C2's AE-7, 10 s: 2289 steps, 322 failed, 0.27 s, against 2399 steps, 1009
///   failed, 0.31 s when renewed only when slow and 2267 steps, 414 failed, 0.38 s with the
///   first-order form's finite-difference Jacobian, 2r right-hand sides per Jacobian).
/// - Method: `fixed_step` gives the fixed-step BDF2; `galpha` and `sdirk` as named; `auto` and `ndf`
///   with a decoder are the NDF of orders ≤ 5 (SDIRK4, which renews `M` only with `D` and `K`,
///   failed 1864 of 2164 attempts in Newton on IV-C2's AE-2, 0.84 s against 0.1 s); `auto` and `ndf`
///   with the structured Jacobian and neither the NDF's order nor its norm given look at the rod's
///   damping ([`gvs::solve::dynamics::damping_regime`]): for a lightly damped rod (stiffest mode
///   underdamped) `auto` is SDIRK4 with the mass-norm error test at rtol 1e-4 and `ndf` the NDF of
///   orders ≤ 2 with the mass norm; otherwise the NDF of orders ≤ 5, componentwise (ode15s).
pub fn choose_integrator(
    built: &Built,
    choice: &IntegratorChoice,
) -> Result<(IntegratorOptions, Option<String>), ScenarioError> {
    check_tolerances(choice)?;
    let decoder = built
        .reduced
        .as_ref()
        .is_some_and(|r| !r.model.param.is_linear());
    let jacobian = if choice.fd_jacobian {
        OdeJacobian::FiniteDifference
    } else {
        OdeJacobian::Structured
    };
    let mut note = None;
    let rtol = choice.rtol.unwrap_or(NdfOptions::default().rtol);
    let atol = choice.atol;
    let error_norm = |default: ErrorNorm| choice.error_norm.map_or(default, ErrorNormChoice::norm);
    // the rod's damping chooses for `auto` and `ndf` unless the NDF's order or norm is given
    let ndf_choice = choice.max_order.is_some() || choice.error_norm.is_some();
    let regime = if choice.fixed_step.is_none()
        && matches!(choice.method, MethodChoice::Auto | MethodChoice::Ndf)
        && !ndf_choice
        && jacobian == OdeJacobian::Structured
        && !decoder
    {
        Some(match &built.reduced {
            Some(r) => gvs::solve::dynamics::damping_regime(&r.model)?,
            None => gvs::solve::dynamics::damping_regime(&built.model)?,
        })
    } else {
        None
    };
    let method = match (choice.fixed_step, choice.method) {
        (Some(h), _) => Method::Fixed(FixedStepOptions {
            h,
            ..FixedStepOptions::default()
        }),
        (None, MethodChoice::Galpha) => Method::GeneralizedAlpha(GeneralizedAlphaOptions {
            rtol,
            atol,
            rho_inf: choice.rho_inf,
            error_norm: error_norm(ErrorNorm::Componentwise),
            ..GeneralizedAlphaOptions::default()
        }),
        (None, MethodChoice::Sdirk) => Method::Sdirk(SdirkOptions {
            rtol,
            atol,
            error_norm: error_norm(ErrorNorm::Mass),
            ..SdirkOptions::default()
        }),
        (None, MethodChoice::Auto) if regime.is_some_and(|r| r.is_light()) => {
            let zeta = regime.map_or(0.0, |r| r.zeta_max);
            let rtol = choice
                .rtol
                .unwrap_or(gvs::solve::dynamics::LIGHT_DAMPING_RTOL);
            note = Some(format!(
                "integrator SDIRK4 (order 4, L-stable) with the mass-norm error test at rtol {rtol:e}: lightly damped (stiffest mode ζ = {zeta:.3}; --method or --rtol to choose)"
            ));
            Method::Sdirk(SdirkOptions {
                rtol,
                atol,
                error_norm: ErrorNorm::Mass,
                ..SdirkOptions::default()
            })
        }
        (None, MethodChoice::Ndf | MethodChoice::Auto) => {
            let base = NdfOptions {
                rtol,
                atol,
                max_order: choice.max_order.unwrap_or(5),
                error_norm: error_norm(ErrorNorm::Componentwise),
                mass_renewal: if decoder {
                    MassRenewal::EveryAttempt
                } else {
                    MassRenewal::WhenSlow
                },
                ..NdfOptions::default()
            };
            match regime {
                Some(regime) => {
                    if regime.is_light() {
                        note = Some(format!(
                            "integrator NDF orders ≤ 2 with the mass-norm error test: lightly damped (stiffest mode ζ = {:.3}; --max-order or --error-norm to choose)",
                            regime.zeta_max
                        ));
                    }
                    Method::Ndf(gvs::solve::dynamics::ndf_for_regime(&base, &regime))
                }
                None => Method::Ndf(base),
            }
        }
    };
    Ok((IntegratorOptions { method, jacobian }, note))
}

/// The integrator of a run as its provenance records it (`"integrator"`): the method that ran
/// with its tolerances and options (as [`choose_integrator`] resolved them) and what was
/// `requested` (the command's options).
pub fn integrator_record(
    options: &IntegratorOptions,
    requested: &IntegratorChoice,
) -> serde_json::Value {
    use serde_json::json;
    let norm = |n: ErrorNorm| match n {
        ErrorNorm::Componentwise => "componentwise",
        ErrorNorm::Mass => "mass",
    };
    let mut v = match &options.method {
        Method::Ndf(o) => json!({
            "rtol": o.rtol, "atol": o.atol, "max_order": o.max_order, "bdf": o.bdf,
            "error_norm": norm(o.error_norm),
            "mass_renewal": match o.mass_renewal {
                MassRenewal::WhenSlow => "when_slow",
                MassRenewal::EveryAttempt => "every_attempt",
            },
            "max_steps": o.max_steps,
        }),
        Method::Fixed(o) => {
            json!({"h": o.h, "newton_tol": o.newton_tol, "max_newton": o.max_newton})
        }
        Method::GeneralizedAlpha(o) => json!({
            "rtol": o.rtol, "atol": o.atol, "rho_inf": o.rho_inf,
            "error_norm": norm(o.error_norm), "max_steps": o.max_steps,
        }),
        Method::Sdirk(o) => json!({
            "rtol": o.rtol, "atol": o.atol, "error_norm": norm(o.error_norm),
            "max_steps": o.max_steps,
        }),
    };
    v["method"] = json!(options.method.name());
    v["jacobian"] = json!(match options.jacobian {
        OdeJacobian::FiniteDifference => "finite_difference",
        OdeJacobian::Structured => "structured",
    });
    v["requested"] = serde_json::to_value(requested).unwrap_or(serde_json::Value::Null);
    v
}

/// Smallest `--atol` accepted: `1e-14 ≈ 45 ε`. The coordinates of a rod (strain coefficients
/// in 1/m, reduced coordinates, and their rates) are of order 1e-3 … 1e2 in the presets and carry
/// a round-off of `ε` times their scale; a run from rest starts at `q = 0`, where the absolute
/// tolerance alone bounds the error, so below about `10 ε` the error test and Newton's ask for
/// digits no iteration delivers (measured on the single-tendon arm at `--rtol 1e-12`: SDIRK4 took
/// 1371 steps for the first millisecond at `--atol 1e-16`, made no progress in 10 minutes at
/// `--rtol 1e-30 --atol 1e-30`; the NDF failed in Newton at `--atol 1e-30`). The library takes
/// any `atol > 0` (its units are the problem's); `--rtol` is bounded as the library bounds it,
/// [[`gvs::solve::ode::MIN_RTOL`], [`gvs::solve::ode::MAX_RTOL`]).
pub const MIN_ATOL: f64 = 1e-14;

/// `--rtol` in [[`gvs::solve::ode::MIN_RTOL`], [`gvs::solve::ode::MAX_RTOL`]) and `--atol` finite
/// and at least [`MIN_ATOL`].
fn check_tolerances(choice: &IntegratorChoice) -> Result<(), ScenarioError> {
    use gvs::solve::ode::{MAX_RTOL, MIN_RTOL};
    if let Some(rtol) = choice.rtol {
        if !(MIN_RTOL..MAX_RTOL).contains(&rtol) {
            return Err(ScenarioError::value(
                "--rtol",
                rtol,
                format!(
                    "a number in [{MIN_RTOL:e}, {MAX_RTOL}); below {MIN_RTOL:e} the error estimates are round-off"
                ),
            ));
        }
    }
    if !(choice.atol >= MIN_ATOL && choice.atol.is_finite()) {
        return Err(ScenarioError::value(
            "--atol",
            choice.atol,
            format!(
                "a finite number >= {MIN_ATOL:e}; below it the coordinates' round-off exceeds the tolerance"
            ),
        ));
    }
    Ok(())
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

/// Builds the actuation signal of a run. A function input ([`InputSource::Function`]) has none: the
/// scenario's constant tensions stand for it in the checks before the run.
pub fn input_signal(built: &Built, opts: &SimulateOptions) -> Result<Signal, ScenarioError> {
    let na = built.model.n_actuators();
    let d = opts.duration;
    Ok(match &opts.input {
        InputSource::Constant => Signal::constant(&built.u),
        InputSource::Csv {
            path,
            interpolation,
        } => {
            crate::scenario::check_regular_file("--input", path)?;
            let signal = crate::csv_input::read_csv_signal(path, na, *interpolation)?;
            covers_start("--input", path, &signal, RUN_START)?;
            signal
        }
        InputSource::Rows(signal) => {
            signal.validate("input", na)?;
            covers_start("input", Path::new("input"), signal, RUN_START)?;
            signal.clone()
        }
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
        InputSource::Function(_) => Signal::constant(&built.u),
    })
}

/// Every run starts at t = 0 (its first sample).
const RUN_START: f64 = 0.0;

/// Refuses a signal read from `path` (option `field`) whose first row comes after the run's start
/// `t0`: before its first row the signal would silently hold that row's values.
fn covers_start(field: &str, path: &Path, signal: &Signal, t0: f64) -> Result<(), ScenarioError> {
    match signal.times.first() {
        Some(&first) if first > t0 => Err(ScenarioError::invalid(
            field,
            format!(
                "`{}` starts at t = {} s, after the run's start t = {} s; the input before its first row is not given (add a row at t = {})",
                path.display(),
                gvs::error::fmt_value(first),
                gvs::error::fmt_value(t0),
                gvs::error::fmt_value(t0)
            ),
        )),
        _ => Ok(()),
    }
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

/// Most output samples of one run.
pub const MAX_SAMPLES: usize = 10_000_000;
/// Most steps of one fixed-step run (`--duration / --fixed-step`).
pub const MAX_FIXED_STEPS: f64 = 1e7;
/// Most input switches of a random-step or babbling signal (`--duration / period`).
pub const MAX_INPUT_SWITCHES: f64 = 1e7;
/// Largest trajectory one run writes [bytes] (16 GiB).
pub const MAX_OUTPUT_BYTES: f64 = 16.0 * 1024.0 * 1024.0 * 1024.0;

/// The output times `t_k = k / rate` for `t_k ≤ duration`, followed by `duration` itself when it is
/// not a multiple of the sample period, so the last sample is always at `duration`.
pub fn sample_times(duration: f64, rate: f64) -> Result<Vec<f64>, ScenarioError> {
    positive("--duration", duration, "s")?;
    positive("--sample-rate", rate, "Hz")?;
    let periods = (duration * rate * (1.0 + 4.0 * f64::EPSILON)).floor();
    if !periods.is_finite() || periods >= (MAX_SAMPLES - 1) as f64 {
        return Err(ScenarioError::invalid(
            "--duration",
            format!(
                "{} s at --sample-rate {} Hz gives {:.2e} samples (accepted <= {MAX_SAMPLES}); lower --duration or --sample-rate",
                gvs::error::fmt_value(duration),
                gvs::error::fmt_value(rate),
                periods + 1.0
            ),
        ));
    }
    let m = periods as usize;
    let mut t: Vec<f64> = (0..=m).map(|k| k as f64 / rate).collect();
    let last = t[m];
    if last > duration {
        t[m] = duration; // rounding put k/rate a hair past the end
    } else if duration - last > 1e-9 * duration.max(1.0) / rate.max(1.0) {
        t.push(duration);
    }
    Ok(t)
}

/// A run checked before anything is computed or written: its sample times, actuation, load schedule
/// and initial state. Inputs whose loads or tensions lie far beyond the rod's elastic range are
/// refused here (see [`crate::plausibility`]).
pub struct Plan {
    pub t_out: Vec<f64>,
    pub signal: Signal,
    pub schedule: Option<Signal>,
    pub initial: InitialState,
    /// Output samples per second.
    pub sample_rate: f64,
    /// What `meta.json` records of the run's input ([`input_record`]).
    pub input: serde_json::Value,
    /// How the input signal lies outside a reduced model's training inputs, when used with
    /// `--extrapolate` (`Reduced::check_signal`; without it such a signal is refused).
    pub model_extrapolated: Vec<String>,
    /// A function input, which the run evaluates in place of `signal`.
    pub function: Option<InputFunction>,
}

impl Plan {
    /// The actuation the integrator evaluates: the function input, else the signal.
    pub fn actuation(&self) -> &dyn Actuation {
        match &self.function {
            Some(f) => f.0.as_ref(),
            None => &self.signal,
        }
    }
}

/// Validates `opts` against `built` and builds the [`Plan`] of the run.
pub fn plan(built: &Built, opts: &SimulateOptions) -> Result<Plan, ScenarioError> {
    let t_out = sample_times(opts.duration, opts.sample_rate)?;
    if let Method::Fixed(f) = &opts.integrator.method {
        let h = positive("--fixed-step", f.h, "s")?;
        if opts.duration / h > MAX_FIXED_STEPS {
            return Err(ScenarioError::invalid(
                "--fixed-step",
                format!(
                    "{} s over --duration {} s is {:.2e} steps (accepted <= {}); use a larger step or the adaptive integrator",
                    gvs::error::fmt_value(h),
                    gvs::error::fmt_value(opts.duration),
                    opts.duration / h,
                    gvs::error::fmt_value(MAX_FIXED_STEPS)
                ),
            ));
        }
    }
    let switch_period = match &opts.input {
        InputSource::Steps { period, .. } => Some(("--steps period", *period)),
        InputSource::Babble { hold_min, .. } => Some(("--babble hold_min", *hold_min)),
        _ => None,
    };
    if let Some((field, p)) = switch_period {
        let p = positive(field, p, "s")?;
        if opts.duration / p > MAX_INPUT_SWITCHES {
            return Err(ScenarioError::invalid(
                field,
                format!(
                    "{} s over --duration {} s is {:.2e} input switches (accepted <= {})",
                    gvs::error::fmt_value(p),
                    gvs::error::fmt_value(opts.duration),
                    opts.duration / p,
                    gvs::error::fmt_value(MAX_INPUT_SWITCHES)
                ),
            ));
        }
    }
    let signal = input_signal(built, opts)?;
    // a reduced model answers only for tensions it was trained on: the signal's, at its knots
    // (where a held or linear signal takes its extremes) and at both ends of the run
    let model_extrapolated = match (&built.reduced, &opts.input) {
        (Some(r), input) if !matches!(input, InputSource::Constant | InputSource::Function(_)) => {
            let end = t_out.last().copied().unwrap_or(0.0);
            let mut times: Vec<f64> = signal
                .times
                .iter()
                .copied()
                .filter(|t| (0.0..=end).contains(t))
                .chain([0.0, end])
                .collect();
            times.sort_by(f64::total_cmp);
            let mut u = vec![0.0; signal.channels()];
            r.check_signal(&times, |t| {
                signal.eval(t, &mut u);
                u.clone()
            })?
        }
        _ => vec![],
    };
    let schedule = match &opts.load_schedule {
        Some(path) => {
            crate::scenario::check_regular_file("--load-schedule", path)?;
            let s = crate::csv_input::read_csv_signal(path, 1, Interpolation::Linear)?;
            covers_start("--load-schedule", path, &s, t_out[0])?;
            Some(s)
        }
        None => None,
    };
    let u_max = crate::csv_input::max_abs_per_column(&signal);
    let lambda_max = schedule
        .as_ref()
        .map(|s| crate::csv_input::max_abs_per_column(s)[0])
        .unwrap_or(1.0);
    crate::plausibility::check(built, &u_max, lambda_max)?;
    let initial = if opts.start_at_equilibrium {
        InitialState::Equilibrium {
            u: built.u.clone(),
            loads: built.loads.clone(),
        }
    } else {
        InitialState::Rest
    };
    let input = input_record(built, opts)?;
    Ok(Plan {
        t_out,
        signal,
        schedule,
        initial,
        sample_rate: opts.sample_rate,
        input,
        model_extrapolated,
        function: match &opts.input {
            InputSource::Function(f) => Some(f.clone()),
            _ => None,
        },
    })
}

/// The run's input as `meta.json` records it (`"input"`), for `gvsrom compare` to tell runs with
/// other inputs apart: the signal's specification — `"constant"` with the tensions, `"csv"` with
/// the file, its SHA-256 and the interpolation, `"steps"` or `"babble"` with their parameters and
/// seed —, the start (`"rest"`, or `"equilibrium"` with the tensions it is solved under) and the
/// load schedule (file and SHA-256, or null).
pub fn input_record(
    built: &Built,
    opts: &SimulateOptions,
) -> Result<serde_json::Value, ScenarioError> {
    use serde_json::json;
    let file = |field: &str, path: &Path| -> Result<serde_json::Value, ScenarioError> {
        Ok(json!({
            "file": path.display().to_string(),
            "sha256": crate::csv_input::file_sha256(field, path)?,
        }))
    };
    let mut signal = match &opts.input {
        InputSource::Constant => json!({"signal": "constant", "tensions": built.u}),
        InputSource::Csv {
            path,
            interpolation,
        } => {
            let mut v = file("--input", path)?;
            v["signal"] = json!("csv");
            v["interpolation"] = json!(match interpolation {
                Interpolation::Hold => "hold",
                Interpolation::Linear => "linear",
            });
            v
        }
        InputSource::Rows(signal) => json!({
            "signal": "rows",
            "rows": signal.times.len(),
            "interpolation": match signal.interpolation {
                Interpolation::Hold => "hold",
                Interpolation::Linear => "linear",
            },
        }),
        InputSource::Steps {
            lo,
            hi,
            period,
            seed,
        } => json!({
            "signal": "steps", "lo": lo, "hi": hi, "period": period, "seed": seed,
        }),
        InputSource::Babble {
            lo,
            hi,
            hold_min,
            hold_max,
            seed,
        } => json!({
            "signal": "babble", "lo": lo, "hi": hi, "hold_min": hold_min, "hold_max": hold_max,
            "seed": seed,
        }),
        InputSource::Function(_) => json!({"signal": "function"}),
    };
    if opts.start_at_equilibrium {
        signal["start"] = json!("equilibrium");
        signal["start_tensions"] = json!(built.u);
    } else {
        signal["start"] = json!("rest");
    }
    signal["load_schedule"] = match &opts.load_schedule {
        Some(path) => file("--load-schedule", path)?,
        None => serde_json::Value::Null,
    };
    Ok(signal)
}

/// The scenario's physics as `meta.json` records it (`"physics"`), for `gvsrom compare`: the
/// material, the divisions' geometry, the base pose, the tendons' routing and friction, and the
/// loads (gravity, point and distributed wrenches). Not the tensions (the input), not the strain
/// basis nor the computational points (the discretization, which a reduced model replaces).
fn physics_record(built: &Built) -> serde_json::Value {
    let m = &built.model;
    let rot: Vec<[f64; 3]> = (0..3)
        .map(|i| [m.base.rot[(i, 0)], m.base.rot[(i, 1)], m.base.rot[(i, 2)]])
        .collect();
    serde_json::json!({
        "material": m.rod.material,
        "divisions": m.rod.divisions,
        "base": {"position": [m.base.pos[0], m.base.pos[1], m.base.pos[2]], "rotation": rot},
        "tendons": m.tendons,
        "loads": built.loads,
    })
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// Every sample up to the requested duration was computed.
    Complete,
    /// Stopped on request (an interrupt) after the last sample delivered.
    Interrupted { reason: String },
    /// The integrator failed; the samples before the failure were delivered.
    Failed { error: String },
}

/// The result of [`run`]: the summary of the streamed simulation and the last sample's tip.
#[derive(Debug)]
pub struct Outcome {
    pub summary: RunSummary,
    pub ending: Ending,
    /// Tip pose of the last sample.
    pub last_tip: Option<Pose>,
    /// The run failed because a reduced trajectory left its training region (the decoder would
    /// extrapolate), not because the integrator did.
    pub left_training_region: bool,
}

impl Outcome {
    /// Simulated time per wall-clock time.
    pub fn real_time_factor(&self) -> f64 {
        self.summary.t_last.unwrap_or(0.0) / self.summary.wall_time_s.max(1e-12)
    }
}

/// Runs the planned simulation, streaming each sample to `writer` (if any) and calling
/// `control(t)` after each and before every step attempt of the integrator (with `t` the last
/// sample's time): returning `ControlFlow::Break(reason)` interrupts the run within one step (the
/// samples so far are kept), however far the next sample is. A failed write stops the run with an
/// error.
pub fn run(
    built: &Built,
    plan: &Plan,
    integrator: &IntegratorOptions,
    writer: Option<&mut TrajectoryWriter>,
    control: &mut dyn FnMut(f64) -> ControlFlow<String>,
) -> Result<Outcome, ScenarioError> {
    let sink = writer.map(|w| w as &mut dyn SampleSink);
    run_into(built, plan, integrator, sink, control)
}

/// Where [`run_into`] delivers the samples: a [`TrajectoryWriter`] (files) or a
/// [`TrajectoryBuffer`] (memory).
pub trait SampleSink {
    /// Appends one sample of the run of `built`.
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()>;
}

impl SampleSink for TrajectoryWriter {
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        TrajectoryWriter::push(self, built, s)
    }
}

/// [`run`] with the samples delivered to any [`SampleSink`].
pub fn run_into(
    built: &Built,
    plan: &Plan,
    integrator: &IntegratorOptions,
    mut writer: Option<&mut dyn SampleSink>,
    control: &mut dyn FnMut(f64) -> ControlFlow<String>,
) -> Result<Outcome, ScenarioError> {
    let mut last_tip = None;
    let mut write_error: Option<std::io::Error> = None;
    let mut off_manifold = None;
    // `control` is called from the sink and from the integrator's per-attempt poll, never nested
    let control = std::cell::RefCell::new(control);
    let interrupted = std::cell::RefCell::new(None::<String>);
    let last_t = std::cell::Cell::new(plan.t_out.first().copied().unwrap_or(0.0));
    let check = |t: f64| {
        let flow = (*control.borrow_mut())(t);
        if let ControlFlow::Break(reason) = &flow {
            *interrupted.borrow_mut() = Some(reason.clone());
        }
        flow
    };
    let stop = || match check(last_t.get()) {
        ControlFlow::Break(reason) => Some(reason),
        ControlFlow::Continue(()) => None,
    };
    let mut sink = |s: &Sample<'_>| {
        last_t.set(s.t);
        last_tip = Some(*s.tip);
        if let Some(w) = writer.as_deref_mut() {
            if let Err(e) = w.push(built, s) {
                let msg = format!("cannot write the trajectory: {e}");
                write_error = Some(e);
                return ControlFlow::Break(msg);
            }
        }
        // A reduced trajectory far outside its training encodings is off the learned manifold
        // (the decoder saturates, `Ψ_q → 0`, `M → 0`): stop there with the reason rather than
        // integrating a spurious motion until Newton fails.
        if let Some(v) = built.reduced.as_ref().and_then(|r| r.range_violation(s.q)) {
            let msg = format!(
                "the reduced trajectory left the training region at t = {:.4} s: {v}; the decoder extrapolates there (an input outside the dataset, or a poor model)",
                s.t
            );
            off_manifold = Some(msg.clone());
            return ControlFlow::Break(msg);
        }
        check(s.t)
    };
    let summary = match &built.reduced {
        Some(r) => simulate_streaming_interruptible(
            &r.model,
            plan.actuation(),
            &built.loads,
            plan.schedule.as_ref(),
            &plan.initial,
            &plan.t_out,
            integrator,
            &mut sink,
            &stop,
        ),
        None => simulate_streaming_interruptible(
            &built.model,
            plan.actuation(),
            &built.loads,
            plan.schedule.as_ref(),
            &plan.initial,
            &plan.t_out,
            integrator,
            &mut sink,
            &stop,
        ),
    }
    .map_err(|e| match e {
        SimulationError::Model(m) => ScenarioError::from(m),
        SimulationError::Initial(s) => ScenarioError::invalid(
            "--from-equilibrium",
            format!(
                "the initial equilibrium failed: {s}{}",
                crate::plausibility::largest_load(built, &built.u, 1.0)
                    .map(|l| format!("; {l}"))
                    .unwrap_or_default()
            ),
        ),
    })?;
    if let Some(e) = write_error {
        return Err(ScenarioError::invalid(
            "--out",
            format!(
                "cannot write the trajectory at t = {}: {e}",
                summary.t_last.unwrap_or(0.0)
            ),
        ));
    }
    let left_training_region = summary.error.is_some() && off_manifold.is_some();
    let ending = match (&summary.error, off_manifold, interrupted.into_inner()) {
        (None, _, _) => Ending::Complete,
        (Some(_), Some(error), _) => Ending::Failed { error },
        (Some(_), None, Some(reason)) => Ending::Interrupted { reason },
        (Some(e), None, None) => Ending::Failed {
            error: e.to_string(),
        },
    };
    Ok(Outcome {
        summary,
        ending,
        last_tip,
        left_training_region,
    })
}

/// A trajectory kept in memory (the arrays of the files a [`TrajectoryWriter`] writes, row-major,
/// one row per sample): what the Python binding returns.
pub struct TrajectoryBuffer {
    pub t: Vec<f64>,
    /// `samples × n`.
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    /// `samples × n_a`.
    pub u: Vec<f64>,
    /// `samples × 3`.
    pub tip_position: Vec<f64>,
    /// `samples × 3 × 3`.
    pub tip_rotation: Vec<f64>,
    /// `samples × p × 6`.
    pub strain: Vec<f64>,
    /// `samples × c × 3`, at [`Self::centerline_x`].
    pub centerline: Vec<f64>,
    shape: Centerline,
}

impl TrajectoryBuffer {
    /// An empty trajectory of the run of `built`.
    pub fn new(built: &Built) -> Self {
        TrajectoryBuffer {
            t: vec![],
            q: vec![],
            qd: vec![],
            u: vec![],
            tip_position: vec![],
            tip_rotation: vec![],
            strain: vec![],
            centerline: vec![],
            shape: Centerline::new(built),
        }
    }

    /// Abscissae of the centreline samples [m].
    pub fn centerline_x(&self) -> &[f64] {
        &self.shape.x
    }
}

impl SampleSink for TrajectoryBuffer {
    fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        if s.q.len() != self.shape.q.len() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "a sample of another model's coordinates",
            ));
        }
        self.shape.sample(built, s.q);
        self.centerline.extend_from_slice(&self.shape.points);
        self.t.push(s.t);
        self.q.extend_from_slice(s.q);
        self.qd.extend_from_slice(s.qd);
        self.u.extend_from_slice(s.u);
        self.tip_position.extend(s.tip.pos.iter().copied());
        let r = &s.tip.rot;
        self.tip_rotation
            .extend((0..3).flat_map(|i| (0..3).map(move |j| r[(i, j)])));
        self.strain
            .extend(s.strain.iter().flat_map(|xi| xi.iter().copied()));
        Ok(())
    }
}

/// Why [`run_to_dir`] could not run or write a trajectory.
#[derive(Debug, thiserror::Error)]
pub enum TrajectoryError {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// A run written to a trajectory directory by [`run_to_dir`].
#[derive(Debug)]
pub struct Written {
    pub outcome: Outcome,
    /// The trajectory directory, in place.
    pub dir: PathBuf,
    /// Samples written.
    pub samples: usize,
}

/// `gvsrom simulate … --out DIR` without the printing: plans the run ([`plan`], the output size),
/// stages the trajectory at `out` (`force`: replacing an earlier gvsrom output there), runs it
/// ([`run`], `control` as there) and moves it into place. A run that ended early is written too,
/// marked partial; `outcome.ending` says why. `provenance` (without the input and sampling, which
/// are added here) is recorded in `meta.json`.
pub fn run_to_dir(
    built: &Built,
    opts: &SimulateOptions,
    out: &Path,
    force: bool,
    provenance: Option<crate::provenance::Provenance>,
    control: &mut dyn FnMut(f64) -> ControlFlow<String>,
) -> Result<Written, TrajectoryError> {
    let plan = plan(built, opts)?;
    check_output_size(built, &plan)?;
    let mut writer = TrajectoryWriter::create(out, force, built)?;
    if let Some(p) = provenance {
        let p = p
            .input(plan.input.clone())
            .sampling(opts.duration, opts.sample_rate);
        writer.set_provenance(&p);
    }
    let outcome = run(built, &plan, &opts.integrator, Some(&mut writer), control)?;
    let samples = writer.samples();
    let dir = writer.finish(built, &plan, &outcome)?;
    Ok(Written {
        outcome,
        dir,
        samples,
    })
}

/// Bytes written per sample: `t`, `q`, `q̇`, `u`, tip position and rotation, strains, centreline
/// (f64 each).
fn bytes_per_sample(built: &Built) -> f64 {
    let m = &built.model;
    let c = built.centerline_points.max(2);
    8.0 * (1 + 2 * built.n_dof() + m.n_actuators() + 3 + 9 + 6 * m.disc.n_points() + 3 * c) as f64
}

/// Refuses a trajectory larger than [`MAX_OUTPUT_BYTES`] before anything is computed.
pub fn check_output_size(built: &Built, plan: &Plan) -> Result<(), ScenarioError> {
    let bytes = plan.t_out.len() as f64 * bytes_per_sample(built);
    if bytes > MAX_OUTPUT_BYTES {
        return Err(ScenarioError::invalid(
            "--out",
            format!(
                "the trajectory would take {:.1} GB ({} samples of {} kB; accepted <= {:.1} GB); lower --duration or --sample-rate",
                bytes / 1e9,
                plan.t_out.len(),
                bytes_per_sample(built) / 1e3,
                MAX_OUTPUT_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

/// A trajectory being written sample by sample into an output directory (see the module
/// documentation for the files). Memory does not depend on the number of samples.
pub struct TrajectoryWriter {
    dir: OutputDir,
    t: NpyRows,
    q: NpyRows,
    qd: NpyRows,
    u: NpyRows,
    tip_position: NpyRows,
    tip_rotation: NpyRows,
    strain: NpyRows,
    centerline: NpyRows,
    shape: Centerline,
    provenance: Option<serde_json::Value>,
}

/// The centreline of each sample: the forward kinematics of the model that runs (the reduced one
/// shares the scenario's rod and points) at `q`, sampled at `x` — buffers allocated once, before
/// the run.
struct Centerline {
    /// Abscissae `x_k = L k / (c − 1)`, `k = 0 … c − 1` [m].
    x: Vec<f64>,
    q: nalgebra::DVector<f64>,
    ws: gvs::model::Workspace,
    /// `c × 3` positions of the current sample.
    points: Vec<f64>,
}

impl Centerline {
    fn new(built: &Built) -> Self {
        let (n, ws) = match &built.reduced {
            Some(r) => (r.model.n_dof(), r.model.workspace()),
            None => (built.model.n_dof(), built.model.workspace()),
        };
        let c = built.centerline_points.max(2);
        Centerline {
            x: crate::statics::centerline_abscissae(built.model.disc.length(), c),
            q: nalgebra::DVector::zeros(n),
            ws,
            points: vec![0.0; 3 * c],
        }
    }

    /// The centreline at `q` into [`Self::points`].
    fn sample(&mut self, built: &Built, q: &[f64]) {
        self.q.as_mut_slice().copy_from_slice(q);
        match &built.reduced {
            Some(r) => self.fill(&r.model),
            None => self.fill(&built.model),
        }
    }

    fn fill<P: gvs::strain::StrainParam>(&mut self, model: &gvs::model::Model<P>) {
        model.forward(&self.q, &mut self.ws, false);
        for (k, &x) in self.x.iter().enumerate() {
            let p = model.position_at(&self.ws, x);
            self.points[3 * k..3 * k + 3].copy_from_slice(&[p[0], p[1], p[2]]);
        }
    }
}

impl TrajectoryWriter {
    /// Opens the output directory `path` (refusing unsafe targets, see [`crate::output`]) and the
    /// arrays, before the run starts.
    pub fn create(path: &Path, force: bool, built: &Built) -> Result<Self, OutputError> {
        let mut dir = OutputDir::create("--out", path, "trajectory", force)?;
        let m = &built.model;
        let (n, na, np) = (built.n_dof(), m.n_actuators(), m.disc.n_points());
        let shape = Centerline::new(built);
        let nc = shape.x.len();
        let open = |dir: &mut OutputDir| -> std::io::Result<_> {
            Ok((
                NpyRows::new(dir, "t.npy", &[])?,
                NpyRows::new(dir, "q.npy", &[n])?,
                NpyRows::new(dir, "qd.npy", &[n])?,
                NpyRows::new(dir, "u.npy", &[na])?,
                NpyRows::new(dir, "tip_position.npy", &[3])?,
                NpyRows::new(dir, "tip_rotation.npy", &[3, 3])?,
                NpyRows::new(dir, "strain.npy", &[np, 6])?,
                NpyRows::new(dir, "centerline.npy", &[nc, 3])?,
            ))
        };
        let (t, q, qd, u, tip_position, tip_rotation, strain, centerline) =
            open(&mut dir).map_err(|e| dir.io_error("create the trajectory files", e))?;
        Ok(TrajectoryWriter {
            dir,
            t,
            q,
            qd,
            u,
            tip_position,
            tip_rotation,
            strain,
            centerline,
            shape,
            provenance: None,
        })
    }

    /// Records how the run was made in `meta.json` (`"provenance"`, [`crate::provenance`]).
    pub fn set_provenance(&mut self, provenance: &crate::provenance::Provenance) {
        self.provenance = serde_json::to_value(provenance).ok();
    }

    /// Appends one sample of the run of `built` (the model that runs computes its centreline).
    pub fn push(&mut self, built: &Built, s: &Sample<'_>) -> std::io::Result<()> {
        if s.q.len() != self.shape.q.len() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                format!(
                    "a sample of {} coordinates for a trajectory of {}",
                    s.q.len(),
                    self.shape.q.len()
                ),
            ));
        }
        self.shape.sample(built, s.q);
        self.centerline.push(self.shape.points.iter().copied())?;
        self.t.push([s.t])?;
        self.q.push(s.q.iter().copied())?;
        self.qd.push(s.qd.iter().copied())?;
        self.u.push(s.u.iter().copied())?;
        self.tip_position.push(s.tip.pos.iter().copied())?;
        let r = &s.tip.rot;
        self.tip_rotation
            .push((0..3).flat_map(|i| (0..3).map(move |j| r[(i, j)])))?;
        self.strain
            .push(s.strain.iter().flat_map(|xi| xi.iter().copied()))
    }

    /// Samples written so far.
    pub fn samples(&self) -> usize {
        self.t.rows()
    }

    /// Completes the arrays, writes `meta.json` (with `"complete"`, the reason for an early end,
    /// the last time reached, and the plan's sample rate and input record) and moves the directory
    /// into place.
    pub fn finish(
        self,
        built: &Built,
        plan: &Plan,
        outcome: &Outcome,
    ) -> Result<PathBuf, OutputError> {
        let requested_end = plan.t_out.last().copied().unwrap_or(0.0);
        let TrajectoryWriter {
            mut dir,
            t,
            q,
            qd,
            u,
            tip_position,
            tip_rotation,
            strain,
            centerline,
            shape,
            provenance,
        } = self;
        let samples = t.rows();
        let arrays = [t, q, qd, u, tip_position, tip_rotation, strain, centerline];
        (|| -> std::io::Result<()> {
            for a in arrays {
                a.finish(&mut dir)?;
            }
            crate::npy::write_array(
                &mut dir,
                "strain_x.npy",
                &[built.model.disc.n_points()],
                &built
                    .model
                    .disc
                    .points
                    .iter()
                    .map(|p| p.x)
                    .collect::<Vec<_>>(),
            )
        })()
        .map_err(|e| dir.io_error("write the trajectory arrays", e))?;
        let sm = &outcome.summary;
        let (complete, reason, error) = match &outcome.ending {
            Ending::Complete => (true, None, None),
            Ending::Interrupted { reason } => (false, Some(reason.clone()), None),
            Ending::Failed { error } => (
                false,
                Some("the integration failed".into()),
                Some(error.clone()),
            ),
        };
        let meta = Meta {
            scenario: &built.name,
            complete,
            reason,
            t_reached: sm.t_last,
            t_requested: requested_end,
            sample_rate: plan.sample_rate,
            samples,
            n_dof: built.n_dof(),
            n_points: built.model.disc.n_points(),
            n_actuators: built.model.n_actuators(),
            length: built.model.rod.length(),
            wall_time_s: sm.wall_time_s,
            real_time_factor: outcome.real_time_factor(),
            steps: sm.stats.steps,
            failed_steps: sm.stats.failed_steps,
            newton_failures: sm.stats.newton_failures,
            rhs_evaluations: sm.stats.rhs_evals,
            jacobian_evaluations: sm.stats.jacobian_evals,
            lu_decompositions: sm.stats.lu_decompositions,
            error,
            input: &plan.input,
            physics: physics_record(built),
            model_extrapolated: built
                .reduced
                .iter()
                .flat_map(|r| r.extrapolated.iter())
                .chain(&plan.model_extrapolated)
                .cloned()
                .collect(),
            centerline_x: shape.x,
            provenance,
        };
        dir.commit(meta)
    }
}

#[derive(Serialize)]
struct Meta<'a> {
    scenario: &'a str,
    /// `false` if the run ended before `t_requested` (interrupted or failed): the arrays hold the
    /// samples up to `t_reached`.
    complete: bool,
    /// Why an incomplete run ended.
    reason: Option<String>,
    /// Time of the last sample written.
    t_reached: Option<f64>,
    t_requested: f64,
    /// Output samples per second.
    sample_rate: f64,
    samples: usize,
    n_dof: usize,
    n_points: usize,
    n_actuators: usize,
    /// Rod length [m].
    length: f64,
    wall_time_s: f64,
    real_time_factor: f64,
    /// Work counts of the integrator (up to the end of the run, or to where it stopped).
    steps: usize,
    failed_steps: usize,
    /// Of `failed_steps`, the attempts whose Newton iteration did not converge.
    newton_failures: usize,
    rhs_evaluations: usize,
    jacobian_evaluations: usize,
    lu_decompositions: usize,
    /// The integrator's error if it failed.
    error: Option<String>,
    /// The input signal, start and load schedule ([`input_record`]).
    input: &'a serde_json::Value,
    /// The scenario's physics besides the inputs ([`physics_record`]).
    physics: serde_json::Value,
    /// How the run lies outside its reduced model's training (`--extrapolate`): the scenario's and
    /// the input signal's differences.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    model_extrapolated: Vec<String>,
    /// Abscissae of the centreline samples in `centerline.npy` [m].
    centerline_x: Vec<f64>,
    /// How the run was made ([`crate::provenance::Provenance`]), when the caller recorded it.
    #[serde(skip_serializing_if = "Option::is_none")]
    provenance: Option<serde_json::Value>,
}
