//! Beyond the paper: IV-C2's POD-ROM with the modes of the strain-energy norm (`gvsrom pod --norm
//! energy`), the norm the autoencoders are trained in, on every test input beside the paper's POD
//! (plain norm) and the AE-ROM. The plain norm lets POD neglect elongation and shear, small in value
//! but stiff; the comparison of AE and POD is then also one of norms.

use super::super::report::{Cell, Finding, Table};
use super::super::sim_test::{simulate_test, SimRun, Test};
use super::super::step::Step;
use super::super::tasks::{self, DatasetInfo, ModelInfo, ScenarioSpec};
use super::super::Run;
use super::more_tests::{hom_run, TestRuns};
use super::Dof;
use crate::reduce::PodNorm;

/// The energy-norm POD of size `r` from `data` (`gvsrom pod DATASET --modes r --norm energy`).
pub(super) fn energy_pod_model(
    run: &Run,
    data: &Step<DatasetInfo>,
    r: usize,
) -> anyhow::Result<Step<ModelInfo>> {
    let name = format!("iv-c2/pod-{r}-energy");
    tasks::pod_in(run, &name, data, r, PodNorm::Energy)
}

/// The energy-norm POD `pod` of size `r` simulated on the test inputs of `seeds`, each against the
/// HOM's run of that input.
pub(super) fn run_energy_pod(
    run: &Run,
    scenario: &ScenarioSpec,
    test: &Test,
    pod: &Step<ModelInfo>,
    r: usize,
    seeds: &[u64],
) -> anyhow::Result<Vec<SimRun>> {
    seeds
        .iter()
        .map(|&seed| {
            let t = Test {
                seed,
                ..test.clone()
            };
            let hom = hom_run(run, scenario, &t)?;
            Ok(simulate_test(
                run,
                &format!("iv-c2/test-pod-{r}-energy-test-seed{seed}"),
                &format!("POD-{r}, energy norm (test seed {seed})"),
                scenario,
                &t,
                Some(pod),
                Some(&hom),
            )?
            .value)
        })
        .collect()
}

/// Per test input: the tip errors of the AE-ROM, the paper's POD-ROM and the energy-norm POD-ROM,
/// and the latter's time and status; the mean over the inputs last.
pub(super) fn energy_pod_table(r: usize, tests: &[TestRuns], energy: &[SimRun]) -> Table {
    let n = tests.len().max(1) as f64;
    let mean = |f: &dyn Fn(usize) -> f64| (0..tests.len()).map(f).sum::<f64>() / n;
    let mut rows: Vec<Vec<Cell>> = tests
        .iter()
        .zip(energy)
        .map(|(t, e)| {
            vec![
                Cell::int(t.seed as usize),
                Cell::sig(t.ae.tip_mean(), 3),
                Cell::sig(t.pod.tip_mean(), 3),
                Cell::sig(e.tip_mean(), 3),
                Cell::sig(e.wall_time_s, 3),
                Cell::sig(t.hom.wall_time_s, 3),
                Cell::text(e.status()),
            ]
        })
        .collect();
    rows.push(vec![
        Cell::text("mean"),
        Cell::sig(mean(&|i| tests[i].ae.tip_mean()), 3),
        Cell::sig(mean(&|i| tests[i].pod.tip_mean()), 3),
        Cell::sig(mean(&|i| energy[i].tip_mean()), 3),
        Cell::sig(mean(&|i| energy[i].wall_time_s), 3),
        Cell::sig(mean(&|i| tests[i].hom.wall_time_s), 3),
        Cell::text(""),
    ]);
    Table {
        id: "energy-pod".into(),
        title: format!("POD-{r} in the strain-energy norm, beside AE-{r} and the paper's POD-{r} (not in the paper)"),
        columns: [
            "test seed",
            "AE-ROM tip error [% L]",
            "POD-ROM tip error [% L]",
            "energy-norm POD-ROM tip error [% L]",
            "energy-norm POD-ROM time [s]",
            "HOM time [s]",
            "energy-norm POD-ROM run",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        note: format!("The same data, test inputs and HOM runs as the table of test inputs; the energy-norm POD's {r} modes are those of `gvsrom pod DATASET --modes {r} --norm energy`: optimal, and orthonormal, in the norm that weighs each strain value by its section stiffness (the autoencoders' loss), where the paper's POD weighs every value alike and so neglects elongation and shear, small in value but stiff. Tip error: mean over the samples of ‖p_ROM − p_HOM‖ / L."),
    }
}

/// Whether the AE-ROM stays more accurate than the energy-norm POD-ROM on every test input.
pub(super) fn energy_pod_finding(r: usize, tests: &[TestRuns], energy: &[SimRun]) -> Finding {
    let pairs: Vec<(u64, f64, f64, bool)> = tests
        .iter()
        .zip(energy)
        .map(|(t, e)| {
            let both = t.ae.complete && e.complete;
            (t.seed, t.ae.tip_mean(), e.tip_mean(), both)
        })
        .collect();
    let better = pairs
        .iter()
        .filter(|(_, a, e, both)| *both && a < e)
        .count();
    let list = pairs
        .iter()
        .map(|(seed, a, e, both)| {
            let (a, e) = (Cell::sig(*a, 3).render(), Cell::sig(*e, 3).render());
            let mark = if *both { "" } else { " (a run stopped early)" };
            format!("seed {seed}: {a} against {e}{mark}")
        })
        .collect::<Vec<_>>()
        .join("; ");
    Finding {
        claim: format!(
            "AE-{r} is more accurate than a POD-{r} of the same norm (strain energy) on every test input (beyond the paper)"
        ),
        holds: !pairs.is_empty() && better == pairs.len(),
        evidence: format!(
            "{better} of {} inputs, AE-{r} against energy-norm POD-{r} tip error in % L: {list}",
            pairs.len()
        ),
    }
}

/// Fig. 9 beyond the paper: at which DOFs the AE-ROM is more accurate than the energy-norm POD-ROM
/// on the paper's test (complete runs both).
pub(super) fn fig9_energy_finding(dofs: &[Dof]) -> Finding {
    let ahead: Vec<usize> = dofs
        .iter()
        .filter(|d| {
            d.ae_run.complete
                && d.pod_energy_run.complete
                && d.ae_run.tip_mean() < d.pod_energy_run.tip_mean()
        })
        .map(|d| d.r)
        .collect();
    let list = dofs
        .iter()
        .map(|d| {
            let (a, e) = (d.ae_run.tip_mean(), d.pod_energy_run.tip_mean());
            let (a, e) = (Cell::sig(a, 3).render(), Cell::sig(e, 3).render());
            format!("r = {}: {a} against {e}", d.r)
        })
        .collect::<Vec<_>>()
        .join("; ");
    let at = ahead.iter().map(usize::to_string).collect::<Vec<_>>();
    Finding {
        claim: "the AE-ROM is more accurate than a POD-ROM of the same norm (strain energy) and DOF at every r of Fig. 9 (beyond the paper)".into(),
        holds: !dofs.is_empty() && ahead.len() == dofs.len(),
        evidence: format!(
            "ahead at r = {} of {} DOFs; mean tip error in % L, AE against energy-norm POD: {list}",
            if at.is_empty() { "none".into() } else { at.join(", ") },
            dofs.len()
        ),
    }
}
