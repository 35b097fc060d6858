//! Legend placement: the corner of the plotting area (upper right first) where the legend box covers
//! the fewest drawn data, so the legend hides as little of the curves as it can.

use plotters::chart::{ChartContext, SeriesLabelPosition};
use plotters::coord::CoordTranslate;
use plotters::element::MultiLineText;
use plotters::prelude::DrawingBackend;
use plotters::style::TextStyle;

use super::PlotError;

/// Size and padding of the legend box, as given to plotters' `configure_series_labels`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LegendBox {
    /// Width reserved for each entry's line/marker glyph.
    pub glyph_area: i32,
    /// Padding inside the box.
    pub margin: i32,
    /// Distance of the box from the plotting area's edges.
    pub inset: i32,
}

/// Pixels along the drawn data: the points, and for connected runs samples every 4 px along each
/// segment; relative to the plotting area's top-left corner.
fn data_pixels<DB, CT>(
    chart: &ChartContext<'_, DB, CT>,
    runs: &[(&[(f64, f64)], bool)],
) -> Vec<(i32, i32)>
where
    DB: DrawingBackend,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let base = chart.plotting_area().get_base_pixel();
    let to_px = |p: &(f64, f64)| {
        let q = chart.as_coord_spec().translate(p);
        (q.0 - base.0, q.1 - base.1)
    };
    let mut out = Vec::new();
    for &(run, connected) in runs {
        let px: Vec<_> = run.iter().map(to_px).collect();
        out.extend_from_slice(&px);
        if connected {
            for w in px.windows(2) {
                let (a, b) = (w[0], w[1]);
                let len = ((b.0 - a.0) as f64).hypot((b.1 - a.1) as f64);
                let n = ((len / 4.0).ceil() as i32).min(2000);
                for k in 1..n {
                    let t = k as f64 / n as f64;
                    out.push((
                        a.0 + ((b.0 - a.0) as f64 * t) as i32,
                        a.1 + ((b.1 - a.1) as f64 * t) as i32,
                    ));
                }
            }
        }
    }
    out
}

/// The legend position for `labels` in `font`: of the four corners (upper right, upper left, lower
/// right, lower left — ties go to the earlier), the one whose box holds the fewest data pixels.
pub(crate) fn place<DB, CT>(
    chart: &ChartContext<'_, DB, CT>,
    labels: &[String],
    font: &TextStyle,
    lb: LegendBox,
    runs: &[(&[(f64, f64)], bool)],
    title: &str,
) -> Result<SeriesLabelPosition, PlotError>
where
    DB: DrawingBackend,
    CT: CoordTranslate<From = (f64, f64)>,
{
    let mut text = MultiLineText::<(i32, i32), &str>::new((0, 0), font);
    for l in labels {
        text.push_line(l.as_str());
    }
    let (tw, th) = text.estimate_dimension().map_err(|e| PlotError::Backend {
        title: title.to_string(),
        message: format!("legend text: {e:?}"),
    })?;
    let (w, h) = (tw + lb.glyph_area + 2 * lb.margin, th + 2 * lb.margin);
    let (pw, ph) = chart.plotting_area().dim_in_pixel();
    let (pw, ph) = (pw as i32, ph as i32);
    let corners = [
        (pw - w - lb.inset, lb.inset),
        (lb.inset, lb.inset),
        (pw - w - lb.inset, ph - h - lb.inset),
        (lb.inset, ph - h - lb.inset),
    ];
    let pixels = data_pixels(chart, runs);
    let covered = |&(x, y): &(i32, i32)| {
        let pad = 3;
        pixels
            .iter()
            .filter(|p| {
                p.0 >= x - pad && p.0 <= x + w + pad && p.1 >= y - pad && p.1 <= y + h + pad
            })
            .count()
    };
    let mut best = corners[0];
    let mut best_n = covered(&best);
    for c in &corners[1..] {
        let n = covered(c);
        if n < best_n {
            (best, best_n) = (*c, n);
        }
    }
    Ok(SeriesLabelPosition::Coordinate(best.0, best.1))
}
