//! Figure builders the statics cases share: strain profiles along the rod and side views of the
//! configurations, from an [`Evaluation`].

use super::evaluation::{Evaluation, Solved};
use crate::plot::{Figure, LineChart, Rgb, Series, SeriesStyle};

/// How a model is drawn: its label in the evaluation, its colour and its line style.
pub type Look<'a> = (&'a str, Rgb, SeriesStyle);

/// The solution of model `label` at input `i`, if it solved.
fn solved<'a>(ev: &'a Evaluation, i: usize, label: &str) -> Option<&'a Solved> {
    ev.points
        .get(i)?
        .models
        .iter()
        .find(|m| m.label == label && m.error.is_none())
}

/// One model's strain component `component` along the rod as a series.
pub fn strain_series(ev: &Evaluation, s: &Solved, component: &str, look: Look<'_>) -> Series {
    let a = ev.components.len();
    let c = ev
        .components
        .iter()
        .position(|n| n == component)
        .unwrap_or(0);
    Series {
        label: look.0.into(),
        x: ev.strain_x.clone(),
        y: (0..ev.strain_x.len())
            .map(|j| s.strain.get(j * a + c).copied().unwrap_or(f64::NAN))
            .collect(),
        style: look.2,
        color: Some(look.1),
    }
}

/// The strain component `component` of `models` along the rod at input `i`.
pub fn strain_panel(
    ev: &Evaluation,
    i: usize,
    component: &str,
    y_label: &str,
    title: String,
    models: &[Look<'_>],
) -> Figure {
    Figure::Line(LineChart {
        title,
        x_label: "X [m]".into(),
        y_label: y_label.into(),
        series: models
            .iter()
            .filter_map(|look| Some(strain_series(ev, solved(ev, i, look.0)?, component, *look)))
            .collect(),
        log_y: false,
        equal_aspect: false,
    })
}

/// The centrelines of `models` at the inputs `inputs`, side view x–z (equal scales); each model's
/// label appears once in the legend.
pub fn configurations(
    ev: &Evaluation,
    inputs: &[usize],
    models: &[Look<'_>],
    title: &str,
) -> LineChart {
    let mut series = vec![];
    for (n, &i) in inputs.iter().enumerate() {
        for &(label, color, style) in models {
            if let Some(s) = solved(ev, i, label) {
                series.push(Series {
                    label: if n == 0 { label.into() } else { String::new() },
                    x: s.centerline.iter().map(|c| c[0]).collect(),
                    y: s.centerline.iter().map(|c| c[2]).collect(),
                    style,
                    color: Some(color),
                });
            }
        }
    }
    LineChart {
        title: title.into(),
        x_label: "x [m]".into(),
        y_label: "z [m]".into(),
        series,
        log_y: false,
        equal_aspect: true,
    }
}
