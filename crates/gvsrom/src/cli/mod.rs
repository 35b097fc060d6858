//! Command-line interface: argument parsing (clap) and the text printed by each command. Nothing
//! else: scenarios are resolved, solved, reduced and written by the library — the functions the
//! Python package calls too. One file per command group; `print.rs` holds the shared summaries.

mod compare;
mod equilibrium;
mod linearize;
mod plot;
mod print;
mod reduction;
mod reproduce;
mod signals;
mod simulate;

pub use signals::Interrupted;

use compare::*;
use equilibrium::*;
use linearize::*;
use plot::*;
use print::*;
use reduction::*;
use reproduce::*;
use signals::*;
use simulate::*;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use gvsrom::build::{resolve, Request, Resolved};
use gvsrom::output::OutputFile;
use gvsrom::presets::{self, PRESETS};
use gvsrom::reduce;
use gvsrom::simulate::{Ending, TrajectoryWriter};
use gvsrom::statics::{self, StaticsReport};
use gvsrom::{Built, Scenario};
use std::io::Write;
use std::ops::ControlFlow;

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// `simulate --method` and `--error-norm` (the library chooses the integrator from them).
pub use gvsrom::simulate::{ErrorNormChoice, MethodChoice};

/// Simulate slender soft robots with the Geometric Variable Strain (GVS) Cosserat-rod model.
#[derive(Debug, Parser)]
#[command(name = "gvsrom", version, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// Every command takes a negative number as an option's value (`--seed -1` reaches the option's
/// own check, which names it and what it accepts, rather than clap's "unexpected argument").
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Solve the static equilibrium of a preset or a scenario file and print a summary.
    #[command(allow_negative_numbers = true)]
    Statics(StaticsArgs),
    /// Simulate the dynamics of a preset or scenario file (stiff NDF integrator, ode15s class) and
    /// write the trajectory as NumPy arrays.
    #[command(allow_negative_numbers = true)]
    Simulate(SimulateArgs),
    /// Natural frequencies and mode shapes about the static equilibrium under the scenario's loads
    /// and tensions (undamped, linearized; see docs/modes.md).
    #[command(allow_negative_numbers = true)]
    Modes(ModesArgs),
    /// The equations of motion linearized about the static equilibrium, for control design:
    /// `δẋ = A δx + B δu`, `δy = C δx` (state `[q; q̇]`, tendon tensions, tip position), its poles
    /// and the static gain from tensions to tip (see docs/linearize.md).
    #[command(allow_negative_numbers = true)]
    Linearize(LinearizeArgs),
    /// Generate a strain snapshot dataset: solve the statics over a sampling plan (`--sweep`,
    /// `--grid`, `--random`) in parallel and write NumPy arrays (see docs/datasets.md).
    #[command(allow_negative_numbers = true)]
    Dataset(DatasetArgs),
    /// POD of a dataset's strain snapshots: K modes become a reduced model (`--model` on `statics`
    /// and `simulate`).
    #[command(allow_negative_numbers = true)]
    Pod(PodArgs),
    /// Train a tanh autoencoder on a dataset's strain snapshots; its decoder becomes a nonlinear
    /// reduced model (`--model` on `statics` and `simulate`).
    #[command(allow_negative_numbers = true)]
    Train(TrainArgs),
    /// How closely a reduced model reconstructs a dataset's snapshots, `D(E(x))`: Table I's RMSE,
    /// the relative error and the worst snapshot, e.g. on data the model was not trained on.
    /// Prints; writes nothing.
    #[command(allow_negative_numbers = true)]
    Reconstruct(ReconstructArgs),
    /// Compare a trajectory with a reference one (e.g. `simulate --model` against the full model)
    /// of the same scenario, input and sample times: tip and strain errors over the common samples,
    /// and the speed ratio (simulated time per wall time).
    #[command(allow_negative_numbers = true)]
    Compare(CompareArgs),
    /// Reproduce the paper's studies end to end (data, training, reduced models, evaluation) with
    /// their tables beside the paper's, figures and one HTML page `OUT/index.html`; finished steps
    /// are kept and reused by the next run.
    #[command(allow_negative_numbers = true)]
    Reproduce(ReproduceArgs),
    /// Validate a preset or scenario file and print the model's size, without solving.
    #[command(mut_arg("extrapolate", |a| a.hide(true)), allow_negative_numbers = true)]
    Check(ScenarioArgs),
    /// Figures (SVG and PNG) of a gvsrom output: a `statics --json` file, or a `simulate --out`,
    /// `dataset`, `pod` or `train` directory (rod shapes, tip paths, strain, an animation of the
    /// rod, input coverage, POD spectra, training curves, reduced coordinates).
    #[command(allow_negative_numbers = true)]
    Plot(PlotArgs),
    /// List the built-in presets.
    Presets,
    /// Print a preset's TOML (save it with `gvsrom show NAME > my.toml` to start your own).
    Show {
        /// Preset name (see `gvsrom presets`).
        preset: String,
    },
}

/// Which scenario, with overrides.
#[derive(Debug, Args)]
pub struct ScenarioArgs {
    /// A preset name (see `gvsrom presets`) or the path of a scenario TOML file.
    pub scenario: String,

    /// Override a scenario value by its TOML path; repeatable. The value is read as TOML (number,
    /// bool, array, quoted string; a bare word is a string). Examples: `--set tendons.0.tension=-2`,
    /// `--set loads.distributed.0.magnitude=3`, `--set divisions.0.basis.order=6`,
    /// `--set solver.ramp_steps=3`, `--set loads.gravity=[0,0,0]`; `*` stands for every entry of
    /// a list: `--set 'tendons.*.friction=0'`.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,

    /// Tendon tensions u [N] (negative pulls): one value for every tendon, or one per tendon as a
    /// comma-separated list, e.g. `--tension=-10,0,0,0,0,0`. Applied after `--set`.
    #[arg(
        long,
        value_name = "U[,U...]",
        allow_hyphen_values = true,
        value_delimiter = ','
    )]
    pub tension: Option<Vec<f64>>,

    /// Drive the tendons by displacement instead: the length δ [m] each actuator has wound in from
    /// the tendon's rest length (negative pays out); one value for every tendon, or one per
    /// tendon, e.g. `--displacement=0.004,0`. `statics` finds the tensions (a cable pulls or goes
    /// slack); `simulate` needs each such tendon's thread stiffness (`--set
    /// tendons.0.axial_stiffness=EA`, in N) and finds its tension from the stretch as it runs.
    /// Applied after `--set`.
    #[arg(
        long,
        value_name = "D[,D...]",
        allow_hyphen_values = true,
        value_delimiter = ',',
        conflicts_with = "tension"
    )]
    pub displacement: Option<Vec<f64>>,

    /// Number of centreline samples, at equally spaced material abscissae X (the arc length of the
    /// undeformed rod; a stretched rod's samples are as far apart as it stretched), in the JSON output and per
    /// sample of a trajectory (`centerline.npy`); overrides `output.centerline_points`, default 21.
    #[arg(value_parser = whole::<usize>, long, value_name = "N")]
    pub centerline_points: Option<usize>,

    /// Use `--model` even where the scenario lies outside what the model was trained on (an input
    /// outside the training range, other physics). Without it such a scenario is refused; with it
    /// every difference is printed as a warning and recorded in the outputs.
    #[arg(long)]
    pub extrapolate: bool,
}

/// Runs the parsed command, printing to `out`.
pub fn run(cli: Cli, out: &mut impl Write) -> Result<()> {
    match cli.command {
        Command::Statics(args) => statics_cmd(&args, out),
        Command::Simulate(args) => simulate_cmd(&args, out),
        Command::Modes(args) => modes_cmd(&args, out),
        Command::Linearize(args) => linearize_cmd(&args, out),
        Command::Dataset(args) => dataset_cmd(&args, out),
        Command::Pod(args) => pod_cmd(&args, out),
        Command::Train(args) => train_cmd(&args, out),
        Command::Reconstruct(args) => reconstruct_cmd(&args, out),
        Command::Compare(args) => compare_cmd(&args, out),
        Command::Reproduce(args) => reproduce_cmd(&args, out),
        Command::Check(args) => check_cmd(&args, out),
        Command::Plot(args) => plot_cmd(&args, out),
        Command::Presets => presets_cmd(out),
        Command::Show { preset } => {
            let p = presets::find(&preset).ok_or_else(|| {
                anyhow::anyhow!("unknown preset `{preset}` (presets: {})", presets::names())
            })?;
            out.write_all(p.toml.as_bytes())?;
            Ok(())
        }
    }
}

/// The scenario of `args` resolved by the library ([`gvsrom::build::resolve`]); its build
/// warnings ([`gvsrom::build::warnings`]: a tendon whose load the basis cannot hold, a division
/// the kinematics under-integrate) go to stderr.
/// A count or a seed on the command line: a whole number (`T`'s range), with a message that says
/// so for a negative or fractional value or one out of range (clap's own says "invalid digit found
/// in string" for `-3` and `2.5`).
fn whole<T: std::str::FromStr<Err = std::num::ParseIntError>>(
    s: &str,
) -> std::result::Result<T, String> {
    use std::num::IntErrorKind;
    s.trim().parse::<T>().map_err(|e| {
        let accepted = match e.kind() {
            _ if s.trim().starts_with('-') => "expected a whole number ≥ 0, not a negative one",
            IntErrorKind::Empty => "expected a whole number ≥ 0, got nothing",
            IntErrorKind::PosOverflow => "expected a whole number ≥ 0, not one this large",
            _ if s.trim().parse::<f64>().is_ok() => "expected a whole number ≥ 0, not a fraction",
            _ => "expected a whole number ≥ 0",
        };
        accepted.to_string()
    })
}

fn load(args: &ScenarioArgs) -> Result<Resolved> {
    let r = resolve(&Request {
        source: &args.scenario,
        overrides: &args.set,
        tensions: args.tension.as_deref(),
        displacements: args.displacement.as_deref(),
        centerline_points: args.centerline_points,
    })?;
    for w in gvsrom::build::warnings(&r.scenario, &r.built) {
        gvsrom::progress::stderr_line(format_args!("warning: {w}"));
    }
    Ok(r)
}

/// Refuses `--extrapolate` without a `--model` for it to apply to (it would be ignored).
fn extrapolate_needs_model(args: &ScenarioArgs, model: Option<&std::path::Path>) -> Result<()> {
    if args.extrapolate && model.is_none() {
        anyhow::bail!(
            "--extrapolate applies to a reduced model: give `--model DIR` with it (without a model the full model answers, which needs no permission)"
        );
    }
    Ok(())
}

/// `--model DIR` on the resolved scenario ([`reduce::attach_resolved`]); its warnings go to stderr.
fn attach_model(
    r: &mut Resolved,
    args: &ScenarioArgs,
    dir: &std::path::Path,
    tensions_from_signal: bool,
) -> Result<()> {
    let options = reduce::AttachOptions {
        extrapolate: args.extrapolate,
        tensions_from_signal,
    };
    reduce::attach_resolved(r, dir, options)?;
    for w in r.built.reduced.iter().flat_map(|m| &m.warnings) {
        gvsrom::progress::stderr_line(format_args!("warning: {w}"));
    }
    Ok(())
}

fn presets_cmd(out: &mut impl Write) -> Result<()> {
    let width = PRESETS.iter().map(|p| p.name.len()).max().unwrap_or(0);
    for p in PRESETS {
        writeln!(out, "{:width$}  {}", p.name, p.summary)?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "Run one with `gvsrom statics NAME`; print its TOML with `gvsrom show NAME`."
    )?;
    Ok(())
}

fn check_cmd(args: &ScenarioArgs, out: &mut impl Write) -> Result<()> {
    if args.extrapolate {
        anyhow::bail!(
            "--extrapolate: `check` takes no `--model` for it to apply to (it validates the scenario alone; `statics`, `simulate` and `modes` take `--model DIR --extrapolate`)"
        );
    }
    let r = load(args)?;
    print_model(&r.scenario, args, &r.built, None, out)?;
    writeln!(out, "ok         the scenario is valid")?;
    Ok(())
}

/// The command's input files and directories that an output must not replace: the scenario file
/// (not a preset name, which is resolved first) and `model`, with their option names.
/// What `statics`, `modes` and `linearize` do before they solve: `--extrapolate` only with
/// `--model`, a `--json` FILE that is none of the inputs, the scenario resolved and the model
/// attached; returns it with the provenance of the run (scenario and solver).
fn load_for_equilibrium(
    args: &ScenarioArgs,
    model: Option<&PathBuf>,
    json: Option<&PathBuf>,
) -> Result<(Resolved, gvsrom::provenance::Provenance)> {
    extrapolate_needs_model(args, model.map(PathBuf::as_path))?;
    if let Some(path) = json {
        gvsrom::output::refuse_overlap("--json", path, &scenario_inputs(args, model))?;
    }
    let mut r = load(args)?;
    if let Some(dir) = model {
        attach_model(&mut r, args, dir, false)?;
    }
    let provenance = r.provenance.clone().solver(&r.built.options);
    Ok((r, provenance))
}

fn scenario_inputs<'a>(
    args: &'a ScenarioArgs,
    model: Option<&'a PathBuf>,
) -> Vec<(&'static str, &'a std::path::Path)> {
    let mut inputs = vec![];
    if presets::find(&args.scenario).is_none() {
        inputs.push(("SCENARIO", std::path::Path::new(&args.scenario)));
    }
    if let Some(m) = model {
        inputs.push(("--model", m.as_path()));
    }
    inputs
}
