//! Cycle groups composited per pixel: the last resort of the visibility
//! order.
//!
//! A group ([`crate::visibility::Order::groups`]) is a range of pieces with
//! no back-to-front order the sorter could find; every piece outside the
//! range is correctly ordered against the whole range. So the group can be
//! reduced to one premultiplied RGBA layer, composited at its place in the
//! order, provided the layer is right at every pixel centre.
//!
//! # How the layer is made
//! On the CPU, for every pixel centre in the union of the pieces' screen
//! bounding boxes:
//! 1. the pixel-centre ray ([`crate::camera::Camera::ray_at`], here in view
//!    space) is clipped against each piece whose box holds the pixel, by the
//!    half-spaces of its boundary triangles (Cyrus-Beck: the pieces are
//!    convex), giving the entry and exit distance and, by barycentric
//!    interpolation on the entry and exit triangles, the front and back
//!    scalars (the same field model as the projection: linear on each
//!    boundary triangle and along the ray);
//! 2. the segments are sorted by the ray parameter of their midpoints: for
//!    pieces that do not overlap in space this is their true order along
//!    this ray, which is exactly what no global order could give;
//! 3. each segment's exact colour, opacity and optical depth
//!    ([`crate::integrate::segment`], breakpoints inside handled in closed
//!    form) are composited front to back.
//!
//! The layer is the same for every mode: the driver draws it with the layer
//! stage ([`crate::gpu::layer`]), one quad per covered pixel with the
//! pixel's premultiplied colour and opacity `1 - exp(-depth)`; pixel
//! centres lie strictly inside their quad, so each is covered exactly once.
//!
//! Pieces that overlap in space (self-intersecting meshes, the only source of
//! groups seen in real data) have no true order even along one ray; their
//! segments are ordered by midpoint, an approximation limited to the overlap.

use glam::DVec3;
use rayon::prelude::*;

use super::gradients::{boundary_gradient, piece_gradient};
use crate::camera::Camera;
use crate::projection::Polyhedron;
use crate::visibility::Piece;

use super::pieces::{value_range, PieceError, PieceSource};

/// A covered pixel of a layer: column, row, premultiplied colour and
/// opacity.
pub type LayerPixel = (u32, u32, [f32; 4]);

/// The layer of one cycle group.
#[derive(Debug, Default)]
pub struct GroupLayer {
    /// The pixels it colours, row by row.
    pub pixels: Vec<LayerPixel>,
    /// Pieces left out for zero extinction over their range.
    pub culled: usize,
}

/// One group piece ready for ray clipping.
struct GroupPiece {
    /// Boundary planes: `n . p <= d` inside (view space), with the triangle
    /// each comes from.
    planes: Vec<(DVec3, f64, usize)>,
    poly: Polyhedron,
    /// Its flat gradient (isosurface light), view space.
    flat_gradient: DVec3,
    /// Pixel box `[x0, x1) x [y0, y1)`.
    bbox: [u32; 4],
}

/// A ray segment through one piece: parameters and scalars at both ends.
#[derive(Clone, Copy, Debug)]
struct Hit {
    /// Index of the piece in the group's prepared pieces.
    piece: usize,
    t_in: f64,
    t_out: f64,
    s_in: f64,
    s_out: f64,
}

/// Makes the per-pixel layer of one group.
pub(super) fn composite_group(
    src: &PieceSource,
    pieces: &[Piece],
) -> Result<GroupLayer, PieceError> {
    let camera = src.camera;
    let mut layer = GroupLayer::default();
    let mut prepared = Vec::with_capacity(pieces.len());
    for piece in pieces {
        let mut poly = Polyhedron::default();
        src.polyhedron(piece, &mut poly)?;
        src.piece_gradients(piece, &mut poly);
        let (lo, hi) = value_range(poly.scalars.iter().copied());
        if src.invisible(lo, hi) {
            layer.culled += 1;
            continue;
        }
        if let Some(gp) = prepare(poly, camera) {
            prepared.push(gp);
        }
    }
    if prepared.is_empty() {
        return Ok(layer);
    }
    let bbox = prepared.iter().fold([u32::MAX, u32::MAX, 0, 0], |b, p| {
        [
            b[0].min(p.bbox[0]),
            b[1].min(p.bbox[1]),
            b[2].max(p.bbox[2]),
            b[3].max(p.bbox[3]),
        ]
    });
    let rows: Vec<Vec<LayerPixel>> = (bbox[1]..bbox[3])
        .into_par_iter()
        .map(|j| {
            let mut hits = Vec::new();
            let mut row = Vec::new();
            for i in bbox[0]..bbox[2] {
                hits.clear();
                let (o, d) = view_ray(camera, i as f64 + 0.5, j as f64 + 0.5);
                for (k, p) in prepared.iter().enumerate() {
                    if i < p.bbox[0] || i >= p.bbox[2] || j < p.bbox[1] || j >= p.bbox[3] {
                        continue;
                    }
                    if let Some(h) = clip_ray(p, o, d, camera) {
                        hits.push(Hit { piece: k, ..h });
                    }
                }
                if hits.is_empty() {
                    continue;
                }
                hits.sort_by(|a, b| (a.t_in + a.t_out).total_cmp(&(b.t_in + b.t_out)));
                let (mut color, mut depth, mut trans) = ([0.0; 3], 0.0, 1.0);
                for h in &hits {
                    let seg = src.segment_value(h.t_out - h.t_in, h.s_in, h.s_out, || {
                        let p = &prepared[h.piece];
                        [h.t_in, h.t_out]
                            .map(|t| boundary_gradient(&p.poly, o + d * t, p.flat_gradient))
                    });
                    for (c, sc) in color.iter_mut().zip(seg.color) {
                        *c += trans * sc;
                    }
                    trans *= 1.0 - seg.alpha;
                    depth += seg.depth;
                }
                let alpha = -(-depth).exp_m1();
                // An opaque isosurface makes the depth infinite.
                if depth > 0.0 && alpha > 0.0 && !depth.is_nan() {
                    let c = color.map(|c| c as f32);
                    row.push((i, j, [c[0], c[1], c[2], alpha as f32]));
                }
            }
            row
        })
        .collect();
    layer.pixels = rows.into_iter().flatten().collect();
    Ok(layer)
}

/// The pixel-centre ray through continuous pixel position `(px, py)`
/// ([`Camera::ray_at`]) in view space: origin and unit direction.
fn view_ray(camera: &Camera, px: f64, py: f64) -> (DVec3, DVec3) {
    let r = camera.ray_at(px, py);
    let o = camera.to_view(r.origin);
    (o, camera.to_view(r.origin + r.dir) - o)
}

/// Planes and pixel box of a piece; `None` when it has no volume or lies
/// off the image.
fn prepare(poly: Polyhedron, camera: &Camera) -> Option<GroupPiece> {
    let n = poly.points.len();
    if n < 4 {
        return None;
    }
    let centre = poly.points.iter().copied().sum::<DVec3>() / n as f64;
    let mut planes = Vec::with_capacity(poly.triangles.len());
    for (k, t) in poly.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| poly.points[v as usize]);
        let mut nrm = (b - a).cross(c - a);
        if nrm.length_squared() == 0.0 || !nrm.is_finite() {
            continue;
        }
        let mut d = nrm.dot(a);
        // Outward: the centre is inside.
        if nrm.dot(centre) > d {
            nrm = -nrm;
            d = -d;
        }
        planes.push((nrm, d, k));
    }
    if planes.len() < 4 {
        return None;
    }
    let (w, h) = (camera.width, camera.height);
    let mut bbox = [0, 0, w, h];
    let projected: Option<Vec<(f64, f64)>> = poly
        .points
        .iter()
        .map(|&p| camera.view_to_pixel(p).map(|(x, y, _)| (x, y)))
        .collect();
    if let Some(pts) = projected {
        let (mut x0, mut y0, mut x1, mut y1) = (f64::INFINITY, f64::INFINITY, f64::MIN, f64::MIN);
        for (x, y) in pts {
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x);
            y1 = y1.max(y);
        }
        // Pixel centres i + 0.5 inside [x0, x1].
        let lo = |v: f64, max: u32| (v - 0.5).ceil().clamp(0.0, max as f64) as u32;
        let hi = |v: f64, max: u32| ((v - 0.5).floor() + 1.0).clamp(0.0, max as f64) as u32;
        bbox = [lo(x0, w), lo(y0, h), hi(x1, w), hi(y1, h)];
    }
    if bbox[0] >= bbox[2] || bbox[1] >= bbox[3] {
        return None;
    }
    let flat_gradient = piece_gradient(&poly);
    Some(GroupPiece {
        planes,
        poly,
        flat_gradient,
        bbox,
    })
}

/// Clips the ray `o + t d` to the piece (and, in perspective, to the near
/// plane): `None` when it misses or only grazes it.
fn clip_ray(p: &GroupPiece, o: DVec3, d: DVec3, camera: &Camera) -> Option<Hit> {
    let mut t_in = if camera.ortho {
        f64::NEG_INFINITY
    } else {
        camera.near
    };
    let mut t_out = f64::INFINITY;
    let (mut f_in, mut f_out) = (usize::MAX, usize::MAX);
    for &(n, dist, k) in &p.planes {
        let den = n.dot(d);
        let num = dist - n.dot(o);
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
            continue;
        }
        let t = num / den;
        if den < 0.0 {
            if t > t_in {
                t_in = t;
                f_in = k;
            }
        } else if t < t_out {
            t_out = t;
            f_out = k;
        }
    }
    if t_in >= t_out || t_in.is_nan() || f_out == usize::MAX || !t_in.is_finite() {
        return None;
    }
    let s_out = scalar_on(&p.poly, f_out, o + d * t_out);
    let s_in = if f_in == usize::MAX {
        // Entry at the near plane: the scalar is linear along the ray inside
        // the piece; extrapolate from the exit using the ray's far entry.
        near_scalar(p, o, d, t_in, t_out, s_out)
    } else {
        scalar_on(&p.poly, f_in, o + d * t_in)
    };
    Some(Hit {
        piece: 0,
        t_in,
        t_out,
        s_in,
        s_out,
    })
}

/// Scalar at the near-plane entry `t_near` of a ray that starts inside the
/// piece: interpolated along the ray between the true (behind the eye)
/// entry and the exit.
fn near_scalar(p: &GroupPiece, o: DVec3, d: DVec3, t_near: f64, t_out: f64, s_out: f64) -> f64 {
    let mut t_in = f64::NEG_INFINITY;
    let mut f_in = usize::MAX;
    for &(n, dist, k) in &p.planes {
        let den = n.dot(d);
        if den < 0.0 {
            let t = (dist - n.dot(o)) / den;
            if t > t_in {
                t_in = t;
                f_in = k;
            }
        }
    }
    if f_in == usize::MAX || t_in >= t_out || t_in.is_nan() {
        return s_out;
    }
    let s_in = scalar_on(&p.poly, f_in, o + d * t_in);
    let u = ((t_near - t_in) / (t_out - t_in)).clamp(0.0, 1.0);
    s_in + (s_out - s_in) * u
}

/// The scalar at point `x` of boundary triangle `k` (barycentric, weights
/// clamped to the triangle).
fn scalar_on(poly: &Polyhedron, k: usize, x: DVec3) -> f64 {
    let t = poly.triangles[k];
    let [a, b, c] = t.map(|v| poly.points[v as usize]);
    let [sa, sb, sc] = t.map(|v| poly.scalars[v as usize]);
    let n = (b - a).cross(c - a);
    let nn = n.length_squared();
    if nn == 0.0 {
        return (sa + sb + sc) / 3.0;
    }
    let wa = ((c - b).cross(x - b).dot(n) / nn).max(0.0);
    let wb = ((a - c).cross(x - c).dot(n) / nn).max(0.0);
    let wc = ((b - a).cross(x - a).dot(n) / nn).max(0.0);
    let sum = wa + wb + wc;
    if sum > 0.0 {
        (wa * sa + wb * sb + wc * sc) / sum
    } else {
        (sa + sb + sc) / 3.0
    }
}
