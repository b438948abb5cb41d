//! Cells a file marks as not to be drawn: VTK's ghost array.
//!
//! VTK and ParaView flag cells in a cell array named `vtkGhostType`
//! (unsigned char, one value per cell) whose bits are VTK's ghost types:
//! [`DUPLICATE_CELL`] (1, a copy of a cell that another piece owns) and
//! [`HIDDEN_CELL`] (32, not part of the data: blanked or inactive cells,
//! e.g. the inactive cells of a corner-point reservoir grid). Points have
//! their own array of the same name in point data, with
//! [`DUPLICATE_POINT`] (1) and [`HIDDEN_POINT`] (2). ParaView draws
//! neither hidden nor duplicate cells, and neither does zoovr:
//! `render::Geometry::build` calls [`remove_ghost_cells`] before it merges
//! points and builds topology (unless `--show-hidden`), so every mode, the
//! visibility order and the reference ray caster see only the cells left.
//!
//! - [`cell_flags`] reads the cell array. The readers keep the file's type
//!   (integers widened, floats as they are); any numeric type is accepted
//!   as long as the array has one component, one tuple per cell and every
//!   value is a whole number in 0..=255. Anything else is a [`GhostError`]
//!   naming the array, never a silent guess.
//! - [`GhostCounts`]: hidden and duplicate cells, as `zoovr info` prints
//!   them (a cell with both bits counts in both).
//! - [`remove_ghost_cells`]: drops the cells with either bit, the tuples of
//!   every cell array that belong to them, and the points only they used
//!   ([`super::subset::keep_cells`]). The scalar range of the default
//!   transfer function is then taken over what is drawn, as ParaView
//!   computes ranges over non-ghost data.
//!
//! Point flags do not remove cells: whether a cell is drawn is decided by
//! its own flag alone, and a drawn cell needs all its nodes (positions and
//! values) whatever the point array says about them.

use thiserror::Error;

use super::data::DataArray;
use super::subset::keep_cells;
use super::Mesh;

/// Name of VTK's ghost arrays (cell data for cells, point data for points).
pub const GHOST_ARRAY: &str = "vtkGhostType";
/// Cell flag: a copy of a cell that another piece owns.
pub const DUPLICATE_CELL: u8 = 1;
/// Cell flag: not part of the data (blanked, inactive).
pub const HIDDEN_CELL: u8 = 32;
/// Point flag: a copy of a point that another piece owns.
pub const DUPLICATE_POINT: u8 = 1;
/// Point flag: not part of the data.
pub const HIDDEN_POINT: u8 = 2;
/// The cell flags that keep a cell from being drawn.
pub const NOT_DRAWN: u8 = DUPLICATE_CELL | HIDDEN_CELL;

/// A cell ghost array zoovr cannot read as flags.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum GhostError {
    #[error("cell array '{GHOST_ARRAY}' has {got} tuples but the mesh has {want} cells")]
    WrongLength { got: usize, want: usize },
    #[error("cell array '{GHOST_ARRAY}' has {0} components; a ghost array has 1")]
    Components(usize),
    #[error(
        "cell array '{GHOST_ARRAY}': value {value} of cell {cell} is not a ghost flag \
         (a whole number in 0..=255)"
    )]
    BadValue { cell: usize, value: f64 },
}

/// Hidden and duplicate cells of a mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GhostCounts {
    /// Cells with [`HIDDEN_CELL`].
    pub hidden: usize,
    /// Cells with [`DUPLICATE_CELL`].
    pub duplicate: usize,
    /// Cells with either (those left out of a render).
    pub not_drawn: usize,
}

impl GhostCounts {
    /// Counts the flags of `mesh`; all zero without a cell ghost array.
    pub fn of(mesh: &Mesh) -> Result<GhostCounts, GhostError> {
        let mut n = GhostCounts::default();
        for g in cell_flags(mesh)?.unwrap_or_default() {
            n.hidden += usize::from(g & HIDDEN_CELL != 0);
            n.duplicate += usize::from(g & DUPLICATE_CELL != 0);
            n.not_drawn += usize::from(g & NOT_DRAWN != 0);
        }
        Ok(n)
    }
}

/// The cell ghost array of `mesh`, if it has one.
pub fn cell_ghost_array(mesh: &Mesh) -> Option<&DataArray> {
    mesh.cell_data.iter().find(|a| a.name == GHOST_ARRAY)
}

/// The flags of every cell from the cell ghost array (`None` without one);
/// see the module docs for what is accepted.
pub fn cell_flags(mesh: &Mesh) -> Result<Option<Vec<u8>>, GhostError> {
    let Some(a) = cell_ghost_array(mesh) else {
        return Ok(None);
    };
    if a.components != 1 {
        return Err(GhostError::Components(a.components));
    }
    let want = mesh.cells.len();
    if a.data.len() != want {
        return Err(GhostError::WrongLength {
            got: a.data.len(),
            want,
        });
    }
    (0..want)
        .map(|cell| {
            let value = a.data.get(cell);
            if value.fract() == 0.0 && (0.0..=255.0).contains(&value) {
                Ok(value as u8)
            } else {
                Err(GhostError::BadValue { cell, value })
            }
        })
        .collect::<Result<Vec<u8>, _>>()
        .map(Some)
}

/// Removes the cells flagged hidden or duplicate (see the module docs);
/// returns how many were removed (0 without a ghost array).
pub fn remove_ghost_cells(mesh: &mut Mesh) -> Result<usize, GhostError> {
    let Some(flags) = cell_flags(mesh)? else {
        return Ok(0);
    };
    let keep: Vec<bool> = flags.iter().map(|&g| g & NOT_DRAWN == 0).collect();
    Ok(keep_cells(mesh, &keep))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{ghost_grid, ghost_grid_flags, warped_hex_grid, Warp};
    use crate::mesh::data::ArrayData;

    fn with_ghosts(data: ArrayData, components: usize) -> Mesh {
        let mut m = warped_hex_grid(2, &Warp::default());
        m.cell_data.push(DataArray {
            name: GHOST_ARRAY.into(),
            components,
            data,
            vtk_type: "UInt8".into(),
        });
        m
    }

    #[test]
    fn counts_and_removes_flagged_cells() {
        let n = 4;
        let mut m = ghost_grid(n, &Warp::default());
        let c = GhostCounts::of(&m).unwrap();
        let (mut hidden, mut dup, mut either) = (0, 0, 0);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let g = ghost_grid_flags(n, i, j, k);
                    hidden += usize::from(g & 32 != 0);
                    dup += usize::from(g & 1 != 0);
                    either += usize::from(g != 0);
                }
            }
        }
        assert!(hidden > 0 && dup > 0 && either < hidden + dup);
        assert_eq!((c.hidden, c.duplicate, c.not_drawn), (hidden, dup, either));
        assert_eq!(remove_ghost_cells(&mut m).unwrap(), either);
        m.sanity_check().unwrap();
        assert_eq!(m.cells.len(), n * n * n - either);
        assert_eq!(GhostCounts::of(&m).unwrap(), GhostCounts::default());
        // no flags left, nothing more to remove
        assert_eq!(remove_ghost_cells(&mut m).unwrap(), 0);
    }

    #[test]
    fn other_bits_and_other_types_are_read() {
        // 2 and 4 are not cell flags that hide; floats holding whole numbers are fine
        let data = ArrayData::F32(vec![0.0, 2.0, 4.0, 32.0, 33.0, 1.0, 8.0, 0.0]);
        let mut m = with_ghosts(data, 1);
        let c = GhostCounts::of(&m).unwrap();
        assert_eq!((c.hidden, c.duplicate, c.not_drawn), (2, 2, 3));
        assert_eq!(remove_ghost_cells(&mut m).unwrap(), 3);
        assert_eq!(m.cells.len(), 5);
        assert!(cell_flags(&warped_hex_grid(2, &Warp::default()))
            .unwrap()
            .is_none());
    }

    #[test]
    fn malformed_arrays_are_errors() {
        let m = with_ghosts(ArrayData::Int(vec![0; 5]), 1);
        assert_eq!(
            remove_ghost_cells(&mut m.clone()),
            Err(GhostError::WrongLength { got: 5, want: 8 })
        );
        let msg = GhostCounts::of(&m).unwrap_err().to_string();
        assert!(msg.contains("vtkGhostType") && msg.contains('5'), "{msg}");
        let m = with_ghosts(ArrayData::Int(vec![0; 16]), 2);
        assert_eq!(GhostCounts::of(&m), Err(GhostError::Components(2)));
        for bad in [-1.0, 256.0, 0.5, f64::NAN] {
            let mut v = vec![0.0; 8];
            v[3] = bad;
            let m = with_ghosts(ArrayData::F64(v), 1);
            match cell_flags(&m) {
                Err(GhostError::BadValue { cell: 3, .. }) => {}
                other => panic!("{bad}: {other:?}"),
            }
        }
    }
}
