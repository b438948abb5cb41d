//! Lookup tables as textures: `R32Float` texels in 2D or 3D, read by the
//! shaders with `textureLoad` and filtered by hand in `f32` (so the CPU
//! twins can filter the same way; hardware filtering has 8-bit weights).
//!
//! A mode builds its table on the CPU and uploads it once per device with
//! [`Context::resource`]; tables do not change between frames.

use super::device::Context;
use super::GpuError;

/// A table on the GPU.
#[derive(Debug)]
pub struct Table {
    view: wgpu::TextureView,
    size: [u32; 3],
}

impl Table {
    /// Uploads `data`, `size[0]` texels per row, `size[1]` rows per layer,
    /// `size[2]` layers (1 makes a 2D table), x fastest.
    pub fn upload(
        ctx: &Context,
        label: &str,
        size: [u32; 3],
        data: &[f32],
    ) -> Result<Table, GpuError> {
        let [w, h, d] = size;
        let n = w as usize * h as usize * d as usize;
        if n == 0 || data.len() != n {
            return Err(GpuError::BadOption("table size does not match its data"));
        }
        let lim = ctx.limits();
        let is_3d = d > 1;
        let max = if is_3d {
            lim.max_texture_dimension_3d
        } else {
            lim.max_texture_dimension_2d
        };
        if w > max || h > max || d > max {
            return Err(GpuError::BadSize {
                width: w,
                height: h,
                max,
            });
        }
        let extent = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: d,
        };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: if is_3d {
                wgpu::TextureDimension::D3
            } else {
                wgpu::TextureDimension::D2
            },
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(data),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * w),
                rows_per_image: Some(h),
            },
            extent,
        );
        ctx.check()?;
        Ok(Table {
            view: texture.create_view(&wgpu::TextureViewDescriptor::default()),
            size,
        })
    }

    /// Texels per axis.
    pub fn size(&self) -> [u32; 3] {
        self.size
    }

    /// Whether it is a 3D table.
    pub fn is_3d(&self) -> bool {
        self.size[2] > 1
    }

    pub(crate) fn view(&self) -> &wgpu::TextureView {
        &self.view
    }
}
