//! Cells of structured datasets (structured, rectilinear and image grids).
//!
//! A grid of `nx x ny x nz` points numbers point `(i, j, k)` as
//! `i + nx * (j + ny * k)`. Each box of eight neighbouring points becomes a
//! hexahedron in VTK node order: `(i,j,k), (i+1,j,k), (i+1,j+1,k), (i,j+1,k)`,
//! then the same four at `k + 1`. A grid with a dimension of 1 is 2D (or
//! less): its VTK cells are quads, lines or a vertex, which zoovr counts as
//! ignored. The same builder serves the PLOT3D reader.

use crate::mesh::Cells;

/// Number of VTK cells of a structured grid (of whatever dimension).
pub(crate) fn vtk_cell_count(dims: [usize; 3]) -> usize {
    let mut n = 1usize;
    for d in dims {
        if d > 1 {
            n = n.saturating_mul(d - 1);
        }
    }
    if dims.contains(&0) {
        0
    } else {
        n
    }
}

/// Whether the grid has 3D cells (every dimension at least 2).
pub(crate) fn is_3d(dims: [usize; 3]) -> bool {
    dims.iter().all(|&d| d >= 2)
}

/// The hexahedra of a 3D grid (none for a lower-dimensional one). The caller
/// has checked that the point count `nx * ny * nz` fits in `u32`.
pub(crate) fn hexahedra(dims: [usize; 3]) -> Cells {
    if !is_3d(dims) {
        return Cells::default();
    }
    Cells::lattice(dims)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_order_matches_vtk() {
        let c = hexahedra([3, 2, 2]);
        assert_eq!(c.len(), 2);
        assert_eq!(c.nodes(0), &[0, 1, 4, 3, 6, 7, 10, 9]);
        assert_eq!(c.nodes(1), &[1, 2, 5, 4, 7, 8, 11, 10]);
        assert_eq!(vtk_cell_count([3, 2, 2]), 2);
        assert_eq!(vtk_cell_count([3, 1, 4]), 6);
        assert!(hexahedra([3, 1, 4]).is_empty());
    }
}
