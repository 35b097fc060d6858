//! Animations: a sequence of figures (e.g. a rod's shape at successive times, on the same axes) as
//! the frames of one looping animated GIF, which every browser and image viewer plays without a
//! video codec. Frames are drawn like [`super::render`]'s PNG and reduced to a 256-colour palette
//! per frame by the GIF encoder.

use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, RgbaImage};

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
    let encode_error = |e: image::ImageError| PlotError::Encode {
        title: title.clone(),
        message: e.to_string(),
    };
    let mut gif = Vec::new();
    {
        // speed 30 of 1..=30: the fastest palette search, ample for flat plot colours
        let mut encoder = GifEncoder::new_with_speed(&mut gif, 30);
        encoder.set_repeat(Repeat::Infinite).map_err(encode_error)?;
        for fig in frames {
            let rgb = backend::render_rgb(fig, width, height)?;
            let rgba: Vec<u8> = rgb
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect();
            let img =
                RgbaImage::from_raw(width, height, rgba).ok_or_else(|| PlotError::Encode {
                    title: fig.title().to_string(),
                    message: "frame buffer of the wrong size".into(),
                })?;
            let frame =
                image::Frame::from_parts(img, 0, 0, Delay::from_numer_denom_ms(delay_ms, 1));
            encoder.encode_frame(frame).map_err(encode_error)?;
        }
    }
    Ok(gif)
}
