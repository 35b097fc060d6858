//! Figures drawn in Rust (plotters) to SVG text and PNG bytes, with the DejaVu Sans font embedded in the
//! binary: line charts of strain profiles, rod configurations and error curves, scatter plots of latent
//! codes coloured by a scalar (2-D and 3-D), and grids of such panels. No system font and no file I/O:
//! [`render`] returns both images in memory and the caller writes or inlines them.
//!
//! Data are never trusted: non-finite values leave gaps, empty or mismatched data give a [`PlotError`]
//! naming the figure title and the series, and no input makes the renderer panic.

pub mod animation;
mod axes3;
mod backend;
mod chart;
mod color;
mod colorbar;
mod gif_palette;
mod layout;
mod legend;
mod line3;
pub mod palette;
mod range;
mod scatter;
mod scatter3;
mod theme;
mod validate;

pub(crate) use range::extent;

/// An sRGB colour, 8 bits per channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

/// How a series is drawn: a solid line, a dashed line, filled circle markers, or a line with markers;
/// or not at all (`Bounds`): its points only extend the axes, e.g. to keep the axes of every frame of
/// an animation the same. A `Bounds` series never shows in the legend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    Line,
    Dashed,
    Markers,
    LineMarkers,
    Bounds,
}

/// One data series of a chart: `(x[i], y[i])` pairs; a pair with a value that is NaN, infinite or
/// beyond ±1e300 (or, on a log axis, y < 1e-300) is left out and breaks the line there.
///
/// `color: None` takes the next colour of [`palette::EXTRA`] (by the series' index in the chart); an empty
/// `label` keeps the series out of the legend.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: SeriesStyle,
    pub color: Option<Rgb>,
}

impl Series {
    /// A series of the given style with the default colour.
    pub fn new(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, style: SeriesStyle) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            style,
            color: None,
        }
    }

    /// The same series drawn in `color`.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }
}

/// A 2-D chart: axes whose labels carry quantity and unit (e.g. "X \[m\]"), and a legend in the upper
/// right when any series has a non-empty label.
///
/// `log_y` puts y on a log₁₀ scale (points with y ≤ 0 are skipped); `equal_aspect` gives one unit the
/// same length on both axes (rod side views, x against z in metres) and is ignored with `log_y`.
#[derive(Clone, Debug, Default)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub log_y: bool,
    pub equal_aspect: bool,
}

/// Points `(x[i], y[i])`, each coloured by `color[i]` on a viridis scale shown by a colour bar titled
/// `color_label`; without `color` the points are dark grey and there is no colour bar.
#[derive(Clone, Debug, Default)]
pub struct Scatter2 {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub color: Option<Vec<f64>>,
    pub color_label: String,
}

/// Points in 3-D under a fixed oblique projection, coloured like [`Scatter2`]. `labels[2]` names the
/// vertical axis, `labels[0]` and `labels[1]` the two horizontal ones.
#[derive(Clone, Debug, Default)]
pub struct Scatter3 {
    pub title: String,
    pub labels: [String; 3],
    pub points: Vec<[f64; 3]>,
    pub color: Option<Vec<f64>>,
    pub color_label: String,
}

/// One polyline of a [`Line3`] chart: points `[x, y, z]` (a point with a coordinate that is not
/// plottable breaks the line there), drawn in `style` (markers and `Bounds` as in [`SeriesStyle`]);
/// `color: None` takes the next colour of [`palette::EXTRA`], an empty `label` keeps it out of the
/// legend.
#[derive(Clone, Debug)]
pub struct Series3 {
    pub label: String,
    pub points: Vec<[f64; 3]>,
    pub style: SeriesStyle,
    pub color: Option<Rgb>,
}

impl Series3 {
    /// A series of the given style with the default colour.
    pub fn new(label: impl Into<String>, points: Vec<[f64; 3]>, style: SeriesStyle) -> Self {
        Self {
            label: label.into(),
            points,
            style,
            color: None,
        }
    }

    /// The same series drawn in `color`.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }
}

/// Polylines in 3-D (rod centrelines, tip paths) in the box and projection of [`Scatter3`], with a
/// legend in the upper left when any series has a label. `labels[2]` names the vertical axis.
/// `equal_aspect` gives the three axes the same span, so a rod keeps its shape.
#[derive(Clone, Debug, Default)]
pub struct Line3 {
    pub title: String,
    pub labels: [String; 3],
    pub series: Vec<Series3>,
    pub equal_aspect: bool,
}

/// A figure: one chart, or several in a grid.
#[derive(Clone, Debug)]
pub enum Figure {
    Line(LineChart),
    Scatter2(Scatter2),
    Scatter3(Scatter3),
    Line3(Line3),
    /// Panels in a grid of `cols` columns, filled row-major, under an overall `title` (may be empty).
    Grid {
        title: String,
        cols: usize,
        panels: Vec<Figure>,
    },
}

impl Figure {
    /// The figure's title (a grid's overall title).
    pub fn title(&self) -> &str {
        match self {
            Figure::Line(c) => &c.title,
            Figure::Scatter2(s) => &s.title,
            Figure::Scatter3(s) => &s.title,
            Figure::Line3(c) => &c.title,
            Figure::Grid { title, .. } => title,
        }
    }
}

/// A rendered figure: SVG text and PNG bytes of the same picture, the same pixel size.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub svg: String,
    pub png: Vec<u8>,
}

/// Why a figure could not be drawn; every variant names the figure (its title) and, where one is at
/// fault, the series.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("figure \"{title}\": no data to plot (no series, or every series is empty)")]
    Empty { title: String },
    #[error("figure \"{title}\": no finite data to plot{}", if *.log_y { " (log y axis: only y > 0 is drawn)" } else { "" })]
    NoFiniteData { title: String, log_y: bool },
    #[error(
        "figure \"{title}\", series \"{series}\": {x_len} x values but {other_len} {other} values"
    )]
    LengthMismatch {
        title: String,
        series: String,
        x_len: usize,
        other_len: usize,
        other: &'static str,
    },
    #[error("figure \"{title}\": invalid grid: {reason}")]
    InvalidGrid { title: String, reason: String },
    #[error(
        "figure \"{title}\": invalid size {width}×{height} px (expected 64..=16384 on each side)"
    )]
    InvalidSize {
        title: String,
        width: u32,
        height: u32,
    },
    #[error("figure \"{title}\": drawing failed: {message}")]
    Backend { title: String, message: String },
    #[error("figure \"{title}\": PNG encoding failed: {message}")]
    Encode { title: String, message: String },
}

/// Renders `fig` at `width × height` pixels to SVG text and PNG bytes (the PNG at the same size).
///
/// The data are checked first ([`PlotError`] on empty, mismatched or non-finite-only data); the embedded
/// DejaVu Sans font is registered with plotters on the first call (once per process).
pub fn render(fig: &Figure, width: u32, height: u32) -> Result<Rendered, PlotError> {
    validate::figure(fig)?;
    if !(64..=16384).contains(&width) || !(64..=16384).contains(&height) {
        return Err(PlotError::InvalidSize {
            title: fig.title().to_string(),
            width,
            height,
        });
    }
    theme::register_font();
    let svg = backend::render_svg(fig, width, height)?;
    let png = backend::render_png(fig, width, height)?;
    Ok(Rendered { svg, png })
}
