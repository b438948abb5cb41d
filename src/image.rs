//! Images: linear premultiplied RGBA `f32`, PNG/EXR output and comparison.
//!
//! Every renderer produces an [`Image`]. PNG output follows docs/conventions.md:
//! 8-bit RGB of the premultiplied colour composited over the background,
//! written linearly (no sRGB curve); with `alpha`, RGBA with straight alpha.
//! Float output is OpenEXR (RGBA f32, linear premultiplied). Files are written
//! to a temporary name in the same folder and renamed, so an interrupted
//! render never leaves a half-written image.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// A linear premultiplied RGBA image, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// `width * height` pixels, row-major.
    pub pixels: Vec<[f32; 4]>,
}

/// Errors writing or reading images.
#[derive(Debug, Error)]
pub enum ImageError {
    #[error("cannot write '{path}': {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot encode '{path}': {msg}")]
    Encode { path: PathBuf, msg: String },
    #[error("cannot read image '{path}': {msg}")]
    Read { path: PathBuf, msg: String },
    #[error("images differ in size: {a:?} vs {b:?}")]
    SizeMismatch { a: (u32, u32), b: (u32, u32) },
}

impl Image {
    /// A transparent black image.
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            pixels: vec![[0.0; 4]; width as usize * height as usize],
        }
    }

    /// Pixel `(i, j)` (column, row).
    #[inline]
    pub fn get(&self, i: u32, j: u32) -> [f32; 4] {
        self.pixels[(j * self.width + i) as usize]
    }

    /// Sets pixel `(i, j)`.
    #[inline]
    pub fn set(&mut self, i: u32, j: u32, v: [f32; 4]) {
        self.pixels[(j * self.width + i) as usize] = v;
    }

    /// Number of non-finite channel values.
    pub fn count_non_finite(&self) -> usize {
        self.pixels
            .iter()
            .flat_map(|p| p.iter())
            .filter(|v| !v.is_finite())
            .count()
    }

    /// Display values in [0, 1] per docs/conventions.md: RGB over `background`, or
    /// straight-alpha RGBA when `alpha` is set (colour 0 where the opacity
    /// is below half an 8-bit step, so that its alpha byte is 0). Values
    /// are clamped, not gamma encoded. Returns 3 or 4 channels per pixel.
    pub fn display_values(&self, background: [f32; 3], alpha: bool) -> Vec<f32> {
        let ch = if alpha { 4 } else { 3 };
        let mut out = Vec::with_capacity(self.pixels.len() * ch);
        for p in &self.pixels {
            let a = p[3].clamp(0.0, 1.0);
            if alpha {
                // The straight colour c / a of a pixel whose opacity is
                // below half an 8-bit step is written as 0 with its alpha
                // byte 0: invisible, and ill-conditioned (a grazing ray's
                // opacity of 1e-5 or none at all would give any colour).
                let shown = a * 255.0 >= 0.5;
                for c in &p[..3] {
                    out.push(if shown { (c / a).clamp(0.0, 1.0) } else { 0.0 });
                }
                out.push(a);
            } else {
                for k in 0..3 {
                    out.push((p[k] + (1.0 - a) * background[k]).clamp(0.0, 1.0));
                }
            }
        }
        out
    }

    /// 8-bit PNG bytes per docs/conventions.md.
    pub fn to_png_bytes(&self, background: [f32; 3], alpha: bool) -> Vec<u8> {
        self.display_values(background, alpha)
            .iter()
            .map(|v| (v * 255.0 + 0.5).floor().clamp(0.0, 255.0) as u8)
            .collect()
    }

    /// Writes an 8-bit PNG (atomically: temp file + rename).
    pub fn write_png(
        &self,
        path: &Path,
        background: [f32; 3],
        alpha: bool,
    ) -> Result<(), ImageError> {
        let bytes = self.to_png_bytes(background, alpha);
        write_png_bytes(path, &bytes, self.width, self.height, alpha)
    }

    /// Writes linear premultiplied RGBA f32 as OpenEXR (atomically).
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        let flat: Vec<f32> = self.pixels.iter().flat_map(|p| p.iter().copied()).collect();
        write_atomic(path, |tmp| {
            let buf = image::Rgba32FImage::from_raw(self.width, self.height, flat.clone())
                .ok_or_else(|| "buffer size mismatch".to_string())?;
            image::DynamicImage::ImageRgba32F(buf)
                .save_with_format(tmp, image::ImageFormat::OpenExr)
                .map_err(|e| e.to_string())
        })
    }

    /// Reads a PNG (as display values: RGB with alpha 1, or RGBA straight
    /// converted to premultiplied) or an EXR (as stored).
    pub fn read(path: &Path) -> Result<Image, ImageError> {
        let err = |msg: String| ImageError::Read {
            path: path.to_path_buf(),
            msg,
        };
        let img = image::open(path).map_err(|e| err(e.to_string()))?;
        let rgba = img.to_rgba32f();
        let (w, h) = rgba.dimensions();
        let is_float = matches!(
            img,
            image::DynamicImage::ImageRgba32F(_) | image::DynamicImage::ImageRgb32F(_)
        );
        let pixels = rgba
            .pixels()
            .map(|p| {
                let [r, g, b, a] = p.0;
                if is_float {
                    [r, g, b, a]
                } else {
                    [r * a, g * a, b * a, a]
                }
            })
            .collect();
        Ok(Image {
            width: w,
            height: h,
            pixels,
        })
    }
}

/// Writes 8-bit RGB (or RGBA with `alpha`) bytes as a PNG, atomically
/// (temp file + rename).
pub fn write_png_bytes(
    path: &Path,
    bytes: &[u8],
    width: u32,
    height: u32,
    alpha: bool,
) -> Result<(), ImageError> {
    let ct = if alpha {
        image::ExtendedColorType::Rgba8
    } else {
        image::ExtendedColorType::Rgb8
    };
    write_atomic(path, |tmp| {
        image::save_buffer_with_format(tmp, bytes, width, height, ct, image::ImageFormat::Png)
            .map_err(|e| e.to_string())
    })
}

fn write_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), ImageError> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp.{ext}", std::process::id()));
    if let Err(msg) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        // Distinguish an I/O problem (missing folder, permissions, full disk).
        if let Err(e) = std::fs::metadata(dir) {
            return Err(ImageError::Write {
                path: path.to_path_buf(),
                source: e,
            });
        }
        return Err(ImageError::Encode {
            path: path.to_path_buf(),
            msg,
        });
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        ImageError::Write {
            path: path.to_path_buf(),
            source: e,
        }
    })
}

/// Error statistics of one image against another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDiff {
    /// Maximum absolute difference over pixels and channels.
    pub max_abs: f64,
    /// Root mean square difference over pixels and channels.
    pub rms: f64,
    /// Peak signal-to-noise ratio in dB for a peak of 1 (infinite if equal).
    pub psnr: f64,
    /// Pixel `(i, j)` where the maximum occurs.
    pub worst: (u32, u32),
    /// 99.9th percentile over pixels of the largest channel difference of a
    /// pixel (isolated outliers, e.g. pixel centres on shared edges where
    /// tie rules differ, do not move it).
    pub p999: f64,
}

/// Compares display values (`background`, RGB, as PNG values in [0, 1]
/// before quantisation) of two images.
pub fn compare_display(
    a: &Image,
    b: &Image,
    background: [f32; 3],
) -> Result<(ImageDiff, Image), ImageError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(ImageError::SizeMismatch {
            a: (a.width, a.height),
            b: (b.width, b.height),
        });
    }
    let da = a.display_values(background, false);
    let db = b.display_values(background, false);
    Ok(diff_of(&da, &db, 3, a.width, a.height))
}

/// Compares the raw premultiplied float RGBA values of two images.
pub fn compare_float(a: &Image, b: &Image) -> Result<(ImageDiff, Image), ImageError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(ImageError::SizeMismatch {
            a: (a.width, a.height),
            b: (b.width, b.height),
        });
    }
    let da: Vec<f32> = a.pixels.iter().flatten().copied().collect();
    let db: Vec<f32> = b.pixels.iter().flatten().copied().collect();
    Ok(diff_of(&da, &db, 4, a.width, a.height))
}

fn diff_of(da: &[f32], db: &[f32], ch: usize, w: u32, h: u32) -> (ImageDiff, Image) {
    let mut max_abs = 0.0f64;
    let mut worst = 0usize;
    let mut sum = 0.0f64;
    let mut diff = Image::new(w, h);
    for (i, (x, y)) in da.iter().zip(db).enumerate() {
        let d = if x.is_finite() && y.is_finite() {
            (*x as f64 - *y as f64).abs()
        } else if x.is_nan() && y.is_nan() {
            0.0
        } else {
            f64::INFINITY
        };
        if d > max_abs || (d.is_nan() && !max_abs.is_nan()) {
            max_abs = d;
            worst = i / ch;
        }
        sum += d * d;
        let px = &mut diff.pixels[i / ch];
        let k = i % ch;
        if k < 3 {
            px[k] = d as f32;
        }
        px[3] = 1.0;
    }
    let n = da.len().max(1) as f64;
    let rms = (sum / n).sqrt();
    let mut per_pixel: Vec<f64> = diff
        .pixels
        .iter()
        .map(|p| p[..3].iter().fold(0.0f64, |m, &v| m.max(v as f64)))
        .collect();
    per_pixel.sort_by(|a, b| a.total_cmp(b));
    let p999 = per_pixel
        .get(((per_pixel.len() as f64 * 0.999) as usize).min(per_pixel.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0);
    let psnr = if rms == 0.0 {
        f64::INFINITY
    } else {
        -20.0 * rms.log10()
    };
    (
        ImageDiff {
            max_abs,
            rms,
            psnr,
            worst: ((worst as u32) % w.max(1), (worst as u32) / w.max(1)),
            p999,
        },
        diff,
    )
}

/// Folder where image tests write actual and difference images on failure.
pub fn test_output_dir() -> PathBuf {
    let base = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target"));
    base.join("test-output")
}

/// Compares `actual` with `expected` on PNG display values over black and
/// fails (with a message) when `max_abs` or `rms` exceed the bounds; on
/// failure writes `NAME.actual.png`, `NAME.expected.png` and `NAME.diff.png`
/// (difference scaled x10) under [`test_output_dir`]. Returns the statistics.
pub fn check_images(
    name: &str,
    actual: &Image,
    expected: &Image,
    max_abs: f64,
    rms: f64,
) -> Result<ImageDiff, String> {
    let b = Bounds {
        max_abs,
        p999: max_abs,
        rms,
    };
    check_images_with(name, actual, expected, &b)
}

/// Error bounds for [`check_images_with`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Largest difference anywhere.
    pub max_abs: f64,
    /// Bound on [`ImageDiff::p999`].
    pub p999: f64,
    /// Bound on the RMS difference.
    pub rms: f64,
}

/// [`check_images`] with separate bounds for the maximum, the 99.9th
/// percentile pixel and the RMS.
pub fn check_images_with(
    name: &str,
    actual: &Image,
    expected: &Image,
    b: &Bounds,
) -> Result<ImageDiff, String> {
    let (max_abs, rms) = (b.max_abs, b.rms);
    let (d, diff) = compare_display(actual, expected, [0.0; 3]).map_err(|e| e.to_string())?;
    let bad_nan = actual.count_non_finite() > 0;
    if d.max_abs <= max_abs && d.p999 <= b.p999 && d.rms <= rms && !bad_nan {
        return Ok(d);
    }
    let dir = test_output_dir();
    let _ = std::fs::create_dir_all(&dir);
    let _ = actual.write_png(&dir.join(format!("{name}.actual.png")), [0.0; 3], false);
    let _ = expected.write_png(&dir.join(format!("{name}.expected.png")), [0.0; 3], false);
    let mut scaled = diff;
    for p in &mut scaled.pixels {
        for v in p.iter_mut().take(3) {
            *v = (*v * 10.0).min(1.0);
        }
    }
    let _ = scaled.write_png(&dir.join(format!("{name}.diff.png")), [0.0; 3], false);
    Err(format!(
        "{name}: max {:.3e} (bound {max_abs:.1e}) at {:?}, p99.9 {:.3e} (bound {:.1e}), rms {:.3e} (bound {rms:.1e}), non-finite {}; images in {}",
        d.max_abs,
        d.worst,
        d.p999,
        b.p999,
        d.rms,
        actual.count_non_finite(),
        dir.display()
    ))
}

/// [`check_images_with`] on the float values (linear premultiplied RGBA,
/// all four channels) instead of the PNG display values: for tests whose
/// bounds are tighter than 8-bit output can show. On failure it writes the
/// actual, expected and difference images (as PNGs) like
/// [`check_images_with`].
pub fn check_float_images(
    name: &str,
    actual: &Image,
    expected: &Image,
    max_abs: f64,
    rms: f64,
) -> Result<ImageDiff, String> {
    let (d, diff) = compare_float(actual, expected).map_err(|e| e.to_string())?;
    if d.max_abs <= max_abs && d.rms <= rms && actual.count_non_finite() == 0 {
        return Ok(d);
    }
    let dir = test_output_dir();
    let _ = std::fs::create_dir_all(&dir);
    let _ = actual.write_png(&dir.join(format!("{name}.actual.png")), [0.0; 3], false);
    let _ = expected.write_png(&dir.join(format!("{name}.expected.png")), [0.0; 3], false);
    let _ = diff.write_png(&dir.join(format!("{name}.diff.png")), [0.0; 3], false);
    Err(format!(
        "{name}: float max {:.3e} (bound {max_abs:.1e}) at {:?}, rms {:.3e} (bound {rms:.1e}), non-finite {}; images in {}",
        d.max_abs,
        d.worst,
        d.rms,
        actual.count_non_finite(),
        dir.display()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_composites_over_background() {
        let mut img = Image::new(1, 1);
        img.set(0, 0, [0.25, 0.0, 0.0, 0.5]);
        let v = img.display_values([0.0, 1.0, 0.0], false);
        assert_eq!(v, vec![0.25, 0.5, 0.0]);
        let v = img.display_values([0.0; 3], true);
        assert_eq!(v, vec![0.5, 0.0, 0.0, 0.5]);
    }

    #[test]
    fn straight_alpha_below_half_a_step_is_written_transparent_black() {
        // Opacity 1e-4 (a grazing ray) and 0 give the same bytes, where
        // colour over opacity would write the full colour for one of them.
        let mut img = Image::new(3, 1);
        img.set(0, 0, [0.7e-4, 0.2e-4, 1e-4, 1e-4]);
        img.set(2, 0, [0.7e-2, 0.2e-2, 1e-2, 1e-2]);
        let bytes = img.to_png_bytes([0.0; 3], true);
        assert_eq!(&bytes[..8], &[0; 8]);
        assert_eq!(&bytes[8..], &[179, 51, 255, 3]);
        // Half a step is shown.
        img.set(0, 0, [0.5 / 255.0, 0.0, 0.0, 0.5 / 255.0]);
        assert_eq!(&img.to_png_bytes([0.0; 3], true)[..4], &[255, 0, 0, 1]);
    }

    #[test]
    fn compare_reports_max_and_rms() {
        let a = Image::new(2, 1);
        let mut b = Image::new(2, 1);
        b.set(1, 0, [0.5, 0.0, 0.0, 1.0]);
        let (d, _) = compare_display(&a, &b, [0.0; 3]).unwrap();
        assert_eq!(d.max_abs, 0.5);
        assert_eq!(d.worst, (1, 0));
        assert!((d.rms - (0.25f64 / 6.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn png_and_exr_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let mut img = Image::new(3, 2);
        img.set(2, 1, [0.2, 0.4, 0.6, 0.8]);
        let exr = dir.path().join("a.exr");
        img.write_exr(&exr).unwrap();
        assert_eq!(Image::read(&exr).unwrap(), img);
        let png = dir.path().join("a.png");
        img.write_png(&png, [0.0; 3], false).unwrap();
        let back = Image::read(&png).unwrap();
        assert!((back.get(2, 1)[1] - 0.4).abs() < 1.0 / 255.0);
        assert!(img
            .write_png(Path::new("/nonexistent/dir/x.png"), [0.0; 3], false)
            .is_err());
    }
}
