//! `gvsrom reproduce` and `gvsrom dataset`: the long runs that write directories.

use super::*;

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

pub(super) fn dataset_cmd(args: &gvsrom::dataset::DatasetArgs, out: &mut impl Write) -> Result<()> {
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
