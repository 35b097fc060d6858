//! `gvsrom reproduce`: the paper's studies end to end (Sections IV and V), each a thin orchestration
//! of the library functions the commands call (`dataset`, `pod`, `train`, `statics [--model]`),
//! with its tables beside the paper's, its figures and one HTML page.
//!
//! A run directory `<out>` ([`crate::output::RunDir`]) holds `steps/` (every step's output and
//! record, keyed by a hash of its configuration and inputs: see [`step`]), one report directory per
//! case (`summary.md`, `results.json`, figures: see [`report`]) and `index.html`. Running again
//! reuses every step whose key is unchanged, so an interrupted run resumes and one changed option
//! recomputes only what depends on it.

pub mod evaluation;
pub mod figures;
pub mod html;
pub mod intrinsic;
pub mod iv_a;
pub mod iv_b;
pub mod iv_b_built;
pub mod iv_c1;
pub mod iv_c2;
pub mod iv_common;
pub mod latent;
pub mod noise;
pub mod paper;
pub mod report;
pub mod sim_test;
pub mod statics_study;
pub mod step;
pub mod tasks;
pub mod v;

pub use step::{Interrupted, Run, StepRecord};

use report::CaseReport;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::AtomicUsize;
use std::sync::Arc;
use std::time::Instant;

/// A study of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Case {
    /// IV-A: single-tendon manipulator, Table I (top), Figs. 3–4, Table III row.
    #[value(name = "iv-a")]
    IvA,
    /// IV-B: soft beam under a moment pulse, Table I (bottom), Figs. 5–6, Table III row.
    #[value(name = "iv-b")]
    IvB,
    /// IV-C1: six-tendon manipulator under gravity, statics: AE r = 6 against POD-6 (Fig. 7),
    /// grid against random sampling (Fig. 8), Table III row.
    #[value(name = "iv-c1")]
    IvC1,
    /// IV-C2: six-tendon manipulator, dynamics: babbling data, AE- and POD-ROMs with r = 1 … 8 on a
    /// new 10 s input (Fig. 9), Table III row.
    #[value(name = "iv-c2")]
    IvC2,
    /// V: the prototype's four tensions, AE-ROM and POD-ROM with one DOF (Fig. 10b).
    #[value(name = "v")]
    V,
    /// The IV-A and IV-B autoencoders retrained on snapshots with Gaussian noise.
    #[value(name = "noise")]
    Noise,
    /// Every case above.
    #[value(name = "all")]
    All,
}

impl Case {
    /// The directory name and label of a case.
    pub fn name(self) -> &'static str {
        match self {
            Case::IvA => "iv-a",
            Case::IvB => "iv-b",
            Case::IvC1 => "iv-c1",
            Case::IvC2 => "iv-c2",
            Case::V => "v",
            Case::Noise => "noise",
            Case::All => "all",
        }
    }

    /// Every case, in the paper's order.
    pub const EVERY: [Case; 6] = [
        Case::IvA,
        Case::IvB,
        Case::IvC1,
        Case::IvC2,
        Case::V,
        Case::Noise,
    ];
}

/// What `gvsrom reproduce` is asked to do.
#[derive(Debug, Clone)]
pub struct Options {
    pub cases: Vec<Case>,
    /// Reduced sizes (samples, epochs, architectures): the whole run in minutes.
    pub quick: bool,
    /// The smallest sizes that still exercise every step (tests; implies `quick`). The cases that
    /// do not know them run their quick sizes.
    pub tiny: bool,
    pub out: PathBuf,
    /// Worker threads (dataset generation, training several models at once, anchors).
    pub jobs: usize,
    /// The noise study's σ relative to the RMS of each strain component of the snapshots.
    pub noise: f64,
}

/// Worker threads unless `--jobs` says otherwise: one per core.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}

/// The noise study's level unless `--noise` says otherwise.
pub const DEFAULT_NOISE: f64 = 0.02;

impl Options {
    /// The cases to run, `all` expanded, each once, in the paper's order.
    pub fn case_list(&self) -> Vec<Case> {
        let all = self.cases.contains(&Case::All);
        Case::EVERY
            .into_iter()
            .filter(|c| all || self.cases.contains(c))
            .collect()
    }
}

/// One case done.
#[derive(Debug, Clone)]
pub struct CaseDone {
    pub case: Case,
    pub dir: PathBuf,
    pub wall_time_s: f64,
    pub steps: usize,
    pub reused: usize,
}

/// Runs the cases of `opts` in order, printing a line per case to `log`; writes `index.html` over
/// every case report in the run directory. `interrupt` holds a signal number once SIGINT/SIGTERM
/// arrived: the run stops at the next step boundary (or inside a dataset or a training) with
/// [`Interrupted`], keeping the finished steps.
pub fn run(
    opts: &Options,
    interrupt: Arc<AtomicUsize>,
    log: &mut dyn Write,
) -> anyhow::Result<Vec<CaseDone>> {
    anyhow::ensure!(
        (1..=256).contains(&opts.jobs),
        "--jobs {}: expected an integer in [1, 256]",
        opts.jobs
    );
    anyhow::ensure!(
        opts.noise.is_finite() && (0.0..=1.0).contains(&opts.noise),
        "--noise {}: expected a number in [0, 1] (σ relative to each strain component's RMS)",
        gvs::error::fmt_value(opts.noise)
    );
    let cases = opts.case_list();
    anyhow::ensure!(!cases.is_empty(), "no case to reproduce");
    // a level no case reads would be ignored without a word
    anyhow::ensure!(
        opts.noise == DEFAULT_NOISE || cases.contains(&Case::Noise),
        "--noise {}: only the noise study reads it (`gvsrom reproduce noise`, or `all`); the cases asked for ({}) do not",
        gvs::error::fmt_value(opts.noise),
        cases.iter().map(|c| c.name()).collect::<Vec<_>>().join(", ")
    );
    let dir = crate::output::RunDir::open("--out", &opts.out)?;
    let mut run = Run::new(dir, interrupt);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()?;
    let mut done = vec![];
    for case in cases {
        let t0 = Instant::now();
        let provenance = crate::provenance::Provenance::of_command();
        let before = run.records().len();
        writeln!(
            log,
            "{:<6} {}",
            case.name(),
            match case {
                Case::IvA => "single-tendon manipulator: data, Table I, POD and AE ROMs, Fig. 3–4",
                Case::IvB =>
                    "soft beam under a moment pulse: data, Table I, POD and AE ROMs, Fig. 5–6",
                Case::IvC1 => "six-tendon manipulator under gravity, statics: AE-6 against POD-6, grid against random data (Fig. 7–8)",
                Case::IvC2 => "six-tendon manipulator, dynamics: babbling data, ROMs with r = 1 … 8 on a new input (Fig. 9)",
                Case::V => "prototype tensions with 1-DOF ROMs (Fig. 10b)",
                Case::Noise => "IV-A and IV-B autoencoders trained on noisy snapshots",
                Case::All => "",
            }
        )?;
        let (mut report, figures) = pool.install(|| match case {
            Case::IvA => iv_a::run(&run, opts),
            Case::IvB => iv_b::run(&run, opts),
            Case::IvC1 => iv_c1::run(&run, opts),
            Case::IvC2 => iv_c2::run(&run, opts),
            Case::V => v::run(&run, opts),
            Case::Noise => noise::run(&run, opts),
            Case::All => unreachable!("expanded by case_list"),
        })?;
        report.wall_time_s = t0.elapsed().as_secs_f64();
        report.steps = run.records()[before..].to_vec();
        report.steps.sort_by(StepRecord::report_order);
        report.crate_version = env!("CARGO_PKG_VERSION").into();
        report.quick = opts.quick;
        report.provenance = Some(provenance);
        let path = report::write_case(&run.path().join(case.name()), &mut report, figures)?;
        let steps = &run.records()[before..];
        let reused = steps.iter().filter(|r| r.reused).count();
        writeln!(
            log,
            "       done in {:.1} s ({} steps, {} reused): {}",
            report.wall_time_s,
            steps.len(),
            reused,
            path.join("summary.md").display()
        )?;
        done.push(CaseDone {
            case,
            dir: path,
            wall_time_s: report.wall_time_s,
            steps: steps.len(),
            reused,
        });
    }
    let reports = read_reports(run.path());
    let page = html::index(&reports, run.path())?;
    let index = run.dir_mut().write_file("index.html", page.as_bytes())?;
    writeln!(log, "report {}", index.display())?;
    Ok(done)
}

/// The case reports present in run directory `dir` (`<case>/results.json`), in the paper's order.
/// Only regular files are read ([`crate::output::read`]): a FIFO in a report's place is passed
/// over, not waited on.
pub fn read_reports(dir: &std::path::Path) -> Vec<CaseReport> {
    Case::EVERY
        .iter()
        .filter_map(|c| {
            let path = dir.join(c.name()).join("results.json");
            let text = crate::output::read_regular_to_string(&path).ok()?;
            serde_json::from_str(&text).ok()
        })
        .collect()
}

/// The empty shell of a case's report, filled by the case.
pub(crate) fn new_report(case: Case, title: &str) -> CaseReport {
    CaseReport {
        case: case.name().into(),
        title: title.into(),
        setup: vec![],
        tables: vec![],
        findings: vec![],
        notes: vec![],
        figures: vec![],
        steps: vec![],
        settings: serde_json::Value::Null,
        values: serde_json::Value::Null,
        quick: false,
        crate_version: String::new(),
        wall_time_s: 0.0,
        provenance: None,
    }
}
