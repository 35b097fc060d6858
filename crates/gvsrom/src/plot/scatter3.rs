//! 3-D scatter plots ([`Scatter3`]) under a fixed oblique projection (yaw 0.6 rad, pitch 0.3 rad):
//! three shaded back panels with grid lines and tick labels, the points drawn from far to near in
//! their scalar's colour, the axis names beside the front edges, and a colour bar on the right.

use std::ops::Range;

use plotters::coord::cartesian::Cartesian3d;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::color::{ColorScale, PLAIN};
use super::colorbar;
use super::layout::{self, OrPlotError};
use super::range::{self, LinearFormat};
use super::scatter::point_radius;
use super::theme::Theme;
use super::validate::plottable;
use super::{PlotError, Scatter3};

/// A point in plotters' 3-D coordinates (x, y up, z depth) and its pixel on the backend.
type Projected = ((f64, f64, f64), (i32, i32));

/// Draws `s` into `area`. Data axis `labels[0]` is plotters' x, `labels[1]` its depth axis z and
/// `labels[2]` its vertical axis y, so the third coordinate points up.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &Scatter3,
    theme: &Theme,
) -> Result<(), PlotError> {
    let title = s.title.as_str();
    let area = layout::titled(area, title, &theme.title_font(), theme)?;
    let finite: Vec<usize> = (0..s.points.len())
        .filter(|&i| s.points[i].iter().all(|&v| plottable(v)))
        .collect();
    let no_data = || PlotError::NoFiniteData {
        title: title.to_string(),
        log_y: false,
    };
    let axis = |k: usize| -> Result<Range<f64>, PlotError> {
        Ok(range::linear(
            range::extent(finite.iter().map(|&i| s.points[i][k])).ok_or_else(no_data)?,
            0.05,
        ))
    };
    let (r0, r1, r2) = (axis(0)?, axis(1)?, axis(2)?);

    let scale = s.color.as_deref().and_then(ColorScale::from_values);
    let (main, bar) = match &scale {
        Some(sc) => {
            let w = colorbar::width(&area, sc, &s.color_label, theme, title)?;
            let (main, bar) = area.split_horizontally(area.dim_in_pixel().0.saturating_sub(w));
            (main, Some(bar))
        }
        None => (area.clone(), None),
    };

    let margin = theme.px(16.0);
    let mut chart = ChartBuilder::on(&main)
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

    // Far points first, so near ones cover them.
    let mut order: Vec<(i32, usize)> = finite
        .iter()
        .map(|&i| {
            let p = s.points[i];
            (
                chart.as_coord_spec().projected_depth(&p[0], &p[2], &p[1]),
                i,
            )
        })
        .collect();
    order.sort_by_key(|a| std::cmp::Reverse(a.0));
    let r = point_radius(theme, finite.len());
    let color_of = |i: usize| match (&scale, &s.color) {
        (Some(sc), Some(c)) => sc.color(c[i]),
        _ => PLAIN,
    };
    chart
        .draw_series(order.iter().map(|&(_, i)| {
            let p = s.points[i];
            Circle::new((p[0], p[2], p[1]), r, color_of(i).filled())
        }))
        .or_plot(title)?;

    draw_axis_names(&mut chart, s, (&r0, &r1, &r2), theme)?;

    if let (Some(sc), Some(bar)) = (&scale, &bar) {
        // The bar spans the box's height on screen (corners are in backend pixels).
        let y0 = bar.get_base_pixel().1;
        let top = corners.iter().map(|c| c.1 .1).min().unwrap_or(margin) - y0;
        let bottom = corners.iter().map(|c| c.1 .1).max().unwrap_or(margin) - y0;
        colorbar::draw(bar, sc, &s.color_label, (top, bottom), theme, title)?;
    }
    Ok(())
}

/// Writes each axis name outside the box, beyond the middle of its front edge: for the two
/// horizontal axes the edge lowest on screen, for the vertical axis the leftmost edge.
fn draw_axis_names<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian3d<RangedCoordf64, RangedCoordf64, RangedCoordf64>>,
    s: &Scatter3,
    (r0, r1, r2): (&Range<f64>, &Range<f64>, &Range<f64>),
    theme: &Theme,
) -> Result<(), PlotError> {
    let title = s.title.as_str();
    // Plotters coordinates: (x, y up, z depth) = (data 0, data 2, data 1).
    let lims = [[r0.start, r0.end], [r2.start, r2.end], [r1.start, r1.end]];
    let names = [&s.labels[0], &s.labels[2], &s.labels[1]];
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
