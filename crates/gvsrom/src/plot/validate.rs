//! Checks a figure's data before anything is drawn, so both images fail alike and the error names the
//! figure and the series: lengths agree, something is there, and some of it is finite.

use super::{Figure, Line3, LineChart, PlotError, Scatter2, Scatter3};

/// Largest magnitude drawn; beyond it (and for NaN, ±∞) a value counts as missing, which keeps
/// every span and pixel computation finite.
pub(crate) const LIMIT: f64 = 1e300;

/// Whether `v` can be drawn: finite and |v| ≤ [`LIMIT`].
pub(crate) fn plottable(v: f64) -> bool {
    v.abs() <= LIMIT
}

/// Whether the point `(x, y)` is drawn: both plottable and, on a log y axis, `y ≥ 1/LIMIT` (> 0).
pub(crate) fn usable(x: f64, y: f64, log_y: bool) -> bool {
    plottable(x) && plottable(y) && (!log_y || y >= 1.0 / LIMIT)
}

/// The name of series `index` in messages: its label, or `#n` (1-based) when the label is empty.
pub(crate) fn series_name(index: usize, label: &str) -> String {
    if label.trim().is_empty() {
        format!("#{}", index + 1)
    } else {
        label.to_string()
    }
}

/// Checks `fig` and, for a grid, every panel.
pub(crate) fn figure(fig: &Figure) -> Result<(), PlotError> {
    match fig {
        Figure::Line(c) => line(c),
        Figure::Scatter2(s) => scatter2(s),
        Figure::Scatter3(s) => scatter3(s),
        Figure::Line3(c) => line3(c),
        Figure::Grid {
            title,
            cols,
            panels,
        } => {
            let invalid = |reason: &str| PlotError::InvalidGrid {
                title: title.clone(),
                reason: reason.to_string(),
            };
            if *cols == 0 {
                return Err(invalid("0 columns"));
            }
            if panels.is_empty() {
                return Err(invalid("no panels"));
            }
            panels.iter().try_for_each(figure)
        }
    }
}

/// A line chart: every series has as many y as x values; some point is usable.
fn line(c: &LineChart) -> Result<(), PlotError> {
    for (i, s) in c.series.iter().enumerate() {
        if s.x.len() != s.y.len() {
            return Err(PlotError::LengthMismatch {
                title: c.title.clone(),
                series: series_name(i, &s.label),
                x_len: s.x.len(),
                other_len: s.y.len(),
                other: "y",
            });
        }
    }
    if c.series.iter().all(|s| s.x.is_empty()) {
        return Err(PlotError::Empty {
            title: c.title.clone(),
        });
    }
    let any = c
        .series
        .iter()
        .any(|s| s.x.iter().zip(&s.y).any(|(&x, &y)| usable(x, y, c.log_y)));
    if !any {
        return Err(PlotError::NoFiniteData {
            title: c.title.clone(),
            log_y: c.log_y,
        });
    }
    Ok(())
}

/// A 2-D scatter: x, y (and colour) of equal length; some point finite.
fn scatter2(s: &Scatter2) -> Result<(), PlotError> {
    let mismatch =
        |series: &str, other_len: usize, other: &'static str| PlotError::LengthMismatch {
            title: s.title.clone(),
            series: series.to_string(),
            x_len: s.x.len(),
            other_len,
            other,
        };
    if s.x.len() != s.y.len() {
        return Err(mismatch("points", s.y.len(), "y"));
    }
    if let Some(c) = &s.color {
        if c.len() != s.x.len() {
            return Err(mismatch(&series_name(0, &s.color_label), c.len(), "colour"));
        }
    }
    if s.x.is_empty() {
        return Err(PlotError::Empty {
            title: s.title.clone(),
        });
    }
    if !s.x.iter().zip(&s.y).any(|(&x, &y)| usable(x, y, false)) {
        return Err(PlotError::NoFiniteData {
            title: s.title.clone(),
            log_y: false,
        });
    }
    Ok(())
}

/// A 3-D scatter: colour of the points' length; some point finite in all three coordinates.
fn scatter3(s: &Scatter3) -> Result<(), PlotError> {
    if let Some(c) = &s.color {
        if c.len() != s.points.len() {
            return Err(PlotError::LengthMismatch {
                title: s.title.clone(),
                series: series_name(0, &s.color_label),
                x_len: s.points.len(),
                other_len: c.len(),
                other: "colour",
            });
        }
    }
    if s.points.is_empty() {
        return Err(PlotError::Empty {
            title: s.title.clone(),
        });
    }
    if !s.points.iter().any(|p| p.iter().all(|&v| plottable(v))) {
        return Err(PlotError::NoFiniteData {
            title: s.title.clone(),
            log_y: false,
        });
    }
    Ok(())
}

/// A 3-D line chart: some series has a point finite in all three coordinates.
fn line3(c: &Line3) -> Result<(), PlotError> {
    if c.series.iter().all(|s| s.points.is_empty()) {
        return Err(PlotError::Empty {
            title: c.title.clone(),
        });
    }
    let finite = |p: &[f64; 3]| p.iter().all(|&v| plottable(v));
    if !c.series.iter().any(|s| s.points.iter().any(finite)) {
        return Err(PlotError::NoFiniteData {
            title: c.title.clone(),
            log_y: false,
        });
    }
    Ok(())
}
