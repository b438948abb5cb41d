//! The one pass over a part's exact triangles for what the snap of their
//! corners can do ([`scan_triangles`], see the module docs of
//! [`super`]): the wide triangles drawn **steep** (the exact triangle's
//! values at their snapped corners), where the snap could shift the
//! optical depth at a centre or, in the isosurface modes, carry an entry
//! or exit scalar across an isovalue; and the centres inside **slivers**
//! that the tie decisions take exactly.

use glam::DVec2;

use super::band::{centres_within, in_grown_triangle};
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
    let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
    let (lo, hi) = (
        p[0].min(p[1]).min(p[2]) - TIE_BAND_PX,
        p[0].max(p[1]).max(p[2]) + TIE_BAND_PX,
    );
    let (i0, i1) = (
        (lo.x - 0.5).ceil().max(0.0),
        (hi.x - 0.5).floor().min(part.width as f64 - 1.0),
    );
    let (j0, j1) = (
        (lo.y - 0.5).ceil().max(0.0),
        (hi.y - 0.5).floor().min(part.height as f64 - 1.0),
    );
    if !(area != 0.0 && i0.is_finite() && i1.is_finite() && j0.is_finite() && j1.is_finite()) {
        return true;
    }
    let (i0, i1, j0, j1) = (i0 as i64, i1 as i64, j0 as i64, j1 as i64);
    if (i1 - i0 + 1).max(0) * (j1 - j0 + 1).max(0) > ISO_STEEP_CENTRES {
        return true;
    }
    // Per side: the corner scalars, their weights' factors and the margin.
    let sides = [0, 1].map(|side| {
        let (s, q) = side_corners(part, t, side);
        let (lo, hi) = (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]));
        (s, q, shift + iso_margin(part.iso_origin, lo, hi))
    });
    for j in j0..=j1 {
        for i in i0..=i1 {
            let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
            if !in_grown_triangle(p, c) {
                continue;
            }
            let b = centre_weights(p, area, c);
            for (s, q, margin) in &sides {
                let d = to_nearest(part.isovalues, at_centre(b, s, q));
                // NaN: as near.
                if d.is_nan() || d <= *margin {
                    return true;
                }
            }
        }
    }
    false
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
