//! Cell quality: signed volumes, inverted / degenerate / repeated-index
//! cells, and nonplanar quad faces.
//!
//! **Signed volume** by the divergence theorem over the cell's faces, each
//! split into triangles by the smallest-vertex rule
//! ([`super::tetra::triangulate_face`]):
//! `V = 1/6 * sum (a - o) . ((b - o) x (c - o))` over the face triangles
//! `(a, b, c)`, with `o` the cell's first node (any origin gives the same
//! value; a local one keeps round-off small). This is exactly the volume the
//! `faces` field and the consistent tetrahedra enclose, so "tet volumes sum
//! to the cell volume" is a meaningful test of [`super::tetra`]. Positive
//! means the VTK orientation (outward faces).
//!
//! **Degenerate** cells have `|V| <= DEGENERATE_VOLUME_REL * d^3`, `d` the
//! diagonal of the cell's own bounding box
//! ([`crate::numeric::tolerance::DEGENERATE_VOLUME_REL`]); **inverted** cells
//! have a negative volume and are not degenerate.
//!
//! **Nonplanarity** of a quad face `(a, b, c, d)` is the distance of its
//! vertices from the face's mean plane: the plane through the centroid with
//! normal `(c - a) x (d - b)` (the Newell normal of a quad). All four
//! vertices are at the same distance, `|(b - a) . n| / 2`, half the distance
//! between the lines of the two diagonals. It is reported relative to the
//! face's longer diagonal against
//! [`crate::numeric::tolerance::NONPLANAR_REPORT_REL`], for each quad face of
//! each cell (a face shared by two cells counts twice). This reproduces the
//! nonplanar-face counts of the real datasets exactly: bluntfin 2,
//! disk_out_ref 2,316, angular_sector 0, can_crush 24,569 (the last step of
//! `can_crush/series/`; `can.vtu`, a different state, gives 24,570: the
//! 24,570th face sits 1.3e-6 above the threshold).

use glam::DVec3;
use rayon::prelude::*;

use super::tetra::triangulate_face;
use super::{Cells, Mesh};
use crate::numeric::tolerance::{DEGENERATE_VOLUME_REL, NONPLANAR_REPORT_REL};

/// How a cell's signed volume classifies it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Orientation {
    /// Positive volume: faces outward in the kind's node order.
    Positive,
    /// Negative volume: the cell is mirrored (left-handed).
    Inverted,
    /// Volume zero up to [`DEGENERATE_VOLUME_REL`].
    Degenerate,
}

/// Signed volume of cell `c` (positive for VTK orientation). Nodes out of
/// range of `points` count as the origin (readers reject such cells).
pub fn cell_volume(cells: &Cells, points: &[DVec3], c: usize) -> f64 {
    let p = |i: u32| points.get(i as usize).copied().unwrap_or(DVec3::ZERO);
    let o = cells.nodes(c).first().map_or(DVec3::ZERO, |&i| p(i));
    let mut six_v = 0.0;
    cells.for_each_face(c, |_, face| {
        triangulate_face(face, |[a, b, cc]| {
            let (a, b, cc) = (p(a) - o, p(b) - o, p(cc) - o);
            six_v += a.dot(b.cross(cc));
        });
    });
    six_v / 6.0
}

/// Signed volumes of all cells (parallel).
pub fn cell_volumes(mesh: &Mesh) -> Vec<f64> {
    (0..mesh.cells.len())
        .into_par_iter()
        .map(|c| cell_volume(&mesh.cells, &mesh.points, c))
        .collect()
}

/// Diagonal of the bounding box of cell `c`'s nodes.
pub fn cell_diagonal(cells: &Cells, points: &[DVec3], c: usize) -> f64 {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &i in cells.nodes(c) {
        if let Some(&q) = points.get(i as usize) {
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    if lo.x > hi.x {
        0.0
    } else {
        (hi - lo).length()
    }
}

/// Classifies cell `c` given its signed volume.
pub fn classify(cells: &Cells, points: &[DVec3], c: usize, volume: f64) -> Orientation {
    let d = cell_diagonal(cells, points, c);
    if volume.abs() <= DEGENERATE_VOLUME_REL * d * d * d || !volume.is_finite() {
        Orientation::Degenerate
    } else if volume < 0.0 {
        Orientation::Inverted
    } else {
        Orientation::Positive
    }
}

/// Whether cell `c` uses a point id twice (in its node list, or within one
/// face of a general polyhedron).
pub fn has_repeated_index(cells: &Cells, c: usize) -> bool {
    let nodes = cells.nodes(c);
    let mut buf = [0u32; 12];
    if nodes.len() <= buf.len() && cells.kinds[c] != super::CellKind::Polyhedron {
        let b = &mut buf[..nodes.len()];
        b.copy_from_slice(nodes);
        b.sort_unstable();
        return b.windows(2).any(|w| w[0] == w[1]);
    }
    let mut repeated = false;
    cells.for_each_face(c, |_, face| {
        let mut v = face.to_vec();
        v.sort_unstable();
        repeated |= v.windows(2).any(|w| w[0] == w[1]);
    });
    repeated
}

/// Distance of the fourth vertex of quad `q` from the plane of the first
/// three (0 when the first three are collinear).
pub fn quad_nonplanarity(points: &[DVec3], q: [u32; 4]) -> f64 {
    let p = |i: u32| points.get(i as usize).copied().unwrap_or(DVec3::ZERO);
    let (a, b, c, d) = (p(q[0]), p(q[1]), p(q[2]), p(q[3]));
    let n = (b - a).cross(c - a);
    let len = n.length();
    if len == 0.0 || !len.is_finite() {
        return 0.0;
    }
    (n.dot(d - a) / len).abs()
}

/// Distance of the quad's vertices from its mean plane (through the
/// centroid, normal `(c - a) x (d - b)`), i.e. half the distance between the
/// lines of its diagonals, relative to the longer diagonal. 0 when the
/// diagonals are parallel or of zero length.
pub fn quad_nonplanarity_rel(points: &[DVec3], q: [u32; 4]) -> f64 {
    let p = |i: u32| points.get(i as usize).copied().unwrap_or(DVec3::ZERO);
    let (a, b, c, d) = (p(q[0]), p(q[1]), p(q[2]), p(q[3]));
    let (e, f) = (c - a, d - b);
    let n = e.cross(f);
    let len = n.length();
    let diag = e.length().max(f.length());
    if len == 0.0 || !len.is_finite() || !(diag > 0.0 && diag.is_finite()) {
        return 0.0;
    }
    0.5 * (n.dot(b - a) / len).abs() / diag
}

/// Per-cell counts of the quality checks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QualityCounts {
    /// Cells with negative signed volume (not degenerate).
    pub inverted: usize,
    /// Cells with (near) zero volume.
    pub degenerate: usize,
    /// Cells that use a point id twice.
    pub repeated_index: usize,
    /// Quad faces of cells (counted per cell) whose distance from their mean
    /// plane exceeds [`NONPLANAR_REPORT_REL`] of the face's longer diagonal.
    pub nonplanar_faces: usize,
    /// Largest [`quad_nonplanarity_rel`] over all quad faces.
    pub max_nonplanarity: f64,
    /// Sum of `|V|` over all cells.
    pub total_volume: f64,
}

/// Orientation of every cell from its volume.
pub fn orientations(mesh: &Mesh, volumes: &[f64]) -> Vec<Orientation> {
    (0..mesh.cells.len())
        .into_par_iter()
        .map(|c| classify(&mesh.cells, &mesh.points, c, volumes[c]))
        .collect()
}

/// Counts inverted, degenerate, repeated-index cells and nonplanar faces.
pub fn quality_counts(mesh: &Mesh, volumes: &[f64], orient: &[Orientation]) -> QualityCounts {
    let cells = &mesh.cells;
    let per_cell = |c: usize| {
        let mut q = QualityCounts {
            total_volume: volumes[c].abs(),
            ..Default::default()
        };
        match orient[c] {
            Orientation::Inverted => q.inverted = 1,
            Orientation::Degenerate => q.degenerate = 1,
            Orientation::Positive => {}
        }
        q.repeated_index = has_repeated_index(cells, c) as usize;
        cells.for_each_face(c, |_, f| {
            if let [a, b, cc, d] = *f {
                let np = quad_nonplanarity_rel(&mesh.points, [a, b, cc, d]);
                q.max_nonplanarity = q.max_nonplanarity.max(np);
                q.nonplanar_faces += (np > NONPLANAR_REPORT_REL) as usize;
            }
        });
        q
    };
    (0..cells.len())
        .into_par_iter()
        .map(per_cell)
        .reduce(QualityCounts::default, |a, b| QualityCounts {
            inverted: a.inverted + b.inverted,
            degenerate: a.degenerate + b.degenerate,
            repeated_index: a.repeated_index + b.repeated_index,
            nonplanar_faces: a.nonplanar_faces + b.nonplanar_faces,
            max_nonplanarity: a.max_nonplanarity.max(b.max_nonplanarity),
            total_volume: a.total_volume + b.total_volume,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::CellKind;

    fn cube() -> Vec<DVec3> {
        (0..8)
            .map(|i| {
                let (x, y) = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)][i % 4];
                DVec3::new(x, y, (i / 4) as f64)
            })
            .collect()
    }

    #[test]
    fn unit_cube_volume_and_mirror() {
        let pts = cube();
        let mut cells = Cells::default();
        cells.push(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
        cells.push(CellKind::Hexahedron, &[4, 5, 6, 7, 0, 1, 2, 3]);
        cells.push(CellKind::Wedge, &[0, 1, 2, 4, 5, 6]);
        cells.push(CellKind::Pyramid, &[0, 1, 2, 3, 6]);
        cells.push(CellKind::Tetra, &[0, 1, 3, 4]);
        // A wedge whose first triangle's normal points at the second is
        // positive (VTK parametric orientation).
        let want = [1.0, -1.0, 0.5, 1.0 / 3.0, 1.0 / 6.0];
        for (c, w) in want.iter().enumerate() {
            let v = cell_volume(&cells, &pts, c);
            assert!((v - w).abs() < 1e-14, "cell {c}: {v} vs {w}");
        }
        assert_eq!(classify(&cells, &pts, 1, -1.0), Orientation::Inverted);
    }

    #[test]
    fn flat_and_repeated_cells() {
        let mut pts = cube();
        for p in pts.iter_mut().skip(4) {
            p.z = 0.0; // squash the top onto the bottom
        }
        let mut cells = Cells::default();
        cells.push(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
        cells.push(CellKind::Tetra, &[0, 1, 1, 3]);
        let v = cell_volume(&cells, &pts, 0);
        assert_eq!(classify(&cells, &pts, 0, v), Orientation::Degenerate);
        assert!(!has_repeated_index(&cells, 0));
        assert!(has_repeated_index(&cells, 1));
    }

    #[test]
    fn nonplanarity_of_a_lifted_corner() {
        let pts = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1., 1., 0.),
            DVec3::new(0., 1., 0.25),
        ];
        assert!((quad_nonplanarity(&pts, [0, 1, 2, 3]) - 0.25).abs() < 1e-15);
        assert_eq!(quad_nonplanarity(&pts, [0, 0, 2, 3]), 0.0);
    }
}
