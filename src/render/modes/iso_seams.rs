//! Where a surface meets a face: the lines on a piece's boundary triangles
//! where their scalar is an isovalue, for the isosurface modes on the
//! segment payload ([`super::iso`]).
//!
//! Two pieces sharing a face each interpolate the face's scalar at a pixel
//! centre on their own region triangles, whose corners are snapped to the
//! sub-pixel grid: next to the line where the face's scalar is `V`, the two
//! can put the centre on different sides of `V` (a crack in the surface,
//! or the surface twice). The isosurface payload hands these lines to the
//! driver as seams ([`crate::projection::Projected::seam_lines`]), and the
//! centres next to them take the exact segment in both pieces
//! ([`crate::render::ties`]): the ray caster's crossing of the face, the
//! same numbers in both.

use glam::DVec2;

use crate::projection::{FaceTri, SeamLine};
use crate::render::ties::{affine_gradient, iso_margin, TIE_BAND_PX};

/// Appends to `out` the lines where the scalar of the boundary triangle
/// `face` equals one of `values` (sorted): the segment between the two
/// points of its edges where the field, linear on the triangle in space,
/// takes the value, at their pixel positions (in perspective the pixel
/// position divides the edge in the ratio of the points' `s / z`, not of
/// `s`), each with a band ([`SeamLine::band`]) holding the centres the
/// pieces sharing the face must decide exactly.
///
/// Within the `f32` stage's margin of a value ([`iso_margin`] with
/// `origin`, the scalar the stage maps to 0), the stage's level and its
/// rounding can put a centre on the other side of the value in one piece
/// than in the piece sharing the face (or than the ray caster, on the
/// mesh's boundary). So the line runs where the face's scalar is the
/// middle of its part of that margin, `[V - m, V + m]` within the range of
/// its corners (`V` itself for a value well inside the range; next to a
/// corner or an edge for a value at or just beyond it), and its band is
/// [`TIE_BAND_PX`] grown by the distance over which the scalar changes by
/// half that part: the part over the scalar's least screen gradient on
/// the face (in perspective, `|grad(s/z) - v grad(1/z)|` over the largest
/// `1/z`), at most the face's extent. A face at one value everywhere has
/// no line (the stage's level below the value keeps it uncrossed on both
/// sides).
pub fn iso_lines(
    face: &FaceTri,
    values: &[f64],
    ortho: bool,
    origin: f64,
    out: &mut Vec<SeamLine>,
) {
    let (lo, hi) = crate::render::pieces::value_range(face.s.iter().copied());
    // Also for NaN (no range).
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        return;
    }
    let margin = iso_margin(origin, lo, hi);
    let first = values.partition_point(|&v| v <= lo - margin);
    if values.get(first).is_none_or(|&v| v >= hi + margin) {
        return;
    }
    let extent = {
        let p = &face.p;
        let (a, b) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        (b - a).length()
    };
    // The screen gradients of `s` (orthographic), or of `s / z` and `1 / z`.
    let q = if ortho {
        [1.0; 3]
    } else {
        face.z.map(|z| 1.0 / z)
    };
    let grad_a = affine_gradient(face.p, [0, 1, 2].map(|k| face.s[k] * q[k]));
    let grad_q = affine_gradient(face.p, q);
    let q_max = q[0].abs().max(q[1].abs()).max(q[2].abs());
    for &value in &values[first..] {
        if value >= hi + margin {
            break;
        }
        // The face's scalars within the margin of the value, `[a, b]`:
        // the line at their middle, `v`, strictly inside the face's range,
        // and the band holding them.
        let (a, b) = ((value - margin).max(lo), (value + margin).min(hi));
        if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
            continue;
        }
        let v = if a > lo && b < hi {
            value
        } else {
            0.5 * (a + b)
        };
        let mut ends = [DVec2::ZERO; 2];
        let mut n = 0;
        for k in 0..3 {
            let (i, j) = (k, (k + 1) % 3);
            let (si, sj) = (face.s[i], face.s[j]);
            // Where the corners fall on different sides ("at or above"
            // v, or below): twice around a triangle that brackets v.
            if (si >= v) == (sj >= v) {
                continue;
            }
            let t = (v - si) / (sj - si);
            // In perspective `s / z` and `1 / z` are linear on screen, so
            // the screen fraction `u` where `s = v` solves
            // `(1 - u) (v - si) / zi = u (sj - v) / zj`: with
            // `v - si = t (sj - si)`, `u = t zj / ((1 - t) zi + t zj)`.
            let t = if ortho {
                t
            } else {
                let (zi, zj) = (face.z[i], face.z[j]);
                t * zj / ((1.0 - t) * zi + t * zj)
            };
            if n < 2 && t.is_finite() {
                ends[n] = face.p[i] + (face.p[j] - face.p[i]) * t.clamp(0.0, 1.0);
                n += 1;
            }
        }
        if n == 2 {
            // The least gradient along the line; a face seen edge-on has
            // none finite (no centre lies inside it): the plain band.
            let grad = (grad_a - grad_q * v).length() / q_max;
            let reach = if grad.is_infinite() {
                0.0
            } else if grad > 0.0 {
                (0.5 * (b - a) / grad).min(extent)
            } else {
                // Zero or NaN: the whole face.
                extent
            };
            out.push(SeamLine {
                ends,
                band: TIE_BAND_PX + reach,
            });
        }
    }
}

#[cfg(test)]
mod iso_line_tests {
    use super::*;

    fn face(p: [[f64; 2]; 3], z: [f64; 3], s: [f64; 3]) -> FaceTri {
        FaceTri {
            p: p.map(|q| DVec2::new(q[0], q[1])),
            z,
            s,
        }
    }

    #[test]
    fn lines_where_the_face_holds_each_value() {
        // s = x on the triangle (0,0), (4,0), (0,4): the lines x = 1 and
        // x = 3, each from the bottom edge to the slanted one.
        let f = face(
            [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]],
            [1.0; 3],
            [0.0, 4.0, 0.0],
        );
        let mut out = Vec::new();
        iso_lines(&f, &[-1.0, 1.0, 3.0, 4.0, 9.0], true, 0.0, &mut out);
        // (4 is at the corner (4, 0): a line within the margin next to it.)
        assert_eq!(out.len(), 3, "{out:?}");
        assert!(out[2]
            .ends
            .iter()
            .all(|e| (*e - DVec2::new(4.0, 0.0)).length() < 1e-4));
        for (line, x) in out.iter().zip([1.0, 3.0]) {
            let mut ends = line.ends.map(|e| [e.x, e.y]);
            ends.sort_by(|a, b| a[1].total_cmp(&b[1]));
            assert!((ends[0][0] - x).abs() < 1e-12 && ends[0][1].abs() < 1e-12);
            assert!((ends[1][0] - x).abs() < 1e-12 && (ends[1][1] - (4.0 - x)).abs() < 1e-12);
        }
        // A value at an edge with the other corner on one side has a line
        // next to the edge, within the margin (1e-5 of 4 here) of it, whose
        // band holds that margin; a face at the value everywhere has none;
        // a value at a corner between the others runs from that corner.
        out.clear();
        iso_lines(&f, &[0.0], true, 0.0, &mut out);
        assert_eq!(out.len(), 1);
        let m = crate::numeric::tolerance::ISO_SLIVER_REL * 4.0;
        assert!(out[0].ends.iter().all(|e| (e.x - m / 2.0).abs() < 1e-12));
        let band = crate::render::ties::TIE_BAND_PX + m / 2.0;
        assert!((out[0].band - band).abs() < 1e-12, "{out:?}");
        out.clear();
        let flat = face([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]], [1.0; 3], [2.0; 3]);
        iso_lines(&flat, &[2.0], true, 0.0, &mut out);
        assert!(out.is_empty());
        let g = face(
            [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]],
            [1.0; 3],
            [1.0, 0.0, 2.0],
        );
        iso_lines(&g, &[1.0], true, 0.0, &mut out);
        assert_eq!(out.len(), 1);
        assert!(out[0].ends.contains(&DVec2::ZERO));
        assert!(out[0].ends.contains(&DVec2::new(2.0, 2.0)));
    }

    #[test]
    fn the_band_covers_the_stage_margin_over_the_gradient() {
        use crate::numeric::tolerance::ISO_SLIVER_REL;
        use crate::render::ties::TIE_BAND_PX;
        // s = x / 100 on the triangle (0,0), (400,0), (0,400): a gradient
        // of 0.01 per pixel, the line x = 100 for the value 1.
        let f = face(
            [[0.0, 0.0], [400.0, 0.0], [0.0, 400.0]],
            [1.0; 3],
            [0.0, 4.0, 0.0],
        );
        let band = |origin: f64, ortho: bool| {
            let mut out = Vec::new();
            iso_lines(&f, &[1.0], ortho, origin, &mut out);
            assert_eq!(out.len(), 1);
            out[0].band
        };
        // Origin 0: the margin is 1e-5 of the farthest corner (4), 4e-5,
        // over 0.01 per pixel.
        let near = TIE_BAND_PX + ISO_SLIVER_REL * 4.0 / 0.01;
        assert!(
            (band(0.0, true) - near).abs() < 1e-12,
            "{}",
            band(0.0, true)
        );
        // At equal depths perspective is the same.
        assert!((band(0.0, false) - near).abs() < 1e-12);
        // Origin -1000: 1e-5 of 1004 over 0.01 is about one pixel.
        let far = TIE_BAND_PX + ISO_SLIVER_REL * 1004.0 / 0.01;
        assert!((band(-1000.0, true) - far).abs() < 1e-9);
        // An origin so far that the margin holds the face's whole range:
        // the line at its middle (x = 200), the band to both ends.
        let whole = TIE_BAND_PX + 200.0;
        assert!((band(-1e9, true) - whole).abs() < 1e-9);
        // In perspective the scalar's screen gradient on the line is
        // `|grad(s/z) - V grad(1/z)| / (1/z)`, least where `1/z` is
        // largest: the band takes that.
        let g = face(
            [[0.0, 0.0], [400.0, 0.0], [0.0, 400.0]],
            [1.0, 2.0, 2.0],
            [0.0, 4.0, 0.0],
        );
        let mut out = Vec::new();
        iso_lines(&g, &[1.0], false, 0.0, &mut out);
        // s/z and 1/z affine: corners (0, 2, 0) and (1, 1/2, 1/2); on the
        // line s = 1, grad(s/z) - grad(1/z) = (1/200, 0) - (-1/800, -1/800)
        // = (1/160, 1/800), over the largest 1/z (1).
        let grad = (1.0f64 / 160.0).hypot(1.0 / 800.0);
        let expected = TIE_BAND_PX + ISO_SLIVER_REL * 4.0 / grad;
        assert!((out[0].band - expected).abs() < 1e-12, "{out:?}");
    }

    #[test]
    fn in_perspective_the_line_divides_edges_by_s_over_z() {
        // An edge from (0, 0) at depth 1 to (8, 0) at depth 3 on screen
        // (world x = 0 and 24, screen x = world x / z), with s from 0 to 1:
        // s = 1/2 at the world midpoint, x = 12 at depth 2, which is
        // screen x = 6, 3/4 of the screen edge (the far half is drawn
        // smaller). On the edge from the far corner to (0, 8) at depth 1
        // with s = 0, s = 1/2 at world (12, 4), depth 2: screen (6, 2).
        let f = face(
            [[0.0, 0.0], [8.0, 0.0], [0.0, 8.0]],
            [1.0, 3.0, 1.0],
            [0.0, 1.0, 0.0],
        );
        let mut out = Vec::new();
        iso_lines(&f, &[0.5], false, 0.0, &mut out);
        assert_eq!(out.len(), 1);
        assert!(
            out[0]
                .ends
                .iter()
                .any(|e| (*e - DVec2::new(6.0, 0.0)).length() < 1e-12),
            "{out:?}"
        );
        assert!(
            out[0]
                .ends
                .iter()
                .any(|e| (*e - DVec2::new(6.0, 2.0)).length() < 1e-12),
            "{out:?}"
        );
    }
}
