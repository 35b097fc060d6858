//! 2-D scatter plots ([`Scatter2`]): a mesh like the line charts', one filled circle per finite point
//! coloured by its scalar, and a colour bar on the right.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::color::{ColorScale, PLAIN};
use super::colorbar;
use super::layout::{self, Frame, OrPlotError};
use super::range::{self, LinearFormat};
use super::theme::Theme;
use super::validate::usable;
use super::{PlotError, Scatter2};

/// Marker radius for `n` points: the theme's, one pixel less above 2000 points (dense clouds).
pub(crate) fn point_radius(theme: &Theme, n: usize) -> i32 {
    let r = theme.marker_radius();
    if n > 2000 {
        (r - 1).max(2)
    } else {
        r
    }
}

/// Draws `s` into `area`: title, axes over the finite points (5 % margins), the points, colour bar.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &Scatter2,
    theme: &Theme,
) -> Result<(), PlotError> {
    let title = s.title.as_str();
    let area = layout::titled(area, title, &theme.title_font(), theme)?;
    let finite = || s.x.iter().zip(&s.y).filter(|(&x, &y)| usable(x, y, false));
    let no_data = || PlotError::NoFiniteData {
        title: title.to_string(),
        log_y: false,
    };
    let xr = range::linear(
        range::extent(finite().map(|p| *p.0)).ok_or_else(no_data)?,
        0.05,
    );
    let yr = range::linear(
        range::extent(finite().map(|p| *p.1)).ok_or_else(no_data)?,
        0.05,
    );

    let scale = s.color.as_deref().and_then(ColorScale::from_values);
    let (main, bar) = match &scale {
        Some(sc) => {
            let w = colorbar::width(&area, sc, &s.color_label, theme, title)?;
            let (main, bar) = area.split_horizontally(area.dim_in_pixel().0.saturating_sub(w));
            (main, Some(bar))
        }
        None => (area.clone(), None),
    };

    let (has_x, has_y) = (!s.x_label.trim().is_empty(), !s.y_label.trim().is_empty());
    let dim = main.dim_in_pixel();
    let ny = layout::label_count(
        Frame::new(theme, 0, has_x, has_y).plot_size(dim).1,
        55.0,
        theme,
    );
    let yticks = range::linear_ticks(&yr, ny);
    let yfmt = LinearFormat::for_ticks(&yticks);
    let tick_w = layout::widest(
        &main,
        yticks.iter().map(|&v| yfmt.format(v)),
        &theme.tick_font(),
        title,
    )?;
    let mut frame = Frame::new(theme, tick_w, has_x, has_y);
    if bar.is_some() {
        frame.margin_right = theme.px(8.0);
    }
    let nx = layout::label_count(frame.plot_size(dim).0, 110.0, theme);
    let xfmt = LinearFormat::for_ticks(&range::linear_ticks(&xr, nx));
    let (fx, fy) = (
        move |v: &f64| xfmt.format(*v),
        move |v: &f64| yfmt.format(*v),
    );

    let mut chart = ChartBuilder::on(&main)
        .margin_top(frame.margin_top)
        .margin_right(frame.margin_right)
        .margin_left(frame.margin_left)
        .margin_bottom(frame.margin_bottom)
        .x_label_area_size(frame.x_label_area)
        .y_label_area_size(frame.y_label_area)
        .build_cartesian_2d(xr, yr)
        .or_plot(title)?;
    layout::draw_mesh(
        &mut chart,
        theme,
        (nx, ny),
        (&fx, &fy),
        (&s.x_label, &s.y_label),
    )
    .or_plot(title)?;

    let r = point_radius(theme, s.x.len());
    let color_of = |i: usize| match (&scale, &s.color) {
        (Some(sc), Some(c)) => sc.color(c[i]),
        _ => PLAIN,
    };
    let points =
        s.x.iter()
            .zip(&s.y)
            .enumerate()
            .filter(|(_, (&x, &y))| usable(x, y, false));
    chart
        .draw_series(points.map(|(i, (&x, &y))| Circle::new((x, y), r, color_of(i).filled())))
        .or_plot(title)?;

    if let (Some(sc), Some(bar)) = (&scale, &bar) {
        let top = frame.margin_top;
        let bottom = dim.1 as i32 - frame.margin_bottom - frame.x_label_area;
        colorbar::draw(bar, sc, &s.color_label, (top, bottom), theme, title)?;
    }
    Ok(())
}
