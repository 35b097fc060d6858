//! The 3-D box shared by [`super::Scatter3`] and [`super::Line3`]: a fixed oblique projection (yaw
//! 0.6 rad, pitch 0.3 rad), three shaded back panels with grid lines and tick labels, and the axis
//! names beside the front edges. Data axis 0 is plotters' x, data axis 1 its depth axis z and data
//! axis 2 its vertical axis y, so the third coordinate points up.

use std::ops::Range;

use plotters::coord::cartesian::Cartesian3d;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::layout::OrPlotError;
use super::range::{self, LinearFormat};
use super::theme::Theme;
use super::PlotError;

/// A point in plotters' 3-D coordinates (x, y up, z depth) and its pixel on the backend.
pub(crate) type Projected = ((f64, f64, f64), (i32, i32));

/// A chart over a 3-D box.
pub(crate) type Chart3<'a, DB> =
    ChartContext<'a, DB, Cartesian3d<RangedCoordf64, RangedCoordf64, RangedCoordf64>>;

/// Plotters' coordinates of the data point `p`: (data 0, data 2 up, data 1 depth).
pub(crate) fn coord(p: &[f64; 3]) -> (f64, f64, f64) {
    (p[0], p[2], p[1])
}

/// The data ranges of a box: each axis over `extent` with 5 % margins; with `equal`, every axis
/// spans the largest of the three extents plus 10 % (about its centre), so one data unit has the
/// same length on all and a flat extent (a planar rod) is not blown up.
pub(crate) fn ranges(extent: [(f64, f64); 3], equal: bool) -> [Range<f64>; 3] {
    if equal {
        let half = 1.1 * extent.iter().map(|e| 0.5 * (e.1 - e.0)).fold(0.0, f64::max);
        if half > 1e-280 {
            return extent.map(|(lo, hi)| {
                let c = 0.5 * (lo + hi);
                (c - half)..(c + half)
            });
        }
    }
    extent.map(|e| range::linear(e, 0.05))
}

/// Builds the box over `r` (data axes 0, 1, 2) in `main`, draws its panels, grid and tick labels,
/// and returns the chart with the eight corners of the box projected.
pub(crate) fn build<'a, DB: DrawingBackend>(
    main: &'a DrawingArea<DB, Shift>,
    r: &[Range<f64>; 3],
    theme: &Theme,
    title: &str,
) -> Result<(Chart3<'a, DB>, Vec<Projected>), PlotError> {
    let [r0, r1, r2] = r.clone();
    let margin = theme.px(16.0);
    let mut chart = ChartBuilder::on(main)
        .margin(margin)
        .build_cartesian_3d(r0.clone(), r2.clone(), r1.clone())
        .or_plot(title)?;
    chart.with_projection(|mut pb| {
        pb.yaw = 0.6;
        pb.pitch = 0.3;
        pb.scale = 0.8;
        pb.into_matrix()
    });

    // The two horizontal axes meet at the lowest bottom corner, where their end labels would collide:
    // the depth axis leaves out its label within 15 % of its span of that corner.
    let corners: Vec<Projected> = [r0.start, r0.end]
        .iter()
        .flat_map(|&x| [r2.start, r2.end].map(move |y| (x, y)))
        .flat_map(|(x, y)| [r1.start, r1.end].map(move |z| (x, y, z)))
        .map(|q| (q, chart.as_coord_spec().translate(&q)))
        .collect();
    let front = corners
        .iter()
        .filter(|c| c.0 .1 == r2.start)
        .max_by_key(|c| c.1 .1)
        .map_or(r1.end, |c| c.0 .2);
    let span1 = r1.end - r1.start;
    let fmt = |r: &Range<f64>| LinearFormat::for_ticks(&range::linear_ticks(r, 5));
    let (f0, f1, f2) = (fmt(&r0), fmt(&r1), fmt(&r2));
    let fx = move |v: &f64| f0.format(*v);
    let fy = move |v: &f64| f2.format(*v);
    let fz = move |v: &f64| {
        if (v - front).abs() < 0.15 * span1 {
            String::new()
        } else {
            f1.format(*v)
        }
    };
    chart
        .configure_axes()
        .label_style(theme.tick_font())
        .x_formatter(&fx)
        .y_formatter(&fy)
        .z_formatter(&fz)
        .x_labels(5)
        .y_labels(5)
        .z_labels(5)
        .tick_size(theme.px(6.0))
        .axis_panel_style(BLACK.mix(0.035))
        .bold_grid_style(BLACK.mix(0.15))
        .light_grid_style(TRANSPARENT)
        .draw()
        .or_plot(title)?;
    Ok((chart, corners))
}

/// Writes each axis name of `labels` (data axes 0, 1, 2) outside the box, beyond the middle of its
/// front edge: for the two horizontal axes the edge lowest on screen, for the vertical axis the
/// leftmost edge.
pub(crate) fn draw_axis_names<DB: DrawingBackend>(
    chart: &mut Chart3<'_, DB>,
    labels: &[String; 3],
    [r0, r1, r2]: &[Range<f64>; 3],
    theme: &Theme,
    title: &str,
) -> Result<(), PlotError> {
    // Plotters coordinates: (x, y up, z depth) = (data 0, data 2, data 1).
    let lims = [[r0.start, r0.end], [r2.start, r2.end], [r1.start, r1.end]];
    let names = [&labels[0], &labels[2], &labels[1]];
    let mid = |k: usize| 0.5 * (lims[k][0] + lims[k][1]);
    let centre = chart.as_coord_spec().translate(&(mid(0), mid(1), mid(2)));
    let font = theme.label_font().pos(Pos::new(HPos::Center, VPos::Center));
    let size = font.font.get_size();
    for k in 0..3 {
        if names[k].trim().is_empty() {
            continue;
        }
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let mut best: Option<Projected> = None;
        for ia in 0..2 {
            for ib in 0..2 {
                let mut p = [0.0; 3];
                p[k] = mid(k);
                p[a] = lims[a][ia];
                p[b] = lims[b][ib];
                let q = (p[0], p[1], p[2]);
                let px = chart.as_coord_spec().translate(&q);
                let better = match best {
                    None => true,
                    Some((_, bp)) if k == 1 => px.0 < bp.0,
                    Some((_, bp)) => px.1 > bp.1,
                };
                if better {
                    best = Some((q, px));
                }
            }
        }
        let Some((q, px)) = best else { continue };
        let (dx, dy) = ((px.0 - centre.0) as f64, (px.1 - centre.1) as f64);
        let norm = (dx * dx + dy * dy).sqrt().max(1.0);
        let dist = if k == 1 { size * 3.6 } else { size * 2.6 };
        let off = (
            (dx / norm * dist).round() as i32,
            (dy / norm * dist).round() as i32,
        );
        let text = EmptyElement::at(q) + Text::new(names[k].clone(), off, font.clone());
        chart.plotting_area().draw(&text).or_plot(title)?;
    }
    Ok(())
}
