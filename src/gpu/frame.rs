//! One frame of the exact mode: streaming triangles in bounded batches.
//!
//! A [`Frame`] owns the accumulation target and a CPU batch (vertices and
//! indices, each capped by [`FrameOptions`]). [`Frame::push_triangles`]
//! validates its input (triangles only, indices in range, finite values),
//! appends it with re-based indices, and uploads and draws the batch when the
//! next call would overflow it. A call larger than a whole batch is split
//! triangle by triangle (vertices re-indexed per batch), so any input size
//! works with bounded memory. Batches are drawn in submission order by one
//! command encoder each, into the same reused vertex/index buffers; before
//! submitting batch k+1 the frame waits for batch k-1, so at most two batches
//! (and their staging copies) are alive. The first batch clears the target to
//! transparent black.
//!
//! **Each piece colours a pixel at most once.** Every vertex carries the
//! number of its piece (convex polyhedron) in drawing order, and the frame
//! keeps a depth target whose test (less, with write) compares each
//! fragment's piece key ([`super::vertex::piece_depth`]): a later piece
//! always passes, a second fragment of a piece at the same pixel centre
//! never does. A piece's region triangles tile its silhouette exactly in
//! `f64`, but their corners are rounded to `f32` and then to the
//! rasteriser's sub-pixel grid; a sliver whose corners cross over on the
//! way folds over its neighbours, and a pixel centre in the fold would be
//! coloured twice. Since the rounded triangles still wind once around every
//! point of the rounded silhouette, each centre there is covered at least
//! once (inverted triangles are drawn, no culling); the depth test makes
//! it exactly once. [`DrawKind`] selects counting instead of compositing,
//! for the coverage tests.

use std::time::Instant;

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use super::context::Context;
use super::exptable::{shader_params, TABLE_N};
use super::readback::read_image;
use super::vertex::{raster_side, ExactVertex, RASTER_BORDER};
use super::{AccumFormat, GpuError};
use crate::image::Image;

/// Default cap of vertices per batch (10 MiB of vertex data).
pub const DEFAULT_BATCH_VERTICES: usize = 1 << 18;

/// Largest index value any batch may use: llvmpipe (GL) only guarantees
/// index values below 2^24.
const MAX_INDEX_VALUE: usize = (1 << 24) - 1;

/// Uniforms of the exact stage. Keep in sync with `Params` in
/// `shaders/exact.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug)]
struct FrameUniforms {
    inv_unit: f32,
    unit: f32,
    scale: f32,
    inv_log_range: f32,
    n: u32,
    _pad: [u32; 3],
}

/// The depth format holding the piece keys.
pub(crate) const PIECE_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// What a frame's fragments do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DrawKind {
    /// Composite the exact integrals back to front ("over"), each piece at
    /// most once per pixel.
    #[default]
    Composite = 0,
    /// Add 1 to red per piece covering a pixel centre (at most once per
    /// piece, as when compositing).
    CountPieces = 1,
    /// Add 1 to red per triangle covering a pixel centre (no depth test):
    /// the raw coverage of the triangulation.
    CountTriangles = 2,
}

/// Options of one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameOptions {
    pub width: u32,
    pub height: u32,
    pub format: AccumFormat,
    /// Length unit for the table's addressing: the shader uses `l / unit` and
    /// `tau * unit` (their product, the optical depth, is unchanged). Choose the
    /// scene's unit distance so both stay within the table's per-axis range
    /// `[0, 1e6]`; the default 1 suits any scene of sane units.
    pub length_unit: f32,
    /// Maximum vertices per batch (at least 3; lowered to fit the adapter's
    /// buffer limit and GL's 2^24 index range).
    pub batch_vertices: usize,
    /// Maximum indices per batch (at least 3).
    pub batch_indices: usize,
    /// Compositing, or coverage counting.
    pub draw: DrawKind,
}

impl FrameOptions {
    /// Defaults: unit 1, batches of 2^18 vertices and 3 * 2^18 indices.
    pub fn new(width: u32, height: u32, format: AccumFormat) -> FrameOptions {
        FrameOptions {
            width,
            height,
            format,
            length_unit: 1.0,
            batch_vertices: DEFAULT_BATCH_VERTICES,
            batch_indices: 3 * DEFAULT_BATCH_VERTICES,
            draw: DrawKind::Composite,
        }
    }
}

/// Counters and timings of a frame (seconds of wall time).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameStats {
    pub batches: usize,
    pub triangles: u64,
    /// Uploading batches: buffer writes, encoding, submission.
    pub upload_s: f64,
    /// Waiting for the GPU to draw (bounded-memory waits and the final wait).
    pub gpu_wait_s: f64,
    /// Copy to the staging buffer, map, unpad and convert.
    pub readback_s: f64,
}

/// A frame being composited; see the module docs.
pub struct Frame<'c> {
    ctx: &'c Context,
    width: u32,
    height: u32,
    format: AccumFormat,
    target: wgpu::Texture,
    view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    draw: DrawKind,
    /// Side of the square viewport ([`raster_side`]).
    side: u32,
    bind_group: wgpu::BindGroup,
    cap_vertices: usize,
    cap_indices: usize,
    verts: Vec<ExactVertex>,
    idx: Vec<u32>,
    vbuf: Option<wgpu::Buffer>,
    ibuf: Option<wgpu::Buffer>,
    cleared: bool,
    in_flight: Option<wgpu::SubmissionIndex>,
    stats: FrameStats,
}

impl Context {
    /// Starts a frame of `width x height` with default options.
    pub fn begin_frame(
        &self,
        width: u32,
        height: u32,
        format: AccumFormat,
    ) -> Result<Frame<'_>, GpuError> {
        self.begin_frame_with(&FrameOptions::new(width, height, format))
    }

    /// Starts a frame (validates size, format and options).
    pub fn begin_frame_with(&self, opts: &FrameOptions) -> Result<Frame<'_>, GpuError> {
        self.check()?;
        let max = self.limits().max_texture_dimension_2d;
        if opts.width == 0 || opts.height == 0 || opts.width > max || opts.height > max {
            return Err(GpuError::BadSize {
                width: opts.width,
                height: opts.height,
                max,
            });
        }
        if !(opts.length_unit > 0.0 && opts.length_unit.is_finite()) {
            return Err(GpuError::BadOption(
                "length_unit must be positive and finite",
            ));
        }
        if opts.batch_vertices < 3 || opts.batch_indices < 3 {
            return Err(GpuError::BadOption("batches need room for one triangle"));
        }
        let format = self.resolve_format(opts.format)?;
        let max_buf = self.limits().max_buffer_size as usize;
        let cap_vertices = opts
            .batch_vertices
            .min(max_buf / std::mem::size_of::<ExactVertex>())
            .min(MAX_INDEX_VALUE + 1);
        let cap_indices = opts.batch_indices.min(max_buf / 4);
        if cap_vertices < 3 || cap_indices < 3 {
            return Err(GpuError::BadOption(
                "the adapter's buffer limit is too small",
            ));
        }

        // The square power-of-two viewport that makes sub-pixel positions
        // exact (`raster_side`), placed `RASTER_BORDER` pixels up and left
        // of the target so that the image is inside it with a border
        // (viewports may extend past the attachment).
        let side = raster_side(opts.width, opts.height);
        if side > max {
            return Err(GpuError::BadSize {
                width: opts.width,
                height: opts.height,
                max: (max / 2).saturating_sub(2 * RASTER_BORDER),
            });
        }
        let target = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("accumulation"),
            size: wgpu::Extent3d {
                width: opts.width,
                height: opts.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: format
                .texture_format()
                .unwrap_or(wgpu::TextureFormat::Rgba16Float),
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = target.create_view(&wgpu::TextureViewDescriptor::default());
        let depth = self.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("piece keys"),
            size: wgpu::Extent3d {
                width: opts.width,
                height: opts.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: PIECE_DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth_view = depth.create_view(&wgpu::TextureViewDescriptor::default());
        let (scale, inv_log_range) = shader_params();
        let uniforms = FrameUniforms {
            inv_unit: 1.0 / opts.length_unit,
            unit: opts.length_unit,
            scale,
            inv_log_range,
            n: TABLE_N,
            _pad: [0; 3],
        };
        let ubuf = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("exact uniforms"),
                contents: bytemuck::bytes_of(&uniforms),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("exact"),
            layout: &self.bind_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: ubuf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&self.table_view),
                },
            ],
        });
        self.check()?;
        Ok(Frame {
            ctx: self,
            width: opts.width,
            height: opts.height,
            format,
            target,
            view,
            depth_view,
            draw: opts.draw,
            side,
            bind_group,
            cap_vertices,
            cap_indices,
            verts: Vec::new(),
            idx: Vec::new(),
            vbuf: None,
            ibuf: None,
            cleared: false,
            in_flight: None,
            stats: FrameStats::default(),
        })
    }
}

impl Frame<'_> {
    /// The resolved accumulation format.
    pub fn format(&self) -> AccumFormat {
        self.format
    }

    /// Statistics so far.
    pub fn stats(&self) -> FrameStats {
        self.stats
    }

    /// Appends triangles (`indices` into `vertices`, three per triangle), to
    /// be drawn after everything pushed before. Uploads and draws full batches.
    pub fn push_triangles(
        &mut self,
        vertices: &[ExactVertex],
        indices: &[u32],
    ) -> Result<(), GpuError> {
        if indices.len() % 3 != 0 {
            return Err(GpuError::NotTriangles(indices.len()));
        }
        if let Some(&index) = indices.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(GpuError::IndexOutOfRange {
                index,
                len: vertices.len(),
            });
        }
        if let Some(k) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(GpuError::NonFiniteVertex(k));
        }
        if indices.is_empty() {
            return Ok(());
        }
        self.stats.triangles += (indices.len() / 3) as u64;
        if !self.fits(vertices.len(), indices.len()) {
            self.flush()?;
        }
        if self.fits(vertices.len(), indices.len()) {
            let base = self.verts.len() as u32;
            self.verts.extend_from_slice(vertices);
            self.idx.extend(indices.iter().map(|&i| i + base));
            return Ok(());
        }
        self.push_split(vertices, indices)
    }

    fn fits(&self, nv: usize, ni: usize) -> bool {
        self.verts.len() + nv <= self.cap_vertices && self.idx.len() + ni <= self.cap_indices
    }

    /// Input larger than one batch: copy triangle by triangle, re-indexing
    /// the vertices each batch uses.
    fn push_split(&mut self, vertices: &[ExactVertex], indices: &[u32]) -> Result<(), GpuError> {
        let mut remap = vec![u32::MAX; vertices.len()];
        let mut touched: Vec<usize> = Vec::new();
        for tri in indices.chunks_exact(3) {
            let new = tri
                .iter()
                .filter(|&&i| remap[i as usize] == u32::MAX)
                .count();
            if !self.fits(new, 3) {
                self.flush()?;
                for t in touched.drain(..) {
                    remap[t] = u32::MAX;
                }
            }
            for &i in tri {
                let i = i as usize;
                if remap[i] == u32::MAX {
                    remap[i] = self.verts.len() as u32;
                    self.verts.push(vertices[i]);
                    touched.push(i);
                }
                self.idx.push(remap[i]);
            }
        }
        Ok(())
    }

    /// Uploads and draws the current batch (no-op when empty).
    pub fn flush(&mut self) -> Result<(), GpuError> {
        if self.idx.is_empty() {
            return Ok(());
        }
        let t0 = Instant::now();
        self.ctx.check()?;
        let vbytes: &[u8] = bytemuck::cast_slice(&self.verts);
        let ibytes: &[u8] = bytemuck::cast_slice(&self.idx);
        let cap_v = (self.cap_vertices * std::mem::size_of::<ExactVertex>()) as u64;
        let cap_i = (self.cap_indices * 4) as u64;
        let vbuf = ensure_buffer(
            self.ctx,
            &mut self.vbuf,
            vbytes.len() as u64,
            cap_v,
            wgpu::BufferUsages::VERTEX,
        );
        let ibuf = ensure_buffer(
            self.ctx,
            &mut self.ibuf,
            ibytes.len() as u64,
            cap_i,
            wgpu::BufferUsages::INDEX,
        );
        self.ctx.queue.write_buffer(&vbuf, 0, vbytes);
        self.ctx.queue.write_buffer(&ibuf, 0, ibytes);
        let mut encoder = self
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("exact batch"),
            });
        {
            let mut pass = self.begin_pass(&mut encoder);
            pass.set_pipeline(self.ctx.pipeline(self.format, self.draw));
            let (b, side) = (RASTER_BORDER as f32, self.side as f32);
            pass.set_viewport(-b, -b, side, side, 0.0, 1.0);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.set_vertex_buffer(0, vbuf.slice(..vbytes.len() as u64));
            pass.set_index_buffer(ibuf.slice(..ibytes.len() as u64), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.idx.len() as u32, 0, 0..1);
        }
        let index = self.ctx.queue.submit([encoder.finish()]);
        self.cleared = true;
        self.stats.batches += 1;
        self.verts.clear();
        self.idx.clear();
        self.stats.upload_s += t0.elapsed().as_secs_f64();
        // Bounded memory: at most two batches in flight.
        if let Some(prev) = self.in_flight.replace(index) {
            let t1 = Instant::now();
            self.ctx.wait(Some(prev))?;
            self.stats.gpu_wait_s += t1.elapsed().as_secs_f64();
        }
        self.ctx.check()
    }

    fn begin_pass<'e>(&self, encoder: &'e mut wgpu::CommandEncoder) -> wgpu::RenderPass<'e> {
        let (load, depth_load) = if self.cleared {
            (wgpu::LoadOp::Load, wgpu::LoadOp::Load)
        } else {
            (
                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                wgpu::LoadOp::Clear(1.0),
            )
        };
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("exact"),
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
        })
    }

    /// Draws what is left, waits for the GPU and reads the image back
    /// (linear premultiplied RGBA f32, row 0 at the top).
    pub fn finish(self) -> Result<Image, GpuError> {
        Ok(self.finish_with_stats()?.0)
    }

    /// [`Self::finish`], also returning the frame's statistics.
    pub fn finish_with_stats(mut self) -> Result<(Image, FrameStats), GpuError> {
        self.flush()?;
        if !self.cleared {
            let mut encoder =
                self.ctx
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("clear"),
                    });
            drop(self.begin_pass(&mut encoder));
            self.ctx.queue.submit([encoder.finish()]);
            self.cleared = true;
        }
        let t = Instant::now();
        self.ctx.wait(None)?;
        self.stats.gpu_wait_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let image = read_image(self.ctx, &self.target, self.width, self.height, self.format)?;
        self.stats.readback_s += t.elapsed().as_secs_f64();
        Ok((image, self.stats))
    }
}

/// Returns a buffer of at least `need` bytes, reusing `slot` when it is large
/// enough; new buffers grow in powers of two up to `cap`.
fn ensure_buffer(
    ctx: &Context,
    slot: &mut Option<wgpu::Buffer>,
    need: u64,
    cap: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    if let Some(b) = slot {
        if b.size() >= need {
            return b.clone();
        }
    }
    let size = need.next_power_of_two().min(cap).max(need);
    let size = size.div_ceil(wgpu::COPY_BUFFER_ALIGNMENT) * wgpu::COPY_BUFFER_ALIGNMENT;
    let b = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("exact batch"),
        size,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    *slot = Some(b.clone());
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniforms_match_wgsl_params() {
        let module = naga::front::wgsl::parse_str(super::super::EXACT_WGSL).unwrap();
        let (members, span) = module
            .types
            .iter()
            .find_map(|(_, t)| match (&t.name, &t.inner) {
                (Some(n), naga::TypeInner::Struct { members, span }) if n == "Params" => {
                    Some((members.clone(), *span))
                }
                _ => None,
            })
            .expect("struct Params");
        assert_eq!(span as usize, std::mem::size_of::<FrameUniforms>());
        let offs: Vec<(String, u32)> = members
            .iter()
            .take(5)
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
            .collect();
        let want = [
            ("inv_unit", std::mem::offset_of!(FrameUniforms, inv_unit)),
            ("unit", std::mem::offset_of!(FrameUniforms, unit)),
            ("scale", std::mem::offset_of!(FrameUniforms, scale)),
            (
                "inv_log_range",
                std::mem::offset_of!(FrameUniforms, inv_log_range),
            ),
            ("n", std::mem::offset_of!(FrameUniforms, n)),
        ];
        let want: Vec<(String, u32)> = want
            .iter()
            .map(|(n, o)| (n.to_string(), *o as u32))
            .collect();
        assert_eq!(offs, want);
    }
}
