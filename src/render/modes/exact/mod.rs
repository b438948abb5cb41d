//! The exact mode (Max, Williams and Silva, "Area and Volume Coherence for
//! Efficient Visualization of 3D Scalar Functions", MWS): exact ray
//! integrals at region vertices, composited by the GPU.
//!
//! On the shared projected-cell driver ([`crate::render::driver`]) it
//! supplies:
//! - **split policy**: pieces are sliced at every kink or jump of the
//!   extinction and every jump of the colour
//!   ([`crate::render::breakpoints::split_points`]), so the extinction is
//!   linear along every ray through a piece and the per-pixel opacity
//!   below is exact;
//! - **payload** ([`ExactMode::payload`]): at every region vertex a kept
//!   triangle uses, the closed-form integral
//!   ([`crate::integrate::vertex_values`]) gives the glow colour `C/alpha`
//!   and the mean extinction `tau` along the vertex's ray of length `l`.
//!   Region triangles are refined where the optical depth inside them (a
//!   bound: their corners' largest length times the largest extinction on
//!   the piece's scalar range) times the spread of their corners' glow
//!   colours is large (docs/math.md 8.1: `C/alpha` is interpolated inside a
//!   region), see [`COLOR_REFINE_TOL`] and `EdgeColours`. Each piece's `l` and `tau` are
//!   balanced for the table's axes ([`depth_balance`]);
//! - **stage** (`shaders/exact.wgsl`, [`EXACT_STAGE`]): per fragment,
//!   `alpha = 1 - exp(-l tau)` from the 2D exponential table
//!   ([`exptable`], manual bilinear filtering in `f32`) and colour
//!   `glow * alpha`, premultiplied; [`fs_main`] is its CPU twin.
//!
//! The glow colour per unit opacity is all a vertex carries, so the mode
//! cannot represent independent emission (the registry says so).

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use crate::gpu::common::finite;
use crate::gpu::cpu::{lerp, CpuStage};
use crate::gpu::{Binding, Context, GpuError, GpuVertex, Resource, Stage, StageDesc, Table};
use crate::integrate::{vertex_values, VertexValues};
use crate::numeric::tolerance::{COLOR_REFINE_MAX_DEPTH, COLOR_REFINE_TOL};
use crate::projection::{refine_with, Polyhedron, Projected, RefineScratch, RegionVertex};
use crate::render::breakpoints::split_points;
use crate::render::driver::ProjectedMode;
use crate::render::pieces::{value_range, PieceSource};
use crate::tf::TransferFunction;

pub mod exptable;

use self::exptable::{shader_params, ExpTable, TABLE_N};
use super::{Bounds, ModeInfo};
use crate::raycast::FieldModel;
use crate::tf::EmissionModel;

/// The registry entry of the exact mode.
pub static INFO: ModeInfo = ModeInfo {
    name: "exact",
    summary: "projection of convex pieces with exact vertex integrals, composited by wgpu",
    gpu: true,
    emission: &[EmissionModel::Glow],
    slices_at_breakpoints: true,
    draws_pieces_whole: false,
    stage: Some(&EXACT_STAGE),
    bounds: Some(Bounds {
        reference: FieldModel::Faces,
        split_max: 2.0 / 255.0,
        // Measured up to 7.65e-2 where cells are split (ring_hole,
        // perspective, a TF with kinks; tests/render_exact.rs MODEL_DIFF).
        whole_max: 0.1,
        split_outliers: 0,
        whole_outliers: 0,
    }),
};

/// One vertex of the exact mode.
///
/// Keep in sync with `VertexIn` in `shaders/exact.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct ExactVertex {
    /// Clip-space position (x, y, z, w); see [`crate::gpu::ClipMapper`].
    pub pos: [f32; 4],
    /// `l`, the length of the ray through the piece at this vertex.
    pub thickness: f32,
    /// Mean extinction along that ray (optical depth / l).
    pub tau: f32,
    /// `C / alpha`: colour of the segment per unit opacity.
    pub glow: [f32; 3],
    /// The piece (convex polyhedron) this vertex's triangles belong to,
    /// numbered in drawing order: the shader colours a pixel at most once
    /// per piece ([`crate::gpu::piece_depth`]).
    pub piece: u32,
}

impl ExactVertex {
    /// Vertex attributes (`@location`s of `VertexIn`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 5] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Float32,
        2 => Float32,
        3 => Float32x3,
        4 => Uint32,
    ];

    /// A vertex of piece 0 from a clip position and its optical values.
    pub fn new(pos: [f32; 4], thickness: f32, tau: f32, glow: [f32; 3]) -> ExactVertex {
        ExactVertex {
            pos,
            thickness,
            tau,
            glow,
            piece: 0,
        }
    }
}

impl GpuVertex for ExactVertex {
    fn clip(&self) -> [f32; 4] {
        self.pos
    }
    fn piece(&self) -> u32 {
        self.piece
    }
    fn with_piece(self, piece: u32) -> Self {
        ExactVertex { piece, ..self }
    }
    fn is_finite(&self) -> bool {
        self.pos.iter().all(|v| v.is_finite())
            && self.thickness.is_finite()
            && self.tau.is_finite()
            && self.glow.iter().all(|v| v.is_finite())
    }
    fn with_clip(self, pos: [f32; 4]) -> Self {
        ExactVertex { pos, ..self }
    }
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self {
        ExactVertex {
            thickness: lerp(tri, bary, |v| v.thickness),
            tau: lerp(tri, bary, |v| v.tau),
            glow: [0, 1, 2].map(|k| lerp(tri, bary, |v| v.glow[k])),
            ..*tri[0]
        }
    }
    fn transparent(self) -> Self {
        // alpha_of(0, tau) = 0, and the colour is glow * alpha.
        ExactVertex {
            thickness: 0.0,
            ..self
        }
    }
}

/// Uniforms of the exact stage. Keep in sync with `Params` in
/// `shaders/exact.wgsl`.
///
/// The length unit addresses the table: the shader uses `l / unit` and
/// `tau * unit` (their product, the optical depth, is unchanged); the scene's
/// unit distance keeps both within the table's per-axis range `[0, 1e6]`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug)]
pub struct ExactParams {
    pub inv_unit: f32,
    pub unit: f32,
    pub scale: f32,
    pub inv_log_range: f32,
    pub n: u32,
    pub _pad: [u32; 3],
}

/// The exact stage.
pub static EXACT_STAGE: StageDesc = StageDesc {
    name: "exact.wgsl",
    fragment: "fs_main",
    wgsl: concat!(
        include_str!("../../../../shaders/exptable.wgsl"),
        include_str!("../../../../shaders/exact.wgsl")
    ),
    vertex: wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<ExactVertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ExactVertex::ATTRIBUTES,
    },
    bindings: &[Binding::Uniform, Binding::Table],
    constants: &[],
};

fn check_unit(length_unit: f32) -> Result<(), GpuError> {
    if length_unit > 0.0 && length_unit.is_finite() {
        Ok(())
    } else {
        Err(GpuError::BadOption(
            "length_unit must be positive and finite",
        ))
    }
}

/// Binds the exact stage for a frame with length unit `length_unit` (the
/// exponential table is uploaded once per device).
pub fn bind_exact_stage(gpu: &Context, length_unit: f32) -> Result<Stage, GpuError> {
    bind_table_stage(gpu, &EXACT_STAGE, length_unit, &[])
}

/// Binds `desc`, a stage on `shaders/exptable.wgsl` (bindings 0 and 1),
/// with `extra` resources after those.
pub fn bind_table_stage(
    gpu: &Context,
    desc: &'static StageDesc,
    length_unit: f32,
    extra: &[Resource],
) -> Result<Stage, GpuError> {
    check_unit(length_unit)?;
    let table = gpu.resource("exact: exponential table", |g| {
        Table::upload(
            g,
            "exp table",
            [TABLE_N, TABLE_N, 1],
            ExpTable::new(TABLE_N).data(),
        )
    })?;
    let (scale, inv_log_range) = shader_params();
    let params = ExactParams {
        inv_unit: 1.0 / length_unit,
        unit: length_unit,
        scale,
        inv_log_range,
        n: TABLE_N,
        _pad: [0; 3],
    };
    let mut resources = vec![
        Resource::Uniform(bytemuck::bytes_of(&params)),
        Resource::Table(&table),
    ];
    resources.extend_from_slice(extra);
    gpu.bind_stage(desc, &resources)
}

/// The exact stage's bindings on the CPU (the length unit of `Params` and
/// the exponential table), for its twin [`fs_main`].
pub struct ExactTwin {
    length_unit: f32,
    table: ExpTable,
}

impl ExactTwin {
    /// The twin for length unit `length_unit`.
    pub fn new(length_unit: f32) -> Result<ExactTwin, GpuError> {
        check_unit(length_unit)?;
        Ok(ExactTwin {
            length_unit,
            table: ExpTable::new(TABLE_N),
        })
    }

    /// `l`, `tau` and glow as the shader interpolates and scales them.
    pub(in crate::render::modes) fn values(
        &self,
        tri: [&ExactVertex; 3],
        bary: [f64; 3],
    ) -> (f32, f32, [f32; 3]) {
        let l = lerp(tri, bary, |v| v.thickness) / self.length_unit;
        let tau = lerp(tri, bary, |v| v.tau) * self.length_unit;
        let glow = [0, 1, 2].map(|k| lerp(tri, bary, |v| v.glow[k]));
        (l, tau, glow)
    }
}

/// Twin of `fs_main` in `shaders/exact.wgsl`, the fragment at weights
/// `bary` of `tri` drawn with `stage`'s bindings: a fragment with a
/// non-finite attribute is discarded; otherwise `alpha` comes from the
/// exponential table ([`ExpTable::alpha_of`]) and the colour is
/// `glow * alpha`.
pub fn fs_main(stage: &ExactTwin, tri: [&ExactVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
    let (l, tau, glow) = stage.values(tri, bary);
    if !(finite(l) && finite(tau) && glow.iter().all(|&g| finite(g))) {
        return None;
    }
    let alpha = stage.table.alpha_of(l, tau);
    Some([glow[0] * alpha, glow[1] * alpha, glow[2] * alpha, alpha])
}

impl CpuStage<ExactVertex> for ExactTwin {
    fn shade(&self, tri: [&ExactVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_main(self, tri, bary)
    }

    fn describe(&self, tri: [&ExactVertex; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let (l, tau, glow) = self.values(tri, bary);
        vec![
            ("l", l),
            ("tau", tau),
            ("glow.r", glow[0]),
            ("glow.g", glow[1]),
            ("glow.b", glow[2]),
        ]
    }
}

/// The exact mode on the projected-cell driver.
#[derive(Clone, Copy, Debug)]
pub struct ExactMode {
    /// Colour refinement tolerance (`--refine-tol`, default
    /// [`COLOR_REFINE_TOL`]): a region triangle whose optical depth times
    /// glow spread exceeds it is split at its edge midpoints.
    pub refine_tol: f64,
}

impl Default for ExactMode {
    fn default() -> Self {
        ExactMode {
            refine_tol: COLOR_REFINE_TOL,
        }
    }
}

/// The exact payload of one piece: the vertex integrals and the piece's
/// depth balance.
#[derive(Default)]
pub struct ExactPayload {
    pub(in crate::render::modes) values: Vec<VertexValues>,
    balance: f64,
    /// The colour refinement's scratch.
    refine: RefineScratch,
}

impl ProjectedMode for ExactMode {
    type Vertex = ExactVertex;
    type Payload = ExactPayload;

    fn split_points(&self, tf: &TransferFunction) -> Vec<f64> {
        split_points(tf)
    }

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        bind_exact_stage(gpu, src.length_unit as f32)
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<ExactVertex>> {
        let length_unit = src.length_unit as f32;
        // The driver's unit is the scene's (positive, finite) unit distance.
        Box::new(ExactTwin::new(length_unit).unwrap_or(ExactTwin {
            length_unit: 1.0,
            table: ExpTable::new(TABLE_N),
        }))
    }

    fn payload(
        &self,
        src: &PieceSource,
        part: &Polyhedron,
        proj: &mut Projected,
        used: &mut Vec<bool>,
        payload: &mut ExactPayload,
        refined: &mut usize,
    ) {
        payload.balance = depth_balance(src, part);
        let tf = src.tf;
        let vals = &mut payload.values;
        vals.clear();
        vals.extend(proj.vertices.iter().zip(used.iter()).map(|(v, &u)| {
            if u {
                vertex_values(tf, v.l, v.s_front, v.s_back)
            } else {
                VertexValues::default()
            }
        }));
        // Refine only pieces whose optical depth and glow spread could make
        // the interpolated C/alpha err (the common thin or uniform piece
        // skips it). The optical depth is bounded where the interpolation
        // happens, inside the triangles, not only at their corners: the
        // length there is at most the corners' largest (it is linear on a
        // region), the extinction at most the transfer function's largest
        // on the piece's scalar range. A corner's own depth is no bound: a
        // triangle from a thick corner where the scalar maps to little
        // extinction to silhouette corners (no length) where it maps to
        // much is optically deep inside, with a small depth at every corner
        // (a long cell seen end-on in an orthographic view).
        let spread = (0..3)
            .map(|k| {
                let (lo, hi) = value_range(
                    vals.iter()
                        .zip(used.iter())
                        .filter(|(_, &u)| u)
                        .map(|(v, _)| v.glow[k]),
                );
                hi - lo
            })
            .fold(0.0, f64::max);
        // The depth bound is at most 1: a piece whose glow colours spread
        // less than the tolerance needs neither it nor refinement (most
        // pieces, and NaN).
        if spread.is_nan() || spread <= self.refine_tol {
            return;
        }
        let (s_lo, s_hi) = value_range(part.scalars.iter().copied());
        let edge = EdgeColours {
            tau_max: src.max_extinction(s_lo, s_hi),
            tol: self.refine_tol,
        };
        let l_max = proj
            .vertices
            .iter()
            .zip(used.iter())
            .filter(|(_, &u)| u)
            .map(|(v, _)| v.l)
            .fold(0.0, f64::max);
        let depth = edge.depth_at(l_max);
        if depth * spread > edge.tol {
            let before = proj.triangles.len();
            // Each vertex's values once (a vertex has about six edges, and
            // an edge may be tested at every level): the refinement's new
            // vertices are appended to `vals` as the tests reach them.
            refine_with(
                proj,
                COLOR_REFINE_MAX_DEPTH,
                |v, a, b| {
                    let n = vals.len();
                    vals.extend(
                        v[n..]
                            .iter()
                            .map(|w| vertex_values(tf, w.l, w.s_front, w.s_back)),
                    );
                    edge.splits(
                        (&v[a as usize], &vals[a as usize]),
                        (&v[b as usize], &vals[b as usize]),
                    )
                },
                &mut payload.refine,
            );
            if src.cull {
                proj.cull_to_pixels(&src.grid);
            }
            *refined += proj.triangles.len().saturating_sub(before);
            let n = vals.len();
            used.resize(proj.vertices.len(), true);
            vals.extend(
                proj.vertices[n..]
                    .iter()
                    .map(|v| vertex_values(tf, v.l, v.s_front, v.s_back)),
            );
        }
    }

    fn vertex(
        &self,
        payload: &ExactPayload,
        proj: &Projected,
        i: usize,
        ndc: [f32; 2],
    ) -> ExactVertex {
        let (v, vv, k) = (&proj.vertices[i], &payload.values[i], payload.balance);
        ExactVertex::new(
            [ndc[0], ndc[1], 0.5, 1.0],
            (v.l * k) as f32,
            (vv.tau_mean / k) as f32,
            [vv.glow[0] as f32, vv.glow[1] as f32, vv.glow[2] as f32],
        )
    }
}

/// The colour refinement's test of one region edge (see
/// [`COLOR_REFINE_TOL`]) in a piece whose extinction is at most `tau_max`.
struct EdgeColours {
    tau_max: f64,
    tol: f64,
}

impl EdgeColours {
    /// A bound on the optical depth of a segment of length `l` in the
    /// piece (at most 1: the interpolation error stops growing with the
    /// depth there).
    fn depth_at(&self, l: f64) -> f64 {
        (l * self.tau_max).min(1.0)
    }

    /// Whether the edge between region vertices `a` and `b` (with their
    /// exact values) is split: where the bound on the optical depth along
    /// it (the length is linear along it, so at most its ends') times the
    /// spread of its ends' glow colours exceeds the tolerance.
    fn splits(
        &self,
        (ra, va): (&RegionVertex, &VertexValues),
        (rb, vb): (&RegionVertex, &VertexValues),
    ) -> bool {
        let spread = (0..3)
            .map(|k| (va.glow[k] - vb.glow[k]).abs())
            .fold(0.0, f64::max);
        self.depth_at(ra.l.max(rb.l)) * spread > self.tol
    }
}

/// Per-piece scale `k` sending `l k` and `tau / k` to the shader (their
/// product, the optical depth, is unchanged): it brings the piece's
/// diameter (a bound on `l`) and the largest extinction of the TF over its
/// scalar range to the same size, so neither table axis clamps. It depends
/// on the piece alone, not on which regions and triangles coverage culling
/// keeps, so culling changes no pixel.
fn depth_balance(src: &PieceSource, piece: &Polyhedron) -> f64 {
    let (s_lo, s_hi) = value_range(piece.scalars.iter().copied());
    let (lo, hi) = piece.points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let l_max = (hi - lo).length();
    let tf = src.tf;
    let mut tau_max = tf.tau_at(s_lo).max(tf.tau_at(s_hi));
    for &b in src.breakpoints {
        if b > s_lo && b < s_hi {
            tau_max = tau_max.max(tf.tau_at(b));
        }
    }
    let (l_max, tau_max) = (l_max / src.length_unit, tau_max * src.length_unit);
    let k = (tau_max / l_max).sqrt();
    if l_max > 0.0 && tau_max > 0.0 && k.is_finite() && k > 0.0 {
        k
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An edge from a thick corner where the field maps to little
    /// extinction to a silhouette corner (no length) where it maps to much,
    /// with different glow colours: both ends are optically shallow, the
    /// middle is not (a long cell seen end-on in an orthographic view).
    #[test]
    fn an_edge_deep_only_between_its_ends_is_split() {
        let (hi, unit) = (1.0, 0.01);
        let tf = TransferFunction::from_channels(
            &[(0.0, [0.0]), (hi, [1.0 / unit])],
            &[
                (0.0, [0.0, 0.0, 1.0]),
                (0.2, [0.0, 1.0, 0.0]),
                (hi, [1.0, 1.0, 0.0]),
            ],
            None,
            EmissionModel::Glow,
        )
        .unwrap();
        let vertex = |l: f64, s_front: f64, s_back: f64| RegionVertex {
            px: 0.0,
            py: 0.0,
            z_front: 1.0,
            z_back: 1.0 + l,
            l,
            s_front,
            s_back,
            profile: l == 0.0,
        };
        let thick = vertex(0.005, 0.0, 0.0015);
        let thin = vertex(0.0, 0.65, 0.65);
        let values = |r: &RegionVertex| vertex_values(&tf, r.l, r.s_front, r.s_back);
        let (vt, vs) = (values(&thick), values(&thin));
        // The corners' own depths would not split it.
        let ends = (0..3)
            .map(|k| (vt.glow[k] - vs.glow[k]).abs())
            .fold(0.0, f64::max);
        assert!(
            vt.depth.max(vs.depth) * ends <= COLOR_REFINE_TOL,
            "{vt:?} {vs:?}"
        );
        // The middle is deep (the exact midpoint) and the bound says so.
        let mid = vertex_values(&tf, 0.0025, 0.325, 0.32575);
        assert!(mid.depth > 0.05, "{mid:?}");
        let edge = EdgeColours {
            tau_max: 1.0 / unit,
            tol: COLOR_REFINE_TOL,
        };
        assert!(edge.depth_at(thick.l) >= mid.depth);
        assert!(edge.splits((&thick, &vt), (&thin, &vs)));
    }

    #[test]
    fn layout_matches_struct() {
        assert_eq!(std::mem::size_of::<ExactVertex>(), 40);
        assert_eq!(std::mem::offset_of!(ExactVertex, thickness), 16);
        assert_eq!(std::mem::offset_of!(ExactVertex, tau), 20);
        assert_eq!(std::mem::offset_of!(ExactVertex, glow), 24);
        let offs: Vec<u64> = ExactVertex::ATTRIBUTES.iter().map(|a| a.offset).collect();
        assert_eq!(std::mem::offset_of!(ExactVertex, piece), 36);
        assert_eq!(offs, vec![0, 16, 20, 24, 36]);
    }

    #[test]
    fn uniforms_match_wgsl_params() {
        let src = crate::gpu::stage::stage_source(EXACT_STAGE.wgsl);
        let module = naga::front::wgsl::parse_str(&src).unwrap();
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
        assert_eq!(span as usize, std::mem::size_of::<ExactParams>());
        let offs: Vec<(String, u32)> = members
            .iter()
            .take(5)
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
            .collect();
        let want = [
            ("inv_unit", std::mem::offset_of!(ExactParams, inv_unit)),
            ("unit", std::mem::offset_of!(ExactParams, unit)),
            ("scale", std::mem::offset_of!(ExactParams, scale)),
            (
                "inv_log_range",
                std::mem::offset_of!(ExactParams, inv_log_range),
            ),
            ("n", std::mem::offset_of!(ExactParams, n)),
        ];
        let want: Vec<(String, u32)> = want
            .iter()
            .map(|(n, o)| (n.to_string(), *o as u32))
            .collect();
        assert_eq!(offs, want);
    }
}
