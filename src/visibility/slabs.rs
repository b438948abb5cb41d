//! Breakpoint slabs as pieces of the order.
//!
//! A consistent tet whose nodal scalar range strictly holds transfer-function
//! breakpoints is drawn as slabs: the bands `b_i <= s <= b_{i+1}` between
//! consecutive breakpoints inside its range (the first and last band open),
//! on each of which the transfer function is linear. The sorter lists them
//! as [`super::Piece::Slab`], consecutive, in back-to-front order; this
//! module gives that order.
//!
//! The scalar is linear on the tet, so along any ray it is monotonic and the
//! slabs a ray meets come in scalar order. In view space the eye is the
//! origin: with `e` the (extrapolated) scalar at the eye, a ray meets the
//! slabs on one side of `e` by increasing distance `|s - e|`, so drawing by
//! decreasing distance of the band from `e` is back to front (bands on
//! opposite sides of `e` never share a ray). Orthographic views use the sign
//! of the gradient along the view direction `+z` instead.
//!
//! [`tet_slabs`] is the one slab expansion: the sorter lists a tet's
//! [`super::Piece::Slab`]s from it, and [`crate::projection::slice_tet`]
//! cuts the same slabs geometrically from it. Levels are the sorted,
//! deduplicated finite breakpoints ([`order_levels`]), the
//! [`super::Order::levels`] that slab pieces index.

use std::ops::Range;

use glam::{DMat3, DVec3};

use super::NO_LEVEL;

/// Indices of the sorted `levels` that lie strictly inside the range of
/// `scalars` (empty when none does).
pub fn inner_levels(scalars: &[f64], levels: &[f64]) -> Range<usize> {
    let lo = scalars.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = scalars.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo >= hi || lo.is_nan() || hi.is_nan() {
        return 0..0;
    }
    let a = levels.partition_point(|&b| b <= lo);
    let b = levels.partition_point(|&b| b < hi);
    a..b.max(a)
}

/// The bands `(lo, hi)` of a tet cut by `levels` (sorted, strictly inside
/// its range): `levels.len() + 1` bands, the outer ones unbounded.
pub fn bands(levels: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(levels.len() + 1);
    bands_into(levels, &mut out);
    out
}

/// [`bands`] into a reused buffer.
pub fn bands_into(levels: &[f64], out: &mut Vec<(f64, f64)>) {
    out.clear();
    let mut lo = f64::NEG_INFINITY;
    for &b in levels.iter().chain(std::iter::once(&f64::INFINITY)) {
        out.push((lo, b));
        lo = b;
    }
}

/// Back-to-front order of the `bands` of the view-space tet `points` with
/// nodal `scalars` (indices into `bands`).
pub fn slab_order(
    points: &[DVec3; 4],
    scalars: &[f64; 4],
    bands: &[(f64, f64)],
    ortho: bool,
) -> Vec<usize> {
    let mut keyed = Vec::with_capacity(bands.len());
    slab_order_into(points, scalars, bands, ortho, &mut keyed);
    keyed.into_iter().map(|k| k.1).collect()
}

/// [`slab_order`] into a reused buffer: `keyed[k].1` is the `k`-th band to
/// draw.
pub fn slab_order_into(
    points: &[DVec3; 4],
    scalars: &[f64; 4],
    bands: &[(f64, f64)],
    ortho: bool,
    keyed: &mut Vec<(f64, usize)>,
) {
    let p = points;
    let s = scalars;
    let m = DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]).transpose();
    let ds = DVec3::new(s[1] - s[0], s[2] - s[0], s[3] - s[0]);
    let det = m.determinant();
    let g = if det != 0.0 && det.is_finite() {
        m.inverse() * ds
    } else {
        DVec3::ZERO
    };
    let eye = s[0] - g.dot(p[0]);
    let key = |lo: f64, hi: f64, i: usize| -> f64 {
        if g == DVec3::ZERO || !g.is_finite() || !eye.is_finite() {
            return -(i as f64);
        }
        if ortho {
            // s grows along the view direction: higher bands are behind.
            if g.z >= 0.0 {
                i as f64
            } else {
                -(i as f64)
            }
        } else if eye < lo {
            lo - eye
        } else if eye > hi {
            eye - hi
        } else {
            0.0
        }
    };
    keyed.clear();
    keyed.extend(
        bands
            .iter()
            .enumerate()
            .map(|(i, &(lo, hi))| (key(lo, hi, i), i)),
    );
    // Larger key = further back = drawn first.
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
}

/// The levels slabs index: the finite `breakpoints`, sorted, without
/// duplicates.
pub fn order_levels(breakpoints: &[f64]) -> Vec<f64> {
    let mut levels: Vec<f64> = breakpoints
        .iter()
        .copied()
        .filter(|b| b.is_finite())
        .collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    levels
}

/// The scalar band `(lo, hi)` of the slab between level indices `lo` and
/// `hi` ([`NO_LEVEL`]: unbounded on that side).
pub fn band_values(levels: &[f64], lo: u32, hi: u32) -> (f64, f64) {
    let at = |i: u32, open: f64| {
        if i == NO_LEVEL {
            open
        } else {
            levels[i as usize]
        }
    };
    (at(lo, f64::NEG_INFINITY), at(hi, f64::INFINITY))
}

/// Reusable buffers of [`tet_slabs`].
#[derive(Clone, Debug, Default)]
pub struct SlabScratch {
    bands: Vec<(f64, f64)>,
    keyed: Vec<(f64, usize)>,
    slabs: Vec<(u32, u32)>,
}

/// The slabs of a tet, back to front: the one slab expansion.
///
/// `levels` are the order's levels ([`order_levels`]). The levels strictly
/// inside the range of `range` (the tet's nodal scalars, or those of a
/// fragment of the tet) cut it; `scalars` are the tet's nodal scalars and
/// `view()` its view-space corners (called only when some level cuts), which
/// give the back-to-front order ([`slab_order_into`]; `ortho` for an
/// orthographic camera). Returns each slab as the level indices `(lo, hi)`
/// of its band `levels[lo] <= s <= levels[hi]` ([`NO_LEVEL`] for an open
/// end, see [`band_values`]), in drawing order; empty when no level cuts
/// (the piece is drawn whole).
pub fn tet_slabs<'s>(
    range: &[f64],
    scalars: &[f64; 4],
    view: impl FnOnce() -> [DVec3; 4],
    levels: &[f64],
    ortho: bool,
    scratch: &'s mut SlabScratch,
) -> &'s [(u32, u32)] {
    scratch.slabs.clear();
    let inner = inner_levels(range, levels);
    if inner.is_empty() {
        return &scratch.slabs;
    }
    bands_into(&levels[inner.clone()], &mut scratch.bands);
    slab_order_into(&view(), scalars, &scratch.bands, ortho, &mut scratch.keyed);
    let last = scratch.bands.len() - 1;
    for &(_, i) in &scratch.keyed {
        // Band i lies between inner levels i - 1 and i.
        let lo = if i == 0 {
            NO_LEVEL
        } else {
            (inner.start + i - 1) as u32
        };
        let hi = if i == last {
            NO_LEVEL
        } else {
            (inner.start + i) as u32
        };
        scratch.slabs.push((lo, hi));
    }
    &scratch.slabs
}
