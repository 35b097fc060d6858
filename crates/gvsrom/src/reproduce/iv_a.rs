//! Case IV-A: the single-tendon manipulator (paper Section IV-A, Table I top, Figs. 3–4, Table III).
//!
//! Data: 1000 equilibria at tensions evenly spaced in [−6, 3] N (preset `single-tendon`: gravity,
//! friction 0.88). Models: autoencoders r = 1, 2, 3 × 3, 5, 7 hidden layers (Table I) and POD with
//! 1 … 10 modes. Test: 20 tensions between the training ones (−5.85 + 0.45 i N), where every model's
//! equilibrium is solved as `gvsrom statics [--model]` solves it.

use super::evaluation::{statics_eval, EvalModel, Evaluation};
use super::figures;
use super::report::{figure, ratio, CaseReport, Cell, RenderedFigure, Table};
use super::statics_study::StaticsComparison;
use super::step::Step;
use super::tasks::{self, AeConfig, DatasetSpec, ModelInfo, ScenarioSpec};
use super::{new_report, paper, Case, Options, Run};
use crate::plot::{palette, Figure, SeriesStyle};
use serde_json::json;

/// The setup shared by IV-A and V: scenario, data and the models both use.
pub struct Models {
    pub scenario: ScenarioSpec,
    pub data: super::step::Step<tasks::DatasetInfo>,
    /// Table I: `[h][r − 1]` for h in 3, 5, 7 hidden layers.
    pub aes: Vec<Vec<super::step::Step<ModelInfo>>>,
    /// POD with 1 … `pods.len()` modes.
    pub pods: Vec<super::step::Step<ModelInfo>>,
    pub settings: serde_json::Value,
}

/// Beyond the paper: POD in the autoencoders' norm (strain energy) with 1 … this many modes.
const ENERGY_PODS: usize = 4;

/// Sizes of the full and the quick run.
struct Sizes {
    samples: usize,
    epochs: usize,
    max_pod: usize,
    repeat: u32,
}

fn sizes(opts: &Options) -> Sizes {
    if opts.tiny {
        Sizes {
            samples: 40,
            epochs: 15,
            max_pod: 3,
            repeat: 1,
        }
    } else if opts.quick {
        Sizes {
            samples: 200,
            epochs: 150,
            max_pod: 8,
            repeat: 2,
        }
    } else {
        Sizes {
            samples: 1000,
            // r = 1, 7 layers: 1000 epochs 48 s and RMSE 8.2e-3, 2000 epochs 98 s and 6.2e-3 (idle
            // 2-core machine; the paper 0.0383): the shorter budget keeps a model within a minute
            epochs: 1000,
            max_pod: 10,
            repeat: 5,
        }
    }
}

/// The IV-A scenario: the preset as it is (gravity, friction 0.88).
pub fn scenario() -> ScenarioSpec {
    ScenarioSpec::new("single-tendon", &[])
}

fn plan(opts: &Options) -> DatasetSpec {
    DatasetSpec {
        sweep: vec!["tendons.0.tension=-6:3".into()],
        samples: Some(sizes(opts).samples),
        ..DatasetSpec::default()
    }
}

/// The IV-A dataset (step `iv-a/dataset`).
pub fn dataset(run: &Run, opts: &Options) -> anyhow::Result<Step<tasks::DatasetInfo>> {
    tasks::dataset(run, "iv-a/dataset", &scenario(), &plan(opts), opts.jobs)
}

/// The settings of the IV-A autoencoder with `r` latent coordinates and `h` hidden layers.
pub fn ae_config(opts: &Options, r: usize, h: usize) -> AeConfig {
    let mut c = AeConfig::new(r, h, sizes(opts).epochs);
    if opts.tiny {
        c.lbfgs_iterations = 10;
    }
    c
}

/// The name of the step that trains the IV-A autoencoder `c` on `data`.
pub fn ae_step(
    run: &Run,
    data: &Step<tasks::DatasetInfo>,
    c: &AeConfig,
) -> anyhow::Result<Step<ModelInfo>> {
    tasks::train(
        run,
        &format!("iv-a/ae-r{}-h{}", c.latent, c.hidden_layers),
        data,
        c,
    )
}

/// The IV-A data and every model trained on it (steps shared with case V).
pub fn models(run: &Run, opts: &Options) -> anyhow::Result<Models> {
    let s = sizes(opts);
    let scenario = scenario();
    let data = dataset(run, opts)?;
    let configs: Vec<AeConfig> = paper::TABLE_I_LAYERS
        .iter()
        .flat_map(|&h| (1..=3).map(move |r| (h, r)))
        .map(|(h, r)| ae_config(opts, r, h))
        .collect();
    let trained = tasks::parallel(&configs, |c| ae_step(run, &data, c))?;
    let aes = trained.chunks(3).map(<[_]>::to_vec).collect();
    let modes: Vec<usize> = (1..=s.max_pod).collect();
    let pods = tasks::parallel(&modes, |&k| {
        tasks::pod(run, &format!("iv-a/pod-{k}"), &data, k)
    })?;
    let settings = json!({
        "scenario": scenario, "plan": plan(opts), "autoencoders": configs, "pod_modes": modes,
    });
    Ok(Models {
        scenario,
        data,
        aes,
        pods,
        settings,
    })
}

/// The 20 test tensions of IV-A \[N\]: midway between training levels, never on one.
pub fn test_tensions() -> Vec<f64> {
    (0..20)
        .map(|i| (-585.0 + 45.0 * i as f64) / 100.0)
        .collect()
}

/// Runs case IV-A.
pub fn run(run: &Run, opts: &Options) -> anyhow::Result<(CaseReport, Vec<RenderedFigure>)> {
    let s = sizes(opts);
    let m = models(run, opts)?;
    // beyond the paper: POD in the autoencoders' norm, at the sizes where plain POD reaches 1 %
    let energy_modes: Vec<usize> = (1..=m.pods.len().min(ENERGY_PODS)).collect();
    let pods_energy = tasks::parallel(&energy_modes, |&k| {
        tasks::pod_in(
            run,
            &format!("iv-a/pod-{k}-energy"),
            &m.data,
            k,
            crate::reduce::PodNorm::Energy,
        )
    })?;
    let mut report = new_report(
        Case::IvA,
        "single-tendon soft manipulator (paper Section IV-A)",
    );
    report.setup = vec![
        "scenario: preset `single-tendon` (0.25 m tapered arm, horizontal cantilever under gravity along −z, friction μ = 0.88 with the preset's smoothing, 33-DOF Legendre basis, 102 computational points; 3 active strain components: bend-y, elongation, shear-z)".into(),
        format!("data: {} equilibria at tensions evenly spaced in [−6, 3] N (`gvsrom dataset single-tendon --sweep tendons.0.tension=-6:3 --samples {}`); {} solved, {} failed", m.data.value.samples, m.data.value.samples, m.data.value.ok, m.data.value.failed),
        format!("autoencoders: r = 1, 2, 3 × 3, 5, 7 hidden layers, tanh, λ = 1e-4 against a whole snapshot's squared error (eq. 15), loss in the strain-energy norm, Adam ≤ {} epochs with learning-rate reductions at plateaus and early stopping, then L-BFGS (`gvsrom train` defaults)", s.epochs),
        format!("POD: 1 … {} modes of the uncentred snapshots; beyond the paper also 1 … {} modes in the strain-energy norm, the autoencoders' (`gvsrom pod --norm energy`: each strain value weighted by its section stiffness)", m.pods.len(), pods_energy.len()),
        format!("test: the 20 tensions −5.85 + 0.45 i N (between training levels); each equilibrium solved {} times, mean time; the HOM from the straight rod, the ROMs from their anchors (as `gvsrom statics [--model]`)", s.repeat),
    ];
    report.tables.push(table_i(
        "table-i",
        "Table I (top): RMS reconstruction error over the full dataset",
        &m.aes,
        &paper::TABLE_I_IV_A,
        "RMS of x̂ − x over every entry of every snapshot (training and validation rows), x = ξ − ξ* at the 102 points for bend-y [1/m], elongation and shear-z [–]; the paper gives no units. Columns: ours, the paper's, ours / paper.",
    ));

    // evaluation of the HOM, the AE r = 1 (7 layers) and every POD model at the test tensions
    let mut models = vec![EvalModel::hom(), EvalModel::of("AE-1", &m.aes[2][0])];
    for (k, p) in m.pods.iter().enumerate() {
        models.push(EvalModel::of(&format!("POD-{}", k + 1), p));
    }
    for (k, p) in pods_energy.iter().enumerate() {
        models.push(EvalModel::of(&format!("POD-{} (energy norm)", k + 1), p));
    }
    let inputs: Vec<Vec<String>> = test_tensions()
        .iter()
        .map(|u| vec![format!("tendons.0.tension={u}")])
        .collect();
    let ev = statics_eval(run, "iv-a/eval", &m.scenario, &inputs, &models, s.repeat)?;
    let ev = &ev.value;
    let modes: Vec<usize> = (1..=m.pods.len()).collect();
    let c = StaticsComparison::of(ev, 1, &modes);
    let (k, pod_k) = (c.pod_k, c.pod_k_label());
    report.tables.push(accuracy_table(ev, &models));
    report.tables.push(c.table_iii(&paper::TABLE_III_IV_A));
    report.findings = c.findings("the 20 test tensions");
    let latent = super::iv_common::latent_and_dimension(
        &m.data.path,
        &[&m.aes[0][1], &m.aes[0][2]],
        &m.aes[2],
        0,
        "tension u [N]",
    )?;
    report.tables.push(latent.table.clone());
    report.notes = vec![
        format!("POD needs {} modes here for < 1 % strain error at every test tension; the paper needed 7. Our HOM is the same 33-DOF model; the difference is in how the paper's error was measured (it does not state the normalisation: ours is the MAE over the points and active components / the HOM's peak |ξ − ξ*|) and in its test tensions.", k.map_or("more than the tried".to_string(), |k| k.to_string())),
        "Times are gvsrom's on this machine (single solve, mean of the repetitions, one thread), the paper's MATLAB's on an i9-13900HX: compare the ratios between models, not the absolute times.".into(),
    ];
    report.settings = m.settings.clone();
    report.values = json!({
        "table_i": table_i_values(&m.aes),
        "pod_k_below_1_percent": k,
        "evaluation": ev,
        "intrinsic_dimension": latent.values,
    });
    let figures = vec![
        fig4(ev, pod_k.as_deref())?,
        figure("fig3-latent", "Fig. 3: latent coordinates of the training samples, AE with r = 2 (left) and r = 3 (right), 3 hidden layers, coloured by the tension", &latent.figure, 1400, 620)?,
    ];
    Ok((report, figures))
}

/// Table I for one case: ours, the paper's and the ratio per r, one row per depth.
pub fn table_i(
    id: &str,
    title: &str,
    aes: &[Vec<super::step::Step<ModelInfo>>],
    paper: &[[f64; 3]; 3],
    note: &str,
) -> Table {
    let mut columns = vec!["hidden layers".to_string()];
    for r in 1..=3 {
        columns.extend([format!("r = {r}"), format!("paper r = {r}"), "ratio".into()]);
    }
    let rows = aes
        .iter()
        .zip(paper::TABLE_I_LAYERS)
        .zip(paper)
        .map(|((row, h), p)| {
            let mut cells = vec![Cell::int(h)];
            for (ae, pv) in row.iter().zip(p) {
                cells.extend([
                    Cell::sig(ae.value.rmse_full, 3),
                    Cell::fixed(*pv, 4),
                    ratio(ae.value.rmse_full, *pv),
                ]);
            }
            cells
        })
        .collect();
    Table {
        id: id.into(),
        title: title.into(),
        columns,
        rows,
        note: note.into(),
    }
}

fn table_i_values(aes: &[Vec<super::step::Step<ModelInfo>>]) -> serde_json::Value {
    json!(aes
        .iter()
        .map(|row| row.iter().map(|a| &a.value).collect::<Vec<_>>())
        .collect::<Vec<_>>())
}

/// Per model: DOF, strain and tip errors (mean, max over the test inputs) and mean time.
pub fn accuracy_table(ev: &Evaluation, models: &[EvalModel]) -> Table {
    let rows = models
        .iter()
        .filter_map(|m| {
            let first = ev.of(&m.label).next()?;
            let (se, sm) = ev.stats(&m.label, |s| s.strain_error_percent);
            let (te, tm) = ev.stats(&m.label, |s| s.tip_error_percent);
            let (t, _) = ev.stats(&m.label, |s| s.time_s);
            let failed = ev.of(&m.label).filter(|s| s.error.is_some()).count();
            Some(vec![
                Cell::text(&m.label),
                Cell::int(first.dof),
                Cell::sig(se, 3),
                Cell::sig(sm, 3),
                Cell::sig(te, 3),
                Cell::sig(tm, 3),
                Cell::sig(t * 1e3, 3),
                Cell::int(failed),
            ])
        })
        .collect();
    Table {
        id: "accuracy".into(),
        title: "Accuracy and time at the test inputs (Fig. 4 / Fig. 6 numbers)".into(),
        columns: [
            "model", "DOF", "strain error mean [%]", "strain error max [%]", "tip error mean [% L]",
            "tip error max [% L]", "time per equilibrium [ms]", "failed solves",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        note: "Strain error: mean |ξ_ROM − ξ_HOM| over the points and active components, in % of the HOM's largest |ξ − ξ*| (the paper's \"< 1 % strain error\"); tip error: ‖p_ROM − p_HOM‖ / L. A failed solve (no convergence, or the decoder extrapolating) makes its row's errors –.".into(),
    }
}

/// Fig. 4: bend-y strain along the rod at three test tensions (HOM, AE-1, POD-2, POD-k) and the
/// AE-ROM's configurations at six.
fn fig4(ev: &Evaluation, pod_k: Option<&str>) -> anyhow::Result<RenderedFigure> {
    let mut looks = vec![
        ("HOM", palette::HOM, SeriesStyle::Line),
        ("AE-1", palette::AE, SeriesStyle::Dashed),
        ("POD-2", palette::POD, SeriesStyle::Dashed),
    ];
    if let Some(l) = pod_k {
        looks.push((l, palette::POD_ALT, SeriesStyle::Dashed));
    }
    let mut panels: Vec<Figure> = [0usize, 7, 16]
        .iter()
        .map(|&i| {
            let title = ev.points[i]
                .set
                .join(" ")
                .replace("tendons.0.tension=", "u = ")
                + " N";
            figures::strain_panel(ev, i, "bend_y", "bend-y strain ξ₂ [1/m]", title, &looks)
        })
        .collect();
    panels.push(Figure::Line(figures::configurations(
        ev,
        &[0, 4, 8, 12, 16, 19],
        &looks[..2],
        "configurations, u = −5.85 … 2.7 N",
    )));
    figure(
        "fig4-strain",
        "Fig. 4: bend-y strain along the rod of the HOM, the AE-ROM (r = 1) and POD-ROMs with 2 and k modes (k: the fewest reaching < 1 %) at three test tensions, and the HOM and AE-ROM configurations (side view x–z) at six",
        &Figure::Grid { title: "IV-A: strain profiles and configurations".into(), cols: 2, panels },
        1400,
        1000,
    )
}
