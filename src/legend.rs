//! The colour legend drawn into 8-bit frames (`--legend`): a horizontal
//! colour bar of the transfer function's colours over the scalar range,
//! the field's name above it, the two ends of the range below it, and
//! (for animations) the time value in the top-left corner.
//!
//! How it is drawn: the bar is sampled from [`TransferFunction::color_at`]
//! once per pixel column and written with the PNG's own encoding (linear
//! values times 255, no sRGB curve); text is laid out with `ab_glyph`
//! (glyph advances and kerning of the font) and each glyph's coverage is
//! blended over the pixels. The font is Hack Regular (MIT and Bitstream
//! Vera licences) as embedded by the `epaint_default_fonts` crate, so no
//! font file is needed at run time. Sizes scale with the image height;
//! text colour is white, or black over a light background.

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};
use thiserror::Error;

use crate::tf::TransferFunction;

/// Errors of drawing a legend.
#[derive(Debug, Error)]
pub enum LegendError {
    #[error("the embedded legend font cannot be read: {0}")]
    Font(String),
    #[error("the image buffer has {got} bytes, expected {want}")]
    Buffer { got: usize, want: usize },
}

/// What a legend shows.
#[derive(Clone, Copy, Debug)]
pub struct Legend<'a> {
    /// Field name (above the bar).
    pub title: &'a str,
    /// Scalar range the bar spans.
    pub range: (f64, f64),
    /// The time value of an animation frame.
    pub time: Option<f64>,
    pub tf: &'a TransferFunction,
}

/// An 8-bit image to draw into: RGB or straight-alpha RGBA.
pub struct Canvas<'a> {
    pub pixels: &'a mut [u8],
    pub width: u32,
    pub height: u32,
    /// 3 (RGB) or 4 (RGBA).
    pub channels: usize,
}

impl Canvas<'_> {
    /// Blends `rgb` with coverage `a` in [0, 1] over pixel (x, y).
    fn blend(&mut self, x: i64, y: i64, rgb: [u8; 3], a: f32) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 || a <= 0.0 {
            return;
        }
        let a = a.min(1.0);
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        for (dst, &src) in self.pixels[i..i + 3].iter_mut().zip(&rgb) {
            let old = *dst as f32;
            *dst = (old + (src as f32 - old) * a).round() as u8;
        }
        if self.channels == 4 {
            let old = self.pixels[i + 3] as f32;
            self.pixels[i + 3] = (old + (255.0 - old) * a).round() as u8;
        }
    }
}

/// A number as a legend prints it: up to 4 significant digits, scientific
/// notation outside 1e-3..1e5.
pub fn format_value(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.3e}");
    }
    let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Width in pixels of `text` at `scale`.
fn text_width(font: &impl ScaleFont<FontRef<'static>>, text: &str) -> f32 {
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            w += font.kern(p, id);
        }
        w += font.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Draws `text` with its baseline at (x, y).
fn draw_text(
    canvas: &mut Canvas,
    font: &impl ScaleFont<FontRef<'static>>,
    text: &str,
    x: f32,
    y: f32,
    rgb: [u8; 3],
) {
    let mut caret = x;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            caret += font.kern(p, id);
        }
        let glyph = id.with_scale_and_position(font.scale(), point(caret, y));
        caret += font.h_advance(id);
        prev = Some(id);
        if let Some(outline) = font.outline_glyph(glyph) {
            let b = outline.px_bounds();
            outline.draw(|gx, gy, cov| {
                canvas.blend(
                    b.min.x as i64 + gx as i64,
                    b.min.y as i64 + gy as i64,
                    rgb,
                    cov,
                );
            });
        }
    }
}

/// Draws `legend` into `canvas` over a background of `background` (which
/// picks the text colour).
pub fn draw(canvas: &mut Canvas, legend: &Legend, background: [f32; 3]) -> Result<(), LegendError> {
    let want = canvas.width as usize * canvas.height as usize * canvas.channels;
    if canvas.pixels.len() != want || !(3..=4).contains(&canvas.channels) {
        return Err(LegendError::Buffer {
            got: canvas.pixels.len(),
            want,
        });
    }
    let font = FontRef::try_from_slice(epaint_default_fonts::HACK_REGULAR)
        .map_err(|e| LegendError::Font(e.to_string()))?;
    let (w, h) = (canvas.width as f32, canvas.height as f32);
    let px = (h / 28.0).clamp(9.0, 48.0);
    let font = font.into_scaled(PxScale::from(px));
    let luminance = 0.2126 * background[0] + 0.7152 * background[1] + 0.0722 * background[2];
    let ink = if luminance > 0.5 {
        [0, 0, 0]
    } else {
        [255, 255, 255]
    };
    let margin = (h / 40.0).max(3.0);
    let bar_h = (h / 36.0).max(4.0).round();
    let bar_w = (w * 0.6).round().max(8.0);
    let x0 = ((w - bar_w) / 2.0).round();
    let line = font.ascent() - font.descent();
    // Bar above the bottom labels.
    let y_labels = h - margin + font.descent();
    let y1 = (y_labels - font.ascent() - margin * 0.5).round();
    let y0 = y1 - bar_h;
    let (lo, hi) = legend.range;
    for i in 0..bar_w as i64 {
        let t = (i as f64 + 0.5) / bar_w as f64;
        let c = legend.tf.color_at(lo + t * (hi - lo));
        let rgb = c.map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8);
        for y in y0 as i64..y1 as i64 {
            canvas.blend(x0 as i64 + i, y, rgb, 1.0);
        }
    }
    // Thin frame around the bar.
    for i in -1..=bar_w as i64 {
        canvas.blend(x0 as i64 + i, y0 as i64 - 1, ink, 1.0);
        canvas.blend(x0 as i64 + i, y1 as i64, ink, 1.0);
    }
    for y in y0 as i64 - 1..=y1 as i64 {
        canvas.blend(x0 as i64 - 1, y, ink, 1.0);
        canvas.blend(x0 as i64 + bar_w as i64, y, ink, 1.0);
    }
    let lo_s = format_value(lo);
    let hi_s = format_value(hi);
    draw_text(canvas, &font, &lo_s, x0, y_labels, ink);
    let hw = text_width(&font, &hi_s);
    draw_text(canvas, &font, &hi_s, x0 + bar_w - hw, y_labels, ink);
    let tw = text_width(&font, legend.title);
    let y_title = y0 - margin * 0.5 + font.descent();
    draw_text(
        canvas,
        &font,
        legend.title,
        (w - tw) / 2.0,
        y_title.max(line),
        ink,
    );
    if let Some(t) = legend.time {
        let s = format!("t = {}", format_value(t));
        draw_text(canvas, &font, &s, margin, margin + font.ascent(), ink);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_print_short() {
        assert_eq!(format_value(0.5), "0.5");
        assert_eq!(format_value(123.456), "123.5");
        assert_eq!(format_value(-2.0), "-2");
        assert_eq!(format_value(1.5e-7), "1.500e-7");
        assert_eq!(format_value(0.0), "0");
    }

    #[test]
    fn draws_bar_and_text_inside_the_image() {
        let tf = TransferFunction::default_for((0.0, 1.0), 1.0);
        let (w, h) = (200u32, 120u32);
        let mut px = vec![0u8; (w * h * 3) as usize];
        let mut canvas = Canvas {
            pixels: &mut px,
            width: w,
            height: h,
            channels: 3,
        };
        let legend = Legend {
            title: "pressure",
            range: (0.0, 1.0),
            time: Some(0.25),
            tf: &tf,
        };
        draw(&mut canvas, &legend, [0.0; 3]).unwrap();
        let lit = px.iter().filter(|&&v| v > 0).count();
        assert!(lit > 500, "{lit}");
        // The top-left corner holds the time text.
        let corner = (0..20)
            .flat_map(|y| (0..60).map(move |x| (y * w + x) as usize * 3))
            .filter(|&i| px[i] > 128)
            .count();
        assert!(corner > 10, "{corner}");
        let mut short = vec![0u8; 10];
        let mut bad = Canvas {
            pixels: &mut short,
            width: w,
            height: h,
            channels: 3,
        };
        assert!(draw(&mut bad, &legend, [0.0; 3]).is_err());
    }
}
