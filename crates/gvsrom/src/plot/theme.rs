//! Look of every figure: the embedded DejaVu Sans font (registered once with plotters' ab_glyph text
//! renderer, so no system font is used), font sizes and stroke widths scaled with the panel size
//! (title 22 px, axis labels 18 px, tick labels and legend 15 px, lines 2 px at 900 × 600).

use std::sync::Once;

use plotters::style::{register_font as plotters_register_font, FontStyle, IntoFont, TextStyle};
use plotters::style::{Color, BLACK};

/// Font family of all text; also what the SVG's `font-family` attributes say.
pub(crate) const FAMILY: &str = "DejaVu Sans, sans-serif";

static REGISTER: Once = Once::new();

/// Registers DejaVu Sans (regular and bold) under [`FAMILY`] and under plotters' default `"sans-serif"`,
/// once per process. The font bytes are compiled in (`dejavu` crate) and always parse.
pub(crate) fn register_font() {
    REGISTER.call_once(|| {
        for name in [FAMILY, "sans-serif"] {
            // A static, valid TrueType file: registration cannot fail; a failure would show as missing
            // text (the render tests look for it), not as a panic here.
            let _ = plotters_register_font(name, FontStyle::Normal, dejavu::sans::regular());
            let _ = plotters_register_font(name, FontStyle::Bold, dejavu::sans::bold());
        }
    });
}

/// Sizes for one panel, scaled by `√(w·h / (900·600))` clamped to [0.85, 2.5].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Theme {
    pub scale: f64,
}

impl Theme {
    /// The theme of a panel of `width × height` pixels.
    pub fn for_size(width: u32, height: u32) -> Self {
        let ratio = (width as f64 * height as f64) / (900.0 * 600.0);
        Self {
            scale: ratio.sqrt().clamp(0.85, 2.5),
        }
    }

    /// `base` pixels (at 900 × 600) scaled to this panel, at least 1.
    pub fn px(&self, base: f64) -> i32 {
        (base * self.scale).round().max(1.0) as i32
    }

    /// Panel title: 22 px.
    pub fn title_font(&self) -> TextStyle<'static> {
        self.font(22.0)
    }

    /// Overall title of a grid: 24 px.
    pub fn grid_title_font(&self) -> TextStyle<'static> {
        self.font(24.0)
    }

    /// Axis descriptions ("X [m]"): 18 px.
    pub fn label_font(&self) -> TextStyle<'static> {
        self.font(18.0)
    }

    /// Tick labels: 15 px.
    pub fn tick_font(&self) -> TextStyle<'static> {
        self.font(15.0)
    }

    /// Legend entries: 15 px.
    pub fn legend_font(&self) -> TextStyle<'static> {
        self.font(15.0)
    }

    /// Line width: 2 px (3 px on large panels).
    pub fn line_width(&self) -> u32 {
        if self.scale >= 1.6 {
            3
        } else {
            2
        }
    }

    /// Marker radius: 3.5 px scaled, at least 3.
    pub fn marker_radius(&self) -> i32 {
        self.px(3.5).max(3)
    }

    /// Black text in [`FAMILY`] of `base` pixels scaled.
    /// The font of `style` at `size` pixels (its family and colour): a title shrunk to fit.
    pub fn resized(style: &TextStyle<'static>, size: f64) -> TextStyle<'static> {
        TextStyle {
            font: (FAMILY, size).into_font(),
            ..style.clone()
        }
    }

    fn font(&self, base: f64) -> TextStyle<'static> {
        (FAMILY, base * self.scale)
            .into_font()
            .color(&BLACK.mix(0.9))
    }
}
