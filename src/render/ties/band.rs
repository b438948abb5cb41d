//! The pixel centres near a segment or inside a triangle, for the tie
//! decisions ([`super`]): lattice searches that return supersets (the
//! decisions test each centre they return), and the float test that
//! settles the centres whose answer rounding cannot change.

use glam::DVec2;

use super::TIE_BAND_PX;
use crate::projection::coverage::Span;

/// Whether pixel position `c` lies in one of the triangles `tris` (of
/// the positions `pos`), where a float test is certain: `Some(true)`
/// when it is farther than `margin` pixels inside one of them,
/// `Some(false)` when it is farther than that outside each of them, `None`
/// otherwise (near an edge: the exact test decides). The triangles tile
/// the part's exact projection up to rounding (triangles inverted by the
/// rounding of a crossing point are left out; the gaps they leave are far
/// narrower than the margin) and coverage culling removed only triangles
/// farther than [`crate::numeric::tolerance::COVERAGE_MARGIN_PX`] from
/// every centre, so the answer is the exact test's.
pub(super) fn inside_by_float(
    tris: &[[u32; 3]],
    pos: &impl Fn(u32) -> DVec2,
    c: DVec2,
    margin: f64,
) -> Option<bool> {
    let mut outside_all = true;
    for t in tris {
        let p = t.map(pos);
        let sign = (p[1] - p[0]).perp_dot(p[2] - p[0]).signum();
        let (mut inside, mut outside) = (true, false);
        for k in 0..3 {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            let d = b - a;
            let e = sign * d.perp_dot(c - a);
            let m = margin * d.length();
            // NaN is neither: not certain.
            if e < -m {
                outside = true;
            }
            if e.is_nan() || e <= m {
                inside = false;
            }
        }
        if inside {
            return Some(true);
        }
        if !outside {
            outside_all = false;
        }
    }
    outside_all.then_some(false)
}

/// Whether `c` is inside triangle `p` (either winding) or within
/// [`TIE_BAND_PX`] of one of its edges.
pub(super) fn in_grown_triangle(p: [DVec2; 3], c: DVec2) -> bool {
    let e = [0, 1, 2].map(|k| (p[(k + 1) % 3] - p[k]).perp_dot(c - p[k]));
    if (e[0] >= 0.0 && e[1] >= 0.0 && e[2] >= 0.0) || (e[0] <= 0.0 && e[1] <= 0.0 && e[2] <= 0.0) {
        return true;
    }
    (0..3).any(|k| dist2_to_segment(p[k], p[(k + 1) % 3], c) <= TIE_BAND_PX * TIE_BAND_PX)
}

/// The screen gradient of the function that is affine on the triangle at
/// pixel positions `p` with values `f` at its corners (infinite or NaN for
/// a triangle of no area).
pub(crate) fn affine_gradient(p: [DVec2; 3], f: [f64; 3]) -> DVec2 {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (d1, d2) = (f[1] - f[0], f[2] - f[0]);
    DVec2::new(d1 * e2.y - d2 * e1.y, d2 * e1.x - d1 * e2.x) / e1.perp_dot(e2)
}

/// The squared distance from `c` to segment `a b` (NaN where an input is).
#[inline]
fn dist2_to_segment(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let d = b - a;
    let l2 = d.length_squared();
    let t = if l2 > 0.0 {
        ((c - a).dot(d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t - c).length_squared()
}

/// Appends the image's pixel centres within [`TIE_BAND_PX`] of segment
/// `a b` whose end points' grown box is `span` (the join of their
/// [`crate::projection::Projected::vertex_spans`], grown by
/// [`crate::numeric::tolerance::COVERAGE_MARGIN_PX`], more than the band,
/// so it holds every such centre), as a superset: the box is walked along
/// the segment's major axis, and in each of its lines the one centre
/// nearest the segment's line is taken when it is within the band (times
/// `sqrt(2)`, the most the distance along the minor axis can exceed the
/// distance to the line). The hot loop of the decisions (millions of
/// outline edges a frame, nearly all with no centre that close). Without
/// spans, [`near_centres`].
#[inline(always)]
pub(super) fn near_edge(
    a: DVec2,
    b: DVec2,
    span: Option<Span>,
    width: u32,
    height: u32,
    out: &mut Vec<(u32, u32)>,
) {
    let Some(s) = span else {
        return near_centres(a, b, width, height, out);
    };
    if s.x0 > s.x1 || s.y0 > s.y1 {
        return;
    }
    let d = b - a;
    let major_x = d.x.abs() >= d.y.abs();
    let (a_m, a_n, d_m, d_n, k0, k1, l0, l1) = if major_x {
        (a.x, a.y, d.x, d.y, s.x0, s.x1, s.y0, s.y1)
    } else {
        (a.y, a.x, d.y, d.x, s.y0, s.y1, s.x0, s.x1)
    };
    // A segment of no length has slope 0: its one point's row.
    let slope = if d_m != 0.0 { d_n / d_m } else { 0.0 };
    let reach = TIE_BAND_PX * std::f64::consts::SQRT_2;
    for k in k0..=k1 {
        // The line's minor coordinate at the centre line k + 1/2, minus
        // 1/2 (centre rows at integers). Rows below 0 (r < -1/2) round
        // towards 0 and fail the reach test or the box.
        let r = a_n + slope * (k as f64 + 0.5 - a_m) - 0.5;
        let l = (r + 0.5) as i32;
        if (r - l as f64).abs() <= reach && l >= l0 && l <= l1 {
            out.push(if major_x {
                (k as u32, l as u32)
            } else {
                (l as u32, k as u32)
            });
        }
    }
}

/// Appends the image's pixel centres within [`TIE_BAND_PX`] of segment `a b`
/// (a superset: the band is walked along the segment's major axis, one
/// candidate row per column): for parts without spans ([`near_edge`]
/// takes the others), so without branches but the loop's.
#[inline]
pub(super) fn near_centres(a: DVec2, b: DVec2, width: u32, height: u32, out: &mut Vec<(u32, u32)>) {
    if !(a.is_finite() && b.is_finite()) {
        return;
    }
    let d = b - a;
    let major_x = d.x.abs() >= d.y.abs();
    let (a_m, b_m, a_n, b_n, n_major, n_minor) = if major_x {
        (a.x, b.x, a.y, b.y, width, height)
    } else {
        (a.y, b.y, a.x, b.x, height, width)
    };
    let (m_lo, m_hi) = (a_m.min(b_m), a_m.max(b_m));
    let k0 = ceil_i(m_lo - TIE_BAND_PX - 0.5).max(0);
    let k1 = floor_i(m_hi + TIE_BAND_PX - 0.5).min(n_major as i64 - 1);
    if k0 > k1 {
        return;
    }
    // Across the major axis, the segment's coordinate at the column
    // (clamped to the segment) is within `reach` of at most one centre row
    // (`reach` < 1/2).
    let reach = TIE_BAND_PX * std::f64::consts::SQRT_2;
    let slope = if b_m != a_m {
        (b_n - a_n) / (b_m - a_m)
    } else {
        0.0
    };
    for k in k0..=k1 {
        let m = (k as f64 + 0.5).clamp(m_lo, m_hi);
        // Minus 1/2: the centre rows at integers.
        let r = a_n + slope * (m - a_m) - 0.5;
        let l = floor_i(r + 0.5);
        let hit = ((r - l as f64).abs() <= reach) & (l >= 0) & (l < n_minor as i64);
        if hit {
            let (i, j) = if major_x { (k, l) } else { (l, k) };
            out.push((i as u32, j as u32));
        }
    }
}

/// Appends the image's pixel centres within `band` pixels of segment `a b`
/// (a superset, as [`near_centres`]).
#[inline(always)]
pub(super) fn centres_within(
    a: DVec2,
    b: DVec2,
    band: f64,
    width: u32,
    height: u32,
    out: &mut Vec<(u32, u32)>,
) {
    let d = b - a;
    if !(a.is_finite() && b.is_finite()) {
        return;
    }
    let (major_x, len) = if d.x.abs() >= d.y.abs() {
        (true, d.x.abs())
    } else {
        (false, d.y.abs())
    };
    // Along the major axis, the centres' coordinates k + 0.5 within the
    // segment's extent grown by the band; across it, the segment's
    // coordinate there (clamped to the segment) +- band * sqrt(2).
    let (a_m, b_m, a_n, b_n, n_major, n_minor) = if major_x {
        (a.x, b.x, a.y, b.y, width, height)
    } else {
        (a.y, b.y, a.x, b.x, height, width)
    };
    let lo = a_m.min(b_m) - band;
    let hi = a_m.max(b_m) + band;
    let k0 = ceil_i(lo - 0.5).max(0);
    let k1 = floor_i(hi - 0.5).min(n_major as i64 - 1);
    let reach = band * std::f64::consts::SQRT_2;
    let inv = if len > 0.0 { 1.0 / (b_m - a_m) } else { 0.0 };
    for k in k0..=k1 {
        let m = k as f64 + 0.5;
        let t = ((m - a_m) * inv).clamp(0.0, 1.0);
        // The one centre row within `reach` (< 1/2) of the segment here,
        // if any.
        let r = a_n + (b_n - a_n) * t - 0.5;
        if reach < 0.5 {
            let l = floor_i(r + 0.5);
            if (r - l as f64).abs() <= reach && l >= 0 && l < n_minor as i64 {
                let (i, j) = if major_x { (k, l) } else { (l, k) };
                out.push((i as u32, j as u32));
            }
        } else {
            let l0 = ceil_i(r - reach).max(0);
            let l1 = floor_i(r + reach).min(n_minor as i64 - 1);
            for l in l0..=l1 {
                let (i, j) = if major_x { (k, l) } else { (l, k) };
                out.push((i as u32, j as u32));
            }
        }
    }
}

/// Keeps, of the centres `out[from..]`, those within `band` pixels of
/// segment `a b` (the searches above return supersets).
pub(super) fn within_band(out: &mut Vec<(u32, u32)>, from: usize, a: DVec2, b: DVec2, band: f64) {
    let mut k = from;
    for n in from..out.len() {
        let (i, j) = out[n];
        let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
        // NaN keeps the centre (decided exactly).
        let dist2 = dist2_to_segment(a, b, c);
        if dist2.is_nan() || dist2 <= band * band {
            out[k] = out[n];
            k += 1;
        }
    }
    out.truncate(k);
}

/// `x.floor()` as an integer (saturating), without the libm call the
/// baseline x86-64 target makes of `floor`, and without a branch.
#[inline]
pub(super) fn floor_i(x: f64) -> i64 {
    let i = x as i64;
    i.saturating_sub(((i as f64) > x) as i64)
}

/// `x.ceil()` as an integer (saturating); see [`floor_i`].
#[inline]
pub(super) fn ceil_i(x: f64) -> i64 {
    let i = x as i64;
    i.saturating_add(((i as f64) < x) as i64)
}
