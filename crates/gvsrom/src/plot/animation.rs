//! Animations: a sequence of figures (e.g. a rod's shape at successive times, on the same axes) as
//! the frames of one looping animated GIF, which every browser and image viewer plays without a
//! video codec. Frames are drawn like [`super::render`]'s PNG, mapped to one colour table shared by
//! all frames (`gif_palette`), and each frame after the first stores only the rectangle
//! that changed, its unchanged pixels transparent over the previous frame (disposal "keep").

use std::borrow::Cow;

use super::gif_palette::{Quantizer, TRANSPARENT};
use super::{backend, theme, validate, Figure, PlotError};

/// Most frames an animation may have: a GIF of more frames grows large and slow to encode for
/// what a figure shows.
pub const MAX_FRAMES: usize = 200;

/// Renders `frames` at `width × height` pixels into an animated GIF that loops forever, showing each
/// frame for `delay_ms` milliseconds.
///
/// Every frame is checked as [`super::render`] checks a figure; no frames, more than
/// [`MAX_FRAMES`], or a size outside 64..=4096 pixels per side are errors naming the first frame.
pub fn render_gif(
    frames: &[Figure],
    width: u32,
    height: u32,
    delay_ms: u32,
) -> Result<Vec<u8>, PlotError> {
    let title = frames
        .first()
        .map_or("animation", |f| f.title())
        .to_string();
    if frames.is_empty() {
        return Err(PlotError::Empty { title });
    }
    if frames.len() > MAX_FRAMES {
        return Err(PlotError::InvalidGrid {
            title,
            reason: format!(
                "{} frames (an animation has at most {MAX_FRAMES})",
                frames.len()
            ),
        });
    }
    if !(64..=4096).contains(&width) || !(64..=4096).contains(&height) {
        return Err(PlotError::InvalidSize {
            title,
            width,
            height,
        });
    }
    frames.iter().try_for_each(validate::figure)?;
    theme::register_font();
    let encode_error = |e: gif::EncodingError| PlotError::Encode {
        title: title.clone(),
        message: e.to_string(),
    };
    let mut quantizer = Quantizer::for_frames(frames);
    let table = quantizer.table_rgb();
    // GIF delays are in centiseconds
    let delay = (delay_ms.div_ceil(10)).min(u16::MAX as u32) as u16;
    let mut gif = Vec::new();
    {
        let mut encoder = gif::Encoder::new(&mut gif, width as u16, height as u16, &table)
            .map_err(encode_error)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(encode_error)?;
        let mut shown: Option<Vec<u8>> = None;
        for fig in frames {
            let now = quantizer.indices(&backend::render_rgb(fig, width, height)?);
            let mut frame = match &shown {
                None => full_frame(&now, width, height),
                Some(before) => changed_frame(before, &now, width),
            };
            frame.delay = delay;
            frame.dispose = gif::DisposalMethod::Keep;
            encoder.write_frame(&frame).map_err(encode_error)?;
            shown = Some(now);
        }
    }
    Ok(gif)
}

/// The whole picture `now` (`width × height` indices) as a frame.
fn full_frame(now: &[u8], width: u32, height: u32) -> gif::Frame<'static> {
    gif::Frame {
        width: width as u16,
        height: height as u16,
        buffer: Cow::Owned(now.to_vec()),
        ..gif::Frame::default()
    }
}

/// The smallest rectangle holding every pixel where `now` differs from `before`, those pixels with
/// their index and the others [`TRANSPARENT`] (a single transparent pixel when nothing changed).
fn changed_frame(before: &[u8], now: &[u8], width: u32) -> gif::Frame<'static> {
    let w = width as usize;
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for (i, _) in before
        .iter()
        .zip(now)
        .enumerate()
        .filter(|(_, (a, b))| a != b)
    {
        let (x, y) = (i % w, i / w);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
    }
    let mut frame = gif::Frame {
        transparent: Some(TRANSPARENT),
        ..gif::Frame::default()
    };
    if x0 == usize::MAX {
        (frame.width, frame.height) = (1, 1);
        frame.buffer = Cow::Owned(vec![TRANSPARENT]);
        return frame;
    }
    let mut buffer = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        let row = y * w;
        buffer.extend((row + x0..=row + x1).map(|i| {
            if now[i] == before[i] {
                TRANSPARENT
            } else {
                now[i]
            }
        }));
    }
    (frame.left, frame.top) = (x0 as u16, y0 as u16);
    (frame.width, frame.height) = ((x1 - x0 + 1) as u16, (y1 - y0 + 1) as u16);
    frame.buffer = Cow::Owned(buffer);
    frame
}
