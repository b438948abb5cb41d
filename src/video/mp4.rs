//! MP4 through the system's `ffmpeg`.
//!
//! zoovr does not bundle a video encoder: the pure-Rust AV1 encoder
//! (rav1e) takes minutes to build and the bundled H.264 ones compile a C++
//! codec at build time, for a feature most runs do not use. `ffmpeg` is on
//! most machines that make videos and is found on `PATH` at run time;
//! where it is missing, [`find_encoder`] says what to install.
//!
//! The frames are piped to ffmpeg as raw RGB (`-f rawvideo -pix_fmt
//! rgb24`) and encoded with the first of these that the ffmpeg build has:
//! libx264 or libopenh264 (H.264), libsvtav1 or libaom-av1 (AV1), in
//! yuv420p (odd sizes padded by one pixel), with `+faststart` so players
//! can start before the whole file is read.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

use super::VideoError;

/// Encoders tried, best first.
const ENCODERS: [&str; 4] = ["libx264", "libopenh264", "libsvtav1", "libaom-av1"];

/// The message when no encoder is found.
const INSTALL: &str = "--mp4 needs ffmpeg with an H.264 or AV1 encoder on PATH \
     (e.g. `apt-get install ffmpeg`, `brew install ffmpeg`, `conda install ffmpeg`); \
     the frames are written anyway, and --gif needs nothing";

/// The ffmpeg encoder to use, or why there is none.
pub fn find_encoder() -> Result<&'static str, VideoError> {
    let out = Command::new("ffmpeg")
        .args(["-hide_banner", "-encoders"])
        .stdin(Stdio::null())
        .output()
        .map_err(|e| VideoError::NoEncoder(format!("{INSTALL} (running ffmpeg: {e})")))?;
    let list = String::from_utf8_lossy(&out.stdout);
    ENCODERS
        .into_iter()
        .find(|e| list.split_whitespace().any(|w| w == *e))
        .ok_or_else(|| {
            VideoError::NoEncoder(format!(
                "{INSTALL} (the ffmpeg found has none of {})",
                ENCODERS.join(", ")
            ))
        })
}

/// Encodes `count` RGB frames of `width x height`, fetched by `frame`, at
/// `fps` frames per second into `path`.
pub fn write_mp4(
    path: &Path,
    width: u32,
    height: u32,
    count: usize,
    fps: f64,
    mut frame: impl FnMut(usize) -> Result<Vec<u8>, VideoError>,
) -> Result<(), VideoError> {
    let encoder = find_encoder()?;
    let werr = |msg: String| VideoError::Write {
        path: path.to_path_buf(),
        msg,
    };
    let tmp = super::temp_path(path);
    let mut child = Command::new("ffmpeg")
        .args(["-hide_banner", "-loglevel", "error", "-y"])
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
        .args(["-s", &format!("{width}x{height}"), "-r", &format!("{fps}")])
        .args(["-i", "-", "-an", "-c:v", encoder])
        .args([
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-pix_fmt",
            "yuv420p",
        ])
        .args(["-movflags", "+faststart", "-f", "mp4"])
        .arg(&tmp)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| werr(format!("cannot run ffmpeg: {e}")))?;
    let fed = (|| {
        let mut stdin = child
            .stdin
            .take()
            .ok_or_else(|| werr("no pipe to ffmpeg".into()))?;
        for i in 0..count {
            let rgb = frame(i)?;
            stdin
                .write_all(&rgb)
                .map_err(|e| werr(format!("writing frame {i} to ffmpeg: {e}")))?;
        }
        Ok(())
    })();
    let out = child
        .wait_with_output()
        .map_err(|e| werr(format!("waiting for ffmpeg: {e}")))?;
    let result = match fed {
        Err(e) => Err(e),
        Ok(()) if !out.status.success() => Err(werr(format!(
            "ffmpeg ({encoder}) failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        ))),
        Ok(()) => std::fs::rename(&tmp, path).map_err(|e| werr(e.to_string())),
    };
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
