//! Cells no pixel-centre ray meets: outside the view frustum.
//!
//! Every pixel-centre ray ([`Camera::pixel_ray`]) lies inside the view
//! pyramid of the image rectangle (perspective: four planes through the
//! eye; orthographic: a box around the direction of projection). A cell
//! whose points all lie beyond one side of it, grown by
//! [`FRUSTUM_MARGIN_PX`], meets no such ray: a cell lies in the convex hull
//! of its points (its faces' triangles and bilinear patches do). Each point
//! gets an outcode (one bit per side it lies beyond); a cell is outside
//! when the bitwise AND of its points' codes is not zero, as in
//! Cohen-Sutherland clipping.
//!
//! **Why the order of the rest stays exact.** The sorter leaves such cells
//! out before classifying faces ([`super::Sorter::frustum_margin`]): their
//! faces give no constraint and their problem faces split nothing. What
//! the image needs of the order is that along every pixel-centre ray the
//! pieces it crosses come back to front. Consecutive pieces along a ray
//! share a face or are joined by a boundary constraint of that very ray
//! (module docs of [`super`], step 3), and both are met by the ray, so both
//! are kept: no constraint the image needs passes through a cell left out.
//! Leaving cells out removes constraints only, so it makes no cycle.
//!
//! A point whose view coordinates are not numbers lies beyond no side
//! (its cell is kept).

use glam::DVec3;
use rayon::prelude::*;

use crate::camera::Camera;
use crate::mesh::Mesh;
#[cfg(doc)]
use crate::numeric::tolerance::FRUSTUM_MARGIN_PX;

/// Points per block of the parallel outcode pass.
const BLOCK: usize = 1 << 14;

/// Marks in `out` (one entry per cell) the cells of `mesh` outside the view
/// frustum of `camera` grown by `margin_px` pixels on every side (see the
/// module docs; [`FRUSTUM_MARGIN_PX`] is the sorter's), and returns how
/// many. A negative margin shrinks the frustum: tests use it to check that
/// culling visible cells shows in the image.
pub fn outside_cells(camera: &Camera, mesh: &Mesh, margin_px: f64, out: &mut Vec<bool>) -> usize {
    let (hw, hh) = camera.half_extent();
    // The half extents (at unit depth in perspective) grown by the margin:
    // a pixel is 2 hw / width wide there.
    let gx = hw * (1.0 + 2.0 * margin_px / camera.width.max(1) as f64);
    let gy = hh * (1.0 + 2.0 * margin_px / camera.height.max(1) as f64);
    let code = |p: DVec3| -> u8 {
        let v = camera.to_view(p);
        let (ex, ey) = if camera.ortho {
            (gx, gy)
        } else {
            (gx * v.z, gy * v.z)
        };
        (v.x > ex) as u8
            | ((v.x < -ex) as u8) << 1
            | ((v.y > ey) as u8) << 2
            | ((v.y < -ey) as u8) << 3
    };
    let codes: Vec<u8> = mesh
        .points
        .par_chunks(BLOCK)
        .flat_map_iter(|b| b.iter().map(|&p| code(p)))
        .collect();
    let n = mesh.cells.len();
    out.clear();
    out.resize(n, false);
    out.par_chunks_mut(BLOCK)
        .enumerate()
        .map(|(k, block)| {
            let mut culled = 0;
            for (i, o) in block.iter_mut().enumerate() {
                let c = k * BLOCK + i;
                let and = mesh
                    .cells
                    .nodes(c)
                    .iter()
                    .fold(0xf, |a, &v| a & codes.get(v as usize).copied().unwrap_or(0));
                *o = and != 0 && !mesh.cells.nodes(c).is_empty();
                culled += *o as usize;
            }
            culled
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraParams;
    use crate::generate::{warped_hex_grid, Warp};

    /// Brute force: a cell is outside exactly when no pixel-centre ray of a
    /// finer-than-pixel sampling comes near it; here the weaker, checkable
    /// half: every culled cell's points project outside the image grown by
    /// the margin, beyond one common side.
    #[test]
    fn culled_cells_lie_beyond_one_side() {
        let mesh = warped_hex_grid(
            8,
            &Warp {
                amplitude: 0.05,
                seed: 3,
            },
        );
        for ortho in [false, true] {
            let camera = Camera::fit(
                mesh.bounds(),
                &CameraParams {
                    width: 40,
                    height: 30,
                    zoom: 3.0,
                    azimuth: 25.0,
                    elevation: 15.0,
                    ortho,
                    ..Default::default()
                },
            );
            let mut out = Vec::new();
            let n = outside_cells(&camera, &mesh, 1.0, &mut out);
            assert!(n > 0 && n < mesh.cells.len(), "{ortho}: {n}");
            for (c, &culled) in out.iter().enumerate() {
                let px: Vec<(f64, f64)> = mesh
                    .cells
                    .nodes(c)
                    .iter()
                    .map(|&v| {
                        let (x, y, _) = camera.project(mesh.points[v as usize]).expect("in front");
                        (x, y)
                    })
                    .collect();
                let beyond = [
                    px.iter().all(|p| p.0 > 41.0),
                    px.iter().all(|p| p.0 < -1.0),
                    px.iter().all(|p| p.1 > 31.0),
                    px.iter().all(|p| p.1 < -1.0),
                ];
                // Culled: beyond one side (up to rounding at the margin).
                // Kept: a cell clearly beyond a side (2 px) is culled.
                if culled {
                    assert!(beyond.iter().any(|&b| b), "{ortho} cell {c}: {px:?}");
                }
                let far = [
                    px.iter().all(|p| p.0 > 42.0),
                    px.iter().all(|p| p.0 < -2.0),
                    px.iter().all(|p| p.1 > 32.0),
                    px.iter().all(|p| p.1 < -2.0),
                ];
                if far.iter().any(|&b| b) {
                    assert!(culled, "{ortho} cell {c}: {px:?}");
                }
            }
        }
    }
}
