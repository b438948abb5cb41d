//! A frame's triangles kept for the next frame that differs only in the
//! transfer function's colours ([`super::super::ProjectedOptions::keep_projection`]):
//! that frame draws them again with its own stage (its transfer function,
//! its table) and neither sorts nor projects.
//!
//! **What the triangles depend on.** The modes on the segment payload
//! (exact-frag and the table modes) send each vertex its position, its
//! front and back scalars and its thickness, with the scalars normalised to
//! the transfer function's node range: no colour. Apart from that map, the
//! transfer function decides *which* triangles are drawn, in three places:
//! - pieces whose scalar range maps to zero extinction are skipped (dark);
//! - pieces behind opaque ones are skipped (occlusion, the least
//!   extinction on a cell's range);
//! - the tie decisions draw exact pixel triangles inside slivers and steep
//!   triangles where the snap could matter at the piece's largest rate,
//!   `max(extinction, |source|)`.
//!
//! With glow emission the source is extinction times colour, so where every
//! colour channel is at most 1 the rate is the extinction. A transfer
//! function with the same nodes, the same extinction on both sides of each,
//! glow emission and colours at most 1 therefore gives the same triangles,
//! bit for bit: [`stream_signature`] is that part of it, and a frame whose
//! signature, order, geometry, field, camera and options are those of the
//! kept frame is drawn from the kept triangles. The image is the one a fresh
//! render gives (`tests/keep_projection.rs`). Anything else (independent
//! emission, a colour above 1, new extinction) renders afresh.
//!
//! Frames with a cycle group (composited on the CPU with the colours) or
//! isosurfaces are never kept, and neither is a frame whose triangles take
//! more than [`KEEP_MAX_BYTES`].

use std::any::TypeId;
use std::sync::Arc;

use crate::camera::Camera;
use crate::field::ScalarField;
use crate::mesh::Mesh;
use crate::tf::{EmissionModel, TransferFunction};
use crate::visibility::Order;

use super::super::{ProjectedOptions, ProjectedStats};

/// The most a kept frame may hold (vertices and indices), bytes.
pub const KEEP_MAX_BYTES: usize = 1 << 30;

/// The part of `tf` the segment payload's triangles depend on (module
/// docs), or `None` where they depend on all of it.
pub fn stream_signature(tf: &TransferFunction) -> Option<Vec<u64>> {
    if tf.model() != EmissionModel::Glow || tf.col.iter().flatten().any(|&c| c > 1.0 || c.is_nan())
    {
        return None;
    }
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let mut sig = vec![tf.s.len() as u64];
    sig.extend(bits(&tf.s));
    sig.extend(bits(&tf.tau));
    sig.push(tf.breaks.len() as u64);
    sig.extend(bits(&tf.breaks));
    Some(sig)
}

/// What a kept frame was drawn for.
#[derive(Clone)]
pub struct KeepKey {
    /// The mode's type name.
    pub mode: &'static str,
    pub order: Arc<Order>,
    pub mesh: Arc<Mesh>,
    pub field: Option<Arc<ScalarField>>,
    pub camera: Camera,
    pub options: ProjectedOptions,
    pub unit_distance: u64,
    pub tf: Vec<u64>,
}

impl KeepKey {
    /// Whether a frame of `self` may draw what `kept` drew.
    fn matches(&self, kept: &KeepKey) -> bool {
        let field = match (&self.field, &kept.field) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        };
        self.mode == kept.mode
            && Arc::ptr_eq(&self.order, &kept.order)
            && Arc::ptr_eq(&self.mesh, &kept.mesh)
            && field
            && self.camera == kept.camera
            && self.options == kept.options
            && self.unit_distance == kept.unit_distance
            && self.tf == kept.tf
    }
}

/// The counts of the kept frame, reported again when it is drawn.
#[derive(Clone, Copy, Debug, Default)]
pub struct KeptCounts {
    pub culled_pieces: usize,
    pub slabs: usize,
    pub refined_triangles: usize,
    pub tie_pixels: usize,
    pub thin_outlines: usize,
    pub steep_triangles: usize,
    pub triangles: usize,
    pub hidden_pieces: usize,
    pub occlusion_nodes_hidden: usize,
    pub hidden_by_nodes: usize,
}

impl KeptCounts {
    /// The counts of a frame's statistics.
    pub fn of(s: &ProjectedStats) -> KeptCounts {
        KeptCounts {
            culled_pieces: s.culled_pieces,
            slabs: s.slabs,
            refined_triangles: s.refined_triangles,
            tie_pixels: s.tie_pixels,
            thin_outlines: s.thin_outlines,
            steep_triangles: s.steep_triangles,
            triangles: s.triangles,
            hidden_pieces: s.hidden_pieces,
            occlusion_nodes_hidden: s.occlusion_nodes_hidden,
            hidden_by_nodes: s.hidden_by_nodes,
        }
    }

    /// Writes them into the statistics of a frame that drew the kept
    /// triangles, and says so.
    pub fn restore(&self, s: &mut ProjectedStats) {
        s.culled_pieces = self.culled_pieces;
        s.slabs = self.slabs;
        s.refined_triangles = self.refined_triangles;
        s.tie_pixels = self.tie_pixels;
        s.thin_outlines = self.thin_outlines;
        s.steep_triangles = self.steep_triangles;
        s.triangles = self.triangles;
        s.hidden_pieces = self.hidden_pieces;
        s.occlusion_nodes_hidden = self.occlusion_nodes_hidden;
        s.hidden_by_nodes = self.hidden_by_nodes;
        s.projection_reused = true;
    }
}

/// A frame's triangles as they went to the GPU, batch by batch.
pub struct KeptProjection {
    pub key: KeepKey,
    /// The vertex type of `vertices`.
    vertex: Option<TypeId>,
    /// The vertices' bytes (the mode's vertex type, which `key.mode`
    /// fixes), with the frame's piece numbers.
    vertices: Vec<u8>,
    indices: Vec<u32>,
    /// The end of each batch in `vertices` (bytes) and `indices`.
    batches: Vec<(usize, usize)>,
    pub counts: KeptCounts,
    /// Past [`KEEP_MAX_BYTES`]: dropped.
    full: bool,
}

impl KeptProjection {
    /// An empty record for a frame of `key`.
    pub fn new(key: KeepKey) -> KeptProjection {
        KeptProjection {
            key,
            vertex: None,
            vertices: Vec::new(),
            indices: Vec::new(),
            batches: Vec::new(),
            counts: KeptCounts::default(),
            full: false,
        }
    }

    /// Records one batch, unless the record is past its cap.
    pub fn record<V: bytemuck::Pod>(&mut self, vertices: &[V], indices: &[u32]) {
        let ty = TypeId::of::<V>();
        if *self.vertex.get_or_insert(ty) != ty {
            self.full = true;
        }
        let bytes: &[u8] = bytemuck::cast_slice(vertices);
        let size = self.vertices.len() + bytes.len() + 4 * (self.indices.len() + indices.len());
        if self.full || size > KEEP_MAX_BYTES {
            self.full = true;
            self.vertices = Vec::new();
            self.indices = Vec::new();
            self.batches = Vec::new();
            return;
        }
        self.vertices.extend_from_slice(bytes);
        self.indices.extend_from_slice(indices);
        self.batches.push((self.vertices.len(), self.indices.len()));
    }

    /// The record, if it holds the whole frame.
    pub fn complete(self) -> Option<KeptProjection> {
        (!self.full).then_some(self)
    }

    /// The kept batches, for a frame of `key`, as the vertex type `V`;
    /// `None` where the key differs.
    pub fn batches_for<V: bytemuck::Pod>(&self, key: &KeepKey) -> Option<Vec<(&[V], &[u32])>> {
        if !key.matches(&self.key) || self.vertex.is_some_and(|t| t != TypeId::of::<V>()) {
            return None;
        }
        let (mut v0, mut i0) = (0, 0);
        let mut out = Vec::with_capacity(self.batches.len());
        for &(v1, i1) in &self.batches {
            let v: &[V] = bytemuck::try_cast_slice(&self.vertices[v0..v1]).ok()?;
            out.push((v, &self.indices[i0..i1]));
            (v0, i0) = (v1, i1);
        }
        Some(out)
    }
}
