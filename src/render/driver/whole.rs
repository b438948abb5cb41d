//! Parts drawn whole ([`ProjectedMode::whole_part`](super::ProjectedMode)):
//! the screen polygon that carries a part's one vertex payload to every
//! pixel centre its outline may hold.
//!
//! The outline of a convex part whose points all lie in front of the eye is
//! the convex hull of its projected points. The part is drawn as that hull
//! pushed out by [`QUAD_HULL_MARGIN_PX`] (each edge moved outward along its
//! normal, corners mitred, or bevelled where they are sharp), as a fan of
//! triangles from its first corner; the stage discards the fragments whose
//! ray misses the part, so the polygon only has to hold every centre the
//! part's own (`f32`) test may take. Against the pixel bounding box the
//! earlier quads used, the hull leaves out the box's corners and the ring of
//! partial pixels around it: a piece a few pixels wide shades about half the
//! fragments.
//!
//! Corners are snapped to the rasteriser's sub-pixel grid
//! ([`ClipMapper::ndc`]) and the snapped polygon must stay strictly convex
//! (exact integer turns): then the fan's triangles share their edges
//! exactly and the rasteriser's tie rule gives a centre on a diagonal to one
//! of them, so every centre is shaded once. Where it does not (a hull too
//! thin for its margin), where the hull reaches past the image, or where
//! the points do not make a polygon, the part is drawn as the quad over its
//! pixel bounding box (widened by
//! [`crate::numeric::tolerance::COVERAGE_MARGIN_PX`], corners on whole
//! pixels, so no centre is near its edges).

use glam::DVec2;

use crate::camera::Camera;
use crate::gpu::{ClipMapper, GpuVertex};
use crate::numeric::tolerance::{COVERAGE_MARGIN_PX, QUAD_HULL_MARGIN_PX};
use crate::projection::Polyhedron;

use super::ChunkOut;

/// Most corners of a drawn hull: the hull of [`crate::render::modes::piece_quad::MAX_POINTS`]
/// points, each corner possibly bevelled into two.
const MAX_CORNERS: usize = 2 * 8;

/// Smallest pixel bounding box (in pixels) drawn as its hull: below it
/// the box's two triangles cost a rasteriser less than the hull's more
/// corners save (lavapipe, 2026-12-06: on the 1M-hex grid, whose pieces are
/// a few pixels, hulls for every piece made the frame 8-10 % slower).
const HULL_MIN_BOX_PX: f64 = 36.0;

/// A hull is drawn only where it covers at most this share of the box.
const HULL_MAX_BOX_SHARE: f64 = 0.6;

/// The area of a convex polygon wound with positive area.
fn area(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f64>()
        / 2.0
}

/// Draws `part` whole as one piece, every corner of its polygon carrying
/// `v` (module docs). A part whose outline holds no pixel centre of the
/// image is culled.
pub(super) fn draw_whole<V: GpuVertex>(
    camera: &Camera,
    part: &Polyhedron,
    v: V,
    out: &mut ChunkOut<V>,
) {
    let extent = camera.half_extent();
    // The projected points (the first MAX_CORNERS of them kept for the
    // hull; a part with more is drawn as its box) and their bounds.
    let mut pts = [DVec2::ZERO; MAX_CORNERS];
    let n = part.points.len();
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for (i, p) in part.points.iter().enumerate() {
        let Some((px, py, _)) = camera.view_to_pixel_with(*p, extent) else {
            out.culled += 1;
            return;
        };
        let q = DVec2::new(px, py);
        (lo, hi) = (lo.min(q), hi.max(q));
        if let Some(slot) = pts.get_mut(i) {
            *slot = q;
        }
    }
    let mapper = ClipMapper::for_camera(camera);
    let size = DVec2::new(camera.width as f64, camera.height as f64);
    let lo = (lo - COVERAGE_MARGIN_PX).floor().max(DVec2::ZERO);
    let hi = (hi + COVERAGE_MARGIN_PX).ceil().min(size);
    let box_area = (hi - lo).x * (hi - lo).y;
    let mut corners = [DVec2::ZERO; MAX_CORNERS];
    let drawn = if box_area >= HULL_MIN_BOX_PX && n <= MAX_CORNERS {
        let hull = convex_hull(&mut pts[..n]);
        widened(&pts[..hull], QUAD_HULL_MARGIN_PX, &mut corners)
            .filter(|&k| {
                let poly = &corners[..k];
                poly.iter()
                    .all(|c| c.x >= 0.0 && c.y >= 0.0 && c.x <= size.x && c.y <= size.y)
                    && area(poly) <= HULL_MAX_BOX_SHARE * box_area
            })
            .and_then(|k| snapped_convex(&mapper, &corners[..k]).map(|g| (k, g)))
    } else {
        None
    };
    // The polygon's corners in NDC: the hull's, or the box's (on whole
    // pixels), drawn as one fan either way.
    let (k, ndc) = match drawn {
        Some(hull) => {
            out.hulls += 1;
            hull
        }
        None => {
            if !(hi.x > lo.x && hi.y > lo.y) {
                out.culled += 1;
                return;
            }
            let mut ndc = [[0.0f32; 2]; MAX_CORNERS];
            let corners = [(lo.x, lo.y), (hi.x, lo.y), (hi.x, hi.y), (lo.x, hi.y)];
            for ((x, y), c) in corners.into_iter().zip(ndc.iter_mut()) {
                let Some((n, _)) = mapper.ndc(x, y) else {
                    out.culled += 1;
                    return;
                };
                *c = n;
            }
            (4, ndc)
        }
    };
    let base = out.vertices.len() as u32;
    for c in &ndc[..k] {
        out.vertices
            .push(v.with_clip([c[0], c[1], 0.5, 1.0]).with_piece(out.pieces));
    }
    for i in 1..k as u32 - 1 {
        out.indices
            .extend_from_slice(&[base, base + i, base + i + 1]);
    }
    out.pieces += 1;
    out.whole += 1;
}

/// Sorts `pts` into their convex hull's corners, wound with positive area
/// in pixel coordinates (y down, as the region triangles), collinear points
/// left out (Andrew's monotone chain); returns the number of corners (fewer
/// than 3 for points on a line). The rest of `pts` is left in any order.
pub(super) fn convex_hull(pts: &mut [DVec2]) -> usize {
    let n = pts.len();
    if n < 3 {
        return 0;
    }
    pts.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull = [DVec2::ZERO; 2 * MAX_CORNERS];
    let mut k = 0;
    let mut keep = |p: DVec2, k: &mut usize, floor: usize| {
        while *k >= floor && turn(hull[*k - 2], hull[*k - 1], p) <= 0.0 {
            *k -= 1;
        }
        hull[*k] = p;
        *k += 1;
    };
    // Lower chain, then the upper chain, which ends where the lower began.
    for &p in pts.iter() {
        keep(p, &mut k, 2);
    }
    let floor = k + 1;
    for i in (0..n - 1).rev() {
        keep(pts[i], &mut k, floor);
    }
    // The chain ends where it started.
    let corners = k.saturating_sub(1);
    if corners < 3 || corners > pts.len() {
        return 0;
    }
    pts[..corners].copy_from_slice(&hull[..corners]);
    corners
}

/// The convex polygon `hull` (positive area, pixel coordinates) pushed
/// outward by `margin`: every edge moved along its outward normal, each
/// corner the meeting point of its two moved edges (a mitre), or, where the
/// corner is sharp enough that the mitre would reach past `sqrt(2) *
/// margin`, two corners cut by the tangent across the bisector (a bevel).
/// Holds every point within `margin` of `hull`. Writes the corners into
/// `out` and returns their number; `None` for fewer than 3 corners or too
/// many.
pub(super) fn widened(hull: &[DVec2], margin: f64, out: &mut [DVec2]) -> Option<usize> {
    let n = hull.len();
    if n < 3 {
        return None;
    }
    // Outward normal of edge i (from corner i to corner i + 1): the
    // interior lies to the left of a positive-area winding.
    let normal = |i: usize| {
        let e = hull[(i + 1) % n] - hull[i];
        DVec2::new(e.y, -e.x).normalize()
    };
    let mut k = 0;
    let mut push = |p: DVec2, k: &mut usize| -> Option<()> {
        *out.get_mut(*k)? = p;
        *k += 1;
        Some(())
    };
    for (i, &p) in hull.iter().enumerate() {
        let (a, b) = (normal((i + n - 1) % n), normal(i));
        if !(a.is_finite() && b.is_finite()) {
            return None;
        }
        let c = a.dot(b);
        if c >= 0.0 {
            // Turn of at most 90 degrees: the mitre is at most sqrt(2)
            // margins from the corner.
            push(p + margin * (a + b) / (1.0 + c), &mut k)?;
        } else {
            let m = (a + b).normalize();
            if !m.is_finite() {
                return None;
            }
            push(p + margin * (a + m) / (1.0 + a.dot(m)), &mut k)?;
            push(p + margin * (m + b) / (1.0 + m.dot(b)), &mut k)?;
        }
    }
    Some(k)
}

/// The NDC corners of `poly` snapped to the sub-pixel grid, or `None` where
/// the snapped polygon is not strictly convex with positive area (exact
/// integer turns at every corner) or a corner cannot be mapped.
fn snapped_convex(mapper: &ClipMapper, poly: &[DVec2]) -> Option<[[f32; 2]; MAX_CORNERS]> {
    let mut ndc = [[0.0f32; 2]; MAX_CORNERS];
    let mut grid = [[0i128; 2]; MAX_CORNERS];
    for (i, p) in poly.iter().enumerate() {
        let (c, g) = mapper.ndc(p.x, p.y)?;
        ndc[i] = c;
        grid[i] = [g[0] as i128, g[1] as i128];
    }
    let n = poly.len();
    for i in 0..n {
        let [o, a, b] = [grid[i], grid[(i + 1) % n], grid[(i + 2) % n]];
        // Below 2^40 grid units: exact in i128.
        if (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) <= 0 {
            return None;
        }
    }
    Some(ndc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hull_of_a_square_with_inner_points_is_its_corners() {
        let mut pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(0.0, 2.0),
            DVec2::new(1.0, 0.0),
        ];
        let k = convex_hull(&mut pts);
        assert_eq!(k, 4);
        let area: f64 = (0..k).map(|i| pts[i].perp_dot(pts[(i + 1) % k])).sum();
        assert!(area > 0.0, "positive winding: {area}");
        for c in [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)] {
            assert!(pts[..k].contains(&DVec2::new(c.0, c.1)), "{c:?}");
        }
    }

    #[test]
    fn points_on_a_line_make_no_hull() {
        let mut pts = [0.0, 1.0, 2.0, 3.0].map(|t| DVec2::new(t, 2.0 * t));
        assert_eq!(convex_hull(&mut pts), 0);
    }

    /// Distance from `p` to the convex polygon `poly` (0 inside).
    fn outside(poly: &[DVec2], p: DVec2) -> f64 {
        let n = poly.len();
        let mut worst: f64 = 0.0;
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let e = b - a;
            let out = (p - a).perp_dot(e) / e.length();
            worst = worst.max(out);
        }
        worst
    }

    #[test]
    fn the_widened_hull_holds_every_point_within_the_margin_and_little_more() {
        // A sharp triangle (bevelled corner) and a hexagon (mitres).
        let shapes: [&[DVec2]; 2] = [
            &[
                DVec2::new(0.0, 0.0),
                DVec2::new(10.0, 0.3),
                DVec2::new(0.0, 0.6),
            ],
            &[
                DVec2::new(1.0, 0.0),
                DVec2::new(3.0, 0.0),
                DVec2::new(4.0, 1.5),
                DVec2::new(3.0, 3.0),
                DVec2::new(1.0, 3.0),
                DVec2::new(0.0, 1.5),
            ],
        ];
        let margin = 0.05;
        for shape in shapes {
            let mut pts = shape.to_vec();
            let k = convex_hull(&mut pts);
            let mut out = [DVec2::ZERO; MAX_CORNERS];
            let m = widened(&pts[..k], margin, &mut out).expect("widened");
            let poly = &out[..m];
            // Every point at distance `margin` from a corner or an edge.
            for i in 0..k {
                let (a, b) = (pts[i], pts[(i + 1) % k]);
                for s in 0..=16 {
                    let p = a + (b - a) * (s as f64 / 16.0);
                    for t in 0..64 {
                        let ang = t as f64 * std::f64::consts::TAU / 64.0;
                        let q = p + margin * DVec2::new(ang.cos(), ang.sin());
                        assert!(outside(poly, q) <= 1e-12, "{q} outside {poly:?}");
                    }
                }
            }
            // No corner further than sqrt(2) margins from the hull.
            for c in poly {
                let d = outside(&pts[..k], *c);
                assert!(d <= margin * 2f64.sqrt() + 1e-12, "{c}: {d}");
            }
        }
    }
}
