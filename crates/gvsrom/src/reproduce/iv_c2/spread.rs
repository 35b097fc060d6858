//! Beyond the paper: the same snapshot budget spread over a longer babbling. The paper's data is
//! 180 s of babbling sampled at 100 Hz; [`SPREAD`] times the babbling sampled [`SPREAD`] times less
//! often gives as many snapshots of more varied states. The inset's AE and POD are trained again on
//! it (same settings) and run on every test input, against the same HOM runs: whether the test
//! inputs' states, which leave the paper's data on some inputs, are covered by it.

use super::super::report::{Cell, Finding, Table};
use super::super::sim_test::{simulate_test, Test};
use super::super::step::Step;
use super::super::tasks::{self, AeConfig, DatasetInfo, DatasetSpec, ModelInfo, ScenarioSpec};
use super::super::Run;
use super::more_tests::{hom_run, more_tests_table, TestRuns};

/// How many times longer the babbling is, and how many times less often it is sampled.
pub(super) const SPREAD: f64 = 2.0;

/// The spread data, its two models and their runs on each test input.
pub(super) struct Spread {
    pub(super) data: Step<DatasetInfo>,
    pub(super) ae: Step<ModelInfo>,
    pub(super) pod: Step<ModelInfo>,
    pub(super) tests: Vec<TestRuns>,
}

/// The babbling of `plan` [`SPREAD`] times longer at a [`SPREAD`] times lower rate.
pub(super) fn spread_plan(plan: &DatasetSpec) -> DatasetSpec {
    DatasetSpec {
        duration: plan.duration.map(|d| d * SPREAD),
        sample_rate: plan.sample_rate.map(|f| f / SPREAD),
        ..plan.clone()
    }
}

/// Trains the AE (`ae`'s settings) and POD of size `r` on the spread babbling of `plan` and runs
/// both on `test` with each of `seeds` (the paper's seed first, whose HOM run is `paper_hom`).
#[allow(clippy::too_many_arguments)]
pub(super) fn run_spread(
    run: &Run,
    scenario: &ScenarioSpec,
    plan: &DatasetSpec,
    jobs: usize,
    ae: &AeConfig,
    test: &Test,
    paper_hom: &Step<super::SimRun>,
    seeds: &[u64],
) -> anyhow::Result<Spread> {
    let r = ae.latent;
    let data = tasks::dataset(
        run,
        "iv-c2/dataset-spread",
        scenario,
        &spread_plan(plan),
        jobs,
    )?;
    let model = tasks::train(run, &format!("iv-c2/ae-r{r}-spread"), &data, ae)?;
    let pod = tasks::pod(run, &format!("iv-c2/pod-{r}-spread"), &data, r)?;
    let mut tests = vec![];
    for &seed in seeds {
        let t = Test {
            seed,
            ..test.clone()
        };
        let hom = match seed == test.seed {
            true => paper_hom.clone(),
            false => hom_run(run, scenario, &t)?,
        };
        let tag = format!("spread data, test seed {seed}");
        let rom_run = |m: &Step<ModelInfo>, step: &str, label: &str| {
            simulate_test(
                run,
                &format!("iv-c2/test-{step}{r}-spread-test-seed{seed}"),
                &format!("{label}{r} ({tag})"),
                scenario,
                &t,
                Some(m),
                Some(&hom),
            )
        };
        let ae_run = rom_run(&model, "ae-r", "AE-")?;
        let pod_run = rom_run(&pod, "pod-", "POD-")?;
        tests.push(TestRuns {
            seed,
            hom: hom.value,
            ae: ae_run.value,
            pod: pod_run.value,
        });
    }
    Ok(Spread {
        data,
        ae: model,
        pod,
        tests,
    })
}

/// The table of the spread models on every test input.
pub(super) fn spread_table(r: usize, spread: &Spread, plan: &DatasetSpec) -> Table {
    let mut t = more_tests_table(r, &spread.tests);
    let p = spread_plan(plan);
    t.id = "spread-data".into();
    t.title = format!(
        "AE-{r} and POD-{r} from the same number of snapshots over a {}× longer babbling ({} s at {} Hz; not in the paper)",
        SPREAD,
        p.duration.unwrap_or(f64::NAN),
        p.sample_rate.unwrap_or(f64::NAN)
    );
    t.note = format!(
        "As the table of test inputs above, with models trained on {} snapshots of {} s of babbling (the same babbling process and seed, sampled {}× less often) instead of the paper's; the HOM runs are the same. The runs of a row are not one after the other: compare the errors, and the times only roughly.",
        spread.data.value.samples,
        p.duration.unwrap_or(f64::NAN),
        SPREAD
    );
    t
}

/// Whether the spread data keeps every run inside its training region and how its AE does.
pub(super) fn spread_finding(r: usize, spread: &Spread) -> Finding {
    let n = spread.tests.len();
    let left: Vec<String> = spread
        .tests
        .iter()
        .filter(|t| t.ae.left_training_region || t.pod.left_training_region)
        .map(|t| t.seed.to_string())
        .collect();
    let mean = spread.tests.iter().map(|t| t.ae.tip_mean()).sum::<f64>() / n.max(1) as f64;
    let pod = spread.tests.iter().map(|t| t.pod.tip_mean()).sum::<f64>() / n.max(1) as f64;
    Finding {
        claim: format!(
            "with the same number of snapshots over a {SPREAD}× longer babbling (beyond the paper), no AE-{r} or POD-{r} run leaves its training region"
        ),
        holds: n > 0 && left.is_empty(),
        evidence: format!(
            "{} of {n} inputs had a run that left{}; AE-{r} mean tip error {} % L, POD-{r} {} % L over the {n} inputs",
            left.len(),
            if left.is_empty() {
                String::new()
            } else {
                format!(" (seeds {})", left.join(", "))
            },
            Cell::sig(mean, 3).render(),
            Cell::sig(pod, 3).render()
        ),
    }
}
