//! Isosurfaces on the projected-cell driver: `--mode iso` (surfaces alone)
//! and `--iso` with `exact-frag` or a table mode (surfaces mixed with the
//! volume, in each piece's place in the exact order). `--iso` with the
//! exact mode draws exact-frag's frame: the exact mode's integrals at
//! region vertices cannot hold a crossing inside a segment, and slicing
//! cells at the isovalues (as at breakpoints) would put the `tets`
//! field's surfaces into whole cells. The rules (what a
//! crossing is, the sides, the light, the mixing) are in
//! [`crate::render::iso`]; this is the GPU stage and its twin.
//!
//! On the shared driver ([`crate::render::driver`]) the mode supplies:
//! - **split policy**: none (as the segment modes: the fragment finds its
//!   crossings between `s_f` and `s_b`, so no cell is split for a surface);
//! - **skipping**: pieces whose scalar range holds no isovalue are drawn
//!   only for the volume, and not at all in `--mode iso`
//!   ([`ProjectedMode::isosurfaces`], [`ProjectedMode::draws_volume`]);
//! - **payload**: the segment payload ([`super::segment`]) and the gradient
//!   at each region vertex's entry and exit points ([`IsoVertex`]): flat
//!   (the part's least-squares gradient) or smooth (the points' gradients
//!   interpolated on the boundary triangle holding the point,
//!   [`crate::render::gradients`]); in perspective multiplied by `q = 1/z`
//!   like the scalars, so they interpolate exactly;
//! - **stage**: `shaders/iso_vertex.wgsl`, `shaders/segment.wgsl`, the
//!   volume's files, the segment with its crossings, and
//!   `shaders/iso.wgsl` with the entry point `fs_iso` (one stage per
//!   volume, [`super::iso_stages`]; [`fs_iso`] is its twin, on the same volume twins as the segment modes). The segment is
//!   `shaders/iso_split.wgsl` over a one-line `volume(l, s0, s1)` per
//!   sub-segment (the table lookup, or zero: [`super::iso_split`]) or, for
//!   the closed-form integral, `shaders/iso_walk.wgsl`, one walk over the
//!   transfer function's nodes and the crossings ([`super::iso_walk`]).

use bytemuck::{Pod, Zeroable};
use glam::{DVec2, DVec3};

use crate::gpu::cpu::{lerp, CpuStage};
use crate::gpu::{ClipMapper, Context, GpuError, GpuVertex, Resource, Stage, StageDesc};
use crate::projection::{Polyhedron, Projected};
use crate::render::driver::ProjectedMode;
use crate::render::gradients::{barycentric, boundary_gradient, piece_gradient};
use crate::render::iso::{IsoMix, IsoSet, Lighting, AMBIENT, DIFFUSE};
use crate::render::pieces::PieceSource;
use crate::tf::{EmissionModel, TransferFunction};

use super::exact_frag::{bind_integral_stage, integral_stage, longest_segment, ExactFragTwin};
use super::integral::TfBuffer;
pub use super::iso_levels::{decided_end, gpu_level};
pub use super::iso_stages::{
    ISO_EXACT_FRAG_STAGE, ISO_EXACT_FRAG_STAGES, ISO_PREINT2D_CYL_STAGE, ISO_PREINT2D_STAGE,
    ISO_PREINT3D_STAGE, ISO_STAGE,
};
use super::preint::{PreintMode, PreintTwin};
use super::preint_tables::{TableKind, TableStats};
use super::segment::{segment_at, ScalarMap, Seg, SegmentPayload, SegmentVertex, SegmentView};
use super::{Bounds, ModeInfo};
use crate::raycast::FieldModel;

/// The registry entry of `--mode iso`.
pub static INFO: ModeInfo = ModeInfo {
    name: "iso",
    summary: "isosurfaces alone (--iso), found per fragment between the segment's end scalars, in the exact order",
    gpu: true,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    draws_pieces_whole: false,
    stage: Some(&ISO_STAGE),
    bounds: Some(Bounds {
        reference: FieldModel::Faces,
        // tests/modes.rs (one opaque surface mid-range, lit smooth, the
        // reference drawing the surfaces alone; measured 8.7e-3 at most
        // elsewhere on the outliers' edges) and tests/iso.rs (2e-3 beyond
        // them, more surfaces): f32 crossings and light.
        split_max: 2.0 / 255.0,
        whole_max: 2.0 / 255.0,
        // None: every pixel within the bound on Vulkan and GL (1 before the
        // perspective iso lines and the tie ends on the reference's side
        // of each level, 6 before the face's iso lines were decided
        // exactly).
        split_outliers: 0,
        // Whole cells against `faces`: in the cells the order splits into
        // tets (zoo_3x3x3's nonplanar cells) the surface is the `tets`
        // field's, elsewhere than the `faces` field's. Measured 41 there,
        // at most 1 on meshes without split cells.
        whole_outliers: 48,
    }),
};

/// One vertex of the isosurface stages: the segment vertex and the
/// gradients at the entry and exit points. Keep in sync with `VertexIn` in
/// `shaders/iso_vertex.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct IsoVertex {
    pub seg: SegmentVertex,
    /// `g_f` (orthographic) or `g_f q_f` (perspective), view space,
    /// normalised scalar units.
    pub grad_front: [f32; 3],
    /// `g_b` or `g_b q_b`.
    pub grad_back: [f32; 3],
    /// The surfaces the part can cross (flat): indices
    /// `candidates[0] .. candidates[1]` (exact in `f32`), those whose
    /// values lie within the part's normalised scalar range widened by
    /// [`RANGE_MARGIN`]. Every segment of the part lies in that range, so
    /// the stage searches only these (a part holding no value, none). A
    /// rasteriser may shade lanes outside the triangle (llvmpipe runs
    /// whole pixel blocks) with extrapolated scalars; without the bound
    /// their crossing loops ran over every isovalue, which made a frame's
    /// cost grow with their number.
    pub candidates: [f32; 2],
}

/// How far the scalar range of [`IsoVertex::candidates`] is widened beyond
/// the part's scalars (normalised units, relative above 1): far above the
/// `f32` rounding of a fragment's interpolated scalars, so that the bound
/// never changes a fragment inside the triangle.
pub const RANGE_MARGIN: f64 = 1e-3;

/// How far a cell's normalised scalar range is widened (relative above 1)
/// when deciding whether its points need gradients
/// ([`IsoMode::with_surface_gradients`]): ten times [`RANGE_MARGIN`], so
/// that every piece whose candidates hold a value (its range lies in its
/// cell's, up to the rounding of interpolated scalars) finds them.
pub const GRADIENT_MARGIN: f64 = 10.0 * RANGE_MARGIN;

impl IsoVertex {
    /// Vertex attributes (`@location`s of `VertexIn`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 8] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Float32x2,
        2 => Float32x2,
        3 => Float32,
        4 => Uint32,
        5 => Float32x3,
        6 => Float32x3,
        7 => Float32x2,
    ];

    /// The vertex buffer layout of the isosurface stages.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<IsoVertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &IsoVertex::ATTRIBUTES,
    };
}

impl GpuVertex for IsoVertex {
    fn clip(&self) -> [f32; 4] {
        self.seg.pos
    }
    fn piece(&self) -> u32 {
        self.seg.piece
    }
    fn with_piece(self, piece: u32) -> Self {
        IsoVertex {
            seg: self.seg.with_piece(piece),
            ..self
        }
    }
    fn is_finite(&self) -> bool {
        self.seg.is_finite()
            && self.grad_front.iter().all(|v| v.is_finite())
            && self.grad_back.iter().all(|v| v.is_finite())
            && self.candidates.iter().all(|v| !v.is_nan())
    }
    fn with_clip(self, pos: [f32; 4]) -> Self {
        IsoVertex {
            seg: self.seg.with_clip(pos),
            ..self
        }
    }
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self {
        IsoVertex {
            seg: SegmentVertex::lerp3(tri.map(|v| &v.seg), bary),
            grad_front: [0, 1, 2].map(|k| lerp(tri, bary, |v| v.grad_front[k])),
            grad_back: [0, 1, 2].map(|k| lerp(tri, bary, |v| v.grad_back[k])),
            // Flat: the first vertex's (every vertex of a part has the
            // part's).
            candidates: tri[0].candidates,
        }
    }
    fn transparent(self) -> Self {
        // The empty segment at one scalar: no volume, no crossing.
        IsoVertex {
            seg: SegmentVertex {
                back: self.seg.front,
                ..self.seg.transparent()
            },
            ..self
        }
    }
}

/// The isosurface uniform. Keep in sync with `IsoParams` in
/// `shaders/iso.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct IsoParams {
    pub count: u32,
    pub lighting: u32,
    pub ambient: f32,
    pub diffuse: f32,
    /// 0: exact mixing, 1: RKE's blend ([`crate::render::iso::IsoMix`]).
    pub mix: u32,
    /// The scalar map's origin in a table volume's normalised terms
    /// ([`IsoMode::table_offset`]), added to the scalars of its lookups;
    /// 0 for the other volumes.
    pub table_offset: f32,
    pub _pad: [u32; 2],
}

/// One surface as the stage reads it. Keep in sync with `IsoSurface` in
/// `shaders/iso.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct IsoSurface {
    /// `x`: the normalised isovalue.
    pub value: [f32; 4],
    /// Straight colour and opacity of the front side (the stage's
    /// `sides[0]`: indexed there, so a fragment loads only the side it
    /// sees).
    pub front: [f32; 4],
    /// The back side (`sides[1]`).
    pub back: [f32; 4],
}

/// The uniform and the surface list of `set`, its values through `map`
/// (one zero surface when the set is empty: a storage binding is never
/// empty), a table volume's lookups offset by `table_offset`.
pub fn iso_buffers(
    set: &IsoSet,
    map: &ScalarMap,
    table_offset: f32,
) -> (IsoParams, Vec<IsoSurface>) {
    let params = IsoParams {
        count: set.values.len() as u32,
        lighting: set.lighting.code(),
        ambient: AMBIENT as f32,
        diffuse: DIFFUSE as f32,
        mix: match set.mix {
            IsoMix::Exact => 0,
            IsoMix::Blend => 1,
        },
        table_offset,
        _pad: [0; 2],
    };
    let mut surfaces: Vec<IsoSurface> = set
        .values
        .iter()
        .zip(&set.sides)
        .map(|(&v, sides)| IsoSurface {
            value: [gpu_level(map.apply(v)), 0.0, 0.0, 0.0],
            front: sides[0].map(|c| c as f32),
            back: sides[1].map(|c| c as f32),
        })
        .collect();
    if surfaces.is_empty() {
        surfaces.push(IsoSurface::default());
    }
    (params, surfaces)
}

/// The volume between the crossings.
pub enum Volume {
    /// None (`--mode iso`).
    None,
    /// The closed-form integral per fragment (`exact-frag`).
    Integral,
    /// A pre-integrated table mode.
    Table(PreintMode),
}

/// The volume's twin.
pub enum VolumeTwin {
    None,
    Integral(ExactFragTwin),
    /// The table's twin and [`IsoParams::table_offset`].
    Table(PreintTwin, f32),
}

impl VolumeTwin {
    /// Twin of the stage's `volume`.
    pub fn volume(&self, l: f32, sf: f32, sb: f32) -> [f32; 4] {
        match self {
            VolumeTwin::None => [0.0; 4],
            VolumeTwin::Integral(t) => t.volume(l, sf, sb),
            VolumeTwin::Table(t, offset) => t.volume(l, sf + offset, sb + offset),
        }
    }
}

/// The isosurface stage's bindings on the CPU, for its twin [`fs_iso`].
pub struct IsoTwin {
    view: SegmentView,
    mapper: ClipMapper,
    pub(crate) params: IsoParams,
    pub(crate) surfaces: Vec<IsoSurface>,
    pub(crate) volume: VolumeTwin,
}

/// Twin of `count_at_most`: the number of isovalues `<= x` for an `x`
/// between surfaces `first - 1` and `end`, searched among `first..end`.
pub fn count_at_most(stage: &IsoTwin, x: f32, first: u32, end: u32) -> u32 {
    let (mut lo, mut hi) = (first, end);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if stage.surfaces[mid as usize].value[0] <= x {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Twin of `iso_window`: the surfaces `a..b` the segment from `s_f` to
/// `s_b` crosses, among the part's `candidates` ([`IsoVertex::candidates`]).
pub fn iso_window(stage: &IsoTwin, s_f: f32, s_b: f32, candidates: [f32; 2]) -> [u32; 2] {
    let (first, end) = (candidates[0] as u32, candidates[1] as u32);
    if first < end {
        let a = count_at_most(stage, s_f.min(s_b), first, end);
        return [a, count_at_most(stage, s_f.max(s_b), first, end).max(a)];
    }
    [first, first]
}

/// Twin of `iso_light`.
pub fn iso_light(stage: &IsoTwin, g: [f32; 3]) -> f32 {
    if stage.params.lighting == 0 {
        return 1.0;
    }
    let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if n.is_nan() || n <= 0.0 || !n.is_finite() {
        return 1.0;
    }
    stage.params.ambient + stage.params.diffuse * (g[2].abs() / n).min(1.0)
}

/// Twin of `iso_surface`.
pub fn iso_surface(stage: &IsoTwin, k: u32, rising: bool, g: [f32; 3], w: f32) -> [f32; 4] {
    let s = &stage.surfaces[k as usize];
    let c = if rising { s.front } else { s.back };
    let a = (c[3] * w).clamp(0.0, 1.0);
    let i = iso_light(stage, g) * a;
    [c[0] * i, c[1] * i, c[2] * i, a]
}

/// Twin of `iso_over`.
pub fn iso_over(front: [f32; 4], back: [f32; 4]) -> [f32; 4] {
    let t = 1.0 - front[3];
    std::array::from_fn(|k| front[k] + t * back[k])
}

/// Twin of `iso_crosses`.
pub fn iso_crosses(v: f32, seg: &Seg) -> bool {
    let (lo, hi) = (seg.s_f.min(seg.s_b), seg.s_f.max(seg.s_b));
    v > lo && v <= hi
}

/// Twin of `fs_iso` in `shaders/iso.wgsl`, the fragment at weights `bary`
/// of `tri` drawn with `stage`'s bindings.
pub fn fs_iso(stage: &IsoTwin, tri: [&IsoVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
    let seg = segment_at(&stage.view, &stage.mapper, tri.map(|v| &v.seg), bary);
    if !seg.ok {
        return None;
    }
    let mut gf = [0, 1, 2].map(|k| lerp(tri, bary, |v| v.grad_front[k]));
    let mut gb = [0, 1, 2].map(|k| lerp(tri, bary, |v| v.grad_back[k]));
    if stage.view.ortho != 1 {
        let qf = lerp(tri, bary, |v| v.seg.front[1]);
        let qb = lerp(tri, bary, |v| v.seg.back[1]);
        gf = gf.map(|g| g / qf);
        gb = gb.map(|g| g / qb);
    }
    let candidates = tri[0].candidates;
    Some(match &stage.volume {
        VolumeTwin::Integral(t) => super::iso_walk::iso_segment(stage, t, &seg, gf, gb, candidates),
        _ => super::iso_split::iso_segment(stage, &seg, gf, gb, candidates),
    })
}

impl CpuStage<IsoVertex> for IsoTwin {
    fn shade(&self, tri: [&IsoVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_iso(self, tri, bary)
    }

    fn describe(&self, tri: [&IsoVertex; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let seg = segment_at(&self.view, &self.mapper, tri.map(|v| &v.seg), bary);
        let mut out = vec![("s_f", seg.s_f), ("s_b", seg.s_b), ("l", seg.l)];
        // The gradients as `fs_iso` reads them (view space, per unit of the
        // normalised scalar).
        let (qf, qb) = if self.view.ortho != 1 {
            (
                lerp(tri, bary, |v| v.seg.front[1]),
                lerp(tri, bary, |v| v.seg.back[1]),
            )
        } else {
            (1.0, 1.0)
        };
        for (k, name) in ["gf_x", "gf_y", "gf_z"].into_iter().enumerate() {
            out.push((name, lerp(tri, bary, |v| v.grad_front[k]) / qf));
        }
        for (k, name) in ["gb_x", "gb_y", "gb_z"].into_iter().enumerate() {
            out.push((name, lerp(tri, bary, |v| v.grad_back[k]) / qb));
        }
        out
    }
}

/// The payload of one part: the segment payload, and the entry and exit
/// gradients of every vertex (normalised scalar units, view space).
#[derive(Default)]
pub struct IsoPayload {
    seg: SegmentPayload,
    grads: Vec<[DVec3; 2]>,
    /// The part's [`IsoVertex::candidates`].
    candidates: [f32; 2],
    /// Scratch: the vertices whose gradients are set.
    done: Vec<bool>,
}

/// The surfaces of `set` (their values through `map` as the stage holds
/// them) within the part's normalised scalar range widened by
/// [`RANGE_MARGIN`] ([`IsoVertex::candidates`]); every surface for a part
/// without scalars.
fn part_candidates(part: &Polyhedron, map: &ScalarMap, set: &IsoSet) -> [f32; 2] {
    let n = set.values.len();
    let (lo, hi) = crate::render::pieces::value_range(part.scalars.iter().copied());
    if lo.is_nan() || hi.is_nan() || lo > hi {
        return [0.0, n as f32];
    }
    let (lo, hi) = (map.apply(lo), map.apply(hi));
    let widen = |v: f64, sign: f64| v + sign * RANGE_MARGIN * v.abs().max(1.0);
    let level = |v: &f64| gpu_level(map.apply(*v)) as f64;
    let first = set.values.partition_point(|v| level(v) <= widen(lo, -1.0));
    let end = set.values.partition_point(|v| level(v) <= widen(hi, 1.0));
    [first as f32, end.max(first) as f32]
}

/// The values of a part's search window ([`part_candidates`]): the only
/// ones its fragments can cross (a line where a face's scalar is another
/// lies where neither piece sharing the face crosses it).
fn window(values: &[f64], [first, end]: [f32; 2]) -> &[f64] {
    let end = (end as usize).min(values.len());
    &values[(first as usize).min(end)..end]
}

/// Isosurfaces alone or over a volume, on the projected-cell driver.
pub struct IsoMode {
    volume: Volume,
    set: IsoSet,
    /// World-space point gradients (smooth light).
    gradients: Option<Vec<DVec3>>,
}

impl IsoMode {
    /// The surfaces `set` over `volume`; `gradients` are the points'
    /// (needed for smooth light, [`crate::render::gradients::point_gradients`]).
    pub fn new(volume: Volume, set: IsoSet, gradients: Option<Vec<DVec3>>) -> IsoMode {
        IsoMode {
            volume,
            set,
            gradients,
        }
    }

    /// This mode with the points' gradients for smooth light
    /// ([`crate::render::gradients::point_gradients_where`]) where it can
    /// draw a surface: at the points of every cell of `mesh` whose range of
    /// `values` (normalised by [`Self::map`]) widened by [`GRADIENT_MARGIN`]
    /// holds an isovalue, zero elsewhere. Each piece's range lies in its
    /// cell's, so every piece that can search a value
    /// ([`IsoVertex::candidates`], with a tenth of that margin) has its
    /// gradients; the others cross nothing and read none. A narrow set of
    /// values then visits few cells (the generated 1M-hex grid, one value:
    /// 0.2 s of the frame's 0.9 s for every point's gradient).
    pub fn with_surface_gradients(
        mut self,
        tf: &TransferFunction,
        mesh: &crate::mesh::Mesh,
        values: &[f64],
    ) -> IsoMode {
        let map = self.map(tf);
        let levels: Vec<f64> = self.set.values.iter().map(|&v| map.apply(v)).collect();
        let wanted = |c: usize| {
            let scalar = |p: &u32| values.get(*p as usize).copied().unwrap_or(f64::NAN);
            let (lo, hi) =
                crate::render::pieces::value_range(mesh.cells.nodes(c).iter().map(scalar));
            // As the candidates: a cell without a range may search any.
            if lo.is_nan() || hi.is_nan() || lo > hi {
                return true;
            }
            let widen = |v: f64, sign: f64| v + sign * GRADIENT_MARGIN * v.abs().max(1.0);
            let (a, b) = (widen(map.apply(lo), -1.0), widen(map.apply(hi), 1.0));
            let k = levels.partition_point(|&x| x < a);
            levels.get(k).is_some_and(|&x| x <= b)
        };
        self.gradients = Some(crate::render::gradients::point_gradients_where(
            mesh, values, wanted,
        ));
        self
    }

    /// What the last frame's table build did (a table volume).
    pub fn take_stats(&self) -> Option<TableStats> {
        match &self.volume {
            Volume::Table(p) => p.take_stats(),
            _ => None,
        }
    }

    fn stage(&self) -> &'static StageDesc {
        match &self.volume {
            Volume::None => &ISO_STAGE,
            Volume::Integral => &ISO_EXACT_FRAG_STAGE,
            Volume::Table(p) => match p.kind() {
                TableKind::Cube => &ISO_PREINT3D_STAGE,
                TableKind::Flat => &ISO_PREINT2D_STAGE,
                TableKind::Cylinder => &ISO_PREINT2D_CYL_STAGE,
            },
        }
    }

    /// The map of the stage's scalars for one frame of `tf`: centred on
    /// the isovalues ([`ScalarMap::centred`]); a table volume's lookups,
    /// which need the transfer function's first node at 0 and its last at
    /// 1, add [`Self::table_offset`].
    pub fn map(&self, tf: &TransferFunction) -> ScalarMap {
        ScalarMap::centred(tf, &self.set.values)
    }

    /// The origin of [`Self::map`] in a table volume's terms (the transfer
    /// function's normalised scalar, [`ScalarMap::of`], whose scale is the
    /// same): what its lookups add to the fragment's scalars. 0 for the
    /// other volumes.
    pub fn table_offset(&self, tf: &TransferFunction) -> f32 {
        match &self.volume {
            Volume::Table(_) => ScalarMap::of(tf).apply(self.map(tf).offset) as f32,
            Volume::None | Volume::Integral => 0.0,
        }
    }

    /// The twin for one frame of `tf` seen by `camera` over `mesh`.
    pub fn twin_for(
        &self,
        mesh: &crate::mesh::Mesh,
        tf: &TransferFunction,
        camera: &crate::camera::Camera,
    ) -> IsoTwin {
        let map = self.map(tf);
        let volume = match &self.volume {
            Volume::None => VolumeTwin::None,
            Volume::Integral => VolumeTwin::Integral(
                ExactFragTwin::with(
                    SegmentView::of(camera),
                    ClipMapper::for_camera(camera),
                    TfBuffer::new(tf, &map),
                )
                .for_mesh(mesh),
            ),
            Volume::Table(p) => {
                VolumeTwin::Table(p.twin_for(mesh, tf, camera), self.table_offset(tf))
            }
        };
        IsoTwin::new(&self.set, &map, camera, volume)
    }
}

impl IsoTwin {
    /// The twin of a stage drawing `set`'s surfaces (scalars through `map`)
    /// over `volume`, seen by `camera`.
    pub fn new(
        set: &IsoSet,
        map: &ScalarMap,
        camera: &crate::camera::Camera,
        volume: VolumeTwin,
    ) -> IsoTwin {
        let offset = match volume {
            VolumeTwin::Table(_, offset) => offset,
            VolumeTwin::None | VolumeTwin::Integral(_) => 0.0,
        };
        let (params, surfaces) = iso_buffers(set, map, offset);
        IsoTwin {
            view: SegmentView::of(camera),
            mapper: ClipMapper::for_camera(camera),
            params,
            surfaces,
            volume,
        }
    }
}

/// The smooth gradient at `x` on boundary triangle `t` of `part`.
pub(super) fn face_gradient(part: &Polyhedron, t: u32, x: DVec3) -> Option<DVec3> {
    let tri = part.triangles.get(t as usize)?;
    let p = tri.map(|i| part.points.get(i as usize).copied());
    let g = tri.map(|i| part.gradients.get(i as usize).copied());
    let (Some(p0), Some(p1), Some(p2)) = (p[0], p[1], p[2]) else {
        return None;
    };
    let (Some(g0), Some(g1), Some(g2)) = (g[0], g[1], g[2]) else {
        return None;
    };
    let w = barycentric([p0, p1, p2], x);
    Some(g0 * w[0] + g1 * w[1] + g2 * w[2])
}

/// [`face_gradient`] at the region vertex at pixel position `q` on
/// boundary triangle `t` of `part`, whose projection is `faces[t]`: the
/// corners' gradients weighted as [`crate::projection::FaceTri::eval`]
/// weights the scalar (perspective-correct: in view space, the
/// barycentric weights of the point there, clamped to the triangle as
/// [`face_gradient`] clamps them), from the pixel position alone. `None`
/// where the projected triangle is narrower than
/// [`crate::numeric::tolerance::GRADIENT_FACE_WIDTH_PX`], whose
/// weights on screen are ill-conditioned ([`face_gradient`] then).
fn face_gradient_at(
    part: &Polyhedron,
    faces: &[crate::projection::FaceTri],
    ortho: bool,
    t: u32,
    q: DVec2,
) -> Option<DVec3> {
    let tri = part.triangles.get(t as usize)?;
    let f = faces.get(t as usize)?;
    let g = tri.map(|i| part.gradients.get(i as usize).copied());
    let (Some(g0), Some(g1), Some(g2)) = (g[0], g[1], g[2]) else {
        return None;
    };
    // (0 for a degenerate or non-finite triangle.)
    if f.width() < crate::numeric::tolerance::GRADIENT_FACE_WIDTH_PX {
        return None;
    }
    let lam = f.barycentric(q)?.map(|l| l.max(0.0));
    let w = if ortho {
        lam
    } else {
        [lam[0] / f.z[0], lam[1] / f.z[1], lam[2] / f.z[2]]
    };
    let sum = w[0] + w[1] + w[2];
    (sum > 0.0 && sum.is_finite()).then(|| (g0 * w[0] + g1 * w[1] + g2 * w[2]) / sum)
}

/// A region vertex's entry (`side` 0) or exit point in view space.
pub(super) fn view_point(proj: &Projected, i: usize, side: usize) -> DVec3 {
    let v = &proj.vertices[i];
    let z = if side == 0 { v.z_front } else { v.z_back };
    let u = proj.view.plane(DVec2::new(v.px, v.py));
    if proj.view.ortho {
        DVec3::new(u.x, u.y, z)
    } else {
        DVec3::new(u.x * z, u.y * z, z)
    }
}

impl ProjectedMode for IsoMode {
    type Vertex = IsoVertex;
    type Payload = IsoPayload;

    fn split_points(&self, _tf: &TransferFunction) -> Vec<f64> {
        Vec::new()
    }

    fn perspective_refine(&self) -> bool {
        SegmentVertex::needs_perspective_refinement()
    }

    fn isosurfaces(&self) -> Option<&IsoSet> {
        Some(&self.set)
    }

    fn fragment_isovalues(&self) -> &[f64] {
        &self.set.values
    }

    fn part_isovalues(&self, payload: &IsoPayload) -> &[f64] {
        window(&self.set.values, payload.candidates)
    }

    fn fragment_iso_origin(&self, src: &PieceSource) -> f64 {
        self.map(src.tf).offset
    }

    fn draws_volume(&self) -> bool {
        !matches!(self.volume, Volume::None)
    }

    fn point_gradients(&self) -> Option<&[DVec3]> {
        match self.set.lighting {
            Lighting::Smooth => self.gradients.as_deref(),
            _ => None,
        }
    }

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        let map = self.map(src.tf);
        let (params, surfaces) = iso_buffers(&self.set, &map, self.table_offset(src.tf));
        let extra = [
            Resource::Uniform(bytemuck::bytes_of(&params)),
            Resource::Storage(bytemuck::cast_slice(&surfaces)),
        ];
        let view = SegmentView::of(src.camera);
        match &self.volume {
            Volume::None => {
                let tf = TfBuffer::new(src.tf, &map);
                bind_integral_stage(gpu, self.stage(), &view, &tf, &extra)
            }
            Volume::Integral => {
                let tf = TfBuffer::new(src.tf, &map);
                let longest = longest_segment(gpu, src)?;
                let stage = integral_stage(&tf, longest, &ISO_EXACT_FRAG_STAGES);
                bind_integral_stage(gpu, stage, &view, &tf, &extra)
            }
            Volume::Table(p) => p.bind_stage(
                gpu,
                Some(self.stage()),
                src.whole,
                src.tf,
                src.camera,
                &extra,
            ),
        }
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<IsoVertex>> {
        Box::new(self.twin_for(src.whole, src.tf, src.camera))
    }

    fn payload(
        &self,
        src: &PieceSource,
        part: &Polyhedron,
        proj: &mut Projected,
        used: &mut Vec<bool>,
        payload: &mut IsoPayload,
        _refined: &mut usize,
    ) {
        payload.seg.set(src);
        payload.seg.map = self.map(src.tf);
        let scale = payload.seg.map.scale;
        payload.candidates = part_candidates(part, &payload.seg.map, &self.set);
        // Where a boundary triangle's scalar is an isovalue, a surface
        // meets the face shared with the next piece: the two pieces
        // interpolate the face's scalar on different triangles with
        // snapped corners, so a centre next to that line could fall below
        // the value in one and above it in the other (a crack, or the
        // surface twice). The driver decides such centres exactly
        // ([`crate::render::ties`]), with the ray caster's crossing of the
        // face, the same in both. (Tie values have no faces.)
        let values = window(&self.set.values, payload.candidates);
        for face in &proj.faces {
            super::iso_seams::iso_lines(
                face,
                values,
                payload.seg.ortho,
                payload.seg.map.offset,
                &mut proj.seam_lines,
            );
        }
        payload.grads.clear();
        payload.grads.resize(proj.vertices.len(), [DVec3::ZERO; 2]);
        // No light, or no isovalue within the part's range: no fragment
        // of it lights a surface (its search window is empty), so its
        // gradients are never read (most parts with one value).
        let [first, end] = payload.candidates;
        if self.set.lighting == Lighting::None || first >= end {
            return;
        }
        let flat = piece_gradient(part) * scale;
        let smooth =
            self.set.lighting == Lighting::Smooth && part.gradients.len() == part.points.len();
        if !smooth {
            payload.grads.fill([flat; 2]);
            return;
        }
        // A region vertex lies on its regions' front and back triangles
        // (any of them: the smooth field is continuous): interpolate on the
        // first region's; a vertex without a region (a tie triangle's) searches
        // the boundary.
        let mut done = std::mem::take(&mut payload.done);
        done.clear();
        done.resize(proj.vertices.len(), false);
        for (r, reg) in proj.regions.iter().enumerate() {
            let Some(&faces) = proj.region_faces.get(r) else {
                continue;
            };
            for &v in reg {
                let v = v as usize;
                if done[v] {
                    continue;
                }
                done[v] = true;
                let q = proj.vertices[v].pos();
                payload.grads[v] = [0, 1].map(|side| {
                    face_gradient_at(part, &proj.faces, proj.view.ortho, faces[side], q)
                        .or_else(|| face_gradient(part, faces[side], view_point(proj, v, side)))
                        .unwrap_or(flat / scale)
                        * scale
                });
            }
        }
        // A tie vertex (no region) knows the boundary triangles its ray
        // enters and leaves by (`Projected::tie_faces`); any other searches
        // the boundary.
        for (i, g) in payload.grads.iter_mut().enumerate() {
            if done[i] || !used.get(i).copied().unwrap_or(true) {
                continue;
            }
            let faces = proj.tie_faces.get(i);
            *g = [0, 1].map(|side| {
                let x = view_point(proj, i, side);
                faces
                    .and_then(|f| face_gradient(part, f[side], x))
                    .unwrap_or_else(|| boundary_gradient(part, x, flat / scale))
                    * scale
            });
        }
        payload.done = done;
    }

    fn vertex(&self, payload: &IsoPayload, proj: &Projected, i: usize, ndc: [f32; 2]) -> IsoVertex {
        let mut seg = SegmentVertex::of(proj, i, ndc, &payload.seg.map, payload.seg.ortho);
        let g = payload.grads.get(i).copied().unwrap_or([DVec3::ZERO; 2]);
        let v = &proj.vertices[i];
        // A tie triangle's exact segment (its values come with their faces)
        // decides its pixel as the ray caster does: its ends on the
        // reference's side of every level. Not a region vertex's: its
        // values are interpolated over the region, where the stage's
        // margin keeps a field that stays within it of a value (a face
        // whose corners all hold the value) from crossing it.
        if !proj.tie_faces.is_empty() {
            let map = &payload.seg.map;
            seg.front = decided_end(&self.set, map, v.s_front, seg.front);
            seg.back = decided_end(&self.set, map, v.s_back, seg.back);
        }
        let (zf, zb) = (v.z_front, v.z_back.max(v.z_front));
        let (qf, qb) = if payload.seg.ortho || !(zf > 0.0 && zb.is_finite()) {
            (1.0, 1.0)
        } else {
            (1.0 / zf, 1.0 / zb)
        };
        let f32x3 = |g: DVec3, q: f64| {
            let g = g * q;
            [g.x as f32, g.y as f32, g.z as f32].map(|c| if c.is_finite() { c } else { 0.0 })
        };
        IsoVertex {
            seg,
            grad_front: f32x3(g[0], qf),
            grad_back: f32x3(g[1], qb),
            candidates: payload.candidates,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_matches_struct() {
        assert_eq!(std::mem::size_of::<IsoVertex>(), 72);
        let offs: Vec<u64> = IsoVertex::ATTRIBUTES.iter().map(|a| a.offset).collect();
        assert_eq!(offs, vec![0, 16, 24, 32, 36, 40, 52, 64]);
        assert_eq!(std::mem::size_of::<IsoSurface>(), 48);
    }
}
