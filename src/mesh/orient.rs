//! Orientation repair: inverted cells are mirrored into positively oriented
//! ones by reordering their nodes.
//!
//! Zoo kinds use [`CellKind::reorder_for_inversion`] (swap the two caps of a
//! prism or hexahedron, two base nodes of a tetrahedron or pyramid); general
//! polyhedra reverse the vertex order of every face, which flips every face
//! normal. Reordering never changes point ids, so the consistent
//! tetrahedralisation of a repaired cell is the same set of tetrahedra with
//! the opposite orientation (see `tests/mesh_tetra.rs`). Degenerate cells are
//! left alone: they have no orientation to repair.

use super::quality::{cell_volumes, orientations, Orientation};
use super::{CellKind, Cells, Mesh};

/// Mirrors cell `c` in place (reverses its orientation).
pub fn flip_cell(cells: &mut Cells, c: usize) {
    let kind = cells.kinds[c];
    if kind == CellKind::Polyhedron {
        if let Some(faces) = cells.poly_faces.get_mut(&(c as u32)) {
            for f in faces.iter_mut() {
                f.reverse();
            }
        }
        return;
    }
    let perm = kind.reorder_for_inversion();
    let (a, b) = (cells.offsets[c] as usize, cells.offsets[c + 1] as usize);
    let Some(nodes) = cells.conn.get_mut(a..b) else {
        return;
    };
    if nodes.len() != perm.len() {
        return;
    }
    let old: Vec<u32> = nodes.to_vec();
    for (i, &p) in perm.iter().enumerate() {
        nodes[i] = old[p as usize];
    }
}

/// Flips every cell whose orientation is [`Orientation::Inverted`]; returns
/// how many were flipped.
pub fn repair_with(cells: &mut Cells, orient: &[Orientation]) -> usize {
    let mut n = 0;
    for (c, o) in orient.iter().enumerate().take(cells.len()) {
        if *o == Orientation::Inverted {
            flip_cell(cells, c);
            n += 1;
        }
    }
    n
}

/// Computes volumes and flips every inverted cell of `mesh`; returns how
/// many were flipped. Afterwards no cell has a negative volume except
/// degenerate ones.
pub fn repair_orientation(mesh: &mut Mesh) -> usize {
    let vols = cell_volumes(mesh);
    let orient = orientations(mesh, &vols);
    repair_with(&mut mesh.cells, &orient)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::quality::cell_volume;
    use glam::DVec3;

    #[test]
    fn every_kind_flips_to_the_opposite_volume() {
        let mut pts = Vec::new();
        for k in 0..2 {
            for i in 0..6 {
                let a = i as f64 * std::f64::consts::TAU / 6.0;
                pts.push(DVec3::new(a.cos(), a.sin(), k as f64));
            }
        }
        // points 12.. : a second ring of 5 for the pentagonal prism
        for k in 0..2 {
            for i in 0..5 {
                let a = i as f64 * std::f64::consts::TAU / 5.0;
                pts.push(DVec3::new(a.cos(), a.sin(), 2.0 + k as f64));
            }
        }
        let mut cells = Cells::default();
        cells.push(CellKind::Tetra, &[0, 1, 2, 6]);
        cells.push(CellKind::Pyramid, &[0, 1, 3, 4, 6]);
        cells.push(CellKind::Wedge, &[0, 2, 4, 6, 8, 10]);
        cells.push(CellKind::Hexahedron, &[0, 1, 3, 4, 6, 7, 9, 10]);
        cells.push(CellKind::HexagonalPrism, &(0..12).collect::<Vec<_>>());
        cells.push(CellKind::PentagonalPrism, &(12..22).collect::<Vec<_>>());
        cells.push_polyhedron(vec![
            vec![0, 2, 1],
            vec![0, 1, 6],
            vec![1, 2, 6],
            vec![2, 0, 6],
        ]);
        for c in 0..cells.len() {
            let v = cell_volume(&cells, &pts, c);
            assert!(v.abs() > 1e-3, "cell {c} volume {v}");
            flip_cell(&mut cells, c);
            let w = cell_volume(&cells, &pts, c);
            assert!((v + w).abs() < 1e-12, "cell {c}: {v} then {w}");
        }
    }
}
