//! Input checks of the visibility sort: a hostile mesh (point ids out of
//! range, non-finite coordinates, a topology of another mesh, wrong corner
//! counts) or camera becomes a [`VisibilityError`], never a panic.

use super::VisibilityError;
use crate::camera::Camera;
use crate::mesh::topology::Topology;
use crate::mesh::{Mesh, NONE};

/// The first problem with `mesh` and `topo`, if any.
pub(super) fn check_input(mesh: &Mesh, topo: &Topology) -> Option<VisibilityError> {
    let np = mesh.points.len();
    for (i, p) in mesh.points.iter().enumerate() {
        if !p.is_finite() {
            return Some(VisibilityError::NonFinitePoint(i));
        }
    }
    let n = mesh.cells.len();
    if mesh.cells.offsets.len() != n + 1 && n > 0 {
        return Some(VisibilityError::TopologyMismatch { topo: 0, mesh: n });
    }
    for c in 0..n {
        let (a, b) = (
            mesh.cells.offsets[c] as usize,
            mesh.cells.offsets[c + 1] as usize,
        );
        if a > b || b > mesh.cells.conn.len() {
            return Some(VisibilityError::TopologyMismatch { topo: 0, mesh: n });
        }
        for &v in &mesh.cells.conn[a..b] {
            if v as usize >= np {
                return Some(VisibilityError::PointOutOfRange {
                    cell: c,
                    point: v,
                    points: np,
                });
            }
        }
        if let Some(k) = mesh.cells.kinds[c].corner_count() {
            if b - a != k {
                return Some(VisibilityError::TopologyMismatch {
                    topo: b - a,
                    mesh: k,
                });
            }
        }
    }
    for faces in mesh.cells.poly_faces.values() {
        for &v in faces.iter().flatten() {
            if v as usize >= np {
                return Some(VisibilityError::PointOutOfRange {
                    cell: 0,
                    point: v,
                    points: np,
                });
            }
        }
    }
    if topo.cell_face_offsets.len() != n + 1 && !(n == 0 && topo.cell_face_offsets.len() <= 1) {
        return Some(VisibilityError::TopologyMismatch {
            topo: topo.cell_face_offsets.len().saturating_sub(1),
            mesh: n,
        });
    }
    let nf = topo.face_count();
    let ok = topo.face_offsets.len() == nf + 1
        && topo
            .face_offsets
            .last()
            .is_some_and(|&e| e as usize <= topo.face_verts.len())
        && topo.face_verts.iter().all(|&v| (v as usize) < np)
        && topo.cell_faces.iter().all(|&f| (f as usize) < nf)
        && topo
            .face_cells
            .iter()
            .all(|&[a, b]| (a as usize) < n && (b == NONE || (b as usize) < n));
    if !ok {
        return Some(VisibilityError::TopologyMismatch {
            topo: topo.cell_face_offsets.len().saturating_sub(1),
            mesh: n,
        });
    }
    None
}

/// Rejects cameras the sort cannot use.
pub(super) fn check_camera(c: &Camera) -> Result<(), VisibilityError> {
    if c.width == 0 || c.height == 0 {
        return Err(VisibilityError::BadCamera("empty image"));
    }
    if !c.position.is_finite() || !c.forward.is_finite() || c.forward.length_squared() == 0.0 {
        return Err(VisibilityError::BadCamera(
            "non-finite position or direction",
        ));
    }
    if (c.width as u64) * (c.height as u64) > u32::MAX as u64 {
        return Err(VisibilityError::BadCamera("image too large"));
    }
    Ok(())
}
