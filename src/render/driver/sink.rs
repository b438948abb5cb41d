//! Where a frame's triangles go: the GPU frame with the mode's stage and
//! the layer stage, or the CPU twin ([`Sink`]); chunks handed over in
//! order, their pieces numbered frame-wide ([`push_out`]); the image and
//! the GPU's figures at the end ([`finish`]).

use std::time::Instant;

use crate::gpu::cpu::{CpuFrame, CpuStage};
use crate::gpu::layer::{LayerTwin, LayerVertex};
use crate::gpu::{Frame, FrameStats, GpuError, GpuVertex, Stage, MAX_PIECES};
use crate::image::Image;

use super::super::stats::ProjectedStats;
use super::super::RenderError;
use super::kept::KeptProjection;
use super::ChunkOut;

/// Where a frame's triangles go: the GPU, or its CPU twin; with the mode's
/// stage and the layer stage.
pub(super) enum Sink<'c, V> {
    Gpu {
        frame: Box<Frame<'c>>,
        stage: Stage,
        layer: Stage,
    },
    Cpu {
        frame: Box<CpuFrame>,
        twin: Box<dyn CpuStage<V>>,
    },
}

impl<V: GpuVertex> Sink<'_, V> {
    pub(super) fn push(&mut self, vertices: &[V], indices: &[u32]) -> Result<(), GpuError> {
        match self {
            Sink::Gpu { frame, stage, .. } => frame.push_triangles(stage, vertices, indices),
            Sink::Cpu { frame, twin } => frame.push_triangles(twin.as_ref(), vertices, indices),
        }
    }

    pub(super) fn push_layer(
        &mut self,
        vertices: &[LayerVertex],
        indices: &[u32],
    ) -> Result<(), GpuError> {
        match self {
            Sink::Gpu { frame, layer, .. } => frame.push_triangles(layer, vertices, indices),
            Sink::Cpu { frame, .. } => frame.push_triangles(&LayerTwin, vertices, indices),
        }
    }
}

/// Frame-wide piece numbers: the next one, and the rebasing of a chunk's.
pub(super) fn take_pieces(next_piece: &mut u32, count: u32) -> Result<u32, RenderError> {
    let base = *next_piece;
    *next_piece = base
        .checked_add(count)
        .filter(|&n| n <= MAX_PIECES)
        .ok_or(RenderError::TooManyPieces(MAX_PIECES))?;
    Ok(base)
}

/// Sends one chunk's triangles to the frame and adds up its counts; its
/// pieces are numbered on from `next_piece` (drawing order).
pub(super) fn push_out<V: GpuVertex>(
    sink: &mut Sink<V>,
    out: &mut ChunkOut<V>,
    stats: &mut ProjectedStats,
    next_piece: &mut u32,
    record: Option<&mut KeptProjection>,
) -> Result<(), RenderError> {
    if let Some(e) = out.error.take() {
        return Err(e.into());
    }
    let base = take_pieces(next_piece, out.pieces)?;
    if base > 0 {
        for v in &mut out.vertices {
            *v = v.with_piece(v.piece() + base);
        }
    }
    stats.culled_pieces += out.culled;
    stats.slabs += out.slabs;
    stats.refined_triangles += out.refined;
    stats.tie_pixels += out.tie_pixels;
    stats.steep_triangles += out.steep;
    stats.thin_outlines += out.thin;
    stats.whole_pieces += out.whole;
    stats.whole_hulls += out.hulls;
    stats.regions_reused += out.regions_reused;
    stats.triangles += out.indices.len() / 3;
    sink.push(&out.vertices, &out.indices)?;
    if let Some(r) = record {
        r.record(&out.vertices, &out.indices);
    }
    Ok(())
}

/// Finishes the frame of `sink`: the image, and the GPU's figures in
/// `stats` (`project_s` spent projecting and drawing since `t_gpu`).
pub(super) fn finish<V: GpuVertex>(
    sink: Sink<V>,
    mut stats: ProjectedStats,
    project_s: f64,
    t_gpu: Instant,
) -> Result<(Image, ProjectedStats), RenderError> {
    let (image, fstats) = match sink {
        Sink::Gpu { frame, .. } => frame.finish_with_stats()?,
        Sink::Cpu { frame, .. } => {
            stats.watched = frame.covering().to_vec();
            let fs = FrameStats {
                triangles: frame.triangles(),
                ..Default::default()
            };
            (frame.finish(), fs)
        }
    };
    stats.gpu = fstats;
    stats.project_s = project_s;
    stats.gpu_total_s = t_gpu.elapsed().as_secs_f64() - project_s;
    Ok((image, stats))
}
