//! The pool of split cells: cells currently drawn as their consistent
//! tetrahedra, kept between views and restored when no longer needed.
//!
//! A [`SplitCell`] holds the cell's tets, which tet owns each triangle of each
//! of the cell's faces (indexed by the face's position in
//! `Topology::faces_of(c)` and the triangle's index in the smallest-vertex
//! triangulation of the topology's stored face), and the triangles shared by
//! two tets inside the cell, with the side of the first tet's apex.

use rayon::prelude::*;

use crate::mesh::tetra::{tetrahedralize_cell, triangulate_face};
use crate::mesh::topology::Topology;
use crate::mesh::{Mesh, NONE};
use crate::numeric::predicates::{orient3d, Side};

/// A triangle shared by two tets of one split cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Internal {
    pub i: u32,
    pub j: u32,
    pub tri: [u32; 3],
    /// Side of tet `i` relative to the plane of `tri` (as wound).
    pub side_i: Side,
}

/// One cell drawn as tets.
#[derive(Clone, Debug, Default)]
pub struct SplitCell {
    pub cell: u32,
    pub tets: Vec<[u32; 4]>,
    /// `owner_off[li]..owner_off[li + 1]` indexes `owner` for local face `li`.
    pub owner_off: Vec<u32>,
    /// Local tet owning each face triangle.
    pub owner: Vec<u32>,
    pub internal: Vec<Internal>,
    /// Face triangles no tet matched (only for malformed cells).
    pub unmatched: usize,
}

fn sorted3(mut t: [u32; 3]) -> [u32; 3] {
    t.sort_unstable();
    t
}

impl SplitCell {
    /// Splits cell `c` into its consistent tets and records their faces.
    pub fn build(mesh: &Mesh, topo: &Topology, c: usize) -> SplitCell {
        // Sized up front: most of a split's cost was growing these (a
        // hexahedron has 5 or 6 tets, 12 face triangles, up to 7 inner ones).
        let mut tets = Vec::with_capacity(6);
        tetrahedralize_cell(&mesh.cells, c, &mut tets);
        // (sorted triangle, tet, apex) for every tet face.
        let mut keyed: Vec<([u32; 3], u32, u32)> = Vec::with_capacity(tets.len() * 4);
        for (ti, t) in tets.iter().enumerate() {
            for skip in 0..4 {
                let mut tri = [0u32; 3];
                let mut n = 0;
                for (k, &v) in t.iter().enumerate() {
                    if k != skip {
                        tri[n] = v;
                        n += 1;
                    }
                }
                keyed.push((sorted3(tri), ti as u32, t[skip]));
            }
        }
        keyed.sort_unstable();
        let p = &mesh.points;
        let mut internal = Vec::with_capacity(2 * tets.len());
        let mut i = 0;
        while i < keyed.len() {
            let mut j = i + 1;
            while j < keyed.len() && keyed[j].0 == keyed[i].0 {
                j += 1;
            }
            if j - i == 2 && keyed[i].1 != keyed[i + 1].1 {
                let tri = keyed[i].0;
                let [a, b, cc] = tri.map(|v| p[v as usize]);
                let mut side_i = orient3d(a, b, cc, p[keyed[i].2 as usize]);
                if side_i == Side::On {
                    side_i = match orient3d(a, b, cc, p[keyed[i + 1].2 as usize]) {
                        Side::Positive => Side::Negative,
                        Side::Negative => Side::Positive,
                        Side::On => Side::On,
                    };
                }
                internal.push(Internal {
                    i: keyed[i].1,
                    j: keyed[i + 1].1,
                    tri,
                    side_i,
                });
            }
            i = j;
        }
        let faces = topo.faces_of(c);
        let mut owner_off = Vec::with_capacity(faces.len() + 1);
        owner_off.push(0u32);
        let mut owner = Vec::with_capacity(
            faces
                .iter()
                .map(|&f| topo.face(f as usize).len().saturating_sub(2))
                .sum(),
        );
        let mut unmatched = 0;
        for &f in faces {
            triangulate_face(topo.face(f as usize), |t| {
                let key = sorted3(t);
                match keyed.binary_search_by(|e| e.0.cmp(&key).then(std::cmp::Ordering::Greater)) {
                    Err(pos) if pos < keyed.len() && keyed[pos].0 == key => {
                        owner.push(keyed[pos].1)
                    }
                    _ => {
                        unmatched += 1;
                        owner.push(0);
                    }
                }
            });
            owner_off.push(owner.len() as u32);
        }
        SplitCell {
            cell: c as u32,
            tets,
            owner_off,
            owner,
            internal,
            unmatched,
        }
    }

    /// The local tet owning triangle `k` of local face `li`.
    #[inline]
    pub fn owner(&self, li: usize, k: usize) -> u32 {
        let at = self.owner_off.get(li).map_or(0, |&o| o as usize) + k;
        self.owner.get(at).copied().unwrap_or(0)
    }
}

/// Split cells by cell id, with slot reuse.
#[derive(Clone, Debug, Default)]
pub struct SplitPool {
    /// Per cell: its slot in `slots`, or [`NONE`].
    pub slot_of: Vec<u32>,
    pub slots: Vec<SplitCell>,
    pub free: Vec<u32>,
    /// Cells currently split, in increasing order.
    pub active: Vec<u32>,
}

/// What [`SplitPool::update`] changed.
#[derive(Clone, Copy, Debug, Default)]
pub struct PoolChange {
    pub newly_split: usize,
    pub restored: usize,
}

impl SplitPool {
    pub fn new(cells: usize) -> SplitPool {
        SplitPool {
            slot_of: vec![NONE; cells],
            ..Default::default()
        }
    }

    /// Makes the split set exactly the cells with `want[c] != 0`.
    pub fn update(&mut self, mesh: &Mesh, topo: &Topology, want: &[u8]) -> PoolChange {
        let mut change = PoolChange::default();
        for &c in &self.active {
            if want[c as usize] == 0 {
                let s = self.slot_of[c as usize];
                self.slot_of[c as usize] = NONE;
                self.free.push(s);
                change.restored += 1;
            }
        }
        self.active.clear();
        let mut new_cells = Vec::new();
        for (c, &w) in want.iter().enumerate() {
            if w == 0 {
                continue;
            }
            self.active.push(c as u32);
            if self.slot_of[c] == NONE {
                new_cells.push(c);
            }
        }
        // The splits are independent: built in parallel, stored in cell
        // order (the same slots as a serial build).
        let built: Vec<SplitCell> = new_cells
            .par_iter()
            .map(|&c| SplitCell::build(mesh, topo, c))
            .collect();
        self.slots
            .reserve(new_cells.len().saturating_sub(self.free.len()));
        for (&c, sc) in new_cells.iter().zip(built) {
            let s = match self.free.pop() {
                Some(s) => {
                    self.slots[s as usize] = sc;
                    s
                }
                None => {
                    self.slots.push(sc);
                    (self.slots.len() - 1) as u32
                }
            };
            self.slot_of[c] = s;
            change.newly_split += 1;
        }
        change
    }

    /// The split cell of `c`, if split.
    #[inline]
    pub fn get(&self, c: u32) -> Option<&SplitCell> {
        match self.slot_of.get(c as usize) {
            Some(&s) if s != NONE => self.slots.get(s as usize),
            _ => None,
        }
    }
}
