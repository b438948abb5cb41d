//! Gradients of the scalar field, for the shading of isosurfaces
//! ([`super::iso`]): the same definitions in the projected modes and in the
//! reference ray caster, so that both shade a surface point alike.
//!
//! - **Flat** (one normal per piece): the gradient of the linear function
//!   that fits the piece's corner scalars best in least squares
//!   ([`fit_gradient`]). For a tetrahedron (and any part of one, such as a
//!   fragment of a plane cut) it is the exact gradient of the linear field;
//!   for a whole cell it is the best linear approximation of the `faces`
//!   field, which has no gradient of its own (it is defined along rays).
//!   The gradient is equivariant under rigid motions, so it may be fitted
//!   in world or view coordinates.
//! - **Smooth** (Roettger, Kraus and Ertl 2000, section 8: gradients at the
//!   vertices): each point's gradient is the volume-weighted mean of the
//!   gradients of the consistent tetrahedra around it ([`point_gradients`]);
//!   inside a piece it is interpolated as the scalar is (barycentric on the
//!   boundary triangles, linear along the ray between entry and exit), so
//!   it is continuous across faces.
//!
//! A zero gradient (constant field, degenerate cell) has no direction: the
//! surface there is lit as if it faced the viewer ([`super::iso`]).

use glam::{DMat3, DVec3};

use crate::mesh::tetra::tetrahedralize_cell;
use crate::mesh::Mesh;
use crate::projection::Polyhedron;

/// The least-squares linear gradient of `(point, scalar)` samples (exact
/// when the samples lie on a linear function of 3D position and span a
/// volume); zero when they do not span three dimensions.
pub fn fit_gradient(samples: impl Iterator<Item = (DVec3, f64)> + Clone) -> DVec3 {
    let (mut n, mut pc, mut sc) = (0.0, DVec3::ZERO, 0.0);
    for (p, s) in samples.clone() {
        n += 1.0;
        pc += p;
        sc += s;
    }
    if n < 4.0 {
        return DVec3::ZERO;
    }
    pc /= n;
    sc /= n;
    let (mut m, mut r) = (DMat3::ZERO, DVec3::ZERO);
    let mut scale: f64 = 0.0;
    for (p, s) in samples {
        let d = p - pc;
        m += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
        r += d * (s - sc);
        scale = scale.max(d.length_squared());
    }
    // Relative to the piece's size, a determinant this small is a flat
    // (coplanar) set of points: no gradient across it.
    let det = m.determinant();
    if det
        .abs()
        .partial_cmp(&(crate::numeric::tolerance::GRADIENT_FLAT_REL * scale.powi(3)))
        != Some(std::cmp::Ordering::Greater)
    {
        return DVec3::ZERO;
    }
    let g = m.inverse() * r;
    if g.is_finite() {
        g
    } else {
        DVec3::ZERO
    }
}

/// The exact gradient of the linear field of a tetrahedron (zero for a flat
/// one).
pub fn tet_gradient(p: [DVec3; 4], s: [f64; 4]) -> DVec3 {
    fit_gradient((0..4).map(|k| (p[k], s[k])))
}

/// The gradient at every point: the mean of the gradients of the
/// consistent tetrahedra that use it, weighted by their (unsigned) volume;
/// zero for a point no tetrahedron of positive volume uses.
pub fn point_gradients(mesh: &Mesh, scalars: &[f64]) -> Vec<DVec3> {
    point_gradients_where(mesh, scalars, |_| true)
}

/// Cells per batch of [`point_gradients_where`]: their tetrahedra's
/// gradients are computed in parallel, then summed in cell order (a few
/// MiB of contributions at a time).
const GRADIENT_BATCH: usize = 1 << 15;

/// [`point_gradients`] at the points of the cells for which `wanted` holds
/// (the same values, bit for bit: each such point's sum runs over every
/// tetrahedron around it, in the same order), zero at every other point.
/// A frame needs the gradients only where it draws a surface; the cells
/// around the wanted points are the only ones visited.
pub fn point_gradients_where(
    mesh: &Mesh,
    scalars: &[f64],
    wanted: impl Fn(usize) -> bool + Sync,
) -> Vec<DVec3> {
    use rayon::prelude::*;
    let n = mesh.points.len();
    let cells = mesh.cells.len();
    let wanted_cells: Vec<bool> = (0..cells).into_par_iter().map(&wanted).collect();
    let mut want = vec![false; n];
    for c in (0..cells).filter(|&c| wanted_cells[c]) {
        for &p in mesh.cells.nodes(c) {
            if let Some(w) = want.get_mut(p as usize) {
                *w = true;
            }
        }
    }
    // The cells with a wanted point: they hold every tetrahedron around one.
    let visit: Vec<usize> = (0..cells)
        .into_par_iter()
        .filter(|&c| {
            mesh.cells
                .nodes(c)
                .iter()
                .any(|&p| want.get(p as usize) == Some(&true))
        })
        .collect();
    let mut sum = vec![DVec3::ZERO; n];
    let mut weight = vec![0.0f64; n];
    for batch in visit.chunks(GRADIENT_BATCH) {
        // Each cell's tetrahedra with their gradient times volume and
        // volume, in cell order.
        let parts: Vec<Vec<([u32; 4], DVec3, f64)>> = batch
            .par_chunks(256)
            .map(|chunk| {
                let mut out = Vec::new();
                let mut tets = Vec::new();
                for &c in chunk {
                    tets.clear();
                    tetrahedralize_cell(&mesh.cells, c, &mut tets);
                    out.extend(
                        tets.iter()
                            .filter_map(|&t| tet_contribution(mesh, scalars, t)),
                    );
                }
                out
            })
            .collect();
        for (t, gv, vol) in parts.iter().flatten() {
            for &i in t {
                sum[i as usize] += *gv;
                weight[i as usize] += *vol;
            }
        }
    }
    sum.iter()
        .zip(&weight)
        .zip(&want)
        .map(|((&g, &w), &keep)| if keep && w > 0.0 { g / w } else { DVec3::ZERO })
        .collect()
}

/// Tetrahedron `t`'s gradient times its volume, and its volume; `None`
/// for one with a point or scalar missing or not finite, or of no volume.
fn tet_contribution(mesh: &Mesh, scalars: &[f64], t: [u32; 4]) -> Option<([u32; 4], DVec3, f64)> {
    let (mut p, mut s) = ([DVec3::ZERO; 4], [0.0; 4]);
    for k in 0..4 {
        match (mesh.points.get(t[k] as usize), scalars.get(t[k] as usize)) {
            (Some(&pk), Some(&sk)) if sk.is_finite() => (p[k], s[k]) = (pk, sk),
            _ => return None,
        }
    }
    let vol = ((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0).abs();
    if vol.is_nan() || vol <= 0.0 {
        return None;
    }
    Some((t, tet_gradient(p, s) * vol, vol))
}

/// `g` in view coordinates of a camera with unit axes `right`, `up` and
/// `forward` (a rotation: the length is kept).
#[inline]
pub fn to_view(g: DVec3, right: DVec3, up: DVec3, forward: DVec3) -> DVec3 {
    DVec3::new(g.dot(right), g.dot(up), g.dot(forward))
}

/// The barycentric weights of `x` (a point of the triangle's plane, up to
/// rounding) in triangle `t`, unclamped (negative outside it); `None` when
/// the triangle is degenerate.
pub fn barycentric_raw(t: [DVec3; 3], x: DVec3) -> Option<[f64; 3]> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let nn = n.length_squared();
    if nn.is_nan() || nn <= 0.0 {
        return None;
    }
    Some([
        (t[2] - t[1]).cross(x - t[1]).dot(n) / nn,
        (t[0] - t[2]).cross(x - t[2]).dot(n) / nn,
        (t[1] - t[0]).cross(x - t[0]).dot(n) / nn,
    ])
}

/// The barycentric weights of `x` (a point of the triangle's plane, up to
/// rounding) in triangle `t`, clamped to the triangle; the first corner's
/// when the triangle is degenerate.
pub fn barycentric(t: [DVec3; 3], x: DVec3) -> [f64; 3] {
    let Some(w) = barycentric_raw(t, x) else {
        return [1.0, 0.0, 0.0];
    };
    let w = w.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
    let sum = w[0] + w[1] + w[2];
    if sum > 0.0 {
        w.map(|v| v / sum)
    } else {
        [1.0, 0.0, 0.0]
    }
}

/// The gradient of a piece at a point `x` of its boundary (view space):
/// interpolated on the boundary triangle nearest `x` from
/// [`Polyhedron::gradients`] (the smooth field, continuous across the
/// triangles, so any triangle holding `x` gives the same value), or `flat`
/// when the piece carries no gradients.
pub fn boundary_gradient(poly: &Polyhedron, x: DVec3, flat: DVec3) -> DVec3 {
    if poly.gradients.len() != poly.points.len() || poly.triangles.is_empty() {
        return flat;
    }
    let mut best = (f64::INFINITY, flat);
    for t in &poly.triangles {
        let p = t.map(|i| poly.points.get(i as usize).copied());
        let (Some(p0), Some(p1), Some(p2)) = (p[0], p[1], p[2]) else {
            continue;
        };
        let tri = [p0, p1, p2];
        let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
        let nn = n.length_squared();
        if nn.is_nan() || nn <= 0.0 {
            continue;
        }
        // Distance to the plane, plus how far outside the edges.
        let w = [
            (tri[2] - tri[1]).cross(x - tri[1]).dot(n) / nn,
            (tri[0] - tri[2]).cross(x - tri[2]).dot(n) / nn,
            (tri[1] - tri[0]).cross(x - tri[0]).dot(n) / nn,
        ];
        let size = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length());
        let outside: f64 = w.iter().map(|v| (-v).max(0.0)).sum::<f64>() * size;
        let score = (x - tri[0]).dot(n).abs() / nn.sqrt() + outside;
        if score < best.0 {
            let b = barycentric(tri, x);
            let g = t.map(|i| poly.gradients[i as usize]);
            best = (score, g[0] * b[0] + g[1] * b[1] + g[2] * b[2]);
        }
    }
    best.1
}

/// The flat gradient of a piece: [`fit_gradient`] of its points.
pub fn piece_gradient(poly: &Polyhedron) -> DVec3 {
    fit_gradient(
        poly.points
            .iter()
            .copied()
            .zip(poly.scalars.iter().copied()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{warped_hex_grid, Warp};

    #[test]
    fn linear_fields_have_their_exact_gradient() {
        let g = DVec3::new(1.5, -2.0, 0.25);
        let f = |p: DVec3| 3.0 + g.dot(p);
        let p = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.1, 0.0),
            DVec3::new(0.2, 1.0, 0.3),
            DVec3::new(0.1, 0.2, 0.9),
        ];
        assert!((tet_gradient(p, p.map(f)) - g).length() < 1e-12);
        // A cube's eight corners, and every point of an unwarped grid.
        let mesh = warped_hex_grid(2, &Warp::default());
        let s: Vec<f64> = mesh.points.iter().map(|&p| f(p)).collect();
        for pg in point_gradients(&mesh, &s) {
            assert!((pg - g).length() < 1e-9, "{pg} against {g}");
        }
        let nodes = mesh.cells.nodes(0);
        let fit = fit_gradient(
            nodes
                .iter()
                .map(|&n| (mesh.points[n as usize], s[n as usize])),
        );
        assert!((fit - g).length() < 1e-12);
    }

    /// The sum of the module docs, cell after cell on one thread.
    fn sequential_point_gradients(mesh: &Mesh, scalars: &[f64]) -> Vec<DVec3> {
        let n = mesh.points.len();
        let (mut sum, mut weight) = (vec![DVec3::ZERO; n], vec![0.0f64; n]);
        let mut tets = Vec::new();
        for c in 0..mesh.cells.len() {
            tets.clear();
            tetrahedralize_cell(&mesh.cells, c, &mut tets);
            for &t in &tets {
                if let Some((t, gv, vol)) = tet_contribution(mesh, scalars, t) {
                    for i in t {
                        sum[i as usize] += gv;
                        weight[i as usize] += vol;
                    }
                }
            }
        }
        sum.iter()
            .zip(&weight)
            .map(|(&g, &w)| if w > 0.0 { g / w } else { DVec3::ZERO })
            .collect()
    }

    #[test]
    fn gradients_where_wanted_are_every_points_bit_for_bit_and_zero_elsewhere() {
        // More cells than a batch, a curved field, a NaN scalar.
        let mesh = warped_hex_grid(
            33,
            &Warp {
                amplitude: 0.1,
                seed: 3,
            },
        );
        assert!(mesh.cells.len() > GRADIENT_BATCH);
        let mut s: Vec<f64> = mesh
            .points
            .iter()
            .map(|p| (3.0 * p.x).sin() * p.y + p.z * p.z)
            .collect();
        s[1000] = f64::NAN;
        let all = sequential_point_gradients(&mesh, &s);
        assert_eq!(point_gradients(&mesh, &s), all);
        // The cells of a slab and every 97th cell.
        let wanted = |c: usize| {
            let z = mesh.points[mesh.cells.nodes(c)[0] as usize].z;
            (0.4..0.5).contains(&z) || c % 97 == 0
        };
        let some = point_gradients_where(&mesh, &s, wanted);
        let mut want = vec![false; mesh.points.len()];
        for c in (0..mesh.cells.len()).filter(|&c| wanted(c)) {
            for &p in mesh.cells.nodes(c) {
                want[p as usize] = true;
            }
        }
        let kept = want.iter().filter(|&&w| w).count();
        assert!(kept > 1000 && kept < mesh.points.len() / 2, "{kept}");
        for (k, (g, w)) in some.iter().zip(&want).enumerate() {
            if *w {
                assert_eq!(*g, all[k], "point {k}");
            } else {
                assert_eq!(*g, DVec3::ZERO, "point {k}");
            }
        }
    }

    #[test]
    fn flat_sets_have_no_gradient() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        assert_eq!(tet_gradient(p, [0.0, 1.0, 2.0, 3.0]), DVec3::ZERO);
        assert_eq!(fit_gradient([(DVec3::ZERO, 1.0)].into_iter()), DVec3::ZERO);
    }

    #[test]
    fn barycentric_weights_rebuild_the_point() {
        let t = [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(0.0, 3.0, 0.0),
        ];
        let w = [0.2, 0.5, 0.3];
        let x = t[0] * w[0] + t[1] * w[1] + t[2] * w[2];
        let b = barycentric(t, x);
        for k in 0..3 {
            assert!((b[k] - w[k]).abs() < 1e-12);
        }
    }
}
