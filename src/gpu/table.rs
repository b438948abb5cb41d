//! Lookup tables as textures: `R32Float` or `Rgba32Float` texels in a 2D
//! texture, a 3D texture or a 2D-array texture (one layer per plane), read
//! by the shaders with `textureLoad` and filtered by hand in `f32` (so the
//! CPU twins can filter the same way: hardware filtering has 8-bit weights,
//! and GL cannot filter `f32` textures at all).
//!
//! A mode builds its table on the CPU and uploads it ([`Table::upload`],
//! [`Table::upload_rgba`]), or fills it on the GPU from a storage buffer
//! ([`Table::empty_rgba`], [`super::compute::GpuBuffer::copy_to_table`]),
//! and keeps it per device with [`Context::resource`].
//!
//! Sizes are checked against the adapter before anything is allocated
//! ([`Table::check_size`]): a side of zero, or above the adapter's limit for
//! the texture's dimension (3D: 2048 on GL llvmpipe, 4096 on lavapipe;
//! array layers: `max_texture_array_layers`), is refused with
//! [`GpuError::TableSize`], which names the limit.

use super::device::Context;
use super::GpuError;

/// The shape of a table texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TableDim {
    /// `texture_2d<f32>` (`size[2]` is 1).
    D2,
    /// `texture_3d<f32>`.
    D3,
    /// `texture_2d_array<f32>`, `size[2]` layers.
    D2Array,
}

impl TableDim {
    fn name(self) -> &'static str {
        match self {
            TableDim::D2 => "2D texture",
            TableDim::D3 => "3D texture",
            TableDim::D2Array => "2D-array texture",
        }
    }
}

/// A table on the GPU.
#[derive(Debug)]
pub struct Table {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    size: [u32; 3],
    dim: TableDim,
    rgba: bool,
}

impl Table {
    /// Uploads `R32Float` `data`, `size[0]` texels per row, `size[1]` rows
    /// per layer, `size[2]` layers (1 makes a 2D table, more a 3D one), x
    /// fastest.
    pub fn upload(
        ctx: &Context,
        label: &str,
        size: [u32; 3],
        data: &[f32],
    ) -> Result<Table, GpuError> {
        let dim = if size[2] > 1 {
            TableDim::D3
        } else {
            TableDim::D2
        };
        Self::upload_with(ctx, label, dim, size, data, false)
    }

    /// Uploads `Rgba32Float` `data` (four floats per texel, x fastest, then
    /// rows, then layers or slices) as a table of shape `dim`.
    pub fn upload_rgba(
        ctx: &Context,
        label: &str,
        dim: TableDim,
        size: [u32; 3],
        data: &[f32],
    ) -> Result<Table, GpuError> {
        Self::upload_with(ctx, label, dim, size, data, true)
    }

    /// An `Rgba32Float` table of shape `dim` whose texels are still to be
    /// written (zero until then).
    pub fn empty_rgba(
        ctx: &Context,
        label: &str,
        dim: TableDim,
        size: [u32; 3],
    ) -> Result<Table, GpuError> {
        Self::check_size(ctx.limits(), dim, size)?;
        Ok(Self::create(ctx, label, dim, size, true))
    }

    /// Refuses a size the adapter cannot hold: any side zero, a side above
    /// the dimension's limit, more layers than the adapter allows.
    pub fn check_size(
        limits: &wgpu::Limits,
        dim: TableDim,
        size: [u32; 3],
    ) -> Result<(), GpuError> {
        let [w, h, d] = size;
        let (max_side, max_depth, depth_what) = match dim {
            TableDim::D2 => (limits.max_texture_dimension_2d, 1, "layers"),
            TableDim::D3 => (
                limits.max_texture_dimension_3d,
                limits.max_texture_dimension_3d,
                "slices",
            ),
            TableDim::D2Array => (
                limits.max_texture_dimension_2d,
                limits.max_texture_array_layers,
                "layers",
            ),
        };
        let bad = |value: u32, max: u32, what: &'static str| GpuError::TableSize {
            dim: dim.name(),
            what,
            value,
            max,
        };
        for (v, what) in [(w, "width"), (h, "height")] {
            if v == 0 || v > max_side {
                return Err(bad(v, max_side, what));
            }
        }
        if d == 0 || d > max_depth {
            return Err(bad(d, max_depth, depth_what));
        }
        Ok(())
    }

    fn upload_with(
        ctx: &Context,
        label: &str,
        dim: TableDim,
        size: [u32; 3],
        data: &[f32],
        rgba: bool,
    ) -> Result<Table, GpuError> {
        Self::check_size(ctx.limits(), dim, size)?;
        let [w, h, d] = size;
        let per = if rgba { 4 } else { 1 };
        let n = w as usize * h as usize * d as usize * per;
        if data.len() != n {
            return Err(GpuError::BadOption("table size does not match its data"));
        }
        let table = Self::create(ctx, label, dim, size, rgba);
        table.write(ctx, data);
        ctx.check()?;
        Ok(table)
    }

    /// Overwrites every texel of an `Rgba32Float` table with `data`.
    pub fn write_rgba(&self, ctx: &Context, data: &[f32]) -> Result<(), GpuError> {
        let n = self.size.iter().map(|&v| v as usize).product::<usize>() * 4;
        if !self.rgba || data.len() != n {
            return Err(GpuError::BadOption("table size does not match its data"));
        }
        self.write(ctx, data);
        ctx.check()
    }

    fn write(&self, ctx: &Context, data: &[f32]) {
        let per = if self.rgba { 4 } else { 1 };
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(data),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * per * self.size[0]),
                rows_per_image: Some(self.size[1]),
            },
            self.extent(),
        );
    }

    fn create(ctx: &Context, label: &str, dim: TableDim, size: [u32; 3], rgba: bool) -> Table {
        let extent = wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: size[2],
        };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: if dim == TableDim::D3 {
                wgpu::TextureDimension::D3
            } else {
                wgpu::TextureDimension::D2
            },
            format: if rgba {
                wgpu::TextureFormat::Rgba32Float
            } else {
                wgpu::TextureFormat::R32Float
            },
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(match dim {
                TableDim::D2 => wgpu::TextureViewDimension::D2,
                TableDim::D3 => wgpu::TextureViewDimension::D3,
                TableDim::D2Array => wgpu::TextureViewDimension::D2Array,
            }),
            ..Default::default()
        });
        Table {
            texture,
            view,
            size,
            dim,
            rgba,
        }
    }

    pub(crate) fn extent(&self) -> wgpu::Extent3d {
        wgpu::Extent3d {
            width: self.size[0],
            height: self.size[1],
            depth_or_array_layers: self.size[2],
        }
    }

    pub(crate) fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }

    /// Texels per axis.
    pub fn size(&self) -> [u32; 3] {
        self.size
    }

    /// Its shape.
    pub fn dim(&self) -> TableDim {
        self.dim
    }

    /// Whether it is a 3D table.
    pub fn is_3d(&self) -> bool {
        self.dim == TableDim::D3
    }

    /// Whether its texels are RGBA (else one channel).
    pub fn is_rgba(&self) -> bool {
        self.rgba
    }

    pub(crate) fn view(&self) -> &wgpu::TextureView {
        &self.view
    }
}
