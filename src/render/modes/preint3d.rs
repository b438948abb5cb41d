//! The preint3d mode: per fragment, a lookup in the 3D pre-integrated table
//! over `(s_f, s_b, l)` (Röttger, Kraus, Ertl 2000, section 3), whose texels
//! are the premultiplied colour and opacity of the exact ray integral
//! ([`super::preint_tables`], [`TableKind::Cube`]).
//!
//! The table spans the normalised scalars [0, 1] (the transfer function's
//! nodes) on both scalar axes with `N` samples each (`--table N`, default
//! 128), and lengths `[0, l_table]` with `N` samples, `l_table` the largest
//! cell diameter of the mesh (a bound of every piece's thickness, computed
//! once per mesh), so no segment needs more than one lookup; longer ones
//! would be composited in steps ([`super::preint`]). The lookup is
//! trilinear, by hand in `f32` on a storage buffer ([`table_rgba`], the
//! twin of `table_rgba` in
//! `shaders/preint3d.wgsl`).
//!
//! Where the error comes from: the trilinear interpolation of the
//! integral between samples, largest where the transfer function has a
//! narrow peak or a jump (one texel spans 1/(N-1) of the scalar range) and
//! for optically thick cells (the opacity changes fastest with `l` near
//! `l = 0`). The table holds any source term, so glow and independent
//! emission are both drawn.

use crate::gpu::StageDesc;
use crate::raycast::FieldModel;
use crate::tf::EmissionModel;

use super::preint::{axis, lerp4, preint_stage, CpuTable, PreintParams};
use super::{Bounds, ModeInfo};

/// The registry entry of the preint3d mode.
pub static INFO: ModeInfo = ModeInfo {
    name: "preint3d",
    summary: "projection of convex pieces, a 3D pre-integrated (s_f, s_b, l) table looked up per fragment by wgpu",
    gpu: true,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    draws_pieces_whole: true,
    stage: Some(&PREINT3D_STAGE),
    bounds: Some(Bounds {
        reference: FieldModel::Faces,
        // Measured at most 2.15e-3 (ring_hole, orthographic; tests/modes.rs
        // scenes, CPU twin and Vulkan alike) with the default 128^3 table:
        // the trilinear interpolation of the integral between texels (the
        // default transfer function's opacity ramp is smooth) plus what
        // exact-frag has (f32 arithmetic, corner snapping: 2.1e-3).
        split_max: 4e-3,
        // Measured 1.18e-2 (zoo_3x3x3, perspective), as the exact and
        // exact-frag modes: cells the order splits into tets integrate the
        // `tets` field there, not `faces`.
        whole_max: 0.02,
        split_outliers: 0,
        whole_outliers: 0,
    }),
};

/// The preint3d stage.
pub static PREINT3D_STAGE: StageDesc = preint_stage!("preint3d.wgsl", "preint3d.wgsl", &[]);

/// The preint3d stage compiled for fields inside the transfer function's
/// node range (`EXTENDED` false in `shaders/preint.wgsl`: each segment one
/// lookup at its clamped scalars, no parts outside).
pub static PREINT3D_BARE_STAGE: StageDesc = preint_stage!(
    "preint3d.wgsl+inside",
    "preint3d.wgsl",
    &[("EXTENDED", 0.0)]
);

/// Twin of `texel3d`: texel `(i, j, k)` of the table's storage buffer.
#[inline]
pub fn texel3d(t: &CpuTable, i: usize, j: usize, k: usize) -> [f32; 4] {
    t.load(i, j, k)
}

/// Twin of `table_rgba` in `shaders/preint3d.wgsl`.
pub fn table_rgba(p: &PreintParams, t: &CpuTable, sf: f32, sb: f32, l: f32) -> [f32; 4] {
    let (i, wa) = axis(sf, p.ns);
    let (j, wb) = axis(sb, p.ns);
    let (k, wc) = axis(l / p.l_table, p.nz);
    let plane = |k: usize| {
        let r0 = lerp4(texel3d(t, i, j, k), texel3d(t, i + 1, j, k), wa);
        let r1 = lerp4(texel3d(t, i, j + 1, k), texel3d(t, i + 1, j + 1, k), wa);
        lerp4(r0, r1, wb)
    };
    lerp4(plane(k), plane(k + 1), wc)
}
