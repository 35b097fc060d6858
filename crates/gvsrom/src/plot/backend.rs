//! The two backends: the figure drawn once into an SVG string and once into an RGB buffer that is
//! encoded as PNG; and the dispatch from a [`Figure`] to the drawing of its kind (grids recursively).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::layout::{self, OrPlotError};
use super::theme::Theme;
use super::{chart, line3, scatter, scatter3, Figure, PlotError};

/// Draws `fig` into `area`: white background, then the chart, or for a grid the overall title and
/// the panels in `cols` columns, row-major.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fig: &Figure,
) -> Result<(), PlotError> {
    let (w, h) = area.dim_in_pixel();
    let theme = Theme::for_size(w, h);
    area.fill(&WHITE).or_plot(fig.title())?;
    match fig {
        Figure::Line(c) => chart::draw(area, c, &theme),
        Figure::Scatter2(s) => scatter::draw(area, s, &theme),
        Figure::Scatter3(s) => scatter3::draw(area, s, &theme),
        Figure::Line3(c) => line3::draw(area, c, &theme),
        Figure::Grid {
            title,
            cols,
            panels,
        } => {
            let cols = (*cols).clamp(1, panels.len().max(1));
            let rows = panels.len().div_ceil(cols);
            // The overall title is sized for the whole figure, the panels for their own size.
            let inner = layout::titled(area, title, &theme.grid_title_font(), &theme)?;
            for (cell, panel) in inner.split_evenly((rows, cols)).iter().zip(panels) {
                draw(cell, panel)?;
            }
            Ok(())
        }
    }
}

/// `fig` as SVG text of `width × height` pixels.
pub(crate) fn render_svg(fig: &Figure, width: u32, height: u32) -> Result<String, PlotError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        draw(&root, fig)?;
        root.present().or_plot(fig.title())?;
    }
    Ok(svg)
}

/// `fig` as packed 8-bit RGB pixels, `width × height`, row-major.
pub(crate) fn render_rgb(fig: &Figure, width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    let mut rgb = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        draw(&root, fig)?;
        root.present().or_plot(fig.title())?;
    }
    Ok(rgb)
}

/// `fig` as PNG bytes of `width × height` pixels (8-bit RGB).
pub(crate) fn render_png(fig: &Figure, width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    let rgb = render_rgb(fig, width, height)?;
    encode_png(&rgb, width, height).map_err(|e| PlotError::Encode {
        title: fig.title().to_string(),
        message: e.to_string(),
    })
}

/// PNG encoding of a packed RGB buffer.
fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, image::ImageError> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png).write_image(
        rgb,
        width,
        height,
        image::ColorType::Rgb8,
    )?;
    Ok(png)
}
