//! One frame: triangles of any stage streamed in bounded batches into one
//! render target.
//!
//! A [`Frame`] owns the target ([`super::target`]) and a CPU batch (vertex
//! bytes and indices, each capped by [`FrameOptions`]).
//! [`Frame::push_triangles`] takes the triangles of one [`Stage`] with its
//! vertex type ([`GpuVertex`]), validates them (triangles only, indices in
//! range, finite values, the stage's vertex size), appends them with
//! re-based indices, and uploads and draws the batch when the next call
//! would overflow it or names another stage. A call larger than a whole
//! batch is split triangle by triangle (vertices re-indexed per batch), so
//! any input size works with bounded memory. Batches are drawn in
//! submission order by one command encoder each, into reused vertex/index
//! buffers; before submitting batch k+1 the frame waits for batch k-1, so
//! at most two batches (and their staging copies) are alive. The first
//! batch clears the target to transparent black.
//!
//! **Each piece colours a pixel at most once.** Every vertex carries the
//! number of its piece (convex polyhedron) in drawing order, and the
//! target's depth test (less, with write) compares each fragment's piece
//! key ([`super::piece_depth`]): a later piece always passes, a second
//! fragment of a piece at the same pixel centre never does. A piece's
//! region triangles tile its silhouette exactly in `f64`, but their
//! corners are rounded to `f32` and then to the rasteriser's sub-pixel
//! grid; a sliver whose corners cross over on the way folds over its
//! neighbours, and a pixel centre in the fold would be coloured twice.
//! Since the rounded triangles still wind once around every point of the
//! rounded silhouette, each centre there is covered at least once
//! (inverted triangles are drawn, no culling); the depth test makes it
//! exactly once. Piece numbers run on across stages, so a frame can mix
//! stages (a mode's triangles and the layers of cycle groups). [`DrawKind`]
//! selects counting instead of compositing, for the coverage tests.

use std::time::Instant;

use super::device::Context;
use super::raster::GpuVertex;
use super::stage::Stage;
use super::target::Target;
use super::{AccumFormat, GpuError};
use crate::image::Image;

/// Default cap of vertices per batch (10 MiB of vertex data).
pub const DEFAULT_BATCH_VERTICES: usize = 1 << 18;

/// Largest index value any batch may use: llvmpipe (GL) only guarantees
/// index values below 2^24.
const MAX_INDEX_VALUE: usize = (1 << 24) - 1;

/// What a frame's fragments do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
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
    /// Maximum vertices per batch (at least 3; lowered to fit the adapter's
    /// buffer limit and GL's 2^24 index range).
    pub batch_vertices: usize,
    /// Maximum indices per batch (at least 3).
    pub batch_indices: usize,
    /// Compositing, or coverage counting.
    pub draw: DrawKind,
}

impl FrameOptions {
    /// Defaults: batches of 2^18 vertices and 3 * 2^18 indices.
    pub fn new(width: u32, height: u32, format: AccumFormat) -> FrameOptions {
        FrameOptions {
            width,
            height,
            format,
            batch_vertices: DEFAULT_BATCH_VERTICES,
            batch_indices: 3 * DEFAULT_BATCH_VERTICES,
            draw: DrawKind::Composite,
        }
    }
}

/// Counters and timings of a frame (seconds of wall time).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
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
    target: Target,
    draw: DrawKind,
    batch_vertices: usize,
    cap_indices: usize,
    /// Vertices the current batch may hold (by its stage's vertex size).
    cap_vertices: usize,
    /// The stage of the current batch, its vertex size, its vertex bytes
    /// and its indices.
    stage: Option<Stage>,
    stride: usize,
    verts: Vec<u8>,
    nverts: usize,
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
        if opts.batch_vertices < 3 || opts.batch_indices < 3 {
            return Err(GpuError::BadOption("batches need room for one triangle"));
        }
        let format = self.resolve_format(opts.format)?;
        let cap_indices = opts
            .batch_indices
            .min(self.limits().max_buffer_size as usize / 4);
        if cap_indices < 3 {
            return Err(GpuError::BadOption(
                "the adapter's buffer limit is too small",
            ));
        }
        let target = Target::new(self, opts.width, opts.height, format)?;
        self.check()?;
        Ok(Frame {
            ctx: self,
            target,
            draw: opts.draw,
            batch_vertices: opts.batch_vertices,
            cap_indices,
            cap_vertices: 0,
            stage: None,
            stride: 0,
            verts: Vec::new(),
            nverts: 0,
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
        self.target.format
    }

    /// Statistics so far.
    pub fn stats(&self) -> FrameStats {
        self.stats
    }

    /// Appends triangles of `stage` (`indices` into `vertices`, three per
    /// triangle), to be drawn after everything pushed before. Uploads and
    /// draws full batches, and the batch of another stage first.
    pub fn push_triangles<V: GpuVertex>(
        &mut self,
        stage: &Stage,
        vertices: &[V],
        indices: &[u32],
    ) -> Result<(), GpuError> {
        validate(vertices, indices)?;
        let stride = std::mem::size_of::<V>();
        if stage.desc().vertex.array_stride != stride as u64 {
            return Err(GpuError::BadOption(
                "the vertex type does not match the stage's vertex layout",
            ));
        }
        if indices.is_empty() {
            return Ok(());
        }
        self.stats.triangles += (indices.len() / 3) as u64;
        if self.stage.as_ref().map(|s| s.id) != Some(stage.id) {
            self.flush()?;
            let max_buf = self.ctx.limits().max_buffer_size as usize;
            self.cap_vertices = self
                .batch_vertices
                .min(max_buf / stride)
                .min(MAX_INDEX_VALUE + 1);
            if self.cap_vertices < 3 {
                return Err(GpuError::BadOption(
                    "the adapter's buffer limit is too small",
                ));
            }
            self.stage = Some(stage.clone());
            self.stride = stride;
        }
        if !self.fits(vertices.len(), indices.len()) {
            self.flush()?;
        }
        if self.fits(vertices.len(), indices.len()) {
            let base = self.nverts as u32;
            self.verts.extend_from_slice(bytemuck::cast_slice(vertices));
            self.nverts += vertices.len();
            self.idx.extend(indices.iter().map(|&i| i + base));
            return Ok(());
        }
        self.push_split(vertices, indices)
    }

    fn fits(&self, nv: usize, ni: usize) -> bool {
        self.nverts + nv <= self.cap_vertices && self.idx.len() + ni <= self.cap_indices
    }

    /// Input larger than one batch: copy triangle by triangle, re-indexing
    /// the vertices each batch uses.
    fn push_split<V: GpuVertex>(
        &mut self,
        vertices: &[V],
        indices: &[u32],
    ) -> Result<(), GpuError> {
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
                    remap[i] = self.nverts as u32;
                    self.verts
                        .extend_from_slice(bytemuck::bytes_of(&vertices[i]));
                    self.nverts += 1;
                    touched.push(i);
                }
                self.idx.push(remap[i]);
            }
        }
        Ok(())
    }

    /// Uploads and draws the current batch (no-op when empty).
    pub fn flush(&mut self) -> Result<(), GpuError> {
        let Some(stage) = self.stage.clone() else {
            return Ok(());
        };
        if self.idx.is_empty() {
            return Ok(());
        }
        let t0 = Instant::now();
        self.ctx.check()?;
        let vbytes: &[u8] = &self.verts;
        let ibytes: &[u8] = bytemuck::cast_slice(&self.idx);
        let cap_v = (self.cap_vertices * self.stride) as u64;
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
                label: Some("batch"),
            });
        {
            let mut pass = self.target.begin_pass(&mut encoder, !self.cleared);
            pass.set_pipeline(stage.pipeline(self.ctx, self.target.format, self.draw));
            pass.set_bind_group(0, &stage.bind_group, &[]);
            pass.set_vertex_buffer(0, vbuf.slice(..vbytes.len() as u64));
            pass.set_index_buffer(ibuf.slice(..ibytes.len() as u64), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.idx.len() as u32, 0, 0..1);
        }
        let index = self.ctx.queue.submit([encoder.finish()]);
        self.cleared = true;
        self.stats.batches += 1;
        self.verts.clear();
        self.nverts = 0;
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
            drop(self.target.begin_pass(&mut encoder, true));
            self.ctx.queue.submit([encoder.finish()]);
            self.cleared = true;
        }
        let t = Instant::now();
        self.ctx.wait(None)?;
        self.stats.gpu_wait_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let image = self.target.read(self.ctx)?;
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
        label: Some("batch"),
        size,
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    *slot = Some(b.clone());
    b
}

/// The checks every frame (GPU or CPU twin) makes of its input.
pub(crate) fn validate<V: GpuVertex>(vertices: &[V], indices: &[u32]) -> Result<(), GpuError> {
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
    Ok(())
}
