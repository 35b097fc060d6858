//! Case V: the prototype's four tensions (paper Section V, Fig. 10b), simulated. The paper compares
//! its 1-DOF ROMs with *measured* tip positions; without the prototype, gvsrom compares them with
//! the HOM, which the paper's ROMs approximate, and prints the paper's measured errors beside.
//! Data and models are IV-A's (same robot: gravity, friction 0.88; same steps, reused).

use super::evaluation::{statics_eval, EvalModel};
use super::figures;
use super::report::{figure, CaseReport, Cell, Finding, RenderedFigure, Table};
use super::{iv_a, new_report, paper, Case, Options, Run};
use crate::plot::{palette, Figure, Series, SeriesStyle};
use serde_json::json;

/// Runs case V.
pub fn run(run: &Run, opts: &Options) -> anyhow::Result<(CaseReport, Vec<RenderedFigure>)> {
    let m = iv_a::models(run, opts)?;
    let mut report = new_report(
        Case::V,
        "experimental validation, simulated (paper Section V)",
    );
    report.setup = vec![
        "scenario: preset `single-tendon`, the prototype of Table II with gravity along −z and friction μ = 0.88 (as IV-A)".into(),
        format!("models: IV-A's autoencoder with r = 1 and 7 hidden layers and POD with 1 mode, trained on IV-A's {} equilibria in [−6, 3] N", m.data.value.samples),
        format!("tensions: {:?} N, the prototype's measured tensions", paper::V_TENSIONS),
        "reference: the HOM (the paper's reference is the prototype's tip, measured by camera)".into(),
    ];
    let models = [
        EvalModel::hom(),
        EvalModel::of("AE-1", &m.aes[2][0]),
        EvalModel::of("POD-1", &m.pods[0]),
    ];
    let inputs: Vec<Vec<String>> = paper::V_TENSIONS
        .iter()
        .map(|u| vec![format!("tendons.0.tension={u}")])
        .collect();
    let ev = statics_eval(run, "v/eval", &m.scenario, &inputs, &models, 1)?;
    let ev = &ev.value;
    let length = ev.length;
    let mut rows = vec![];
    for (p, u) in ev.points.iter().zip(paper::V_TENSIONS) {
        let tip = |l: &str| {
            p.models
                .iter()
                .find(|s| s.label == l)
                .map(|s| s.tip)
                .unwrap_or([f64::NAN; 3])
        };
        let (h, a, q) = (tip("HOM"), tip("AE-1"), tip("POD-1"));
        let d = |x: [f64; 3]| {
            ((x[0] - h[0]).powi(2) + (x[2] - h[2]).powi(2) + (x[1] - h[1]).powi(2)).sqrt()
        };
        rows.push(vec![
            Cell::fixed(u, 2),
            Cell::fixed(h[0] * 100.0, 2),
            Cell::fixed(h[2] * 100.0, 2),
            Cell::fixed(a[0] * 100.0, 2),
            Cell::fixed(a[2] * 100.0, 2),
            Cell::fixed(q[0] * 100.0, 2),
            Cell::fixed(q[2] * 100.0, 2),
            Cell::fixed(d(a) * 100.0, 3),
            Cell::fixed(d(q) * 100.0, 3),
        ]);
    }
    report.tables.push(Table {
        id: "tips".into(),
        title: "Tip positions [cm] and the ROMs' distance from the HOM's tip [cm]".into(),
        columns: [
            "u [N]",
            "HOM x",
            "HOM z",
            "AE-1 x",
            "AE-1 z",
            "POD-1 x",
            "POD-1 z",
            "AE-1 − HOM",
            "POD-1 − HOM",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        note:
            "World frame: the arm leaves its base along +x, gravity along −z; y stays 0 (planar)."
                .into(),
    });
    let (ae_mean, ae_max) = ev.stats("AE-1", |s| s.tip_error_percent);
    let (pod_mean, pod_max) = ev.stats("POD-1", |s| s.tip_error_percent);
    let cm = |pct: f64| pct / 100.0 * length * 100.0;
    report.tables.push(Table {
        id: "errors".into(),
        title: "Tip errors beside the paper's (ours: ROM against the HOM; paper: ROM against the measured prototype)".into(),
        columns: ["model", "mean [cm]", "max [cm]", "mean [% L]", "max [% L]", "paper mean [cm]", "paper max [cm]", "paper mean [% L]", "paper max [% L]"].map(String::from).to_vec(),
        rows: vec![
            vec![Cell::text("AE-ROM r = 1"), Cell::sig(cm(ae_mean), 3), Cell::sig(cm(ae_max), 3), Cell::sig(ae_mean, 3), Cell::sig(ae_max, 3), Cell::sig(paper::V_AE_ERROR_CM[0], 3), Cell::sig(paper::V_AE_ERROR_CM[1], 3), Cell::sig(paper::V_AE_ERROR_PERCENT[0], 3), Cell::sig(paper::V_AE_ERROR_PERCENT[1], 3)],
            vec![Cell::text("POD-ROM r = 1"), Cell::sig(cm(pod_mean), 3), Cell::sig(cm(pod_max), 3), Cell::sig(pod_mean, 3), Cell::sig(pod_max, 3), Cell::sig(paper::V_POD_ERROR_CM[0], 3), Cell::sig(paper::V_POD_ERROR_CM[1], 3), Cell::sig(paper::V_POD_ERROR_PERCENT[0], 4), Cell::sig(paper::V_POD_ERROR_PERCENT[1], 4)],
        ],
        note: "The paper's errors include the HOM's own modelling error against the prototype; ours are the reduction error alone.".into(),
    });
    report.findings = vec![Finding {
        claim: "with one DOF the AE-ROM is far closer than the POD-ROM".into(),
        holds: ae_mean < pod_mean,
        evidence: format!(
            "mean tip error {} % L (AE-1) against {} % L (POD-1) of the HOM's tip",
            Cell::sig(ae_mean, 3).render(),
            Cell::sig(pod_mean, 3).render()
        ),
    }];
    report.notes = vec![format!(
        "Without the prototype the measured tips are not available. The paper's errors contain the HOM's own error against the prototype as well as the reduction's; ours are the reduction's alone: POD-1 {} % L here against the paper's {} % L, AE-1 {} % L against {} % L.",
        Cell::sig(pod_mean, 3).render(),
        Cell::sig(paper::V_POD_ERROR_PERCENT[0], 4).render(),
        Cell::sig(ae_mean, 3).render(),
        Cell::sig(paper::V_AE_ERROR_PERCENT[0], 3).render(),
    )];
    report.settings = m.settings.clone();
    report.values = json!({ "evaluation": ev });
    let looks = [
        ("AE-1", palette::AE, SeriesStyle::Line),
        ("POD-1", palette::POD, SeriesStyle::Line),
    ];
    let all: Vec<usize> = (0..ev.points.len()).collect();
    let mut chart = figures::configurations(
        ev,
        &all,
        &looks,
        "V: configurations at u = −1.12, −2.35, −3.7, −5.05 N",
    );
    let hom_tips: Vec<[f64; 3]> = ev.of("HOM").map(|s| s.tip).collect();
    chart.series.push(Series {
        label: "HOM tip".into(),
        x: hom_tips.iter().map(|t| t[0]).collect(),
        y: hom_tips.iter().map(|t| t[2]).collect(),
        style: SeriesStyle::Markers,
        color: Some(palette::HOM),
    });
    let fig = Figure::Line(chart);
    let figures = vec![figure("fig10b-configurations", "Fig. 10b (simulated): the configurations of the 1-DOF AE-ROM and POD-ROM at the prototype's tensions, with the HOM's tips", &fig, 1000, 750)?];
    Ok((report, figures))
}
