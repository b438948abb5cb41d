//! Half-edge (winged-edge) planar subdivision: topology only.
//!
//! The structure stores integer ids in arenas and nothing else: a vertex
//! knows one outgoing half-edge, a half-edge knows its origin, its `next` and
//! `prev` around the face on its left, and its twin is implicit (`h ^ 1`,
//! half-edges are allocated in pairs). Faces are not stored: they are the
//! cycles of `next`, traced on demand ([`Subdivision::trace_faces`]).
//! Positions, predicates and the decision *where* an edge goes live a layer
//! above (`arrangement`); this layer only performs the two primitive
//! mutations a segment arrangement needs:
//!
//! - [`Subdivision::connect`]: add an edge between two existing vertices,
//!   given the outgoing half-edge after which it is inserted (in clockwise
//!   order) at each end, or nothing for an isolated vertex;
//! - [`Subdivision::split`]: put a new vertex in the middle of an edge.
//!
//! Around a vertex, the outgoing half-edges in clockwise order are
//! `h, next(twin(h)), ...` ([`Subdivision::cw_next`]): the face on the left
//! of `h` continues with the first edge clockwise from `twin(h)`, so bounded
//! faces are traversed counter-clockwise. Orientation here is the
//! mathematical one of whatever 2D coordinates the layer above uses.
//! [`Subdivision::sanity_check`] verifies every invariant, including Euler's
//! formula per connected component (planarity of the rotation system).

use thiserror::Error;

/// "No element" sentinel.
pub const NIL: u32 = u32::MAX;

/// A broken invariant found by [`Subdivision::sanity_check`].
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum TopologyError {
    #[error("half-edge {0}: next/prev pointers are not inverse")]
    NextPrev(u32),
    #[error("half-edge {0}: next does not start where it ends")]
    NotClosed(u32),
    #[error("vertex {0}: its half-edge does not start at it")]
    VertexEdge(u32),
    #[error("vertex {0}: rotation does not visit all its half-edges")]
    Rotation(u32),
    #[error("euler formula violated: V={v} E={e} cycles={f} components={c}")]
    Euler {
        v: usize,
        e: usize,
        f: usize,
        c: usize,
    },
    #[error("half-edge {0}: degenerate edge (loop)")]
    Loop(u32),
    #[error("geometry: {0}")]
    Geometry(&'static str),
}

#[derive(Clone, Copy, Debug)]
struct HalfEdge {
    origin: u32,
    next: u32,
    prev: u32,
}

/// The topology of a planar subdivision (see module docs).
#[derive(Clone, Debug, Default)]
pub struct Subdivision {
    /// One outgoing half-edge per vertex (`NIL` for an isolated vertex).
    vertex_edge: Vec<u32>,
    half: Vec<HalfEdge>,
}

impl Subdivision {
    /// Removes everything, keeping the allocations.
    pub fn clear(&mut self) {
        self.vertex_edge.clear();
        self.half.clear();
    }

    /// Adds an isolated vertex and returns its id.
    pub fn add_vertex(&mut self) -> u32 {
        self.vertex_edge.push(NIL);
        (self.vertex_edge.len() - 1) as u32
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.vertex_edge.len()
    }

    /// Number of half-edges (twice the number of edges).
    pub fn half_edge_count(&self) -> usize {
        self.half.len()
    }

    /// The twin of half-edge `h`.
    #[inline]
    pub fn twin(h: u32) -> u32 {
        h ^ 1
    }

    /// Origin vertex of `h`.
    #[inline]
    pub fn origin(&self, h: u32) -> u32 {
        self.half[h as usize].origin
    }

    /// Destination vertex of `h`.
    #[inline]
    pub fn dest(&self, h: u32) -> u32 {
        self.half[(h ^ 1) as usize].origin
    }

    /// Next half-edge around the face on the left of `h`.
    #[inline]
    pub fn next(&self, h: u32) -> u32 {
        self.half[h as usize].next
    }

    /// Previous half-edge around the face on the left of `h`.
    #[inline]
    pub fn prev(&self, h: u32) -> u32 {
        self.half[h as usize].prev
    }

    /// One outgoing half-edge of vertex `v`, or `NIL`.
    #[inline]
    pub fn vertex_edge(&self, v: u32) -> u32 {
        self.vertex_edge[v as usize]
    }

    /// The outgoing half-edge after `h` clockwise around its origin.
    #[inline]
    pub fn cw_next(&self, h: u32) -> u32 {
        self.next(h ^ 1)
    }

    fn link(&mut self, a: u32, b: u32) {
        self.half[a as usize].next = b;
        self.half[b as usize].prev = a;
    }

    /// Adds the edge `u -> v` and returns the half-edge from `u`.
    ///
    /// `after_u` is the outgoing half-edge of `u` that precedes the new edge
    /// clockwise around `u` (`NIL` when `u` is isolated); likewise
    /// `after_v` at `v`. The caller (geometry layer) guarantees these are
    /// right; [`Self::sanity_check`] detects when they were not.
    pub fn connect(&mut self, u: u32, v: u32, after_u: u32, after_v: u32) -> u32 {
        let a = self.half.len() as u32;
        let b = a + 1;
        self.half.push(HalfEdge {
            origin: u,
            next: b,
            prev: b,
        });
        self.half.push(HalfEdge {
            origin: v,
            next: a,
            prev: a,
        });
        // At u: previously next(twin(after_u)) = e_next; now twin(after_u) -> a
        // and b -> e_next.
        if after_u != NIL {
            let t = after_u ^ 1;
            let e_next = self.next(t);
            self.link(t, a);
            self.link(b, e_next);
        } else {
            self.link(b, a);
        }
        if after_v != NIL {
            let t = after_v ^ 1;
            let e_next = self.next(t);
            self.link(t, b);
            self.link(a, e_next);
        } else {
            self.link(a, b);
        }
        if self.vertex_edge[u as usize] == NIL {
            self.vertex_edge[u as usize] = a;
        }
        if self.vertex_edge[v as usize] == NIL {
            self.vertex_edge[v as usize] = b;
        }
        a
    }

    /// Splits the edge of half-edge `h` (`u -> v`) at the new vertex `w`
    /// (which must be isolated): afterwards `h` is `u -> w` and the returned
    /// half-edge is `w -> v`.
    pub fn split(&mut self, h: u32, w: u32) -> u32 {
        let t = h ^ 1; // v -> u
        let v = self.origin(t);
        let h_next = self.next(h);
        let t_prev = self.prev(t);
        let a = self.half.len() as u32; // w -> v
        let b = a + 1; // v -> w
        self.half.push(HalfEdge {
            origin: w,
            next: NIL,
            prev: NIL,
        });
        self.half.push(HalfEdge {
            origin: v,
            next: NIL,
            prev: NIL,
        });
        // The old twin t now starts at w: v -> w is b, w -> u is t.
        self.half[t as usize].origin = w;
        // Face left of h: ... h (u->w), a (w->v), h_next ...
        if h_next == t {
            // v was a dead end: u->v->u becomes u->w->v->w->u.
            self.link(h, a);
            self.link(a, b);
            self.link(b, t);
        } else {
            self.link(h, a);
            self.link(a, h_next);
            // Face left of t: ... t_prev, b (v->w), t (w->u) ...
            self.link(t_prev, b);
            self.link(b, t);
        }
        if self.vertex_edge[v as usize] == t {
            self.vertex_edge[v as usize] = b;
        }
        self.vertex_edge[w as usize] = a;
        a
    }

    /// Traces every face cycle, calling `f(first_half_edge)` once per cycle,
    /// using `mark` as scratch (one flag per half-edge).
    pub fn trace_faces(&self, mark: &mut Vec<bool>, mut f: impl FnMut(u32)) {
        mark.clear();
        mark.resize(self.half.len(), false);
        for h0 in 0..self.half.len() as u32 {
            if mark[h0 as usize] {
                continue;
            }
            let mut h = h0;
            let mut guard = 0;
            while !mark[h as usize] && guard <= self.half.len() {
                mark[h as usize] = true;
                h = self.next(h);
                guard += 1;
            }
            f(h0);
        }
    }

    /// Checks every invariant: twins, `next`/`prev` inverse, cycles closed,
    /// vertex rotations complete, and Euler's formula
    /// `cycles = E - V + 2C` over the `C` components that have edges.
    pub fn sanity_check(&self) -> Result<(), TopologyError> {
        let n = self.half.len();
        for h in 0..n as u32 {
            let e = &self.half[h as usize];
            if e.next as usize >= n || e.prev as usize >= n {
                return Err(TopologyError::NextPrev(h));
            }
            if self.prev(e.next) != h || self.next(e.prev) != h {
                return Err(TopologyError::NextPrev(h));
            }
            if self.origin(e.next) != self.dest(h) {
                return Err(TopologyError::NotClosed(h));
            }
            if self.origin(h) == self.dest(h) {
                return Err(TopologyError::Loop(h));
            }
        }
        // Rotations: the clockwise walk from the vertex's half-edge meets exactly
        // the half-edges starting at the vertex.
        let mut count = vec![0usize; self.vertex_edge.len()];
        for e in &self.half {
            if let Some(c) = count.get_mut(e.origin as usize) {
                *c += 1;
            }
        }
        let mut parent: Vec<u32> = (0..self.vertex_edge.len() as u32).collect();
        for (v, &h0) in self.vertex_edge.iter().enumerate() {
            if h0 == NIL {
                if count[v] != 0 {
                    return Err(TopologyError::Rotation(v as u32));
                }
                continue;
            }
            if h0 as usize >= n || self.origin(h0) != v as u32 {
                return Err(TopologyError::VertexEdge(v as u32));
            }
            let mut h = h0;
            let mut k = 0;
            loop {
                if self.origin(h) != v as u32 || k > n {
                    return Err(TopologyError::Rotation(v as u32));
                }
                k += 1;
                h = self.cw_next(h);
                if h == h0 {
                    break;
                }
            }
            if k != count[v] {
                return Err(TopologyError::Rotation(v as u32));
            }
        }
        // Components (union-find over edges).
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        for h in (0..n as u32).step_by(2) {
            let (a, b) = (
                find(&mut parent, self.origin(h)),
                find(&mut parent, self.dest(h)),
            );
            if a != b {
                parent[a as usize] = b;
            }
        }
        let mut comps = 0;
        for v in 0..self.vertex_edge.len() as u32 {
            if self.vertex_edge[v as usize] != NIL && find(&mut parent, v) == v {
                comps += 1;
            }
        }
        let mut cycles = 0;
        let mut mark = Vec::new();
        self.trace_faces(&mut mark, |_| cycles += 1);
        let (v, e) = (
            self.vertex_edge.iter().filter(|&&h| h != NIL).count(),
            n / 2,
        );
        if cycles + v != e + 2 * comps {
            return Err(TopologyError::Euler {
                v,
                e,
                f: cycles,
                c: comps,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square 0-1-2-3 (ccw) with its diagonal 0-2, built by hand.
    #[test]
    fn square_with_diagonal() {
        let mut s = Subdivision::default();
        let v: Vec<u32> = (0..4).map(|_| s.add_vertex()).collect();
        let e01 = s.connect(v[0], v[1], NIL, NIL);
        s.sanity_check().unwrap();
        // 1 -> 2: at 1 the only outgoing is 1->0 (twin of e01).
        let e12 = s.connect(v[1], v[2], e01 ^ 1, NIL);
        s.sanity_check().unwrap();
        let e23 = s.connect(v[2], v[3], e12 ^ 1, NIL);
        // 3 -> 0 closes the square: at 3 after 3->2, at 0 after 0->1 (two
        // edges: either order is the same cycle).
        let e30 = s.connect(v[3], v[0], e23 ^ 1, e01);
        s.sanity_check().unwrap();
        let mut cycles = 0;
        let mut mark = Vec::new();
        s.trace_faces(&mut mark, |_| cycles += 1);
        assert_eq!(cycles, 2);
        // Diagonal 0 -> 2 (45 deg): clockwise at 0 it follows 0->3 (90 deg);
        // at 2 (225 deg) it follows 2->1 (270 deg).
        let d = s.connect(v[0], v[2], e30 ^ 1, e12 ^ 1);
        // The triangle 0-1-2 is a face traversed 0 -> 1 -> 2 -> 0.
        assert_eq!(s.next(e01), e12);
        assert_eq!(s.next(e12), d ^ 1);
        s.sanity_check().unwrap();
        s.trace_faces(&mut mark, |_| cycles += 1);
        assert_eq!(cycles, 2 + 3);
        // Split the diagonal.
        let w = s.add_vertex();
        s.split(e01, w);
        s.sanity_check().unwrap();
        assert_eq!(s.half_edge_count(), 12);
    }

    #[test]
    fn wrong_rotation_is_detected() {
        let mut s = Subdivision::default();
        let v: Vec<u32> = (0..4).map(|_| s.add_vertex()).collect();
        let e01 = s.connect(v[0], v[1], NIL, NIL);
        let e12 = s.connect(v[1], v[2], e01 ^ 1, NIL);
        let e23 = s.connect(v[2], v[3], e12 ^ 1, NIL);
        let e30 = s.connect(v[3], v[0], e23 ^ 1, e01);
        // Diagonal inserted on the wrong side at 2 (after 2->3 instead of
        // after 2->1) makes the rotation system non-planar.
        s.connect(v[0], v[2], e30 ^ 1, e23);
        assert!(s.sanity_check().is_err());
    }

    #[test]
    fn split_dead_end() {
        let mut s = Subdivision::default();
        let a = s.add_vertex();
        let b = s.add_vertex();
        let h = s.connect(a, b, NIL, NIL);
        let w = s.add_vertex();
        let h2 = s.split(h, w);
        s.sanity_check().unwrap();
        assert_eq!(s.dest(h), w);
        assert_eq!(s.dest(h2), b);
        let w2 = s.add_vertex();
        s.split(h ^ 1, w2);
        s.sanity_check().unwrap();
    }
}
