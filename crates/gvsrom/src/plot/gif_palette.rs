//! The one colour table of an animation's frames (the GIF's global colour table): the colours the
//! frames are drawn in, read off the figures (series colours, viridis when a scatter is coloured),
//! each with its antialiasing blends over white, plus a grey ramp for text, mesh and axes. Every
//! pixel maps to its nearest entry without dithering, so flat areas stay flat and antialiased edges
//! take a few shades instead of hundreds, which keeps the LZW streams short.

use std::collections::HashMap;

use super::color::{self, series_color, MISSING, PLAIN};
use super::{Figure, Rgb};

/// Entries of the table; index [`TRANSPARENT`] is kept free for the unchanged pixels of a frame.
pub(crate) const TABLE_LEN: usize = 256;
/// The index that leaves the pixel of the previous frame showing.
pub(crate) const TRANSPARENT: u8 = 255;

/// Weights of a colour over white in its antialiasing blends, `c·a + white·(1 − a)`.
const BLENDS: [f64; 7] = [1.0, 0.82, 0.64, 0.48, 0.34, 0.22, 0.11];
/// Grey levels every 8 from black to 248, then white.
const GREY_STEP: usize = 8;
/// Samples of the viridis scale when a scatter is coloured by a scalar.
const VIRIDIS_SAMPLES: usize = 40;

/// Maps RGB pixels to the indices of a table of at most 255 colours.
pub(crate) struct Quantizer {
    table: Vec<[u8; 3]>,
    nearest: HashMap<[u8; 3], u8>,
}

impl Quantizer {
    /// The table for `frames`: greys, then each colour the frames draw in with its blends, then
    /// viridis samples; entries past 255 are dropped (their pixels take the nearest kept entry).
    pub fn for_frames(frames: &[Figure]) -> Self {
        let mut bases = Vec::new();
        let mut viridis = false;
        for fig in frames {
            collect(fig, &mut bases, &mut viridis);
        }
        let mut table: Vec<[u8; 3]> = (0..=255 / GREY_STEP)
            .map(|k| [(k * GREY_STEP) as u8; 3])
            .chain([[255; 3]])
            .collect();
        for Rgb(r, g, b) in bases {
            for a in BLENDS {
                let mix = |c: u8| (c as f64 * a + 255.0 * (1.0 - a)).round() as u8;
                table.push([mix(r), mix(g), mix(b)]);
            }
        }
        if viridis {
            table.extend((0..VIRIDIS_SAMPLES).map(|k| {
                let c = color::viridis(k as f64 / (VIRIDIS_SAMPLES - 1) as f64);
                [c.0, c.1, c.2]
            }));
        }
        let mut seen = std::collections::HashSet::new();
        table.retain(|c| seen.insert(*c));
        table.truncate(TRANSPARENT as usize);
        Self {
            table,
            nearest: HashMap::new(),
        }
    }

    /// The table as `TABLE_LEN` packed RGB triples (unused entries white).
    pub fn table_rgb(&self) -> Vec<u8> {
        let mut out: Vec<u8> = self.table.iter().flatten().copied().collect();
        out.resize(TABLE_LEN * 3, 255);
        out
    }

    /// The index of the entry nearest to `rgb` (squared distance in RGB).
    pub fn index(&mut self, rgb: [u8; 3]) -> u8 {
        let table = &self.table;
        *self.nearest.entry(rgb).or_insert_with(|| {
            let d2 = |c: &[u8; 3]| {
                (0..3)
                    .map(|k| (c[k] as i32 - rgb[k] as i32).pow(2))
                    .sum::<i32>()
            };
            (0..table.len()).min_by_key(|&i| d2(&table[i])).unwrap_or(0) as u8
        })
    }

    /// Indices of the packed RGB pixels `rgb`.
    pub fn indices(&mut self, rgb: &[u8]) -> Vec<u8> {
        rgb.chunks_exact(3)
            .map(|p| self.index([p[0], p[1], p[2]]))
            .collect()
    }
}

/// Adds the colours `fig` draws in to `bases` (each once) and sets `viridis` when it colours points
/// by a scalar.
fn collect(fig: &Figure, bases: &mut Vec<Rgb>, viridis: &mut bool) {
    let mut add = |c: plotters::style::RGBColor| {
        let c = Rgb(c.0, c.1, c.2);
        if !bases.contains(&c) {
            bases.push(c);
        }
    };
    match fig {
        Figure::Line(c) => {
            (c.series.iter().enumerate()).for_each(|(i, s)| add(series_color(i, s.color)))
        }
        Figure::Line3(c) => {
            (c.series.iter().enumerate()).for_each(|(i, s)| add(series_color(i, s.color)))
        }
        Figure::Scatter2(super::Scatter2 { color, .. })
        | Figure::Scatter3(super::Scatter3 { color, .. }) => {
            if color.is_some() {
                *viridis = true;
                add(MISSING);
            } else {
                add(PLAIN);
            }
        }
        Figure::Grid { panels, .. } => panels.iter().for_each(|p| collect(p, bases, viridis)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::{palette, LineChart, Series, SeriesStyle};

    #[test]
    fn table_holds_greys_series_colours_and_their_blends_over_white() {
        let fig = Figure::Line(LineChart {
            series: vec![
                Series::new("a", vec![0.0], vec![0.0], SeriesStyle::Line).with_color(palette::POD),
                Series::new("b", vec![0.0], vec![0.0], SeriesStyle::Line),
            ],
            ..Default::default()
        });
        let mut q = Quantizer::for_frames(&[fig]);
        let exact = |q: &mut Quantizer, c: [u8; 3]| {
            let i = q.index(c) as usize;
            q.table[i] == c
        };
        for c in [[0, 0, 0], [255, 255, 255], [128, 128, 128]] {
            assert!(exact(&mut q, c), "{c:?} not in the table");
        }
        // series 1 without a colour of its own takes EXTRA[1]
        for Rgb(r, g, b) in [palette::POD, palette::EXTRA[1]] {
            assert!(exact(&mut q, [r, g, b]));
        }
        // POD at half weight over white, (214, 39, 40)·0.48 + 255·0.52 = (235, 151, 152), is a blend
        assert!(exact(&mut q, [235, 151, 152]));
        assert!(q.table.len() < TRANSPARENT as usize);
    }
}
