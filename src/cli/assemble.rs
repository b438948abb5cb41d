//! `--gif` / `--mp4` of `zoovr animate`, and `zoovr animate --assemble DIR`:
//! the frames `DIR/frame_NNNNN.png` into a GIF and/or an MP4: with
//! `--assemble`, all of them (from one run or from several `--frames`
//! runs); after a run, the frames that run wrote. The frames are read
//! back from the folder one at a time, so memory does not grow with the
//! number of frames; a gap in the numbering is an error naming the missing
//! frames.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};

use zoovr::video::{self, VideoError};

pub struct AssembleArgs {
    pub dir: PathBuf,
    pub gif: Option<PathBuf>,
    pub mp4: Option<PathBuf>,
    pub fps: f64,
    /// The frame indices to use (those a run just wrote); `None`: every
    /// frame in the folder, which must be numbered without gaps.
    pub only: Option<Vec<usize>>,
}

/// Fails early, before rendering, when `--mp4` cannot hold frames of
/// `width x height` (the encoder's largest frame).
pub fn check_mp4_size((width, height): (u32, u32)) -> Result<()> {
    video::mp4::check_size(width, height).context("--mp4")?;
    Ok(())
}

/// The frame files of `dir` in index order.
fn frames(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut found: Vec<(usize, PathBuf)> = Vec::new();
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("{}: cannot read the folder", dir.display()))?;
    for e in entries {
        let e = e.with_context(|| format!("{}", dir.display()))?;
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(num) = name
            .strip_prefix("frame_")
            .and_then(|n| n.strip_suffix(".png"))
        else {
            continue;
        };
        if let Ok(i) = num.parse::<usize>() {
            found.push((i, e.path()));
        }
    }
    if found.is_empty() {
        bail!("{}: no frames (frame_NNNNN.png) to assemble", dir.display());
    }
    found.sort();
    let missing: Vec<String> = (0..found.last().map_or(0, |f| f.0))
        .filter(|i| found.binary_search_by_key(i, |f| f.0).is_err())
        .take(10)
        .map(super::animate::frame_name)
        .collect();
    if !missing.is_empty() {
        bail!(
            "{}: frames are missing: {}{}",
            dir.display(),
            missing.join(", "),
            if missing.len() == 10 { ", ..." } else { "" }
        );
    }
    Ok(found.into_iter().map(|f| f.1).collect())
}

/// Reads one frame as RGB bytes of the expected size.
fn read_rgb(path: &Path, size: Option<(u32, u32)>) -> Result<(u32, u32, Vec<u8>), VideoError> {
    let img = image::open(path)
        .map_err(|e| {
            VideoError::Invalid(format!("{}: cannot read the frame: {e}", path.display()))
        })?
        .to_rgb8();
    let (w, h) = img.dimensions();
    if let Some((ew, eh)) = size {
        if (w, h) != (ew, eh) {
            return Err(VideoError::Invalid(format!(
                "{}: the frame is {w}x{h}, the first frame {ew}x{eh}",
                path.display()
            )));
        }
    }
    Ok((w, h, img.into_raw()))
}

pub fn run(args: &AssembleArgs) -> Result<()> {
    let files = match &args.only {
        Some(list) if !list.is_empty() => list
            .iter()
            .map(|&i| args.dir.join(super::animate::frame_name(i)))
            .collect(),
        _ => frames(&args.dir)?,
    };
    let (w, h, _) = read_rgb(&files[0], None)?;
    let fetch = |i: usize| read_rgb(&files[i], Some((w, h))).map(|f| f.2);
    if let Some(gif) = &args.gif {
        let palette = video::gif::learn_palette(files.len(), fetch)?;
        video::gif::write_gif(gif, w, h, files.len(), args.fps, &palette, fetch)?;
    }
    if let Some(mp4) = &args.mp4 {
        video::mp4::write_mp4(mp4, w, h, files.len(), args.fps, fetch)?;
    }
    Ok(())
}
