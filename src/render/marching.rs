//! Marching tetrahedra: the isosurface of the `tets` field (the consistent
//! tetrahedralisation, linear in each tet) as a triangle mesh. The
//! projected modes never extract triangles; this is the independent
//! cross-check of `--mode iso` (drawn with a depth test, the opaque
//! surface of `--split all` is this mesh) and a way to export a surface.
//!
//! A tet's corners are classed "at or above `V`" or "below" (the crossing
//! rule of [`super::iso`]); an edge between classes holds the surface point
//! at `t = (V - s_a) / (s_b - s_a)`. One corner apart from the others gives
//! a triangle, two and two a quadrilateral (two triangles).

use glam::DVec3;

use crate::mesh::tetra::tetrahedralize_cell;
use crate::mesh::Mesh;

/// The triangles of the isosurface `value` of the point field `scalars`
/// (missing or non-finite values: the tet is left out).
pub fn marching_tets(mesh: &Mesh, scalars: &[f64], value: f64) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    let mut tets = Vec::new();
    for c in 0..mesh.cells.len() {
        tets.clear();
        tetrahedralize_cell(&mesh.cells, c, &mut tets);
        for t in &tets {
            let mut p = [DVec3::ZERO; 4];
            let mut s = [0.0; 4];
            let mut ok = true;
            for k in 0..4 {
                match (mesh.points.get(t[k] as usize), scalars.get(t[k] as usize)) {
                    (Some(&pk), Some(&sk)) if sk.is_finite() => {
                        p[k] = pk;
                        s[k] = sk;
                    }
                    _ => ok = false,
                }
            }
            if ok {
                tet_surface(p, s, value, &mut out);
            }
        }
    }
    out
}

/// The part of the surface in one tet.
fn tet_surface(p: [DVec3; 4], s: [f64; 4], v: f64, out: &mut Vec<[DVec3; 3]>) {
    let above: Vec<usize> = (0..4).filter(|&k| s[k] >= v).collect();
    let below: Vec<usize> = (0..4).filter(|&k| s[k] < v).collect();
    let cut = |a: usize, b: usize| {
        let t = (v - s[a]) / (s[b] - s[a]);
        p[a] + (p[b] - p[a]) * t
    };
    match (above.len(), below.len()) {
        (1, 3) | (3, 1) => {
            let (lone, rest) = if above.len() == 1 {
                (above[0], &below)
            } else {
                (below[0], &above)
            };
            out.push([cut(lone, rest[0]), cut(lone, rest[1]), cut(lone, rest[2])]);
        }
        (2, 2) => {
            let (a, b) = (above[0], above[1]);
            let (c, d) = (below[0], below[1]);
            let q = [cut(a, c), cut(a, d), cut(b, d), cut(b, c)];
            out.push([q[0], q[1], q[2]]);
            out.push([q[0], q[2], q[3]]);
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{warped_hex_grid, Warp};

    #[test]
    fn a_plane_through_a_cube_has_the_plane_s_area() {
        let mesh = warped_hex_grid(
            1,
            &Warp {
                amplitude: 0.0,
                seed: 1,
            },
        );
        let s: Vec<f64> = mesh.points.iter().map(|p| p.x).collect();
        let tris = marching_tets(&mesh, &s, 0.3);
        let area: f64 = tris
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .sum();
        assert!((area - 1.0).abs() < 1e-12, "{area}");
        assert!(tris.iter().flatten().all(|p| (p.x - 0.3).abs() < 1e-12));
    }
}
