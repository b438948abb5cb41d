//! Unique faces and face adjacency of the 3D cells.
//!
//! Every cell face is identified by the sorted set of its point ids. Faces
//! seen from two cells become one interior face with both cells; faces seen
//! from one cell are boundary faces. A face's stored vertex order is the one
//! of the first cell that listed it (outward for that cell when the cell is
//! positively oriented). Ids only: no geometry is stored here.
//!
//! How [`Topology::build`] works (sort-based, no hash map):
//! 1. Every local face of every cell gets a *slot* (`cell_face_offsets` is
//!    the CSR over cells). In parallel (rayon, chunks of cells), each slot
//!    writes a 20-byte key: its sorted point ids padded with [`NONE`] (faces
//!    of up to 4 points) followed by the slot number. Faces with more than 4
//!    points (prism caps, polyhedron faces) go to a separate list of full
//!    sorted id vectors.
//! 2. The keys are sorted in parallel; equal faces become runs. In each run
//!    the second slot is linked to the first one; further slots are
//!    non-manifold (kept as boundary faces of their cells and counted).
//! 3. One ordered pass over the cells turns links into face ids: a slot that
//!    starts a face creates it (ids therefore follow the first cell that
//!    lists a face, as a hash-map build would give), a linked slot joins the
//!    face of its partner. A face listed twice by the same cell is not an
//!    interior face; it is also counted as non-manifold.
//!
//! Peak extra memory is the key array (20 bytes per cell face) plus one
//! `u32` per cell face; 1M hexahedra connect in well under a second on two
//! cores (see `benches/load.rs`).

use rayon::prelude::*;
use thiserror::Error;

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

/// A broken invariant found by [`Topology::sanity_check`].
#[derive(Debug, Error, PartialEq, Eq)]
#[error("topology invariant broken: {0}")]
pub struct TopologyError(pub String);

/// Cells per parallel work item when writing keys.
const CHUNK: usize = 1 << 14;

/// Key of a face of up to 4 points: sorted ids padded with [`NONE`], then the
/// slot. Larger faces get the sentinel key `[NONE; 4]` (matched elsewhere).
#[inline]
fn small_key(verts: &[u32], slot: u32) -> [u32; 5] {
    let mut k = [NONE, NONE, NONE, NONE, slot];
    if verts.len() <= 4 {
        k[..verts.len()].copy_from_slice(verts);
        k[..4].sort_unstable();
    }
    k
}

impl Topology {
    /// Builds unique faces and adjacency for `cells`.
    pub fn build(cells: &Cells) -> Topology {
        let n = cells.len();
        let mut cell_face_offsets = Vec::with_capacity(n + 1);
        cell_face_offsets.push(0u32);
        let mut total = 0u32;
        for c in 0..n {
            total = total.saturating_add(cells.face_count(c) as u32);
            cell_face_offsets.push(total);
        }
        let slots = total as usize;

        // 1. Keys, in parallel over chunks of cells.
        let mut keys: Vec<[u32; 5]> = vec![[0; 5]; slots];
        let mut jobs = Vec::with_capacity(n / CHUNK + 1);
        let mut rest: &mut [[u32; 5]] = &mut keys;
        let mut c0 = 0;
        while c0 < n {
            let c1 = (c0 + CHUNK).min(n);
            let len = (cell_face_offsets[c1] - cell_face_offsets[c0]) as usize;
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            jobs.push((c0, c1, head));
            c0 = c1;
        }
        let offsets = &cell_face_offsets;
        let mut large: Vec<(Vec<u32>, u32)> = jobs
            .into_par_iter()
            .flat_map_iter(|(c0, c1, out)| {
                let base = offsets[c0];
                let mut large = Vec::new();
                let mut k = 0usize;
                for c in c0..c1 {
                    cells.for_each_face(c, |_, verts| {
                        let slot = base + k as u32;
                        if let Some(o) = out.get_mut(k) {
                            *o = small_key(verts, slot);
                        }
                        if verts.len() > 4 {
                            let mut v = verts.to_vec();
                            v.sort_unstable();
                            large.push((v, slot));
                        }
                        k += 1;
                    });
                }
                large
            })
            .collect();

        // 2. Sort and link runs of equal faces.
        keys.par_sort_unstable();
        let mut link = vec![NONE; slots];
        let mut nonmanifold = 0usize;
        let mut pairs = 0usize;
        let mut i = 0;
        while i < keys.len() {
            let k = keys[i];
            if k[..4] == [NONE; 4] {
                break; // sentinels sort last
            }
            let mut j = i + 1;
            while j < keys.len() && keys[j][..4] == k[..4] {
                j += 1;
            }
            if j - i >= 2 {
                link[keys[i + 1][4] as usize] = k[4];
                pairs += 1;
                nonmanifold += j - i - 2;
            }
            i = j;
        }
        drop(keys);
        large.par_sort_unstable();
        let mut i = 0;
        while i < large.len() {
            let mut j = i + 1;
            while j < large.len() && large[j].0 == large[i].0 {
                j += 1;
            }
            if j - i >= 2 {
                link[large[i + 1].1 as usize] = large[i].1;
                pairs += 1;
                nonmanifold += j - i - 2;
            }
            i = j;
        }
        drop(large);

        // 3. Ordered pass: links become face ids.
        let n_faces = slots - pairs;
        let mut t = Topology {
            face_offsets: Vec::with_capacity(n_faces + 1),
            face_verts: Vec::with_capacity(n_faces * 4),
            face_cells: Vec::with_capacity(n_faces),
            face_local: Vec::with_capacity(n_faces),
            cell_face_offsets,
            cell_faces: Vec::new(),
            nonmanifold_faces: nonmanifold,
        };
        t.face_offsets.push(0);
        let mut face_of = link;
        for c in 0..n {
            let first_slot = t.cell_face_offsets[c];
            cells.for_each_face(c, |local, verts| {
                let slot = first_slot + local as u32;
                let Some(l) = face_of.get(slot as usize).copied() else {
                    return;
                };
                let id = if l == NONE || l >= first_slot {
                    if l != NONE {
                        t.nonmanifold_faces += 1; // same cell lists it twice
                    }
                    t.push_face(c, local, verts)
                } else {
                    let f = face_of[l as usize] as usize;
                    t.face_cells[f][1] = c as u32;
                    t.face_local[f][1] = local as u8;
                    f as u32
                };
                face_of[slot as usize] = id;
            });
        }
        t.cell_faces = face_of;
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

    /// Number of cells the topology was built for.
    pub fn cell_count(&self) -> usize {
        self.cell_face_offsets.len().saturating_sub(1)
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

    /// Checks every invariant against the cells the topology was built from:
    /// counts agree; each local face of each cell maps to a unique face whose
    /// cells contain that cell at the recorded local index and whose vertex
    /// set equals the cell's local face; interior faces join two distinct
    /// cells; no two unique faces of two cells have the same vertex set unless
    /// they are counted as non-manifold.
    pub fn sanity_check(&self, cells: &Cells) -> Result<(), TopologyError> {
        let err = |s: String| Err(TopologyError(s));
        let n = cells.len();
        if self.cell_face_offsets.len() != n + 1 {
            return err(format!(
                "{} cell face offsets for {n} cells",
                self.cell_face_offsets.len()
            ));
        }
        let nf = self.face_count();
        if self.face_offsets.len() != nf + 1 || self.face_local.len() != nf {
            return err("face array lengths disagree".into());
        }
        if self.face_offsets.last().copied() != Some(self.face_verts.len() as u32) {
            return err("face offsets do not end at face_verts.len()".into());
        }
        if self.cell_faces.len() != *self.cell_face_offsets.last().unwrap_or(&0) as usize {
            return err("cell_faces length disagrees with its offsets".into());
        }
        let mut uses = vec![0u8; nf];
        for c in 0..n {
            let faces = self.faces_of(c);
            if faces.len() != cells.face_count(c) {
                return err(format!("cell {c}: {} faces recorded", faces.len()));
            }
            let mut bad = None;
            cells.for_each_face(c, |local, verts| {
                if bad.is_some() {
                    return;
                }
                let f = faces[local] as usize;
                if f >= nf {
                    bad = Some(format!("cell {c} face {local}: id {f} out of range"));
                    return;
                }
                let side = match self.face_cells[f] {
                    [a, _] if a == c as u32 && self.face_local[f][0] as usize == local % 256 => 0,
                    [_, b] if b == c as u32 && self.face_local[f][1] as usize == local % 256 => 1,
                    fc => {
                        bad = Some(format!("cell {c} face {local}: face {f} has cells {fc:?}"));
                        return;
                    }
                };
                let _ = side;
                uses[f] = uses[f].saturating_add(1);
                let mut a = verts.to_vec();
                let mut b = self.face(f).to_vec();
                a.sort_unstable();
                b.sort_unstable();
                if a != b {
                    bad = Some(format!("cell {c} face {local}: vertices {a:?} vs {b:?}"));
                }
            });
            if let Some(b) = bad {
                return err(b);
            }
        }
        for (f, (&[a, b], &used)) in self.face_cells.iter().zip(&uses).enumerate() {
            let want = if b == NONE { 1 } else { 2 };
            if a == b {
                return err(format!("face {f}: both sides are cell {a}"));
            }
            if used != want {
                return err(format!("face {f}: used {used} times, want {want}"));
            }
        }
        // Unique vertex sets, except for the counted non-manifold extras.
        let mut sets: Vec<Vec<u32>> = (0..nf)
            .map(|f| {
                let mut v = self.face(f).to_vec();
                v.sort_unstable();
                v
            })
            .collect();
        sets.sort_unstable();
        let dups = sets.windows(2).filter(|w| w[0] == w[1]).count();
        if dups != self.nonmanifold_faces {
            return err(format!(
                "{dups} repeated face vertex sets but {} non-manifold faces counted",
                self.nonmanifold_faces
            ));
        }
        Ok(())
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
        t.sanity_check(&cells).unwrap();
    }

    #[test]
    fn three_cells_on_one_face_are_nonmanifold() {
        let mut cells = Cells::default();
        cells.push(CellKind::Tetra, &[0, 1, 2, 3]);
        cells.push(CellKind::Tetra, &[0, 2, 1, 4]);
        cells.push(CellKind::Tetra, &[0, 2, 1, 5]);
        let t = Topology::build(&cells);
        assert_eq!(t.nonmanifold_faces, 1);
        // 4 + 3 + 3 unique faces + the extra copy of the shared triangle
        assert_eq!(t.face_count(), 11);
        t.sanity_check(&cells).unwrap();
    }

    #[test]
    fn prism_caps_match_through_the_large_face_path() {
        let mut cells = Cells::default();
        let a: Vec<u32> = (0..12).collect();
        let b: Vec<u32> = (6..18).collect();
        cells.push(CellKind::HexagonalPrism, &a);
        cells.push(CellKind::HexagonalPrism, &b);
        let t = Topology::build(&cells);
        assert_eq!(t.face_count(), 15);
        let f = t.faces_of(0)[1] as usize;
        assert_eq!(t.face_cells[f], [0, 1]);
        assert_eq!(t.face_local[f], [1, 0]);
        t.sanity_check(&cells).unwrap();
    }

    #[test]
    fn sanity_check_catches_corruption() {
        let mut cells = Cells::default();
        cells.push(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]);
        cells.push(CellKind::Hexahedron, &[1, 8, 9, 2, 5, 10, 11, 6]);
        let mut t = Topology::build(&cells);
        t.cell_faces.swap(0, 1);
        assert!(t.sanity_check(&cells).is_err());
    }
}
