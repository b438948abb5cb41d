//! Breakpoint slabs: a tetrahedron whose scalar range strictly contains
//! transfer-function breakpoints is cut by the iso-planes `s = b` into convex
//! slabs, on each of which the transfer function is linear.
//!
//! Each slab is the band `b_i <= s <= b_{i+1}` of the tet, clipped in one
//! pass ([`Clipper`] with [`ClipValue::Scalar`]): cut points are computed
//! from the tet's own corners and carry the breakpoint scalar exactly, and
//! the two slabs sharing an iso-plane compute its points identically.
//!
//! Order: back to front along the gradient
//! ([`crate::visibility::slabs::slab_order`], the order the sorter lists
//! [`crate::visibility::Piece::Slab`]s in).

use glam::DVec3;

use super::clip::{ClipValue, Clipper};
use super::polyhedron::Polyhedron;
use crate::camera::Camera;
use crate::visibility::slabs::{bands, inner_levels, slab_order};

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
    let mut levels: Vec<f64> = breakpoints
        .iter()
        .copied()
        .filter(|b| b.is_finite())
        .collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let inner = &levels[inner_levels(&scalars, &levels)];
    if inner.is_empty() {
        return vec![tet];
    }
    let bands = bands(inner);
    let mut clipper = Clipper::default();
    let mut out = Vec::with_capacity(bands.len());
    for i in slab_order(&points, &scalars, &bands, camera.ortho) {
        let (lo, hi) = bands[i];
        let mut slab = Polyhedron::default();
        if let Ok(true) = clipper.clip(&tet, ClipValue::Scalar, lo, hi, &mut slab) {
            out.push(slab);
        }
    }
    out
}
