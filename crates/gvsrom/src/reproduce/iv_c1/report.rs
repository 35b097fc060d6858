//! IV-C1's tables and figures: the datasets and models tables, Fig. 7's configurations with its
//! inputs table, the Table III same-DOF row beside the paper's, and Fig. 8's table and figure.

use super::super::evaluation::{EvalPoint, Evaluation};
use super::super::paper;
use super::super::report::{figure, ratio, Cell, Digits, RenderedFigure, Table};
use super::super::step::Step;
use super::super::tasks::{DatasetInfo, ModelInfo};
use super::{Sampling, Times, R, TESTS};
use crate::plot::{palette, Figure, LineChart, Scatter3, Series, SeriesStyle};

/// Samples, solved and failed equilibria of each dataset.
pub(super) fn datasets_table(rows: [(&str, &DatasetInfo); 3]) -> Table {
    Table {
        id: "datasets".into(),
        title: "Datasets".into(),
        columns: ["dataset", "samples", "solved", "failed"]
            .map(String::from)
            .to_vec(),
        rows: rows
            .iter()
            .map(|(name, d)| {
                vec![
                    Cell::text(*name),
                    Cell::int(d.samples),
                    Cell::int(d.ok),
                    Cell::int(d.failed),
                ]
            })
            .collect(),
        note: "A failed sample is an equilibrium the HOM's Newton solver (with its load ramp) did not reach; it is recorded as failed and left out of the snapshots.".into(),
    }
}

/// The two reduced models: reconstruction error, training outcome.
pub(super) fn models_table(ae: &Step<ModelInfo>, pod: &Step<ModelInfo>) -> Table {
    let opt = |v: Option<f64>| Cell::sig(v.unwrap_or(f64::NAN), 3);
    Table {
        id: "models".into(),
        title: "Reduced models".into(),
        columns: [
            "model",
            "DOF",
            "RMS reconstruction error",
            "validation RMSE",
            "epochs run",
            "POD captured energy",
        ]
        .map(String::from)
        .to_vec(),
        rows: vec![
            vec![
                Cell::text("AE-6"),
                Cell::int(ae.value.latent),
                Cell::sig(ae.value.rmse_full, 3),
                opt(ae.value.val_rmse),
                ae.value
                    .epochs_run
                    .map_or(Cell::num(f64::NAN, Digits::Fixed(0)), Cell::int),
                Cell::num(f64::NAN, Digits::Sig(3)),
            ],
            vec![
                Cell::text("POD-6"),
                Cell::int(pod.value.latent),
                Cell::sig(pod.value.rmse_full, 3),
                Cell::num(f64::NAN, Digits::Sig(3)),
                Cell::num(f64::NAN, Digits::Fixed(0)),
                opt(pod.value.captured_energy),
            ],
        ],
        note: "RMS of x̂ − x over every entry of every solved snapshot of the training data, x = ξ − ξ* at the computational points, six components (curvatures in 1/m, elongation and shears unitless). Epochs: Adam epochs plus L-BFGS iterations. Captured energy: Σ of the kept squared singular values / Σ of all.".into(),
    }
}

/// Fig. 7's annotations: each test input's tensions and the ROMs' tip errors against the HOM.
pub(super) fn inputs_table(ev: &Evaluation, tensions: &[[f64; 6]]) -> Table {
    let mut columns = vec!["input".to_string()];
    columns.extend((1..=6).map(|k| format!("u{k} [N]")));
    columns.extend(
        [
            "AE-6 tip error [cm]",
            "AE-6 tip error [% L]",
            "POD-6 tip error [cm]",
            "POD-6 tip error [% L]",
        ]
        .map(String::from),
    );
    let rows = ev
        .points
        .iter()
        .zip(tensions)
        .enumerate()
        .map(|(i, (p, u))| {
            let mut row = vec![Cell::int(i + 1)];
            row.extend(u.iter().map(|&v| Cell::fixed(v, 1)));
            for label in ["AE-6", "POD-6"] {
                let (cm, pct) = tip_error(p, label);
                row.extend([Cell::sig(cm, 3), Cell::sig(pct, 3)]);
            }
            row
        })
        .collect();
    Table {
        id: "inputs".into(),
        title: "Test inputs and tip errors (Fig. 7's annotations)".into(),
        columns,
        rows,
        note: "u_k: tension of tendon k (negative pulls; odd k full length, even k half length, numbering from 1). Tip error: ‖p_ROM − p_HOM‖, and in % of the length L = 0.6 m. – : the ROM's solve failed.".into(),
    }
}

/// Model `label`'s tip error at point `p`: ‖p_ROM − p_HOM‖ [cm] and in % of the length (NaN if a
/// solve failed).
fn tip_error(p: &EvalPoint, label: &str) -> (f64, f64) {
    let find = |l: &str| p.models.iter().find(|m| m.label == l && m.error.is_none());
    match (find("HOM"), find(label)) {
        (Some(h), Some(m)) => {
            let d = (0..3).map(|i| (m.tip[i] - h.tip[i]).powi(2)).sum::<f64>();
            (d.sqrt() * 100.0, m.tip_error_percent)
        }
        _ => (f64::NAN, f64::NAN),
    }
}

/// Table III's same-DOF row: tip errors and times of POD-6 and AE-6, the HOM's time, beside the
/// paper's.
pub(super) fn table_iii(
    hom_dof: usize,
    ae_tip: f64,
    pod_tip: f64,
    length: f64,
    t: &Times,
) -> Table {
    let p = &paper::TABLE_III_IV_C1;
    let (p_pod_err, p_ae_err) = (
        p.pod_error.unwrap_or(f64::NAN),
        p.ae_error.unwrap_or(f64::NAN),
    );
    let cm = |pct: f64| pct / 100.0 * length * 100.0;
    let row = |q: &str, ours: Cell, paper: Cell, r: Cell| vec![Cell::text(q), ours, paper, r];
    let num = |q: &str, ours: f64, paper: f64| {
        row(
            q,
            Cell::sig(ours, 3),
            Cell::sig(paper, 3),
            ratio(ours, paper),
        )
    };
    let int = |q: &str, ours: usize, paper: usize| {
        row(
            q,
            Cell::int(ours),
            Cell::int(paper),
            ratio(ours as f64, paper as f64),
        )
    };
    let rows = vec![
        int("HOM DOF", hom_dof, paper::IV_C_HOM_DOF),
        int("ROM DOF (POD modes = AE latent size)", R, p.ae_dof),
        num("POD-ROM tip error [% L]", pod_tip, p_pod_err),
        num("AE-ROM tip error [% L]", ae_tip, p_ae_err),
        num(
            "POD-ROM tip error [cm]",
            cm(pod_tip),
            paper::IV_C1_POD_TIP_ERROR_CM,
        ),
        num(
            "AE-ROM tip error [cm]",
            cm(ae_tip),
            paper::IV_C1_AE_TIP_ERROR_CM,
        ),
        num("POD-ROM time [s]", t.pod, p.pod_time_s),
        num("AE-ROM time [s]", t.ae, p.ae_time_s),
        num("HOM time [s]", t.hom, p.hom_time_s),
        num(
            "POD-ROM tip error / AE-ROM tip error",
            pod_tip / ae_tip,
            p_pod_err / p_ae_err,
        ),
        num(
            "AE-ROM time / POD-ROM time",
            t.ae / t.pod,
            p.ae_time_s / p.pod_time_s,
        ),
        num(
            "AE-ROM speed-up over the HOM",
            t.hom / t.ae,
            p.hom_time_s / p.ae_time_s,
        ),
        num(
            "POD-ROM speed-up over the HOM",
            t.hom / t.pod,
            p.hom_time_s / p.pod_time_s,
        ),
    ];
    Table {
        id: "table-iii".into(),
        title: "Table III row (same DOF study: 6 DOF)".into(),
        columns: ["quantity", "ours", "paper", "ratio"].map(String::from).to_vec(),
        rows,
        note: "Tip errors: mean over the five test inputs of ‖p_ROM − p_HOM‖ (the paper's cm values are from its text). Times: mean wall time of one static equilibrium over the test inputs. Ours: gvsrom, one thread, this machine; the paper's: MATLAB on an i9-13900HX.".into(),
    }
}

/// Fig. 8's numbers: per sampling, the codes' spread over PC₁–PC₃.
pub(super) fn fig8_table(s: &[Sampling; 2]) -> Table {
    Table {
        id: "fig8".into(),
        title: "Fig. 8: grid against random sampling, r = 6 autoencoders".into(),
        columns: [
            "sampling",
            "samples",
            "AE validation RMSE",
            "variance on PC₁–PC₃ [%]",
            "grid cells n",
            "occupied cells of the PC₁–PC₃ box [%]",
        ]
        .map(String::from)
        .to_vec(),
        rows: s
            .iter()
            .map(|x| {
                vec![
                    Cell::text(x.name),
                    Cell::int(x.samples),
                    Cell::sig(x.val_rmse, 3),
                    Cell::sig(x.explained * 100.0, 3),
                    Cell::int(x.bins),
                    Cell::sig(x.occupied * 100.0, 3),
                ]
            })
            .collect(),
        note: "Each autoencoder encodes its own training samples; the codes are centred and projected on their first three principal components. Occupied cells: of an n × n × n grid over the bounding box of the projections (a higher share: the codes chart the box more evenly).".into(),
    }
}

/// Fig. 7: the HOM's, AE-6's and POD-6's centrelines at the five test inputs, side view (x–z, top
/// row) and top view (x–y, bottom row), the inputs and the ROMs' tip errors in the titles.
pub(super) fn fig7(ev: &Evaluation, tensions: &[[f64; 6]]) -> anyhow::Result<RenderedFigure> {
    let styles = [
        ("HOM", palette::HOM, SeriesStyle::Line),
        ("AE-6", palette::AE, SeriesStyle::Dashed),
        ("POD-6", palette::POD, SeriesStyle::Dashed),
    ];
    let views: [(usize, &str); 2] = [(2, "z [m]"), (1, "y [m]")];
    let mut panels = vec![];
    for (v, (axis, y_label)) in views.iter().enumerate() {
        // each model enters the legend once per row, in the first panel where it solved
        let mut in_legend = [false; 3];
        for (i, (p, u)) in ev.points.iter().zip(tensions).enumerate() {
            let mut series = vec![];
            for ((label, color, style), shown) in styles.iter().zip(in_legend.iter_mut()) {
                let Some(s) = p
                    .models
                    .iter()
                    .find(|m| m.label == *label && m.error.is_none())
                else {
                    continue;
                };
                let first = !std::mem::replace(shown, true);
                series.push(Series {
                    label: if first {
                        label.to_string()
                    } else {
                        String::new()
                    },
                    x: s.centerline.iter().map(|c| c[0]).collect(),
                    y: s.centerline.iter().map(|c| c[*axis]).collect(),
                    style: *style,
                    color: Some(*color),
                });
                // the tip, whose distance from the HOM's is the annotated error
                series.push(Series {
                    label: String::new(),
                    x: vec![s.tip[0]],
                    y: vec![s.tip[*axis]],
                    style: SeriesStyle::Markers,
                    color: Some(*color),
                });
            }
            let title = if v == 0 {
                let u: Vec<String> = u.iter().map(|x| Cell::fixed(*x, 1).render()).collect();
                format!("#{}: u = [{}] N", i + 1, u.join(", "))
            } else {
                let err = |label: &str| match tip_error(p, label).0 {
                    e if e.is_finite() => format!("{} cm", Cell::sig(e, 3).render()),
                    _ => "failed".to_string(),
                };
                format!(
                    "#{}: tip error AE {}, POD {}",
                    i + 1,
                    err("AE-6"),
                    err("POD-6")
                )
            };
            panels.push(Figure::Line(LineChart {
                title,
                x_label: "x [m]".into(),
                y_label: y_label.to_string(),
                series,
                log_y: false,
                equal_aspect: true,
            }));
        }
    }
    figure(
        "fig7-configurations",
        "Fig. 7: configurations of the HOM (green), the AE-ROM with r = 6 (gold) and the POD-ROM with 6 modes (red) at the five test inputs; top row side view (x–z, gravity along −z) with the tensions, bottom row top view (x–y) with the ROMs' tip errors against the HOM",
        &Figure::Grid {
            title: "IV-C1: six-tendon manipulator under gravity, HOM against 6-DOF ROMs".into(),
            cols: TESTS,
            panels,
        },
        2600,
        1150,
    )
}

/// Fig. 8: the training codes of the grid- and the random-sampled autoencoders on PC₁–PC₃,
/// coloured by PC₃.
pub(super) fn fig8_figure(s: &[Sampling; 2]) -> anyhow::Result<RenderedFigure> {
    let panels = s
        .iter()
        .map(|x| {
            Figure::Scatter3(Scatter3 {
                title: format!("{} sampling ({} samples)", x.name, x.samples),
                labels: ["PC₁".into(), "PC₂".into(), "PC₃".into()],
                points: x.pcs.clone(),
                color: Some(x.pcs.iter().map(|p| p[2]).collect()),
                color_label: "PC₃".into(),
            })
        })
        .collect();
    figure(
        "fig8-sampling",
        "Fig. 8: the 6-D latent codes of the training samples on their first three principal components, for an autoencoder (r = 6) trained on grid-sampled (left) and one trained on random-sampled tensions (right), equal sample counts; colour: PC₃",
        &Figure::Grid {
            title: "IV-C1: latent codes, grid against random sampling".into(),
            cols: 2,
            panels,
        },
        1400,
        650,
    )
}
