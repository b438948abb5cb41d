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

use crate::projection::FaceTri;

/// Appends to `out` the lines where the scalar of the boundary triangle
/// `face` equals one of `values` (sorted): the segment between the two
/// points of its edges where the field, linear on the triangle in space,
/// takes the value, at their pixel positions (in perspective the pixel
/// position divides the edge in the ratio of the points' `s / z`, not of
/// `s`). A value the triangle's scalars do not strictly bracket has no such
/// line: a face at the value everywhere is not crossed there, and a line
/// through a corner alone meets the other pieces' outline there.
pub fn iso_lines(face: &FaceTri, values: &[f64], ortho: bool, out: &mut Vec<[DVec2; 2]>) {
    let (lo, hi) = crate::render::pieces::value_range(face.s.iter().copied());
    // Also for NaN (no range).
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        return;
    }
    let first = values.partition_point(|&v| v <= lo);
    for &v in &values[first..] {
        if v >= hi {
            break;
        }
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
            out.push(ends);
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
        iso_lines(&f, &[-1.0, 1.0, 3.0, 4.0, 9.0], true, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        for (line, x) in out.iter().zip([1.0, 3.0]) {
            let mut ends = line.map(|e| [e.x, e.y]);
            ends.sort_by(|a, b| a[1].total_cmp(&b[1]));
            assert!((ends[0][0] - x).abs() < 1e-12 && ends[0][1].abs() < 1e-12);
            assert!((ends[1][0] - x).abs() < 1e-12 && (ends[1][1] - (4.0 - x)).abs() < 1e-12);
        }
        // A value at a corner with the others on one side, and a face at
        // the value everywhere, have no line; a value at a corner between
        // the others runs from that corner.
        out.clear();
        iso_lines(&f, &[0.0], true, &mut out);
        let flat = face([[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]], [1.0; 3], [2.0; 3]);
        iso_lines(&flat, &[2.0], true, &mut out);
        assert!(out.is_empty());
        let g = face(
            [[0.0, 0.0], [4.0, 0.0], [0.0, 4.0]],
            [1.0; 3],
            [1.0, 0.0, 2.0],
        );
        iso_lines(&g, &[1.0], true, &mut out);
        assert_eq!(out.len(), 1);
        assert!(out[0].contains(&DVec2::ZERO));
        assert!(out[0].contains(&DVec2::new(2.0, 2.0)));
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
        iso_lines(&f, &[0.5], false, &mut out);
        assert_eq!(out.len(), 1);
        assert!(
            out[0]
                .iter()
                .any(|e| (*e - DVec2::new(6.0, 0.0)).length() < 1e-12),
            "{out:?}"
        );
        assert!(
            out[0]
                .iter()
                .any(|e| (*e - DVec2::new(6.0, 2.0)).length() < 1e-12),
            "{out:?}"
        );
    }
}
