//! Reading the accumulation target back into an [`Image`].
//!
//! Rows are copied into a staging buffer with `bytes_per_row` padded to
//! `COPY_BYTES_PER_ROW_ALIGNMENT` (256). The staging buffer holds a chunk of
//! rows no larger than 64 MiB or the adapter's buffer limit and is reused for
//! each chunk, so large images never need one huge buffer. Each chunk is
//! mapped with `map_async` and waited for with the context's poll loop (which
//! tolerates GL's `Timeout`), then unpadded and converted (f16 -> f32 with
//! the `half` crate) row by row. Texture row 0 is the top row of the image.

use std::sync::{Arc, Mutex};

use super::device::Context;
use super::{AccumFormat, GpuError};
use crate::image::Image;

/// Upper bound of the staging buffer.
const STAGING_MAX_BYTES: u64 = 64 << 20;

pub(crate) fn read_image(
    ctx: &Context,
    texture: &wgpu::Texture,
    width: u32,
    height: u32,
    format: AccumFormat,
) -> Result<Image, GpuError> {
    let bpp = format.bytes_per_pixel();
    let unpadded = width as u64 * bpp as u64;
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;
    let padded = unpadded.div_ceil(align) * align;
    let budget = STAGING_MAX_BYTES.min(ctx.limits().max_buffer_size);
    if padded > budget || padded > u32::MAX as u64 {
        return Err(GpuError::Readback(format!(
            "one row of {padded} bytes exceeds the staging limit {budget}"
        )));
    }
    let rows_per_chunk = (budget / padded).clamp(1, height as u64) as u32;
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: padded * rows_per_chunk as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut pixels: Vec<[f32; 4]> = Vec::with_capacity(width as usize * height as usize);
    let mut y0 = 0u32;
    while y0 < height {
        let rows = rows_per_chunk.min(height - y0);
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("readback"),
            });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: y0, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d {
                width,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        let index = ctx.queue.submit([encoder.finish()]);
        let bytes = padded * rows as u64;
        let slice = staging.slice(..bytes);
        let status: Arc<Mutex<Option<Result<(), String>>>> = Arc::new(Mutex::new(None));
        let sink = status.clone();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            if let Ok(mut s) = sink.lock() {
                *s = Some(r.map_err(|e| e.to_string()));
            }
        });
        ctx.wait(Some(index))?;
        // The callback runs inside a poll; poll again until it has.
        let mut tries = 0;
        loop {
            let done = status.lock().ok().and_then(|s| s.clone());
            match done {
                Some(Ok(())) => break,
                Some(Err(e)) => return Err(GpuError::Readback(e)),
                None if tries < 100 => {
                    tries += 1;
                    ctx.wait(None)?;
                }
                None => return Err(GpuError::Readback("buffer was never mapped".into())),
            }
        }
        {
            let data = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            for row in data.chunks_exact(padded as usize) {
                let row = row.get(..unpadded as usize).unwrap_or(row);
                convert_row(row, format, &mut pixels);
            }
        }
        staging.unmap();
        y0 += rows;
    }
    if pixels.len() != width as usize * height as usize {
        return Err(GpuError::Readback(format!(
            "read {} pixels, expected {}",
            pixels.len(),
            width as usize * height as usize
        )));
    }
    Ok(Image {
        width,
        height,
        pixels,
    })
}

/// Appends the pixels of one unpadded row.
fn convert_row(row: &[u8], format: AccumFormat, out: &mut Vec<[f32; 4]>) {
    match format {
        AccumFormat::F32 => {
            for px in row.chunks_exact(16) {
                let mut p = [0.0f32; 4];
                for (k, c) in px.chunks_exact(4).enumerate() {
                    p[k] = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
                }
                out.push(p);
            }
        }
        _ => {
            for px in row.chunks_exact(8) {
                let mut p = [0.0f32; 4];
                for (k, c) in px.chunks_exact(2).enumerate() {
                    p[k] = half::f16::from_bits(u16::from_le_bytes([c[0], c[1]])).to_f32();
                }
                out.push(p);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_f16_and_f32_rows() {
        let mut out = Vec::new();
        let vals = [0.5f32, -1.25, 3.0, 1.0];
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        convert_row(&bytes, AccumFormat::F32, &mut out);
        let bytes: Vec<u8> = vals
            .iter()
            .flat_map(|v| half::f16::from_f32(*v).to_bits().to_le_bytes())
            .collect();
        convert_row(&bytes, AccumFormat::F16, &mut out);
        assert_eq!(out, vec![vals, vals]);
    }
}
