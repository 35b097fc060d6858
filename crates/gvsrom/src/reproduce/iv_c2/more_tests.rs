//! IV-C2's inset ROMs (r = 7 in the full run) on more test inputs than the paper's one: the same
//! kind of input (new random tensions every second) drawn with other seeds, each simulated with
//! the HOM, the AE-ROM and the POD-ROM (`gvsrom simulate --seed S [--model M]`, `gvsrom compare`).
//! One test input can flatter or wrong a model; the table gives the spread, the findings the
//! paper's accuracy claim on every input.

use super::super::paper;
use super::super::report::{Cell, Finding, Table};
use super::super::sim_test::{simulate_test, time_pairs, PairedTiming, SimRun, Test};
use super::super::step::Step;
use super::super::tasks::{ModelInfo, ScenarioSpec};
use super::super::Run;
use serde::Serialize;

/// One test input: its seed and the three runs, and the AE-ROM's wall time against the HOM's in
/// interleaved pairs (where measured).
#[derive(Debug, Clone, Serialize)]
pub(super) struct TestRuns {
    pub(super) seed: u64,
    pub(super) hom: SimRun,
    pub(super) ae: SimRun,
    pub(super) pod: SimRun,
    pub(super) ae_timing: Option<PairedTiming>,
}

/// The AE-ROM's [`PairedTiming`] against the HOM on `test` (`rounds` pairs).
pub(super) fn ae_timing(
    run: &Run,
    scenario: &ScenarioSpec,
    test: &Test,
    r: usize,
    ae: &Step<ModelInfo>,
    rounds: usize,
) -> anyhow::Result<PairedTiming> {
    let name = format!("iv-c2/time-ae-r{r}-test-seed{}", test.seed);
    Ok(time_pairs(run, &name, scenario, test, ae, rounds)?.value)
}

/// Simulates `test` with each of `seeds` (instead of its own) with the HOM and the models `ae` and
/// `pod` of size `r`, one after the other (their wall times compare), and times AE against the HOM
/// in `rounds` interleaved pairs (none if 0).
#[allow(clippy::too_many_arguments)]
pub(super) fn run_more_tests(
    run: &Run,
    scenario: &ScenarioSpec,
    test: &Test,
    seeds: &[u64],
    r: usize,
    ae: &Step<ModelInfo>,
    pod: &Step<ModelInfo>,
    rounds: usize,
) -> anyhow::Result<Vec<TestRuns>> {
    seeds
        .iter()
        .map(|&seed| {
            let t = Test {
                seed,
                ..test.clone()
            };
            let tag = format!("test seed {seed}");
            let hom = hom_run(run, scenario, &t)?;
            let ae_run = simulate_test(
                run,
                &format!("iv-c2/test-ae-r{r}-test-seed{seed}"),
                &format!("AE-{r} ({tag})"),
                scenario,
                &t,
                Some(ae),
                Some(&hom),
            )?;
            let pod_run = simulate_test(
                run,
                &format!("iv-c2/test-pod-{r}-test-seed{seed}"),
                &format!("POD-{r} ({tag})"),
                scenario,
                &t,
                Some(pod),
                Some(&hom),
            )?;
            let ae_timing = match rounds {
                0 => None,
                _ => Some(ae_timing(run, scenario, &t, r, ae, rounds)?),
            };
            Ok(TestRuns {
                seed,
                hom: hom.value,
                ae: ae_run.value,
                pod: pod_run.value,
                ae_timing,
            })
        })
        .collect()
}

/// The HOM's run of `test` (with its own seed, not the paper's [`super::TEST_SEED`]): a step that
/// every model tested on that input compares with.
pub(super) fn hom_run(
    run: &Run,
    scenario: &ScenarioSpec,
    test: &Test,
) -> anyhow::Result<Step<SimRun>> {
    simulate_test(
        run,
        &format!("iv-c2/test-hom-seed{}", test.seed),
        &format!("HOM (test seed {})", test.seed),
        scenario,
        test,
        None,
        None,
    )
}

/// Per test input: both ROMs' mean tip error, wall time and status, and the HOM's time; the mean
/// over the inputs last.
pub(super) fn more_tests_table(r: usize, tests: &[TestRuns]) -> Table {
    let mean =
        |f: &dyn Fn(&TestRuns) -> f64| tests.iter().map(f).sum::<f64>() / tests.len().max(1) as f64;
    let mut rows: Vec<Vec<Cell>> = tests
        .iter()
        .map(|t| {
            vec![
                Cell::int(t.seed as usize),
                Cell::sig(t.ae.tip_mean(), 3),
                Cell::sig(t.pod.tip_mean(), 3),
                Cell::sig(t.ae.wall_time_s, 3),
                Cell::sig(t.pod.wall_time_s, 3),
                Cell::sig(t.hom.wall_time_s, 3),
                t.ae_timing
                    .as_ref()
                    .map_or(Cell::text("–"), |p| Cell::sig(p.median_ratio, 3)),
                Cell::text(t.ae.status()),
                Cell::text(t.pod.status()),
            ]
        })
        .collect();
    rows.push(vec![
        Cell::text("mean"),
        Cell::sig(mean(&|t| t.ae.tip_mean()), 3),
        Cell::sig(mean(&|t| t.pod.tip_mean()), 3),
        Cell::sig(mean(&|t| t.ae.wall_time_s), 3),
        Cell::sig(mean(&|t| t.pod.wall_time_s), 3),
        Cell::sig(mean(&|t| t.hom.wall_time_s), 3),
        Cell::text(""),
        Cell::text(""),
        Cell::text(""),
    ]);
    Table {
        id: "more-tests".into(),
        title: format!("AE-{r} and POD-{r} on {} test inputs", tests.len()),
        columns: [
            "test seed",
            "AE-ROM tip error [% L]",
            "POD-ROM tip error [% L]",
            "AE-ROM time [s]",
            "POD-ROM time [s]",
            "HOM time [s]",
            "AE-ROM / HOM time, interleaved",
            "AE-ROM run",
            "POD-ROM run",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        note: "Each row is a test input of the same kind (new uniform random tensions on every tendon every second) drawn with its seed; the first is the paper's test above. Tip error: mean over the samples of ‖p_ROM − p_HOM‖ / L against the HOM on the same input; times: smallest wall time of the integration, one thread, the three runs of a row one after the other; AE-ROM / HOM time, interleaved: the median over rounds of HOM, then AE-ROM, of the ratio of their wall times (the machine's drift cancels within a round), – where not measured.".into(),
    }
}

/// The paper's accuracy and speed claims at r on every test input.
pub(super) fn more_tests_findings(r: usize, tests: &[TestRuns]) -> Vec<Finding> {
    let p = &paper::TABLE_III_IV_C2;
    let target = p.ae_error.unwrap_or(f64::NAN);
    let n = tests.len();
    let list = |f: &dyn Fn(&TestRuns) -> bool| {
        let seeds: Vec<String> = tests
            .iter()
            .filter(|t| f(t))
            .map(|t| t.seed.to_string())
            .collect();
        (seeds.len(), seeds.join(", "))
    };
    let errors = tests
        .iter()
        .map(|t| Cell::sig(t.ae.tip_mean(), 3).render())
        .collect::<Vec<_>>()
        .join(", ");
    let (k_target, _) = list(&|t| t.ae.complete && t.ae.tip_mean() <= target);
    let (k_better, better_at) =
        list(&|t| t.ae.complete && t.pod.complete && t.ae.tip_mean() < t.pod.tip_mean());
    let (k_left, left_at) = list(&|t| t.ae.left_training_region || t.pod.left_training_region);
    // the interleaved median ratio where measured, else the ratio of the smallest times
    let time_ratio = |t: &TestRuns| {
        t.ae_timing
            .as_ref()
            .map_or(t.ae.wall_time_s / t.hom.wall_time_s, |p| p.median_ratio)
    };
    let (k_fast, _) = list(&|t| t.ae.complete && time_ratio(t) <= 1.0);
    let interleaved = tests.iter().any(|t| t.ae_timing.is_some());
    let ratios = tests
        .iter()
        .map(|t| {
            let ratio = Cell::sig(time_ratio(t), 2).render();
            if t.ae.complete {
                ratio
            } else {
                format!("{ratio} (stopped early)")
            }
        })
        .collect::<Vec<_>>()
        .join(", ");
    vec![
        Finding {
            claim: format!(
                "AE-{r}'s mean tip error is at most the paper's {target} % L on every test input"
            ),
            holds: n > 0 && k_target == n,
            evidence: format!(
                "{k_target} of {n} inputs; AE-{r} errors {errors} % L (seeds {})",
                seeds(tests)
            ),
        },
        Finding {
            claim: format!("AE-{r} is more accurate than POD-{r} on every test input"),
            holds: n > 0 && k_better == n,
            evidence: format!("{k_better} of {n} inputs (seeds {better_at})"),
        },
        Finding {
            claim: format!("no AE-{r} or POD-{r} run leaves its training region"),
            holds: k_left == 0,
            evidence: if k_left == 0 {
                format!("every run of the {n} inputs stayed inside")
            } else {
                format!("{k_left} of {n} inputs had a run that left (seeds {left_at})")
            },
        },
        Finding {
            claim: format!("the AE-{r}-ROM takes no more wall time than the HOM on the same input"),
            holds: n > 0 && k_fast == n,
            evidence: format!(
                "{k_fast} of {n} inputs; AE-ROM / HOM time {ratios}{}",
                if interleaved {
                    " (median of interleaved pairs)"
                } else {
                    ""
                }
            ),
        },
    ]
}

fn seeds(tests: &[TestRuns]) -> String {
    tests
        .iter()
        .map(|t| t.seed.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
