//! Animations from frames: an animated GIF ([`gif`]) and an MP4 ([`mp4`],
//! H.264 encoded in process).
//!
//! Both take the frames as 8-bit RGB, fetched one at a time by index, so a
//! long run never holds every frame in memory, and both write to a
//! temporary file renamed into place, so a failed write leaves no partial
//! file.

pub mod gif;
pub mod mp4;

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Errors of writing an animation.
#[derive(Debug, Error)]
pub enum VideoError {
    #[error("{}: {msg}", path.display())]
    Write { path: PathBuf, msg: String },
    #[error("{0}")]
    Invalid(String),
}

/// The temporary file written before it is renamed to `path`.
pub(crate) fn temp_path(path: &Path) -> PathBuf {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.join(format!(".{name}.{}.tmp", std::process::id()))
}
