//! 3-D scatter plots ([`Scatter3`]) in the box of [`super::axes3`]: the points drawn from far to near
//! in their scalar's colour, and a colour bar on the right.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes3::{self, coord};
use super::color::{ColorScale, PLAIN};
use super::colorbar;
use super::layout::{self, OrPlotError};
use super::range;
use super::scatter::point_radius;
use super::theme::Theme;
use super::validate::plottable;
use super::{PlotError, Scatter3};

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
    let extent =
        |k: usize| range::extent(finite.iter().map(|&i| s.points[i][k])).ok_or_else(no_data);
    let r = axes3::ranges([extent(0)?, extent(1)?, extent(2)?], false);

    let scale = s.color.as_deref().and_then(ColorScale::from_values);
    let (main, bar) = match &scale {
        Some(sc) => {
            let w = colorbar::width(&area, sc, &s.color_label, theme, title)?;
            let (main, bar) = area.split_horizontally(area.dim_in_pixel().0.saturating_sub(w));
            (main, Some(bar))
        }
        None => (area.clone(), None),
    };
    let (mut chart, corners) = axes3::build(&main, &r, theme, title)?;

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
    let radius = point_radius(theme, finite.len());
    let color_of = |i: usize| match (&scale, &s.color) {
        (Some(sc), Some(c)) => sc.color(c[i]),
        _ => PLAIN,
    };
    chart
        .draw_series(
            order
                .iter()
                .map(|&(_, i)| Circle::new(coord(&s.points[i]), radius, color_of(i).filled())),
        )
        .or_plot(title)?;

    axes3::draw_axis_names(&mut chart, &s.labels, &r, theme, title)?;

    if let (Some(sc), Some(bar)) = (&scale, &bar) {
        // The bar spans the box's height on screen (corners are in backend pixels).
        let margin = theme.px(16.0);
        let y0 = bar.get_base_pixel().1;
        let top = corners.iter().map(|c| c.1 .1).min().unwrap_or(margin) - y0;
        let bottom = corners.iter().map(|c| c.1 .1).max().unwrap_or(margin) - y0;
        colorbar::draw(bar, sc, &s.color_label, (top, bottom), theme, title)?;
    }
    Ok(())
}
