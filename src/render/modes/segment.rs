//! The payload the segment modes share (exact-frag and the pre-integrated
//! table modes): per region vertex, what the fragment needs to rebuild its
//! own ray segment through the piece — front scalar `s_f`, back scalar
//! `s_b` and length `l` — exactly, in orthographic and perspective views.
//! `shaders/segment.wgsl` is the GPU side (vertex format, view uniform,
//! `segment_at`); this module is its Rust mirror and CPU twin.
//!
//! How the values stay exact: a region lies under one front and one back
//! boundary triangle ([`crate::projection`]), on which the scalar is linear
//! in space. In orthographic views `s_f`, `s_b` and `l` are then affine in
//! screen position and are sent as they are. In perspective views `s q` and
//! `q = 1/z` are affine in screen position (z the view depth of the entry
//! or exit point), and so is `q_f - q_b`; the vertex carries those, the
//! rasteriser interpolates them linearly (`w = 1`), and the fragment
//! divides: `s = (s q) / q`, `l = (q_f - q_b) / (q_f q_b) |ray|`, where
//! `|ray| = sqrt(1 + |u|^2)` is the ray length per unit depth at the
//! fragment's view-plane position `u`. No perspective refinement of the
//! regions is needed ([`SegmentVertex::needs_perspective_refinement`]).
//!
//! Scalars are normalised to the transfer function's node range
//! ([`ScalarMap`]) before they are rounded to `f32`, so data with a large
//! offset keeps its resolution where the transfer function changes.
//!
//! A mode on this payload implements [`SegmentMode`] (its stage and its
//! twin's bindings); the rest of its [`ProjectedMode`] (no slicing, no
//! perspective refinement, [`SegmentPayload`] and [`SegmentVertex::of`])
//! is held here once.

use bytemuck::{Pod, Zeroable};

use crate::camera::Camera;
use crate::gpu::cpu::{lerp, CpuStage};
use crate::gpu::{ClipMapper, Context, GpuError, GpuVertex, Stage};
use crate::projection::{Polyhedron, Projected, ViewMap};
use crate::render::driver::ProjectedMode;
use crate::render::pieces::PieceSource;

pub use super::segment_view::segment_of;
use crate::tf::TransferFunction;

/// Normalised scalars beyond this magnitude are clamped (they lie far in the
/// transfer function's constant extension; `f32` would overflow).
const MAX_NORMALISED: f64 = 1e30;

/// One vertex of the segment modes. Keep in sync with `VertexIn` in
/// `shaders/segment.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentVertex {
    /// Clip-space position (x, y, z, w), `w = 1`.
    pub pos: [f32; 4],
    /// `(s_f, 1)` (orthographic) or `(s_f q_f, q_f)` (perspective).
    pub front: [f32; 2],
    /// `(s_b, 1)` or `(s_b q_b, q_b)`.
    pub back: [f32; 2],
    /// `l` (orthographic) or `q_f - q_b` (perspective).
    pub thick: f32,
    /// The piece its triangles belong to ([`crate::gpu::piece_depth`]).
    pub piece: u32,
}

impl SegmentVertex {
    /// Vertex attributes (`@location`s of `VertexIn`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 5] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Float32x2,
        2 => Float32x2,
        3 => Float32,
        4 => Uint32,
    ];

    /// The vertex buffer layout of the segment stages.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<SegmentVertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &SegmentVertex::ATTRIBUTES,
    };

    /// Whether regions must be refined for screen-linear interpolation in
    /// perspective views: no, the values above interpolate exactly.
    pub const fn needs_perspective_refinement() -> bool {
        false
    }

    /// Vertex `i` of `proj` at snapped NDC `ndc`, with scalars through `map`.
    pub fn of(proj: &Projected, i: usize, ndc: [f32; 2], map: &ScalarMap, ortho: bool) -> Self {
        let v = &proj.vertices[i];
        let (sf, sb) = (map.apply(v.s_front), map.apply(v.s_back));
        let pos = [ndc[0], ndc[1], 0.5, 1.0];
        if ortho {
            return SegmentVertex {
                pos,
                front: [sf as f32, 1.0],
                back: [sb as f32, 1.0],
                thick: v.l.max(0.0) as f32,
                piece: 0,
            };
        }
        // The near plane keeps depths positive; a point that is not (never
        // from the projection) gets the empty segment.
        let (zf, zb) = (v.z_front, v.z_back.max(v.z_front));
        if !(zf > 0.0 && zb.is_finite()) {
            return SegmentVertex {
                pos,
                front: [sf as f32, 1.0],
                back: [sb as f32, 1.0],
                thick: 0.0,
                piece: 0,
            };
        }
        let (qf, qb) = (1.0 / zf, 1.0 / zb);
        SegmentVertex {
            pos,
            front: [(sf * qf) as f32, qf as f32],
            back: [(sb * qb) as f32, qb as f32],
            thick: ((zb - zf) / (zf * zb)) as f32,
            piece: 0,
        }
    }
}

impl GpuVertex for SegmentVertex {
    fn clip(&self) -> [f32; 4] {
        self.pos
    }
    fn piece(&self) -> u32 {
        self.piece
    }
    fn with_piece(self, piece: u32) -> Self {
        SegmentVertex { piece, ..self }
    }
    fn is_finite(&self) -> bool {
        self.pos.iter().all(|v| v.is_finite())
            && self.front.iter().all(|v| v.is_finite())
            && self.back.iter().all(|v| v.is_finite())
            && self.thick.is_finite()
    }
    fn with_clip(self, pos: [f32; 4]) -> Self {
        SegmentVertex { pos, ..self }
    }
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self {
        SegmentVertex {
            front: [0, 1].map(|k| lerp(tri, bary, |v| v.front[k])),
            back: [0, 1].map(|k| lerp(tri, bary, |v| v.back[k])),
            thick: lerp(tri, bary, |v| v.thick),
            ..*tri[0]
        }
    }
    fn transparent(self) -> Self {
        // l = 0: the empty segment.
        SegmentVertex { thick: 0.0, ..self }
    }
}

/// The affine map sending data scalars to the values the segment stages
/// see: the transfer function's first node to 0 and its last to 1 (a
/// single-node or non-finite range keeps the unit scale), or with that
/// scale the middle of the isovalues to 0 ([`ScalarMap::centred`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalarMap {
    pub offset: f64,
    pub scale: f64,
}

impl ScalarMap {
    /// The map of `tf`.
    pub fn of(tf: &TransferFunction) -> ScalarMap {
        let (lo, hi) = tf.scalar_range();
        let span = hi - lo;
        let scale = if span > 0.0 && span.is_finite() {
            1.0 / span
        } else {
            1.0
        };
        ScalarMap { offset: lo, scale }
    }

    /// The map of `tf`'s scale with the middle of the sorted `values`'
    /// range sent to 0 instead of the first node (`tf`'s map without
    /// values): for the isosurface stages, whose crossings and closed-form
    /// integral take any origin (a table volume's lookups add the origin's
    /// place in the table: `modes::iso::IsoMode::table_offset`). An `f32` scalar
    /// rounds relative to its distance from the origin, and the stages'
    /// levels lie [`crate::numeric::tolerance::ISO_LEVEL_F32`] of it below
    /// the values, so an origin among the values keeps both small next to
    /// the surfaces: with the first node of a field from -10,000 to 30,000
    /// as origin, a surface at 25 was drawn 0.01 below its value, more
    /// than a pixel where the field changes slowly.
    pub fn centred(tf: &TransferFunction, values: &[f64]) -> ScalarMap {
        let map = ScalarMap::of(tf);
        match (values.first(), values.last()) {
            (Some(&lo), Some(&hi)) if lo.is_finite() && hi.is_finite() => ScalarMap {
                offset: 0.5 * (lo + hi),
                ..map
            },
            _ => map,
        }
    }

    /// The normalised value of `s` (NaN stays NaN: the stage then draws
    /// nothing for the fragment).
    #[inline]
    pub fn apply(&self, s: f64) -> f64 {
        ((s - self.offset) * self.scale).clamp(-MAX_NORMALISED, MAX_NORMALISED)
    }
}

/// The view uniform of the segment stages. Keep in sync with `View` in
/// `shaders/segment.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentView {
    pub ortho: u32,
    pub _pad0: u32,
    /// View-plane position of framebuffer position `p`: `p * scale + offset`.
    pub scale: [f32; 2],
    pub offset: [f32; 2],
    pub _pad1: [f32; 2],
}

impl SegmentView {
    /// An orthographic view (the fragment's position is not needed).
    pub fn ortho() -> SegmentView {
        SegmentView {
            ortho: 1,
            ..Default::default()
        }
    }

    /// The view of `camera` (framebuffer position = continuous pixel
    /// position, see [`crate::gpu::raster_side`]).
    pub fn of(camera: &Camera) -> SegmentView {
        let m = ViewMap::of(camera);
        SegmentView {
            ortho: camera.ortho as u32,
            _pad0: 0,
            scale: [
                (2.0 * m.half_width / m.width) as f32,
                (-2.0 * m.half_height / m.height) as f32,
            ],
            offset: [-m.half_width as f32, m.half_height as f32],
            _pad1: [0.0; 2],
        }
    }
}

/// A fragment's ray segment (twin of `Seg` in `shaders/segment.wgsl`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seg {
    pub s_f: f32,
    pub s_b: f32,
    pub l: f32,
    pub ok: bool,
}

/// The CPU twin of `segment_at`: the segment of the fragment of `tri` at
/// barycentric weights `bary`, its framebuffer position recovered from the
/// interpolated clip position through `mapper`.
pub fn segment_at(
    view: &SegmentView,
    mapper: &ClipMapper,
    tri: [&SegmentVertex; 3],
    bary: [f64; 3],
) -> Seg {
    let front = [0, 1].map(|k| lerp(tri, bary, |v| v.front[k]));
    let back = [0, 1].map(|k| lerp(tri, bary, |v| v.back[k]));
    let thick = lerp(tri, bary, |v| v.thick);
    let p = if view.ortho == 1 {
        [0.0; 2]
    } else {
        let clip = [0, 1].map(|k| lerp(tri, bary, |v| v.pos[k]));
        let (px, py) = mapper.pixel_of([clip[0], clip[1], 0.5, 1.0]);
        [px as f32, py as f32]
    };
    segment_of(view, front, back, thick, p)
}

/// The payload of the segment modes for one part: the frame's scalar map
/// and projection (the values themselves are the projection's).
#[derive(Clone, Copy, Debug)]
pub struct SegmentPayload {
    pub map: ScalarMap,
    pub ortho: bool,
}

impl Default for SegmentPayload {
    fn default() -> Self {
        SegmentPayload {
            map: ScalarMap {
                offset: 0.0,
                scale: 1.0,
            },
            ortho: true,
        }
    }
}

impl SegmentPayload {
    /// Sets the frame's map and projection from `src`.
    pub fn set(&mut self, src: &PieceSource) {
        self.map = ScalarMap::of(src.tf);
        self.ortho = src.camera.ortho;
    }
}

/// A projected-cell mode on the segment payload (exact-frag, the table
/// modes): it supplies its stage and its twin; every such mode is a
/// [`ProjectedMode`] that slices nowhere, needs no perspective refinement
/// and sends [`SegmentVertex::of`] its [`SegmentPayload`] (as its own
/// vertex type, [`SegmentMode::Vertex`]: the segment vertex itself, or a
/// vertex that carries it, as exact-frag's whole-piece quads do).
pub trait SegmentMode: Sync {
    /// The stage's vertex: [`SegmentVertex`], or one made from it.
    type Vertex: GpuVertex + From<SegmentVertex>;
    /// Binds the mode's stage for one frame of `src`.
    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError>;
    /// The stage's bindings on the CPU, drawing through its twin, for one
    /// frame of `src`.
    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<Self::Vertex>>;
    /// The vertex that draws `part` whole ([`ProjectedMode::whole_part`];
    /// a mode that does sets `payload` for the frame first); none by
    /// default, at no cost per part.
    fn whole_part(
        &self,
        _src: &PieceSource,
        _part: &Polyhedron,
        _payload: &mut SegmentPayload,
        _rate: &dyn Fn() -> f64,
    ) -> Option<Self::Vertex> {
        None
    }
    /// Whether a frame's triangles may be kept for the next frame whose
    /// transfer function differs only in colours
    /// ([`ProjectedMode::stream_signature`]): yes by default.
    fn keeps_projection(&self) -> bool {
        true
    }
}

impl<M: SegmentMode> ProjectedMode for M {
    type Vertex = M::Vertex;
    type Payload = SegmentPayload;

    fn split_points(&self, _tf: &TransferFunction) -> Vec<f64> {
        Vec::new()
    }

    fn perspective_refine(&self) -> bool {
        SegmentVertex::needs_perspective_refinement()
    }

    fn stream_signature(&self, tf: &TransferFunction) -> Option<Vec<u64>> {
        self.keeps_projection()
            .then(|| crate::render::driver::kept::stream_signature(tf))
            .flatten()
    }

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        SegmentMode::bind(self, gpu, src)
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<M::Vertex>> {
        SegmentMode::twin(self, src)
    }

    fn whole_part(
        &self,
        src: &PieceSource,
        part: &Polyhedron,
        payload: &mut SegmentPayload,
        rate: &dyn Fn() -> f64,
    ) -> Option<M::Vertex> {
        SegmentMode::whole_part(self, src, part, payload, rate)
    }

    fn payload(
        &self,
        src: &PieceSource,
        _part: &Polyhedron,
        _proj: &mut Projected,
        _used: &mut Vec<bool>,
        payload: &mut SegmentPayload,
        _refined: &mut usize,
    ) {
        payload.set(src);
    }

    fn vertex(
        &self,
        payload: &SegmentPayload,
        proj: &Projected,
        i: usize,
        ndc: [f32; 2],
    ) -> M::Vertex {
        SegmentVertex::of(proj, i, ndc, &payload.map, payload.ortho).into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_matches_struct() {
        assert_eq!(std::mem::size_of::<SegmentVertex>(), 40);
        let offs: Vec<u64> = SegmentVertex::ATTRIBUTES.iter().map(|a| a.offset).collect();
        assert_eq!(
            offs,
            vec![
                0,
                std::mem::offset_of!(SegmentVertex, front) as u64,
                std::mem::offset_of!(SegmentVertex, back) as u64,
                std::mem::offset_of!(SegmentVertex, thick) as u64,
                std::mem::offset_of!(SegmentVertex, piece) as u64,
            ]
        );
        assert_eq!(std::mem::size_of::<SegmentView>(), 32);
    }

    #[test]
    fn scalar_map_sends_the_node_range_to_the_unit_interval() {
        let tf = TransferFunction::default_for((10.0, 30.0), 1.0);
        let m = ScalarMap::of(&tf);
        assert_eq!(m.apply(10.0), 0.0);
        assert_eq!(m.apply(30.0), 1.0);
        assert!(m.apply(f64::NAN).is_nan());
        assert_eq!(m.apply(1e300), MAX_NORMALISED);
    }
}
