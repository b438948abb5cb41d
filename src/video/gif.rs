//! Animated GIF with one global palette.
//!
//! A GIF frame holds at most 256 colours. Quantising every frame on its
//! own gives each its own palette, and the same colour then lands on
//! different palette entries from frame to frame: the picture shimmers. So
//! the palette is learnt once, by NeuQuant (`color_quant`, the quantiser
//! the `image` crate uses) from pixels sampled evenly over all frames, and
//! every frame is indexed against it. The file (`gif` crate) carries it as
//! its global colour table, the frames have no local table, the delay is
//! 100 / fps hundredths of a second and the animation loops forever
//! (NETSCAPE2.0 extension, repeat count 0).

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use super::VideoError;

/// Pixels sampled per frame to learn the palette (at most).
const SAMPLES_PER_FRAME: usize = 16_384;
/// NeuQuant's sampling factor (1 = best, 30 = fastest); 10 is its default.
const NEUQUANT_SAMPLE: i32 = 10;

/// One frame: RGB bytes, `width * height * 3`.
pub struct RgbFrame<'a> {
    pub width: u32,
    pub height: u32,
    pub rgb: &'a [u8],
}

/// The global palette learnt from samples of every frame given by
/// `frames` (called once per frame index in `0..count`).
pub fn learn_palette(
    count: usize,
    mut frame: impl FnMut(usize) -> Result<Vec<u8>, VideoError>,
) -> Result<color_quant::NeuQuant, VideoError> {
    let mut samples: Vec<u8> = Vec::new();
    for i in 0..count {
        let rgb = frame(i)?;
        let pixels = rgb.len() / 3;
        let step = pixels.div_ceil(SAMPLES_PER_FRAME).max(1);
        for p in (0..pixels).step_by(step) {
            samples.extend_from_slice(&rgb[3 * p..3 * p + 3]);
            samples.push(255);
        }
    }
    if samples.is_empty() {
        samples.extend_from_slice(&[0, 0, 0, 255]);
    }
    Ok(color_quant::NeuQuant::new(NEUQUANT_SAMPLE, 256, &samples))
}

/// Writes the GIF: `count` frames, each fetched by `frame`, indexed against
/// `palette`, `fps` frames per second, looping forever.
pub fn write_gif(
    path: &Path,
    width: u32,
    height: u32,
    count: usize,
    fps: f64,
    palette: &color_quant::NeuQuant,
    mut frame: impl FnMut(usize) -> Result<Vec<u8>, VideoError>,
) -> Result<(), VideoError> {
    let too_big = |d: u32| d > u16::MAX as u32;
    if too_big(width) || too_big(height) {
        return Err(VideoError::Invalid(format!(
            "{}: a GIF is at most 65535 pixels wide and high, the frames are {width}x{height}",
            path.display()
        )));
    }
    let werr = |e: String| VideoError::Write {
        path: path.to_path_buf(),
        msg: e,
    };
    let tmp = super::temp_path(path);
    let result = (|| {
        let file = File::create(&tmp).map_err(|e| werr(e.to_string()))?;
        let map = palette.color_map_rgb();
        let mut enc = gif::Encoder::new(BufWriter::new(file), width as u16, height as u16, &map)
            .map_err(|e| werr(e.to_string()))?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|e| werr(e.to_string()))?;
        let delay = (100.0 / fps).round().clamp(1.0, u16::MAX as f64) as u16;
        for i in 0..count {
            let rgb = frame(i)?;
            let want = width as usize * height as usize * 3;
            if rgb.len() != want {
                return Err(VideoError::Invalid(format!(
                    "frame {i} has {} bytes, expected {want} ({width}x{height} RGB)",
                    rgb.len()
                )));
            }
            let indices: Vec<u8> = rgb
                .chunks_exact(3)
                .map(|p| palette.index_of(&[p[0], p[1], p[2], 255]) as u8)
                .collect();
            let mut f = gif::Frame {
                width: width as u16,
                height: height as u16,
                delay,
                buffer: std::borrow::Cow::Owned(indices),
                ..Default::default()
            };
            f.palette = None; // the global table
            enc.write_frame(&f).map_err(|e| werr(e.to_string()))?;
        }
        let mut w = enc.into_inner().map_err(|e| werr(e.to_string()))?;
        std::io::Write::flush(&mut w).map_err(|e| werr(e.to_string()))?;
        drop(w);
        std::fs::rename(&tmp, path).map_err(|e| werr(e.to_string()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
