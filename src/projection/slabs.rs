//! Breakpoint slabs: a tetrahedron whose scalar range strictly contains
//! transfer-function breakpoints is cut by the iso-planes `s = b` into convex
//! slabs, on each of which the transfer function is linear.
//!
//! Each slab is the band `b_i <= s <= b_{i+1}` of the tet, clipped in one
//! pass ([`Clipper`] with [`ClipValue::Scalar`]): cut points are computed
//! from the tet's own corners and carry the breakpoint scalar exactly, and
//! the two slabs sharing an iso-plane compute its points identically.
//!
//! Which slabs, and their order: [`crate::visibility::slabs::tet_slabs`],
//! the expansion the sorter lists [`crate::visibility::Piece::Slab`]s from.

use glam::DVec3;

use super::clip::{ClipValue, Clipper};
use super::polyhedron::Polyhedron;
use crate::camera::Camera;
use crate::visibility::slabs::{band_values, order_levels, tet_slabs, SlabScratch};

/// Cuts the view-space tet `points` by the breakpoints strictly inside its
/// scalar range and returns the slabs in back-to-front order for `camera`
/// (the slabs [`tet_slabs`] lists, the ones the sorter orders).
/// Without such breakpoints the result is the whole tet.
pub fn slice_tet(
    points: [DVec3; 4],
    scalars: [f64; 4],
    breakpoints: &[f64],
    camera: &Camera,
) -> Vec<Polyhedron> {
    let tet = Polyhedron::from_tet(points, scalars);
    let levels = order_levels(breakpoints);
    let mut scratch = SlabScratch::default();
    let slabs = tet_slabs(
        &scalars,
        &scalars,
        || points,
        &levels,
        camera.ortho,
        &mut scratch,
    );
    if slabs.is_empty() {
        return vec![tet];
    }
    let mut clipper = Clipper::default();
    let mut out = Vec::with_capacity(slabs.len());
    for &(lo, hi) in slabs {
        let (lo, hi) = band_values(&levels, lo, hi);
        let mut slab = Polyhedron::default();
        if let Ok(true) = clipper.clip(&tet, ClipValue::Scalar, lo, hi, &mut slab) {
            out.push(slab);
        }
    }
    out
}
