//! Figures of a `gvsrom dataset` directory: the coverage of the inputs (`input_coverage`: each input
//! over the samples, or pairs of inputs against each other, failed samples in red), the strain
//! envelope along the rod (`strain_envelope`: minimum, mean and maximum of each stored component
//! over the usable samples) and the tip positions reached (`tip_workspace`).

use super::views;
use super::{input_error, FiguresError, Sink};
use crate::dataset::generate::STATUS_FAILED;
use crate::dataset::Dataset;
use crate::plot::{palette, Figure, LineChart, Series, Series3, SeriesStyle};
use std::path::Path;

/// Input pairs drawn at most (the first inputs' pairs beyond that are left out).
const MAX_PAIRS: usize = 6;

/// All figures of the dataset in `dir`.
pub(crate) fn figures(dir: &Path, sink: &mut Sink) -> Result<(), FiguresError> {
    let ds = Dataset::load(dir).map_err(|e| input_error(dir, e.to_string()))?;
    sink.origin = Some(ds.origin.clone());
    if ds.samples() == 0 {
        return Err(input_error(dir, "the dataset has no samples"));
    }
    let ok = ds.ok_rows();
    let failed: Vec<usize> = (0..ds.samples())
        .filter(|&k| ds.status[k] == STATUS_FAILED)
        .collect();
    let caption = format!(
        "{}, {} of {} samples ok{}",
        ds.meta.scenario,
        ok.len(),
        ds.samples(),
        if ds.meta.complete {
            ""
        } else {
            " (incomplete)"
        }
    );
    if !failed.is_empty() {
        sink.note(format!(
            "{} failed samples are marked in red in input_coverage",
            failed.len()
        ));
    }
    input_coverage(&ds, &ok, &failed, &caption, sink)?;
    if ok.is_empty() {
        sink.note("strain_envelope, tip_workspace: the dataset has no usable sample");
        return Ok(());
    }
    strain_envelope(&ds, &ok, &caption, sink)?;
    let tips: Vec<[f64; 3]> = ok
        .iter()
        .map(|&k| std::array::from_fn(|i| ds.tip_position[3 * k + i]))
        .collect();
    let series = [Series3::new("tip", tips, SeriesStyle::Markers).with_color(palette::POD_ALT)];
    let fig = views::side_views(&format!("Tip positions — {caption}"), &series, &[]);
    sink.figure("tip_workspace", &fig, (1400, 600))
}

/// Input `i` of sample `k`.
fn input(ds: &Dataset, k: usize, i: usize) -> f64 {
    ds.inputs[k * ds.meta.parameters.len() + i]
}

/// The usable and the failed samples as two marker series of `(x(k), y(k))`.
fn ok_and_failed(
    ok: &[usize],
    failed: &[usize],
    x: impl Fn(usize) -> f64,
    y: impl Fn(usize) -> f64,
) -> Vec<Series> {
    let mut v = vec![Series::new(
        format!("ok ({})", ok.len()),
        ok.iter().map(|&k| x(k)).collect(),
        ok.iter().map(|&k| y(k)).collect(),
        SeriesStyle::Markers,
    )
    .with_color(palette::POD_ALT)];
    if !failed.is_empty() {
        v.push(
            Series::new(
                format!("failed ({})", failed.len()),
                failed.iter().map(|&k| x(k)).collect(),
                failed.iter().map(|&k| y(k)).collect(),
                SeriesStyle::Markers,
            )
            .with_color(palette::POD),
        );
    }
    v
}

/// `input_coverage`: one input over the samples (or time, for a dynamic dataset), or each pair of
/// the first inputs against each other.
fn input_coverage(
    ds: &Dataset,
    ok: &[usize],
    failed: &[usize],
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let names = &ds.meta.parameters;
    let d = names.len();
    let pairs: Vec<(usize, usize)> = (0..d)
        .flat_map(|a| (a + 1..d).map(move |b| (a, b)))
        .take(MAX_PAIRS)
        .collect();
    let title = format!("Input coverage — {caption}");
    let fig = if d == 0 {
        sink.note("input_coverage: the dataset records no inputs");
        return Ok(());
    } else if d == 1 || ds.t.is_some() {
        // each input against the sample index (or time)
        let (x_label, x): (&str, Box<dyn Fn(usize) -> f64>) = match &ds.t {
            Some(t) => ("t [s]", Box::new(move |k| t[k])),
            None => ("sample", Box::new(|k| k as f64)),
        };
        let panels: Vec<Figure> = (0..d.min(MAX_PAIRS))
            .map(|i| {
                Figure::Line(LineChart {
                    title: String::new(),
                    x_label: x_label.into(),
                    y_label: names[i].clone(),
                    series: ok_and_failed(ok, failed, &x, |k| input(ds, k, i)),
                    log_y: false,
                    equal_aspect: false,
                })
            })
            .collect();
        Figure::Grid {
            title,
            cols: 1,
            panels,
        }
    } else {
        let panels: Vec<Figure> = pairs
            .iter()
            .map(|&(a, b)| {
                Figure::Line(LineChart {
                    title: String::new(),
                    x_label: names[a].clone(),
                    y_label: names[b].clone(),
                    series: ok_and_failed(ok, failed, |k| input(ds, k, a), |k| input(ds, k, b)),
                    log_y: false,
                    equal_aspect: false,
                })
            })
            .collect();
        Figure::Grid {
            title,
            cols: panels.len().min(3),
            panels,
        }
    };
    let (cols, rows) = match &fig {
        Figure::Grid { cols, panels, .. } => (*cols as u32, panels.len().div_ceil(*cols) as u32),
        _ => (1, 1),
    };
    let width = if cols <= 1 { 900 } else { 640 * cols };
    sink.figure("input_coverage", &fig, (width, 60 + 420 * rows))
}

/// `strain_envelope`: per stored component, the minimum, mean and maximum of `ξ − ξ*` over the
/// usable samples at each point.
fn strain_envelope(
    ds: &Dataset,
    ok: &[usize],
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let a = ds.meta.components.len();
    let p = ds.strain_x.len();
    let value = |k: usize, j: usize, c: usize| ds.strain_row(k)[j * a + c];
    let panels: Vec<Figure> = ds
        .meta
        .components
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let (label, unit) = match views::component_index(name) {
                Some(e) => (
                    views::component_label(e).to_string(),
                    views::component_unit(e),
                ),
                None => (name.clone(), "?"),
            };
            let stat = |f: &dyn Fn(&mut dyn Iterator<Item = f64>) -> f64| -> Vec<f64> {
                (0..p)
                    .map(|j| f(&mut ok.iter().map(|&k| value(k, j, c))))
                    .collect()
            };
            let min = stat(&|it| it.fold(f64::INFINITY, f64::min));
            let max = stat(&|it| it.fold(f64::NEG_INFINITY, f64::max));
            let mean = stat(&|it| it.sum::<f64>() / ok.len() as f64);
            let x = ds.strain_x.clone();
            Figure::Line(LineChart {
                title: label,
                x_label: "X [m]".into(),
                y_label: format!("ξ − ξ* [{unit}]"),
                series: vec![
                    Series::new("max", x.clone(), max, SeriesStyle::Dashed)
                        .with_color(palette::POD),
                    Series::new("mean", x.clone(), mean, SeriesStyle::Line)
                        .with_color(palette::HOM),
                    Series::new("min", x, min, SeriesStyle::Dashed).with_color(palette::POD_ALT),
                ],
                log_y: false,
                equal_aspect: false,
            })
        })
        .collect();
    if panels.is_empty() {
        sink.note("strain_envelope: the dataset stores no strain component");
        return Ok(());
    }
    let cols = if panels.len() > 1 { 2 } else { 1 };
    let rows = panels.len().div_ceil(cols) as u32;
    let fig = Figure::Grid {
        title: format!("Strain envelope (min, mean, max) — {caption}"),
        cols,
        panels,
    };
    sink.figure(
        "strain_envelope",
        &fig,
        (700 * cols as u32, 60 + 450 * rows),
    )
}
