//! The preint2d-cyl mode: the 3D pre-integrated table re-mapped into 2D
//! textures (Röttger, Ertl 2002, section 4): the 3D table's accuracy with
//! 2D lookups.
//!
//! All fragments of one projected tetrahedron lie in one half-plane
//! through the axis of zero-length segments `{S_f = S_b, L = 0}` of the
//! normalised `(S_f, S_b, L = l / l_table)` cube. Equation 10 of the paper
//! takes a segment to the plane parameter `a in [0, 1]` and in-plane
//! coordinates `(u, v = S_b)`; the table holds planes `a_k = k / (P - 1)`,
//! each `N x N` over `(u, v) in [0, 1]^2`, filled at equation 9's
//! `(S_f, S_b, L)` from the exact integrals ([`TableKind::Cylinder`]), as
//! consecutive layers of one storage buffer (the paper's tiles). A lookup is
//! bilinear in each of the two nearest planes and linear between them, by
//! hand in `f32` ([`table_rgba`], the twin of `table_rgba` in
//! `shaders/preint2d_cyl.wgsl`). `--table N` gives `N` samples per axis and
//! `P = 2 N` planes (the paper: `4 N` reconstructs the 3D table exactly,
//! `N` to `2 N` usually suffice). `l_table` is the largest cell diameter,
//! as for preint3d; the constant extensions beyond the node range and the
//! steps are shared ([`super::preint`]).
//!
//! Where the error comes from: the interpolation between planes (a plane
//! is a different slice of the cube than the fragment's, off by up to half
//! a plane spacing in `a`), and bilinear interpolation within a plane,
//! which spans `u` (a scalar difference or a length) with the same `N`
//! samples that the 3D table spends on one axis. Glow and independent
//! emission are both tabulated.

use crate::gpu::StageDesc;
use crate::raycast::FieldModel;
use crate::tf::EmissionModel;

use super::preint::{axis, lerp4, preint_stage, CpuTable, PreintParams};
use super::{Bounds, ModeInfo};

/// The registry entry of the preint2d-cyl mode.
pub static INFO: ModeInfo = ModeInfo {
    name: "preint2d-cyl",
    summary: "projection of convex pieces, the 3D pre-integrated table re-mapped into cylindrical 2D planes (RE eq. 9-10), looked up per fragment by wgpu",
    gpu: true,
    emission: &[EmissionModel::Glow, EmissionModel::Independent],
    slices_at_breakpoints: false,
    draws_pieces_whole: true,
    stage: Some(&PREINT2D_CYL_STAGE),
    bounds: Some(Bounds {
        reference: FieldModel::Faces,
        // Measured at most 2.15e-3 (ring_hole, orthographic), as preint3d:
        // with 2N planes the re-mapping adds at most 3e-4 here (the
        // default transfer function is smooth); the plane spacing matters
        // for transfer functions with narrow peaks (benches/tables.rs
        // prints the curve).
        split_max: 4e-3,
        // Measured 1.18e-2 (zoo_3x3x3, perspective): the model difference
        // inside cells split into tets, as for every projected mode.
        whole_max: 0.02,
        split_outliers: 0,
        whole_outliers: 0,
    }),
};

/// The preint2d-cyl stage.
pub static PREINT2D_CYL_STAGE: StageDesc =
    preint_stage!("preint2d_cyl.wgsl", "preint2d_cyl.wgsl", &[]);

/// The preint2d-cyl stage compiled for fields inside the transfer function's
/// node range (`EXTENDED` false in `shaders/preint.wgsl`: each segment one
/// lookup at its clamped scalars, no parts outside).
pub static PREINT2D_CYL_BARE_STAGE: StageDesc = preint_stage!(
    "preint2d_cyl.wgsl+inside",
    "preint2d_cyl.wgsl",
    &[("EXTENDED", 0.0)]
);

/// Equation 10 in `f32`, as the shader computes it: `(a, u)` of the
/// normalised segment (`v` is `S_b`).
pub fn table_to_cyl(sf: f32, sb: f32, big_l: f32) -> (f32, f32) {
    let d = sf - sb;
    if d >= 0.0 {
        if big_l <= d {
            (if d > 0.0 { big_l / (4.0 * d) } else { 0.0 }, d)
        } else {
            (0.5 - d / (4.0 * big_l), big_l)
        }
    } else if big_l >= -d {
        (0.5 - d / (4.0 * big_l), big_l)
    } else {
        (1.0 + big_l / (4.0 * d), -d)
    }
}

/// Twin of `plane_texel`: texel `(i, j)` of plane `k` of the table's
/// storage buffer.
#[inline]
pub fn plane_texel(t: &CpuTable, i: usize, j: usize, k: usize) -> [f32; 4] {
    t.load(i, j, k)
}

/// Twin of `table_rgba` in `shaders/preint2d_cyl.wgsl`.
pub fn table_rgba(p: &PreintParams, t: &CpuTable, sf: f32, sb: f32, l: f32) -> [f32; 4] {
    let big_l = (l / p.l_table).clamp(0.0, 1.0);
    let (a, u) = table_to_cyl(sf, sb, big_l);
    let (k, wp) = axis(a, p.nz);
    let (i, wu) = axis(u, p.ns);
    let (j, wv) = axis(sb, p.ns);
    let layer = |k: usize| {
        let r0 = lerp4(plane_texel(t, i, j, k), plane_texel(t, i + 1, j, k), wu);
        let r1 = lerp4(
            plane_texel(t, i, j + 1, k),
            plane_texel(t, i + 1, j + 1, k),
            wu,
        );
        lerp4(r0, r1, wv)
    };
    lerp4(layer(k), layer(k + 1), wp)
}
