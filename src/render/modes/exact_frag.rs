//! The exact-frag mode: every fragment evaluates the closed-form
//! Williams–Max integral of its own ray segment through its piece, over
//! every transfer-function piece between the segment's end scalars. There
//! is no table (so no table error), no colour interpolation (so no colour
//! refinement) and no slicing at breakpoints (so fewer, whole pieces).
//!
//! On the shared projected-cell driver ([`crate::render::driver`]) it
//! supplies:
//! - **split policy**: none (cells with a breakpoint in their scalar range
//!   stay whole; the fragment loops over the breakpoints);
//! - **payload**: the segment payload ([`super::segment`]): `s_f`, `s_b`
//!   and `l` per region vertex, exact under linear interpolation in
//!   orthographic views and, through `1/z`, in perspective views (so the
//!   regions need no perspective refinement);
//! - **stage** (`shaders/exact_frag.wgsl` behind `shaders/segment.wgsl` and
//!   `shaders/integral.wgsl`, [`EXACT_FRAG_STAGE`]): per fragment
//!   `integrate_segment(l, s_f, s_b)` in `f32`; [`fs_main`] is its CPU twin
//!   (on [`super::segment::segment_at`] and [`super::integral`]).
//!
//! Glow and independent emission are both exact (the fragment integrates
//! the source the transfer function defines). Within a whole cell the
//! scalar is linear along each ray between its entry and exit values (the
//! ray caster's `faces` model); pieces the order splits into tets integrate
//! the `tets` field.

use crate::gpu::cpu::CpuStage;
use crate::gpu::{Binding, ClipMapper, Context, GpuError, Resource, Stage, StageDesc};
use crate::raycast::FieldModel;
use crate::render::pieces::PieceSource;
use crate::tf::{EmissionModel, TransferFunction};

use super::integral::{closed_form_constants, GaussRule, TfBuffer};
use super::preint_tables::{SceneLengths, TableCache};
use super::segment::{segment_at, ScalarMap, SegmentMode, SegmentVertex, SegmentView};
use super::{Bounds, ModeInfo};

/// The registry entry of the exact-frag mode.
pub static INFO: ModeInfo = ModeInfo {
    name: "exact-frag",
    summary: "projection of convex pieces, the exact ray integral evaluated per fragment by wgpu",
    gpu: true,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    draws_pieces_whole: true,
    stage: Some(&EXACT_FRAG_STAGE),
    bounds: Some(Bounds {
        reference: FieldModel::Faces,
        // Measured at most 2.1e-3 (tests/modes.rs scenes, both backends):
        // f32 arithmetic and the snap of region corners to the sub-pixel
        // grid.
        split_max: 2.0 / 255.0,
        // Measured 1.18e-2 (zoo_3x3x3, perspective), the same as the exact
        // mode: the order splits cells with nonplanar faces into tets, whose
        // field differs from the `faces` model there. Elsewhere whole cells
        // integrate the `faces` field itself (within 5.4e-4).
        whole_max: 0.02,
        split_outliers: 0,
        whole_outliers: 0,
    }),
};

/// The exact-frag stage: the segment vertex and view, the integral, and
/// the fragment entry points.
pub static EXACT_FRAG_STAGE: StageDesc = exact_frag_stage("exact_frag.wgsl", &[]);

/// The exact-frag stage's variants ([`integral_stage`] picks one per
/// frame): [`EXACT_FRAG_STAGE`] where a segment can be optically thick,
/// else compiled without the closed form for thick segments
/// (`THICK_SEGMENTS` false in `shaders/integral.wgsl`: about 12 % faster
/// on llvmpipe) and with the frame's Gauss rule (`GAUSS_NODES`).
pub static EXACT_FRAG_STAGES: IntegralStages = IntegralStages {
    full: &EXACT_FRAG_STAGE,
    thin: [
        &exact_frag_stage("exact_frag.wgsl+thin4", THIN_CONSTANTS[0]),
        &exact_frag_stage("exact_frag.wgsl+thin5", THIN_CONSTANTS[1]),
        &exact_frag_stage("exact_frag.wgsl+thin6", THIN_CONSTANTS[2]),
    ],
};

/// The variants of one stage that includes `shaders/integral.wgsl` for its
/// volume: `full` draws every segment, `thin` only segments no thicker
/// than [`GAUSS_MAX`](super::integral::GAUSS_MAX), with the Gauss rule of
/// 4, 5 and 6 nodes ([`GaussRule`]). The same images within the rules' error (below
/// `f32`'s rounding unit).
pub struct IntegralStages {
    pub full: &'static StageDesc,
    pub thin: [&'static StageDesc; 3],
}

/// The override constants of the thin stages, by Gauss rule (4, 5, 6
/// nodes).
pub const THIN_CONSTANTS: [&[(&str, f64)]; 3] = [
    &[("THICK_SEGMENTS", 0.0), ("GAUSS_NODES", 4.0)],
    &[("THICK_SEGMENTS", 0.0), ("GAUSS_NODES", 5.0)],
    &[("THICK_SEGMENTS", 0.0), ("GAUSS_NODES", 6.0)],
];

impl IntegralStages {
    /// Every variant (for shader validation).
    pub fn all(&self) -> [&'static StageDesc; 4] {
        [self.full, self.thin[0], self.thin[1], self.thin[2]]
    }
}

/// The exact-frag WGSL as the stage `name` with `constants`.
const fn exact_frag_stage(
    name: &'static str,
    constants: &'static [(&'static str, f64)],
) -> StageDesc {
    StageDesc {
        name,
        fragment: "fs_main",
        wgsl: concat!(
            include_str!("../../../shaders/segment_vertex.wgsl"),
            include_str!("../../../shaders/segment_view.wgsl"),
            include_str!("../../../shaders/segment.wgsl"),
            include_str!("../../../shaders/integral.wgsl"),
            include_str!("../../../shaders/exact_frag.wgsl"),
        ),
        vertex: SegmentVertex::LAYOUT,
        bindings: &[Binding::Uniform, Binding::Storage, Binding::Storage],
        constants,
    }
}

/// The Gauss rule of a frame whose segments are at most `max_length` long,
/// or `None` where one can reach the closed form's optical thickness: the
/// largest extinction of the transfer function (its nodes' extinctions in
/// `f32`, as the stage reads them; the function is linear between them and
/// constant beyond) times the longest segment a piece can hold
/// (`max_length`, the mesh's largest cell diameter), with a margin of
/// [`THIN_MARGIN`] for the rounding of interpolated lengths, is the
/// thickest segment's depth; the shortest rule holding it
/// ([`GaussRule::for_depth`]).
pub fn thin_rule(tf: &TfBuffer, max_length: f64) -> Option<GaussRule> {
    let depth = tf.max_tau() as f64 * max_length * (1.0 + THIN_MARGIN);
    if !depth.is_finite() {
        return None;
    }
    GaussRule::for_depth(depth)
}

/// Relative margin on a segment's length in [`thin_rule`]: the
/// rasteriser interpolates `l` (or `q_f - q_b`) in `f32`, a few ulps off.
pub const THIN_MARGIN: f64 = 1e-3;

/// The variant of `stages` for a frame whose segments are at most
/// `max_length` long: the thin stage of [`thin_rule`]'s Gauss rule where
/// no segment can be optically thick, else the full one (6 nodes): the
/// one choice of every stage that includes `shaders/integral.wgsl` for its
/// volume ([`twin_rule`] is the same choice for a twin).
pub fn integral_stage(
    tf: &TfBuffer,
    max_length: f64,
    stages: &IntegralStages,
) -> &'static StageDesc {
    match thin_rule(tf, max_length) {
        Some(GaussRule::Four) => stages.thin[0],
        Some(GaussRule::Five) => stages.thin[1],
        Some(GaussRule::Six) => stages.thin[2],
        None => stages.full,
    }
}

/// The Gauss rule of [`integral_stage`] for a twin drawing `mesh` with
/// `tf` (normalised as the stage reads it).
pub fn twin_rule(tf: &TfBuffer, mesh: &crate::mesh::Mesh) -> GaussRule {
    thin_rule(tf, SceneLengths::of(mesh).max_diameter).unwrap_or_default()
}

/// The longest segment a piece of `src`'s mesh can hold: its largest cell
/// diameter, computed once per mesh on the device's table cache.
pub fn longest_segment(gpu: &Context, src: &PieceSource) -> Result<f64, GpuError> {
    Ok(TableCache::of(gpu)?.lengths(src.whole).max_diameter)
}

/// Binds the exact-frag stage for one frame: its view and transfer
/// function (normalised as the vertices' scalars are), the thin stage
/// where no segment up to `max_length` can be optically thick
/// ([`integral_stage`]).
pub fn bind_exact_frag_stage(
    gpu: &Context,
    view: &SegmentView,
    tf: &TfBuffer,
    max_length: f64,
) -> Result<Stage, GpuError> {
    let stage = integral_stage(tf, max_length, &EXACT_FRAG_STAGES);
    bind_integral_stage(gpu, stage, view, tf, &[])
}

/// Binds `stage`, a stage on the segment payload with the closed-form
/// integral at bindings 1 and 2, with `extra` resources from binding 3 on.
pub fn bind_integral_stage(
    gpu: &Context,
    stage: &'static StageDesc,
    view: &SegmentView,
    tf: &TfBuffer,
    extra: &[Resource],
) -> Result<Stage, GpuError> {
    let consts = closed_form_constants();
    let tf = tf.bytes();
    let mut res = vec![
        Resource::Uniform(bytemuck::bytes_of(view)),
        Resource::Storage(&tf),
        Resource::Storage(bytemuck::cast_slice(&consts)),
    ];
    res.extend_from_slice(extra);
    gpu.bind_stage(stage, &res)
}

/// The exact-frag stage's bindings on the CPU (view, transfer function,
/// the closed form's constants), for its twin [`fs_main`].
pub struct ExactFragTwin {
    view: SegmentView,
    mapper: ClipMapper,
    tf: TfBuffer,
    consts: Vec<[f32; 4]>,
    rule: GaussRule,
}

impl ExactFragTwin {
    /// The twin for `tf` seen by `camera`.
    pub fn new(tf: &TransferFunction, camera: &crate::camera::Camera) -> ExactFragTwin {
        ExactFragTwin::with(
            SegmentView::of(camera),
            ClipMapper::for_camera(camera),
            TfBuffer::new(tf, &ScalarMap::of(tf)),
        )
    }

    /// The twin of a stage bound to `view` and `tf`, drawing through
    /// `mapper`.
    pub fn with(view: SegmentView, mapper: ClipMapper, tf: TfBuffer) -> ExactFragTwin {
        ExactFragTwin {
            view,
            mapper,
            tf,
            consts: closed_form_constants(),
            rule: GaussRule::Six,
        }
    }

    /// The twin of the stage drawing `mesh`: with the Gauss rule
    /// [`integral_stage`] picks for it ([`twin_rule`]).
    pub fn for_mesh(mut self, mesh: &crate::mesh::Mesh) -> ExactFragTwin {
        self.rule = twin_rule(&self.tf, mesh);
        self
    }

    /// The Gauss rule the twin integrates thin pieces with.
    pub fn rule(&self) -> GaussRule {
        self.rule
    }
}

impl ExactFragTwin {
    /// The integral of the segment `(l, s_f, s_b)` (normalised scalars).
    pub fn volume(&self, l: f32, sf: f32, sb: f32) -> [f32; 4] {
        self.tf
            .integrate_segment(&self.consts, self.rule, l, sf, sb)
    }

    /// The transfer function, the closed form's constants and the Gauss
    /// rule the stage integrates with.
    pub(crate) fn integral(&self) -> (&TfBuffer, &[[f32; 4]], GaussRule) {
        (&self.tf, &self.consts, self.rule)
    }

    /// The stage's view and clip mapping.
    pub fn view(&self) -> (SegmentView, ClipMapper) {
        (self.view, self.mapper)
    }
}

/// Twin of `fs_main` in `shaders/exact_frag.wgsl`, the fragment at
/// weights `bary` of `tri` drawn with `stage`'s bindings: its segment
/// (`segment_at`), integrated (`integrate_segment`).
pub fn fs_main(
    stage: &ExactFragTwin,
    tri: [&SegmentVertex; 3],
    bary: [f64; 3],
) -> Option<[f32; 4]> {
    let seg = segment_at(&stage.view, &stage.mapper, tri, bary);
    if !seg.ok {
        return None;
    }
    Some(
        stage
            .tf
            .integrate_segment(&stage.consts, stage.rule, seg.l, seg.s_f, seg.s_b),
    )
}

impl CpuStage<SegmentVertex> for ExactFragTwin {
    fn shade(&self, tri: [&SegmentVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_main(self, tri, bary)
    }

    fn describe(&self, tri: [&SegmentVertex; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let seg = segment_at(&self.view, &self.mapper, tri, bary);
        vec![("s_f", seg.s_f), ("s_b", seg.s_b), ("l", seg.l)]
    }
}

/// The exact-frag mode on the projected-cell driver.
pub struct ExactFragMode;

impl SegmentMode for ExactFragMode {
    type Vertex = SegmentVertex;

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        let tf = TfBuffer::new(src.tf, &ScalarMap::of(src.tf));
        let longest = longest_segment(gpu, src)?;
        bind_exact_frag_stage(gpu, &SegmentView::of(src.camera), &tf, longest)
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<SegmentVertex>> {
        Box::new(ExactFragTwin::new(src.tf, src.camera).for_mesh(src.whole))
    }
}
