//! Figures of a `gvsrom modes --json` result: the mode shapes (`mode_shapes`: for each mode, the
//! equilibrium's centreline and the centreline displaced by ± the mode, scaled so that its largest
//! displacement is a tenth of the rod's length, in side views x–z and x–y, the one across which
//! nothing moves left out) and the spectrum
//! (`frequencies`: every mode's natural frequency on a log scale, the described ones marked).

use super::{input_error, FiguresError, Sink};
use crate::plot::{palette, Figure, LineChart, Series, SeriesStyle};
use serde::Deserialize;
use std::path::Path;

/// One mode as `modes --json` writes it.
#[derive(Debug, Clone, Deserialize)]
pub struct ModeDoc {
    pub mode: usize,
    pub frequency_hz: f64,
    pub omega_squared: f64,
    pub dominant_strain: String,
    /// The centreline's displacement per unit modal coordinate (results written before it was
    /// recorded have none).
    #[serde(default)]
    pub centerline_shape: Vec<[f64; 3]>,
}

/// The fields of a `modes --json` document the figures use.
#[derive(Debug, Clone, Deserialize)]
pub struct ModesDoc {
    pub scenario: String,
    #[serde(default)]
    pub u: Vec<f64>,
    pub all_frequencies_hz: Vec<f64>,
    #[serde(default)]
    pub centerline_x: Vec<f64>,
    #[serde(default)]
    pub centerline: Vec<[f64; 3]>,
    pub modes: Vec<ModeDoc>,
    #[serde(default)]
    pub model: Option<String>,
    #[serde(skip)]
    pub origin: Option<crate::provenance::DirOrigin>,
}

/// Modes drawn in `mode_shapes` at most (the lowest).
pub const MAX_SHAPES: usize = 6;

impl ModesDoc {
    /// Reads and checks the document at `path`: each mode's shape has a value per centreline
    /// sample.
    pub fn load(path: &Path) -> Result<ModesDoc, FiguresError> {
        let (mut doc, origin): (ModesDoc, _) = super::read_json_result(path, "modes")?;
        let c = doc.centerline.len();
        if doc.centerline_x.len() != c {
            return Err(input_error(
                path,
                format!(
                    "centerline: {} abscissae but {c} positions",
                    doc.centerline_x.len()
                ),
            ));
        }
        for m in &doc.modes {
            if !m.centerline_shape.is_empty() && m.centerline_shape.len() != c {
                return Err(input_error(
                    path,
                    format!(
                        "mode {}: centerline_shape has {} values for {c} centreline samples",
                        m.mode,
                        m.centerline_shape.len()
                    ),
                ));
            }
        }
        doc.origin = Some(origin);
        Ok(doc)
    }

    /// The figure titles' description: scenario, tensions and model.
    fn caption(&self) -> String {
        super::run_caption(&self.scenario, &self.u, self.model.as_deref())
    }
}

/// `frequencies` and, when the result holds the shapes, `mode_shapes`.
pub(crate) fn figures(path: &Path, sink: &mut Sink) -> Result<(), FiguresError> {
    let doc = ModesDoc::load(path)?;
    sink.origin = doc.origin.clone();
    let caption = doc.caption();
    frequencies(path, &doc, &caption, sink)?;
    if doc.centerline.len() < 2 {
        sink.note(match doc.centerline.is_empty() {
            true => "mode_shapes: the result holds no centreline (written by an earlier gvsrom)",
            false => "mode_shapes: the centreline has one sample (at least 2 are needed)",
        });
        return Ok(());
    }
    if doc.modes.iter().all(|m| m.centerline_shape.is_empty()) {
        sink.note(
            "mode_shapes: the result holds no centreline shapes (written by an earlier gvsrom)",
        );
        return Ok(());
    }
    mode_shapes(&doc, &caption, sink)
}

/// `frequencies`: every mode's frequency against its number, log scale; modes at 0 Hz (unstable
/// or free directions) are counted in a note.
fn frequencies(
    path: &Path,
    doc: &ModesDoc,
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let zero = doc.all_frequencies_hz.iter().filter(|f| **f <= 0.0).count();
    if zero > 0 {
        sink.note(format!(
            "frequencies: {zero} mode(s) at 0 Hz (ω² ≤ 0) left out of the log scale"
        ));
    }
    let (x, y): (Vec<f64>, Vec<f64>) = (doc.all_frequencies_hz.iter().enumerate())
        .filter(|(_, f)| **f > 0.0)
        .map(|(k, f)| ((k + 1) as f64, *f))
        .unzip();
    if x.is_empty() {
        return Err(input_error(
            path,
            "the result holds no mode above 0 Hz to plot",
        ));
    }
    let described: (Vec<f64>, Vec<f64>) = (doc.modes.iter())
        .filter(|m| m.frequency_hz > 0.0)
        .map(|m| (m.mode as f64, m.frequency_hz))
        .unzip();
    let chart = Figure::Line(LineChart {
        title: format!("Natural frequencies — {caption}"),
        x_label: "mode".into(),
        y_label: "natural frequency [Hz]".into(),
        series: vec![
            Series::new("all modes", x, y, SeriesStyle::Markers).with_color(palette::POD_ALT),
            Series::new("described", described.0, described.1, SeriesStyle::Markers)
                .with_color(palette::POD),
        ],
        log_y: true,
        equal_aspect: false,
    });
    sink.figure("frequencies", &chart, (1000, 650))
}

/// `mode_shapes`: one row per mode (the lowest [`MAX_SHAPES`]), side views x–z and x–y.
fn mode_shapes(doc: &ModesDoc, caption: &str, sink: &mut Sink) -> Result<(), FiguresError> {
    let length = doc.centerline_x.last().copied().unwrap_or(1.0);
    let axis = |p: &[f64; 3], a: usize| p[a];
    let mut panels = vec![];
    let shown: Vec<&ModeDoc> = (doc.modes.iter())
        .filter(|m| !m.centerline_shape.is_empty())
        .take(MAX_SHAPES)
        .collect();
    // a view across which nothing moves (y of a planar rod) is left out
    // (the centreline within 1e-9 L of the plane, every shape within 1e-9 of the largest
    // displacement: mass-normalized shapes have no length scale of their own)
    let largest = (shown.iter().flat_map(|m| m.centerline_shape.iter()))
        .flat_map(|d| d.iter())
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    let flat = |a: usize| {
        doc.centerline.iter().all(|p| p[a].abs() <= 1e-9 * length)
            && (shown.iter())
                .all(|m| (m.centerline_shape.iter()).all(|d| d[a].abs() <= 1e-9 * largest))
    };
    let views: Vec<(usize, usize, &str)> = [(0, 2, "x–z"), (0, 1, "x–y")]
        .into_iter()
        .filter(|v| !flat(v.1))
        .collect();
    let views = if views.is_empty() {
        vec![(0, 2, "x–z")]
    } else {
        views
    };
    for m in &shown {
        let peak = (m.centerline_shape.iter())
            .map(|d| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt())
            .fold(0.0, f64::max);
        let scale = if peak > 0.0 { 0.1 * length / peak } else { 0.0 };
        if peak == 0.0 {
            sink.note(format!(
                "mode_shapes: mode {} moves no centreline sample (drawn at rest)",
                m.mode
            ));
        }
        let displaced = |sign: f64| -> Vec<[f64; 3]> {
            (doc.centerline.iter().zip(&m.centerline_shape))
                .map(|(p, d)| [0, 1, 2].map(|a| p[a] + sign * scale * d[a]))
                .collect()
        };
        let (plus, minus) = (displaced(1.0), displaced(-1.0));
        let state = match m.omega_squared < 0.0 {
            true => "unstable (ω² < 0)".to_string(),
            false if m.frequency_hz < 1e4 => format!("{:.3} Hz", m.frequency_hz),
            false => format!("{:.3e} Hz", m.frequency_hz),
        };
        for &(h, v, name) in &views {
            let line = |pts: &[[f64; 3]], label: &str, style, color| {
                Series::new(
                    label,
                    pts.iter().map(|p| axis(p, h)).collect(),
                    pts.iter().map(|p| axis(p, v)).collect(),
                    style,
                )
                .with_color(color)
            };
            panels.push(Figure::Line(LineChart {
                title: format!("mode {}: {state}, {} ({name})", m.mode, m.dominant_strain),
                x_label: "x [m]".into(),
                y_label: format!("{} [m]", ["x", "y", "z"][v]),
                series: vec![
                    line(
                        &doc.centerline,
                        "equilibrium",
                        SeriesStyle::Dashed,
                        palette::EXTRA[7],
                    ),
                    line(&plus, "+ mode", SeriesStyle::Line, palette::POD_ALT),
                    line(&minus, "− mode", SeriesStyle::Line, palette::POD),
                ],
                log_y: false,
                equal_aspect: true,
            }));
        }
    }
    let rows = shown.len() as u32;
    let grid = Figure::Grid {
        title: format!("Mode shapes ± 0.1 L — {caption}"),
        cols: views.len(),
        panels,
    };
    let width = (200 + 500 * views.len() as u32).max(1000);
    sink.figure("mode_shapes", &grid, (width, 120 + 380 * rows))
}
