//! Layout helpers shared by the chart kinds: the title strip above a panel, the sizes of the tick-label
//! areas around a 2-D plotting area, and the conversion of plotters' errors into [`PlotError`].

use plotters::chart::ChartContext;
use plotters::coord::cartesian::Cartesian2d;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::drawing::{DrawingArea, DrawingAreaErrorKind};
use plotters::prelude::DrawingBackend;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::TextStyle;
use plotters::style::{Color, BLACK};

use super::theme::Theme;
use super::PlotError;

/// Converts a plotters drawing error into [`PlotError::Backend`] naming the figure.
pub(crate) trait OrPlotError<T> {
    fn or_plot(self, title: &str) -> Result<T, PlotError>;
}

impl<T, E: std::error::Error + Send + Sync> OrPlotError<T> for Result<T, DrawingAreaErrorKind<E>> {
    fn or_plot(self, title: &str) -> Result<T, PlotError> {
        self.map_err(|e| PlotError::Backend {
            title: title.to_string(),
            message: e.to_string(),
        })
    }
}

/// Draws `title` centred in a strip at the top of `area` (1.7 × the font size high) and returns the
/// rest of the area; an empty title takes no space. A title wider than 96 % of the area is drawn
/// in a font shrunk to fit it (a long caption on a narrow, tall grid ran off both edges).
pub(crate) fn titled<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    font: &TextStyle<'static>,
    theme: &Theme,
) -> Result<DrawingArea<DB, Shift>, PlotError> {
    if title.trim().is_empty() {
        return Ok(area.clone());
    }
    let (w, _) = area.dim_in_pixel();
    let wide = area.estimate_text_size(title, font).or_plot(title)?.0 as f64;
    let room = 0.96 * w as f64;
    let shrunk;
    let font = match wide > room {
        true => {
            shrunk = Theme::resized(font, font.font.get_size() * room / wide);
            &shrunk
        }
        false => font,
    };
    let strip = (font.font.get_size() * 1.7).round() as i32 + theme.px(4.0);
    let (top, rest) = area.split_vertically(strip);
    let centred = font.clone().pos(Pos::new(HPos::Center, VPos::Center));
    top.draw_text(title, &centred, (w as i32 / 2, strip / 2 + theme.px(2.0)))
        .or_plot(title)?;
    Ok(rest)
}

/// Width in pixels of the widest of `texts` in `font` (0 when there are none).
pub(crate) fn widest<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    texts: impl IntoIterator<Item = String>,
    font: &TextStyle,
    title: &str,
) -> Result<u32, PlotError> {
    let mut w = 0;
    for t in texts {
        w = w.max(area.estimate_text_size(&t, font).or_plot(title)?.0);
    }
    Ok(w)
}

/// Margins and label-area sizes around a 2-D plotting area, in pixels.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub margin_top: i32,
    pub margin_right: i32,
    pub margin_left: i32,
    pub margin_bottom: i32,
    /// Height of the x tick labels plus the x axis description.
    pub x_label_area: i32,
    /// Width of the y tick labels plus the y axis description.
    pub y_label_area: i32,
}

impl Frame {
    /// The frame for y tick labels at most `y_tick_width` pixels wide; `has_x_desc`/`has_y_desc` say
    /// whether the axis descriptions take room.
    pub fn new(theme: &Theme, y_tick_width: u32, has_x_desc: bool, has_y_desc: bool) -> Self {
        let tick = theme.tick_font().font.get_size();
        let desc = theme.label_font().font.get_size();
        let x_label_area =
            tick * 1.0 + 14.0 * theme.scale + if has_x_desc { desc * 1.25 } else { 0.0 };
        let y_label_area =
            y_tick_width as f64 + 16.0 * theme.scale + if has_y_desc { desc * 1.4 } else { 0.0 };
        Self {
            margin_top: theme.px(8.0),
            margin_right: theme.px(24.0),
            margin_left: theme.px(8.0),
            margin_bottom: theme.px(6.0),
            x_label_area: x_label_area.round() as i32,
            y_label_area: y_label_area.round() as i32,
        }
    }

    /// Pixel size of the plotting area inside an area of `dim` pixels.
    pub fn plot_size(&self, dim: (u32, u32)) -> (u32, u32) {
        let w = dim.0 as i32 - self.margin_left - self.margin_right - self.y_label_area;
        let h = dim.1 as i32 - self.margin_top - self.margin_bottom - self.x_label_area;
        (w.max(1) as u32, h.max(1) as u32)
    }
}

/// Number of tick labels for an axis `len` pixels long, one per `spacing` base pixels, 2 to 10.
pub(crate) fn label_count(len: u32, spacing: f64, theme: &Theme) -> usize {
    ((len as f64 / (spacing * theme.scale)).floor() as usize).clamp(2, 10)
}

/// A tick-label formatter.
pub(crate) type TickFormat<'a> = &'a dyn Fn(&f64) -> String;

/// Draws the light mesh, the axes, the tick labels (`n` = at most (x, y) labels, formatted by `fmt`)
/// and the axis descriptions `desc` (left out when empty) of a 2-D chart.
pub(crate) fn draw_mesh<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    theme: &Theme,
    n: (usize, usize),
    fmt: (TickFormat<'_>, TickFormat<'_>),
    desc: (&str, &str),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(n.0)
        .y_labels(n.1)
        .x_label_formatter(fmt.0)
        .y_label_formatter(fmt.1)
        .label_style(theme.tick_font())
        .axis_desc_style(theme.label_font())
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04))
        .x_max_light_lines(4)
        .y_max_light_lines(4)
        .axis_style(BLACK.mix(0.75));
    if !desc.0.trim().is_empty() {
        mesh.x_desc(desc.0);
    }
    if !desc.1.trim().is_empty() {
        mesh.y_desc(desc.1);
    }
    mesh.draw()
}
