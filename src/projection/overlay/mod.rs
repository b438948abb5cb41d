//! The fast path of the projection: the regions of a piece in general
//! position, as the intersections of its front and back triangles, without
//! building the arrangement.
//!
//! The front triangles of a convex piece tile its silhouette `S`, and so do
//! the back triangles; a region is then exactly the intersection `F ∩ B` of
//! a front and a back triangle with positive area (no other edge enters the
//! interior of `F` or of `B`). [`Overlay::build`] first checks, exactly,
//! that the rounded pixel positions keep that structure, and otherwise
//! declines (the caller then takes the general path, `arrangement`):
//!
//! 1. all points distinct (checked by the caller), no triangle edge-on, and
//!    a closed surface (every edge used once in each direction);
//! 2. the silhouette edges (one front and one back triangle) form a single
//!    cycle with strictly left turns at every vertex that winds once around
//!    (a strictly convex polygon). The boundary of the 2-chain of front
//!    triangles (all counter-clockwise once front ones are reversed) is that
//!    cycle, so by the degree argument every point off the edges is covered
//!    by exactly one front triangle (its winding number, 1 inside and 0
//!    outside); likewise for the back triangles;
//! 3. no point lies on an edge it does not end, so two edges meet at most
//!    at a shared endpoint or at a proper crossing, and no three edges
//!    cross at a point (front edges never cross front edges in a tiling).
//!    Only points used by front triangles alone against edges between two
//!    back triangles need testing (`orient2d` when in the edge's bounding
//!    box), and vice versa: a front point cannot lie inside a front edge
//!    (the non-degenerate front triangles tile `S`), nor a silhouette point
//!    (an extreme point of `S`) inside any edge.
//!
//! Then every crossing is a proper crossing of an edge between two front
//! triangles and an edge between two back triangles. Its position is
//! computed once, in `f64` from the two edges' original endpoints (the
//! general path's formula). Regions are traced counter-clockwise from
//! neighbour to neighbour, starting with the front and back triangle of one
//! silhouette edge (whose intersection has the edge's start as a corner).
//! Leaving a vertex along edge `g` of one triangle into the other, `T`: the
//! line of `g` leaves `T` across the edge of `T` whose start lies strictly
//! right of `g` and whose end strictly left (the sides of `T`'s corners,
//! cached `orient2d` of original points, or known from an edge's own ends
//! and its triangles' exact facings; a corner on the line is a shared
//! endpoint or lies beyond `g`'s ends). If `g`'s end is outside that edge,
//! `g` crosses it: the next vertex is the crossing, then follow the crossed
//! edge. Otherwise the next vertex is `g`'s end, strictly inside `T`
//! (continue along the same triangle) or a shared corner (continue along the
//! more counter-clockwise of the two triangles' next edges: a cached side).
//! Each piece of boundary followed along a non-silhouette
//! edge is also a piece of the boundary of the region across it (the
//! triangle across the edge, intersected with the same other triangle),
//! which is queued with its walk's start (the piece's end, along the edge
//! reversed) unless already found; that walk's first step, back along the
//! piece, and where it turns at the piece's start are known from this walk
//! when it reached the piece's start by a crossing or strictly inside a
//! triangle, and are not traced again. Every decision is an exact predicate on
//! original points; anything unexpected (a zero orientation, a walk that
//! does not close) declines to the general path.

use glam::DVec2;

use self::surface::Topology;
use super::arrangement::segment_crossing;
use super::subdivision::NIL;
use super::{Facing, VertexKind};
use crate::numeric::predicates::{orient2d, Side};

mod surface;

/// Pieces with more points take the general path (the edge table is
/// `n * n`).
pub(super) const MAX_POINTS: usize = 64;

/// Pieces with more triangles take the general path (a closed surface of
/// `MAX_POINTS` points without handles has `2 * MAX_POINTS - 4`).
const MAX_TRIANGLES: usize = 1 << 15;

/// Not computed yet (crossing table).
const UNKNOWN: u32 = NIL - 1;

/// Where to start tracing a region: at vertex `v`, along edge `k` of
/// triangle `t1`, inside triangle `t2`.
#[derive(Clone, Copy, Debug)]
struct Start {
    v: u32,
    t1: u32,
    k: u8,
    t2: u32,
}

/// A [`Start`] packed into one word (`v` in bits 0-31, `t1` 32-46, `t2`
/// 47-61, `k` 62-63; triangle ids are below [`MAX_TRIANGLES`]): queued
/// and taken back at once, so it is written and read by a single store
/// and load (a struct written field by field and read as a block stalls).
#[derive(Clone, Copy, Debug)]
struct Packed(u64);

impl Start {
    #[inline]
    fn pack(self) -> Packed {
        Packed(
            self.v as u64 | (self.t1 as u64) << 32 | (self.t2 as u64) << 47 | (self.k as u64) << 62,
        )
    }

    #[inline]
    fn unpack(p: Packed) -> Start {
        let w = p.0;
        Start {
            v: w as u32,
            t1: (w >> 32) as u32 & 0x7fff,
            t2: (w >> 47) as u32 & 0x7fff,
            k: (w >> 62) as u8,
        }
    }
}

/// How a walk arrived at the start of its current step (along edge `k` of
/// `t1`, inside `t2`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Arrival {
    /// Not recorded (the walk's first step, or after a shared corner).
    Unknown,
    /// By crossing edge `k` of the current `t2`: its previous step went
    /// along that edge, inside the current `t1`.
    Crossing(u8),
    /// At the end of `t1`'s previous edge, strictly inside `t2`.
    Inside,
}

/// The first step of a queued walk, when the walk that queued it knows it
/// (see [`Overlay::region`]): the vertex it reaches and how, packed into
/// one word (`v` in bits 0-31, the arrival in 32-34: 0-2 a crossing of
/// that edge, 3 inside, 4 none).
#[derive(Clone, Copy, Debug)]
struct Known(u64);

impl Known {
    const NONE: Known = Known(4 << 32);

    #[inline]
    fn new(v: u32, how: Arrival) -> Known {
        let a = match how {
            Arrival::Crossing(k) => k as u64,
            Arrival::Inside => 3,
            Arrival::Unknown => 4,
        };
        Known(v as u64 | a << 32)
    }

    #[inline]
    fn get(self) -> (u32, Arrival) {
        let how = match (self.0 >> 32) as u8 {
            k @ 0..=2 => Arrival::Crossing(k),
            3 => Arrival::Inside,
            _ => Arrival::Unknown,
        };
        (self.0 as u32, how)
    }
}

/// A triangle's edge, as the walk needs it.
#[derive(Clone, Copy, Debug, Default)]
struct TriEdge {
    /// Edge id.
    e: u32,
    /// Index among the front (back) edges; `NIL` for a silhouette edge.
    class: u32,
    /// Whether the triangle runs along it from its smaller end.
    fwd: bool,
    /// The triangle across it, and the edge's index there.
    nbr: u32,
    nbr_k: u8,
    /// The neighbour's part of a region's index in `visited` (see
    /// `Overlay::slot`).
    nbr_slot: u32,
}

/// The next corner (edge) of a triangle.
const NEXT: [usize; 3] = [1, 2, 0];

/// Longest region walk: the intersection of two triangles has at most six
/// corners.
const MAX_WALK: usize = 8;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum EdgeKind {
    /// Between two front triangles.
    Front,
    /// Between two back triangles.
    Back,
    /// One front and one back triangle.
    Silhouette,
}

/// What an edge is in this view.
#[derive(Clone, Copy, Debug)]
struct Edge {
    kind: EdgeKind,
    /// Index among the edges of its kind (front or back).
    class: u32,
}

/// Which of its edges `ccw[t][k] -> ccw[t][k + 1]` stands for which input
/// edge `tris[t][k] -> tris[t][k + 1]` (reversed) once a front triangle
/// `t` is turned counter-clockwise as `[t0, t2, t1]`: edge `k` is input
/// edge `REVERSED[k]` (an involution).
const REVERSED: [usize; 3] = [2, 1, 0];

/// Regions of a piece in general position (see module docs). Outputs are
/// valid after [`Overlay::build`] returned `true`.
#[derive(Clone, Debug, Default)]
pub(super) struct Overlay {
    /// Corners of each triangle, counter-clockwise (front ones reversed).
    ccw: Vec<[u32; 3]>,
    is_front: Vec<bool>,
    /// The boundary's topology (view-independent, cached).
    topo: Topology,
    /// Edge id of each triangle's edge `ccw[k] -> ccw[k + 1]`.
    tri_edge: Vec<[u32; 3]>,
    /// The same edges with what the walk needs.
    te: Vec<[TriEdge; 3]>,
    edges: Vec<Edge>,
    front_edges: Vec<u32>,
    back_edges: Vec<u32>,
    succ: Vec<u32>,
    /// `orient2d(a, b, v)` of point `v` and edge `a < b`, cached.
    sides: Sides,
    /// Crossing vertex of front edge `i` and back edge `j` (`i * nb + j`),
    /// `NIL` for none, [`UNKNOWN`] before it is computed.
    cross: Vec<u32>,
    /// Per point: 1 when used by front triangles only, 2 back only, 3 both.
    vkind: Vec<u8>,
    /// Index of each triangle among the front (back) triangles.
    class: Vec<u32>,
    /// Each triangle's part of the index in `visited` of the regions under
    /// it: its class times the number of back triangles for a front one,
    /// its class for a back one (the two parts of a region add up).
    slot: Vec<u32>,
    /// Regions found (front index * backs + back index).
    visited: Vec<bool>,
    queue: Vec<(Packed, Known)>,
    /// Trace every step of every region (tests: the steps that are known
    /// from the neighbour's walk must come out the same).
    pub retrace: bool,
    /// Positions of the vertices: the points, then the crossings.
    pub pos: Vec<DVec2>,
    /// Silhouette vertices.
    pub on_hull: Vec<bool>,
    /// What the vertices are (the points, then the crossings).
    pub kinds: Vec<VertexKind>,
    /// Vertices of region `r`: `region_verts[region_start[r]..region_start[r + 1]]`.
    pub region_verts: Vec<u32>,
    pub region_start: Vec<u32>,
    /// Front and back triangle of each region.
    pub face_fb: Vec<[u32; 2]>,
}

/// Cached exact sides of points against edges: `orient2d(a, b, v)` of
/// point `v` and edge `a < b`, as a sign, computed on first use.
#[derive(Clone, Debug, Default)]
struct Sides {
    /// Index `(e << shift) + v`; 2 while not computed.
    s: Vec<i8>,
    /// Room for the points: `1 << shift` is at least their number.
    shift: u32,
}

impl Sides {
    /// Starts over for `n` points, edges with `ends` and the triangles
    /// along them (corners `ccw`, edges `tri_edge`), with the sides known
    /// without an `orient2d`: an edge's ends are on it, and the third corner
    /// of each triangle along it is on that triangle's side (exactly: the
    /// triangle is counter-clockwise by its exact facing).
    fn reset(&mut self, n: usize, ends: &[[u32; 2]], ccw: &[[u32; 3]], tri_edge: &[[u32; 3]]) {
        self.shift = n.next_power_of_two().trailing_zeros();
        self.s.clear();
        self.s.resize(ends.len() << self.shift, 2);
        for (e, &[a, b]) in ends.iter().enumerate() {
            self.s[(e << self.shift) + a as usize] = 0;
            self.s[(e << self.shift) + b as usize] = 0;
        }
        for (c, te) in ccw.iter().zip(tri_edge) {
            for k in 0..3 {
                let e = te[k] as usize;
                let third = c[NEXT[NEXT[k]]] as usize;
                self.s[(e << self.shift) + third] = if c[k] == ends[e][0] { 1 } else { -1 };
            }
        }
    }

    /// Side of point `v` of edge `e` (with `ends`, from its smaller end).
    #[inline(always)]
    fn get(&mut self, pix: &[DVec2], ends: &[[u32; 2]], v: u32, e: u32) -> i8 {
        let i = (e as usize) << self.shift | v as usize;
        let s = self.s[i];
        if s != 2 {
            return s;
        }
        self.compute(pix, ends, v, e, i)
    }

    #[cold]
    #[inline(never)]
    fn compute(&mut self, pix: &[DVec2], ends: &[[u32; 2]], v: u32, e: u32, i: usize) -> i8 {
        let [a, b] = ends[e as usize];
        let s = sign(orient2d(pix[a as usize], pix[b as usize], pix[v as usize]));
        self.s[i] = s;
        s
    }

    /// Side of point `v` of a triangle's edge `h` (counter-clockwise:
    /// positive is the triangle's side).
    #[inline(always)]
    fn tri(&mut self, pix: &[DVec2], ends: &[[u32; 2]], v: u32, h: TriEdge) -> i8 {
        let s = self.get(pix, ends, v, h.e);
        if h.fwd {
            s
        } else {
            -s
        }
    }
}

fn sign(s: Side) -> i8 {
    match s {
        Side::Positive => 1,
        Side::Negative => -1,
        Side::On => 0,
    }
}

impl Overlay {
    /// Builds the regions of the piece with (distinct) pixel positions
    /// `pix`, boundary triangles `tris` and their `facing`; `false` when the
    /// piece is not in general position (see module docs; nothing useful is
    /// left then).
    pub(super) fn build(&mut self, pix: &[DVec2], tris: &[[u32; 3]], facing: &[Facing]) -> bool {
        let n = pix.len();
        if n > MAX_POINTS || tris.is_empty() || tris.len() > MAX_TRIANGLES {
            return false;
        }
        // 1. Triangles counter-clockwise, edges and their kinds.
        self.ccw.clear();
        self.is_front.clear();
        self.class.clear();
        let (mut n_fronts, mut n_backs) = (0u32, 0u32);
        for (t, f) in tris.iter().zip(facing) {
            let c = match f {
                Facing::Front => {
                    self.class.push(n_fronts);
                    n_fronts += 1;
                    [t[0], t[2], t[1]]
                }
                Facing::Back => {
                    self.class.push(n_backs);
                    n_backs += 1;
                    *t
                }
                Facing::EdgeOn => return false,
            };
            self.ccw.push(c);
            self.is_front.push(*f == Facing::Front);
        }
        self.topo.update(n, tris);
        if !self.topo.closed {
            return false; // not a closed surface
        }
        let topo = &self.topo;
        self.front_edges.clear();
        self.back_edges.clear();
        self.edges.clear();
        self.succ.clear();
        self.succ.resize(n, NIL);
        let mut n_sil = 0;
        let mut first = NIL;
        for (id, sd) in topo.sides.iter().enumerate() {
            let (f0, f1) = (
                self.is_front[sd[0].0 as usize],
                self.is_front[sd[1].0 as usize],
            );
            self.edges.push(if f0 && f1 {
                self.front_edges.push(id as u32);
                Edge {
                    kind: EdgeKind::Front,
                    class: self.front_edges.len() as u32 - 1,
                }
            } else if !f0 && !f1 {
                self.back_edges.push(id as u32);
                Edge {
                    kind: EdgeKind::Back,
                    class: self.back_edges.len() as u32 - 1,
                }
            } else {
                // The front triangle runs along it (counter-clockwise)
                // from its input edge's end.
                let (t, k) = if f0 { sd[0] } else { sd[1] };
                let t = &topo.tris[t as usize];
                let (from, to) = (t[NEXT[k as usize]], t[k as usize]);
                if self.succ[from as usize] != NIL {
                    return false;
                }
                self.succ[from as usize] = to;
                n_sil += 1;
                first = from;
                Edge {
                    kind: EdgeKind::Silhouette,
                    class: NIL,
                }
            });
        }
        // 2. The silhouette: one strictly convex cycle, winding once.
        if n_sil < 3 {
            return false;
        }
        self.on_hull.clear();
        self.on_hull.resize(n, false);
        let half = |d: DVec2| d.y < 0.0 || (d.y == 0.0 && d.x < 0.0);
        let (mut prev, mut cur) = (first, self.succ[first as usize]);
        let mut wraps = 0;
        for step in 0..n_sil {
            let next = self.succ[cur as usize];
            if next == NIL || (step + 1 < n_sil && cur == first) {
                return false;
            }
            let (p, c, q) = (pix[prev as usize], pix[cur as usize], pix[next as usize]);
            if orient2d(p, c, q) != Side::Positive {
                return false;
            }
            if half(c - p) && !half(q - c) {
                wraps += 1;
            }
            self.on_hull[cur as usize] = true;
            (prev, cur) = (cur, next);
        }
        if prev != first || wraps != 1 {
            return false;
        }
        self.slot.clear();
        self.slot
            .extend(self.is_front.iter().zip(&self.class).map(
                |(&f, &c)| {
                    if f {
                        c * n_backs
                    } else {
                        c
                    }
                },
            ));
        self.te.clear();
        self.tri_edge.clear();
        for t in 0..self.ccw.len() {
            let front = self.is_front[t];
            let adj = &topo.adj[t];
            let mut row = [TriEdge::default(); 3];
            let mut ids = [NIL; 3];
            for (k, r) in row.iter_mut().enumerate() {
                // A front triangle runs along its input edges reversed.
                let a = adj[if front { REVERSED[k] } else { k }];
                let nbr_k = if self.is_front[a.nbr as usize] {
                    REVERSED[a.nbr_j as usize]
                } else {
                    a.nbr_j as usize
                };
                ids[k] = a.e;
                *r = TriEdge {
                    e: a.e,
                    class: self.edges[a.e as usize].class,
                    fwd: a.fwd != front,
                    nbr: a.nbr,
                    nbr_k: nbr_k as u8,
                    nbr_slot: self.slot[a.nbr as usize],
                };
            }
            self.te.push(row);
            self.tri_edge.push(ids);
        }
        // 3. No point on an edge it does not end. A front vertex cannot lie
        // inside a front edge (the front triangles tile `S` and are not
        // degenerate), nor a silhouette vertex (an extreme point of `S`)
        // inside any: only vertices of one kind against edges of the other
        // remain.
        self.sides.reset(n, &topo.ends, &self.ccw, &self.tri_edge);
        self.vkind.clear();
        self.vkind.resize(n, 0);
        for (t, c) in self.ccw.iter().enumerate() {
            let bit = if self.is_front[t] { 1 } else { 2 };
            for &v in c {
                self.vkind[v as usize] |= bit;
            }
        }
        for v in 0..n {
            let count = match self.vkind[v] {
                1 => self.back_edges.len(),
                2 => self.front_edges.len(),
                _ => continue,
            };
            let q = pix[v];
            for i in 0..count {
                let e = if self.vkind[v] == 1 {
                    self.back_edges[i]
                } else {
                    self.front_edges[i]
                };
                let [a, b] = topo.ends[e as usize];
                let (pa, pb) = (pix[a as usize], pix[b as usize]);
                if q.x < pa.x.min(pb.x)
                    || q.x > pa.x.max(pb.x)
                    || q.y < pa.y.min(pb.y)
                    || q.y > pa.y.max(pb.y)
                {
                    continue;
                }
                if self.sides.get(pix, &topo.ends, v as u32, e) == 0 {
                    return false;
                }
            }
        }
        // Crossings of front and back edges, computed on demand.
        self.cross.clear();
        self.cross
            .resize(self.front_edges.len() * self.back_edges.len(), UNKNOWN);
        self.pos.clear();
        self.pos.extend_from_slice(pix);
        self.kinds.clear();
        self.kinds.extend(self.vkind.iter().map(|&k| match k {
            1 => VertexKind::Front,
            2 => VertexKind::Back,
            _ => VertexKind::Silhouette,
        }));
        // 4. Regions, from neighbour to neighbour, starting at a silhouette
        // edge `u -> v` of front triangle `f` and back triangle `b`: the
        // region `f ∩ b` has the corner `u`, left along that edge.
        self.region_verts.clear();
        self.region_start.clear();
        self.region_start.push(0);
        self.face_fb.clear();
        self.visited.clear();
        self.visited.resize((n_fronts * n_backs) as usize, false);
        self.queue.clear();
        let Some(seed) = self
            .edges
            .iter()
            .position(|e| e.kind == EdgeKind::Silhouette)
        else {
            return false;
        };
        let [(t0, _), (t1, _)] = self.topo.sides[seed];
        let (f, b) = if self.is_front[t0 as usize] {
            (t0, t1)
        } else {
            (t1, t0)
        };
        let Some(k) = (0..3).find(|&k| self.tri_edge[f as usize][k] == seed as u32) else {
            return false;
        };
        let u = self.ccw[f as usize][k];
        self.visited[(self.slot[f as usize] + self.slot[b as usize]) as usize] = true;
        self.queue.push((
            Start {
                v: u,
                t1: f,
                k: k as u8,
                t2: b,
            }
            .pack(),
            Known::NONE,
        ));
        while let Some((st, known)) = self.queue.pop() {
            if !self.region(pix, Start::unpack(st), known) {
                return false;
            }
        }
        true
    }

    /// Traces region `t1 ∩ t2` counter-clockwise from `st` and queues its
    /// neighbours not found yet; `false` when something unexpected declines
    /// the fast path. (The fields are borrowed one by one, so that the
    /// walk's tables stay in registers.)
    ///
    /// A walk that followed a piece `u -> v` of edge `g` (of `t1`, inside
    /// `t2`) queues the region across `g` (`t1' ∩ t2`, `t1'` across `g`)
    /// to start at `v` along `g` reversed: its first step ends at `u`, and
    /// where it goes on from there is known (`known`) when this walk
    /// arrived at `u` by crossing edge `h` of `t2` (it crosses `h` there
    /// too, and follows `h` inside `t1'`) or at `g`'s start strictly inside
    /// `t2` (it follows the edge of `t1'` after `g`). Only at a shared
    /// corner is its turn left to the walk.
    fn region(&mut self, pix: &[DVec2], st: Start, known: Known) -> bool {
        let Overlay {
            ccw,
            is_front,
            te,
            topo,
            back_edges,
            slot,
            sides,
            cross,
            visited,
            queue,
            pos,
            kinds,
            region_verts,
            region_start,
            face_fb,
            retrace,
            ..
        } = self;
        let (ccw, is_front, te, slot) = (&ccw[..], &is_front[..], &te[..], &slot[..]);
        let ends = &topo.ends[..];
        let n_back_edges = back_edges.len();
        let Start { v: v0, t1, k, t2 } = st;
        let (mut t1, mut k, mut t2) = (t1 as usize, k as usize, t2 as usize);
        let mut t1_front = is_front[t1];
        let (f, b) = if t1_front { (t1, t2) } else { (t2, t1) };
        let begin = region_verts.len();
        region_verts.push(v0);
        // The current step's start, and how the walk got there.
        let (mut cur, mut arrived) = (v0, Arrival::Unknown);
        match known.get() {
            (u, Arrival::Crossing(j)) if !*retrace => {
                // Along edge j of t2 (crossed at u), inside t1.
                region_verts.push(u);
                (t1, t2, k) = (t2, t1, j as usize);
                t1_front = !t1_front;
                (cur, arrived) = (u, Arrival::Crossing(st.k));
            }
            (u, Arrival::Inside) if !*retrace => {
                region_verts.push(u);
                k = NEXT[k];
                (cur, arrived) = (u, Arrival::Inside);
            }
            _ => {}
        }
        let mut closed = false;
        for _ in 0..MAX_WALK {
            // Along edge g = k of t1 (s -> e), inside t2.
            let e = ccw[t1][NEXT[k]];
            let g = te[t1][k];
            let other = t2;
            let c = ccw[t2];
            // The line of g leaves t2 across the edge whose start is on its
            // right and whose end on its left (strictly: a corner of t2 on
            // the line is a shared endpoint, or beyond g's ends); g itself
            // leaves there when e is outside that edge. A silhouette edge
            // never leaves.
            let mut exit = None;
            let mut inside = false;
            if g.class != NIL {
                let o = [
                    sides.tri(pix, ends, c[0], g),
                    sides.tri(pix, ends, c[1], g),
                    sides.tri(pix, ends, c[2], g),
                ];
                let j = if o[0] < 0 && o[1] > 0 {
                    0
                } else if o[1] < 0 && o[2] > 0 {
                    1
                } else if o[2] < 0 && o[0] > 0 {
                    2
                } else {
                    3
                };
                if j < 3 {
                    let h = te[t2][j];
                    match sides.tri(pix, ends, e, h) {
                        -1 => {
                            // g crosses h: the crossing vertex, computed
                            // once from the front edge's ends and the back
                            // edge's.
                            let (fe, be) = if t1_front { (g, h) } else { (h, g) };
                            let slot = fe.class as usize * n_back_edges + be.class as usize;
                            let mut x = cross[slot];
                            if x == UNKNOWN {
                                let (fe, be) = (ends[fe.e as usize], ends[be.e as usize]);
                                x = pos.len() as u32;
                                pos.push(segment_crossing(
                                    pix[fe[0] as usize],
                                    pix[fe[1] as usize],
                                    pix[be[0] as usize],
                                    pix[be[1] as usize],
                                ));
                                kinds.push(VertexKind::Crossing {
                                    front: fe,
                                    back: be,
                                });
                                cross[slot] = x;
                            }
                            exit = Some((x, j));
                        }
                        0 => return false,
                        // e before the exit: strictly inside t2.
                        _ => inside = true,
                    }
                }
            }
            let from = (cur, arrived);
            let v = if let Some((x, j)) = exit {
                arrived = Arrival::Crossing(k as u8);
                (t1, t2, k) = (t2, t1, j);
                t1_front = !t1_front;
                x
            } else if let Some(j) = (0..3).find(|&j| c[j] == e) {
                arrived = Arrival::Unknown;
                // A shared corner: the region's wedge there starts at the
                // more counter-clockwise of the two next edges, `e -> a`
                // (t1's edge after g) and `e -> c` (t2's): the side of `c`
                // of t1's edge `e -> a` (cached).
                let (a, c) = (ccw[t1][NEXT[NEXT[k]]], c[NEXT[j]]);
                let turn = if a == c {
                    -1
                } else {
                    sides.tri(pix, ends, c, te[t1][NEXT[k]])
                };
                match turn {
                    -1 => k = NEXT[k],
                    1 => {
                        (t1, t2, k) = (t2, t1, j);
                        t1_front = !t1_front;
                    }
                    _ => return false,
                }
                e
            } else if inside || te[t2].iter().all(|&h| sides.tri(pix, ends, e, h) > 0) {
                arrived = Arrival::Inside;
                k = NEXT[k];
                e
            } else {
                return false;
            };
            // The neighbour across the edge just followed shares this piece
            // of it, reversed: its walk can start at `v`.
            if g.class != NIL {
                let i = (g.nbr_slot + slot[other]) as usize;
                if !std::mem::replace(&mut visited[i], true) {
                    queue.push((
                        Start {
                            v,
                            t1: g.nbr,
                            k: g.nbr_k,
                            t2: other as u32,
                        }
                        .pack(),
                        Known::new(from.0, from.1),
                    ));
                }
            }
            if v == v0 {
                closed = true;
                break;
            }
            region_verts.push(v);
            cur = v;
        }
        let len = region_verts.len() - begin;
        if !closed || len < 3 {
            return false;
        }
        region_start.push(region_verts.len() as u32);
        face_fb.push([f as u32, b as u32]);
        true
    }
}

#[cfg(test)]
mod tests;
