//! The table modes (`preint3d`, `preint2d`, `preint2d-cyl`) with their
//! pieces drawn whole (`--piece-draw quads`, and `auto` on a hardware GPU),
//! as exact-frag draws them ([`super::piece_quad`]): the CPU sorts and
//! packs each piece into one [`QuadVertex`], the driver draws it over its
//! outline, and each fragment finds its own segment `(s_f, s_b, l)` by the
//! watertight search of `shaders/piece_quad.wgsl` and looks it up in the
//! mode's table through the same fragment program as on the region path
//! (`shaders/preint.wgsl`: the parts outside the transfer function's range
//! in closed form, the rest in table steps, the mode's own filter).
//!
//! Nothing here is new code on the GPU: each stage is the quad vertex and
//! segment file in place of the region vertex and segment files of the
//! mode's own stage, on the same bindings. The pieces the quad vertex
//! declines (near plane, faces nearly edge-on, optically thick beyond
//! what `f32` geometry settles, more than 8 points) are projected as
//! regions into the same stage, with their exact tie decisions.

use crate::gpu::cpu::CpuStage;
use crate::gpu::{Binding, ClipMapper, Context, GpuError, Stage, StageDesc};
use crate::projection::Polyhedron;
use crate::render::pieces::PieceSource;

use super::piece_quad::{QuadTwin, QuadVertex, SegmentTwin};
use super::preint::{PreintMode, PreintTwin};
use super::preint_tables::TableKind;
use super::segment::{SegmentMode, SegmentPayload, SegmentView};

/// A table stage on the quad vertex: the quad vertex and its segment
/// search, the segment view, the table modes' fragment program and the
/// mode's lookup (`wgsl`), on `bindings` (the view, the mode's table, the
/// table parameters: those of the mode's own stage).
const fn quad_table_stage(
    name: &'static str,
    wgsl: &'static str,
    bindings: &'static [Binding],
) -> StageDesc {
    StageDesc {
        name,
        fragment: "fs_main",
        wgsl,
        vertex: QuadVertex::LAYOUT,
        bindings,
        constants: &[],
    }
}

/// preint3d's stage with whole pieces.
pub static PREINT3D_QUAD_STAGE: StageDesc = quad_table_stage(
    "piece_quad.wgsl+preint3d.wgsl",
    concat!(
        include_str!("../../../shaders/piece_quad.wgsl"),
        include_str!("../../../shaders/segment_view.wgsl"),
        include_str!("../../../shaders/preint.wgsl"),
        include_str!("../../../shaders/preint3d.wgsl"),
    ),
    &[Binding::Uniform, Binding::Table, Binding::Uniform],
);

/// preint2d's stage with whole pieces.
pub static PREINT2D_QUAD_STAGE: StageDesc = quad_table_stage(
    "piece_quad.wgsl+preint2d.wgsl",
    concat!(
        include_str!("../../../shaders/piece_quad.wgsl"),
        include_str!("../../../shaders/segment_view.wgsl"),
        include_str!("../../../shaders/preint.wgsl"),
        include_str!("../../../shaders/preint2d.wgsl"),
    ),
    &[Binding::Uniform, Binding::Table, Binding::Uniform],
);

/// preint2d-cyl's stage with whole pieces.
pub static PREINT2D_CYL_QUAD_STAGE: StageDesc = quad_table_stage(
    "piece_quad.wgsl+preint2d_cyl.wgsl",
    concat!(
        include_str!("../../../shaders/piece_quad.wgsl"),
        include_str!("../../../shaders/segment_view.wgsl"),
        include_str!("../../../shaders/preint.wgsl"),
        include_str!("../../../shaders/preint2d_cyl.wgsl"),
    ),
    &[Binding::Uniform, Binding::Table, Binding::Uniform],
);

/// A table mode with its pieces drawn whole (module docs); the table
/// mode keeps its build statistics ([`PreintMode::take_stats`]).
pub struct PreintQuads<'a>(pub &'a PreintMode);

impl PreintQuads<'_> {
    /// The quad stage of the table kind `kind`.
    pub fn stage(kind: TableKind) -> &'static StageDesc {
        match kind {
            TableKind::Cube => &PREINT3D_QUAD_STAGE,
            TableKind::Flat => &PREINT2D_QUAD_STAGE,
            TableKind::Cylinder => &PREINT2D_CYL_QUAD_STAGE,
        }
    }
}

impl SegmentMode for PreintQuads<'_> {
    type Vertex = QuadVertex;

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        let stage = PreintQuads::stage(self.0.kind());
        self.0
            .bind_stage(gpu, Some(stage), src.whole, src.tf, src.camera, &[])
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<QuadVertex>> {
        Box::new(QuadTwin(self.0.twin_for(src.whole, src.tf, src.camera)))
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

    /// Which pieces go whole depends on the extinction (as for
    /// exact-frag's quads), so a frame is not kept for the next.
    fn keeps_projection(&self) -> bool {
        false
    }
}

impl SegmentTwin for PreintTwin {
    fn view(&self) -> (SegmentView, ClipMapper) {
        PreintTwin::view(self)
    }
    fn volume(&self, l: f32, sf: f32, sb: f32) -> [f32; 4] {
        PreintTwin::volume(self, l, sf, sb)
    }
}
