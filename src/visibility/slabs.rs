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

use std::ops::Range;

use glam::{DMat3, DVec3};

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
