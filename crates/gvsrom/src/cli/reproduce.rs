//! `gvsrom reproduce` and `gvsrom dataset`: the long runs that write directories.

use super::*;

/// `gvsrom reproduce`.
#[derive(Debug, Args)]
pub struct ReproduceArgs {
    /// The paper's cases to run (one or more, or `all`).
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
    #[arg(value_parser = super::whole::<usize>, long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Testing aid: the smallest sizes that still run every step (implies --quick).
    #[arg(long, hide = true)]
    pub test_sizes: bool,
    /// The noise study's Gaussian noise, σ relative to the RMS of each strain component of the snapshots.
    #[arg(long, value_name = "LEVEL", default_value_t = gvsrom::reproduce::DEFAULT_NOISE)]
    pub noise: f64,
}

pub(super) fn reproduce_cmd(args: &ReproduceArgs, out: &mut impl Write) -> Result<()> {
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

pub(super) fn dataset_cmd(args: &DatasetArgs, out: &mut impl Write) -> Result<()> {
    let signal = interrupt_flag();
    let request = args.request();
    gvsrom::dataset::refuse_set_varied(&args.set, &request)?;
    let outcome = gvsrom::dataset::run(&request, &signal)?;
    for w in &outcome.warnings {
        gvsrom::progress::stderr_line(format_args!("warning: {w}"));
    }
    summary(out, &outcome.path, &outcome.meta, outcome.resumed_chunks)?;
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

/// `gvsrom dataset`: the scenario, the plan and the output.
#[derive(Debug, Args)]
pub struct DatasetArgs {
    /// A preset name (see `gvsrom presets`) or the path of a scenario TOML file.
    pub scenario: String,

    /// Override a scenario value by its TOML path before sampling (as for `statics`); repeatable.
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub set: Vec<String>,

    /// Sweep PATH over an even 1-D grid from LO to HI including both ends (`--samples` values).
    /// Repeat it (or use `*`, e.g. `tendons.*.tension`) to sweep several values together.
    #[arg(long, value_name = "PATH=LO:HI", allow_hyphen_values = true)]
    pub sweep: Vec<String>,

    /// Grid over the product of the ranges: round(samples^(1/d)) even values per parameter, which
    /// must give exactly `--samples` (e.g. 15625 = 5^6 for `tendons.*.tension` on six tendons).
    #[arg(long, value_name = "PATH=LO:HI", allow_hyphen_values = true)]
    pub grid: Vec<String>,

    /// Uniform random values in [LO, HI), seeded by `--seed`; repeatable, `*` allowed.
    #[arg(long, value_name = "PATH=LO:HI", allow_hyphen_values = true)]
    pub random: Vec<String>,

    /// Number of samples.
    #[arg(value_parser = super::whole::<usize>, long, value_name = "N")]
    pub samples: Option<usize>,

    /// Seed of `--random`, `--steps` and `--babble` (same seed, same dataset) [default: 0].
    // (no `requires`: the plan refuses a seed it would not use, saying why, where clap's message
    // only listed the options)
    #[arg(value_parser = super::whole::<u64>, long)]
    pub seed: Option<u64>,

    /// Samples per chunk: the unit of parallel work, of warm-start chains and of resuming. Part of
    /// the plan (a different chunk size gives slightly different last digits).
    #[arg(value_parser = super::whole::<usize>, long, value_name = "N", default_value_t = gvsrom::dataset::DEFAULT_CHUNK_SIZE, conflicts_with = "duration")]
    pub chunk_size: usize,

    /// Worker threads (default: one per core). The files do not depend on it.
    #[arg(value_parser = super::whole::<usize>, long, value_name = "N")]
    pub threads: Option<usize>,

    /// Write the dataset into the new directory DIR.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Replace DIR if it is an earlier gvsrom output holding only its own files.
    #[arg(long, conflicts_with = "resume")]
    pub force: bool,

    /// Continue the incomplete dataset in DIR (same scenario, plan and seed): its finished chunks are
    /// kept, the missing ones computed, and DIR replaced by the result.
    #[arg(long)]
    pub resume: bool,

    /// Dynamic dataset: simulate T seconds (inputs as for `simulate`) and store every output sample.
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    pub duration: Option<f64>,

    /// Dynamic dataset: output samples per second [Hz].
    #[arg(
        long,
        value_name = "HZ",
        allow_hyphen_values = true,
        requires = "duration"
    )]
    pub sample_rate: Option<f64>,

    /// Dynamic dataset: actuation from a CSV file `t, u_1, …, u_na` (as for `simulate`).
    #[arg(long, value_name = "FILE", requires = "duration", conflicts_with_all = ["steps", "babble"])]
    pub input: Option<PathBuf>,

    /// Dynamic dataset: interpolate the CSV input linearly.
    #[arg(long, requires = "input")]
    pub interpolate: bool,

    /// Dynamic dataset: random step actuation LO,HI,PERIOD (seeded by `--seed`).
    #[arg(
        long,
        value_name = "LO,HI,PERIOD",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "duration",
        conflicts_with = "babble"
    )]
    pub steps: Option<Vec<f64>>,

    /// Dynamic dataset: actuator babbling LO,HI,HOLD_MIN,HOLD_MAX (paper IV-C2: `--babble=-15,0,0.5,1`).
    #[arg(
        long,
        value_name = "LO,HI,HOLD_MIN,HOLD_MAX",
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "duration"
    )]
    pub babble: Option<Vec<f64>>,

    /// Dynamic dataset: start at the static equilibrium under the scenario's loads and tensions.
    #[arg(long, requires = "duration")]
    pub from_equilibrium: bool,

    /// Dynamic dataset: relative tolerance of the integrator (default as `simulate`: 1e-3, or
    /// 1e-4 with SDIRK4 for a lightly damped rod).
    #[arg(long, requires = "duration")]
    pub rtol: Option<f64>,

    /// Dynamic dataset: absolute tolerance of the integrator.
    #[arg(long, default_value_t = 1e-6, requires = "duration")]
    pub atol: f64,

    /// Testing aid: stop (as if interrupted) once N chunks have been started.
    #[arg(value_parser = super::whole::<usize>, long, value_name = "N", hide = true)]
    pub stop_after_chunks: Option<usize>,
}

impl DatasetArgs {
    /// The library's request of these options.
    fn request(&self) -> gvsrom::dataset::DatasetRequest {
        gvsrom::dataset::DatasetRequest {
            scenario: self.scenario.clone(),
            set: self.set.clone(),
            sweep: self.sweep.clone(),
            grid: self.grid.clone(),
            random: self.random.clone(),
            samples: self.samples,
            seed: self.seed,
            chunk_size: self.chunk_size,
            threads: self.threads,
            out: self.out.clone(),
            force: self.force,
            resume: self.resume,
            duration: self.duration,
            sample_rate: self.sample_rate,
            input: self.input.clone(),
            interpolate: self.interpolate,
            steps: self.steps.clone(),
            babble: self.babble.clone(),
            from_equilibrium: self.from_equilibrium,
            rtol: self.rtol,
            atol: self.atol,
            stop_after_chunks: self.stop_after_chunks,
        }
    }
}

/// The summary `gvsrom dataset` prints of a finished (or interrupted) dataset.
fn summary(
    out: &mut dyn Write,
    path: &std::path::Path,
    m: &gvsrom::dataset::Meta,
    resumed: usize,
) -> std::io::Result<()> {
    writeln!(
        out,
        "scenario   {}: {} DOF, {} computational points, active strains [{}]",
        m.scenario,
        m.n_dof,
        m.n_points,
        m.components.join(", ")
    )?;
    match (&m.plan, &m.dynamic) {
        (Some(p), _) => writeln!(
            out,
            "plan       {} {} ({}, {}, seed {})",
            p.kind.option(),
            p.specs.join(" "),
            print::plural(m.samples, "sample"),
            print::plural(m.parameters.len(), "parameter"),
            m.seed
        )?,
        (None, Some(d)) => writeln!(
            out,
            "run        {} s at {} Hz, input {} ({})",
            d.duration,
            d.sample_rate,
            d.input,
            print::plural(m.samples, "sample")
        )?,
        (None, None) => {}
    }
    let c = &m.counts;
    if m.dynamic.is_some() {
        writeln!(
            out,
            "simulated  {} stored in {:.2} s",
            print::plural(c.ok, "sample"),
            m.wall_time_s
        )?;
    } else {
        writeln!(
            out,
            "solved     {} ok ({} warm-started), {} failed, {} not computed in {:.2} s on {}{}",
            c.ok,
            c.warm_started,
            c.failed,
            c.not_computed,
            m.wall_time_s,
            print::plural(m.threads, "thread"),
            if resumed > 0 {
                format!(" ({resumed} chunks kept from the resumed run)")
            } else {
                String::new()
            }
        )?;
    }
    for f in m.failures.iter().take(5) {
        writeln!(out, "failed     sample {}: {}", f.index, f.reason)?;
    }
    if m.failures.len() > 5 {
        writeln!(
            out,
            "failed     … {} more in meta.json",
            m.failures.len() - 5
        )?;
    }
    writeln!(
        out,
        "dataset    {} ({} × {} strain values{})",
        path.display(),
        m.samples,
        m.n_points * m.components.len(),
        if m.complete { "" } else { ", incomplete" }
    )
}
