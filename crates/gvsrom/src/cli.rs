//! Command-line interface: argument parsing (clap) and the text printed by each command. No physics
//! here: scenarios are loaded and built by the library, solved by the engine.

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use gvsrom::presets::{self, PRESETS};
use gvsrom::statics::{self, StaticsReport};
use gvsrom::{build, Built, Scenario};
use std::io::Write;
use std::path::PathBuf;

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
    /// Validate a preset or scenario file and print the model's size, without solving.
    Check(ScenarioArgs),
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

    /// Number of equally spaced centreline samples in the JSON output (overrides
    /// `output.centerline_points`, default 21).
    #[arg(long, value_name = "N")]
    pub centerline_points: Option<usize>,
}

#[derive(Debug, Args)]
pub struct StaticsArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Also write the solution (q, tip pose, centreline, strains, solver statistics) as JSON to FILE.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// Runs the parsed command, printing to `out`.
pub fn run(cli: Cli, out: &mut impl Write) -> Result<()> {
    match cli.command {
        Command::Statics(args) => statics_cmd(&args, out),
        Command::Check(args) => check_cmd(&args, out),
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

fn load(args: &ScenarioArgs) -> Result<(Scenario, Built)> {
    let mut scenario = presets::load(&args.scenario, &args.set)?;
    if let Some(u) = &args.tension {
        scenario.set_tensions(u).context("--tension")?;
    }
    if let Some(n) = args.centerline_points {
        scenario.output.centerline_points = n;
    }
    let built = build(&scenario)?;
    Ok((scenario, built))
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
    let (scenario, built) = load(args)?;
    print_model(&scenario, &built, out)?;
    writeln!(out, "ok         the scenario is valid")?;
    Ok(())
}

fn statics_cmd(args: &StaticsArgs, out: &mut impl Write) -> Result<()> {
    let (scenario, built) = load(&args.scenario)?;
    print_model(&scenario, &built, out)?;
    let report = statics::solve(&built)?;
    print_solution(&report, out)?;
    if let Some(path) = &args.json {
        statics::write_json_atomic(path, &report)
            .with_context(|| format!("cannot write `{}`", path.display()))?;
        writeln!(out, "json       {}", path.display())?;
    }
    Ok(())
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

fn print_model(scenario: &Scenario, built: &Built, out: &mut impl Write) -> Result<()> {
    let m = &built.model;
    let desc = scenario
        .description
        .as_deref()
        .map(|d| format!(" — {d}"))
        .unwrap_or_default();
    writeln!(out, "scenario   {}{desc}", built.name)?;
    writeln!(
        out,
        "model      {} DOF, {} computational points, {}, length {} m, Magnus {:?}",
        m.n_dof(),
        m.disc.n_points(),
        plural(m.rod.divisions.len(), "division"),
        m.rod.length(),
        m.disc.order
    )?;
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
