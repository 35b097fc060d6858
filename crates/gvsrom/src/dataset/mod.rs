//! Strain snapshot datasets (paper eq. 13, Section IV): the HOM solved over a sampling plan, one row
//! per sample, written as NumPy arrays through [`crate::output`].
//!
//! | file | shape | dtype | content |
//! |---|---|---|---|
//! | `inputs.npy` | (N, k) | f64 | the plan's parameter values (`parameters` in meta.json names the columns) |
//! | `strain.npy` | (N, p·a) | f64 | ξ − ξ* at the p computational points, the a active components, point-major: column `j·a + c` is point j, component `components[c]`; NaN rows for failed samples |
//! | `q.npy` | (N, n) | f64 | HOM coordinates, in the order `q_order` of meta.json names ([`gvs::strain::COORDINATE_ORDER`]) |
//! | `tip_position.npy` | (N, 3) | f64 | tip position \[m\] |
//! | `tip_rotation.npy` | (N, 3, 3) | f64 | tip rotation (section → world) |
//! | `status.npy` | (N,) | u8 | 0 ok, 1 failed (reason in meta.json `failures`), 2 not computed (incomplete dataset) |
//! | `iterations.npy` | (N,) | u32 | dogleg iterations of the successful solve |
//! | `residual.npy` | (N,) | f64 | ‖R‖∞ at the solution |
//! | `strain_x.npy` | (p,) | f64 | abscissae of the computational points \[m\] |
//! | `tendon_lengths.npy` | (N, n_a) | f64 | the tendons' lengths ℓ_k(q) \[m\] (what a position-controlled actuator reads; NaN rows for failed samples); `n_tendons` in meta.json (datasets written before it have neither) |
//! | `meta.json` | | | manifest, scenario TOML (after `--set`), plan, seed, parameters, point layout, active components, chunking and `chunk_done`, counts, failures, `complete`, crate version, wall time |
//!
//! A strain component is *active* if the scenario's basis can excite it at some site; the others are
//! identically zero and not stored. Samples are solved in chunks (see [`generate`]) in parallel; the
//! files are bit-identical for a given plan and seed whatever the thread count. An interrupted run
//! writes its finished chunks with `"complete": false`; `--resume` computes only the missing chunks.

pub mod dynamic;
pub mod generate;
pub mod noise;
pub mod plan;
pub mod reader;
mod resume;
mod write;

pub use generate::Layout;
pub use plan::{Plan, PlanKind};
pub use reader::Dataset;

use crate::build::Built;
use crate::error::ScenarioError;
use crate::output::{OutputDir, OutputError};
use generate::{Generator, SampleResult};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use thiserror::Error;

/// The arrays of a dataset, in the order [`Dataset::load`] reads them.
pub const FILES: [&str; 9] = [
    "inputs.npy",
    "strain.npy",
    "q.npy",
    "tip_position.npy",
    "tip_rotation.npy",
    "status.npy",
    "iterations.npy",
    "residual.npy",
    "strain_x.npy",
];

/// How a strain row is laid out (in meta.json).
pub const STRAIN_LAYOUT: &str = "point-major: column j*len(components) + c holds point j (abscissa strain_x[j]), component components[c]; values are xi - xi_star";

/// The sample times of a dynamic dataset.
pub const T_FILE: &str = "t.npy";

/// The tendons' lengths, `samples × n_tendons` (absent from datasets written before they were
/// recorded: `n_tendons` is then absent from meta.json).
pub const TENDON_LENGTHS_FILE: &str = "tendon_lengths.npy";

/// Samples per chunk unless `--chunk-size` says otherwise.
pub const DEFAULT_CHUNK_SIZE: usize = 128;
/// Largest `--chunk-size`.
pub const MAX_CHUNK_SIZE: usize = 4096;
/// Largest dataset held in memory while it is generated \[bytes\] (8 GiB).
pub const MAX_DATASET_BYTES: f64 = 8.0 * 1024.0 * 1024.0 * 1024.0;

#[derive(Debug, Error)]
pub enum DatasetError {
    /// A bad plan or option (the message names it, its value and what is accepted).
    #[error("{0}")]
    Plan(String),
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A dataset file that is missing, truncated or inconsistent.
    #[error("{file}: {message}")]
    File { file: String, message: String },
    /// `--resume` on something that cannot be resumed.
    #[error("--resume `{path}`: {message}")]
    Resume { path: String, message: String },
}

/// A dataset as a front-end asks for it (the options of `gvsrom dataset`): the scenario, the plan
/// and the output.
#[derive(Debug, Clone)]
pub struct DatasetRequest {
    /// A preset name (see `gvsrom presets`) or the path of a scenario TOML file.
    pub scenario: String,

    /// Override a scenario value by its TOML path before sampling (as for `statics`); repeatable.
    pub set: Vec<String>,

    /// Sweep PATH over an even 1-D grid from LO to HI including both ends (`--samples` values).
    /// Repeat it (or use `*`, e.g. `tendons.*.tension`) to sweep several values together.
    pub sweep: Vec<String>,

    /// Grid over the product of the ranges: round(samples^(1/d)) even values per parameter, which
    /// must give exactly `--samples` (e.g. 15625 = 5^6 for `tendons.*.tension` on six tendons).
    pub grid: Vec<String>,

    /// Uniform random values in [LO, HI), seeded by `--seed`; repeatable, `*` allowed.
    pub random: Vec<String>,

    /// Number of samples.
    pub samples: Option<usize>,

    /// Seed of `--random`, `--steps` and `--babble` (same seed, same dataset); `None`: 0. Given
    /// with a plan that draws nothing (`--sweep`, `--grid`, `--input`) it is refused.
    pub seed: Option<u64>,

    /// Samples per chunk: the unit of parallel work, of warm-start chains and of resuming. Part of
    /// the plan (a different chunk size gives slightly different last digits).
    pub chunk_size: usize,

    /// Worker threads (default: one per core). The files do not depend on it.
    pub threads: Option<usize>,

    /// Write the dataset into the new directory DIR.
    pub out: PathBuf,

    /// Replace DIR if it is an earlier gvsrom output holding only its own files.
    pub force: bool,

    /// Continue the incomplete dataset in DIR (same scenario, plan and seed): its finished chunks are
    /// kept, the missing ones computed, and DIR replaced by the result.
    pub resume: bool,

    /// Dynamic dataset: simulate T seconds (inputs as for `simulate`) and store every output sample.
    pub duration: Option<f64>,

    /// Dynamic dataset: output samples per second \[Hz\].
    pub sample_rate: Option<f64>,

    /// Dynamic dataset: actuation from a CSV file `t, u_1, …, u_na` (as for `simulate`).
    pub input: Option<PathBuf>,

    /// Dynamic dataset: interpolate the CSV input linearly.
    pub interpolate: bool,

    /// Dynamic dataset: random step actuation LO,HI,PERIOD (seeded by `--seed`).
    pub steps: Option<Vec<f64>>,

    /// Dynamic dataset: actuator babbling LO,HI,HOLD_MIN,HOLD_MAX (paper IV-C2: `--babble=-15,0,0.5,1`).
    pub babble: Option<Vec<f64>>,

    /// Dynamic dataset: start at the static equilibrium under the scenario's loads and tensions.
    pub from_equilibrium: bool,

    /// Dynamic dataset: relative tolerance of the integrator (default as `simulate`: 1e-3, or
    /// 1e-4 with SDIRK4 for a lightly damped rod).
    pub rtol: Option<f64>,

    /// Dynamic dataset: absolute tolerance of the integrator.
    pub atol: f64,

    /// Testing aid: stop (as if interrupted) once N chunks have been started.
    pub stop_after_chunks: Option<usize>,
}

/// Sample counts of a dataset.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    pub ok: usize,
    pub failed: usize,
    pub not_computed: usize,
    /// Samples solved from a neighbour's solution by this run (the rest were ramped from straight;
    /// chunks kept by `--resume` are not counted).
    pub warm_started: usize,
}

/// A failed sample and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    pub index: usize,
    pub reason: String,
}

/// The dataset part of `meta.json` (the manifest sits beside it under `"gvsrom"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    /// `"statics"` or `"dynamics"`.
    pub kind: String,
    pub scenario: String,
    /// The scenario's TOML after `--set` overrides.
    pub scenario_toml: String,
    /// The sampling plan of a static dataset.
    pub plan: Option<Plan>,
    /// The run of a dynamic dataset.
    pub dynamic: Option<dynamic::DynamicInfo>,
    pub seed: u64,
    /// Column names of `inputs.npy`.
    pub parameters: Vec<String>,
    pub samples: usize,
    pub n_dof: usize,
    pub n_points: usize,
    pub strain_x: Vec<f64>,
    /// Names of the stored strain components, in column order within a point.
    pub components: Vec<String>,
    /// How a strain row is laid out.
    pub strain_layout: String,
    pub chunk_size: usize,
    /// Per chunk (samples `c·chunk_size ..`): finished or not.
    pub chunk_done: Vec<bool>,
    pub complete: bool,
    /// Why an incomplete dataset stopped.
    pub reason: Option<String>,
    /// A dynamic dataset's run that failed: the full message (`reason` says which kind).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    pub counts: Counts,
    pub failures: Vec<Failure>,
    pub crate_version: String,
    /// Order of the coordinates in `q.npy` ([`gvs::strain::COORDINATE_ORDER`]); datasets written
    /// before it was recorded used `"fem-mode-major"`.
    #[serde(default = "legacy_q_order")]
    pub q_order: String,
    /// Columns of `tendon_lengths.npy`, one per tendon (`None`: a dataset written before the
    /// lengths were recorded, which has no such file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub n_tendons: Option<usize>,
    /// Wall time of this run (a resumed run: of its own part).
    pub wall_time_s: f64,
    pub threads: usize,
    /// A dataset made from another by adding noise to its snapshots ([`noise::with_noise`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<noise::NoiseInfo>,
    /// How the dataset was made ([`crate::provenance`]; absent in datasets from before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<crate::provenance::Provenance>,
}

/// The result of [`run`].
#[derive(Debug)]
pub struct Outcome {
    pub path: PathBuf,
    pub meta: Meta,
    /// `Some(reason)` if the run was interrupted (the finished chunks were written).
    pub interrupted: Option<String>,
    /// Chunks taken over from the resumed dataset.
    pub resumed_chunks: usize,
    /// What the scenario's model cannot do that the user may expect
    /// ([`crate::build::model_warnings`]), for the front-end to warn with.
    pub warnings: Vec<String>,
}

impl Outcome {
    /// What to tell of the samples that failed (`None` if none did): how many, the first's reason,
    /// and what became of their rows, for a front-end that does not list them as `gvsrom dataset`
    /// does.
    pub fn failure_message(&self) -> Option<String> {
        let c = &self.meta.counts;
        let first = self.meta.failures.first()?;
        Some(format!(
            "{} of the {} samples failed (sample {}: {}{}); their rows are NaN with status 1, and pod and train leave them out",
            c.failed,
            self.meta.samples,
            first.index,
            first.reason,
            match self.meta.failures.len() - 1 {
                0 => String::new(),
                more => format!("; {more} more in meta.json"),
            }
        ))
    }

    /// What to tell of an interrupted run (`None` if it finished): why it stopped and where its
    /// finished samples were written, as `gvsrom dataset` prints it.
    pub fn interruption_message(&self) -> Option<String> {
        let reason = self.interrupted.as_ref()?;
        Some(format!(
            "{reason}; the {} finished samples were written to `{}`, marked incomplete{}",
            self.meta.counts.ok + self.meta.counts.failed,
            self.path.display(),
            if self.meta.plan.is_some() {
                " (continue with --resume)"
            } else {
                ""
            }
        ))
    }
}

fn legacy_q_order() -> String {
    "fem-mode-major".into()
}

/// A `--set` of a value the plan varies would be replaced at every sample: refused, naming both
/// (`--set tendons.0.tension=-1` with `--sweep tendons.0.tension=-6:0` gave the sweep's inputs).
/// `set` holds the values given with the plan (not those a Python `Scenario` carries, the base
/// its plan varies); a `*` of either matches any entry, and a value set is varied when the plan
/// varies it or a value inside it (`loads.gravity` against `loads.gravity.2`).
pub fn refuse_set_varied(set: &[String], request: &DatasetRequest) -> Result<(), DatasetError> {
    // `tendons[0].tension`, `tendons.0.tension` and `tendons.00.tension` alike
    let segments = |path: &str| -> Vec<String> {
        (path.trim().replace('[', ".").replace(']', ""))
            .split('.')
            .filter(|s| !s.is_empty())
            .map(|s| match s.parse::<usize>() {
                Ok(k) => k.to_string(),
                Err(_) => s.to_string(),
            })
            .collect()
    };
    let plans = [
        ("--sweep", &request.sweep),
        ("--grid", &request.grid),
        ("--random", &request.random),
    ];
    for spec in set {
        let Some((path, _)) = spec.split_once('=') else {
            continue;
        };
        let set_path = segments(path);
        for (option, specs) in plans {
            for plan in specs.iter() {
                let varied = plan.split_once('=').map_or(plan.as_str(), |(p, _)| p);
                let param = segments(varied);
                let inside = param.len() >= set_path.len()
                    && (param.iter().zip(&set_path)).all(|(a, b)| a == b || a == "*" || b == "*");
                if inside {
                    return Err(plan_err(format!(
                        "--set {spec}: the plan varies `{}` ({option} {plan}), which would replace the value set at every sample; drop one of them",
                        varied.trim()
                    )));
                }
            }
        }
    }
    Ok(())
}

fn plan_err(e: String) -> DatasetError {
    DatasetError::Plan(e)
}

/// The scenario table after `--set`, the scenario built from it, its TOML text, and the
/// provenance of the dataset (started now).
fn load_scenario(
    args: &DatasetRequest,
) -> Result<(toml::Table, Built, String, crate::provenance::Provenance), DatasetError> {
    let src = crate::presets::source(&args.scenario)?;
    let mut table = crate::scenario::parse_table(&src.origin, &src.text)?;
    for spec in &args.set {
        crate::scenario::apply_override(&mut table, spec)?;
    }
    if !table.contains_key("name") {
        table.insert("name".into(), toml::Value::String(src.default_name.clone()));
    }
    let scenario = crate::scenario::from_table(table.clone())?;
    let built = crate::build(&scenario)?;
    let text = toml::to_string(&table).map_err(|e| plan_err(format!("scenario: {e}")))?;
    let provenance = src.provenance(&args.set, text.clone());
    Ok((table, built, text, provenance))
}

/// Checks the plan before computing: the tensions against the rod's elastic range (shared model),
/// or the scenario rebuilt with every parameter at LO, at HI and at the plan's first samples (which
/// names an unknown path, a value the format rejects — a fractional value of a whole-number field
/// that only random draws give — or a value that changes the model's coordinates or points, which
/// the snapshots of one dataset must share).
fn check_plan(plan: &Plan, table: &toml::Table, built: &Built) -> Result<(), DatasetError> {
    if plan.parameters.iter().all(|p| p.tendon.is_some()) {
        let mut u_max: Vec<f64> = built.u.iter().map(|v| v.abs()).collect();
        for p in &plan.parameters {
            if let Some(t) = p.tendon {
                u_max[t] = p.lo.abs().max(p.hi.abs());
            }
        }
        return crate::plausibility::check(built, &u_max, 1.0).map_err(|e| {
            plan_err(format!(
                "{} {}: {e}",
                plan.kind.option(),
                plan.specs.join(" ")
            ))
        });
    }
    let d = plan.parameters.len();
    let values = plan.values();
    let mut cases: Vec<(String, Vec<f64>)> = vec![
        (
            "every parameter at LO".into(),
            plan.parameters.iter().map(|p| p.lo).collect(),
        ),
        (
            "every parameter at HI".into(),
            plan.parameters.iter().map(|p| p.hi).collect(),
        ),
    ];
    for k in 0..plan.samples.min(3) {
        cases.push((format!("sample {k}"), values[k * d..(k + 1) * d].to_vec()));
    }
    // coordinates, and points at the same abscissae (`strain_x`)
    let layout = |b: &Built| {
        let x: Vec<u64> = b.model.disc.points.iter().map(|p| p.x.to_bits()).collect();
        (b.n_dof(), x)
    };
    let base = layout(built);
    for (which, v) in cases {
        let mut t = table.clone();
        for (p, v) in plan.parameters.iter().zip(&v) {
            crate::scenario::apply_override(&mut t, &format!("{}={v}", p.path)).map_err(|e| {
                let why = match e {
                    ScenarioError::Override { message, .. } => message,
                    other => other.to_string(),
                };
                plan_err(format!("{} {}: {why}", plan.kind.option(), p.spec))
            })?;
        }
        let shown = || {
            let at: Vec<String> = (plan.parameters.iter().zip(&v))
                .map(|(p, v)| format!("{} = {v}", p.path))
                .collect();
            format!(
                "{} {}: with {which} ({})",
                plan.kind.option(),
                plan.specs.join(" "),
                at.join(", ")
            )
        };
        match crate::scenario::from_table(t).and_then(|s| crate::build(&s)) {
            Err(e) => return Err(plan_err(format!("{}: {e}", shown()))),
            Ok(b) if layout(&b) != base => {
                return Err(plan_err(format!(
                    "{}: the model has {} DOF and {} points (at their abscissae) there, {} and {} in the scenario: the snapshots of one dataset share one layout, coordinates and points (vary a value that keeps the basis and the points, or make one dataset per layout)",
                    shown(),
                    b.n_dof(),
                    b.model.disc.n_points(),
                    built.n_dof(),
                    built.model.disc.n_points()
                )))
            }
            Ok(_) => {}
        }
    }
    Ok(())
}

/// Builds the dataset described by `args`, writing a summary to `out`. `interrupt` holds a signal
/// number once SIGINT/SIGTERM arrived: the run then stops after the chunks under way.
pub fn run(args: &DatasetRequest, interrupt: &AtomicUsize) -> Result<Outcome, DatasetError> {
    let t0 = Instant::now();
    // `--resume` reads the dataset at --out itself, on purpose; the other inputs must stay apart
    let mut inputs = vec![];
    if crate::presets::find(&args.scenario).is_none() {
        inputs.push(("SCENARIO", Path::new(&args.scenario)));
    }
    if let Some(p) = &args.input {
        inputs.push(("--input", p.as_path()));
    }
    crate::output::refuse_overlap("--out", &args.out, &inputs)?;
    let draws = !args.random.is_empty() || args.steps.is_some() || args.babble.is_some();
    if let (Some(s), false) = (args.seed, draws) {
        return Err(plan_err(format!(
            "--seed {s}: this plan draws nothing (a --sweep, --grid or --input); --seed applies to --random, --steps and --babble"
        )));
    }
    let seed = args.seed.unwrap_or(0);
    // checked for every dataset (a dynamic one runs on one thread, whatever it is given)
    if args.threads == Some(0) || args.threads.is_some_and(|t| t > 1024) {
        return Err(plan_err(format!(
            "--threads {}: expected an integer in [1, 1024]",
            args.threads.unwrap_or(0)
        )));
    }
    // a plan over displacements: refused before a sample builds (with its tension, "both given")
    if let Some(path) = (args.sweep.iter().chain(&args.grid).chain(&args.random))
        .find(|p| p.split('=').next().unwrap_or("").ends_with("displacement"))
    {
        return Err(plan_err(format!(
            "`{path}`: dataset drives tendons by their tension only (its snapshots are samples of tensions and loads); sample the tensions instead, e.g. over the range `gvsrom statics --displacement` finds for the displacements"
        )));
    }
    let (table, built, scenario_toml, provenance) = load_scenario(args)?;
    built
        .tension_driven_for("dataset")
        .map_err(|e| plan_err(e.to_string()))?;
    let mut warnings = crate::build::model_warnings(&built.model);
    if let Ok(scenario) = crate::scenario::from_table(table.clone()) {
        warnings.extend(crate::build::under_integrated_divisions(&scenario));
    }
    if args.duration.is_some() {
        let provenance = provenance.seed("input", seed);
        return dynamic::run(args, &built, scenario_toml, interrupt, provenance, t0)
            .map(|o| Outcome { warnings, ..o });
    }
    let plan = Plan::new(
        &args.sweep,
        &args.grid,
        &args.random,
        args.samples,
        seed,
        &table,
    )
    .map_err(plan_err)?;
    if !(1..=MAX_CHUNK_SIZE).contains(&args.chunk_size) {
        return Err(plan_err(format!(
            "--chunk-size {}: expected an integer in [1, {MAX_CHUNK_SIZE}]",
            args.chunk_size
        )));
    }
    check_plan(&plan, &table, &built)?;
    let layout = Layout::of(&built);
    let n = plan.samples;
    let per_sample =
        (plan.parameters.len() + layout.row_len() + layout.n_dof + layout.n_tendons + 14) as f64
            * 8.0;
    if n as f64 * per_sample > MAX_DATASET_BYTES {
        return Err(plan_err(format!(
            "--samples {n}: the dataset would take {:.1} GB in memory (accepted <= {:.1} GB); use fewer samples",
            n as f64 * per_sample / 1e9,
            MAX_DATASET_BYTES / 1e9
        )));
    }
    let values = plan.values();
    let gen = Generator {
        base: &built,
        table: &table,
        plan: &plan,
        values: &values,
        layout: &layout,
        chunk_size: args.chunk_size,
    };
    let n_chunks = gen.n_chunks();
    let mut meta = Meta {
        kind: "statics".into(),
        scenario: built.name.clone(),
        scenario_toml,
        seed: plan.seed,
        parameters: plan.names(),
        samples: n,
        n_dof: layout.n_dof,
        n_points: layout.strain_x.len(),
        strain_x: layout.strain_x.clone(),
        components: layout.component_names(),
        strain_layout: STRAIN_LAYOUT.into(),
        chunk_size: args.chunk_size,
        chunk_done: vec![false; n_chunks],
        complete: false,
        reason: None,
        error: None,
        counts: Counts::default(),
        failures: vec![],
        crate_version: env!("CARGO_PKG_VERSION").into(),
        q_order: gvs::strain::COORDINATE_ORDER.into(),
        n_tendons: Some(layout.n_tendons),
        wall_time_s: 0.0,
        threads: 0,
        plan: Some(plan.clone()),
        dynamic: None,
        noise: None,
        provenance: Some(provenance.seed("plan", seed)),
    };
    // the output is checked, locked and staged before the computation
    let mut dir = OutputDir::create("--out", &args.out, "dataset", args.force || args.resume)?;
    let mut results: Vec<Option<Vec<SampleResult>>> = vec![None; n_chunks];
    let mut resumed_chunks = 0;
    // the kept samples' warm starts: rows do not record them, the previous counts do (its chunks
    // not done hold none)
    let mut kept_warm_starts = 0;
    if args.resume {
        let prev = resume::resumable(&args.out, &meta)?;
        kept_warm_starts = prev.meta.counts.warm_started;
        for c in 0..n_chunks {
            if prev.meta.chunk_done[c] {
                results[c] = Some(
                    gen.chunk_range(c)
                        .map(|k| {
                            resume::from_previous(&prev, k, |k, q| {
                                gen.tendon_lengths_at(k, prev.status[k], q)
                            })
                        })
                        .collect(),
                );
                resumed_chunks += 1;
            }
        }
    }
    let todo: Vec<usize> = (0..n_chunks).filter(|&c| results[c].is_none()).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .map_err(|e| plan_err(format!("--threads: cannot start the worker threads: {e}")))?;
    meta.threads = pool.current_num_threads();
    let todo_samples: usize = todo.iter().map(|&c| gen.chunk_range(c).len()).sum();
    let bar = progress_bar(todo_samples as u64);
    let started = AtomicUsize::new(0);
    let stop_after = args.stop_after_chunks.unwrap_or(usize::MAX);
    // polled before every load stage of every solve: an interrupt ends the chunks under way (they
    // are then not done) within one stage, however long their ramps
    let stop = || match interrupt.load(Ordering::SeqCst) {
        0 => None,
        sig => Some(format!("interrupted by {}", signal_name(sig))),
    };
    let computed: Vec<(usize, Option<Vec<SampleResult>>)> = pool.install(|| {
        use rayon::prelude::*;
        todo.par_iter()
            .map(|&c| {
                if interrupt.load(Ordering::SeqCst) != 0
                    || started.fetch_add(1, Ordering::SeqCst) >= stop_after
                {
                    return (c, None);
                }
                let r = gen.chunk(c, &stop);
                if let Some(r) = &r {
                    bar.inc(r.len() as u64);
                }
                (c, r)
            })
            .collect()
    });
    bar.finish_and_clear();
    for (c, r) in computed {
        if r.is_some() {
            results[c] = r;
        }
    }
    let signal = interrupt.load(Ordering::SeqCst);
    let interrupted = if results.iter().all(Option::is_some) {
        None
    } else if signal != 0 {
        Some(format!("interrupted by {}", signal_name(signal)))
    } else {
        Some(format!(
            "stopped after {stop_after} chunks (--stop-after-chunks)"
        ))
    };
    meta.complete = interrupted.is_none();
    meta.reason = interrupted.clone();
    meta.wall_time_s = t0.elapsed().as_secs_f64();
    write::write(&mut dir, &mut meta, &gen, results)?;
    meta.counts.warm_started += kept_warm_starts;
    let path = dir.commit(&meta)?;
    // a plan none of whose samples solves is an error, not a dataset: every row failed
    if meta.complete && meta.samples > 0 && meta.counts.ok == 0 {
        return Err(DatasetError::Plan(format!(
            "none of the {} samples solved; sample {}: {} (the failures were written to `{}` for inspection)",
            meta.samples,
            meta.failures.first().map_or(0, |f| f.index),
            meta.failures
                .first()
                .map_or("no reason recorded", |f| f.reason.as_str()),
            path.display()
        )));
    }
    Ok(Outcome {
        path,
        meta,
        interrupted,
        resumed_chunks,
        warnings,
    })
}

pub(crate) fn signal_name(sig: usize) -> &'static str {
    match sig {
        2 => "SIGINT",
        15 => "SIGTERM",
        _ => "a signal",
    }
}

/// A progress bar of `len` samples on stderr ([`crate::progress::bar`]).
pub(crate) fn progress_bar(len: u64) -> indicatif::ProgressBar {
    crate::progress::bar(len, "samples")
}
