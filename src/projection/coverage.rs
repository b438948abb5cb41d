//! Pixel-centre coverage: which pieces and triangles can colour a pixel.
//!
//! The rasteriser samples each pixel at its centre only (no multisampling),
//! so a triangle that contains no pixel centre of the image draws nothing:
//! dropping it changes no pixel, and spares its vertex integrals, its upload
//! and the rasteriser's per-triangle setup (on a fine mesh most region
//! triangles are thinner than a pixel: on the hex_shell benchmark 72 % of
//! them contain no centre).
//!
//! The tests are conservative. The GPU does not rasterise our `f64`
//! positions but their `f32` clip coordinates snapped to its sub-pixel grid,
//! so a centre just outside the `f64` triangle may be inside the drawn one;
//! every test therefore grows the triangle by
//! [`COVERAGE_MARGIN_PX`] (see there for the bound it covers). Rounding in
//! the tests themselves (`f64`, ~1e-13 px) is far below that margin.
//!
//! - [`PixelGrid::box_reaches`]: whether the pixel-centre lattice of the
//!   image has a point in a (grown) bounding box; a piece whose projected
//!   points' box has none draws nothing at all.
//! - [`PixelGrid::polygon_reaches`] (convex polygons) and
//!   [`PixelGrid::triangle_reaches`]: the lattice points in the grown box,
//!   each tested against the edge lines moved outwards by the margin
//!   (signed distances, either winding; a degenerate polygon keeps every
//!   centre near its line). Shapes whose box holds more than
//!   [`MAX_CANDIDATES`] centres are kept untested: they are wide enough to
//!   cover one except as long slivers, which cost little to draw.
//! - [`Projected::cull_to_pixels`]: drops the triangles of a projection
//!   that reach no centre ([`crate::projection::Projector::cull_to_pixels`]
//!   runs it; the exact mode turns it on).

use glam::DVec2;

use super::Projected;
use crate::numeric::tolerance::COVERAGE_MARGIN_PX;

/// Beyond this many candidate centres a triangle is kept without testing.
pub const MAX_CANDIDATES: i64 = 16;
/// Polygons with more points are kept without testing.
pub const MAX_POLYGON: usize = 16;

/// The pixel centres `(i + 0.5, j + 0.5)`, `0 <= i < width`,
/// `0 <= j < height`, in continuous pixel coordinates
/// ([`crate::camera::Camera::view_to_pixel`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelGrid {
    pub width: u32,
    pub height: u32,
}

impl PixelGrid {
    /// The grid of a `width` x `height` image.
    pub fn new(width: u32, height: u32) -> PixelGrid {
        PixelGrid { width, height }
    }

    /// The centres a point can reach within the margin, per axis: indices
    /// `i` of the centres `i + 0.5` in `[x - m, x + m]` (`m` the margin)
    /// as `[i_lo, i_hi]` (empty when `i_lo > i_hi`), clamped to the image
    /// (`i_lo <= n`, `i_hi >= -1`), and the same for `y`. A polygon's span
    /// is the smallest `lo` and the largest `hi` of its points' spans
    /// (rounding and `ceil`/`floor` are monotone, so this is exactly the
    /// span of its grown bounding box). A NaN coordinate reaches nothing.
    #[inline]
    pub fn span(&self, p: DVec2) -> Span {
        #[inline(always)]
        fn axis(x: f64, n: u32) -> [i32; 2] {
            if x.is_nan() {
                return [n as i32, -1]; // reaches nothing
            }
            let top = n as f64;
            // Clamped first: positions may be ~1e9 pixels away.
            let a = (x - COVERAGE_MARGIN_PX - 0.5).clamp(-1.0, top);
            let b = (x + COVERAGE_MARGIN_PX - 0.5).clamp(-1.0, top - 1.0);
            // ceil(a) and floor(b) by truncation (`f64::ceil` and
            // `f64::floor` are library calls on baseline x86-64).
            let ia = a as i32;
            let ia = ia + ((ia as f64) < a) as i32;
            let ib = b as i32;
            let ib = ib - ((ib as f64) > b) as i32;
            [ia.max(0), ib]
        }
        let [x0, x1] = axis(p.x, self.width);
        let [y0, y1] = axis(p.y, self.height);
        Span { x0, x1, y0, y1 }
    }

    /// Whether a pixel centre lies in the box `[min, max]` grown by the
    /// margin.
    pub fn box_reaches(&self, min: DVec2, max: DVec2) -> bool {
        let s = self.span(min).join(&self.span(max));
        s.x0 <= s.x1 && s.y0 <= s.y1
    }

    /// Whether a pixel centre lies in triangle `a, b, c` (either winding)
    /// grown by the margin (see module docs).
    #[inline]
    pub fn triangle_reaches(&self, a: DVec2, b: DVec2, c: DVec2) -> bool {
        let s = self.span(a).join(&self.span(b)).join(&self.span(c));
        Self::centres_reach(&[a, b, c], s)
    }

    /// Whether a pixel centre lies in the convex polygon of `n` points
    /// `at(0..n)` (either winding) grown by the margin (see module docs).
    /// Polygons of more than [`MAX_POLYGON`] points are kept untested.
    pub fn polygon_reaches(&self, n: usize, at: impl Fn(usize) -> DVec2) -> bool {
        if n == 0 {
            return false;
        }
        if n > MAX_POLYGON {
            return true;
        }
        let mut p = [DVec2::ZERO; MAX_POLYGON];
        let mut s = self.span(at(0));
        for (k, q) in p.iter_mut().enumerate().take(n) {
            *q = at(k);
            s = s.join(&self.span(*q));
        }
        Self::centres_reach(&p[..n], s)
    }

    /// Whether a centre of span `s` (the polygon's) lies in the convex
    /// polygon `p` grown by the margin; polygons whose span holds more than
    /// [`MAX_CANDIDATES`] centres are kept untested. Inlined into
    /// [`Self::triangle_reaches`] and [`Projected::cull_to_pixels`], where
    /// the three points' loops unroll.
    #[inline(always)]
    fn centres_reach(p: &[DVec2], s: Span) -> bool {
        if s.x0 > s.x1 || s.y0 > s.y1 {
            return false;
        }
        let count = (s.x1 - s.x0 + 1) as i64 * (s.y1 - s.y0 + 1) as i64;
        if count > MAX_CANDIDATES {
            return true;
        }
        let n = p.len();
        // Edge k from p[k] to p[k + 1]: the signed distance of q to its line
        // is cross(d, q - p) / |d| (positive on the left); compared squared,
        // `e < -m |d|` is `e < 0 && e^2 > m^2 |d|^2`.
        let m2 = COVERAGE_MARGIN_PX * COVERAGE_MARGIN_PX;
        for j in s.y0..=s.y1 {
            let y = j as f64 + 0.5;
            for i in s.x0..=s.x1 {
                let q = DVec2::new(i as f64 + 0.5, y);
                let (mut left, mut right) = (true, true);
                for k in 0..n {
                    let pk = p[k];
                    let d = p[if k + 1 == n { 0 } else { k + 1 }] - pk;
                    let e = d.perp_dot(q - pk);
                    let far = e * e > m2 * d.length_squared();
                    left &= !(e < 0.0 && far);
                    right &= !(e > 0.0 && far);
                }
                if left || right {
                    return true;
                }
            }
        }
        false
    }
}

/// The pixel centres a point or polygon can reach ([`PixelGrid::span`]):
/// column indices `x0..=x1`, row indices `y0..=y1`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Span {
    pub x0: i32,
    pub x1: i32,
    pub y0: i32,
    pub y1: i32,
}

impl Span {
    /// The span of the union.
    #[inline(always)]
    pub fn join(&self, o: &Span) -> Span {
        Span {
            x0: self.x0.min(o.x0),
            x1: self.x1.max(o.x1),
            y0: self.y0.min(o.y0),
            y1: self.y1.max(o.y1),
        }
    }
}

impl Projected {
    /// Drops the triangles that contain no pixel centre of `grid`
    /// ([`PixelGrid::triangle_reaches`]; each vertex's span is computed
    /// once); vertices and regions stay (a vertex may now be used by no
    /// triangle). Returns how many were dropped.
    pub fn cull_to_pixels(&mut self, grid: &PixelGrid) -> usize {
        let mut spans = std::mem::take(&mut self.spans);
        spans.clear();
        spans.extend(self.vertices.iter().map(|v| grid.span(v.pos())));
        let before = self.triangles.len();
        self.culled.clear();
        let mut w = 0;
        for r in 0..before {
            let t = self.triangles[r];
            let [a, b, c] = t.map(|i| spans[i as usize]);
            let s = a.join(&b).join(&c);
            if s.x0 <= s.x1
                && s.y0 <= s.y1
                && PixelGrid::centres_reach(&t.map(|i| self.vertices[i as usize].pos()), s)
            {
                self.triangles[w] = t;
                self.triangle_region[w] = self.triangle_region[r];
                w += 1;
            } else {
                self.culled.push(t);
            }
        }
        self.triangles.truncate(w);
        self.triangle_region.truncate(w);
        self.spans = spans;
        before - w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testdata::Rng;

    /// Brute force: whether a pixel centre of the image lies within
    /// `margin` of the closed triangle (true Euclidean distance).
    fn brute(grid: &PixelGrid, p: [DVec2; 3], margin: f64) -> bool {
        let seg = |q: DVec2, a: DVec2, b: DVec2| {
            let d = b - a;
            let t = if d.length_squared() > 0.0 {
                ((q - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (q - (a + d * t)).length()
        };
        for j in 0..grid.height {
            for i in 0..grid.width {
                let q = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                let e: Vec<f64> = (0..3)
                    .map(|k| (p[(k + 1) % 3] - p[k]).perp_dot(q - p[k]))
                    .collect();
                let inside = e.iter().all(|&e| e >= 0.0) || e.iter().all(|&e| e <= 0.0);
                let dist = (0..3)
                    .map(|k| seg(q, p[k], p[(k + 1) % 3]))
                    .fold(f64::INFINITY, f64::min);
                if inside || dist <= margin {
                    return true;
                }
            }
        }
        false
    }

    #[test]
    fn small_triangles_agree_with_brute_force() {
        let grid = PixelGrid::new(12, 9);
        let mut rng = Rng(7);
        let (mut kept, mut dropped, mut spared) = (0, 0, 0);
        for _ in 0..20000 {
            // Sub-pixel to few-pixel triangles, some reaching off the image.
            let o = DVec2::new(rng.f64() * 14.0 - 1.0, rng.f64() * 11.0 - 1.0);
            let s = 0.05 + 2.0 * rng.f64() * rng.f64();
            let p = [
                o,
                o + DVec2::new(rng.f64(), rng.f64()) * s,
                o + DVec2::new(rng.f64(), rng.f64()) * s,
            ];
            let fast = grid.triangle_reaches(p[0], p[1], p[2]);
            // Never drops a triangle that reaches a centre with the margin.
            if brute(&grid, p, COVERAGE_MARGIN_PX) {
                assert!(fast, "{p:?} reaches a centre but was dropped");
                kept += 1;
            } else if fast {
                // Kept though it misses: a centre in the grown box and
                // within the margin of all three edge lines (past an acute
                // corner), or too many candidates. Must stay rare.
                spared += 1;
            } else {
                dropped += 1;
            }
        }
        assert!(
            spared * 50 < dropped,
            "{spared} kept needlessly against {dropped} dropped"
        );
        // Both outcomes are exercised.
        assert!(
            kept > 1000 && dropped > 1000,
            "{kept} kept, {dropped} dropped"
        );
    }

    /// A convex polygon reaches a centre exactly when one of its fan
    /// triangles does (same margin tests on the shared outer edges).
    #[test]
    fn polygons_agree_with_their_fans() {
        let grid = PixelGrid::new(10, 10);
        let mut rng = Rng(3);
        let (mut yes, mut no) = (0, 0);
        for _ in 0..20000 {
            // A convex polygon: points on an ellipse at sorted angles.
            let c = DVec2::new(rng.f64() * 12.0 - 1.0, rng.f64() * 12.0 - 1.0);
            let (rx, ry) = (0.05 + rng.f64() * 1.5, 0.05 + rng.f64() * 1.5);
            let n = 3 + (rng.f64() * 6.0) as usize;
            let mut ang: Vec<f64> = (0..n).map(|_| rng.f64() * std::f64::consts::TAU).collect();
            ang.sort_by(f64::total_cmp);
            let p: Vec<DVec2> = ang
                .iter()
                .map(|a| c + DVec2::new(rx * a.cos(), ry * a.sin()))
                .collect();
            let whole = grid.polygon_reaches(n, |k| p[k]);
            let fan = (1..n - 1).any(|k| brute(&grid, [p[0], p[k], p[k + 1]], COVERAGE_MARGIN_PX));
            // Never drops a polygon whose area (grown) holds a centre.
            if fan {
                assert!(whole, "{p:?}");
                yes += 1;
            } else {
                no += !whole as usize;
            }
        }
        assert!(yes > 1000 && no > 1000, "{yes} {no}");
    }

    /// The integer spans agree with the centres counted directly in the
    /// grown box, including boxes on the margin's edges, off the image and
    /// ~1e9 pixels away.
    #[test]
    fn spans_count_the_centres_of_the_grown_box() {
        let grid = PixelGrid::new(7, 5);
        let m = COVERAGE_MARGIN_PX;
        let direct = |lo: f64, hi: f64, n: u32| -> usize {
            (0..n)
                .filter(|&i| {
                    let c = i as f64 + 0.5;
                    c >= lo - m && c <= hi + m
                })
                .count()
        };
        let mut rng = Rng(5);
        let pick = |rng: &mut Rng| match rng.below(5) {
            0 => rng.range(-3.0, 10.0),
            1 => (rng.below(12) as f64 - 2.0) + 0.5 + m * [-1.0, 1.0][rng.below(2)],
            2 => (rng.below(12) as f64 - 2.0) + 0.5 + m * [-1.0, 1.0][rng.below(2)] * (1.0 + 1e-9),
            3 => rng.range(-1e9, 1e9),
            _ => (rng.below(12) as f64 - 2.0) + 0.5,
        };
        for _ in 0..20000 {
            let (a, b) = (pick(&mut rng), pick(&mut rng));
            let (c, d) = (pick(&mut rng), pick(&mut rng));
            let (lo, hi) = (
                DVec2::new(a.min(b), c.min(d)),
                DVec2::new(a.max(b), c.max(d)),
            );
            let s = grid.span(lo).join(&grid.span(hi));
            let nx = (s.x1 - s.x0 + 1).max(0) as usize;
            let ny = (s.y1 - s.y0 + 1).max(0) as usize;
            assert_eq!(nx, direct(lo.x, hi.x, 7), "{lo} {hi}");
            assert_eq!(ny, direct(lo.y, hi.y, 5), "{lo} {hi}");
            assert_eq!(grid.box_reaches(lo, hi), nx * ny > 0);
        }
    }

    #[test]
    fn centres_on_edges_and_degenerate_triangles_are_kept() {
        let grid = PixelGrid::new(4, 4);
        let c = DVec2::new(1.5, 1.5);
        // A centre exactly on an edge, on a vertex, and a segment through it.
        assert!(grid.triangle_reaches(c, DVec2::new(2.5, 1.5), DVec2::new(2.0, 1.0)));
        assert!(grid.triangle_reaches(c, DVec2::new(1.9, 1.9), DVec2::new(1.9, 1.6)));
        assert!(grid.triangle_reaches(DVec2::new(1.0, 1.0), DVec2::new(2.0, 2.0), c));
        // Just inside the margin, and just outside it.
        let e = COVERAGE_MARGIN_PX;
        let tri = |dx: f64| {
            let a = DVec2::new(1.5 + dx, 1.0);
            grid.triangle_reaches(a, DVec2::new(1.5 + dx, 2.0), DVec2::new(1.9, 1.5))
        };
        assert!(tri(0.5 * e));
        assert!(!tri(1.5 * e));
        // Off the image: pixel centres outside 0..W do not count.
        assert!(!grid.triangle_reaches(
            DVec2::new(-3.0, 0.0),
            DVec2::new(-0.6, 3.0),
            DVec2::new(-0.6, 0.0)
        ));
        assert!(!grid.box_reaches(DVec2::new(4.1, 0.0), DVec2::new(9.0, 9.0)));
        assert!(grid.box_reaches(DVec2::new(3.45, 0.0), DVec2::new(9.0, 9.0)));
        // NaN reaches nothing rather than panicking.
        assert!(!grid.box_reaches(DVec2::NAN, DVec2::NAN));
    }
}
