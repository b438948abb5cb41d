//! The faces of a finished arrangement: its unbounded face, the signed
//! areas of face cycles, and the sanity check of the whole structure.
//!
//! The unbounded face is found exactly, from the lexicographically lowest
//! original point and the exact angular ranks of its edges
//! ([`Arrangement::outer_half_edge`]). Areas are only used to check the
//! geometry and to tell slivers of rounding size from a second outer
//! boundary ([`is_outer`]); they are computed relative to each cycle's
//! first vertex so their rounding scales with the face, not with the pixel
//! coordinates.

use super::{half_of, Arrangement};
use crate::numeric::tolerance::{ARRANGEMENT_AREA_REL, OUTER_CYCLE_AREA_REL};
use crate::projection::subdivision::{TopologyError, NIL};

impl Arrangement {
    /// Checks the topology ([`Subdivision::sanity_check`]) and, once every
    /// piece is in, the geometry: a single outer boundary (one connected
    /// component), and bounded faces whose areas sum to the area inside it
    /// (they partition the silhouette).
    pub fn sanity_check(&self) -> Result<(), TopologyError> {
        self.sub.sanity_check()?;
        if !self.done() || self.sub.half_edge_count() == 0 {
            return Ok(());
        }
        let mut mark = Vec::new();
        let mut areas = Vec::new();
        self.sub
            .trace_faces(&mut mark, |h0| areas.push((h0, self.cycle_area(h0))));
        let outer = self.outer_cycle(&mut mark);
        let amin = areas.iter().fold(0.0, |m: f64, c| m.min(c.1));
        let a_outer = areas
            .iter()
            .find(|c| outer[c.0 as usize])
            .map_or(0.0, |c| c.1);
        // The exact outer cycle, plus any other cycle of clearly negative
        // area (a second component).
        let n_outer = 1 + areas
            .iter()
            .filter(|c| !outer[c.0 as usize] && is_outer(c.1, amin))
            .count();
        let inside: f64 = areas
            .iter()
            .filter(|c| !outer[c.0 as usize])
            .map(|c| c.1)
            .sum();
        if n_outer != 1 || a_outer >= 0.0 {
            return Err(TopologyError::Geometry("not exactly one outer boundary"));
        }
        if (inside + a_outer).abs() > ARRANGEMENT_AREA_REL * -a_outer {
            return Err(TopologyError::Geometry(
                "regions do not partition the silhouette",
            ));
        }
        Ok(())
    }

    /// The outgoing half-edge of the lexicographically lowest original point
    /// (smallest `x`, then `y`) that has edges, with the unbounded face on
    /// its left (`NIL` without edges). Exact: every crossing lies strictly
    /// inside a piece, so lexicographically above that piece's lower end,
    /// and the lowest vertex `v` of the arrangement is an original point.
    /// All its edges leave it at angles in `(-pi/2, pi/2]`; the ray from `v`
    /// towards `-x` meets nothing, so the gap `(pi/2, 3 pi/2)` belongs to the
    /// unbounded face, which lies on the left of the most counter-clockwise
    /// edge (exact angular ranks, as for insertion).
    pub fn outer_half_edge(&self) -> u32 {
        let mut low = NIL;
        for v in 0..self.n_points as u32 {
            if self.sub.vertex_edge(v) == NIL {
                continue;
            }
            let p = self.pt(v);
            if low == NIL || {
                let q = self.pt(low);
                p.x < q.x || (p.x == q.x && p.y < q.y)
            } {
                low = v;
            }
        }
        if low == NIL {
            return NIL;
        }
        let key = |h: u32| {
            let piece = self.edge_piece[(h >> 1) as usize];
            let d = self.dir_vec((piece, h & 1 == 0));
            (half_of(d) == 0, self.hrank[h as usize])
        };
        let h0 = self.sub.vertex_edge(low);
        let (mut best, mut h, mut guard) = (h0, self.sub.cw_next(h0), 0);
        while h != h0 && guard <= self.sub.half_edge_count() {
            if key(h) > key(best) {
                best = h;
            }
            h = self.sub.cw_next(h);
            guard += 1;
        }
        best
    }

    /// Flags (one per half-edge, in `mark`) of the unbounded face's cycle
    /// ([`Self::outer_half_edge`]).
    pub fn outer_cycle<'m>(&self, mark: &'m mut Vec<bool>) -> &'m [bool] {
        mark.clear();
        mark.resize(self.sub.half_edge_count(), false);
        let h0 = self.outer_half_edge();
        if h0 != NIL {
            let mut h = h0;
            while !mark[h as usize] {
                mark[h as usize] = true;
                h = self.sub.next(h);
            }
        }
        mark
    }

    /// Twice the signed area of the face cycle through `h0`, from positions
    /// relative to its first vertex: its rounding error scales with the
    /// face's size, not with the pixel coordinates (a piece a fraction of a
    /// pixel wide far from the image origin would otherwise give its slivers
    /// areas of rounding noise larger than `is_outer`'s threshold).
    pub fn cycle_area(&self, h0: u32) -> f64 {
        let o = self.pt(self.sub.origin(h0));
        let mut a = 0.0;
        let mut h = h0;
        let mut k = 0;
        loop {
            a += (self.pt(self.sub.origin(h)) - o).perp_dot(self.pt(self.sub.dest(h)) - o);
            h = self.sub.next(h);
            k += 1;
            if h == h0 || k > self.sub.half_edge_count() {
                return a;
            }
        }
    }
}

/// Whether a face cycle of (twice the) signed area `a` is clearly an outer
/// boundary, given the most negative cycle area `amin`: bounded faces have
/// positive area, except slivers whose rounded crossing points make their
/// computed area zero or slightly negative; those are tiny next to the outer
/// cycle. Only a fallback for a second component: the outer cycle itself is
/// found exactly ([`Arrangement::outer_half_edge`]).
pub fn is_outer(a: f64, amin: f64) -> bool {
    a < 0.0 && -a > OUTER_CYCLE_AREA_REL * -amin
}
