//! Command-line interface: argument parsing (clap) and the text printed by each command. No physics
//! here: scenarios are loaded and built by the library, solved by the engine.

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use gvsrom::output::OutputFile;
use gvsrom::presets::{self, PRESETS};
use gvsrom::provenance::Provenance;
use gvsrom::reduce;
use gvsrom::simulate::{Ending, TrajectoryWriter};
use gvsrom::statics::{self, StaticsReport};
use gvsrom::{build, Built, Scenario};
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

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Solve the static equilibrium of a preset or a scenario file and print a summary.
    Statics(StaticsArgs),
    /// Simulate the dynamics of a preset or scenario file (stiff NDF integrator, ode15s class) and
    /// write the trajectory as NumPy arrays.
    Simulate(SimulateArgs),
    /// Natural frequencies and mode shapes about the static equilibrium under the scenario's loads
    /// and tensions (undamped, linearized; see docs/modes.md).
    Modes(ModesArgs),
    /// Generate a strain snapshot dataset: solve the statics over a sampling plan (`--sweep`,
    /// `--grid`, `--random`) in parallel and write NumPy arrays (see docs/datasets.md).
    Dataset(gvsrom::dataset::DatasetArgs),
    /// POD of a dataset's strain snapshots: K modes become a reduced model (`--model` on `statics`
    /// and `simulate`).
    Pod(PodArgs),
    /// Train a tanh autoencoder on a dataset's strain snapshots; its decoder becomes a nonlinear
    /// reduced model (`--model` on `statics` and `simulate`).
    Train(TrainArgs),
    /// Compare a trajectory with a reference one (e.g. `simulate --model` against the full model)
    /// of the same scenario, input and sample times: tip and strain errors over the common samples,
    /// and the speed ratio (simulated time per wall time).
    Compare(CompareArgs),
    /// Reproduce the paper's studies end to end (data, training, reduced models, evaluation) with
    /// their tables beside the paper's, figures and one HTML page `OUT/index.html`; finished steps
    /// are kept and reused by the next run.
    Reproduce(ReproduceArgs),
    /// Validate a preset or scenario file and print the model's size, without solving.
    Check(ScenarioArgs),
    /// Figures (SVG and PNG) of a gvsrom output: a `statics --json` file, or a `simulate --out`,
    /// `dataset`, `pod` or `train` directory (rod shapes, tip paths, strain, an animation of the
    /// rod, input coverage, POD spectra, training curves, reduced coordinates).
    Plot(PlotArgs),
    /// List the built-in presets.
    Presets,
    /// Print a preset's TOML (save it with `gvsrom show NAME > my.toml` to start your own).
    Show {
        /// Preset name (see `gvsrom presets`).
        preset: String,
    },
}

/// Two trajectories to compare.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The reference trajectory (a `simulate --out` directory), e.g. the full model's
    pub reference: PathBuf,
    /// The trajectory to measure against it, e.g. a reduced model's (same scenario, input and
    /// sample times)
    pub run: PathBuf,
    /// Compare the runs even if their scenario, physics, input or duration differ (or their
    /// meta.json cannot tell): the output then says how they differ. Without it such runs are
    /// refused, since one does not approximate the other.
    #[arg(long)]
    pub allow_different: bool,
    /// Also write the comparison as JSON, with both runs' hashes (`provenance`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Let `--json` replace an earlier gvsrom output at that path.
    #[arg(long)]
    pub force: bool,
}

/// `gvsrom reproduce`.
#[derive(Debug, Args)]
pub struct ReproduceArgs {
    /// The paper's cases to run: `iv-a`, `iv-b`, `v`, or `all`.
    #[arg(required = true, value_enum)]
    pub cases: Vec<gvsrom::reproduce::Case>,
    /// Reduced sizes (fewer samples, epochs, POD modes): every case in minutes, the paper's trends
    /// but not its numbers.
    #[arg(long)]
    pub quick: bool,
    /// The run directory: created, or an earlier `reproduce` run whose finished steps are reused.
    #[arg(long, value_name = "DIR", default_value = "results")]
    pub out: PathBuf,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Testing aid: the smallest sizes that still run every step (implies --quick).
    #[arg(long, hide = true)]
    pub test_sizes: bool,
    /// The noise study's Gaussian noise, σ relative to the RMS of each strain component of the snapshots.
    #[arg(long, value_name = "LEVEL", default_value_t = gvsrom::reproduce::DEFAULT_NOISE)]
    pub noise: f64,
}

/// Which scenario, with overrides.
#[derive(Debug, Args)]
pub struct ScenarioArgs {
    /// A preset name (see `gvsrom presets`) or the path of a scenario TOML file.
    pub scenario: String,

    /// Override a scenario value by its TOML path; repeatable. The value is read as TOML (number,
    /// bool, array, quoted string; a bare word is a string). Examples: `--set tendons.0.tension=-2`,
    /// `--set loads.distributed.0.magnitude=3`, `--set divisions.0.basis.order=6`,
    /// `--set solver.ramp_steps=3`, `--set loads.gravity=[0,0,0]`.
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

    /// Number of centreline samples, equally spaced in arc length, in the JSON output and per
    /// sample of a trajectory (`centerline.npy`); overrides `output.centerline_points`, default 21.
    #[arg(long, value_name = "N")]
    pub centerline_points: Option<usize>,

    /// Use `--model` even where the scenario lies outside what the model was trained on (an input
    /// outside the training range, other physics). Without it such a scenario is refused; with it
    /// every difference is printed as a warning and recorded in the outputs.
    #[arg(long)]
    pub extrapolate: bool,
}

#[derive(Debug, Args)]
pub struct StaticsArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Also write the solution (q, tip pose, centreline, strains, solver statistics) as JSON to FILE
    /// (a new file; see `--force`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Replace FILE if it is an earlier gvsrom output (never anything else).
    #[arg(long, requires = "json")]
    pub force: bool,

    /// Solve with the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in
    /// place of the scenario's basis; the model must have been learned on this scenario's points.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,

    /// With `--model`: also solve the full model and report the strain error (MAE, % of the peak
    /// strain), the tip error (% of the length) and both solve times.
    #[arg(long, requires = "model")]
    pub compare: bool,

    /// Solve N times and report the mean solve time (warm caches; for timing comparisons).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub repeat: u32,
}

#[derive(Debug, Args)]
pub struct ModesArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Number of modes reported, lowest first (an integer ≥ 1, default 10); more than the model's DOF
    /// count reports all of them, with a note.
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    pub count: Option<String>,

    /// Also write the equilibrium, the frequencies and the mode shapes (q-space, tip displacement
    /// and rotation, strain at the computational points) as JSON to FILE (a new file; see `--force`).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,

    /// Replace FILE if it is an earlier gvsrom output (never anything else).
    #[arg(long, requires = "json")]
    pub force: bool,

    /// Use the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in place of
    /// the scenario's basis, for the equilibrium and the modes.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct PodArgs {
    /// A dataset directory (from `gvsrom dataset`).
    pub dataset: PathBuf,
    /// Number of POD modes kept (reduced coordinates).
    #[arg(long, value_name = "K")]
    pub modes: usize,
    /// The new model directory.
    #[arg(long, value_name = "MODEL")]
    pub out: PathBuf,
    /// Replace MODEL if it is an earlier gvsrom output.
    #[arg(long)]
    pub force: bool,
}

#[derive(Debug, Args)]
pub struct TrainArgs {
    /// A dataset directory (from `gvsrom dataset`).
    pub dataset: PathBuf,
    /// Latent size r (reduced coordinates).
    #[arg(long, value_name = "R", default_value_t = 1)]
    pub latent: usize,
    /// Hidden layers of the whole autoencoder (odd: 3, 5, 7…); layer sizes halve from the snapshot
    /// size towards the latent size (paper Section III).
    #[arg(long, value_name = "N", default_value_t = 7)]
    pub hidden_layers: usize,
    /// Maximum Adam epochs.
    #[arg(long, default_value_t = 2000)]
    pub epochs: usize,
    /// Mini-batch size.
    #[arg(long, default_value_t = 64)]
    pub batch_size: usize,
    /// Adam learning rate.
    #[arg(long, default_value_t = 1e-3)]
    pub learning_rate: f64,
    /// L2 weight regularization λ of eq. (15) (paper: 1e-4).
    #[arg(long, default_value_t = 1e-4)]
    pub lambda: f64,
    /// Fraction of the snapshots held out for validation and early stopping.
    #[arg(long, default_value_t = 0.1)]
    pub validation_fraction: f64,
    /// Epochs without a better validation loss before stopping (0: never stop early).
    #[arg(long, default_value_t = 50)]
    pub patience: usize,
    /// Learning-rate reductions (× 0.3 each, from the best weights so far) at validation plateaus of
    /// `--patience` epochs before Adam stops.
    #[arg(long, default_value_t = 4)]
    pub lr_reductions: usize,
    /// Iterations of the full-batch L-BFGS phase that follows Adam from its best weights (0: none).
    #[arg(long, default_value_t = 300)]
    pub lbfgs_iterations: usize,
    /// Seed of the initialization, the split and the shuffles (same seed, same model).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// How each strain value's error weighs in the loss: `standardized` (each point and component
    /// by its own spread), `physical` (plain squared error, the RMSE of Table I) or `energy`
    /// (weighted by the section stiffness: the strain-energy norm, which the reduced model's
    /// elastic force feels).
    #[arg(long, value_enum, default_value_t = reduce::Loss::Energy)]
    pub loss: reduce::Loss,
    /// The new model directory.
    #[arg(long, value_name = "MODEL")]
    pub out: PathBuf,
    /// Replace MODEL if it is an earlier gvsrom output.
    #[arg(long)]
    pub force: bool,
}

#[derive(Debug, Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Simulated time [s].
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    pub duration: f64,

    /// Output samples per second [Hz].
    #[arg(
        long,
        value_name = "HZ",
        default_value_t = 100.0,
        allow_hyphen_values = true
    )]
    pub sample_rate: f64,

    /// Actuation from a CSV file with columns `t, u_1, …, u_na` (held piecewise constant; see
    /// `--interpolate`). Without an input option the scenario's tensions are held constant.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["steps", "babble"])]
    pub input: Option<PathBuf>,

    /// Interpolate the CSV input linearly between its rows instead of holding each row.
    #[arg(long, requires = "input")]
    pub interpolate: bool,

    /// Random step actuation: every actuator draws a new tension uniformly in [LO, HI] every PERIOD
    /// seconds (the paper's IV-C test: `--steps=-15,0,1`).
    #[arg(
        long,
        value_name = "LO,HI,PERIOD",
        value_delimiter = ',',
        allow_hyphen_values = true,
        conflicts_with = "babble"
    )]
    pub steps: Option<Vec<f64>>,

    /// Actuator babbling: each actuator holds a tension uniform in [LO, HI] for a time uniform in
    /// [HOLD_MIN, HOLD_MAX] seconds (the paper's IV-C2 data: `--babble=-15,0,0.5,1`).
    #[arg(
        long,
        value_name = "LO,HI,HOLD_MIN,HOLD_MAX",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub babble: Option<Vec<f64>>,

    /// Seed of the random inputs (same seed, same signal).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,

    /// Start at the static equilibrium under the scenario's tensions and loads, then switch to the
    /// input at t = 0 (a release test when the input differs).
    #[arg(long)]
    pub from_equilibrium: bool,

    /// Relative tolerance of the adaptive integrator, in [1e-12, 1). Default 1e-3 (ode15s), or
    /// 1e-4 when the automatic method is SDIRK4 for a lightly damped rod (see `--method`).
    #[arg(long, allow_hyphen_values = true)]
    pub rtol: Option<f64>,

    /// Absolute tolerance of the adaptive integrator, at least 1e-14 (ode15s default 1e-6).
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub atol: f64,

    /// Use the fixed-step implicit method with step H [s] instead of the adaptive NDF (real time).
    #[arg(long, value_name = "H")]
    pub fixed_step: Option<f64>,

    /// Adaptive integrator: `auto` (default: the NDF for a damped rod; SDIRK4 with the mass-norm
    /// error test at rtol 1e-4 for a lightly damped one, whose stiffest mode is underdamped),
    /// `ndf` (variable order, ode15s class; orders ≤ 2 with the mass-norm test for a lightly damped
    /// rod), `sdirk` (L-stable, order 4, in second-order form: Newton on n unknowns per stage) or
    /// `galpha` (generalized-α in second-order form with numerical dissipation `--rho-inf`).
    #[arg(long, value_enum, default_value_t = MethodChoice::Auto)]
    pub method: MethodChoice,

    /// Highest order of the NDF, 1–5 (orders ≤ 2 are A-stable). Default: 5, or 2 for a lightly
    /// damped rod (its stiffest mode underdamped), which also gets `--error-norm mass`.
    #[arg(long)]
    pub max_order: Option<usize>,

    /// Error test of the adaptive methods: `componentwise` (ode15s) or `mass` (positions and
    /// velocities in the norm of the mass matrix: modes that move little mass do not limit the
    /// step). Default: componentwise, or with the NDF mass for a lightly damped rod (see
    /// `--max-order`). With `--method galpha`, `mass` is what makes it usable on a lightly damped
    /// rod.
    #[arg(long, value_enum)]
    pub error_norm: Option<ErrorNormChoice>,

    /// Generalized-α: spectral radius at infinite frequency in [0, 1] (1: no numerical dissipation).
    #[arg(long, default_value_t = 0.8)]
    pub rho_inf: f64,

    /// Time-varying external loads: a CSV file with columns `t, λ` that scales every external load and
    /// gravity, linearly interpolated between rows (e.g. a load applied then removed).
    #[arg(long, value_name = "FILE")]
    pub load_schedule: Option<PathBuf>,

    /// Use finite differences of the right-hand side for the integrator's Jacobian instead of the
    /// structured analytic one.
    #[arg(long)]
    pub fd_jacobian: bool,

    /// Write the trajectory (t, q, q̇, u, tip pose, strains, centreline) as .npy files and
    /// meta.json into the new directory DIR, streamed as it is computed. An interrupted (Ctrl-C,
    /// SIGTERM) or failed run still writes what it has, marked `"complete": false`.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Replace DIR if it is an earlier gvsrom output holding only its own files (never anything else).
    #[arg(long, requires = "out")]
    pub force: bool,

    /// Simulate with the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in
    /// place of the scenario's basis.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
}

/// Runs the parsed command, printing to `out`.
pub fn run(cli: Cli, out: &mut impl Write) -> Result<()> {
    match cli.command {
        Command::Statics(args) => statics_cmd(&args, out),
        Command::Simulate(args) => simulate_cmd(&args, out),
        Command::Modes(args) => modes_cmd(&args, out),
        Command::Dataset(args) => dataset_cmd(&args, out),
        Command::Pod(args) => pod_cmd(&args, out),
        Command::Train(args) => train_cmd(&args, out),
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

/// The scenario after `--set`, `--tension` and `--centerline-points`, built, and the provenance of
/// a run of it (started now).
fn load(args: &ScenarioArgs) -> Result<(Scenario, Built, Provenance)> {
    let src = presets::source(&args.scenario)?;
    let mut scenario = presets::load_from(&src, &args.set)?;
    if let Some(u) = &args.tension {
        scenario.set_tensions(u).context("--tension")?;
    }
    if let Some(n) = args.centerline_points {
        scenario.output.centerline_points = n;
    }
    let built = build(&scenario)?;
    let provenance = Provenance::of_scenario(&src, &args.set, scenario.to_toml()?);
    Ok((scenario, built, provenance))
}

/// `--model DIR`: attaches a reduced model to `built` (the scenario table supplies the dataset
/// inputs of the model's initial guess).
fn attach_model(
    built: &mut Built,
    args: &ScenarioArgs,
    dir: &std::path::Path,
    tensions_from_signal: bool,
) -> Result<()> {
    let src = presets::source(&args.scenario)?;
    let options = reduce::AttachOptions {
        extrapolate: args.extrapolate,
        tensions_from_signal,
    };
    reduce::attach_source(built, &src, &args.set, dir, options)?;
    for w in built.reduced.iter().flat_map(|r| &r.warnings) {
        eprintln!("warning: {w}");
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

fn compare_cmd(args: &CompareArgs, out: &mut impl Write) -> Result<()> {
    use gvsrom::compare::{compare, differences, speed_ratio, Report, Side, Trajectory};
    let json = match &args.json {
        Some(path) => {
            let inputs = [
                ("REFERENCE", args.reference.as_path()),
                ("RUN", args.run.as_path()),
            ];
            gvsrom::output::refuse_overlap("--json", path, &inputs)?;
            Some(OutputFile::create("--json", path, "compare", args.force)?)
        }
        None => None,
    };
    let reference = Trajectory::load(&args.reference, "REFERENCE")?;
    let run = Trajectory::load(&args.run, "RUN")?;
    // only like with like: the same scenario, physics, input and sample times
    let diffs = differences(&reference, &run);
    if !args.allow_different && !diffs.none() {
        let mut reasons = diffs.differ.clone();
        reasons.extend(diffs.unknown.iter().map(|u| format!("cannot tell {u}")));
        return Err(gvsrom::ScenarioError::invalid(
            "RUN",
            format!(
                "{}; a run approximates a reference only under the same scenario, input and sample times (--allow-different compares them anyway)",
                reasons.join("; ")
            ),
        )
        .into());
    }
    let c = compare(&reference, &run)?;
    let describe = |tr: &Trajectory| {
        let wall = tr.wall_time_s;
        format!(
            "{}: {}, {} DOF, {} samples to t = {} s{}, {}",
            tr.dir.display(),
            tr.scenario,
            tr.n_dof,
            tr.samples(),
            tr.t.last().copied().unwrap_or(0.0),
            if tr.complete { "" } else { " (partial)" },
            if wall.is_finite() && wall > 0.0 {
                format!("{wall:.3} s wall")
            } else {
                "wall time n/a".to_string()
            }
        )
    };
    writeln!(out, "reference  {}", describe(&reference))?;
    // simulated time per wall time, so that a partial run compares fairly
    let speed = match speed_ratio(&reference, &run) {
        Some(ratio) if ratio >= 1.0 => format!("{ratio:.1}× faster"),
        Some(ratio) => format!("{:.1}× slower", 1.0 / ratio),
        None => {
            "speed n/a (a wall time is zero or not recorded, or a run has no time span)".to_string()
        }
    };
    writeln!(out, "run        {}: {speed}", describe(&run))?;
    for d in &diffs.differ {
        writeln!(out, "differ     {d} (compared anyway: --allow-different)")?;
    }
    for u in &diffs.unknown {
        writeln!(out, "unknown    {u} (compared anyway: --allow-different)")?;
    }
    writeln!(
        out,
        "compared   {} samples, t = {} … {} s",
        c.samples,
        reference.t[0],
        reference.t[c.samples - 1]
    )?;
    writeln!(
        out,
        "tip error  mean {:.3} %, max {:.3} % at t = {} s, last {:.3} % of the length {} m",
        c.tip_mean, c.tip_max, c.tip_max_t, c.tip_end, reference.length
    )?;
    let active: Vec<&str> = c
        .active
        .iter()
        .map(|&i| gvsrom::scenario::StrainMode::ALL[i].name())
        .collect();
    match (c.strain_mean, c.strain_max) {
        (Some(mean), Some(max)) => writeln!(
            out,
            "strain     error mean {mean:.3} %, max {max:.3} % (per sample: MAE over the points and {} / the reference's peak |ξ − ξ*|)",
            active.join(", ")
        )?,
        _ => writeln!(out, "strain     the reference is straight at every sample")?,
    }
    if let Some(json) = json {
        let report = Report {
            reference: Side::of(&reference),
            run: Side::of(&run),
            speed_ratio: speed_ratio(&reference, &run),
            comparison: c,
            differ: diffs.differ,
            unknown: diffs.unknown,
            provenance: gvsrom::provenance::Provenance::of_command()
                .compared(&args.reference, &args.run)?,
        };
        let path = json.commit_json(&report)?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}

fn check_cmd(args: &ScenarioArgs, out: &mut impl Write) -> Result<()> {
    let (scenario, built, _) = load(args)?;
    print_model(&scenario, args, &built, out)?;
    writeln!(out, "ok         the scenario is valid")?;
    Ok(())
}

/// The command's input files and directories that an output must not replace: the scenario file
/// (not a preset name, which is resolved first) and `model`, with their option names.
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

fn statics_cmd(args: &StaticsArgs, out: &mut impl Write) -> Result<()> {
    if let Some(path) = &args.json {
        let inputs = scenario_inputs(&args.scenario, args.model.as_ref());
        gvsrom::output::refuse_overlap("--json", path, &inputs)?;
    }
    let (scenario, mut built, mut provenance) = load(&args.scenario)?;
    if let Some(dir) = &args.model {
        attach_model(&mut built, &args.scenario, dir, false)?;
        provenance = provenance.model(dir)?;
    }
    let provenance = provenance.solver(&built.options);
    // the output is checked, locked and staged before the solve, so a bad path fails at once
    let json = match &args.json {
        Some(path) => Some(OutputFile::create("--json", path, "statics", args.force)?),
        None => None,
    };
    print_model(&scenario, &args.scenario, &built, out)?;
    let report = statics::solve_repeated(&built, args.repeat)?;
    print_solution(&report, out)?;
    if let Some(r) = &built.reduced {
        r.check_range(&report.q)?;
    }
    let comparison = if args.compare {
        let reduced = built.reduced.take();
        let hom = statics::solve_repeated(&built, args.repeat)?;
        built.reduced = reduced;
        let c = statics::compare(&built, &hom, &report);
        writeln!(
            out,
            "full model {} DOF solved in {:.2} ms; reduced {} DOF in {:.2} ms: {:.1}× faster",
            hom.n_dof,
            hom.solve_time_s * 1e3,
            report.n_dof,
            report.solve_time_s * 1e3,
            c.speedup
        )?;
        writeln!(
            out,
            "error      strain {:.3} % (MAE / peak |ξ − ξ*|), tip {:.4} % of the length",
            c.strain_error_percent, c.tip_error_percent
        )?;
        Some(c)
    } else {
        None
    };
    if let Some(json) = json {
        let doc = statics::StaticsJson {
            report: &report,
            model: args.model.as_ref().map(|p| p.display().to_string()),
            model_extrapolated: built
                .reduced
                .as_ref()
                .map(|r| r.extrapolated.clone())
                .unwrap_or_default(),
            comparison,
            provenance: Some(&provenance),
        };
        let path = json.commit_json(&doc)?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}

fn modes_cmd(args: &ModesArgs, out: &mut impl Write) -> Result<()> {
    use gvsrom::modes;
    if let Some(path) = &args.json {
        let inputs = scenario_inputs(&args.scenario, args.model.as_ref());
        gvsrom::output::refuse_overlap("--json", path, &inputs)?;
    }
    let (scenario, mut built, mut provenance) = load(&args.scenario)?;
    if let Some(dir) = &args.model {
        attach_model(&mut built, &args.scenario, dir, false)?;
        provenance = provenance.model(dir)?;
    }
    let provenance = provenance.solver(&built.options);
    let n_dof = built.n_dof();
    let (count, clipped) = modes::parse_count(args.count.as_deref(), n_dof)?;
    // the output is checked, locked and staged before the solve, so a bad path fails at once
    let json = match &args.json {
        Some(path) => Some(OutputFile::create("--json", path, "modes", args.force)?),
        None => None,
    };
    print_model(&scenario, &args.scenario, &built, out)?;
    if clipped {
        writeln!(
            out,
            "note       --count {} exceeds the model's {n_dof} DOF: reporting all {n_dof} modes",
            args.count.as_deref().unwrap_or_default()
        )?;
    }
    let (eq, report) = modes::compute(&built, count)?;
    writeln!(
        out,
        "solved     equilibrium in {} and {}, ‖R‖∞ = {:.3e} (as `gvsrom statics`)",
        plural(eq.iterations, "iteration"),
        plural(eq.load_stages, "load stage"),
        eq.residual_norm,
    )?;
    writeln!(
        out,
        "tip        position {} m",
        fmt_vec(&eq.tip_position, 6)
    )?;
    writeln!(
        out,
        "modes      lowest {count} of {n_dof}, undamped, linearized about the equilibrium; each shape by its largest share of the strain energy and its tip motion (world axes)"
    )?;
    writeln!(
        out,
        "{:>4}  {:>14}  {:>12}  {:<20}  tip motion",
        "mode", "frequency [Hz]", "period [s]", "strain energy"
    )?;
    let length = built.model.disc.length();
    let mut unstable = 0;
    for m in &report.modes {
        let period = match m.period_s {
            Some(t) => format!("{t:.6}"),
            None => "∞".into(),
        };
        let mut tip = modes::tip_motion(m, length);
        if m.omega_squared < 0.0 {
            unstable += 1;
            tip.push_str(&format!(" (ω² = {:.3e} < 0: unstable)", m.omega_squared));
        }
        writeln!(
            out,
            "{:>4}  {:>14.6}  {:>12}  {:<20}  {tip}",
            m.mode,
            m.frequency_hz,
            period,
            format!("{} {:.1} %", m.dominant_strain, 100.0 * m.dominant_share()),
        )?;
    }
    if unstable > 0 {
        writeln!(
            out,
            "note       {} with ω² < 0: the equilibrium is unstable (it buckles) along them; their frequency is shown as 0",
            plural(unstable, "mode")
        )?;
    }
    if let Some(json) = json {
        let doc = modes::ModesJson {
            report: &report,
            model: args.model.as_ref().map(|p| p.display().to_string()),
            provenance: Some(&provenance),
        };
        let path = json.commit_json(&doc)?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
}

fn pod_cmd(args: &PodArgs, out: &mut impl Write) -> Result<()> {
    let s = reduce::pod(&args.dataset, args.modes, &args.out, args.force)?;
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    writeln!(
        out,
        "snapshots  {} × {} (failed samples skipped), numerical rank {}",
        s.rows, s.features, s.numerical_rank
    )?;
    let shown: Vec<String> = s
        .singular_values
        .iter()
        .take(10)
        .map(|v| format!("{v:.4e}"))
        .collect();
    writeln!(
        out,
        "σ          {}{}",
        shown.join(" "),
        if s.singular_values.len() > 10 {
            " …"
        } else {
            ""
        }
    )?;
    writeln!(
        out,
        "modes      {} capture {:.8} of the snapshot energy",
        s.modes, s.captured_energy
    )?;
    anchors_line(out, s.anchor_equilibria, s.rows, s.anchor_time_s)?;
    writeln!(out, "model      {}", s.path.display())?;
    Ok(())
}

fn train_cmd(args: &TrainArgs, out: &mut impl Write) -> Result<()> {
    use rom::nn::TrainOptions;
    let options = TrainOptions {
        latent: args.latent,
        hidden_layers: args.hidden_layers,
        lambda: args.lambda,
        epochs: args.epochs,
        batch_size: args.batch_size,
        learning_rate: args.learning_rate,
        validation_fraction: args.validation_fraction,
        patience: (args.patience > 0).then_some(args.patience),
        seed: args.seed,
        lr_reductions: args.lr_reductions,
        fine_tune: rom::nn::FineTune::lbfgs(args.lbfgs_iterations),
        ..TrainOptions::default()
    };
    let signal = interrupt_flag();
    let bar = gvsrom::dataset::progress_bar_of(args.epochs as u64, "epochs");
    let mut progress = |epoch: usize, train: f64, val: Option<f64>| {
        // the fine-tuning phase runs past --epochs
        if epoch as u64 > bar.length().unwrap_or(0) {
            bar.set_length(epoch as u64);
        }
        bar.set_position(epoch as u64);
        bar.set_message(match val {
            Some(v) => format!("loss {train:.3e} / validation {v:.3e}"),
            None => format!("loss {train:.3e}"),
        });
        match signal.load(Ordering::SeqCst) {
            0 => ControlFlow::Continue(()),
            _ => ControlFlow::Break(()),
        }
    };
    let s = reduce::train(
        &args.dataset,
        &options,
        args.loss,
        &args.out,
        args.force,
        &mut progress,
    )?;
    bar.finish_and_clear();
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    let r = &s.report;
    writeln!(
        out,
        "snapshots  {} × {} ({} training, {} validation)",
        s.rows, s.features, r.n_train, r.n_val
    )?;
    writeln!(
        out,
        "network    {} (encoder; the decoder mirrors it), tanh hidden layers, linear output",
        s.encoder_sizes
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join("-")
    )?;
    writeln!(
        out,
        "trained    {} Adam epochs + {} fine-tuning iterations in {:.1} s (best at {} of {}; last phase ended by {:?})",
        r.epochs_run - r.fine_tune_epochs_run,
        r.fine_tune_epochs_run,
        r.wall_time.as_secs_f64(),
        r.best_epoch,
        r.epochs_run,
        r.stop
    )?;
    writeln!(
        out,
        "RMSE       {:.4e} training{}",
        r.final_train_rmse,
        r.final_val_rmse
            .map(|v| format!(", {v:.4e} validation"))
            .unwrap_or_default()
    )?;
    writeln!(
        out,
        "rest       q_r = {} ({}; it decodes to ‖ξ − ξ*‖ = {:.3e}); projection residual ≤ {:.1e}",
        fmt_vec(&s.rest, 6),
        match s.zero_anchor_rows {
            0 => "the encoding of the sample closest to the straight rod".to_string(),
            k => format!("the encoding of the straight rod, trained in as {k} zero-strain rows"),
        },
        s.rest_residual,
        s.projection_residual
    )?;
    anchors_line(out, s.anchor_equilibria, s.rows, s.anchor_time_s)?;
    writeln!(out, "model      {}", s.path.display())?;
    if signal.load(Ordering::SeqCst) != 0 {
        return Err(Interrupted {
            signal: signal.load(Ordering::SeqCst) as i32,
            message: format!(
                "training interrupted; the best weights so far were saved to `{}`",
                s.path.display()
            ),
        }
        .into());
    }
    Ok(())
}

fn simulate_cmd(args: &SimulateArgs, out: &mut impl Write) -> Result<()> {
    use gvs::inputs::Interpolation;
    use gvsrom::simulate::{self, InputSource, SimulateOptions};
    use std::io::IsTerminal;
    if let Some(dir) = &args.out {
        let mut inputs = scenario_inputs(&args.scenario, args.model.as_ref());
        if let Some(p) = &args.input {
            inputs.push(("--input", p.as_path()));
        }
        if let Some(p) = &args.load_schedule {
            inputs.push(("--load-schedule", p.as_path()));
        }
        gvsrom::output::refuse_overlap("--out", dir, &inputs)?;
    }
    let (scenario, mut built, mut provenance) = load(&args.scenario)?;
    if let Some(dir) = &args.model {
        // an input signal's tensions are checked against the model once the signal is built
        let signal_driven = args.input.is_some() || args.steps.is_some() || args.babble.is_some();
        attach_model(&mut built, &args.scenario, dir, signal_driven)?;
        provenance = provenance.model(dir)?;
    }
    let input = if let Some(path) = &args.input {
        let interpolation = if args.interpolate {
            Interpolation::Linear
        } else {
            Interpolation::Hold
        };
        InputSource::Csv {
            path: path.clone(),
            interpolation,
        }
    } else if let Some(v) = &args.steps {
        anyhow::ensure!(
            v.len() == 3,
            "--steps takes 3 comma-separated values LO,HI,PERIOD, got {}",
            v.len()
        );
        InputSource::Steps {
            lo: v[0],
            hi: v[1],
            period: v[2],
            seed: args.seed,
        }
    } else if let Some(v) = &args.babble {
        anyhow::ensure!(
            v.len() == 4,
            "--babble takes 4 comma-separated values LO,HI,HOLD_MIN,HOLD_MAX, got {}",
            v.len()
        );
        InputSource::Babble {
            lo: v[0],
            hi: v[1],
            hold_min: v[2],
            hold_max: v[3],
            seed: args.seed,
        }
    } else {
        InputSource::Constant
    };
    let choice = simulate::IntegratorChoice {
        method: args.method,
        rtol: args.rtol,
        atol: args.atol,
        max_order: args.max_order,
        error_norm: args.error_norm,
        rho_inf: args.rho_inf,
        fixed_step: args.fixed_step,
        fd_jacobian: args.fd_jacobian,
    };
    // the note printed when the rod's damping chose the method
    let (integrator, light) = simulate::choose_integrator(&built, &choice)?;
    let opts = SimulateOptions {
        duration: args.duration,
        sample_rate: args.sample_rate,
        input,
        start_at_equilibrium: args.from_equilibrium,
        integrator,
        load_schedule: args.load_schedule.clone(),
    };
    // everything is checked, and the output staged, before the computation starts
    let plan = simulate::plan(&built, &opts)?;
    for o in &plan.model_extrapolated {
        eprintln!("warning: extrapolating (--extrapolate): {o}");
    }
    let provenance = provenance
        .seed("input", args.seed)
        .input(plan.input.clone())
        .sampling(opts.duration, opts.sample_rate)
        .integrator(simulate::integrator_record(&opts.integrator, &choice));
    let mut writer = match &args.out {
        Some(dir) => {
            simulate::check_output_size(&built, &plan)?;
            let mut w = TrajectoryWriter::create(dir, args.force, &built)?;
            w.set_provenance(&provenance);
            Some(w)
        }
        None => None,
    };
    print_model(&scenario, &args.scenario, &built, out)?;
    if let Some(note) = light {
        writeln!(out, "{note}")?;
    }
    if let (Some(r), false) = (&built.reduced, args.from_equilibrium) {
        let off = r.rest_strain_offset();
        if off > 1e-6 {
            writeln!(
                out,
                "start      the reduced model's rest coordinates decode to max |ξ − ξ*| = {off:.3e} at the points, not to the straight rod the full model starts from (--from-equilibrium starts both at the scenario's equilibrium)"
            )?;
        }
    }
    let signal = interrupt_flag();
    let tty = std::io::stderr().is_terminal();
    let mut last_pct = usize::MAX;
    let duration = args.duration;
    let mut control = |t: f64| {
        if tty {
            let pct = ((t / duration) * 100.0).clamp(0.0, 100.0) as usize;
            if pct != last_pct {
                last_pct = pct;
                let bar = "#".repeat(pct / 4) + &".".repeat(25 - pct / 4);
                eprint!("\r[{bar}] {pct:3}%  t = {t:.2} s");
            }
        }
        match signal.load(Ordering::SeqCst) {
            0 => ControlFlow::Continue(()),
            s => ControlFlow::Break(format!("interrupted by {}", signal_name(s))),
        }
    };
    let outcome = simulate::run(
        &built,
        &plan,
        &opts.integrator,
        writer.as_mut(),
        &mut control,
    )?;
    if tty {
        eprintln!();
    }
    let sm = &outcome.summary;
    let t_last = sm.t_last.unwrap_or(0.0);
    writeln!(
        out,
        "simulated  {t_last:.3} s in {:.3} s wall time (real-time factor {:.1}), {} steps ({} failed, {} of them in Newton), {} RHS and {} Jacobian evaluations",
        sm.wall_time_s,
        outcome.real_time_factor(),
        sm.stats.steps,
        sm.stats.failed_steps,
        sm.stats.newton_failures,
        sm.stats.rhs_evals,
        sm.stats.jacobian_evals
    )?;
    if let Some(g) = &outcome.last_tip {
        writeln!(
            out,
            "tip        position {} m at t = {t_last:.3} s",
            fmt_vec(&[g.pos[0], g.pos[1], g.pos[2]], 6),
        )?;
    }
    let written = match writer {
        Some(w) => {
            let samples = w.samples();
            let dir = w.finish(&built, &plan, &outcome)?;
            let partial = if outcome.ending == Ending::Complete {
                ""
            } else {
                ", marked partial"
            };
            writeln!(
                out,
                "trajectory {} ({samples} samples{partial})",
                dir.display()
            )?;
            Some((dir, samples))
        }
        None => None,
    };
    let kept = match &written {
        Some((dir, n)) => format!(
            "the {n} samples before it were written to `{}`, marked partial",
            dir.display()
        ),
        None => format!(
            "{} samples computed; nothing was written (no --out)",
            sm.samples
        ),
    };
    match &outcome.ending {
        Ending::Complete => Ok(()),
        Ending::Failed { error } => anyhow::bail!("{error} ({kept})"),
        Ending::Interrupted { reason } => Err(Interrupted {
            signal: signal.load(Ordering::SeqCst) as i32,
            message: format!("{reason} at t = {t_last} s; {kept}"),
        }
        .into()),
    }
}

fn reproduce_cmd(args: &ReproduceArgs, out: &mut impl Write) -> Result<()> {
    use gvsrom::reproduce;
    let jobs = args.jobs.unwrap_or_else(reproduce::default_jobs);
    let opts = reproduce::Options {
        cases: args.cases.clone(),
        quick: args.quick || args.test_sizes,
        tiny: args.test_sizes,
        out: args.out.clone(),
        jobs,
        noise: args.noise,
    };
    let signal = interrupt_flag();
    match reproduce::run(&opts, signal.clone(), out) {
        Ok(_) => Ok(()),
        Err(e) => match e.downcast_ref::<reproduce::Interrupted>() {
            Some(i) => Err(Interrupted {
                signal: i.signal as i32,
                message: i.to_string(),
            }
            .into()),
            None => Err(e),
        },
    }
}

fn dataset_cmd(args: &gvsrom::dataset::DatasetArgs, out: &mut impl Write) -> Result<()> {
    let signal = interrupt_flag();
    let outcome = gvsrom::dataset::run(args, &signal, out)?;
    match outcome.interruption_message() {
        None => Ok(()),
        Some(message) => Err(Interrupted {
            signal: match signal.load(Ordering::SeqCst) {
                0 => signal_hook::consts::SIGINT,
                s => s as i32,
            },
            message,
        }
        .into()),
    }
}

/// A run stopped by SIGINT or SIGTERM; the binary exits with 128 + the signal number.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct Interrupted {
    pub signal: i32,
    pub message: String,
}

/// Installs SIGINT/SIGTERM handlers that record the signal in the returned flag (the run then stops
/// at its next sample and writes what it has); a second signal ends the process at once.
fn interrupt_flag() -> Arc<AtomicUsize> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let which = Arc::new(AtomicUsize::new(0));
    let again = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        // order matters: the shutdown checks the flag set by the earlier signal
        let _ = signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, again.clone());
        let _ = signal_hook::flag::register(sig, again.clone());
        let _ = signal_hook::flag::register_usize(sig, which.clone(), sig as usize);
    }
    which
}

fn signal_name(sig: usize) -> &'static str {
    match sig as i32 {
        signal_hook::consts::SIGINT => "SIGINT",
        signal_hook::consts::SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

fn fmt_vec(v: &[f64], prec: usize) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.prec$}")).collect();
    format!("[{}]", items.join(", "))
}

/// `[a, b, c]` with each number in its shortest exact form.
fn fmt_g(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("[{}]", items.join(", "))
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("{n} {word}")
    } else {
        format!("{n} {word}s")
    }
}

/// The summary of the model that runs. The scenario line is derived from the scenario as built;
/// the file's own `description` follows only when no `--set` or `--tension` changed the scenario
/// (its text may no longer hold then).
fn print_model(
    scenario: &Scenario,
    args: &ScenarioArgs,
    built: &Built,
    out: &mut impl Write,
) -> Result<()> {
    let m = &built.model;
    writeln!(
        out,
        "scenario   {} — {}",
        built.name,
        gvsrom::build::describe(scenario, built)
    )?;
    if let (Some(d), true, None) = (&scenario.description, args.set.is_empty(), &args.tension) {
        writeln!(out, "           {d}")?;
    }
    writeln!(
        out,
        "model      {} DOF, {} computational points, {}, length {} m, Magnus {:?}",
        m.n_dof(),
        m.disc.n_points(),
        plural(m.rod.divisions.len(), "division"),
        m.rod.length(),
        m.disc.order
    )?;
    if let Some(r) = &built.reduced {
        writeln!(
            out,
            "reduced    {} model `{}`: {} on the {}-DOF basis",
            r.kind,
            r.path.display(),
            plural(r.model.n_dof(), "coordinate"),
            m.n_dof()
        )?;
    }
    if built.u.is_empty() {
        writeln!(out, "tendons    none")?;
    } else {
        writeln!(
            out,
            "tendons    {}, u = {} N",
            built.u.len(),
            fmt_g(&built.u)
        )?;
    }
    let l = &built.loads;
    writeln!(
        out,
        "loads      gravity {} m/s², {}, {}",
        fmt_g(&l.gravity),
        plural(l.point.len(), "point wrench").replace("wrenchs", "wrenches"),
        plural(l.distributed.len(), "distributed wrench").replace("wrenchs", "wrenches"),
    )?;
    Ok(())
}

fn print_solution(r: &StaticsReport, out: &mut impl Write) -> Result<()> {
    writeln!(
        out,
        "solved     {} in {}, ‖R‖∞ = {:.3e}, {:.2} ms",
        plural(r.iterations, "iteration"),
        plural(r.load_stages, "load stage"),
        r.residual_norm,
        r.solve_time_s * 1e3
    )?;
    if let Some(c) = &r.continuation {
        let folds = c
            .folds
            .iter()
            .map(|l| format!("{l:.4}"))
            .collect::<Vec<_>>()
            .join(", ");
        writeln!(
            out,
            "continued  the load ramp stalled: followed the equilibria from the straight rod by arc-length continuation in {} ({} rejected), through {}{}",
            plural(c.steps, "step"),
            c.rejected_steps,
            plural(c.folds.len(), "fold"),
            if folds.is_empty() { String::new() } else { format!(" at load factor {folds}") }
        )?;
    }
    writeln!(out, "tip        position {} m", fmt_vec(&r.tip_position, 6))?;
    let (axis, angle) = r.tip_axis_angle();
    writeln!(
        out,
        "           rotation axis {}, angle {:.4}°",
        fmt_vec(&axis, 6),
        angle.to_degrees()
    )?;
    for (i, row) in r.tip_rotation.iter().enumerate() {
        let label = if i == 0 { "R =" } else { "   " };
        writeln!(out, "           {label} {}", fmt_vec(row, 6))?;
    }
    Ok(())
}

/// The `anchors` line of `pod` and `train` (nothing when no anchor is an equilibrium).
fn anchors_line(
    out: &mut dyn Write,
    equilibria: usize,
    rows: usize,
    seconds: f64,
) -> std::io::Result<()> {
    if equilibria == 0 {
        return Ok(());
    }
    writeln!(
        out,
        "anchors    {equilibria} of {rows} training inputs hold the reduced model's own equilibrium (solved in {seconds:.2} s): statics --model starts there"
    )
}

// ---- gvsrom plot ---------------------------------------------------------------------------------

/// `gvsrom plot INPUT --out DIR`.
#[derive(Debug, Args)]
pub struct PlotArgs {
    /// A `statics --json` file, or a directory written by `simulate --out`, `dataset`, `pod` or
    /// `train`
    pub input: PathBuf,
    /// New directory for the figures
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Image formats, comma-separated
    #[arg(long, value_enum, value_delimiter = ',', default_value = "svg,png")]
    pub format: Vec<gvsrom::figures::FigureFormat>,
    /// Replace DIR if it is an earlier gvsrom output
    #[arg(long)]
    pub force: bool,
}

fn plot_cmd(args: &PlotArgs, out: &mut impl Write) -> Result<()> {
    let s = gvsrom::figures::plot_outputs(&args.input, &args.out, &args.format, args.force)?;
    for note in &s.notes {
        writeln!(out, "note: {note}")?;
    }
    writeln!(
        out,
        "{} figures of the {} `{}` in {} ({:.1} s):",
        s.written.len(),
        s.kind.name(),
        args.input.display(),
        s.out.display(),
        s.wall_time_s
    )?;
    for w in &s.written {
        writeln!(out, "  {:<28} {:>9} bytes", w.name, w.bytes)?;
    }
    Ok(())
}
