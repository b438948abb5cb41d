//! Exact-frag's whole-piece quads (`--piece-draw quads`): a convex piece is
//! drawn as one screen polygon over its outline (the driver's `whole`
//! module: its projected points' convex hull widened a little, or the
//! quad over its pixel bounding box), every vertex
//! carrying the whole piece, and each fragment finds where its own ray
//! enters and leaves the piece (view-independent cell projection, Weiler,
//! Kraus, Merz and Ertl 2003). The CPU does no region subdivision: per
//! piece it numbers the points, packs the boundary triangles and checks
//! that `f32` settles the piece (below); the rasteriser has two triangles
//! to set up instead of a dozen.
//!
//! `shaders/piece_quad.wgsl` is the GPU side and says how a fragment finds
//! its segment: the points sheared onto the pixel's ray, the watertight
//! edge functions of Woop, Benthin and Wald (2013) evaluated from each
//! edge's lower-numbered point (points are numbered by view position, one
//! order for every piece, so neighbours compute the same values), the
//! nearer triangle holding the ray the entry and the other the exit, depth
//! and scalar from the hit's barycentric weights. Within the piece the
//! scalar is linear along the ray between its entry and exit values, the
//! `faces` model, as on the region path; a piece the order splits comes as
//! its tets. This module fills the vertices ([`QuadVertex::whole`]) and is
//! the shader's twin ([`segment_at`], [`corners`], [`edge`]).
//!
//! **Which pieces.** A piece goes whole where it has at most
//! [`MAX_POINTS`] points and [`MAX_TRIANGLES`] boundary triangles, lies
//! beyond the near plane's clipping depth, has distinct points, and `f32`
//! settles its segments: the edge functions round by a few ulps of the
//! coordinates, which moves a decision or a hit by
//! `δ =` [`QUAD_F32_REL`] `·` its largest coordinate; across a face at
//! angle `cos` to the ray that changes the depth by `δ / cos`, and depths
//! themselves round by [`QUAD_F32_REL`] of the piece's diameter. The piece
//! goes whole where its largest rate times those lengths stays within
//! [`QUAD_DEPTH_TOL`] and every face is at least [`QUAD_MIN_COS`] off
//! edge-on. Any other piece is projected as on the region path (the same
//! stage: a vertex with no triangles carries the segment payload), with its
//! exact tie decisions: faces seen edge-on, optically thick slivers and the
//! near plane keep the guarantees of that path.

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use crate::camera::Camera;
use crate::gpu::cpu::{lerp, CpuStage};
use crate::gpu::{Binding, ClipMapper, Context, GpuError, GpuVertex, Stage, StageDesc};
use crate::numeric::tolerance::{NEAR_CLIP_SCALE, QUAD_DEPTH_TOL, QUAD_F32_REL, QUAD_MIN_COS};
use crate::projection::Polyhedron;
use crate::render::pieces::PieceSource;
use crate::tf::TransferFunction;

use super::exact_frag::{
    bind_integral_stage, integral_stage, longest_segment, ExactFragTwin, IntegralStages,
    THIN_CONSTANTS,
};
use super::integral::TfBuffer;
use super::segment::{ScalarMap, Seg, SegmentMode, SegmentPayload, SegmentVertex, SegmentView};
use super::segment_view::segment_of;

/// Most points of a piece drawn whole (3 bits per corner index).
pub const MAX_POINTS: usize = 8;

/// Most boundary triangles of a piece drawn whole (three per `u32`, four
/// words, the count in the top bits of the first).
pub const MAX_TRIANGLES: usize = 12;

/// One vertex of the quad stage. Keep in sync with `VertexIn` in
/// `shaders/piece_quad.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct QuadVertex {
    /// Clip-space position (x, y, z, w), `w = 1`.
    pub pos: [f32; 4],
    /// The piece's points in view space (x, y, z) with their normalised
    /// scalar (w), numbered by view position.
    pub points: [[f32; 4]; MAX_POINTS],
    /// Each point's depth minus point 0's, rounded from `f64`.
    pub depth: [[f32; 4]; 2],
    /// The boundary triangles ([`corners`]); no triangles: a region vertex.
    pub topo: [u32; 4],
    /// A region vertex's `front` and `back` ([`SegmentVertex`]).
    pub seg: [f32; 4],
    /// A region vertex's `thick`.
    pub thick: f32,
    /// The piece its triangles belong to ([`crate::gpu::piece_depth`]).
    pub piece: u32,
}

impl QuadVertex {
    /// Vertex attributes (`@location`s of `VertexIn`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 15] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Float32x4,
        2 => Float32x4,
        3 => Float32x4,
        4 => Float32x4,
        5 => Float32x4,
        6 => Float32x4,
        7 => Float32x4,
        8 => Float32x4,
        9 => Float32x4,
        10 => Float32x4,
        11 => Uint32x4,
        12 => Float32x4,
        13 => Float32,
        14 => Uint32,
    ];

    /// The vertex buffer layout of the quad stage.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<QuadVertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &QuadVertex::ATTRIBUTES,
    };

    /// A region vertex: the segment payload `v`, no triangles.
    pub fn region(v: SegmentVertex) -> QuadVertex {
        QuadVertex {
            pos: v.pos,
            seg: [v.front[0], v.front[1], v.back[0], v.back[1]],
            thick: v.thick,
            piece: v.piece,
            ..QuadVertex::default()
        }
    }

    /// The vertex drawing `part` whole for a segment mode
    /// ([`SegmentMode::whole_part`]): the frame's scalar map set in
    /// `payload`, then [`QuadVertex::whole`].
    pub fn for_part(
        src: &PieceSource,
        part: &Polyhedron,
        payload: &mut SegmentPayload,
        rate: &dyn Fn() -> f64,
    ) -> Option<QuadVertex> {
        payload.set(src);
        QuadVertex::whole(part, &payload.map, src.camera, rate)
    }

    /// The number of triangles (0 for a region vertex).
    pub fn triangles(&self) -> u32 {
        self.topo[0] >> 27
    }

    /// The vertex of `part` drawn whole (clip position left to the
    /// driver), or `None` where the piece must be projected (module docs:
    /// which pieces). `rate` is the piece's largest rate, asked only when
    /// the geometry allows the piece.
    pub fn whole(
        part: &Polyhedron,
        map: &ScalarMap,
        camera: &Camera,
        rate: impl FnOnce() -> f64,
    ) -> Option<QuadVertex> {
        let n = part.points.len();
        let m = part.triangles.len();
        if !(4..=MAX_POINTS).contains(&n) || !(4..=MAX_TRIANGLES).contains(&m) {
            return None;
        }
        if !camera.ortho {
            let zc = camera.near * NEAR_CLIP_SCALE;
            if !part.points.iter().all(|p| p.z >= zc) {
                return None;
            }
        }
        // Number the points by view position: one order for every piece.
        let mut order = [0usize; MAX_POINTS];
        for (k, o) in order.iter_mut().enumerate().take(n) {
            *o = k;
        }
        let key = |i: usize| {
            let p = part.points[i];
            [p.x, p.y, p.z]
        };
        order[..n].sort_unstable_by(|&a, &b| {
            let (ka, kb) = (key(a), key(b));
            ka[0]
                .total_cmp(&kb[0])
                .then(ka[1].total_cmp(&kb[1]))
                .then(ka[2].total_cmp(&kb[2]))
        });
        if order[..n].windows(2).any(|w| key(w[0]) == key(w[1])) {
            return None;
        }
        let mut local = [0u32; MAX_POINTS];
        for (k, &o) in order[..n].iter().enumerate() {
            local[o] = k as u32;
        }
        // Faces against the ray, extent, coordinates.
        let mut cos_min = f64::INFINITY;
        for t in &part.triangles {
            let [a, b, c] = t.map(|i| part.points[i as usize]);
            let normal = (b - a).cross(c - a);
            let ray = if camera.ortho {
                DVec3::Z
            } else {
                (a + b + c) / 3.0
            };
            let len = normal.length() * ray.length();
            if len.is_nan() || len <= 0.0 {
                return None;
            }
            cos_min = cos_min.min(normal.dot(ray).abs() / len);
        }
        if cos_min.is_nan() || cos_min < QUAD_MIN_COS {
            return None;
        }
        let (mut lo, mut hi) = (part.points[0], part.points[0]);
        let mut coord = 0.0f64;
        for p in &part.points {
            lo = lo.min(*p);
            hi = hi.max(*p);
            // The shear's operands: the view-plane coordinates, and in
            // perspective the depth too (times the pixel's `u`, below 1
            // inside the usual fields of view).
            let a = p.abs();
            coord = coord.max(if camera.ortho {
                a.x.max(a.y)
            } else {
                a.max_element()
            });
        }
        let diameter = (hi - lo).length();
        let shift = QUAD_F32_REL * (coord / cos_min + diameter);
        let rate = rate();
        let depth = rate * shift;
        if depth.is_nan() || depth > QUAD_DEPTH_TOL {
            return None;
        }
        let mut v = QuadVertex::default();
        let z0 = part.points[order[0]].z;
        for (k, &o) in order[..n].iter().enumerate() {
            let p = part.points[o];
            let s = map.apply(part.scalars[o]);
            v.points[k] = [p.x as f32, p.y as f32, p.z as f32, s as f32];
            v.depth[k / 4][k % 4] = (p.z - z0) as f32;
        }
        // Front triangles first, every triangle wound so that a ray
        // through it has positive edge functions: its projection counter-
        // clockwise (the sheared triangle of a ray through it has the
        // projected one's orientation, depths being positive). A triangle
        // faces the eye where the eye and the piece's centroid (inside it,
        // unlike its bounding box's centre) lie on opposite sides of its
        // plane.
        let centre = part.points.iter().sum::<DVec3>() / n as f64;
        let plane = |p: DVec3| {
            if camera.ortho {
                glam::DVec2::new(p.x, p.y)
            } else {
                glam::DVec2::new(p.x / p.z, p.y / p.z)
            }
        };
        let mut packed = [[0u32; 3]; MAX_TRIANGLES];
        let mut next = 0;
        for pass in [true, false] {
            for t in &part.triangles {
                let [a, b, c] = t.map(|i| part.points[i as usize]);
                let normal = (b - a).cross(c - a);
                let inside = normal.dot(centre - a);
                let eye = if camera.ortho {
                    normal.z
                } else {
                    normal.dot(a)
                };
                if (eye * inside > 0.0) != pass {
                    continue;
                }
                let (pa, pb, pc) = (plane(a), plane(b), plane(c));
                let mut k = t.map(|i| local[i as usize]);
                if (pb - pa).perp_dot(pc - pa) < 0.0 {
                    k.swap(1, 2);
                }
                packed[next] = k;
                next += 1;
            }
            if pass {
                v.topo[1] = (next as u32) << 27;
            }
        }
        for (k, [a, b, c]) in packed[..m].iter().enumerate() {
            v.topo[k / 3] |= (a | b << 3 | c << 6) << (9 * (k % 3));
        }
        v.topo[0] |= (m as u32) << 27;
        v.topo[2] |= (n as u32) << 27;
        Some(v)
    }
}

impl From<SegmentVertex> for QuadVertex {
    fn from(v: SegmentVertex) -> QuadVertex {
        QuadVertex::region(v)
    }
}

impl GpuVertex for QuadVertex {
    fn clip(&self) -> [f32; 4] {
        self.pos
    }
    fn piece(&self) -> u32 {
        self.piece
    }
    fn with_piece(self, piece: u32) -> Self {
        QuadVertex { piece, ..self }
    }
    fn is_finite(&self) -> bool {
        self.pos.iter().all(|v| v.is_finite())
            && self.points.iter().flatten().all(|v| v.is_finite())
            && self.depth.iter().flatten().all(|v| v.is_finite())
            && self.seg.iter().all(|v| v.is_finite())
            && self.thick.is_finite()
    }
    fn with_clip(self, pos: [f32; 4]) -> Self {
        QuadVertex { pos, ..self }
    }
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self {
        QuadVertex {
            seg: [0, 1, 2, 3].map(|k| lerp(tri, bary, |v| v.seg[k])),
            thick: lerp(tri, bary, |v| v.thick),
            ..*tri[0]
        }
    }
    fn transparent(self) -> Self {
        // A region vertex with l = 0: the empty segment.
        QuadVertex {
            thick: 0.0,
            topo: [0; 4],
            ..self
        }
    }
}

/// Twin of `corners` in `shaders/piece_quad.wgsl`: the corners of triangle
/// `k` of `topo`.
pub fn corners(topo: [u32; 4], k: u32) -> [u32; 3] {
    let w = topo[(k / 3) as usize] >> (9 * (k % 3));
    [w & 7, (w >> 3) & 7, (w >> 6) & 7]
}

/// Twin of `edge` in `shaders/piece_quad.wgsl`: the edge function of the
/// sheared points `a` (point `i`) and `b` (point `j`), from the
/// lower-numbered point.
pub fn edge(a: [f32; 2], b: [f32; 2], i: u32, j: u32) -> f32 {
    if i < j {
        a[0] * b[1] - a[1] * b[0]
    } else {
        -(b[0] * a[1] - b[1] * a[0])
    }
}

/// Twin of `point` in `shaders/piece_quad.wgsl`: point `i` of the piece.
pub fn point(f: &QuadVertex, i: u32) -> [f32; 4] {
    f.points[(i & 7) as usize]
}

/// Twin of `depth` in `shaders/piece_quad.wgsl`: point `i`'s depth
/// relative to point 0.
pub fn depth(f: &QuadVertex, i: u32) -> f32 {
    f.depth[((i >> 2) & 1) as usize][(i & 3) as usize]
}

/// Twin of `shear` in `shaders/piece_quad.wgsl`: point `c` sheared onto
/// the ray through view-plane position `u`.
pub fn shear(view: &SegmentView, c: [f32; 4], u: [f32; 2]) -> [f32; 2] {
    if view.ortho == 1 {
        [c[0] - u[0], c[1] - u[1]]
    } else {
        [c[0] - u[0] * c[2], c[1] - u[1] * c[2]]
    }
}

/// Twin of `find` in `shaders/piece_quad.wgsl`: the first of triangles
/// `first..last` holding the ray through `u`, as (depth, scalar, mask of
/// the points with nonzero weight), or `None`.
pub fn find(
    view: &SegmentView,
    f: &QuadVertex,
    u: [f32; 2],
    first: u32,
    last: u32,
) -> Option<[f32; 3]> {
    for k in first..last {
        let [a, b, c] = corners(f.topo, k);
        let [pa, pb, pc] = [a, b, c].map(|i| point(f, i));
        let [qa, qb, qc] = [pa, pb, pc].map(|p| shear(view, p, u));
        let e = [edge(qb, qc, b, c), edge(qc, qa, c, a), edge(qa, qb, a, b)];
        let sum = e[0] + e[1] + e[2];
        if e.iter().all(|&x| x >= 0.0) && sum > 0.0 {
            let w = e.map(|x| x / sum);
            let mask = ((e[0] != 0.0) as u32) << a
                | ((e[1] != 0.0) as u32) << b
                | ((e[2] != 0.0) as u32) << c;
            return Some([
                w[0] * depth(f, a) + w[1] * depth(f, b) + w[2] * depth(f, c),
                w[0] * pa[3] + w[1] * pb[3] + w[2] * pc[3],
                mask as f32,
            ]);
        }
    }
    None
}

/// Twin of `segment_at` in `shaders/piece_quad.wgsl`: the segment of the
/// fragment of `tri` at weights `bary`. The GPU shades pixel centres, so
/// the twin takes the centre of the pixel the interpolated position falls
/// in (bit for bit the shader's `p`, whichever piece asks).
pub fn segment_at(
    view: &SegmentView,
    mapper: &ClipMapper,
    tri: [&QuadVertex; 3],
    bary: [f64; 3],
) -> Seg {
    let clip = [0, 1].map(|k| lerp(tri, bary, |v| v.pos[k]));
    let (px, py) = mapper.pixel_of([clip[0], clip[1], 0.5, 1.0]);
    let p = [(px.floor() + 0.5) as f32, (py.floor() + 0.5) as f32];
    let f = tri[0];
    let count = f.triangles();
    if count == 0 {
        let seg = [0, 1, 2, 3].map(|k| lerp(tri, bary, |v| v.seg[k]));
        let thick = lerp(tri, bary, |v| v.thick);
        return segment_of(view, [seg[0], seg[1]], [seg[2], seg[3]], thick, p);
    }
    let u = [
        p[0] * view.scale[0] + view.offset[0],
        p[1] * view.scale[1] + view.offset[1],
    ];
    let front_count = f.topo[1] >> 27;
    let none = Seg {
        s_f: 0.0,
        s_b: 0.0,
        l: 0.0,
        ok: false,
    };
    let Some(a) = find(view, f, u, 0, front_count) else {
        return none;
    };
    let Some(b) = find(view, f, u, front_count, count) else {
        return none;
    };
    let (front, back) = if b[0] < a[0] { (b, a) } else { (a, b) };
    let mut l = back[0] - front[0];
    if view.ortho == 0 {
        l *= (1.0 + u[0] * u[0] + u[1] * u[1]).sqrt();
    }
    let l = l.max(0.0);
    let (s_f, s_b) = (front[1], back[1]);
    Seg {
        s_f,
        s_b,
        l,
        ok: a[2] != b[2] && s_f.is_finite() && s_b.is_finite() && l.is_finite(),
    }
}

/// The quad stage: the quad vertex, the segment view, the integral and
/// exact-frag's fragment entry point (`fs_main` on this file's
/// `segment_at`).
pub static PIECE_QUAD_STAGE: StageDesc = quad_stage("piece_quad.wgsl", &[]);

/// The quad stage's variants by segment thickness and Gauss rule (as
/// [`super::exact_frag::EXACT_FRAG_STAGES`]).
pub static PIECE_QUAD_STAGES: IntegralStages = IntegralStages {
    full: &PIECE_QUAD_STAGE,
    thin: [
        &quad_stage("piece_quad.wgsl+thin4", THIN_CONSTANTS[0]),
        &quad_stage("piece_quad.wgsl+thin5", THIN_CONSTANTS[1]),
        &quad_stage("piece_quad.wgsl+thin6", THIN_CONSTANTS[2]),
    ],
};

const fn quad_stage(name: &'static str, constants: &'static [(&'static str, f64)]) -> StageDesc {
    StageDesc {
        name,
        fragment: "fs_main",
        wgsl: concat!(
            include_str!("../../../shaders/piece_quad.wgsl"),
            include_str!("../../../shaders/segment_view.wgsl"),
            include_str!("../../../shaders/integral.wgsl"),
            include_str!("../../../shaders/exact_frag.wgsl"),
        ),
        vertex: QuadVertex::LAYOUT,
        bindings: &[Binding::Uniform, Binding::Storage, Binding::Storage],
        constants,
    }
}

/// What a segment stage's CPU bindings give a quad stage's twin: the view
/// the quad's search works in, and the colour and opacity of a segment
/// (exact-frag's closed form, a table mode's lookup).
pub trait SegmentTwin: Sync {
    /// The stage's view and clip mapping.
    fn view(&self) -> (SegmentView, ClipMapper);
    /// The premultiplied colour and opacity of the segment `(l, s_f, s_b)`
    /// (normalised scalars).
    fn volume(&self, l: f32, sf: f32, sb: f32) -> [f32; 4];
}

impl SegmentTwin for ExactFragTwin {
    fn view(&self) -> (SegmentView, ClipMapper) {
        ExactFragTwin::view(self)
    }
    fn volume(&self, l: f32, sf: f32, sb: f32) -> [f32; 4] {
        ExactFragTwin::volume(self, l, sf, sb)
    }
}

/// A quad stage's bindings on the CPU, for its twin [`fs_main`]: those of
/// the segment stage it draws with (exact-frag's by default: view, transfer
/// function, the closed form's constants; a table mode's for
/// [`super::preint_quads`]).
pub struct QuadTwin<T = ExactFragTwin>(pub T);

impl QuadTwin {
    /// The exact-frag twin for `tf` seen by `camera`.
    pub fn new(tf: &TransferFunction, camera: &Camera) -> QuadTwin {
        QuadTwin(ExactFragTwin::new(tf, camera))
    }
}

impl<T: SegmentTwin> QuadTwin<T> {
    fn segment(&self, tri: [&QuadVertex; 3], bary: [f64; 3]) -> Seg {
        let (view, mapper) = self.0.view();
        segment_at(&view, &mapper, tri, bary)
    }
}

/// The twin of the fragment entry `fs_main` in a quad stage: the
/// fragment's segment ([`segment_at`]), integrated by the stage's own
/// program.
pub fn fs_main<T: SegmentTwin>(
    stage: &QuadTwin<T>,
    tri: [&QuadVertex; 3],
    bary: [f64; 3],
) -> Option<[f32; 4]> {
    let seg = stage.segment(tri, bary);
    seg.ok.then(|| stage.0.volume(seg.l, seg.s_f, seg.s_b))
}

impl<T: SegmentTwin> CpuStage<QuadVertex> for QuadTwin<T> {
    fn shade(&self, tri: [&QuadVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_main(self, tri, bary)
    }

    fn covers(&self, tri: [&QuadVertex; 3], bary: [f64; 3]) -> bool {
        self.segment(tri, bary).ok
    }

    fn describe(&self, tri: [&QuadVertex; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let seg = self.segment(tri, bary);
        vec![
            ("s_f", seg.s_f),
            ("s_b", seg.s_b),
            ("l", seg.l),
            ("triangles", tri[0].triangles() as f32),
        ]
    }
}

/// Exact-frag with whole-piece quads, a mode on the segment payload: the
/// pieces [`QuadVertex::whole`] takes are drawn whole, the others as
/// regions with the segment payload, in one stage. Its frames are not
/// kept for the next (which pieces go whole depends on the extinction).
pub struct ExactFragQuads;

impl SegmentMode for ExactFragQuads {
    type Vertex = QuadVertex;

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        let tf = TfBuffer::new(src.tf, &ScalarMap::of(src.tf));
        let longest = longest_segment(gpu, src)?;
        let stage = integral_stage(&tf, longest, &PIECE_QUAD_STAGES);
        bind_integral_stage(gpu, stage, &SegmentView::of(src.camera), &tf, &[])
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<QuadVertex>> {
        Box::new(QuadTwin(
            ExactFragTwin::new(src.tf, src.camera).for_mesh(src.whole),
        ))
    }

    fn whole_part(
        &self,
        src: &PieceSource,
        part: &Polyhedron,
        payload: &mut SegmentPayload,
        rate: &dyn Fn() -> f64,
    ) -> Option<QuadVertex> {
        QuadVertex::for_part(src, part, payload, rate)
    }

    fn keeps_projection(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests;
