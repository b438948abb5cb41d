//! Non-convex constraints sampled at image resolution (XMPVO at pixel
//! centres).
//!
//! Every boundary triangle the eye does not see edge-on is rasterised at the
//! pixel centres: the projected triangle's three edge functions decide in
//! floating point when the centre is farther than
//! [`RASTER_FILTER_PX`] from every edge line, and the exact
//! [`ray_triangle`] test on the pixel's ray (`Camera::pixel_ray`: origin and
//! origin + direction) decides otherwise, also for triangles that reach
//! behind the near plane. Degenerate hits (through an edge or vertex) count as
//! crossings: constraints for every interpretation of the tie.
//!
//! Each crossing records its pixel, its depth `t` along the ray (computed from
//! lexicographically sorted vertices so coincident triangles agree exactly),
//! whether the ray enters or leaves the mesh there, and the boundary
//! triangle. Sorted by pixel, then depth (leaving before entering at equal
//! depth), every "leave X, then enter Y" pair is one constraint: `Y` is
//! behind `X` and is drawn first.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::geometry::line_plane_t;
use super::geometry::BoundaryTri;
use crate::camera::Camera;
use crate::numeric::predicates::{ray_triangle, RayHit};
use crate::numeric::tolerance::{RASTER_FILTER_MAX_COORD_PX, RASTER_FILTER_PX};

/// One boundary crossing of one pixel ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub pixel: u32,
    pub t: f64,
    /// Whether the ray enters the mesh (the eye sees the outer side).
    pub enter: bool,
    /// Index into the boundary triangle list.
    pub tri: u32,
}

/// Boundary triangles per block of the parallel pass.
const RASTER_BLOCK: usize = 1 << 11;

/// Rasterises the boundary triangles; `enter(i)` gives, for boundary triangle
/// `i`, whether a ray crossing it enters the mesh (`None`: seen edge-on, skip).
/// Returns the crossings sorted by pixel, depth, leaving first (then by
/// triangle).
pub fn rasterize(
    camera: &Camera,
    points: &[DVec3],
    tris: &[BoundaryTri],
    enter: impl Fn(usize) -> Option<bool> + Sync,
) -> Vec<Crossing> {
    // Blocks of triangles on the thread pool, joined in order.
    let blocks: Vec<Vec<Crossing>> = tris
        .par_chunks(RASTER_BLOCK)
        .enumerate()
        .map(|(b, block)| {
            let mut out = Vec::new();
            for (k, bt) in block.iter().enumerate() {
                rasterize_one(camera, points, b * RASTER_BLOCK + k, bt, &enter, &mut out);
            }
            out
        })
        .collect();
    let mut out = blocks.concat();
    // The triangle last: a total order, whatever the sort algorithm.
    out.par_sort_unstable_by(|x, y| {
        x.pixel
            .cmp(&y.pixel)
            .then(x.t.total_cmp(&y.t))
            .then(x.enter.cmp(&y.enter))
            .then(x.tri.cmp(&y.tri))
    });
    out
}

/// Appends the crossings of boundary triangle `i` (`bt`) to `out`.
fn rasterize_one(
    camera: &Camera,
    points: &[DVec3],
    i: usize,
    bt: &BoundaryTri,
    enter: &(impl Fn(usize) -> Option<bool> + Sync),
    out: &mut Vec<Crossing>,
) {
    let (w, h) = (camera.width as i64, camera.height as i64);
    let Some(ent) = enter(i) else {
        return;
    };
    let [a, b, c] = bt.verts.map(|v| points[v as usize]);
    let proj = [a, b, c].map(|p| camera.project(p));
    let filtered = proj.iter().all(|q| {
        q.is_some_and(|(x, y, _)| {
            x.abs() < RASTER_FILTER_MAX_COORD_PX && y.abs() < RASTER_FILTER_MAX_COORD_PX
        })
    });
    let mut emit = |i_px: i64, j_px: i64| {
        let ray = camera.pixel_ray(i_px as u32, j_px as u32);
        let (o, q) = (ray.origin, ray.origin + ray.dir);
        if let Some(t) = line_plane_t(o, q, a, b, c) {
            if t > if camera.ortho { 0.0 } else { camera.near } {
                out.push(Crossing {
                    pixel: (j_px * w + i_px) as u32,
                    t,
                    enter: ent,
                    tri: i as u32,
                });
            }
        }
    };
    if !filtered {
        for j in 0..h {
            for ii in 0..w {
                let ray = camera.pixel_ray(ii as u32, j as u32);
                if ray_triangle(ray.origin, ray.origin + ray.dir, a, b, c) != RayHit::Miss {
                    emit(ii, j);
                }
            }
        }
        return;
    }
    let pts = proj.map(|q| {
        let (x, y, _) = q.unwrap_or((0.0, 0.0, 0.0));
        DVec2::new(x, y)
    });
    let lo = pts[0].min(pts[1]).min(pts[2]);
    let hi = pts[0].max(pts[1]).max(pts[2]);
    let i0 = ((lo.x - 1.0).floor() as i64).max(0);
    let i1 = ((hi.x + 1.0).ceil() as i64).min(w - 1);
    let j0 = ((lo.y - 1.0).floor() as i64).max(0);
    let j1 = ((hi.y + 1.0).ceil() as i64).min(h - 1);
    let edges = [(pts[0], pts[1]), (pts[1], pts[2]), (pts[2], pts[0])];
    let lens = edges.map(|(p, q)| (q - p).length() * RASTER_FILTER_PX);
    for j in j0..=j1 {
        for ii in i0..=i1 {
            let pc = DVec2::new(ii as f64 + 0.5, j as f64 + 0.5);
            let mut pos = 0;
            let mut neg = 0;
            for (k, (p, q)) in edges.iter().enumerate() {
                let e = (*q - *p).perp_dot(pc - *p);
                if e > lens[k] {
                    pos += 1;
                } else if e < -lens[k] {
                    neg += 1;
                }
            }
            let hit = if pos > 0 && neg > 0 {
                false
            } else if pos == 3 || neg == 3 {
                true
            } else {
                let ray = camera.pixel_ray(ii as u32, j as u32);
                ray_triangle(ray.origin, ray.origin + ray.dir, a, b, c) != RayHit::Miss
            };
            if hit {
                emit(ii, j);
            }
        }
    }
}

/// The "leave X, enter Y" pairs of boundary triangles along each pixel ray,
/// as `(exit triangle, entry triangle)`, deduplicated.
pub fn exit_entry_pairs(crossings: &[Crossing]) -> Vec<(u32, u32)> {
    let mut pairs: Vec<(u32, u32)> = crossings
        .windows(2)
        .filter(|w| w[0].pixel == w[1].pixel && !w[0].enter && w[1].enter)
        .map(|w| (w[0].tri, w[1].tri))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}
