//! Unique faces and face adjacency of the 3D cells.
//!
//! Every cell face is identified by the sorted set of its point ids. Faces
//! seen from two cells become one interior face with both cells; faces seen
//! from one cell are boundary faces. A face's stored vertex order is the one
//! of the first cell that listed it (outward for that cell when the cell is
//! positively oriented). Ids only: no geometry is stored here.

use std::collections::HashMap;

use super::{Cells, NONE};

/// Unique faces and the cells on each side.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// `face_offsets[f]..face_offsets[f + 1]` indexes `face_verts`.
    pub face_offsets: Vec<u32>,
    /// Point ids of each unique face, in the order of its first cell.
    pub face_verts: Vec<u32>,
    /// `[first cell, second cell]`; the second is [`NONE`] on the boundary.
    pub face_cells: Vec<[u32; 2]>,
    /// Local face index of the face in each of its two cells.
    pub face_local: Vec<[u8; 2]>,
    /// `cell_face_offsets[c]..cell_face_offsets[c + 1]` indexes `cell_faces`.
    pub cell_face_offsets: Vec<u32>,
    /// Unique face id of each local face of each cell (local face order).
    pub cell_faces: Vec<u32>,
    /// Faces shared by more than two cells (non-manifold), left as boundary
    /// faces of the extra cells; counted here.
    pub nonmanifold_faces: usize,
}

#[derive(Clone, PartialEq, Eq, Hash)]
enum FaceKey {
    Small([u32; 6]),
    Large(Box<[u32]>),
}

fn face_key(verts: &[u32]) -> FaceKey {
    if verts.len() <= 6 {
        let mut k = [NONE; 6];
        k[..verts.len()].copy_from_slice(verts);
        k[..verts.len()].sort_unstable();
        FaceKey::Small(k)
    } else {
        let mut v = verts.to_vec();
        v.sort_unstable();
        FaceKey::Large(v.into_boxed_slice())
    }
}

impl Topology {
    /// Builds unique faces and adjacency for `cells`.
    pub fn build(cells: &Cells) -> Topology {
        let n = cells.len();
        let mut t = Topology {
            face_offsets: vec![0],
            cell_face_offsets: Vec::with_capacity(n + 1),
            ..Default::default()
        };
        t.cell_face_offsets.push(0);
        let mut map: HashMap<FaceKey, u32> = HashMap::with_capacity(n * 3);
        for c in 0..n {
            cells.for_each_face(c, |local, verts| {
                let key = face_key(verts);
                let id = match map.get(&key) {
                    Some(&f)
                        if t.face_cells[f as usize][1] == NONE
                            && t.face_cells[f as usize][0] != c as u32 =>
                    {
                        t.face_cells[f as usize][1] = c as u32;
                        t.face_local[f as usize][1] = local as u8;
                        f
                    }
                    Some(_) => {
                        t.nonmanifold_faces += 1;
                        t.push_face(c, local, verts)
                    }
                    None => {
                        let f = t.push_face(c, local, verts);
                        map.insert(key, f);
                        f
                    }
                };
                t.cell_faces.push(id);
            });
            t.cell_face_offsets.push(t.cell_faces.len() as u32);
        }
        t
    }

    fn push_face(&mut self, c: usize, local: usize, verts: &[u32]) -> u32 {
        let id = self.face_cells.len() as u32;
        self.face_verts.extend_from_slice(verts);
        self.face_offsets.push(self.face_verts.len() as u32);
        self.face_cells.push([c as u32, NONE]);
        self.face_local.push([local as u8, 0]);
        id
    }

    /// Number of unique faces.
    pub fn face_count(&self) -> usize {
        self.face_cells.len()
    }

    /// Point ids of face `f`.
    #[inline]
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_verts[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Faces of cell `c` in local order.
    #[inline]
    pub fn faces_of(&self, c: usize) -> &[u32] {
        &self.cell_faces[self.cell_face_offsets[c] as usize..self.cell_face_offsets[c + 1] as usize]
    }

    /// Whether face `f` is on the boundary.
    #[inline]
    pub fn is_boundary(&self, f: usize) -> bool {
        self.face_cells[f][1] == NONE
    }

    /// The cell across face `f` from cell `c` ([`NONE`] on the boundary).
    #[inline]
    pub fn neighbour(&self, f: usize, c: u32) -> u32 {
        let [a, b] = self.face_cells[f];
        if a == c {
            b
        } else {
            a
        }
    }

    /// Number of boundary faces.
    pub fn boundary_face_count(&self) -> usize {
        self.face_cells.iter().filter(|fc| fc[1] == NONE).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::CellKind;

    #[test]
    fn two_hexes_share_one_face() {
        let mut cells = Cells::default();
        cells.push(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
        cells.push(CellKind::Hexahedron, &[1, 8, 9, 2, 5, 10, 11, 6]);
        let t = Topology::build(&cells);
        assert_eq!(t.face_count(), 11);
        assert_eq!(t.boundary_face_count(), 10);
        let shared = t.faces_of(0)[1] as usize;
        assert_eq!(t.face_cells[shared], [0, 1]);
        assert_eq!(t.neighbour(shared, 1), 0);
    }
}
