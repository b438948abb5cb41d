//! The one pass over a part's exact triangles for what the snap of their
//! corners can do ([`scan_triangles`], see the module docs of
//! [`super`]): the wide triangles drawn **steep** (the exact triangle's
//! values at their snapped corners), where the snap could shift the
//! optical depth at a centre or, in the isosurface modes, carry an entry
//! or exit scalar across an isovalue; and the centres inside **slivers**
//! that the tie decisions take exactly.

use glam::DVec2;

use super::band::{affine_gradient, ceil_i, centres_within, floor_i, in_grown_triangle};
use super::{
    iso_margin, snap_is_steep_at, PartTriangles, TieScratch, SLIVER_DEPTH_TOL, SLIVER_TIE_PX,
    SNAP_PX, TIE_BAND_PX,
};

/// One pass over the part's exact triangles for what the snap of their
/// corners can do: marks the [`snap_is_steep`] ones (`scratch.steep[k]`
/// for `part.exact[k]`), and with `slivers` (the tie decisions, which
/// read them) collects the centres inside (or within the band of) the
/// sliver triangles where the snap could move the thickness by more than
/// [`SLIVER_DEPTH_TOL`] over the rate. One pass serves both: the same
/// widths and thickness changes decide them.
pub fn scan_triangles(part: &PartTriangles, slivers: bool, scratch: &mut TieScratch) {
    let pos = |i: u32| part.proj.vertices[i as usize].pos();
    let (out, near, steep) = (&mut scratch.forced, &mut scratch.near, &mut scratch.steep);
    out.clear();
    steep.clear();
    steep.resize(part.exact.len(), false);
    // A triangle's thickness changes by at most the part's, so the bound
    // on the rate and the part's thickness range bound the width below
    // which the snap can matter in a sliver, and whether a wider
    // triangle can be steep; most parts of a fine mesh (thin, or
    // optically thin) have neither.
    let (l_lo, l_hi) = part.l_range;
    let reach = part.rate_bound * (l_hi - l_lo) * SNAP_PX / SLIVER_DEPTH_TOL;
    // NaN stays NaN: no triangle is narrower.
    let widest = if !slivers {
        0.0
    } else if part.isovalues.is_empty() {
        reach.clamp(0.0, SLIVER_TIE_PX)
    } else {
        SLIVER_TIE_PX
    };
    // False for NaN too. With isovalues any wide triangle whose scalars
    // reach one may be steep (below).
    let may_be_steep = reach > SLIVER_TIE_PX || !part.isovalues.is_empty();
    if !(widest > 0.0 || may_be_steep) {
        return;
    }
    // Every exact triangle, also those whose snapped corners collapse (a
    // sliver a few thousandths of a pixel wide on the steep side of a face
    // seen nearly edge-on, dropped as flat on the grid, whose centres the
    // neighbouring triangle then takes with its own, far different,
    // values).
    for (n, t) in part.exact.iter().enumerate() {
        let p = t.map(pos);
        // Cheap tests first: narrow or wide (twice the area against the
        // longest edge, squared), then what the snap can do to the optical
        // depth or colour there (the rate times the thickness's change
        // across the triangle times the snap over the width), with the
        // bound on the rate, then the part's own rate.
        let area2 = (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
        let d2 = [0, 1, 2].map(|k| (p[(k + 1) % 3] - p[k]).length_squared());
        let longest = d2[0].max(d2[1]).max(d2[2]);
        let narrow = area2 * area2 < widest * widest * longest;
        let wide = may_be_steep && area2 * area2 >= SLIVER_TIE_PX * SLIVER_TIE_PX * longest;
        if !(longest > 0.0 && (narrow || wide)) {
            continue;
        }
        let l = t.map(|i| part.proj.vertices[i as usize].l);
        let long = longest.sqrt();
        if wide {
            // Steep for the optical depth, or (isosurface modes) holding
            // an isovalue within the snap's shift of its entry or exit
            // scalars (and the f32 stages' rounding): the snapped corners'
            // interpolation could put a centre on the other side of the
            // value than the exact triangle and the piece beside it do (a
            // surface missed or drawn twice where the volume's rate is
            // small or zero); exact values at the snapped corners keep
            // every centre's.
            steep[n] = (snap_is_steep_at(area2, long, l, part.rate_bound)
                && snap_is_steep_at(area2, long, l, (part.rate)()))
                || (!part.isovalues.is_empty()
                    && isovalue_shift(part, t, part.snap_of(t), area2 / long, true)
                        .is_some_and(|shift| iso_centre_near(part, t, p, shift)));
            continue;
        }
        let dl = l[0].max(l[1]).max(l[2]) - l[0].min(l[1]).min(l[2]);
        let w = area2 / long;
        // How far the snap moved this triangle's corners (at most
        // SNAP_PX): what shifts its interpolated values.
        let snap = part.snap_of(t);
        // False for NaN too.
        let matters = |r: f64| r * dl * snap > SLIVER_DEPTH_TOL * w;
        // With isovalues: the snap's shift of the entry and exit scalars
        // across this sliver, where its corners bracket one (with that
        // shift); 0 otherwise (NaN too).
        let iso_shift = if part.isovalues.is_empty() {
            0.0
        } else {
            isovalue_shift(part, t, snap, w, false).unwrap_or(0.0)
        };
        let narrow_for_depth = w < reach.min(SLIVER_TIE_PX);
        // False for NaN too.
        let iso = iso_shift > 0.0;
        if !iso && (!narrow_for_depth || !matters(part.rate_bound) || !matters((part.rate)())) {
            continue;
        }
        let k = if d2[0] == longest {
            0
        } else if d2[1] == longest {
            1
        } else {
            2
        };
        let (a, b) = (p[k], p[(k + 1) % 3]);
        near.clear();
        centres_within(a, b, w + TIE_BAND_PX, part.width, part.height, near);
        // Only the centres in the exact sliver grown by the band (which
        // holds every centre its snapped triangle can cover): coverage
        // culling keeps every triangle within COVERAGE_MARGIN_PX (1/64 px)
        // of a centre, so it drops no sliver that has such a centre, and
        // changes no decision.
        let depth = narrow_for_depth && matters(part.rate_bound) && matters((part.rate)());
        // Where only an isovalue matters: the centres whose exact scalars
        // (perspective-correct, as the GPU interpolates them) are within
        // the shift (and the f32 stages' rounding) of one.
        let sides = [0, 1].map(|side| side_corners(part, t, side));
        out.extend(near.iter().copied().filter(|&(i, j)| {
            let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
            if !in_grown_triangle(p, c) {
                return false;
            }
            if depth {
                return true;
            }
            let b = centre_weights(p, (p[1] - p[0]).perp_dot(p[2] - p[0]), c);
            sides.iter().any(|(s, q)| {
                let s = at_centre(b, s, q);
                let margin = iso_shift + iso_margin(part.iso_origin, s, s);
                // Not for NaN.
                to_nearest(part.isovalues, s) <= margin
            })
        }));
    }
}

/// The snap's largest shift of the entry or exit scalars of the exact
/// triangle `t` (width `w` pixels, corners moved by at most `snap`: of
/// their spread, `snap` over the width) where their range, grown by that
/// shift (and with `rounding` by the stage's [`iso_margin`]), holds one
/// of `part.isovalues`; `None` where neither does (or a value is NaN).
/// The slivers' rule and the wide triangles' steep rule in
/// [`scan_triangles`].
fn isovalue_shift(
    part: &PartTriangles,
    t: &[u32; 3],
    snap: f64,
    w: f64,
    rounding: bool,
) -> Option<f64> {
    let v = t.map(|i| &part.proj.vertices[i as usize]);
    let side = |s: [f64; 3]| {
        let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
        let shift = (hi - lo) * snap / w;
        let grow = if rounding {
            shift + iso_margin(part.iso_origin, lo, hi)
        } else {
            shift
        };
        let k = part.isovalues.partition_point(|&x| x < lo - grow);
        // False for NaN too.
        part.isovalues
            .get(k)
            .is_some_and(|&x| x <= hi + grow)
            .then_some(shift)
    };
    match (side(v.map(|v| v.s_front)), side(v.map(|v| v.s_back))) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

/// The most centres [`iso_centre_near`] looks at in one triangle; a larger
/// triangle is drawn steep without looking (three vertices of its own cost
/// less than the search).
const ISO_STEEP_CENTRES: i64 = 64;

/// Whether a pixel centre in the wide exact triangle `t` at `p` (grown by
/// [`TIE_BAND_PX`]) has an exact entry or exit scalar within `shift` (the
/// snap's, from [`isovalue_shift`]) and the stage's [`iso_margin`] of the
/// corner scalars of one of `part.isovalues`: only
/// such a centre can fall on the other side of a value than the exact
/// triangle puts it, so only then is the triangle drawn steep (with a
/// dense set of isovalues nearly every triangle holds one, but a value's
/// line meets a centre within the margin rarely). The scalars at a centre
/// are the exact corners' interpolated as the GPU interpolates them
/// (perspective-correct). True for a triangle holding more than
/// [`ISO_STEEP_CENTRES`] centres' box, or one that is degenerate.
fn iso_centre_near(part: &PartTriangles, t: &[u32; 3], p: [DVec2; 3], shift: f64) -> bool {
    // Per side: the corner scalars, their weights' factors and the margin.
    let sides = [0, 1].map(|side| {
        let (s, q) = side_corners(part, t, side);
        let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
        (s, q, shift + iso_margin(part.iso_origin, lo, hi))
    });
    centre_near_values(p, &sides, part.isovalues, part.width, part.height)
}

/// One side of a triangle for [`centre_near_values`]: the corner scalars,
/// their perspective weight factors (`q = 1/z`, [`side_corners`]) and the
/// margin.
type Side = ([f64; 3], [f64; 3], f64);

/// The box of pixel centres `(i0, i1, j0, j1)` (inclusive) around a
/// triangle grown by [`TIE_BAND_PX`].
type CentreBox = (i64, i64, i64, i64);

/// Whether a pixel centre of the `width` x `height` image inside the
/// triangle at `p` grown by [`TIE_BAND_PX`] has, on one of the `sides`,
/// its scalar ([`at_centre`]) within that side's margin of one of the
/// sorted `values` (NaN counts as near): the test of [`iso_centre_near`].
/// True for a degenerate triangle or one whose box holds more than
/// [`ISO_STEEP_CENTRES`] centres.
///
/// The centres that can be near a value lie in a thin strip along the
/// value's line across the triangle, so the search walks those strips
/// ([`near_strips`]) and tests only the centres in them, each with the
/// box search's own test; where it cannot bound the strips (a non-finite
/// input, a steep perspective, more strip rows than centres) it tests
/// every centre of the box ([`centre_near_values_box`]). Both give the
/// same answer.
fn centre_near_values(
    p: [DVec2; 3],
    sides: &[Side; 2],
    values: &[f64],
    width: u32,
    height: u32,
) -> bool {
    let Some(bx) = centre_box(p, width, height) else {
        return true;
    };
    let (i0, i1, j0, j1) = bx;
    if (i1 - i0 + 1).max(0) * (j1 - j0 + 1).max(0) > ISO_STEEP_CENTRES {
        return true;
    }
    near_strips(p, sides, values, bx)
        .unwrap_or_else(|| centre_near_values_box(p, sides, values, bx))
}

/// The box of centres around the triangle at `p` grown by the band, within
/// the image; `None` for a degenerate triangle or a non-finite box.
fn centre_box(p: [DVec2; 3], width: u32, height: u32) -> Option<CentreBox> {
    let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
    let (lo, hi) = (
        p[0].min(p[1]).min(p[2]) - TIE_BAND_PX,
        p[0].max(p[1]).max(p[2]) + TIE_BAND_PX,
    );
    if !(area != 0.0 && lo.is_finite() && hi.is_finite()) {
        return None;
    }
    Some((
        ceil_i(lo.x - 0.5).max(0),
        floor_i(hi.x - 0.5).min(width as i64 - 1),
        ceil_i(lo.y - 0.5).max(0),
        floor_i(hi.y - 0.5).min(height as i64 - 1),
    ))
}

/// Whether the centre `c`, if inside the triangle at `p` grown by the
/// band, is near a value on one of the sides (NaN: near).
fn centre_is_near(p: [DVec2; 3], sides: &[Side; 2], values: &[f64], c: DVec2) -> bool {
    if !in_grown_triangle(p, c) {
        return false;
    }
    let b = centre_weights(p, (p[1] - p[0]).perp_dot(p[2] - p[0]), c);
    sides.iter().any(|(s, q, margin)| {
        let d = to_nearest(values, at_centre(b, s, q));
        d.is_nan() || d <= *margin
    })
}

/// [`centre_near_values`] by testing every centre of the box `bx`.
fn centre_near_values_box(p: [DVec2; 3], sides: &[Side; 2], values: &[f64], bx: CentreBox) -> bool {
    let (i0, i1, j0, j1) = bx;
    (j0..=j1).any(|j| {
        (i0..=i1)
            .any(|i| centre_is_near(p, sides, values, DVec2::new(i as f64 + 0.5, j as f64 + 0.5)))
    })
}

/// [`centre_near_values`] by the strips along the values' lines: for each
/// side and each value `V` its scalars can reach, the centres `c` of the
/// box where the affine `N(c) = sum b_k q_k (s_k - V)` (the scalar's
/// distance from `V` times the affine weight sum `W(c) = sum b_k q_k`) is
/// at most the margin times the largest `W` in the grown triangle, row by
/// row (or column by column, across the line's steeper direction), each
/// tested by [`centre_is_near`]. `None` where that cannot be bounded: a
/// non-finite corner, weights that may not stay positive in the grown
/// triangle (a steep perspective), a side at one value throughout, or more
/// strip lines than the box has centres.
fn near_strips(p: [DVec2; 3], sides: &[Side; 2], values: &[f64], bx: CentreBox) -> Option<bool> {
    let (i0, i1, j0, j1) = bx;
    let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
    // Outside the triangle by at most the band, a centre's barycentric
    // weights are at least -band / altitude; the triangle is wide (its
    // least altitude at least SLIVER_TIE_PX), so each is above -NEG and
    // their absolute sum below 1 + 2 NEG (with room).
    const NEG: f64 = 2.0 * TIE_BAND_PX / SLIVER_TIE_PX;
    let longest = (0..3)
        .map(|k| (p[(k + 1) % 3] - p[k]).length())
        .fold(0.0, f64::max);
    // Also for NaN.
    if area.abs().partial_cmp(&(SLIVER_TIE_PX * longest)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let mut lines = 0i64;
    for (s, q, margin) in sides {
        if !(s.iter().chain(q).all(|v| v.is_finite()) && margin.is_finite()) {
            return None;
        }
        let (q_min, q_max) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        // W(c) >= q_min - 2 NEG (q_min + q_max) > 0 in the grown triangle.
        let w_min = q_min - 2.0 * NEG * (q_min + q_max);
        if !(q_min > 0.0 && w_min >= 0.5 * q_min) {
            return None;
        }
        let w_max = q_max * (1.0 + 2.0 * NEG);
        // The scalar at a centre there lies within `reach` of the
        // corners' middle.
        let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let reach = half * (1.0 + 2.0 * NEG) * q_max / w_min + margin;
        let first = values.partition_point(|&v| v < mid - reach);
        let end = values.partition_point(|&v| v <= mid + reach);
        for &v in &values[first..end.max(first)] {
            let n = [0, 1, 2].map(|k| q[k] * (s[k] - v));
            let g = affine_gradient(p, n);
            if !(g.x.is_finite() && g.y.is_finite()) || (g.x == 0.0 && g.y == 0.0) {
                return None;
            }
            // |N(c)| <= h holds every centre within the margin of v, with
            // room for the rounding of N.
            let h = margin * w_max + 1e-12 * (n[0].abs() + n[1].abs() + n[2].abs());
            let by_rows = g.x.abs() >= g.y.abs();
            let (u0, u1, a0, a1) = if by_rows {
                (j0, j1, i0, i1)
            } else {
                (i0, i1, j0, j1)
            };
            lines += u1 - u0 + 1;
            if lines > ISO_STEEP_CENTRES {
                return None;
            }
            let (gu, ga, pu, pa) = if by_rows {
                (g.y, g.x, p[0].y, p[0].x)
            } else {
                (g.x, g.y, p[0].x, p[0].y)
            };
            for u in u0..=u1 {
                // N = n0 + gu (u + 1/2 - pu) + ga (a + 1/2 - pa) within
                // [-h, h]: the centres a in an interval.
                let base = n[0] + gu * (u as f64 + 0.5 - pu) - ga * pa;
                let (x0, x1) = ((-h - base) / ga, (h - base) / ga);
                let (x0, x1) = (x0.min(x1), x0.max(x1));
                let a_lo = ceil_i(x0 - 0.5).max(a0);
                let a_hi = floor_i(x1 - 0.5).min(a1);
                for a in a_lo..=a_hi {
                    let (i, j) = if by_rows { (a, u) } else { (u, a) };
                    let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                    if centre_is_near(p, sides, values, c) {
                        return Some(true);
                    }
                }
            }
        }
    }
    Some(false)
}

/// The entry (`side` 0) or exit (1) scalars at the corners of the exact
/// triangle `t`, with the factors `q = 1/z` of their screen-space weights
/// (1 orthographic, and where a depth is not a positive number, which has
/// no perspective weight).
fn side_corners(part: &PartTriangles, t: &[u32; 3], side: usize) -> ([f64; 3], [f64; 3]) {
    let v = t.map(|i| &part.proj.vertices[i as usize]);
    let ortho = part.proj.view.ortho;
    let s = v.map(|v| if side == 0 { v.s_front } else { v.s_back });
    let q = v.map(|v| {
        let z = if side == 0 { v.z_front } else { v.z_back };
        if ortho || z.is_nan() || z <= 0.0 {
            1.0
        } else {
            1.0 / z
        }
    });
    (s, q)
}

/// The scalar at a centre with screen-space weights `b` in a triangle with
/// corner scalars `s` and weight factors `q` ([`side_corners`]):
/// perspective-correct, as the GPU interpolates it.
#[inline]
fn at_centre(b: [f64; 3], s: &[f64; 3], q: &[f64; 3]) -> f64 {
    let w = [b[0] * q[0], b[1] * q[1], b[2] * q[2]];
    (w[0] * s[0] + w[1] * s[1] + w[2] * s[2]) / (w[0] + w[1] + w[2])
}

/// The screen-space barycentric weights of centre `c` in the triangle at
/// `p`, whose doubled signed area is `area`.
#[inline]
fn centre_weights(p: [DVec2; 3], area: f64, c: DVec2) -> [f64; 3] {
    let b1 = (c - p[0]).perp_dot(p[2] - p[0]) / area;
    let b2 = (p[1] - p[0]).perp_dot(c - p[0]) / area;
    [1.0 - b1 - b2, b1, b2]
}

/// The distance from `s` to the nearest of the sorted `values`.
fn to_nearest(values: &[f64], s: f64) -> f64 {
    let k = values.partition_point(|&v| v < s);
    let above = values.get(k).map_or(f64::INFINITY, |&v| v - s);
    let below = k.checked_sub(1).map_or(f64::INFINITY, |k| s - values[k]);
    above.min(below)
}

#[cfg(test)]
mod strip_tests {
    use super::*;
    use crate::visibility::synth::Rng;

    /// The strip search answers as the box search does, on random wide
    /// and narrow triangles, orthographic and perspective weights, values
    /// at, near and between the corners' scalars, and margins from the
    /// `f32` stage's to a large part of the scalars' spread; and it
    /// answers (rather than falling back) on most of them.
    #[test]
    fn the_strip_search_agrees_with_the_box_search() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut near, mut decided, mut compared) = (0, 0, 0);
        for n in 0..40_000 {
            let p =
                [0; 3].map(|_| DVec2::new(rng.next_f64() * 9.0 - 1.0, rng.next_f64() * 9.0 - 1.0));
            let perspective = n % 2 == 1;
            let side = |rng: &mut Rng| {
                let s = [0; 3].map(|_| rng.next_f64() * 4.0 - 2.0);
                let q = [0; 3].map(|_| {
                    if perspective {
                        0.3 + rng.next_f64() * 2.0
                    } else {
                        1.0
                    }
                });
                let margin = 10f64.powf(-6.0 + 5.5 * rng.next_f64());
                (s, q, margin)
            };
            let sides = [side(&mut rng), side(&mut rng)];
            // Values: random, one of them sometimes at a corner's scalar.
            let mut values: Vec<f64> = (0..1 + (rng.next_f64() * 6.0) as usize)
                .map(|_| rng.next_f64() * 5.0 - 2.5)
                .collect();
            if n % 3 == 0 {
                values.push(sides[0].0[n % 3]);
            }
            values.sort_by(f64::total_cmp);
            let Some(bx) = centre_box(p, 8, 8) else {
                continue;
            };
            let (i0, i1, j0, j1) = bx;
            if (i1 - i0 + 1).max(0) * (j1 - j0 + 1).max(0) > ISO_STEEP_CENTRES {
                continue;
            }
            let by_box = centre_near_values_box(p, &sides, &values, bx);
            if let Some(by_strips) = near_strips(p, &sides, &values, bx) {
                assert_eq!(by_strips, by_box, "{p:?} {sides:?} {values:?}");
                decided += 1;
            }
            assert_eq!(centre_near_values(p, &sides, &values, 8, 8), by_box);
            near += by_box as usize;
            compared += 1;
        }
        assert!(
            decided > compared / 3 && near > compared / 10 && near < compared * 9 / 10,
            "{decided} {near} {compared}"
        );
    }
}
