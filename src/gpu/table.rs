//! Lookup tables as read-only storage buffers: `f32` texels (one channel,
//! WGSL `array<f32>`) or RGBA texels (`array<vec4<f32>>`), x fastest, then
//! rows, then layers or slices, read by the shaders by index and filtered
//! by hand in `f32` (so the CPU twins filter the same way: hardware
//! filtering has 8-bit weights, and GL cannot filter `f32` textures at
//! all).
//!
//! Why buffers and not textures: on the software rasterisers a texel fetch
//! goes through the sampler's general path (format, bounds and layout per
//! fetch), a buffer load is one gather; the 3D table's eight loads per
//! fragment made the `preint3d` frame 16 % slower as texture fetches
//! (hex_shell, 512^2, lavapipe). A GPU build writes the table's buffer in
//! place ([`Table::buffer`]), with no copy into a texture.
//!
//! A mode builds its table on the CPU and uploads it ([`Table::upload`],
//! [`Table::upload_rgba`]), or fills it on the GPU
//! ([`Table::empty_rgba`], then a compute pass on [`Table::buffer`]), and
//! keeps it per device with [`Context::resource`].
//!
//! Sizes are checked against the adapter before anything is allocated
//! ([`Table::check_size`]): a side of zero, or a table larger than one
//! storage-buffer binding of the adapter (`max_storage_buffer_binding_size`:
//! 128 MiB on lavapipe and GL llvmpipe, a 203^3 RGBA table), is refused
//! with [`GpuError::TableSize`] or [`GpuError::TableBytes`], which name the
//! limit.

use super::compute::GpuBuffer;
use super::device::Context;
use super::GpuError;

/// The shape of a table (how its shader indexes it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TableDim {
    /// One layer (`size[2]` is 1).
    D2,
    /// A volume of `size[2]` slices, interpolated between them.
    D3,
    /// `size[2]` separate layers (planes).
    D2Array,
}

impl TableDim {
    fn name(self) -> &'static str {
        match self {
            TableDim::D2 => "2D table",
            TableDim::D3 => "3D table",
            TableDim::D2Array => "layered table",
        }
    }
}

/// A table on the GPU.
#[derive(Debug)]
pub struct Table {
    buffer: GpuBuffer,
    size: [u32; 3],
    dim: TableDim,
    rgba: bool,
}

impl Table {
    /// Uploads `f32` `data`, `size[0]` texels per row, `size[1]` rows per
    /// layer, `size[2]` layers (1 makes a 2D table, more a 3D one), x
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

    /// Uploads RGBA `data` (four floats per texel, x fastest, then rows,
    /// then layers or slices) as a table of shape `dim`.
    pub fn upload_rgba(
        ctx: &Context,
        label: &str,
        dim: TableDim,
        size: [u32; 3],
        data: &[f32],
    ) -> Result<Table, GpuError> {
        Self::upload_with(ctx, label, dim, size, data, true)
    }

    /// An RGBA table of shape `dim` whose texels are still to be written
    /// (zero until then).
    pub fn empty_rgba(
        ctx: &Context,
        label: &str,
        dim: TableDim,
        size: [u32; 3],
    ) -> Result<Table, GpuError> {
        Self::create(ctx, label, dim, size, true)
    }

    /// Bytes of an RGBA table of `size`.
    fn rgba_bytes(size: [u32; 3]) -> u64 {
        size.iter().map(|&v| v as u64).product::<u64>() * 16
    }

    /// Refuses an RGBA table the adapter cannot hold: any side zero, or
    /// more bytes than one storage-buffer binding.
    pub fn check_size(
        limits: &wgpu::Limits,
        dim: TableDim,
        size: [u32; 3],
    ) -> Result<(), GpuError> {
        Self::check_bytes(limits, dim, size, Self::rgba_bytes(size))
    }

    fn check_bytes(
        limits: &wgpu::Limits,
        dim: TableDim,
        size: [u32; 3],
        bytes: u64,
    ) -> Result<(), GpuError> {
        for (v, what) in size.into_iter().zip(["width", "height", "depth"]) {
            if v == 0 {
                return Err(GpuError::TableSize {
                    dim: dim.name(),
                    what,
                    value: v,
                });
            }
        }
        let max = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        if bytes > max {
            return Err(GpuError::TableBytes {
                dim: dim.name(),
                size,
                mib: bytes as f64 / (1u64 << 20) as f64,
                max_mib: max as f64 / (1u64 << 20) as f64,
            });
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
        let per = if rgba { 4 } else { 1 };
        let n = size.iter().map(|&v| v as usize).product::<usize>() * per;
        if data.len() != n {
            return Err(GpuError::BadOption("table size does not match its data"));
        }
        let table = Self::create(ctx, label, dim, size, rgba)?;
        table.buffer.write(ctx, bytemuck::cast_slice(data));
        ctx.check()?;
        Ok(table)
    }

    /// Overwrites every texel of an RGBA table with `data`.
    pub fn write_rgba(&self, ctx: &Context, data: &[f32]) -> Result<(), GpuError> {
        let n = self.texels() * 4;
        if !self.rgba || data.len() != n {
            return Err(GpuError::BadOption("table size does not match its data"));
        }
        self.buffer.write(ctx, bytemuck::cast_slice(data));
        ctx.check()
    }

    fn create(
        ctx: &Context,
        label: &str,
        dim: TableDim,
        size: [u32; 3],
        rgba: bool,
    ) -> Result<Table, GpuError> {
        let per = if rgba { 16 } else { 4 };
        let bytes = size.iter().map(|&v| v as u64).product::<u64>() * per;
        Self::check_bytes(ctx.limits(), dim, size, bytes)?;
        Ok(Table {
            buffer: GpuBuffer::new(ctx, label, bytes)?,
            size,
            dim,
            rgba,
        })
    }

    /// The texels (x fastest; four floats each where RGBA), read back
    /// (waits for the queue; tests and twins).
    pub fn read(&self, ctx: &Context) -> Result<Vec<f32>, GpuError> {
        let bytes = self.buffer.read(ctx)?;
        let per = if self.rgba { 4 } else { 1 };
        let n = self.texels() * per;
        Ok(bytes
            .chunks_exact(4)
            .take(n)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }

    /// Its storage buffer, which a compute pass may write in place (the
    /// layout of the module docs, no padding).
    pub fn buffer(&self) -> &GpuBuffer {
        &self.buffer
    }

    fn texels(&self) -> usize {
        self.size.iter().map(|&v| v as usize).product()
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
}
