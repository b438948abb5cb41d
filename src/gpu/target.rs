//! The render target of a frame: the accumulation texture (premultiplied
//! RGBA, [`AccumFormat`]), the depth texture of piece keys, the square
//! viewport that makes sub-pixel positions exact, and the read-back.

use super::device::Context;
use super::raster::{raster_side, RASTER_BORDER};
use super::readback::read_image;
use super::stage::PIECE_DEPTH_FORMAT;
use super::{AccumFormat, GpuError};
use crate::image::Image;

/// Accumulation and piece-key textures of one `width x height` image.
pub(crate) struct Target {
    pub(crate) width: u32,
    pub(crate) height: u32,
    /// The resolved accumulation format.
    pub(crate) format: AccumFormat,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    /// Side of the square viewport ([`raster_side`]).
    side: u32,
}

impl Target {
    /// Makes the textures (validates the size; `format` resolved).
    pub(crate) fn new(
        ctx: &Context,
        width: u32,
        height: u32,
        format: AccumFormat,
    ) -> Result<Target, GpuError> {
        let max = ctx.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(GpuError::BadSize { width, height, max });
        }
        // The square power-of-two viewport that makes sub-pixel positions
        // exact (`raster_side`), placed `RASTER_BORDER` pixels up and left
        // of the target so that the image is inside it with a border
        // (viewports may extend past the attachment).
        let side = raster_side(width, height);
        if side > max {
            return Err(GpuError::BadSize {
                width,
                height,
                max: (max / 2).saturating_sub(2 * RASTER_BORDER),
            });
        }
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("accumulation"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: format
                .texture_format()
                .unwrap_or(wgpu::TextureFormat::Rgba16Float),
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let depth = ctx.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("piece keys"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: PIECE_DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
        Ok(Target {
            width,
            height,
            format,
            texture,
            view,
            depth_view,
            side,
        })
    }

    /// A render pass into the target, clearing it first when `clear`
    /// (transparent black, piece keys 1), with the square viewport set.
    pub(crate) fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        clear: bool,
    ) -> wgpu::RenderPass<'e> {
        let (load, depth_load) = if clear {
            (
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                wgpu::LoadOp::Clear(1.0),
            )
        } else {
            (wgpu::LoadOp::Load, wgpu::LoadOp::Load)
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: depth_load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let (b, side) = (RASTER_BORDER as f32, self.side as f32);
        pass.set_viewport(-b, -b, side, side, 0.0, 1.0);
        pass
    }

    /// Reads the image back (linear premultiplied RGBA f32, row 0 at the
    /// top).
    pub(crate) fn read(&self, ctx: &Context) -> Result<Image, GpuError> {
        read_image(ctx, &self.texture, self.width, self.height, self.format)
    }
}
