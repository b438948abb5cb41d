//! The preint2d mode: per fragment, a lookup in a 2D pre-integrated table
//! over `(s_f, s_b)` at one reference length, the mean cell thickness
//! `l_ref` (Röttger, Kraus, Ertl 2000, section 4), scaled to the fragment's
//! own length `l`.
//!
//! RKE scale the colour and the opacity of the `l_ref` texel by `l / l_ref`
//! (first order in `l`). Here the texel holds the colour `C_ref` and the
//! optical depth `D_ref` at `l_ref` ([`TableKind::Flat`]); since the depth
//! of a segment is exactly linear in its length (`l` times the mean
//! extinction over `[s_f, s_b]`), the fragment takes
//!
//! ```text
//! D = D_ref l / l_ref,   alpha = 1 - exp(-D)                      (exact)
//! C = C_ref alpha / alpha_ref = C_ref (l / l_ref) g(D) / g(D_ref),  g(x) = (1 - e^-x) / x
//! ```
//!
//! which is RKE's `l / l_ref` where the segment is thin, exact for any
//! homogeneous segment (either emission model), and never saturates. What
//! is left is the colour's dependence on `l` inside a segment whose colour
//! and extinction vary (the front weighting changes with depth): largest
//! for optically thick cells much longer or shorter than `l_ref`. The
//! lookup is bilinear, by hand in `f32` ([`table_rgba`], the twin of
//! `table_rgba` in `shaders/preint2d.wgsl`). `--table N` sets the samples
//! per scalar axis (default 512: the table is small).

use crate::gpu::StageDesc;
use crate::raycast::FieldModel;
use crate::tf::EmissionModel;

use super::preint::{axis, lerp4, one_minus_exp_over, preint_stage, CpuTable, PreintParams};
use super::{Bounds, ModeInfo};

/// The registry entry of the preint2d mode.
pub static INFO: ModeInfo = ModeInfo {
    name: "preint2d",
    summary: "projection of convex pieces, a 2D pre-integrated (s_f, s_b) table at the mean cell thickness, scaled to each fragment's length",
    gpu: true,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    draws_pieces_whole: true,
    stage: Some(&PREINT2D_STAGE),
    bounds: Some(Bounds {
        reference: FieldModel::Faces,
        // Measured at most 4.14e-2 (zoo_3x3x3, orthographic): zoo_3x3x3
        // has few, optically thick cells whose segments range from 0 to
        // several times the mean thickness, and the colour of a segment
        // whose colour and extinction vary is scaled from the reference
        // length, not integrated (the opacity is exact up to
        // interpolation). The other scenes stay within 1.8e-2.
        split_max: 0.06,
        // Measured 4.54e-2 (zoo_3x3x3, orthographic): the same scaling
        // error (the model difference of split cells is 1.2e-2).
        whole_max: 0.06,
        split_outliers: 0,
        whole_outliers: 0,
    }),
};

/// The preint2d stage.
pub static PREINT2D_STAGE: StageDesc = preint_stage!("preint2d.wgsl", "preint2d.wgsl", &[]);

/// The preint2d stage compiled for fields inside the transfer function's
/// node range (`EXTENDED` false in `shaders/preint.wgsl`: each segment one
/// lookup at its clamped scalars, no parts outside).
pub static PREINT2D_BARE_STAGE: StageDesc = preint_stage!(
    "preint2d.wgsl+inside",
    "preint2d.wgsl",
    &[("EXTENDED", 0.0)]
);

/// Twin of `texel2d`: texel `(i, j)` of the table's storage buffer.
#[inline]
pub fn texel2d(t: &CpuTable, i: usize, j: usize) -> [f32; 4] {
    t.load(i, j, 0)
}

/// Twin of `table_rgba` in `shaders/preint2d.wgsl`.
pub fn table_rgba(p: &PreintParams, t: &CpuTable, sf: f32, sb: f32, l: f32) -> [f32; 4] {
    let (i, wa) = axis(sf, p.ns);
    let (j, wb) = axis(sb, p.ns);
    let r0 = lerp4(texel2d(t, i, j), texel2d(t, i + 1, j), wa);
    let r1 = lerp4(texel2d(t, i, j + 1), texel2d(t, i + 1, j + 1), wa);
    let v = lerp4(r0, r1, wb);
    let r = l / p.l_table;
    let depth_ref = v[3].max(0.0);
    let depth = (depth_ref * r).min(1e30);
    let alpha = depth * one_minus_exp_over(depth);
    let scale = r * (one_minus_exp_over(depth) / one_minus_exp_over(depth_ref));
    [
        (v[0] * scale).min(1e30),
        (v[1] * scale).min(1e30),
        (v[2] * scale).min(1e30),
        alpha,
    ]
}
