//! `gvsrom simulate`.

use super::*;

#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("random_input").args(["steps", "babble"]).multiple(false)))]
pub struct SimulateArgs {
    #[command(flatten)]
    pub scenario: ScenarioArgs,

    /// Simulated time [s], at least 1e-6.
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
    /// `--interpolate`): each tendon's tension [N], or, for a tendon driven by its displacement
    /// (`--displacement` with its thread's `axial_stiffness`), its motor's displacement [m].
    /// Without an input option the scenario's tensions (and displacements) are held constant.
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

    /// Seed of the random inputs `--steps` and `--babble` (same seed, same signal).
    #[arg(value_parser = super::whole::<u64>, long, default_value_t = 1, requires = "random_input")]
    pub seed: u64,

    /// Start at the static equilibrium under the scenario's tensions and loads, then switch to the
    /// input at t = 0 (a release test when the input differs).
    #[arg(long)]
    pub from_equilibrium: bool,

    /// Relative tolerance of the adaptive integrator, in [1e-12, 0.1]. Default 1e-3 (ode15s), or
    /// 1e-4 when the automatic method is SDIRK4 for a lightly damped rod (see `--method`). The
    /// error test is `|e| ≤ atol + rtol |y|`: below about `atol / |y|` the absolute part decides,
    /// so to tighten a run lower `--atol` with it (an undamped release: rtol 1e-6 and 1e-8 gave the
    /// same energy drift at the default atol, 1e-8 with atol 1e-12 a 40× smaller one)
    #[arg(long, allow_hyphen_values = true)]
    pub rtol: Option<f64>,

    /// Absolute tolerance of the adaptive integrator, in [1e-14, 1e-2]. Default 1e-6 (ode15s).
    #[arg(long, allow_hyphen_values = true)]
    pub atol: Option<f64>,

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
    #[arg(value_parser = super::whole::<usize>, long)]
    pub max_order: Option<usize>,

    /// Error test of the adaptive methods: `componentwise` (ode15s) or `mass` (positions and
    /// velocities in the norm of the mass matrix: modes that move little mass do not limit the
    /// step). Default: mass for SDIRK4 (`--method sdirk`, or `auto` on a lightly damped rod) and
    /// for the NDF on a lightly damped rod (see `--max-order`); componentwise otherwise. With
    /// `--method galpha`, `mass` is what makes it usable on a lightly damped rod.
    #[arg(long, value_enum)]
    pub error_norm: Option<ErrorNormChoice>,

    /// Generalized-α: spectral radius at infinite frequency in [0, 1] (1: no numerical dissipation).
    /// Default 0.8; only with `--method galpha`.
    #[arg(long, allow_hyphen_values = true)]
    pub rho_inf: Option<f64>,

    /// Time-varying external loads: a CSV file with columns `t, λ` that scales every external load and
    /// gravity, linearly interpolated between rows (e.g. a load applied then removed).
    #[arg(long, value_name = "FILE")]
    pub load_schedule: Option<PathBuf>,

    /// Use finite differences of the right-hand side for the integrator's Jacobian instead of the
    /// structured analytic one (the NDF and the fixed step; SDIRK4 and generalized-α refuse it).
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

    /// Time the integration N times (≥ 1): after the written run, N − 1 more without output, one
    /// after the other; the wall time reported and recorded (`meta.json`'s `wall_time_s`) is the
    /// smallest, with every run's in `wall_times_s` — for speed comparisons on a shared machine.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub repeat: u32,

    /// Simulate with the reduced model in directory MODEL (from `gvsrom pod` or `gvsrom train`) in
    /// place of the scenario's basis.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
}

pub(super) fn simulate_cmd(args: &SimulateArgs, out: &mut impl Write) -> Result<()> {
    super::extrapolate_needs_model(&args.scenario, args.model.as_deref())?;
    use gvsrom::simulate::{self, InputSource};
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
    let mut r = load(&args.scenario)?;
    if let Some(dir) = &args.model {
        // an input signal's tensions are checked against the model once the signal is built
        // (with --from-equilibrium the scenario's tensions are the start's, and checked too)
        let signal_driven = (args.input.is_some() || args.steps.is_some() || args.babble.is_some())
            && !args.from_equilibrium;
        attach_model(&mut r, &args.scenario, dir, signal_driven)?;
    }
    let (scenario, built) = (&r.scenario, &r.built);
    let input = InputSource::from_options(
        args.input.as_deref(),
        args.interpolate,
        args.steps.as_deref(),
        args.babble.as_deref(),
        args.seed,
    )?;
    // a driven tendon's column is its motor's displacement, its tension found as the run goes
    let driven: Vec<String> = (0..built.displacement.len())
        .filter(|&k| built.displacement[k].is_some())
        .map(|k| k.to_string())
        .collect();
    let input_description = input.describe().map(|d| match driven.len() {
        0 => d,
        1 => format!(
            "{d} (tendon {}'s channel its displacement δ [m]; u.npy holds the tensions found)",
            driven[0]
        ),
        _ => format!(
            "{d} (tendons {}'s channels their displacements δ [m]; u.npy holds the tensions found)",
            driven.join(", ")
        ),
    });
    let signal = input_description.map(|d| match args.from_equilibrium {
        true if built.displacement_driven() => {
            format!("{d}, from the equilibrium under the scenario's drives")
        }
        true => format!(
            "{d}, from the equilibrium under the scenario's u = {} N",
            fmt_g(&built.u)
        ),
        false => d,
    });
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
    // everything is checked, and the output staged, before the computation starts
    let prepared = simulate::prepare(
        built,
        simulate::Request {
            duration: args.duration,
            sample_rate: args.sample_rate,
            input,
            start: simulate::Start::rest_or_equilibrium(args.from_equilibrium),
            load_schedule: args.load_schedule.clone(),
            integrator: choice,
        },
    )?;
    for o in &prepared.plan.model_extrapolated {
        gvsrom::progress::stderr_line(format_args!("warning: extrapolating (--extrapolate): {o}"));
    }
    if let Some(w2) = prepared.plan.start_divergence {
        let note = simulate::unstable_start_note(w2);
        gvsrom::progress::stderr_line(format_args!("warning: {note}"));
    }
    let provenance = prepared.record(r.provenance.clone().seed("input", args.seed), &choice);
    let (opts, plan, light) = (&prepared.opts, &prepared.plan, &prepared.note);
    let mut writer = match &args.out {
        Some(dir) => {
            simulate::check_output_size(built, plan)?;
            let mut w = TrajectoryWriter::create(dir, args.force, built)?;
            w.set_provenance(&provenance);
            Some(w)
        }
        None => None,
    };
    print_model(scenario, &args.scenario, built, signal.as_deref(), out)?;
    print_motion_note(built, out)?;
    if let Some(note) = light {
        writeln!(out, "{note}")?;
    }
    if let (Some(r), false) = (&built.reduced, args.from_equilibrium) {
        let off = r.rest_strain_offset();
        if off > 1e-6 {
            writeln!(
                out,
                "start      the reduced model's rest coordinates decode to max |ξ − ξ*| = {off:.3e} at the points, not to the straight rod the full model starts from (with --from-equilibrium each model starts at its own equilibrium under the starting tensions)"
            )?;
        }
    }
    let signal = interrupt_flag();
    let tty = std::io::stderr().is_terminal();
    let mut last_pct = usize::MAX;
    let duration = args.duration;
    // Ctrl-C or SIGTERM stops the run (and any timing repetition) within one step
    let on_signal = || match signal.load(Ordering::SeqCst) {
        0 => ControlFlow::Continue(()),
        s => ControlFlow::Break(format!("interrupted by {}", signal_name(s))),
    };
    let mut control = |t: f64| {
        if tty {
            let pct = ((t / duration) * 100.0).clamp(0.0, 100.0) as usize;
            if pct != last_pct {
                last_pct = pct;
                let bar = "#".repeat(pct / 4) + &".".repeat(25 - pct / 4);
                // best effort, as every stderr line ([`gvsrom::progress::stderr_line`])
                let _ = write!(std::io::stderr().lock(), "\r[{bar}] {pct:3}%  t = {t:.2} s");
            }
        }
        on_signal()
    };
    let mut outcome = simulate::run(built, plan, &opts.integrator, writer.as_mut(), &mut control)?;
    if tty {
        gvsrom::progress::stderr_line(format_args!(""));
    }
    let timing_stopped = outcome.time_again(
        built,
        plan,
        &opts.integrator,
        args.repeat as usize - 1,
        &mut |_| on_signal(),
    )?;
    let sm = &outcome.summary;
    let t_last = sm.t_last.unwrap_or(0.0);
    let timed = match outcome.wall_times_s.len() {
        1 => String::new(),
        n => format!(
            ", the smallest of {n} runs (median {:.3} s)",
            outcome.median_wall_time_s()
        ),
    };
    let t_shown = fmt_fixed(t_last, 3);
    writeln!(
        out,
        "simulated  {t_shown} s in {} s wall time{timed} (real-time factor {}), {} steps ({} failed, {} of them in Newton), {} RHS and {} Jacobian evaluations",
        fmt_fixed(sm.wall_time_s, 3),
        fmt_fixed(outcome.real_time_factor(), 1),
        sm.stats.steps,
        sm.stats.failed_steps,
        sm.stats.newton_failures,
        sm.stats.rhs_evals,
        sm.stats.jacobian_evals
    )?;
    if let Some(g) = &outcome.last_tip {
        writeln!(
            out,
            "tip        position {} m at t = {t_shown} s",
            fmt_vec(&[g.pos[0], g.pos[1], g.pos[2]], 6),
        )?;
    }
    // the tensions the displacement drives found, as statics prints them
    if built.displacement_driven() && !outcome.last_u.is_empty() {
        let u: Vec<String> = outcome
            .last_u
            .iter()
            .map(|&v| gvsrom::build::significant(v))
            .collect();
        let slack: Vec<String> = (0..outcome.last_u.len())
            .filter(|&k| built.displacement[k].is_some() && outcome.last_u[k] == 0.0)
            .map(|k| k.to_string())
            .collect();
        writeln!(
            out,
            "tensions   u = [{}] N at t = {t_shown} s, the driven tendons' from their threads' stretch{}",
            u.join(", "),
            match slack.len() {
                0 => String::new(),
                1 => format!("; tendon {} is slack", slack[0]),
                _ => format!("; tendons {} are slack", slack.join(", ")),
            }
        )?;
    }
    // a fixed step halves where Newton fails: say so when that set the cost
    if let Some(h) = args.fixed_step {
        let nominal = (t_last / h).ceil().max(1.0) as usize;
        if sm.stats.failed_steps > 0 && sm.stats.steps > nominal + nominal / 2 {
            writeln!(
                out,
                "note       --fixed-step {h} s: Newton failed {} times at that step, which was halved there (up to 10 times) and took {} steps against {nominal} nominal; a smaller --fixed-step runs at a steady cost",
                sm.stats.failed_steps, sm.stats.steps
            )?;
        }
    }
    if let Some(e) = &outcome.energy {
        writeln!(
            out,
            "energy     conservative run (no damping, friction or work by the loads): the total energy moved from {} J by +{} / −{} J at most, {:.3} % / {:.3} % of the largest kinetic energy ({} J)",
            gvs::error::fmt_sci(e.initial, 4),
            gvs::error::fmt_sci(e.largest_gain, 3),
            gvs::error::fmt_sci(e.largest_loss, 3),
            100.0 * e.relative_gain(),
            100.0 * e.relative_loss(),
            gvs::error::fmt_sci(e.kinetic_max, 3),
        )?;
        for note in e.notes(["--rtol", "--atol"]) {
            writeln!(out, "note       {note}")?;
        }
    }
    for o in &outcome.model_extrapolated {
        writeln!(out, "note       {o}")?;
    }

    let written = match writer {
        Some(w) => {
            let samples = w.samples();
            let dir = w.finish(built, plan, &outcome)?;
            let partial = if outcome.ending == Ending::Complete {
                ""
            } else {
                ", marked partial"
            };
            writeln!(
                out,
                "trajectory {} ({}{partial})",
                dir.display(),
                super::print::plural(samples, "sample")
            )?;
            Some((dir, samples))
        }
        None => None,
    };
    let kept = match &written {
        Some((dir, n)) => format!(
            "the {} before it {} written to `{}`, marked partial",
            super::print::plural(*n, "sample"),
            if *n == 1 { "was" } else { "were" },
            dir.display()
        ),
        None => format!(
            "{} computed; nothing was written (no --out)",
            super::print::plural(sm.samples, "sample")
        ),
    };
    match &outcome.ending {
        Ending::Complete => match timing_stopped {
            None => Ok(()),
            Some(reason) => Err(Interrupted {
                signal: signal.load(Ordering::SeqCst) as i32,
                message: format!(
                    "{reason} while timing the run again (--repeat {}): the trajectory is complete{}; {} of the runs were timed",
                    args.repeat,
                    match &written {
                        Some((dir, _)) => format!(" and written to `{}`", dir.display()),
                        None => String::new(),
                    },
                    outcome.wall_times_s.len()
                ),
            }
            .into()),
        },
        Ending::Failed { error, .. } => anyhow::bail!("{error} ({kept})"),
        Ending::Interrupted { reason } => Err(Interrupted {
            signal: signal.load(Ordering::SeqCst) as i32,
            message: format!("{reason} at t = {t_last} s; {kept}"),
        }
        .into()),
    }
}
