//! Unique faces and face adjacency of the 3D cells.
//!
//! Every cell face is identified by the sorted set of its point ids. Faces
//! seen from two cells become one interior face with both cells; faces seen
//! from one cell are boundary faces. A face's stored vertex order is the one
//! of the first cell that listed it (outward for that cell when the cell is
//! positively oriented). Ids only: no geometry is stored here.
//!
//! How [`Topology::build`] works (a bucket sort on the smallest point id,
//! no hash map):
//! 1. Every local face of every cell gets a *slot* (`cell_face_offsets` is
//!    the CSR over cells). In parallel (rayon, chunks of cells), faces of up
//!    to 4 points are counted per smallest point id (atomic counters); faces
//!    with more points (prism caps, polyhedron faces) go to a separate list
//!    of full sorted id vectors, sorted and matched on their own.
//! 2. One pass in slot order writes each small face into its point's bucket
//!    as 16 bytes: the other three sorted ids (padded with [`NONE`]) and the
//!    slot.
//! 3. Buckets are small (a few faces per point); each is sorted and equal
//!    faces become runs, in parallel over groups of buckets. In each run the
//!    second slot is linked to the first one; further slots are non-manifold
//!    (kept as boundary faces of their cells and counted).
//! 4. One ordered pass over the cells turns links into face ids: a slot that
//!    starts a face creates it (ids therefore follow the first cell that
//!    lists a face, as a hash-map build would give), a linked slot joins the
//!    face of its partner. A face listed twice by the same cell is not an
//!    interior face; it is also counted as non-manifold.
//!
//! Peak extra memory is the bucket array (16 bytes per cell face), the
//! links (8 bytes per interior face, then 4 per cell face) and 8 bytes per
//! point; see `benches/load.rs` for times.

use std::sync::atomic::{AtomicU32, Ordering};

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
pub enum TopologyError {
    /// The per-cell face offsets do not cover the cells.
    #[error("topology invariant broken: {offsets} cell face offsets for {cells} cells")]
    CellOffsets { offsets: usize, cells: usize },
    /// The per-face arrays have different lengths.
    #[error("topology invariant broken: face array lengths disagree")]
    FaceArrays,
    /// The face offsets do not end at the length of the face vertex list.
    #[error("topology invariant broken: face offsets do not end at face_verts.len()")]
    FaceOffsets,
    /// The cell-to-face list does not match its offsets.
    #[error("topology invariant broken: cell_faces length disagrees with its offsets")]
    CellFaces,
    /// A cell has another number of faces than its kind.
    #[error("topology invariant broken: cell {cell}: {recorded} faces recorded")]
    FaceCount { cell: usize, recorded: usize },
    /// A cell's face id is not a face.
    #[error("topology invariant broken: cell {cell} face {local}: id {face} out of range")]
    FaceId {
        cell: usize,
        local: usize,
        face: usize,
    },
    /// A face does not record the cell (at that local index) that uses it.
    #[error(
        "topology invariant broken: cell {cell} face {local}: face {face} has cells {cells:?}"
    )]
    FaceCells {
        cell: usize,
        local: usize,
        face: usize,
        cells: [u32; 2],
    },
    /// A cell's local face and its unique face have different vertices.
    #[error("topology invariant broken: cell {cell} face {local}: vertices {cell_verts:?} vs {face_verts:?}")]
    FaceVertices {
        cell: usize,
        local: usize,
        cell_verts: Vec<u32>,
        face_verts: Vec<u32>,
    },
    /// A face joins a cell to itself.
    #[error("topology invariant broken: face {face}: both sides are cell {cell}")]
    SelfAdjacent { face: usize, cell: u32 },
    /// A face is used by another number of cells than it records.
    #[error("topology invariant broken: face {face}: used {used} times, want {want}")]
    FaceUses { face: usize, used: u8, want: u8 },
    /// Repeated vertex sets that are not the counted non-manifold faces.
    #[error("topology invariant broken: {repeated} repeated face vertex sets but {counted} non-manifold faces counted")]
    RepeatedFaces { repeated: usize, counted: usize },
}

/// Cells per parallel work item.
const CHUNK: usize = 1 << 14;
/// Bucket entries per parallel work item when matching.
const MATCH_CHUNK: usize = 1 << 16;

/// Sorted ids of a face of 1 to 4 points, padded with [`NONE`].
#[inline]
fn sorted4(verts: &[u32]) -> [u32; 4] {
    let mut k = [NONE; 4];
    k[..verts.len()].copy_from_slice(verts);
    k.sort_unstable();
    k
}

/// Whether a face takes the bucketed path (up to 4 points).
#[inline]
fn small(verts: &[u32]) -> bool {
    (1..=4).contains(&verts.len())
}

/// Records the runs of equal keys in `sorted` (keys compared by `same`,
/// slots read by `slot`): the second slot of a run links to the first; the
/// rest are non-manifold. Returns `(pairs, nonmanifold)` and pushes links.
fn link_runs<T>(
    sorted: &[T],
    same: impl Fn(&T, &T) -> bool,
    slot: impl Fn(&T) -> u32,
    links: &mut Vec<(u32, u32)>,
) -> usize {
    let mut nonmanifold = 0;
    let mut i = 0;
    while i < sorted.len() {
        let mut j = i + 1;
        while j < sorted.len() && same(&sorted[i], &sorted[j]) {
            j += 1;
        }
        if j - i >= 2 {
            links.push((slot(&sorted[i + 1]), slot(&sorted[i])));
            nonmanifold += j - i - 2;
        }
        i = j;
    }
    nonmanifold
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
        let n_points = cells
            .conn
            .par_iter()
            .copied()
            .max()
            .into_iter()
            .chain(cells.poly_faces.values().flatten().flatten().copied())
            .max()
            .map_or(0, |m| m as usize + 1);

        // 1. Count small faces per smallest point; collect large faces.
        let counts: Vec<AtomicU32> = (0..n_points).map(|_| AtomicU32::new(0)).collect();
        let offsets = &cell_face_offsets;
        let chunks: Vec<(usize, usize)> = (0..n)
            .step_by(CHUNK)
            .map(|c0| (c0, (c0 + CHUNK).min(n)))
            .collect();
        let mut large: Vec<(Vec<u32>, u32)> = chunks
            .par_iter()
            .flat_map_iter(|&(c0, c1)| {
                let mut large = Vec::new();
                for (c, &base) in offsets.iter().enumerate().take(c1).skip(c0) {
                    cells.for_each_face(c, |local, verts| {
                        if small(verts) {
                            let m = verts.iter().copied().min().unwrap_or(NONE);
                            if let Some(x) = counts.get(m as usize) {
                                x.fetch_add(1, Ordering::Relaxed);
                            }
                        } else if verts.len() > 4 {
                            let mut v = verts.to_vec();
                            v.sort_unstable();
                            large.push((v, base + local as u32));
                        }
                    });
                }
                large
            })
            .collect();
        let mut start = Vec::with_capacity(n_points + 1);
        start.push(0u32);
        let mut acc = 0u32;
        for x in counts {
            acc += x.into_inner();
            start.push(acc);
        }

        // 2. Bucket entries (the other three ids and the slot), in slot order.
        let mut entries: Vec<[u32; 4]> = vec![[0; 4]; acc as usize];
        let mut cursor = start.clone();
        for (c, &base) in cell_face_offsets.iter().enumerate().take(n) {
            cells.for_each_face(c, |local, verts| {
                if !small(verts) {
                    return;
                }
                let k = sorted4(verts);
                if let Some(pos) = cursor.get_mut(k[0] as usize) {
                    entries[*pos as usize] = [k[1], k[2], k[3], base + local as u32];
                    *pos += 1;
                }
            });
        }
        drop(cursor);

        // 3. Match within buckets (parallel over runs of whole buckets).
        let mut jobs = Vec::new();
        let mut rest: &mut [[u32; 4]] = &mut entries;
        let (mut p0, mut taken) = (0usize, 0u32);
        while p0 < n_points {
            let mut p1 = p0 + 1;
            while p1 < n_points && ((start[p1] - start[p0]) as usize) < MATCH_CHUNK {
                p1 += 1;
            }
            let len = (start[p1] - taken) as usize;
            let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
            rest = tail;
            jobs.push((p0, p1, head));
            taken = start[p1];
            p0 = p1;
        }
        let start = &start;
        let (links, mut nonmanifold) = jobs
            .into_par_iter()
            .map(|(p0, p1, chunk)| {
                let mut links = Vec::new();
                let mut nm = 0;
                let base = start[p0];
                for p in p0..p1 {
                    let b = &mut chunk[(start[p] - base) as usize..(start[p + 1] - base) as usize];
                    if b.len() < 2 {
                        continue;
                    }
                    b.sort_unstable();
                    nm += link_runs(b, |x, y| x[..3] == y[..3], |x| x[3], &mut links);
                }
                (links, nm)
            })
            .reduce(
                || (Vec::new(), 0),
                |mut a, b| {
                    a.0.extend(b.0);
                    (a.0, a.1 + b.1)
                },
            );
        drop(entries);
        let mut link = vec![NONE; slots];
        let mut pairs = links.len();
        for (second, first) in links {
            link[second as usize] = first;
        }
        large.par_sort_unstable();
        let mut large_links = Vec::new();
        nonmanifold += link_runs(&large, |x, y| x.0 == y.0, |x| x.1, &mut large_links);
        pairs += large_links.len();
        for (second, first) in large_links {
            link[second as usize] = first;
        }
        drop(large);

        // 4. Ordered pass: links become face ids.
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

    /// Faces of cell `c` in local order, `None` for a cell the topology
    /// does not have.
    #[inline]
    pub fn faces_of_checked(&self, c: usize) -> Option<&[u32]> {
        let a = *self.cell_face_offsets.get(c)? as usize;
        let b = *self.cell_face_offsets.get(c + 1)? as usize;
        self.cell_faces.get(a..b)
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
        let n = cells.len();
        if self.cell_face_offsets.len() != n + 1 {
            return Err(TopologyError::CellOffsets {
                offsets: self.cell_face_offsets.len(),
                cells: n,
            });
        }
        let nf = self.face_count();
        if self.face_offsets.len() != nf + 1 || self.face_local.len() != nf {
            return Err(TopologyError::FaceArrays);
        }
        if self.face_offsets.last().copied() != Some(self.face_verts.len() as u32) {
            return Err(TopologyError::FaceOffsets);
        }
        if self.cell_faces.len() != *self.cell_face_offsets.last().unwrap_or(&0) as usize {
            return Err(TopologyError::CellFaces);
        }
        let mut uses = vec![0u8; nf];
        for c in 0..n {
            let faces = self.faces_of(c);
            if faces.len() != cells.face_count(c) {
                return Err(TopologyError::FaceCount {
                    cell: c,
                    recorded: faces.len(),
                });
            }
            let mut bad = None;
            cells.for_each_face(c, |local, verts| {
                if bad.is_some() {
                    return;
                }
                let f = faces[local] as usize;
                if f >= nf {
                    bad = Some(TopologyError::FaceId {
                        cell: c,
                        local,
                        face: f,
                    });
                    return;
                }
                let side = match self.face_cells[f] {
                    [a, _] if a == c as u32 && self.face_local[f][0] as usize == local % 256 => 0,
                    [_, b] if b == c as u32 && self.face_local[f][1] as usize == local % 256 => 1,
                    fc => {
                        bad = Some(TopologyError::FaceCells {
                            cell: c,
                            local,
                            face: f,
                            cells: fc,
                        });
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
                    bad = Some(TopologyError::FaceVertices {
                        cell: c,
                        local,
                        cell_verts: a,
                        face_verts: b,
                    });
                }
            });
            if let Some(b) = bad {
                return Err(b);
            }
        }
        for (f, (&[a, b], &used)) in self.face_cells.iter().zip(&uses).enumerate() {
            let want = if b == NONE { 1 } else { 2 };
            if a == b {
                return Err(TopologyError::SelfAdjacent { face: f, cell: a });
            }
            if used != want {
                return Err(TopologyError::FaceUses {
                    face: f,
                    used,
                    want,
                });
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
            return Err(TopologyError::RepeatedFaces {
                repeated: dups,
                counted: self.nonmanifold_faces,
            });
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
