//! What the pre-integrated table modes share (`preint3d`, `preint2d`,
//! `preint2d-cyl`): the segment payload of [`super::segment`] (so no
//! slicing at breakpoints and no perspective refinement), a table
//! ([`super::preint_tables`]), and one fragment program around each mode's
//! lookup (`shaders/preint.wgsl`, [`preint_segment`] its twin):
//!
//! 1. the fragment rebuilds its segment `(s_f, s_b, l)` exactly
//!    (`segment_at`);
//! 2. the parts of the segment below 0 or above 1 (outside the transfer
//!    function's node range, where it is constant) are homogeneous and
//!    integrated in closed form; the part inside goes to the table, so data
//!    beyond the transfer function's range costs no table resolution;
//! 3. the table spans lengths up to the largest cell diameter (grown by
//!    [`crate::numeric::tolerance::TABLE_LENGTH_MARGIN`]), which bounds
//!    every segment through a piece, so each segment is one lookup (a
//!    length beyond it, only from rounding, reads the last sample); the
//!    three parts are evaluated without branches, absent ones at length 0
//!    (exactly 0): on the software rasterisers a branch runs both sides and
//!    a loop of steps around the lookup cost one more lookup per fragment.
//!    Where every scalar of the field lies inside the transfer function's
//!    node range ([`field_inside`], the default range does that), the
//!    stage is compiled without the parts outside (`EXTENDED` false: one
//!    lookup at the clamped scalars), 9 % faster on lavapipe;
//! 4. the mode's lookup filters the table by hand in `f32` (a storage
//!    buffer, [`crate::gpu::Table`], so the CPU twin filters identically
//!    and GL, which cannot filter `f32` textures, works too).
//!
//! [`PreintMode`] is the [`SegmentMode`] of all three; a mode file gives
//! its registry entry, its stage and its lookup's twin.

use std::sync::{Arc, Mutex};

use bytemuck::{Pod, Zeroable};

use crate::camera::Camera;
use crate::gpu::cpu::CpuStage;
use crate::gpu::{ClipMapper, Context, GpuError, Resource, Stage, StageDesc, Table};
use crate::render::pieces::PieceSource;
use crate::render::{Compositor, RenderOptions, TableBuild, TableOptions};
use crate::tf::{EmissionModel, TransferFunction};

use super::preint_tables::{
    cpu_texels, SceneLengths, TableCache, TableKind, TableSizeError, TableSpec, TableStats,
};
use super::segment::{segment_at, SegmentMode, SegmentVertex, SegmentView};

/// A table mode's stage `$name`: the segment vertex and view, the program
/// the table modes share (`shaders/preint.wgsl`) and the mode's lookup
/// `shaders/$file`, with the values `$constants` of its `override`
/// constants.
macro_rules! preint_stage {
    ($name:literal, $file:literal, $constants:expr) => {
        $crate::gpu::StageDesc {
            name: $name,
            fragment: "fs_main",
            wgsl: concat!(
                include_str!("../../../shaders/segment_vertex.wgsl"),
                include_str!("../../../shaders/segment_view.wgsl"),
                include_str!("../../../shaders/segment.wgsl"),
                include_str!("../../../shaders/preint.wgsl"),
                include_str!(concat!("../../../shaders/", $file)),
            ),
            vertex: $crate::render::modes::segment::SegmentVertex::LAYOUT,
            bindings: &[
                $crate::gpu::Binding::Uniform,
                $crate::gpu::Binding::Table,
                $crate::gpu::Binding::Uniform,
            ],
            constants: $constants,
        }
    };
}
pub(crate) use preint_stage;

/// The parameters of the table stages. Keep in sync with `PreintParams` in
/// `shaders/preint.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct PreintParams {
    /// `(colour or emission, tau)` below the node range.
    pub below: [f32; 4],
    /// `(colour or emission, tau)` above it.
    pub above: [f32; 4],
    pub ns: u32,
    pub nz: u32,
    /// 0: glow, 1: independent emission.
    pub model: u32,
    pub _pad0: u32,
    pub l_table: f32,
    pub _pad1: [f32; 3],
}

impl PreintParams {
    /// The parameters of `spec` for `tf`.
    pub fn new(tf: &TransferFunction, spec: &TableSpec) -> PreintParams {
        let n = tf.s.len() - 1;
        let ext = |i: usize| {
            let c = tf.col[i];
            [c[0] as f32, c[1] as f32, c[2] as f32, tf.tau[i] as f32]
        };
        let l_table = spec.l_table as f32;
        PreintParams {
            below: ext(0),
            above: ext(n),
            ns: spec.size[0],
            nz: spec.size[2],
            model: (tf.model() == EmissionModel::Independent) as u32,
            _pad0: 0,
            l_table,
            _pad1: [0.0; 3],
        }
    }
}

/// A table's texels on the CPU (RGBA, x fastest), for the twins.
#[derive(Clone, Debug)]
pub struct CpuTable {
    pub size: [u32; 3],
    pub data: Vec<f32>,
}

impl CpuTable {
    /// Texel `(i, j, k)` (the storage buffer's `(k * h + j) * w + i`).
    #[inline]
    pub fn load(&self, i: usize, j: usize, k: usize) -> [f32; 4] {
        let [w, h, _] = self.size.map(|v| v as usize);
        let o = 4 * ((k * h + j) * w + i);
        [
            self.data[o],
            self.data[o + 1],
            self.data[o + 2],
            self.data[o + 3],
        ]
    }
}

/// A mode's lookup twin: `table_rgba` of its shader.
pub type LookupFn = fn(&PreintParams, &CpuTable, f32, f32, f32) -> [f32; 4];

/// `(1 - exp(-x)) / x`, stable at 0 (twin of `one_minus_exp_over`).
#[inline]
pub fn one_minus_exp_over(x: f32) -> f32 {
    if x < 1e-3 {
        return 1.0 - 0.5 * x + x * x / 6.0;
    }
    (1.0 - (-x).exp()) / x
}

/// A segment of length `l` in constant material `m` (`homogeneous`).
pub(crate) fn homogeneous(p: &PreintParams, m: [f32; 4], l: f32) -> [f32; 4] {
    let x = (m[3] * l).min(1e30);
    let f = l * one_minus_exp_over(x);
    let alpha = x * one_minus_exp_over(x);
    if p.model == 0 {
        return [m[0] * alpha, m[1] * alpha, m[2] * alpha, alpha];
    }
    [
        (m[0] * f).min(1e30),
        (m[1] * f).min(1e30),
        (m[2] * f).min(1e30),
        alpha,
    ]
}

/// `back` behind `front` (`over`).
#[inline]
pub(crate) fn over(front: [f32; 4], back: [f32; 4]) -> [f32; 4] {
    let t = 1.0 - front[3];
    [
        front[0] + t * back[0],
        front[1] + t * back[1],
        front[2] + t * back[2],
        front[3] + t * back[3],
    ]
}

/// Lower sample and weight of `x` on an axis of `n` samples over [0, 1]
/// (`axis`).
#[inline]
pub fn axis(x: f32, n: u32) -> (usize, f32) {
    let top = (n - 1) as f32;
    let c = x * top;
    // WGSL clamp of NaN is implementation-defined; inputs here are finite.
    let c = c.max(0.0).min(top);
    let i = c.floor().min(top - 1.0);
    (i as usize, c - i)
}

/// `a + (b - a) w` per channel (`lerp4`).
#[inline]
pub fn lerp4(a: [f32; 4], b: [f32; 4], w: f32) -> [f32; 4] {
    std::array::from_fn(|k| a[k] + (b[k] - a[k]) * w)
}

pub(crate) fn extension(p: &PreintParams, s: f32) -> [f32; 4] {
    if s < 0.5 {
        p.below
    } else {
        p.above
    }
}

/// Twin of `preint_segment`: the premultiplied colour and opacity of the
/// segment `(s_f, s_b, l)` (normalised scalars); `extended` is the stage's
/// `EXTENDED`.
pub fn preint_segment(
    p: &PreintParams,
    t: &CpuTable,
    lookup: LookupFn,
    extended: bool,
    sf: f32,
    sb: f32,
    l: f32,
) -> [f32; 4] {
    if !extended {
        return lookup(p, t, sf.clamp(0.0, 1.0), sb.clamp(0.0, 1.0), l);
    }
    let d = sb - sf;
    let outside = !(0.0..=1.0).contains(&sf);
    let (mut ta, mut tb) = (if outside { 1.0f32 } else { 0.0 }, 1.0f32);
    if d != 0.0 {
        let t0 = (0.0 - sf) / d;
        let t1 = (1.0 - sf) / d;
        ta = t0.min(t1).clamp(0.0, 1.0);
        tb = t0.max(t1).clamp(0.0, 1.0);
    }
    let tb = ta.max(tb);
    let s0 = (sf + d * ta).clamp(0.0, 1.0);
    let s1 = (sf + d * tb).clamp(0.0, 1.0);
    let front = homogeneous(p, extension(p, sf), l * ta);
    let inside = over(front, lookup(p, t, s0, s1, l * (tb - ta)));
    over(inside, homogeneous(p, extension(p, sb), l * (1.0 - tb)))
}

/// A table stage's bindings on the CPU (view, table, parameters and the
/// mode's lookup), for its twin [`fs_main`].
pub struct PreintTwin {
    view: SegmentView,
    mapper: ClipMapper,
    params: PreintParams,
    table: Arc<CpuTable>,
    lookup: LookupFn,
    /// The stage's `EXTENDED` (false: the field inside the node range).
    extended: bool,
}

/// Twin of `fs_main` in `shaders/preint.wgsl`, the fragment at weights
/// `bary` of `tri` drawn with `stage`'s bindings: its segment
/// (`segment_at`) through [`preint_segment`].
pub fn fs_main(stage: &PreintTwin, tri: [&SegmentVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
    let seg = segment_at(&stage.view, &stage.mapper, tri, bary);
    if !seg.ok {
        return None;
    }
    Some(preint_segment(
        &stage.params,
        &stage.table,
        stage.lookup,
        stage.extended,
        seg.s_f,
        seg.s_b,
        seg.l,
    ))
}

impl PreintTwin {
    /// The segment `(l, s_f, s_b)` (normalised scalars) through
    /// [`preint_segment`], with the parts outside the node range (the
    /// isosurface and whole-piece stages are always `EXTENDED`).
    pub fn volume(&self, l: f32, sf: f32, sb: f32) -> [f32; 4] {
        preint_segment(&self.params, &self.table, self.lookup, true, sf, sb, l)
    }

    /// The stage's view and clip mapping.
    pub fn view(&self) -> (SegmentView, ClipMapper) {
        (self.view, self.mapper)
    }
}

impl CpuStage<SegmentVertex> for PreintTwin {
    fn shade(&self, tri: [&SegmentVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_main(self, tri, bary)
    }

    fn describe(&self, tri: [&SegmentVertex; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let seg = segment_at(&self.view, &self.mapper, tri, bary);
        vec![("s_f", seg.s_f), ("s_b", seg.s_b), ("l", seg.l)]
    }
}

/// A table mode on the projected-cell driver (see the module docs).
pub struct PreintMode {
    kind: TableKind,
    stage: &'static StageDesc,
    /// The stage for fields inside the node range ([`field_inside`]).
    inside: &'static StageDesc,
    lookup: LookupFn,
    opts: TableOptions,
    stats: Mutex<Option<TableStats>>,
}

impl PreintMode {
    /// The mode of `kind` with `stage` (and `inside`, the same compiled
    /// for fields inside the node range) and `lookup`, for a render with
    /// `opts`; a `--table` size no device could hold is refused here.
    pub fn new(
        kind: TableKind,
        [stage, inside]: [&'static StageDesc; 2],
        lookup: LookupFn,
        opts: &RenderOptions,
    ) -> Result<PreintMode, TableSizeError> {
        // Drawn on the GPU, the adapter's limits are checked first (at
        // bind, naming the limit); on the CPU only zoovr's own.
        match opts.projected.compositor {
            Compositor::Cpu => TableSpec::new(kind, opts.tables.size, 1.0).map(|_| ())?,
            Compositor::Gpu => TableSpec::check_small(kind, opts.tables.size)?,
        }
        Ok(PreintMode {
            kind,
            stage,
            inside,
            lookup,
            opts: opts.tables,
            stats: Mutex::new(None),
        })
    }

    /// The table mode `mode` (one of preint3d, preint2d, preint2d-cyl) for a
    /// render with `opts`.
    pub fn for_mode(mode: super::Mode, opts: &RenderOptions) -> Result<PreintMode, TableSizeError> {
        use super::{preint2d, preint2d_cyl, preint3d, Mode};
        let (kind, stages, lookup): (TableKind, [&'static StageDesc; 2], LookupFn) = match mode {
            Mode::Preint2d => (
                TableKind::Flat,
                [&preint2d::PREINT2D_STAGE, &preint2d::PREINT2D_BARE_STAGE],
                preint2d::table_rgba,
            ),
            Mode::Preint2dCyl => (
                TableKind::Cylinder,
                [
                    &preint2d_cyl::PREINT2D_CYL_STAGE,
                    &preint2d_cyl::PREINT2D_CYL_BARE_STAGE,
                ],
                preint2d_cyl::table_rgba,
            ),
            _ => (
                TableKind::Cube,
                [&preint3d::PREINT3D_STAGE, &preint3d::PREINT3D_BARE_STAGE],
                preint3d::table_rgba,
            ),
        };
        PreintMode::new(kind, stages, lookup, opts)
    }

    /// The kind of table it looks up.
    pub fn kind(&self) -> TableKind {
        self.kind
    }

    /// What the last frame's table build did.
    pub fn take_stats(&self) -> Option<TableStats> {
        self.stats.lock().ok().and_then(|mut s| s.take())
    }

    /// The build method `Auto` resolves to on `gpu` (`None`: drawn on the
    /// CPU): the GPU build on any adapter, else the exact CPU build
    /// (measured on lavapipe, 2 cores: 128^3 in 39 ms by the compute pass
    /// against 0.37 s exact on the CPU; the cylindrical planes at 128 in
    /// 0.37 s against 0.61 s; benches/tables.rs).
    pub fn resolved_build(&self, gpu: Option<&Context>) -> TableBuild {
        match (self.opts.build, gpu) {
            (TableBuild::Auto, Some(_)) => TableBuild::Gpu,
            (TableBuild::Auto, _) => TableBuild::Exact,
            (b, _) => b,
        }
    }

    fn spec(&self, lengths: SceneLengths) -> Result<TableSpec, TableSizeError> {
        let l = match self.kind {
            TableKind::Flat => lengths.mean_thickness,
            _ => lengths.max_diameter,
        };
        TableSpec::new(self.kind, self.opts.size, l)
    }

    /// Binds the stage (the mode's own, or `stage` on the same first three
    /// bindings, with `extra` from binding 3 on) for one frame of `tf` seen
    /// by `camera`, with the device's cached table.
    pub fn bind_stage(
        &self,
        gpu: &Context,
        stage: Option<&'static StageDesc>,
        mesh: &crate::mesh::Mesh,
        tf: &TransferFunction,
        camera: &Camera,
        extra: &[Resource],
    ) -> Result<Stage, GpuError> {
        let n = self.opts.size.unwrap_or(self.kind.default_size());
        Table::check_size(gpu.limits(), self.kind.dim(), self.kind.extent(n))?;
        let cache = TableCache::of(gpu)?;
        let spec = self
            .spec(cache.lengths(mesh))
            .map_err(|e| GpuError::TableTooLarge(e.to_string()))?;
        let (table, stats) = cache.table(gpu, &spec, self.resolved_build(Some(gpu)), tf)?;
        if let Ok(mut s) = self.stats.lock() {
            *s = Some(stats);
        }
        let view = SegmentView::of(camera);
        let params = PreintParams::new(tf, &spec);
        let mut res = vec![
            Resource::Uniform(bytemuck::bytes_of(&view)),
            Resource::Table(&table),
            Resource::Uniform(bytemuck::bytes_of(&params)),
        ];
        res.extend_from_slice(extra);
        gpu.bind_stage(stage.unwrap_or(self.stage), &res)
    }

    /// The CPU twin for one frame (its table built on the CPU, or the
    /// process's copy of the same table, [`cpu_texels`]).
    pub fn twin_for(
        &self,
        mesh: &crate::mesh::Mesh,
        tf: &TransferFunction,
        camera: &Camera,
    ) -> PreintTwin {
        let t0 = std::time::Instant::now();
        let spec = self
            .spec(SceneLengths::of(mesh))
            .unwrap_or_else(|e| unreachable!("checked by PreintMode::new: {e}"));
        let build = self.resolved_build(None);
        let (data, fresh) = cpu_texels(&spec, tf, build);
        let built = if fresh { spec.texels() } else { 0 };
        if let Ok(mut s) = self.stats.lock() {
            *s = Some(TableStats {
                kind: spec.kind,
                size: spec.size,
                build,
                l_table: spec.l_table,
                texels_built: built,
                build_s: t0.elapsed().as_secs_f64(),
            });
        }
        PreintTwin {
            view: SegmentView::of(camera),
            mapper: ClipMapper::for_camera(camera),
            params: PreintParams::new(tf, &spec),
            table: Arc::new(CpuTable {
                size: spec.size,
                data: data.to_vec(),
            }),
            lookup: self.lookup,
            extended: true,
        }
    }
}

impl SegmentMode for PreintMode {
    type Vertex = SegmentVertex;

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        let stage = if field_inside(src) {
            self.inside
        } else {
            self.stage
        };
        self.bind_stage(gpu, Some(stage), src.whole, src.tf, src.camera, &[])
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<SegmentVertex>> {
        let mut twin = self.twin_for(src.whole, src.tf, src.camera);
        twin.extended = !field_inside(src);
        Box::new(twin)
    }
}

/// Whether every scalar of the frame's field lies inside the transfer
/// function's node range (NaN counts as outside): the normalised scalars
/// of its segments then leave [0, 1] only by the rounding of their
/// interpolation, and the table's part is the whole segment, its scalars
/// clamped (the stage with `EXTENDED` false). A field reaching beyond the
/// nodes (`--range` narrower than the data) keeps the parts outside. The
/// field's span is computed once with the field ([`crate::field::ScalarField::span`]),
/// so the question costs nothing per frame.
pub fn field_inside(src: &PieceSource) -> bool {
    let (lo, hi) = src.tf.scalar_range();
    src.field_span
        .is_some_and(|(min, max)| lo <= min && max <= hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tf::Node;

    use super::super::preint_tables::fill_cpu;
    use super::super::{preint2d, preint2d_cyl, preint3d};

    /// Nodes on [10, 20] with extinction at both ends (so the parts below
    /// and above the table's range are not empty).
    fn tf(model: EmissionModel) -> TransferFunction {
        let n = |s: f64, tau: f64, c: [f64; 3]| Node {
            s,
            tau,
            color: c,
            emission: c.map(|v| v * tau),
        };
        let nodes = [
            n(10.0, 0.7, [1.0, 0.0, 0.0]),
            n(13.5, 5.0, [1.0, 1.0, 0.0]),
            n(13.5, 0.5, [0.0, 1.0, 0.0]),
            n(20.0, 2.0, [0.0, 0.0, 1.0]),
        ];
        TransferFunction::from_nodes(&nodes, model).unwrap()
    }

    /// The segment as it was drawn with branches (the parts outside the
    /// table's range only where present): the reference the branch-free
    /// `preint_segment` must equal bit for bit.
    fn branched(p: &PreintParams, t: &CpuTable, f: LookupFn, sf: f32, sb: f32, l: f32) -> [f32; 4] {
        let d = sb - sf;
        let (mut ta, mut tb) = (0.0f32, 1.0f32);
        if d != 0.0 {
            let t0 = (0.0 - sf) / d;
            let t1 = (1.0 - sf) / d;
            ta = t0.min(t1).clamp(0.0, 1.0);
            tb = t0.max(t1).clamp(0.0, 1.0);
        } else if !(0.0..=1.0).contains(&sf) {
            ta = 1.0;
        }
        if ta >= tb {
            return homogeneous(p, extension(p, sf), l);
        }
        let mut acc = [0.0f32; 4];
        if ta > 0.0 {
            acc = homogeneous(p, extension(p, sf), l * ta);
        }
        let s0 = (sf + d * ta).clamp(0.0, 1.0);
        let s1 = (sf + d * tb).clamp(0.0, 1.0);
        acc = over(acc, f(p, t, s0, s1, l * (tb - ta)));
        if tb < 1.0 {
            acc = over(acc, homogeneous(p, extension(p, sb), l * (1.0 - tb)));
        }
        acc
    }

    /// Every table, built every way, reads exactly 0 at length 0, so the
    /// absent parts of a segment add nothing, and the branch-free segment
    /// equals the branched one bit for bit: inside, across either end,
    /// wholly outside on either side, constant scalars, lengths up to and
    /// beyond the table's.
    #[test]
    fn branch_free_segment_equals_the_branched_one() {
        let kinds: [(TableKind, LookupFn); 3] = [
            (TableKind::Cube, preint3d::table_rgba),
            (TableKind::Flat, preint2d::table_rgba),
            (TableKind::Cylinder, preint2d_cyl::table_rgba),
        ];
        let scalars = [-0.7f32, -0.01, 0.0, 0.2, 0.5, 0.77, 1.0, 1.3, 2.5];
        for model in [EmissionModel::Glow, EmissionModel::Independent] {
            let tf = tf(model);
            for (kind, lookup) in kinds {
                let spec = TableSpec::new(kind, Some(9), 0.8).unwrap();
                let p = PreintParams::new(&tf, &spec);
                for build in [TableBuild::Exact, TableBuild::Fast, TableBuild::Gpu] {
                    let mut data = vec![0.0; 4 * spec.texels()];
                    let all = (f64::NEG_INFINITY, f64::INFINITY);
                    fill_cpu(&spec, &tf, build, all, &mut data);
                    let t = CpuTable {
                        size: spec.size,
                        data,
                    };
                    for &a in &scalars {
                        for &b in &scalars {
                            let (a, b) = (a.clamp(0.0, 1.0), b.clamp(0.0, 1.0));
                            let z = lookup(&p, &t, a, b, 0.0);
                            assert_eq!(z, [0.0; 4], "{kind:?} {build:?} ({a}, {b})");
                        }
                    }
                    for &sf in &scalars {
                        for &sb in &scalars {
                            for l in [0.0f32, 1e-12, 0.05, 0.8, 0.9] {
                                let got = preint_segment(&p, &t, lookup, true, sf, sb, l);
                                let want = branched(&p, &t, lookup, sf, sb, l);
                                assert_eq!(
                                    got.map(f32::to_bits),
                                    want.map(f32::to_bits),
                                    "{kind:?} {build:?} {model:?} ({sf}, {sb}, {l})"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    /// For a field inside the node range the stage without the parts
    /// outside (`EXTENDED` false: one lookup at the clamped scalars) draws
    /// what the full one does: within 1e-6 wherever both scalars lie in
    /// [0, 1] (the full stage rebuilds the back scalar as s_f + (s_b - s_f),
    /// an ulp away at most).
    #[test]
    fn inside_stage_matches_the_full_one_inside_the_range() {
        let kinds: [(TableKind, LookupFn); 3] = [
            (TableKind::Cube, preint3d::table_rgba),
            (TableKind::Flat, preint2d::table_rgba),
            (TableKind::Cylinder, preint2d_cyl::table_rgba),
        ];
        let scalars = [0.0f32, 1e-7, 0.2, 0.5, 0.77, 0.999_999, 1.0];
        let tf = tf(EmissionModel::Glow);
        let mut worst = 0.0f32;
        for (kind, lookup) in kinds {
            let spec = TableSpec::new(kind, Some(9), 0.8).unwrap();
            let p = PreintParams::new(&tf, &spec);
            let mut data = vec![0.0; 4 * spec.texels()];
            fill_cpu(
                &spec,
                &tf,
                TableBuild::Exact,
                (f64::NEG_INFINITY, f64::INFINITY),
                &mut data,
            );
            let t = CpuTable {
                size: spec.size,
                data,
            };
            for &sf in &scalars {
                for &sb in &scalars {
                    for l in [0.0f32, 1e-12, 0.05, 0.8] {
                        let full = preint_segment(&p, &t, lookup, true, sf, sb, l);
                        let inside = preint_segment(&p, &t, lookup, false, sf, sb, l);
                        for k in 0..4 {
                            worst = worst.max((full[k] - inside[k]).abs());
                        }
                    }
                }
            }
        }
        assert!(worst <= 1e-6, "{worst}");
    }
}
