//! Writing a frame: the PNG of an image, with the colour legend
//! ([`zoovr::legend`]) drawn in when `--legend` asks for it.

use std::path::Path;

use anyhow::Result;

use zoovr::image::{write_png_bytes, Image};
use zoovr::legend::{self, Canvas, Legend};
use zoovr::render::Shading;

use super::render::ViewArgs;

/// Writes `image` as the PNG `path` (atomically), with the legend of
/// `shading` (and the time value, for an animation) when `view.legend`.
pub fn write_frame(
    image: &Image,
    path: &Path,
    view: &ViewArgs,
    shading: &Shading,
    time: Option<f64>,
) -> Result<()> {
    if !view.legend {
        image.write_png(path, view.background, view.alpha)?;
        return Ok(());
    }
    let mut bytes = image.to_png_bytes(view.background, view.alpha);
    let title = shading
        .field
        .as_ref()
        .map_or("constant".to_string(), |f| f.name.clone());
    let mut canvas = Canvas {
        pixels: &mut bytes,
        width: image.width,
        height: image.height,
        channels: if view.alpha { 4 } else { 3 },
    };
    legend::draw(
        &mut canvas,
        &Legend {
            title: &title,
            range: shading.range,
            time,
            tf: &shading.tf,
        },
        view.background,
    )?;
    write_png_bytes(path, &bytes, image.width, image.height, view.alpha)?;
    Ok(())
}
