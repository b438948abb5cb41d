//! The edge table of a piece's closed triangulated surface: edge ids, each
//! edge's two triangles, and each triangle's three edges with the triangle
//! across each. It depends on the triangle list alone, not on the view, so
//! it is built once and kept while consecutive pieces share their triangle
//! list (pieces of one cell kind whose faces were split along the same
//! diagonals); [`super::Overlay::build`] classifies its edges per view.
//!
//! Edges are numbered in order of first use; `edge_id` maps the ordered
//! pair of ends `(a, b)`, `a < b`, to the id through an `n * n` table, and
//! `uses` counts each direction, so a closed surface is one whose every
//! edge is used exactly once in each direction.

use super::NEXT;
use crate::projection::subdivision::NIL;

/// The piece's boundary topology: what depends on its triangle list alone,
/// not on the view. It is kept for the last list, which the next piece
/// usually has too (pieces of one cell kind whose faces were split along
/// the same diagonals).
#[derive(Clone, Debug, Default)]
pub(super) struct Topology {
    /// The triangle list and point count it was built for.
    pub(super) tris: Vec<[u32; 3]>,
    pub(super) n: usize,
    /// Every edge used once in each direction (a closed surface).
    pub(super) closed: bool,
    /// Ends `a < b` of each edge.
    pub(super) ends: Vec<[u32; 2]>,
    /// The two triangles along each edge, with the edge's index among
    /// each one's input edges.
    pub(super) sides: Vec<[(u32, u8); 2]>,
    /// Edge id of each triangle's input edge `t[k] -> t[k + 1]`.
    pub(super) tri_edge: Vec<[u32; 3]>,
    /// The same edges with their neighbours, as [`super::Overlay::build`] needs
    /// them.
    pub(super) adj: Vec<[Adj; 3]>,
    /// Edge ids by ends (`a * n + b`), and uses of each edge from its
    /// smaller and its larger end (scratch).
    pub(super) edge_id: Vec<u32>,
    pub(super) uses: Vec<[u8; 2]>,
}

/// Input edge `k` of a triangle `t`: its id, whether `t[k]` is its
/// smaller end, and the triangle across it with the edge's input index
/// there.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Adj {
    pub(super) e: u32,
    pub(super) fwd: bool,
    pub(super) nbr: u32,
    pub(super) nbr_j: u8,
}

impl Topology {
    /// Makes this the topology of `tris` over `n` points (nothing to do
    /// when it already is).
    pub(super) fn update(&mut self, n: usize, tris: &[[u32; 3]]) {
        if self.n == n && self.tris == tris {
            return;
        }
        self.n = n;
        self.tris.clear();
        self.tris.extend_from_slice(tris);
        self.edge_id.clear();
        self.edge_id.resize(n * n, NIL);
        self.ends.clear();
        self.sides.clear();
        self.tri_edge.clear();
        self.uses.clear();
        for (ti, t) in tris.iter().enumerate() {
            let mut te = [NIL; 3];
            for k in 0..3 {
                let (u, v) = (t[k], t[NEXT[k]]);
                let (a, b) = (u.min(v), u.max(v));
                let key = a as usize * n + b as usize;
                let mut id = self.edge_id[key];
                if id == NIL {
                    id = self.ends.len() as u32;
                    self.edge_id[key] = id;
                    self.ends.push([a, b]);
                    self.sides.push([(NIL, 0); 2]);
                    self.uses.push([0; 2]);
                }
                let used = &mut self.uses[id as usize][(u > v) as usize];
                *used = used.saturating_add(1);
                let sd = &mut self.sides[id as usize];
                sd[(sd[0].0 != NIL) as usize] = (ti as u32, k as u8);
                te[k] = id;
            }
            self.tri_edge.push(te);
        }
        self.closed = self.uses.iter().all(|&u| u == [1, 1]);
        self.adj.clear();
        if self.closed {
            for (t, (te, c)) in self.tri_edge.iter().zip(tris).enumerate() {
                let mut row = [Adj::default(); 3];
                for (j, r) in row.iter_mut().enumerate() {
                    let e = te[j];
                    let sd = self.sides[e as usize];
                    let (nbr, nbr_j) = if sd[0].0 as usize == t { sd[1] } else { sd[0] };
                    *r = Adj {
                        e,
                        fwd: c[j] == self.ends[e as usize][0],
                        nbr,
                        nbr_j,
                    };
                }
                self.adj.push(row);
            }
        }
    }
}
