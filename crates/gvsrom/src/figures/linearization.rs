//! Figures of a `gvsrom linearize --json` result: the poles (`poles`: each pole's natural
//! frequency `|λ|/2π` on a log scale against its damping ratio `ζ = −Re λ/|λ|`, the unstable ones
//! apart), and the static gain (`static_gain`: per output point, the settled displacement along
//! world x, y and z per newton of each tendon, in mm/N, as markers: the tendons are categories;
//! with tendon lengths as outputs, a panel of their settled change per newton, the tendons'
//! compliance).

use super::{input_error, FiguresError, Sink};
use crate::plot::{palette, Figure, LineChart, Series, SeriesStyle};
use serde::Deserialize;
use std::path::Path;

/// One pole as `linearize --json` writes it.
#[derive(Debug, Clone, Deserialize)]
pub struct PoleDoc {
    pub natural_frequency_hz: f64,
    pub damping_ratio: f64,
}

/// The fields of a `linearize --json` document the figures use.
#[derive(Debug, Clone, Deserialize)]
pub struct LinearizationDoc {
    pub scenario: String,
    #[serde(default)]
    pub u: Vec<f64>,
    pub n_actuators: usize,
    pub poles: Vec<PoleDoc>,
    /// Poles with `Re λ > 0` (conjugates counted).
    #[serde(default)]
    pub unstable_poles: usize,
    /// `−C A⁻¹ B`, 3 rows per output point (absent about a state, or for a singular `A`).
    #[serde(default)]
    pub static_gain: Option<Vec<Vec<f64>>>,
    /// The output points' abscissae (a result written before they were recorded: the tip alone).
    #[serde(default)]
    pub outputs: Option<Vec<f64>>,
    /// With the tip's orientation as an output, its rotation: 3 gain rows after the points'.
    #[serde(default)]
    pub output_tip_rotation: Option<[[f64; 3]; 3]>,
    /// With tendon lengths as outputs, their values: one gain row per tendon, last.
    #[serde(default)]
    pub output_tendon_lengths: Vec<f64>,
    #[serde(default)]
    pub model: Option<String>,
    #[serde(skip)]
    pub origin: Option<crate::provenance::DirOrigin>,
}

impl LinearizationDoc {
    /// Reads and checks the document at `path`: poles to draw, a gain of 3 rows per output point
    /// and one column per tendon.
    pub fn load(path: &Path) -> Result<LinearizationDoc, FiguresError> {
        let (mut doc, origin): (LinearizationDoc, _) = super::read_json_result(path, "linearize")?;
        if doc.outputs.as_ref().is_some_and(Vec::is_empty) {
            return Err(input_error(path, "outputs is empty: no output point"));
        }
        if let Some(g) = &doc.static_gain {
            let points = doc.outputs.as_ref().map_or(1, Vec::len);
            let lengths = doc.output_tendon_lengths.len();
            let turns = doc.tip_rotation_rows();
            if g.len() != 3 * points + turns + lengths {
                return Err(input_error(
                    path,
                    format!(
                        "static_gain has {} rows; expected {} (3 per output point{}{})",
                        g.len(),
                        3 * points + turns + lengths,
                        match turns {
                            0 => "",
                            _ => ", 3 of the tip's orientation",
                        },
                        match lengths {
                            0 => String::new(),
                            m => format!(", and {m} tendon lengths"),
                        }
                    ),
                ));
            }
            if let Some((i, row)) = (g.iter().enumerate()).find(|(_, r)| r.len() != doc.n_actuators)
            {
                return Err(input_error(
                    path,
                    format!(
                        "static_gain row {i} has {} values; expected {} (one per tendon)",
                        row.len(),
                        doc.n_actuators
                    ),
                ));
            }
        }
        doc.origin = Some(origin);
        Ok(doc)
    }

    /// Rows of the tip's orientation in `C` and the gain: 3 if it is an output, else 0.
    fn tip_rotation_rows(&self) -> usize {
        if self.output_tip_rotation.is_some() {
            3
        } else {
            0
        }
    }

    /// The figure titles' description: scenario, tensions and model.
    fn caption(&self) -> String {
        super::run_caption(&self.scenario, &self.u, self.model.as_deref())
    }
}

/// `poles` and, about an equilibrium with tendons, `static_gain` of the result at `path`.
pub(crate) fn figures(path: &Path, sink: &mut Sink) -> Result<(), FiguresError> {
    let doc = LinearizationDoc::load(path)?;
    sink.origin = doc.origin.clone();
    let caption = doc.caption();
    poles(path, &doc, &caption, sink)?;
    match &doc.static_gain {
        _ if doc.n_actuators == 0 => sink.note("static_gain: the rod has no tendons"),
        Some(g) => static_gain(&doc, g, &caption, sink)?,
        None => {
            sink.note("static_gain: none in the result (linearized about a state, or A singular)")
        }
    }
    Ok(())
}

/// `poles`: frequency against damping ratio; poles at 0 Hz (a free rigid motion) cannot sit on
/// the log scale and are counted in a note.
fn poles(
    path: &Path,
    doc: &LinearizationDoc,
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let at_zero = doc
        .poles
        .iter()
        .filter(|p| p.natural_frequency_hz <= 0.0)
        .count();
    if at_zero > 0 {
        sink.note(format!(
            "poles: {at_zero} at 0 Hz left out of the log scale"
        ));
    }
    let series = |label: &str, unstable: bool| {
        let (x, y): (Vec<f64>, Vec<f64>) = (doc.poles.iter())
            .filter(|p| p.natural_frequency_hz > 0.0 && is_unstable(p) == unstable)
            .map(|p| (p.damping_ratio, p.natural_frequency_hz))
            .unzip();
        (!x.is_empty()).then(|| Series::new(label, x, y, SeriesStyle::Markers))
    };
    let mut series: Vec<Series> = [
        series("stable", false).map(|s| s.with_color(palette::POD_ALT)),
        series("unstable (Re λ > 0)", true).map(|s| s.with_color(palette::POD)),
    ]
    .into_iter()
    .flatten()
    .collect();
    // ζ from 0 (undamped) to 1 (critical) on the scale whatever the poles
    if let Some(&f) = series.first().and_then(|s| s.y.first()) {
        series.push(Series::new(
            "",
            vec![0.0, 1.0],
            vec![f, f],
            SeriesStyle::Bounds,
        ));
    }
    if series.is_empty() {
        return Err(input_error(
            path,
            "the result holds no pole with a frequency above 0 Hz to plot",
        ));
    }
    let chart = Figure::Line(LineChart {
        title: format!("Poles of the linearization — {caption}"),
        x_label: "damping ratio ζ = −Re λ / |λ|".into(),
        y_label: "natural frequency |λ|/2π [Hz]".into(),
        series,
        log_y: true,
        equal_aspect: false,
    });
    sink.figure("poles", &chart, (1000, 700))
}

/// Unstable as `linearize` counts it: `Re λ > UNSTABLE_RATIO |λ|` (an undamped rod's poles lie on
/// the imaginary axis up to rounding, ζ ≈ ±1e-15, and are stable).
fn is_unstable(p: &PoleDoc) -> bool {
    p.damping_ratio < -crate::linearize::UNSTABLE_RATIO
}

/// Most output points whose gain `static_gain` draws, one panel each.
const MAX_GAIN_POINTS: usize = 12;

/// `static_gain`: one panel per output point (at most [`MAX_GAIN_POINTS`], spread over them), the
/// x, y and z rows against the tendon number, then one of the tip's rotation and one of the tendon
/// lengths' rows if they are outputs.
fn static_gain(
    doc: &LinearizationDoc,
    g: &[Vec<f64>],
    caption: &str,
    sink: &mut Sink,
) -> Result<(), FiguresError> {
    let points = doc.outputs.clone();
    let (turns, lengths) = (doc.tip_rotation_rows(), doc.output_tendon_lengths.len());
    let n_points = (g.len() - turns - lengths) / 3;
    let world = |prefix: &str| -> Vec<String> {
        ["x", "y", "z"]
            .map(|a| format!("{prefix}world {a}"))
            .to_vec()
    };
    // of many output points, a spread of them (41 points drew a figure 16 700 px high, refused)
    let drawn: Vec<usize> = match n_points <= MAX_GAIN_POINTS {
        true => (0..n_points).collect(),
        false => {
            let last = (n_points - 1) as f64;
            let step = last / (MAX_GAIN_POINTS - 1) as f64;
            let mut picks: Vec<usize> = (0..MAX_GAIN_POINTS)
                .map(|i| (i as f64 * step).round() as usize)
                .collect();
            picks.dedup();
            sink.note(format!(
                "static_gain: {} of the {n_points} output points drawn, evenly spread from the first to the last (the JSON holds every row)",
                picks.len()
            ));
            picks
        }
    };
    let mut panels: Vec<Figure> = (drawn.iter().copied())
        .map(|o| {
            let at = match &points {
                Some(xs) => format!("X = {} m", gvs::error::fmt_rounded(xs[o])),
                None => "the tip".to_string(),
            };
            let title = format!("settled displacement of {at}");
            gain_panel(doc, title, "mm/N", &g[3 * o..3 * o + 3], world(""))
        })
        .collect();
    if turns > 0 {
        let rows = &g[3 * n_points..3 * n_points + 3];
        let title = "settled rotation of the tip".to_string();
        panels.push(gain_panel(doc, title, "mrad/N", rows, world("about ")));
    }
    if lengths > 0 {
        let names = (0..lengths).map(|j| format!("length {j}")).collect();
        let title = "settled change of the tendon lengths (the tendons' compliance)".to_string();
        panels.push(gain_panel(
            doc,
            title,
            "mm/N",
            &g[g.len() - lengths..],
            names,
        ));
    }
    let n = panels.len();
    let unstable = match doc.unstable_poles {
        0 => "",
        _ => " (an unstable equilibrium: no motion settles there)",
    };
    let grid = Figure::Grid {
        title: format!("Static gain −C A⁻¹ B{unstable} — {caption}"),
        cols: 1,
        panels,
    };
    sink.figure("static_gain", &grid, (1000, 300 + 400 * n as u32))
}

/// One panel of the gain: each of `rows` (×1000, in `unit`) as markers against the tendon number,
/// named by `names`, with half a tendon of margin on either side and 0 on the scale.
fn gain_panel(
    doc: &LinearizationDoc,
    title: String,
    unit: &str,
    rows: &[Vec<f64>],
    names: Vec<String>,
) -> Figure {
    // numbered from 0, as the scenario's `tendons[k]` and every other figure and message
    let tendons: Vec<f64> = (0..doc.n_actuators).map(|k| k as f64).collect();
    let margin = Series::new(
        "",
        vec![-0.5, doc.n_actuators as f64 - 0.5],
        vec![0.0, 0.0],
        SeriesStyle::Bounds,
    );
    let series = (rows.iter().zip(names).enumerate())
        .map(|(j, (row, name))| {
            Series::new(
                name,
                tendons.clone(),
                row.iter().map(|v| v * 1e3).collect(),
                SeriesStyle::Markers,
            )
            .with_color(palette::EXTRA[j % palette::EXTRA.len()])
        })
        .chain(std::iter::once(margin))
        .collect();
    Figure::Line(LineChart {
        title,
        x_label: "tendon".into(),
        y_label: format!("per newton of tension [{unit}]"),
        series,
        log_y: false,
        equal_aspect: false,
    })
}
