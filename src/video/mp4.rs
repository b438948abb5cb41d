//! MP4 (H.264), encoded in process: nothing needs to be installed.
//!
//! The frames are converted to 4:2:0 YUV (BT.601, limited range, as the
//! stream's VUI says; odd sizes padded by repeating the last row or
//! column, as 4:2:0 needs even sizes), encoded by Cisco's OpenH264 (the
//! `openh264` crate, which builds it from source with the rest of zoovr:
//! about a minute of C++ on two cores) as Constrained Baseline H.264, the
//! profile every player decodes, and muxed by the `mp4` crate: the
//! encoder's Annex B NAL units become length-prefixed samples, its
//! sequence and picture parameter sets the track's `avcC` record.
//!
//! The rate is set for rendered images rather than camera video: a
//! target of [`BITS_PER_PIXEL`] per pixel and frame (a 512 x 512 orbit at
//! 10 frames per second gets 1.3 Mbit/s), in OpenH264's quality mode, and
//! a key frame every [`KEY_FRAME_SECONDS`] so a player can seek. Should
//! the rate control skip a frame (not seen at these rates), the previous
//! picture stays on screen for its time. Frames up to [`MAX_SIZE`].
//! Sample times are in a 90 kHz time base, each frame's start rounded
//! from `index / fps`, so fractional rates (29.97) do not drift.
//! The encoder is single-threaded, so the same frames give the same file,
//! byte for byte.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use mp4::{
    AvcConfig, Bytes, FourCC, MediaConfig, Mp4Config, Mp4Sample, Mp4Writer, TrackConfig, TrackType,
};
use openh264::encoder::{
    BitRate, Encoder, EncoderConfig, FrameRate, IntraFramePeriod, Profile, RateControlMode,
    VuiConfig,
};
use openh264::formats::YUVBuffer;
use openh264::OpenH264API;

use super::VideoError;

/// Target bits per pixel and frame (module docs).
pub const BITS_PER_PIXEL: f64 = 0.5;
/// Seconds between key frames.
pub const KEY_FRAME_SECONDS: f64 = 2.0;
/// The samples' time base (ticks per second).
const TIMESCALE: u32 = 90_000;
/// The largest frame OpenH264 encodes (level 5.2): 3840 x 2160, either
/// way round.
pub const MAX_SIZE: (u32, u32) = (3840, 2160);

/// Whether frames of `width x height` (padded to even) can be encoded,
/// else why not.
pub fn check_size(width: u32, height: u32) -> Result<(), VideoError> {
    let (pw, ph) = (width + width % 2, height + height % 2);
    if width == 0 || height == 0 || pw.max(ph) > MAX_SIZE.0 || pw.min(ph) > MAX_SIZE.1 {
        return Err(VideoError::Invalid(format!(
            "{width}x{height}: the MP4 encoder takes frames up to {}x{} (or {}x{})",
            MAX_SIZE.0, MAX_SIZE.1, MAX_SIZE.1, MAX_SIZE.0
        )));
    }
    Ok(())
}

/// NAL unit types (H.264 table 7-1) the muxer sorts out.
const NAL_IDR: u8 = 5;
const NAL_SPS: u8 = 7;
const NAL_PPS: u8 = 8;

/// The frame `rgb` (`width x height`, 8-bit RGB rows) as 4:2:0 YUV of the
/// even size `(pw, ph)`, BT.601 limited range, rounded; the padding
/// repeats the last column and row.
fn to_yuv420(rgb: &[u8], width: usize, height: usize, pw: usize, ph: usize) -> YUVBuffer {
    let px = |x: usize, y: usize| {
        let i = 3 * (y.min(height - 1) * width + x.min(width - 1));
        [rgb[i] as f64, rgb[i + 1] as f64, rgb[i + 2] as f64]
    };
    let luma = |p: [f64; 3]| 16.0 + (65.481 * p[0] + 128.553 * p[1] + 24.966 * p[2]) / 255.0;
    let cb = |p: [f64; 3]| 128.0 + (-37.797 * p[0] - 74.203 * p[1] + 112.0 * p[2]) / 255.0;
    let cr = |p: [f64; 3]| 128.0 + (112.0 * p[0] - 93.786 * p[1] - 18.214 * p[2]) / 255.0;
    let byte = |v: f64| v.round().clamp(0.0, 255.0) as u8;
    let mut out = vec![0u8; pw * ph * 3 / 2];
    let (y_plane, chroma) = out.split_at_mut(pw * ph);
    let (u_plane, v_plane) = chroma.split_at_mut(pw * ph / 4);
    for y in 0..ph {
        for x in 0..pw {
            y_plane[y * pw + x] = byte(luma(px(x, y)));
        }
    }
    for y in 0..ph / 2 {
        for x in 0..pw / 2 {
            let q = [
                px(2 * x, 2 * y),
                px(2 * x + 1, 2 * y),
                px(2 * x, 2 * y + 1),
                px(2 * x + 1, 2 * y + 1),
            ];
            let mean: [f64; 3] =
                std::array::from_fn(|k| 0.25 * (q[0][k] + q[1][k] + q[2][k] + q[3][k]));
            u_plane[y * pw / 2 + x] = byte(cb(mean));
            v_plane[y * pw / 2 + x] = byte(cr(mean));
        }
    }
    YUVBuffer::from_vec(out, pw, ph)
}

/// The NAL units of an Annex B access unit, without their start codes.
fn nal_units(annex_b: &[u8]) -> Vec<&[u8]> {
    let mut starts = Vec::new();
    let mut i = 0;
    while i + 3 <= annex_b.len() {
        if annex_b[i..i + 3] == [0, 0, 1] {
            starts.push(i + 3);
            i += 3;
        } else {
            i += 1;
        }
    }
    let mut units = Vec::with_capacity(starts.len());
    for (k, &s) in starts.iter().enumerate() {
        let mut e = starts.get(k + 1).map_or(annex_b.len(), |&n| n - 3);
        // A four-byte start code's leading zero belongs to no unit.
        while e > s && k + 1 < starts.len() && annex_b[e - 1] == 0 {
            e -= 1;
        }
        if e > s {
            units.push(&annex_b[s..e]);
        }
    }
    units
}

/// One access unit as an MP4 sample's bytes (each NAL unit prefixed by
/// its length), without the parameter sets, which are returned apart;
/// with whether it holds an IDR picture.
struct AccessUnit {
    sample: Vec<u8>,
    sps: Option<Vec<u8>>,
    pps: Option<Vec<u8>>,
    idr: bool,
}

fn access_unit(annex_b: &[u8]) -> AccessUnit {
    let mut au = AccessUnit {
        sample: Vec::with_capacity(annex_b.len()),
        sps: None,
        pps: None,
        idr: false,
    };
    for nal in nal_units(annex_b) {
        match nal[0] & 0x1f {
            NAL_SPS => au.sps = Some(nal.to_vec()),
            NAL_PPS => au.pps = Some(nal.to_vec()),
            t => {
                au.idr |= t == NAL_IDR;
                au.sample
                    .extend_from_slice(&(nal.len() as u32).to_be_bytes());
                au.sample.extend_from_slice(nal);
            }
        }
    }
    au
}

/// Encodes `count` RGB frames of `width x height`, fetched by `frame`, at
/// `fps` frames per second into `path` (written to a temporary file
/// renamed into place).
pub fn write_mp4(
    path: &Path,
    width: u32,
    height: u32,
    count: usize,
    fps: f64,
    mut frame: impl FnMut(usize) -> Result<Vec<u8>, VideoError>,
) -> Result<(), VideoError> {
    let werr = |msg: String| VideoError::Write {
        path: path.to_path_buf(),
        msg,
    };
    if count == 0 {
        return Err(VideoError::Invalid(
            "an MP4 needs at least one frame".into(),
        ));
    }
    if !(fps.is_finite() && fps > 0.0) {
        return Err(VideoError::Invalid(format!(
            "--fps {fps}: not a positive rate"
        )));
    }
    check_size(width, height)?;
    let (w, h) = (width as usize, height as usize);
    let (pw, ph) = (w + w % 2, h + h % 2);
    let bps = (BITS_PER_PIXEL * (pw * ph) as f64 * fps).clamp(2e5, 1e9);
    let config = EncoderConfig::new()
        .bitrate(BitRate::from_bps(bps as u32))
        .max_frame_rate(FrameRate::from_hz(fps as f32))
        .rate_control_mode(RateControlMode::Quality)
        .skip_frames(true)
        .profile(Profile::Baseline)
        .num_threads(1)
        .intra_frame_period(IntraFramePeriod::from_num_frames(
            (KEY_FRAME_SECONDS * fps).round().max(1.0) as u32,
        ))
        .vui(VuiConfig::bt601());
    let mut encoder =
        Encoder::with_api_config(OpenH264API::from_source(), config).map_err(|e| {
            VideoError::Invalid(format!(
                "{width}x{height}: the H.264 encoder cannot take this size: {e}"
            ))
        })?;
    let tmp = super::temp_path(path);
    let result = (|| {
        let file = File::create(&tmp).map_err(|e| werr(e.to_string()))?;
        let mut mp4 = Mp4Writer::write_start(
            BufWriter::new(file),
            &Mp4Config {
                major_brand: FourCC::from(*b"isom"),
                minor_version: 512,
                compatible_brands: [*b"isom", *b"iso2", *b"avc1", *b"mp41"]
                    .into_iter()
                    .map(FourCC::from)
                    .collect(),
                timescale: 1000,
            },
        )
        .map_err(|e| werr(e.to_string()))?;
        let tick = |i: usize| (i as f64 * TIMESCALE as f64 / fps).round() as u64;
        // A sample is written when the next one starts (its duration).
        let write = |mp4: &mut Mp4Writer<_>, mut s: Mp4Sample, end: u64| {
            s.duration = (end - s.start_time) as u32;
            mp4.write_sample(1, &s).map_err(|e| {
                werr(format!(
                    "frame at {} s: {e}",
                    s.start_time as f64 / TIMESCALE as f64
                ))
            })
        };
        let mut pending: Option<Mp4Sample> = None;
        let mut track = false;
        for i in 0..count {
            let rgb = frame(i)?;
            if rgb.len() != 3 * w * h {
                return Err(VideoError::Invalid(format!(
                    "frame {i}: {} bytes, not {width}x{height} RGB",
                    rgb.len()
                )));
            }
            let yuv = to_yuv420(&rgb, w, h, pw, ph);
            let bits = encoder
                .encode(&yuv)
                .map_err(|e| werr(format!("encoding frame {i}: {e}")))?
                .to_vec();
            let au = access_unit(&bits);
            if !track {
                let (Some(sps), Some(pps)) = (au.sps.clone(), au.pps.clone()) else {
                    return Err(werr(
                        "the encoder's first frame has no parameter sets".into(),
                    ));
                };
                mp4.add_track(&TrackConfig {
                    track_type: TrackType::Video,
                    timescale: TIMESCALE,
                    language: "und".into(),
                    media_conf: MediaConfig::AvcConfig(AvcConfig {
                        width: pw as u16,
                        height: ph as u16,
                        seq_param_set: sps,
                        pic_param_set: pps,
                    }),
                })
                .map_err(|e| werr(e.to_string()))?;
                track = true;
            }
            if au.sample.is_empty() {
                // Skipped by the rate control (not at these rates): the
                // previous picture stays on screen until the next one.
                continue;
            }
            if let Some(prev) = pending.take() {
                write(&mut mp4, prev, tick(i))?;
            }
            pending = Some(Mp4Sample {
                start_time: tick(i),
                duration: 0,
                rendering_offset: 0,
                is_sync: au.idr,
                bytes: Bytes::from(au.sample),
            });
        }
        match pending.take() {
            Some(last) => write(&mut mp4, last, tick(count))?,
            None => return Err(werr("the encoder gave no picture".into())),
        }
        mp4.write_end().map_err(|e| werr(e.to_string()))?;
        let mut out = mp4.into_writer();
        std::io::Write::flush(&mut out).map_err(|e| werr(e.to_string()))?;
        drop(out);
        std::fs::rename(&tmp, path).map_err(|e| werr(e.to_string()))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use openh264::decoder::Decoder;
    use openh264::formats::YUVSource;

    /// A moving gradient with a sharp edge.
    fn test_frame(i: usize, w: usize, h: usize) -> Vec<u8> {
        let mut rgb = Vec::with_capacity(3 * w * h);
        for y in 0..h {
            for x in 0..w {
                let edge = if (x + 3 * i) % w < w / 3 { 200 } else { 30 };
                rgb.extend_from_slice(&[(255 * x / w) as u8, (255 * y / h) as u8, edge as u8]);
            }
        }
        rgb
    }

    #[test]
    fn frames_come_back_from_the_file_through_a_decoder() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.mp4");
        // Odd: padded to 48 x 34.
        let (w, h, n, fps) = (47usize, 33usize, 25usize, 12.5);
        write_mp4(&path, w as u32, h as u32, n, fps, |i| {
            Ok(test_frame(i, w, h))
        })
        .unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[4..8], b"ftyp");
        let size = bytes.len() as u64;
        let mut reader = mp4::Mp4Reader::read_header(std::io::Cursor::new(bytes), size).unwrap();
        let stream = {
            let track = &reader.tracks()[&1];
            assert_eq!((track.width(), track.height()), (48, 34));
            // 25 frames at 12.5 frames per second: two seconds.
            let duration = track.duration().as_secs_f64();
            assert!((duration - n as f64 / fps).abs() < 1e-3, "{duration}");
            let avc = track.trak.mdia.minf.stbl.stsd.avc1.as_ref().unwrap();
            let mut stream = Vec::new();
            for ps in [
                &avc.avcc.sequence_parameter_sets,
                &avc.avcc.picture_parameter_sets,
            ] {
                for p in ps.iter() {
                    stream.extend_from_slice(&[0, 0, 0, 1]);
                    stream.extend_from_slice(&p.bytes);
                }
            }
            stream
        };
        assert_eq!(reader.sample_count(1).unwrap(), n as u32);
        let mut decoder = Decoder::new().unwrap();
        let mut worst = 0.0f64;
        let mut decoded = 0;
        for s in 1..=n as u32 {
            let sample = reader.read_sample(1, s).unwrap().unwrap();
            assert_eq!(sample.is_sync, s == 1, "sample {s}");
            let mut au = if s == 1 { stream.clone() } else { Vec::new() };
            let mut b = &sample.bytes[..];
            while b.len() >= 4 {
                let len = u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize;
                au.extend_from_slice(&[0, 0, 0, 1]);
                au.extend_from_slice(&b[4..4 + len]);
                b = &b[4 + len..];
            }
            assert!(b.is_empty());
            let Some(yuv) = decoder.decode(&au).unwrap() else {
                continue;
            };
            assert_eq!(yuv.dimensions(), (48, 34));
            // The luma plane against the one encoded: the coding loss.
            let want = to_yuv420(&test_frame(s as usize - 1, w, h), w, h, 48, 34);
            let stride = yuv.strides().0;
            let mut sq = 0.0;
            for y in 0..34 {
                for x in 0..48 {
                    let d = yuv.y()[y * stride + x] as f64 - want.y()[y * 48 + x] as f64;
                    sq += d * d;
                }
            }
            worst = worst.max((sq / (48.0 * 34.0)).sqrt());
            decoded += 1;
        }
        assert_eq!(decoded, n);
        // Luma RMS per frame, in 8-bit steps.
        eprintln!("luma rms {worst}");
        assert!(worst < 2.0, "luma rms {worst}");
        // The same frames give the same bytes.
        let again = dir.path().join("b.mp4");
        write_mp4(&again, w as u32, h as u32, n, fps, |i| {
            Ok(test_frame(i, w, h))
        })
        .unwrap();
        assert_eq!(
            std::fs::read(&path).unwrap(),
            std::fs::read(&again).unwrap()
        );
        eprintln!("bytes {}", std::fs::read(&path).unwrap().len());
    }

    #[test]
    fn start_codes_of_three_and_four_bytes_split_the_units() {
        let au = [
            0, 0, 0, 1, 0x67, 1, 2, 0, 0, 1, 0x68, 3, 0, 0, 0, 1, 0x65, 4, 5, 0,
        ];
        let units = nal_units(&au);
        assert_eq!(units, vec![&[0x67, 1, 2][..], &[0x68, 3], &[0x65, 4, 5, 0]]);
        let a = access_unit(&au);
        assert_eq!(a.sps.as_deref(), Some(&[0x67, 1, 2][..]));
        assert_eq!(a.pps.as_deref(), Some(&[0x68, 3][..]));
        assert!(a.idr);
        assert_eq!(a.sample, [0, 0, 0, 4, 0x65, 4, 5, 0]);
    }
}
