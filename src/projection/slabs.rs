//! Breakpoint slabs: a tetrahedron whose scalar range strictly contains
//! transfer-function breakpoints is cut by the iso-planes `s = b` into convex
//! slabs, on each of which the transfer function is linear.
//!
//! Each slab is the band `b_i <= s <= b_{i+1}` of the tet, clipped in one
//! pass ([`Clipper`] with [`ClipValue::Scalar`]): cut points are computed
//! from the tet's own corners and carry the breakpoint scalar exactly, and
//! the two slabs sharing an iso-plane compute its points identically.
//!
//! Order: the scalar is linear, so along any ray it is monotonic and the
//! slabs a ray meets come in scalar order. In view space the eye is the
//! origin: with `e` the (extrapolated) scalar at the eye, a ray meets the
//! slabs on one side of `e` by increasing distance `|s - e|`, so drawing by
//! decreasing distance of the slab's interval from `e` is back to front
//! (slabs on opposite sides of `e` never share a ray). Orthographic views use
//! the sign of the gradient along the view direction `+z` instead.

use glam::{DMat3, DVec3};

use super::clip::{ClipValue, Clipper};
use super::polyhedron::Polyhedron;
use crate::camera::Camera;

/// Cuts the view-space tet `points` by the breakpoints strictly inside its
/// scalar range and returns the slabs in back-to-front order for `camera`.
/// Without such breakpoints the result is the whole tet.
pub fn slice_tet(
    points: [DVec3; 4],
    scalars: [f64; 4],
    breakpoints: &[f64],
    camera: &Camera,
) -> Vec<Polyhedron> {
    let tet = Polyhedron::from_tet(points, scalars);
    let smin = scalars.iter().copied().fold(f64::INFINITY, f64::min);
    let smax = scalars.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut levels: Vec<f64> = breakpoints
        .iter()
        .copied()
        .filter(|&b| b > smin && b < smax)
        .collect();
    if levels.is_empty() {
        return vec![tet];
    }
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let mut bands = Vec::with_capacity(levels.len() + 1);
    let mut lo = f64::NEG_INFINITY;
    for &b in levels.iter().chain(std::iter::once(&f64::INFINITY)) {
        bands.push((lo, b));
        lo = b;
    }
    let key = order_key(&points, &scalars, camera.ortho);
    let mut keyed: Vec<(f64, usize)> = bands
        .iter()
        .enumerate()
        .map(|(i, &(lo, hi))| (key(lo, hi, i), i))
        .collect();
    // Larger key = further back = drawn first.
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let mut clipper = Clipper::default();
    let mut out = Vec::with_capacity(bands.len());
    for (_, i) in keyed {
        let (lo, hi) = bands[i];
        let mut slab = Polyhedron::default();
        if let Ok(true) = clipper.clip(&tet, ClipValue::Scalar, lo, hi, &mut slab) {
            out.push(slab);
        }
    }
    out
}

/// A sort key per band: larger means further from the eye.
fn order_key(p: &[DVec3; 4], s: &[f64; 4], ortho: bool) -> impl Fn(f64, f64, usize) -> f64 {
    let m = DMat3::from_cols(p[1] - p[0], p[2] - p[0], p[3] - p[0]).transpose();
    let ds = DVec3::new(s[1] - s[0], s[2] - s[0], s[3] - s[0]);
    let det = m.determinant();
    let g = if det != 0.0 && det.is_finite() {
        m.inverse() * ds
    } else {
        DVec3::ZERO
    };
    let eye = s[0] - g.dot(p[0]);
    let gz = g.z;
    move |lo: f64, hi: f64, i: usize| {
        if g == DVec3::ZERO || !eye.is_finite() {
            return -(i as f64);
        }
        if ortho {
            // s grows along the view direction: higher bands are behind.
            if gz >= 0.0 {
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
    }
}
