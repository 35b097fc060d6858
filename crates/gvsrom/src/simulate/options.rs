//! A run's options ([`SimulateOptions`]): its actuation — where it comes from ([`InputSource`]),
//! the signal built from it and its checks — the span, the sampling and the integrator; and how
//! `meta.json` records the input.

use crate::build::Built;
use crate::error::ScenarioError;
use gvs::feedback::FeedbackLaw;
use gvs::inputs::{babble, random_steps, Actuation, Interpolation, Signal};
use gvs::solve::dynamics::IntegratorOptions;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// An actuation given as a function of time (Python's `input=` callable): the integrator evaluates
/// it wherever it needs `u(t)`, in any order, and steps onto its breakpoints, if it has any; it
/// checks its own values (count, finiteness). Nothing about it is checked before the run (its
/// extremes are unknown).
#[derive(Clone)]
pub struct InputFunction(pub Arc<dyn Actuation + Send + Sync>);

impl std::fmt::Debug for InputFunction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("InputFunction(..)")
    }
}

/// A control law (Python's `controller=` callable), run by the plan as a sampled-data controller
/// ([`gvs::feedback::SampledFeedback`] at [`super::control_instants`]). As for an
/// [`InputFunction`], its values are its own to check.
#[derive(Clone)]
pub struct ControlLaw(pub Arc<dyn FeedbackLaw + Send + Sync>);

impl std::fmt::Debug for ControlLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ControlLaw(..)")
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
    /// A sampled-data controller called `control_rate` times a second (default: at every
    /// sample) with the state, its tensions held between calls: the plan runs it as a
    /// [`gvs::feedback::SampledFeedback`] at the instants of [`super::control_instants`].
    Feedback {
        law: ControlLaw,
        control_rate: Option<f64>,
    },
}

impl InputSource {
    /// How the tensions vary in time, for a run's summary; `None` for the scenario's constant
    /// tensions.
    pub fn describe(&self) -> Option<String> {
        let g = gvs::error::fmt_value;
        Some(match self {
            InputSource::Constant => return None,
            InputSource::Csv {
                path,
                interpolation,
            } => format!(
                "u(t) from `{}`, {}",
                path.display(),
                match interpolation {
                    Interpolation::Hold => "each row held until the next",
                    Interpolation::Linear => "interpolated linearly",
                }
            ),
            InputSource::Steps {
                lo,
                hi,
                period,
                seed,
            } => format!(
                "u(t) random steps in [{}, {}] N every {} s (seed {seed})",
                g(*lo),
                g(*hi),
                g(*period)
            ),
            InputSource::Babble {
                lo,
                hi,
                hold_min,
                hold_max,
                seed,
            } => format!(
                "u(t) babbling in [{}, {}] N, holds of {}–{} s (seed {seed})",
                g(*lo),
                g(*hi),
                g(*hold_min),
                g(*hold_max)
            ),
            InputSource::Rows(s) => format!("u(t) from {} rows", s.times.len()),
            InputSource::Function(_) => "u(t) from a function".into(),
            InputSource::Feedback { control_rate, .. } => match control_rate {
                Some(r) => format!("u from a controller called at {} Hz", g(*r)),
                None => "u from a controller called at every sample".into(),
            },
        })
    }

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
            (input, steps, babble) => {
                let given: Vec<&str> = [
                    ("--input", input.is_some()),
                    ("--steps", steps.is_some()),
                    ("--babble", babble.is_some()),
                ]
                .into_iter()
                .filter_map(|(name, set)| set.then_some(name))
                .collect();
                return Err(ScenarioError::invalid(
                    given[1],
                    format!(
                        "`{}` is given too: give at most one input option of `--input`, `--steps` and `--babble`",
                        given[0]
                    ),
                ));
            }
        })
    }
}

/// Where a dynamics run starts.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum Start {
    /// Straight at rest: the rest coordinates of the model that runs, `q̇ = 0`.
    #[default]
    Rest,
    /// At rest in the static equilibrium under the scenario's tensions and loads, then released
    /// to the input signal at t = 0 (`--from-equilibrium`).
    Equilibrium,
    /// A given state `(q, q̇)` of the model that runs — the reduced model's coordinates when one is
    /// attached — e.g. the last sample of an earlier run, to continue it under another input
    /// (Python's `Robot.simulate(q0=…, qd0=…)`: a controller stepping the rod one period at a
    /// time). Checked when the run is planned: `n` finite values each, and for an autoencoder model
    /// inside its training encodings.
    State { q: Vec<f64>, qd: Vec<f64> },
}

impl Start {
    /// [`Start::Equilibrium`] if `from_equilibrium` (the `--from-equilibrium` flag), else
    /// [`Start::Rest`].
    pub fn rest_or_equilibrium(from_equilibrium: bool) -> Start {
        if from_equilibrium {
            Start::Equilibrium
        } else {
            Start::Rest
        }
    }
}

/// Options of a dynamics run.
#[derive(Debug, Clone)]
pub struct SimulateOptions {
    pub duration: f64,
    /// Output samples per second.
    pub sample_rate: f64,
    pub input: InputSource,
    /// Where the run starts ([`Start`]).
    pub start: Start,
    pub integrator: IntegratorOptions,
    /// A CSV file `t, λ` scaling all external loads and gravity over time (linear between rows).
    pub load_schedule: Option<PathBuf>,
}

pub(super) fn positive(field: &str, v: f64, unit: &str) -> Result<f64, ScenarioError> {
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

/// Builds the actuation signal of a run. A function input ([`InputSource::Function`], a
/// controller) has none: the
/// scenario's constant tensions stand for it in the checks before the run.
pub fn input_signal(built: &Built, opts: &SimulateOptions) -> Result<Signal, ScenarioError> {
    let na = built.model.n_actuators();
    let d = opts.duration;
    // a random signal for a rod without tendons would drive nothing: refused, not ignored
    let random = match &opts.input {
        InputSource::Steps { .. } => Some("--steps"),
        InputSource::Babble { .. } => Some("--babble"),
        _ => None,
    };
    if let (0, Some(option)) = (na, random) {
        return Err(ScenarioError::invalid(
            option,
            "the scenario has no tendons for random tensions to drive (add [[tendons]], or drive the rod by its loads and --load-schedule)",
        ));
    }
    Ok(match &opts.input {
        InputSource::Constant => Signal::constant(&built.channels()),
        InputSource::Csv {
            path,
            interpolation,
        } => {
            crate::scenario::check_regular_file("--input", path)?;
            let signal = crate::csv_input::read_csv_signal("--input", path, na, *interpolation)?;
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
        InputSource::Function(_) | InputSource::Feedback { .. } => Signal::constant(&built.u),
    })
}

/// Every run starts at t = 0 (its first sample).
pub(super) const RUN_START: f64 = 0.0;

/// Refuses a signal read from `path` (option `field`) whose first row comes after the run's start
/// `t0`: before its first row the signal would silently hold that row's values.
pub(super) fn covers_start(
    field: &str,
    path: &Path,
    signal: &Signal,
    t0: f64,
) -> Result<(), ScenarioError> {
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

pub(super) fn range_check(field: &str, lo: f64, hi: f64) -> Result<(), ScenarioError> {
    if lo.is_finite() && hi.is_finite() && lo <= hi {
        Ok(())
    } else {
        Err(ScenarioError::invalid(
            field,
            format!("range [{lo}, {hi}] must be finite with lo <= hi"),
        ))
    }
}

/// The most rows of an input given as rows (Python's `input=`) its record lists as they are
/// (every row is in its hash, `sha256` of the rows' little-endian f64 values `t, u_1, …`).
pub const MAX_ROWS_RECORDED: usize = 16;

/// The run's input as `meta.json` records it (`"input"`), for `gvsrom compare` to tell runs with
/// other inputs apart: the signal's specification — `"constant"` with the tensions, `"csv"` with
/// the file, its SHA-256 and the interpolation, `"rows"` with their SHA-256 (and up to
/// [`MAX_ROWS_RECORDED`] of them), `"steps"` or `"babble"` with their parameters and seed —, the
/// start (`"rest"`, or `"equilibrium"` with the tensions it is solved under) and the load schedule
/// (file and SHA-256, or null).
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
        // per tendon its tension or its displacement, the other null
        InputSource::Constant if built.displacement_driven() => json!({
            "signal": "constant",
            "tensions": (built.u.iter().zip(&built.displacement))
                .map(|(u, d)| d.is_none().then_some(*u))
                .collect::<Vec<_>>(),
            "displacements": built.displacement,
        }),
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
        // the rows by their content (as a file by its hash), and a few of them as they are
        InputSource::Rows(signal) => {
            let bytes: Vec<u8> = (signal.times.iter().zip(&signal.values))
                .flat_map(|(t, v)| std::iter::once(t).chain(v))
                .flat_map(|x| x.to_le_bytes())
                .collect();
            let mut v = json!({
                "signal": "rows",
                "rows": signal.times.len(),
                "interpolation": match signal.interpolation {
                    Interpolation::Hold => "hold",
                    Interpolation::Linear => "linear",
                },
                "sha256": crate::provenance::sha256_hex(&bytes),
            });
            if signal.times.len() <= MAX_ROWS_RECORDED {
                v["values"] = json!((signal.times.iter().zip(&signal.values))
                    .map(|(t, u)| std::iter::once(*t).chain(u.iter().copied()).collect())
                    .collect::<Vec<Vec<f64>>>());
            }
            v
        }
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
        InputSource::Feedback { control_rate, .. } => json!({
            "signal": "controller",
            "control_rate": control_rate.unwrap_or(opts.sample_rate),
        }),
    };
    match &opts.start {
        Start::Rest => signal["start"] = json!("rest"),
        Start::Equilibrium => {
            signal["start"] = json!("equilibrium");
            signal["start_tensions"] = json!(built.u);
            if built.displacement_driven() {
                signal["start_displacements"] = json!(built.displacement);
            }
        }
        Start::State { q, qd } => {
            signal["start"] = json!("state");
            signal["start_q"] = json!(q);
            signal["start_qd"] = json!(qd);
        }
    }
    // which channels are displacements [m] of their tendons' motors, not tensions
    if built.displacement_driven() {
        let driven: Vec<usize> = (0..built.displacement.len())
            .filter(|&k| built.displacement[k].is_some())
            .collect();
        signal["displacement_channels"] = json!(driven);
    }
    signal["load_schedule"] = match &opts.load_schedule {
        Some(path) => file("--load-schedule", path)?,
        None => serde_json::Value::Null,
    };
    Ok(signal)
}
