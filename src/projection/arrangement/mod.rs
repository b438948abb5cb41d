//! The geometry layer over [`Subdivision`]: inserting projected segments one
//! by one, splitting at crossings, with every combinatorial decision exact.
//!
//! Input: 2D points (the projected polyhedron vertices, coincident ones
//! already merged to one id) and segments between them. Preparation
//! ([`Arrangement::prepare`]) splits every segment at the original points lying
//! exactly on its interior (exact `orient2d` plus coordinate comparisons) and
//! merges identical pieces, so that afterwards two pieces meet only at a shared
//! endpoint or at a *proper* crossing (each strictly on both sides of the
//! other). Collinear overlaps (faces seen edge-on) vanish in this step.
//!
//! Insertion ([`Arrangement::insert_next`]) of piece `p` finds its proper
//! crossings with the pieces already inserted (four `orient2d` on original
//! endpoints), creates one vertex per crossing, whose position is computed in
//! `f64` from the two pieces' original endpoints (never from other computed
//! points), splits the crossed edge, then connects the consecutive vertices of
//! `p`. Where a new edge goes in the rotation around a vertex is decided by
//! an exact angular comparison: around an original point every incident piece
//! ends there, so directions compare with `orient2d(u, far1, far2)`; around a
//! crossing there are exactly two pieces, compared with `orient2d` of their
//! endpoints. The order of crossings along a piece is exact when the two
//! crossing pieces share an endpoint or one lies on one side of the other's
//! line -- always the case for a convex polyhedron, whose front edges never
//! cross each other (nor the back edges). Three mutually crossing pieces do
//! occur, though: faces seen (nearly) edge-on project to slivers whose
//! rounded pixel positions classify their triangles front or back by
//! rounding noise, so front edges may cross front edges. Their order is
//! decided exactly too, by the side of the third crossing (a degree-4
//! polynomial evaluated with exact expansions,
//! [`crossing_side_times_turn`]), with a symbolic
//! perturbation when the three lines meet in one point. Crossing positions
//! are never used for a decision: those of nearly parallel pieces may be
//! far from the exact point (they are clamped to both bounding boxes).

use glam::DVec2;

mod faces;

pub use faces::is_outer;

use super::subdivision::{Subdivision, NIL};
use crate::numeric::predicates::{crossing_side_times_turn, orient2d, Side};

/// A segment between two original points, with the triangles on its sides:
/// `side = [front_left, front_right, back_left, back_right]` (triangle ids or
/// `NIL`), left and right of the direction `a -> b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    pub a: u32,
    pub b: u32,
    pub side: [u32; 4],
}

#[derive(Clone, Copy, Debug)]
struct ChainEntry {
    v: u32,
    /// Forward half-edge from `v` along the piece (`NIL` for the last entry
    /// or before the piece is inserted).
    h: u32,
}

/// A segment arrangement (see module docs).
#[derive(Clone, Debug, Default)]
pub struct Arrangement {
    /// The topology. Vertex ids `0..n_points` are the original points.
    pub sub: Subdivision,
    /// Position of every subdivision vertex.
    pub pos: Vec<DVec2>,
    /// For crossing vertices, the two pieces that cross there (`[NIL, NIL]`
    /// for original points).
    pub cross: Vec<[u32; 2]>,
    /// The prepared pieces.
    pub pieces: Vec<Segment>,
    /// Segment of every edge (`h >> 1`); the even half-edge runs `a -> b`.
    pub edge_piece: Vec<u32>,
    chains: Vec<Vec<ChainEntry>>,
    /// Cyclic angular rank (counter-clockwise) of each piece's direction at
    /// its ends: `[at a (towards b), at b (towards a)]`.
    end_rank: Vec<[u16; 2]>,
    /// Angular rank of every half-edge's direction around its origin.
    hrank: Vec<u16>,
    sort_buf: Vec<(u32, bool)>,
    inserted: usize,
    n_points: usize,
    scratch: Vec<u32>,
}

#[inline]
fn half_of(d: DVec2) -> u8 {
    // 0 for angles in [0, pi), 1 for [pi, 2 pi); exact sign tests.
    if d.y > 0.0 || (d.y == 0.0 && d.x > 0.0) {
        0
    } else {
        1
    }
}

#[inline]
fn flip(s: Side) -> Side {
    match s {
        Side::Positive => Side::Negative,
        Side::Negative => Side::Positive,
        Side::On => Side::On,
    }
}

impl Arrangement {
    /// Clears the arrangement and prepares `segments` over `points` (see
    /// module docs). Segments are `(a, b, side)` with `a != b`; `points`
    /// become subdivision vertices `0..points.len()`.
    pub fn prepare(&mut self, points: &[DVec2], segments: &[Segment]) {
        self.sub.clear();
        self.pos.clear();
        self.cross.clear();
        self.pieces.clear();
        self.edge_piece.clear();
        for c in &mut self.chains {
            c.clear();
        }
        self.inserted = 0;
        self.n_points = points.len();
        for &p in points {
            self.sub.add_vertex();
            self.pos.push(p);
            self.cross.push([NIL, NIL]);
        }
        let mut on = std::mem::take(&mut self.scratch);
        for s in segments {
            let (pa, pb) = (points[s.a as usize], points[s.b as usize]);
            // Original points strictly inside the segment, sorted along it.
            on.clear();
            let (lo, hi) = (pa.min(pb), pa.max(pb));
            for (v, &q) in points.iter().enumerate() {
                let v = v as u32;
                if v == s.a || v == s.b || q.x < lo.x || q.x > hi.x || q.y < lo.y || q.y > hi.y {
                    continue;
                }
                if q == pa || q == pb || orient2d(pa, pb, q) != Side::On {
                    continue;
                }
                // Collinear and inside the bounding box: strictly between.
                // Skip duplicates of an already listed position.
                if on.iter().any(|&w| points[w as usize] == q) {
                    continue;
                }
                // Insertion in order of distance from a (exact: collinear
                // points compare by their coordinates along the segment).
                let key = |w: u32| {
                    let p = points[w as usize];
                    if pa.x != pb.x {
                        (p.x - pa.x).abs()
                    } else {
                        (p.y - pa.y).abs()
                    }
                };
                let k = key(v);
                let at = on.iter().position(|&w| key(w) > k).unwrap_or(on.len());
                on.insert(at, v);
            }
            let mut prev = s.a;
            for i in 0..=on.len() {
                let next = if i < on.len() { on[i] } else { s.b };
                self.add_piece(Segment {
                    a: prev,
                    b: next,
                    side: s.side,
                });
                prev = next;
            }
        }
        self.scratch = on;
        self.rank_original_vertices();
    }

    /// Sorts the pieces around every original point by exact angle once, so
    /// that insertion positions are found by comparing integer ranks.
    fn rank_original_vertices(&mut self) {
        self.end_rank.clear();
        self.end_rank.resize(self.pieces.len(), [0, 0]);
        self.hrank.clear();
        let mut buf = std::mem::take(&mut self.sort_buf);
        for v in 0..self.n_points as u32 {
            buf.clear();
            for (i, p) in self.pieces.iter().enumerate() {
                if p.a == v {
                    buf.push((i as u32, true));
                } else if p.b == v {
                    buf.push((i as u32, false));
                }
            }
            // Insertion sort (exact comparisons, a handful of elements).
            for i in 1..buf.len() {
                let mut j = i;
                while j > 0 && self.angle_less(v, buf[j], buf[j - 1]) {
                    buf.swap(j, j - 1);
                    j -= 1;
                }
            }
            for (r, &(p, at_a)) in buf.iter().enumerate() {
                self.end_rank[p as usize][if at_a { 0 } else { 1 }] = r as u16;
            }
        }
        self.sort_buf = buf;
    }

    /// Rank of direction `d` (piece, forward) at vertex `u`.
    fn rank(&self, u: u32, d: (u32, bool)) -> u16 {
        if (u as usize) < self.n_points {
            self.end_rank[d.0 as usize][if d.1 { 0 } else { 1 }]
        } else {
            // Crossing of q (first) and p: counter-clockwise order is
            // q+, p+, q-, p- when p+ is counter-clockwise of q+, else
            // q+, p-, q-, p+.
            let [q, p] = self.cross[u as usize];
            let (qq, pp) = (self.pieces[q as usize], self.pieces[p as usize]);
            let ccw = orient2d(self.pt(qq.a), self.pt(qq.b), self.pt(pp.b)) == Side::Positive;
            match (d.0 == q, d.1, ccw) {
                (true, true, _) => 0,
                (true, false, _) => 2,
                (false, fwd, ccw) => {
                    if fwd == ccw {
                        1
                    } else {
                        3
                    }
                }
            }
        }
    }

    fn set_rank(&mut self, h: u32, r: u16) {
        if self.hrank.len() <= h as usize {
            self.hrank.resize(h as usize + 1, 0);
        }
        self.hrank[h as usize] = r;
    }

    fn add_piece(&mut self, p: Segment) {
        // Canonical direction a < b (flip sides accordingly), then merge.
        let p = if p.a < p.b {
            p
        } else {
            Segment {
                a: p.b,
                b: p.a,
                side: [p.side[1], p.side[0], p.side[3], p.side[2]],
            }
        };
        if let Some(q) = self.pieces.iter_mut().find(|q| q.a == p.a && q.b == p.b) {
            for k in 0..4 {
                if q.side[k] == NIL {
                    q.side[k] = p.side[k];
                }
            }
            return;
        }
        self.pieces.push(p);
    }

    /// Number of prepared pieces.
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    /// Whether every piece has been inserted.
    pub fn done(&self) -> bool {
        self.inserted == self.pieces.len()
    }

    #[inline]
    fn pt(&self, v: u32) -> DVec2 {
        self.pos[v as usize]
    }

    /// Whether pieces `p` and `q` cross properly (exact).
    fn crosses(&self, p: Segment, q: Segment) -> bool {
        if p.a == q.a || p.a == q.b || p.b == q.a || p.b == q.b {
            return false;
        }
        let (p0, p1, q0, q1) = (self.pt(p.a), self.pt(p.b), self.pt(q.a), self.pt(q.b));
        if p0.x.max(p1.x) < q0.x.min(q1.x)
            || q0.x.max(q1.x) < p0.x.min(p1.x)
            || p0.y.max(p1.y) < q0.y.min(q1.y)
            || q0.y.max(q1.y) < p0.y.min(p1.y)
        {
            return false;
        }
        let s = |x: Side| x != Side::On;
        let (o1, o2) = (orient2d(p0, p1, q0), orient2d(p0, p1, q1));
        if !(s(o1) && s(o2) && o1 != o2) {
            return false;
        }
        let (o3, o4) = (orient2d(q0, q1, p0), orient2d(q0, q1, p1));
        s(o3) && s(o4) && o3 != o4
    }

    /// Position of the crossing of pieces `p` and `q`, symmetric in `p, q`.
    fn crossing_point(&self, p: u32, q: u32) -> DVec2 {
        let (p, q) = if p < q { (p, q) } else { (q, p) };
        let (pp, qq) = (self.pieces[p as usize], self.pieces[q as usize]);
        segment_crossing(self.pt(pp.a), self.pt(pp.b), self.pt(qq.a), self.pt(qq.b))
    }

    /// Whether, along piece `p` (direction `a -> b`), its crossing with `q1`
    /// comes before its crossing with `q2`.
    fn cross_before(&self, p: u32, q1: u32, q2: u32) -> bool {
        let pp = self.pieces[p as usize];
        let (a, b) = (self.pieces[q1 as usize], self.pieces[q2 as usize]);
        let (p0, p1) = (self.pt(pp.a), self.pt(pp.b));
        // (i) q1 and q2 share an endpoint v off the line of p.
        let shared = if a.a == b.a || a.a == b.b {
            Some(a.a)
        } else if a.b == b.a || a.b == b.b {
            Some(a.b)
        } else {
            None
        };
        if let Some(v) = shared {
            let w1 = if a.a == v { a.b } else { a.a };
            let w2 = if b.a == v { b.b } else { b.a };
            let pv = self.pt(v);
            let turn = orient2d(pv, self.pt(w1), self.pt(w2));
            match orient2d(p0, p1, pv) {
                Side::Positive if turn != Side::On => return turn == Side::Positive,
                Side::Negative if turn != Side::On => return turn == Side::Negative,
                _ => {}
            }
        } else {
            // (ii) q2 on one side of the line of q1.
            if let Some(s) = self.one_side(a, b) {
                return orient2d(self.pt(a.a), self.pt(a.b), p1) == s;
            }
            // (iii) q1 on one side of the line of q2.
            if let Some(s) = self.one_side(b, a) {
                return orient2d(self.pt(b.a), self.pt(b.b), p1) != s;
            }
        }
        // (iv) three mutually crossing pieces (q1 and q2 cross properly).
        self.cross_before_mutual(p, q1, q2)
    }

    /// [`Self::cross_before`] when `q1` and `q2` cross each other properly
    /// (and `p` crosses both): exact, from the side of `p` on which the
    /// crossing `Y` of `q1` and `q2` lies.
    ///
    /// `X1, X2` (the crossings on `p`) and `Y` form a triangle. With `Y` on
    /// side `sigma` of `p`, let `u_i = -sigma s_i e_i` (`s_i` the side of
    /// `q_i.b`, `orient2d(p.a, p.b, q_i.b)`) point from `Y` towards `p` along
    /// `q_i`: then `X1` comes first iff `sigma cross(u1, u2) > 0`. As
    /// `u1 x u2 = s1 s2 (e1 x e2)`, this is the sign of
    /// `sigma (e1 x e2) s1 s2`, and `sigma (e1 x e2)` is one exact polynomial
    /// ([`crossing_side_times_turn`]).
    ///
    /// When the three lines meet in one point, the piece `r` with the largest
    /// id among the three is taken as translated by an infinitesimal amount
    /// to its left (simulation of simplicity): every query about the same
    /// triple, along any of its pieces, then answers for one consistent
    /// (perturbed) configuration, and so do different triples through one
    /// point (larger ids moved by larger infinitesimals).
    fn cross_before_mutual(&self, p: u32, q1: u32, q2: u32) -> bool {
        let seg = |i: u32| {
            let s = self.pieces[i as usize];
            [self.pt(s.a), self.pt(s.b)]
        };
        let (sp, s1, s2) = (seg(p), seg(q1), seg(q2));
        let sign = |s: Side| match s {
            Side::Positive => 1i8,
            Side::Negative => -1,
            Side::On => 0,
        };
        let mut st = sign(crossing_side_times_turn(sp, s1, s2));
        if st == 0 {
            // Y on the line of p exactly: perturb the largest id.
            // turn = sign(e1 x e2) = side of q2.b from q1 (q2 straddles q1).
            let turn = sign(orient2d(s1[0], s1[1], s2[1]));
            let r = p.max(q1).max(q2);
            let sigma = if r == p {
                // p moved left: Y is on its right.
                -1
            } else if r == q1 {
                // Y moves along q2 by sign(e1 x e2); side of p: d x e2.
                -turn * sign(orient2d(s2[0], s2[1], sp[1]))
            } else {
                // Y moves along q1 by -sign(e1 x e2); side of p: d x e1.
                turn * sign(orient2d(s1[0], s1[1], sp[1]))
            };
            st = sigma * turn;
        }
        let s1b = sign(orient2d(sp[0], sp[1], s1[1]));
        let s2b = sign(orient2d(sp[0], sp[1], s2[1]));
        st * s1b * s2b > 0
    }

    /// The side of the line of `l` on which all of `m` lies (endpoints on the
    /// line allowed, not both), or `None`.
    fn one_side(&self, l: Segment, m: Segment) -> Option<Side> {
        let (l0, l1) = (self.pt(l.a), self.pt(l.b));
        let (s1, s2) = (
            orient2d(l0, l1, self.pt(m.a)),
            orient2d(l0, l1, self.pt(m.b)),
        );
        match (s1, s2) {
            (Side::On, Side::On) => None,
            (Side::On, s) | (s, Side::On) => Some(s),
            (s, t) if s == t => Some(s),
            _ => None,
        }
    }

    /// Direction vector (rounded; used for its exact coordinate signs only,
    /// which `b - a` keeps because subtraction of doubles is sign-exact).
    #[inline]
    fn dir_vec(&self, d: (u32, bool)) -> DVec2 {
        let p = self.pieces[d.0 as usize];
        let v = self.pt(p.b) - self.pt(p.a);
        if d.1 {
            v
        } else {
            -v
        }
    }

    /// Exact sign of `cross(d1, d2)` for two directions leaving vertex `u`.
    fn cross_sign(&self, u: u32, d1: (u32, bool), d2: (u32, bool)) -> Side {
        let (p1, p2) = (self.pieces[d1.0 as usize], self.pieces[d2.0 as usize]);
        if (u as usize) < self.n_points {
            let far = |p: Segment| if p.a == u { p.b } else { p.a };
            orient2d(self.pt(u), self.pt(far(p1)), self.pt(far(p2)))
        } else {
            // Crossing of exactly two pieces: cross(forward p1, forward p2)
            // has the sign of orient2d(p1.a, p1.b, p2.b).
            let s = orient2d(self.pt(p1.a), self.pt(p1.b), self.pt(p2.b));
            if d1.1 == d2.1 {
                s
            } else {
                flip(s)
            }
        }
    }

    /// Whether direction `d1` has a smaller angle than `d2` (angles from the
    /// +x axis counter-clockwise, in `[0, 2 pi)`), at vertex `u`.
    fn angle_less(&self, u: u32, d1: (u32, bool), d2: (u32, bool)) -> bool {
        let (h1, h2) = (half_of(self.dir_vec(d1)), half_of(self.dir_vec(d2)));
        if h1 != h2 {
            return h1 < h2;
        }
        self.cross_sign(u, d1, d2) == Side::Positive
    }

    /// The outgoing half-edge of `u` after which direction `d` goes in
    /// clockwise order (`NIL` when `u` is isolated).
    fn find_after(&self, u: u32, d: u16) -> u32 {
        let h0 = self.sub.vertex_edge(u);
        if h0 == NIL {
            return NIL;
        }
        let mut h = h0;
        let mut guard = 0;
        loop {
            // Clockwise from h comes n: d goes after h (clockwise) when it
            // lies strictly between n and h counter-clockwise.
            let n = self.sub.cw_next(h);
            if n == h {
                return h;
            }
            let (a, b) = (self.hrank[n as usize], self.hrank[h as usize]);
            let between = if a < b {
                a < d && d < b
            } else {
                a < d || d < b
            };
            if between {
                return h;
            }
            h = n;
            guard += 1;
            if h == h0 || guard > self.sub.half_edge_count() {
                // Inconsistent ranks (a bug: every decision is exact): any
                // position keeps the structure well formed, and
                // `sanity_check` reports the broken planarity.
                return h0;
            }
        }
    }

    /// Inserts the next prepared piece; returns `false` when all are in.
    pub fn insert_next(&mut self) -> bool {
        if self.inserted >= self.pieces.len() {
            return false;
        }
        let p = self.inserted as u32;
        self.inserted += 1;
        if self.chains.len() < self.pieces.len() {
            self.chains.resize_with(self.pieces.len(), Vec::new);
        }
        let pp = self.pieces[p as usize];
        let mut chain = std::mem::take(&mut self.chains[p as usize]);
        chain.clear();
        chain.push(ChainEntry { v: pp.a, h: NIL });
        // Crossings with earlier pieces.
        for q in 0..p {
            let qq = self.pieces[q as usize];
            if !self.crosses(pp, qq) {
                continue;
            }
            let w = self.sub.add_vertex();
            let x = self.crossing_point(p, q);
            self.pos.push(x);
            self.cross.push([q, p]);
            // Position on q's chain (the first and last entries are q's ends).
            let qc = &self.chains[q as usize];
            let mut i = 1;
            while i + 1 < qc.len() {
                let other = self.other_piece(qc[i].v, q);
                if self.cross_before(q, p, other) {
                    break;
                }
                i += 1;
            }
            let h = self.chains[q as usize][i - 1].h;
            let old_back = self.hrank[(h ^ 1) as usize];
            let h2 = self.sub.split(h, w);
            self.set_edge_piece(h2, q);
            // h keeps its origin; h^1 now leaves w backwards along q; h2
            // leaves w forwards; h2^1 leaves the old end like h^1 did.
            let (rb, rf) = (self.rank(w, (q, false)), self.rank(w, (q, true)));
            self.set_rank(h ^ 1, rb);
            self.set_rank(h2, rf);
            self.set_rank(h2 ^ 1, old_back);
            self.chains[q as usize].insert(i, ChainEntry { v: w, h: h2 });
            // Insertion sort into p's chain.
            let mut j = chain.len();
            while j > 1 && self.cross_before(p, q, self.other_piece(chain[j - 1].v, p)) {
                j -= 1;
            }
            chain.insert(j, ChainEntry { v: w, h: NIL });
        }
        chain.push(ChainEntry { v: pp.b, h: NIL });
        for k in 0..chain.len() - 1 {
            let (u, v) = (chain[k].v, chain[k + 1].v);
            let (ru, rv) = (self.rank(u, (p, true)), self.rank(v, (p, false)));
            let after_u = self.find_after(u, ru);
            let after_v = self.find_after(v, rv);
            let h = self.sub.connect(u, v, after_u, after_v);
            self.set_edge_piece(h, p);
            self.set_rank(h, ru);
            self.set_rank(h ^ 1, rv);
            chain[k].h = h;
        }
        self.chains[p as usize] = chain;
        true
    }

    fn set_edge_piece(&mut self, h: u32, p: u32) {
        let e = (h >> 1) as usize;
        if self.edge_piece.len() <= e {
            self.edge_piece.resize(e + 1, NIL);
        }
        self.edge_piece[e] = p;
    }

    fn other_piece(&self, v: u32, p: u32) -> u32 {
        let c = self.cross[v as usize];
        if c[0] == p {
            c[1]
        } else {
            c[0]
        }
    }
}

/// The crossing of segments `p0 p1` and `q0 q1` (which cross properly), in
/// `f64` from the endpoints: the point at the crossing's parameter along
/// `p` (clamped to `[0, 1]`), kept inside both bounding boxes.
pub(super) fn segment_crossing(p0: DVec2, p1: DVec2, q0: DVec2, q1: DVec2) -> DVec2 {
    let d = p1 - p0;
    let e = q1 - q0;
    let t = (q0 - p0).perp_dot(e) / d.perp_dot(e);
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let x = p0 + d * t;
    let lo = p0.min(p1).max(q0.min(q1));
    let hi = p0.max(p1).min(q0.max(q1));
    x.max(lo).min(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Arrangement of `segs` (endpoint pairs) with point ids permuted by
    /// `perm`; returns, for every input segment, the sequence of input
    /// segments crossing it from its first to its second endpoint.
    fn crossing_orders(segs: &[[DVec2; 2]], perm: &[u32]) -> Vec<Vec<usize>> {
        let mut arr = prepared(segs, perm);
        while arr.insert_next() {
            arr.sub.sanity_check().unwrap();
        }
        // Input segment of each prepared piece.
        let seg_of = |p: u32| {
            let q = arr.pieces[p as usize];
            (0..segs.len())
                .find(|&i| {
                    let (a, b) = (perm[2 * i], perm[2 * i + 1]);
                    (a, b) == (q.a, q.b) || (b, a) == (q.a, q.b)
                })
                .unwrap()
        };
        (0..segs.len())
            .map(|i| {
                let p = (0..segs.len() as u32).find(|&p| seg_of(p) == i).unwrap();
                let chain = &arr.chains[p as usize];
                let mut order: Vec<usize> = chain[1..chain.len() - 1]
                    .iter()
                    .map(|c| seg_of(arr.other_piece(c.v, p)))
                    .collect();
                if arr.pieces[p as usize].a != perm[2 * i] {
                    order.reverse();
                }
                order
            })
            .collect()
    }

    /// The prepared arrangement of `segs` with point ids permuted by `perm`
    /// (segment `i` runs from point `perm[2 i]` to point `perm[2 i + 1]`).
    fn prepared(segs: &[[DVec2; 2]], perm: &[u32]) -> Arrangement {
        let mut pts = vec![DVec2::ZERO; 2 * segs.len()];
        for (i, s) in segs.iter().enumerate() {
            pts[perm[2 * i] as usize] = s[0];
            pts[perm[2 * i + 1] as usize] = s[1];
        }
        let pieces: Vec<Segment> = (0..segs.len())
            .map(|i| Segment {
                a: perm[2 * i],
                b: perm[2 * i + 1],
                side: [NIL; 4],
            })
            .collect();
        let mut arr = Arrangement::default();
        arr.prepare(&pts, &pieces);
        assert_eq!(arr.piece_count(), segs.len());
        arr
    }

    /// Small deterministic permutations of `0..n`.
    fn perms(n: usize, count: usize) -> Vec<Vec<u32>> {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        (0..count)
            .map(|k| {
                let mut p: Vec<u32> = (0..n as u32).collect();
                if k > 0 {
                    for i in (1..n).rev() {
                        s ^= s << 13;
                        s ^= s >> 7;
                        s ^= s << 17;
                        p.swap(i, (s % (i as u64 + 1)) as usize);
                    }
                }
                p
            })
            .collect()
    }

    #[test]
    fn nearly_collinear_mutual_crossings_are_planar() {
        // Pixel positions of a pentagonal prism whose pentagon faces are
        // seen edge-on in perspective (tests/projection_regions.rs,
        // `fuzz_pentagonal_prism_edge_on_perspective`): the pentagon's
        // vertices are collinear up to rounding, and pieces 0-3, 1-2 (edges
        // of triangles whose facing is rounding noise) and 4-9 cross each
        // other at tiny angles. Their f64 crossing parameters are noise (one
        // comes out as 1/3 for a crossing at ~0.376); the exact order is not.
        let v = DVec2::new;
        let segs = [
            [
                v(35.032371601049554, 21.804144702688255),
                v(29.64532101412155, 25.705112369084397),
            ],
            [
                v(33.005128702631424, 23.272148180853108),
                v(29.439587146276473, 25.85409206648945),
            ],
            [
                v(32.87761606112118, 23.364484921257077),
                v(35.61575604517689, 23.463003958812834),
            ],
        ];
        for perm in perms(6, 60) {
            let orders = crossing_orders(&segs, &perm);
            assert!(orders.iter().all(|o| o.len() == 2), "{orders:?}");
            assert_eq!(orders, crossing_orders(&segs, &perms(6, 1)[0]));
        }
    }

    #[test]
    fn tiny_piece_far_from_origin_has_one_outer_boundary() {
        // Pixel positions of a breakpoint slab a twentieth of a pixel wide
        // (fuzz/regressions/projection/tet_slab_outer_boundary): points 0, 1,
        // 2 are collinear up to ~1e-20, so the bounded face 0-1-2 is a
        // sliver whose shoelace area from absolute coordinates (~32, ~24) was
        // rounding noise of -1e-13, taken for a second outer boundary next
        // to the real one of -7e-5.
        let v = DVec2::new;
        let pts = [
            v(32.0, 24.0),
            v(32.00408393945437, 24.00005011999331),
            v(32.00060639978205, 24.00000744201851),
            v(32.04840129791201, 23.98343747846012),
        ];
        let pieces: Vec<Segment> = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)]
            .iter()
            .map(|&(a, b)| Segment {
                a,
                b,
                side: [NIL; 4],
            })
            .collect();
        let mut arr = Arrangement::default();
        arr.prepare(&pts, &pieces);
        while arr.insert_next() {}
        arr.sanity_check().unwrap();
        let h = arr.outer_half_edge();
        assert_eq!(arr.sub.origin(h), 0);
        assert!(arr.cycle_area(h) < 0.0);
        let mut mark = Vec::new();
        let mut areas = Vec::new();
        arr.sub
            .trace_faces(&mut mark, |h0| areas.push(arr.cycle_area(h0)));
        assert_eq!(areas.iter().filter(|&&a| a < 0.0).count(), 1, "{areas:?}");
    }

    #[test]
    fn concurrent_pieces_follow_a_consistent_perturbation() {
        // Four pieces through the origin: every triple meets in one point.
        // The symbolic perturbation (larger piece ids moved left by larger
        // infinitesimals) must give a planar subdivision and the crossing
        // orders of the explicitly perturbed configuration.
        let v = DVec2::new;
        let segs = [
            [v(-4.0, -1.0), v(4.0, 1.0)],
            [v(-1.0, 3.0), v(1.0, -3.0)],
            [v(-3.0, -3.0), v(3.0, 3.0)],
            [v(2.0, -1.0), v(-2.0, 1.0)],
        ];
        for n in [3, 4] {
            for perm in perms(2 * n, 60) {
                let tied = crossing_orders(&segs[..n], &perm);
                // Segment ids follow segment order here (prepare keeps it):
                // shift segment i left by 2^-(40 - 10 i).
                let shifted: Vec<[DVec2; 2]> = segs[..n]
                    .iter()
                    .enumerate()
                    .map(|(i, s)| {
                        // Left of the piece's direction (lower point id first).
                        let d = if perm[2 * i] < perm[2 * i + 1] {
                            s[1] - s[0]
                        } else {
                            s[0] - s[1]
                        };
                        let w = DVec2::new(-d.y, d.x) * (2f64).powi(-40 + 10 * i as i32);
                        [s[0] + w, s[1] + w]
                    })
                    .collect();
                let exact = crossing_orders(&shifted, &perm);
                assert_eq!(tied, exact, "perm {perm:?}");
                // Every role of the largest id (insertion only asks with it
                // as p or q1): one order per pair, whichever comes first.
                let arr = prepared(&segs[..n], &perm);
                for p in 0..n as u32 {
                    for q1 in 0..n as u32 {
                        for q2 in 0..n as u32 {
                            if p != q1 && p != q2 && q1 != q2 {
                                assert_ne!(
                                    arr.cross_before_mutual(p, q1, q2),
                                    arr.cross_before_mutual(p, q2, q1)
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
