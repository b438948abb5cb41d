//! Occlusion culling: pieces hidden behind opaque ones are not drawn.
//!
//! The projected-cell driver draws the order back to front. Before it does,
//! this pass walks the order front to back with one number per pixel
//! centre: a lower bound on the optical depth that the pieces already
//! walked put in front of the centre, as drawn. A piece every centre of
//! whose screen box already lies behind more than [`cut_depth`] is hidden:
//! whatever it and the pieces behind it would add to such a pixel is at
//! most the transmittance in front (below
//! [`OCCLUSION_TRANSMITTANCE`] over the brightest colour) times that
//! colour, so leaving it out changes no channel by more than
//! `OCCLUSION_TRANSMITTANCE` (the image tests allow 1e-6).
//!
//! **Why the walk may use the order, not the geometry.** A pixel's value
//! is the pieces drawn at it, each attenuated by those drawn after it. The
//! pieces before a piece in the front-to-back walk are exactly those drawn
//! after it, so the bound, a sum over them, bounds the attenuation the
//! piece gets, whatever the geometry (cycle groups aside, below).
//!
//! **The bound.** A cell is credited once all its pieces have been walked
//! (its tets and slabs tile it, so at every centre they add up to the
//! cell's own segment). Its credit is that of its largest ball about the
//! mean of its points: where every boundary triangle's plane (the `faces`
//! field's triangles, which are the cell's faces everywhere) lies on one
//! side at distance at least `r`, the ball of radius `r` lies in the
//! intersection of those half-spaces, which is inside the cell. A pixel
//! ray passing at distance `d < r` from the centre crosses the ball over
//! the chord `2 sqrt(r^2 - d^2)`, which the cell's segment contains, and
//! the extinction along it is at least the transfer function's least on
//! the cell's scalar range. The credit is that product, shrunk by
//! [`CREDIT_SHRINK`] for the rounding of the drawn segment. A dense opaque
//! layer is credited about half its true depth; that is plenty, since the
//! cut is at an optical depth of about 16 and such layers reach hundreds.
//!
//! **The test.** A piece's pixels lie in the box of its cell's projected
//! points (the projection of a convex piece is the hull of its corners',
//! and the pixels the driver's exact decisions give it are on rays that
//! meet it), grown by [`FRUSTUM_MARGIN_PX`]. Pieces with a corner not in
//! front of the near plane are never hidden and never credit.
//!
//! **What it leaves alone.** Cycle groups are composited per pixel into
//! one layer: their pieces are never hidden, and their cells never
//! credited. Independent emission is not bounded by the opacity in front
//! (no culling there), and neither is a frame that draws no volume (`--mode
//! iso`) or counts coverage.
//!
//! The pass is sequential (each test depends on the credits before it);
//! the balls are computed in parallel first. A transfer function whose
//! largest extinction times the mesh's diagonal cannot reach the cut skips
//! it at once.

use glam::DVec3;
use rayon::prelude::*;

use crate::camera::Camera;
use crate::mesh::tetra::triangulate_face;
use crate::numeric::tolerance::{FRUSTUM_MARGIN_PX, OCCLUSION_TRANSMITTANCE};
use crate::tf::EmissionModel;
use crate::visibility::Order;

use super::pieces::{value_range, PieceSource};

/// Credits are shrunk by this factor: the drawn segment differs from the
/// exact one by the snap of its corners and `f32` interpolation, far below
/// a tenth.
pub const CREDIT_SHRINK: f64 = 0.9;

/// The optical depth in front of a centre beyond which nothing behind it
/// can change a channel by more than [`OCCLUSION_TRANSMITTANCE`]: `ln(c /
/// OCCLUSION_TRANSMITTANCE)` with `c` the brightest colour (at least 1,
/// the most an isosurface adds).
pub fn cut_depth(brightest: f64) -> f64 {
    (brightest.max(1.0) / OCCLUSION_TRANSMITTANCE).ln()
}

/// What the pass found.
#[derive(Clone, Debug, Default)]
pub struct Occlusion {
    /// Per piece of the order: hidden behind opaque pieces.
    pub hidden: Vec<bool>,
    /// How many are.
    pub count: usize,
}

/// A cell's ball: centre (world), radius, and least extinction.
#[derive(Clone, Copy)]
struct Ball {
    centre: DVec3,
    radius: f64,
    tau: f64,
}

/// Runs the pass over `order` for `src` (see the module docs); `None` when
/// it does not apply or cannot hide anything.
pub fn hidden_pieces(src: &PieceSource, order: &Order) -> Option<Occlusion> {
    let tf = src.tf;
    if !src.volume || tf.model() != EmissionModel::Glow || order.pieces.is_empty() {
        return None;
    }
    let nodes = tf.nodes();
    let brightest = nodes
        .iter()
        .flat_map(|n| n.color)
        .fold(0.0f64, |a, c| a.max(c.abs()));
    let cut = cut_depth(brightest);
    let (lo, hi) = tf.scalar_range();
    let tau_max = src.max_rate(lo.min(hi), hi.max(lo));
    let mesh = src.mesh;
    if !(tau_max * mesh.diagonal() >= cut) || !cut.is_finite() {
        return None;
    }
    let camera = src.camera;
    let (w, h) = (camera.width as usize, camera.height as usize);
    if w == 0 || h == 0 {
        return None;
    }
    // Pieces per cell (a cell is credited when its last one is walked),
    // and the cells in cycle groups (never credited).
    let ncells = mesh.cells.len();
    let mut left = vec![0u32; ncells];
    for p in &order.pieces {
        left[p.cell() as usize] += 1;
    }
    let mut in_group = vec![false; order.pieces.len()];
    for g in &order.groups {
        for k in g.clone() {
            in_group[k] = true;
            left[order.pieces[k].cell() as usize] = u32::MAX;
        }
    }
    // The pixel positions of the points (None: not in front of the near
    // plane).
    let he = camera.half_extent();
    let screen: Vec<Option<(f64, f64)>> = mesh
        .points
        .par_iter()
        .map(|&p| {
            let v = camera.to_view(p);
            if v.z <= camera.near.max(0.0) {
                return None;
            }
            camera
                .view_to_pixel_with(v, he)
                .map(|(x, y, _)| (x, y))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
        })
        .collect();
    // The balls of the cells that may credit, in parallel.
    let credited: Vec<u32> = {
        let mut seen = vec![false; ncells];
        let mut v = Vec::new();
        for p in &order.pieces {
            let c = p.cell() as usize;
            if left[c] != u32::MAX && !seen[c] {
                seen[c] = true;
                v.push(c as u32);
            }
        }
        v
    };
    let mut balls: Vec<Option<Ball>> = vec![None; ncells];
    let computed: Vec<(u32, Option<Ball>)> = credited
        .par_iter()
        .map(|&c| (c, ball(src, c, cut)))
        .collect();
    for (c, b) in computed {
        balls[c as usize] = b;
    }
    // Unit pixel-ray directions and origins, computed once.
    let rays: Vec<(DVec3, DVec3)> = (0..w * h)
        .into_par_iter()
        .map(|k| {
            let r = camera.pixel_ray((k % w) as u32, (k / w) as u32);
            (r.origin, r.dir)
        })
        .collect();
    let mut depth = vec![0.0f64; w * h];
    let mut hidden = vec![false; order.pieces.len()];
    let mut count = 0;
    let mut any_opaque = false;
    let m = FRUSTUM_MARGIN_PX;
    for k in (0..order.pieces.len()).rev() {
        let piece = &order.pieces[k];
        let c = piece.cell() as usize;
        if any_opaque && !in_group[k] {
            if let Some((x0, x1, y0, y1)) = cell_box(src, c, &screen, m) {
                let covered =
                    (y0..y1).all(|j| depth[j * w + x0..j * w + x1].iter().all(|&d| d >= cut));
                if covered {
                    hidden[k] = true;
                    count += 1;
                }
            }
        }
        if left[c] == u32::MAX {
            continue;
        }
        left[c] -= 1;
        if left[c] > 0 {
            continue;
        }
        let Some(b) = balls[c] else { continue };
        any_opaque |= credit(camera, &b, &rays, &mut depth, cut);
    }
    Some(Occlusion { hidden, count })
}

/// Pixel-centre index ranges `[x0, x1) x [y0, y1)` of the box of cell
/// `c`'s projected points grown by `margin` (centres at `i + 0.5`); `None`
/// when a point is not in front of the near plane or the box misses the
/// image.
fn cell_box(
    src: &PieceSource,
    c: usize,
    screen: &[Option<(f64, f64)>],
    margin: f64,
) -> Option<(usize, usize, usize, usize)> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &n in src.mesh.cells.nodes(c) {
        let (x, y) = screen.get(n as usize).copied().flatten()?;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let (w, h) = (src.camera.width as f64, src.camera.height as f64);
    // Centres i + 0.5 with x0 - margin <= i + 0.5 <= x1 + margin.
    let lo = |v: f64| (v - margin - 0.5).ceil().max(0.0);
    let hi = |v: f64, n: f64| (v + margin - 0.5).floor().min(n - 1.0);
    let (i0, i1, j0, j1) = (lo(x0), hi(x1, w), lo(y0), hi(y1, h));
    if i0 > i1 || j0 > j1 {
        // No centre: nothing of it is drawn, so nothing to hide.
        return None;
    }
    Some((i0 as usize, i1 as usize + 1, j0 as usize, j1 as usize + 1))
}

/// The ball of cell `c` (see the module docs), or `None` when it credits
/// nothing worth adding (no extinction, a cell whose planes do not all
/// face the centre, a credit far below `cut`).
fn ball(src: &PieceSource, c: u32, cut: f64) -> Option<Ball> {
    let mesh = src.mesh;
    let nodes = mesh.cells.nodes(c as usize);
    let (lo, hi) = value_range(nodes.iter().map(|&n| src.scalar(c, n)));
    let tau = src.min_extinction(lo, hi);
    if !(tau > 0.0) {
        return None;
    }
    let centre = nodes
        .iter()
        .map(|&n| mesh.points[n as usize])
        .sum::<DVec3>()
        / nodes.len() as f64;
    let (mut pos, mut neg) = (f64::INFINITY, f64::INFINITY);
    let mut faces = 0;
    mesh.cells.for_each_face(c as usize, |_, face| {
        triangulate_face(face, |t| {
            let [a, b, d] = t.map(|i| mesh.points[i as usize]);
            let n = (b - a).cross(d - a);
            let len = n.length();
            faces += 1;
            if !(len > 0.0) {
                // A degenerate triangle: no plane to keep the ball inside.
                pos = f64::NEG_INFINITY;
                neg = f64::NEG_INFINITY;
                return;
            }
            let s = (centre - a).dot(n) / len;
            if s >= 0.0 {
                pos = pos.min(s);
                neg = f64::NEG_INFINITY;
            } else {
                neg = neg.min(-s);
                pos = f64::NEG_INFINITY;
            }
        })
    });
    // Shrunk by a relative 1e-9 for the rounding of the distances.
    let radius = pos.max(neg) * (1.0 - 1e-9);
    if faces < 4 || !(radius > 0.0 && radius.is_finite()) {
        return None;
    }
    // A credit below a millionth of the cut is not worth its pixels.
    if tau * 2.0 * radius * CREDIT_SHRINK < cut * 1e-6 {
        return None;
    }
    Some(Ball {
        centre,
        radius,
        tau,
    })
}

/// Adds ball `b`'s credit to the centres whose rays pass through it;
/// returns whether one of them reached `cut`.
fn credit(camera: &Camera, b: &Ball, rays: &[(DVec3, DVec3)], depth: &mut [f64], cut: f64) -> bool {
    let v = camera.to_view(b.centre);
    if v.z - b.radius <= camera.near.max(0.0) {
        return false;
    }
    // The box of the ball's view-space bounding cube, projected: every ray
    // through the ball passes through it.
    let he = camera.half_extent();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for k in 0..8 {
        let d = DVec3::new(
            if k & 1 == 0 { -b.radius } else { b.radius },
            if k & 2 == 0 { -b.radius } else { b.radius },
            if k & 4 == 0 { -b.radius } else { b.radius },
        );
        let Some((x, y, _)) = camera.view_to_pixel_with(v + d, he) else {
            return false;
        };
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let (w, h) = (camera.width as usize, camera.height as usize);
    let i0 = (x0 - 0.5).ceil().max(0.0);
    let i1 = (x1 - 0.5).floor().min(w as f64 - 1.0);
    let j0 = (y0 - 0.5).ceil().max(0.0);
    let j1 = (y1 - 0.5).floor().min(h as f64 - 1.0);
    if !(i0 <= i1 && j0 <= j1) {
        return false;
    }
    let r2 = b.radius * b.radius;
    let mut reached = false;
    for j in j0 as usize..=j1 as usize {
        for i in i0 as usize..=i1 as usize {
            let (o, dir) = rays[j * w + i];
            let to = b.centre - o;
            let along = to.dot(dir);
            let d2 = to.length_squared() - along * along;
            if d2 < r2 {
                let at = &mut depth[j * w + i];
                *at += b.tau * 2.0 * (r2 - d2).sqrt() * CREDIT_SHRINK;
                reached |= *at >= cut;
            }
        }
    }
    reached
}
