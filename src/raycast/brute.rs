//! Brute-force traversal: every piece a ray meets, found without adjacency.
//!
//! The walk ([`super::walk`]) goes from cell to cell by face adjacency.
//! Where adjacency cannot be trusted (non-conforming faces that only partly
//! overlap, as in corner-point grids with faults; overlapping or duplicated
//! cells; duplicated points that were not merged) it may skip a piece or
//! follow one of two overlapping layers. This traversal looks at every
//! piece on its own, so it settles such disagreements. On a conforming mesh
//! it gives the walk's image to rounding (`tests/raycast_brute.rs`).
//!
//! **Pieces.** `faces`: each mesh cell, as the closed surface of its face
//! triangles (quads split by the diagonal from the smallest point id, n-gons
//! fanned from it: the walk's triangles). `tets`: each tet of the consistent
//! tetrahedralisation ([`tetrahedralize_cell`]). A piece whose consistent
//! tets are all flat (exact [`orient3d`]) encloses no volume and is left
//! out: its surface is the boundary of those tets as a chain, so its
//! winding number is zero off their planes.
//!
//! **Candidates.** A [`Bvh`] over the cells' boxes, plus a test of each
//! candidate's own box (rounded outwards to `f32`), gives the cells whose
//! box the line meets at `t >= t_near`, leaf by leaf in order of depth
//! ([`Bvh::query_ordered`]). A candidate cell's points are projected onto
//! the ray's frame once; if they all lie clearly on one side of the line
//! ([`RayFrame::clear_sides`]) the cell is skipped, otherwise its pieces
//! (the cell, or its tets) are crossed, sharing the edge values.
//!
//! **Crossings.** For each candidate, the line's crossings with all its
//! triangles are decided by the walk's exact predicate ([`RayFrame::edge`]
//! and [`RayFrame::crossing`]: the same Plücker signs and the same
//! simulation-of-simplicity tie rule, with the same far point, so a ray
//! through an edge or vertex crosses exactly one triangle of each closed
//! fan, as in the walk). A triangle is evaluated with its vertices in
//! increasing point id (the crossing's sign corrected by the parity of that
//! permutation), so the two pieces on either side of a shared triangle get
//! bit-identical depths and weights: on a conforming mesh neighbouring
//! segments meet exactly, with no gap and no overlap. The scalar at a
//! crossing is the barycentric interpolation on the triangle, as in the
//! walk.
//!
//! **Entries and exits.** A piece's crossings, sorted by depth and summed by
//! sign (+1 along the triangle's winding normal, -1 against), give the
//! winding number of its surface along the line, 0 far away. The piece
//! holds the parts of the line where the winding is non-zero: a segment
//! opens where it leaves 0 and closes where it returns to 0. So a convex
//! piece gives one segment; a `faces` cell with nonplanar faces that the ray
//! leaves and re-enters gives two or more; an inverted piece (winding -1
//! inside) counts like a positive one; a surface that wraps twice (winding
//! 2) counts once; a piece of zero net volume that is not flat (a twisted
//! cell whose lobes have opposite orientation) counts both lobes. Crossings
//! are taken on the whole line, so an eye inside a piece is inside it;
//! segments are then clipped to `t >= t_near` (scalar interpolated linearly,
//! as the walk clips) and zero-length ones dropped. An unpaired last
//! crossing (an open surface: a polyhedron with missing faces) is dropped.
//!
//! **Compositing.** The segments of all pieces are sorted by entry depth
//! (ties by piece index) and integrated exactly with the walk's
//! `material.segment(l, s_in, s_out)`, front to back, with its early
//! termination. This happens while the leaves are visited: segments in
//! front of the next leaf's box are final, so a terminated ray stops the
//! search ([`Brute::trace`]). Where segments overlap in depth (overlapping pieces), the
//! overlapping run is split at every segment boundary, and within each
//! sub-interval the pieces' sub-segments (scalars interpolated linearly to
//! the cuts) are composited one after the other in order of their segment's
//! entry depth. Optical depths of overlapping pieces therefore add (the
//! transmittance is the product: "extinction adds", the physical rule, for
//! opacity). The colour is exact where the overlapping sub-segments have
//! one constant colour (a duplicated cell under glow with a constant colour
//! gives `c (1 - e^(-2 d))`); otherwise the front piece's light in a
//! sub-interval is not dimmed by the back piece's extinction there, an error
//! of the order of the product of their optical depths times their colour
//! difference. Overlaps are counted ([`Brute::stats`]; those of ~1e-16
//! where two pieces meet at an edge or vertex, whose depths round
//! differently through different triangles, are not).
//!
//! **Isosurfaces** ([`super::iso::BruteIsoReference`]): each composited
//! part ([`Part`]: a whole segment, or a sub-interval of an overlap) is
//! split at the surfaces it crosses by [`crate::render::iso::IsoSet::composite`],
//! the scalar being linear along it as on the walk's segments; the
//! gradient is its piece's (flat) or the points' gradients interpolated at
//! the crossings with the triangles' barycentric weights, linear between
//! (smooth, [`Brute::trace_with`]).
//!
//! The `native` model is not offered ([`RaycastError::BruteModel`]): its
//! pieces are bounded by bilinear patches, not triangles.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use super::bvh::{ray_hits_box, Bvh, NodeQueue};
use super::geometry::{Proj, RayFrame};
use super::{stop_depth, Segment};
use super::{validate, FieldModel, RayTracer, RaycastError, RaycastOptions, Scalars, Scene};
use crate::camera::Ray;
use crate::integrate::{RayAccumulator, RayMaterial, SegmentValue};
use crate::mesh::tetra::{tetrahedralize, tetrahedralize_cell};
use crate::mesh::CellKind;
use crate::numeric::predicates::{orient3d, Side};
use crate::numeric::tolerance::{BRUTE_OVERLAP_REPORT_REL, BVH_PAD_REL};

/// Counts of a brute-force render (summed over every ray traced so far).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct BruteStats {
    /// Candidate cells: those whose own box the ray meets (their points
    /// are projected onto the ray).
    pub cells_tested: u64,
    /// Segments integrated (after clipping; none after a ray terminated).
    pub segments: u64,
    /// Segments that start before the segments ahead of them end (by more
    /// than [`BRUTE_OVERLAP_REPORT_REL`] of the bounds diagonal): pieces
    /// that overlap in space.
    pub overlapping_segments: u64,
}

impl BruteStats {
    /// The counts accumulated since `before`.
    pub fn since(&self, before: &BruteStats) -> BruteStats {
        BruteStats {
            cells_tested: self.cells_tested.saturating_sub(before.cells_tested),
            segments: self.segments.saturating_sub(before.segments),
            overlapping_segments: self
                .overlapping_segments
                .saturating_sub(before.overlapping_segments),
        }
    }
}

/// Per-thread scratch space for brute-force rays.
#[derive(Default)]
pub struct BruteScratch {
    stack: Vec<u32>,
    queue: NodeQueue,
    proj: Vec<(u32, DVec3, Proj)>,
    /// Edge values of the current cell by local node pair (NaN: not yet).
    edges: Vec<f64>,
    local: Vec<usize>,
    /// Crossings of the current piece: depth, sign, scalar, gradient.
    crossings: Vec<(f64, i8, f64, DVec3)>,
    /// Segments of the ray with their piece and end gradients.
    segs: Vec<PieceSegment>,
    cuts: Vec<f64>,
    active: Vec<usize>,
}

/// A scene prepared for brute-force ray casting with the `faces` or `tets`
/// model.
pub struct Brute<'a> {
    pub(super) scene: Scene<'a>,
    model: FieldModel,
    /// `tets`: the non-flat consistent tets, cell `c`'s at
    /// `tets[tet_offsets[c]..tet_offsets[c + 1]]`.
    tets: Option<(Vec<[u32; 4]>, Vec<u32>)>,
    /// Pieces traced (cells or tets).
    pieces: usize,
    /// BVH item `k` is cell `ids[k]`, with box `boxes[k]` (lo, hi).
    ids: Vec<u32>,
    boxes: Vec<[f32; 6]>,
    bvh: Bvh,
    center: DVec3,
    radius: f64,
    /// Padding of the boxes ([`BVH_PAD_REL`] x scene size, as the walk's BVH).
    pad: f64,
    flat: usize,
    counts: [AtomicU64; 3],
}

/// A segment of the ray with its piece and the points' gradients
/// interpolated at its ends (zero unless asked for: [`Brute::trace_with`]).
type PieceSegment = (Segment, u32, [DVec3; 2]);

/// The part of a piece's segment composited at once (the whole segment, or
/// a sub-interval of an overlap): length, scalars and gradients at its ends
/// (linear between), the piece (a cell for `faces`, an index of
/// [`Brute::piece_nodes`] for `tets`) and its mesh cell.
#[derive(Clone, Copy, Debug)]
pub struct Part {
    pub piece: u32,
    pub cell: u32,
    pub l: f64,
    pub s: [f64; 2],
    pub g: [DVec3; 2],
}

/// The largest `f32` not above `x` (boxes are rounded outwards).
fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) <= x || f.is_nan() || f == f32::NEG_INFINITY {
        return f;
    }
    let b = f.to_bits();
    if f == 0.0 {
        f32::from_bits(0x8000_0001)
    } else if b >> 31 == 0 {
        f32::from_bits(b - 1)
    } else {
        f32::from_bits(b + 1)
    }
}

fn f32_up(x: f64) -> f32 {
    -f32_down(-x)
}

/// The three local indices sorted by point id (then local index), and
/// the parity of that permutation (+1 even, -1 odd).
#[inline]
fn canonical(t: [usize; 3], nodes: &[u32]) -> ([usize; 3], i8) {
    let key = |k: usize| (nodes[k], k);
    let [mut a, mut b, mut c] = t;
    let mut parity = 1;
    if key(a) > key(b) {
        std::mem::swap(&mut a, &mut b);
        parity = -parity;
    }
    if key(b) > key(c) {
        std::mem::swap(&mut b, &mut c);
        parity = -parity;
    }
    if key(a) > key(b) {
        std::mem::swap(&mut a, &mut b);
        parity = -parity;
    }
    ([a, b, c], parity)
}

impl<'a> Brute<'a> {
    /// Validates the scene and builds the pieces and their BVH; `native`
    /// is an error ([`RaycastError::BruteModel`]).
    pub fn new(scene: Scene<'a>, model: FieldModel) -> Result<Brute<'a>, RaycastError> {
        if model == FieldModel::Native {
            return Err(RaycastError::BruteModel(model.name()));
        }
        validate(&scene)?;
        let mesh = scene.mesh;
        let points = &mesh.points[..];
        let cells = &mesh.cells;
        let flat_tet = |t: &[u32; 4]| {
            let [a, b, c, d] = t.map(|v| points[v as usize]);
            orient3d(a, b, c, d) == Side::On
        };
        // The walk's bounding sphere (over the nodes of its cells or tets),
        // so that the ray frame and its tie-breaking far point are the
        // walk's.
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let mut grow = |n: u32| {
            lo = lo.min(points[n as usize]);
            hi = hi.max(points[n as usize]);
        };
        let mut kept = vec![true; cells.len()];
        let (tets, pieces, flat) = if model == FieldModel::Tets {
            let (all, offsets) = tetrahedralize(cells);
            all.iter().flatten().for_each(|&n| grow(n));
            let mut list = Vec::with_capacity(all.len());
            let mut offs = Vec::with_capacity(cells.len() + 1);
            offs.push(0);
            for c in 0..cells.len() {
                let ts = &all[offsets[c] as usize..offsets[c + 1] as usize];
                list.extend(ts.iter().filter(|t| !flat_tet(t)));
                kept[c] = list.len() > *offs.last().unwrap_or(&0) as usize;
                offs.push(list.len() as u32);
            }
            let (n, flat) = (list.len(), all.len() - list.len());
            (Some((list, offs)), n, flat)
        } else {
            cells.conn.iter().for_each(|&n| grow(n));
            let mut buf = Vec::new();
            let mut flat = 0;
            for (c, k) in kept.iter_mut().enumerate() {
                buf.clear();
                tetrahedralize_cell(cells, c, &mut buf);
                if buf.iter().all(flat_tet) {
                    *k = false;
                    flat += 1;
                }
            }
            (None, cells.len() - flat, flat)
        };
        if lo.x > hi.x {
            lo = DVec3::ZERO;
            hi = DVec3::ZERO;
        }
        let (center, radius) = super::geometry::bounding_sphere(lo, hi);
        let mut ids = Vec::with_capacity(cells.len());
        let mut boxes = Vec::with_capacity(cells.len());
        let mut dboxes = Vec::with_capacity(cells.len());
        for c in (0..cells.len()).filter(|&c| kept[c]) {
            let mut plo = DVec3::splat(f64::INFINITY);
            let mut phi = DVec3::splat(f64::NEG_INFINITY);
            for &n in cells.nodes(c) {
                plo = plo.min(points[n as usize]);
                phi = phi.max(points[n as usize]);
            }
            ids.push(c as u32);
            dboxes.push((plo, phi));
        }
        let pad = BVH_PAD_REL * (radius + center.abs().max_element()).max(f64::MIN_POSITIVE);
        let mut bvh = Bvh::build(&dboxes, pad);
        let order = bvh.renumber_in_leaf_order();
        let ids: Vec<u32> = order.iter().map(|&k| ids[k as usize]).collect();
        for &k in &order {
            let (plo, phi) = dboxes[k as usize];
            let (a, b) = (plo - DVec3::splat(pad), phi + DVec3::splat(pad));
            boxes.push([
                f32_down(a.x),
                f32_down(a.y),
                f32_down(a.z),
                f32_up(b.x),
                f32_up(b.y),
                f32_up(b.z),
            ]);
        }
        Ok(Brute {
            scene,
            model,
            tets,
            pieces,
            ids,
            boxes,
            bvh,
            center,
            radius,
            pad,
            flat,
            counts: Default::default(),
        })
    }

    /// The field model.
    pub fn model(&self) -> FieldModel {
        self.model
    }

    /// Number of pieces left out because they are flat (zero volume).
    pub fn flat_pieces(&self) -> usize {
        self.flat
    }

    /// Number of pieces traced (cells or tets, flat ones left out).
    pub fn piece_count(&self) -> usize {
        self.pieces
    }

    /// Bytes of memory the prepared structures hold (beyond the mesh).
    pub fn bytes(&self) -> usize {
        let mut b = self.bvh.bytes() + self.ids.len() * 4 + self.boxes.len() * 24;
        if let Some((t, o)) = &self.tets {
            b += t.len() * 16 + o.len() * 4;
        }
        b
    }

    /// The point ids of piece `piece` (a cell for `faces`, a tet for `tets`).
    pub fn piece_nodes(&self, piece: u32) -> Option<&[u32]> {
        match &self.tets {
            Some((tets, _)) => tets.get(piece as usize).map(|t| &t[..]),
            None => {
                let cells = &self.scene.mesh.cells;
                ((piece as usize) < cells.len()).then(|| cells.nodes(piece as usize))
            }
        }
    }

    /// The counts summed over every ray traced so far.
    pub fn stats(&self) -> BruteStats {
        let c = |k: usize| self.counts[k].load(Ordering::Relaxed);
        BruteStats {
            cells_tested: c(0),
            segments: c(1),
            overlapping_segments: c(2),
        }
    }

    /// Every segment of `ray` with `t >= t_near` (clipped there), sorted by
    /// entry depth then piece; segments of overlapping pieces overlap.
    pub fn segments(&self, ray: &Ray, t_near: f64) -> Vec<Segment> {
        let mut scratch = BruteScratch::default();
        self.collect(ray, t_near, &mut scratch);
        scratch.segs.iter().map(|s| s.0).collect()
    }

    /// Whether the line meets BVH item `k`'s own box at `t >= t0`.
    #[inline]
    fn item_hit(&self, k: u32, o: DVec3, inv: DVec3, t0: f64) -> bool {
        let b = &self.boxes[k as usize];
        let lo = DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64);
        let hi = DVec3::new(b[3] as f64, b[4] as f64, b[5] as f64);
        ray_hits_box(lo, hi, o, inv, t0)
    }

    /// Collects all sorted segments of `ray` into `scratch.segs`.
    fn collect(&self, ray: &Ray, t_near: f64, scratch: &mut BruteScratch) {
        let frame = RayFrame::new(ray, self.center, self.radius);
        let mut segs = std::mem::take(&mut scratch.segs);
        let mut stack = std::mem::take(&mut scratch.stack);
        segs.clear();
        let inv = DVec3::ONE / frame.d;
        self.bvh.query(frame.o, frame.d, t_near, &mut stack, |k| {
            if self.item_hit(k, frame.o, inv, t_near) {
                let c = self.ids[k as usize];
                self.cell_segments(&frame, c, t_near, None, scratch, &mut segs);
            }
        });
        segs.sort_unstable_by(|a, b| a.0.t_in.total_cmp(&b.0.t_in).then(a.1.cmp(&b.1)));
        scratch.segs = segs;
        scratch.stack = stack;
    }

    /// Appends the segments of cell `c`'s pieces along the ray (see the
    /// module docs: non-zero winding, clipped at `t_near`), with the
    /// points' gradients `grads` interpolated at their ends where given.
    fn cell_segments(
        &self,
        frame: &RayFrame,
        c: u32,
        t_near: f64,
        grads: Option<&[DVec3]>,
        scratch: &mut BruteScratch,
        out: &mut Vec<PieceSegment>,
    ) {
        let cells = &self.scene.mesh.cells;
        let ci = c as usize;
        let nodes = cells.nodes(ci);
        let points = &self.scene.mesh.points;
        let proj = &mut scratch.proj;
        proj.clear();
        // Quick reject: every point clearly on one side of the line.
        let mut shared = 0xff;
        for &n in nodes {
            let q = points[n as usize];
            let pr = frame.project(q);
            shared &= frame.clear_sides(&pr);
            proj.push((n, q, pr));
        }
        if shared != 0 {
            return;
        }
        let nn = nodes.len();
        scratch.edges.clear();
        scratch.edges.resize(nn * nn, f64::NAN);
        let mut ray = CellRay {
            frame,
            proj: &scratch.proj,
            edges: &mut scratch.edges,
            nodes,
            scalars: self.scene.scalars,
            cell: c,
            grads,
        };
        let crossings = &mut scratch.crossings;
        match &self.tets {
            None => {
                crossings.clear();
                let kind = cells.kinds[ci];
                if kind != CellKind::Polyhedron {
                    for lf in kind.faces() {
                        let n = lf.len();
                        let k0 = (0..n).min_by_key(|&i| nodes[lf[i] as usize]).unwrap_or(0);
                        for i in 1..n.saturating_sub(1) {
                            let t = [lf[k0], lf[(k0 + i) % n], lf[(k0 + i + 1) % n]];
                            crossings.extend(ray.crossing(t.map(|k| k as usize)));
                        }
                    }
                } else {
                    let local = &mut scratch.local;
                    cells.for_each_face(ci, |_, face| {
                        local.clear();
                        for &g in face {
                            match nodes.iter().position(|&n| n == g) {
                                Some(k) => local.push(k),
                                None => return,
                            }
                        }
                        let n = local.len();
                        let k0 = (0..n).min_by_key(|&i| nodes[local[i]]).unwrap_or(0);
                        for i in 1..n.saturating_sub(1) {
                            let t = [local[k0], local[(k0 + i) % n], local[(k0 + i + 1) % n]];
                            crossings.extend(ray.crossing(t));
                        }
                    });
                }
                pair_crossings(crossings, c, c, t_near, out);
            }
            Some((tets, offsets)) => {
                let range = offsets[ci] as usize..offsets[ci + 1] as usize;
                for (ti, tet) in tets[range.clone()].iter().enumerate() {
                    let local = tet.map(|g| nodes.iter().position(|&n| n == g).unwrap_or(0));
                    crossings.clear();
                    for f in CellKind::Tetra.faces() {
                        let t = [
                            local[f[0] as usize],
                            local[f[1] as usize],
                            local[f[2] as usize],
                        ];
                        crossings.extend(ray.crossing(t));
                    }
                    let piece = (range.start + ti) as u32;
                    pair_crossings(crossings, c, piece, t_near, out);
                }
            }
        }
    }

    /// Integrates one ray from `t_near` on.
    ///
    /// Leaves of the BVH are visited front to back
    /// ([`Bvh::query_ordered`]); before a leaf whose box starts at depth
    /// `T`, every run of segments (segments overlapping transitively) that
    /// ends before `T` is complete (no piece not yet seen starts before
    /// `T`) and is composited, so a ray that reaches the termination depth
    /// stops looking at pieces. The result is that of compositing all the
    /// ray's sorted segments at once.
    pub fn trace<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut BruteScratch,
    ) -> RayAccumulator {
        self.trace_with(ray, t_near, opts, scratch, None, |p| {
            material.segment(p.l, p.s[0], p.s[1])
        })
    }

    /// [`Brute::trace`] with each [`Part`]'s value given by `value` (the
    /// material's integral, or that with isosurfaces), the points'
    /// gradients `grads` interpolated at the segments' ends where given.
    pub fn trace_with(
        &self,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut BruteScratch,
        grads: Option<&[DVec3]>,
        value: impl Fn(&Part) -> SegmentValue,
    ) -> RayAccumulator {
        let frame = RayFrame::new(ray, self.center, self.radius);
        let stop = stop_depth(opts);
        let mut pending = std::mem::take(&mut scratch.segs);
        let mut queue = std::mem::take(&mut scratch.queue);
        pending.clear();
        let mut acc = RayAccumulator::default();
        let mut counts = [0u64; 3];
        let inv = DVec3::ONE / frame.d;
        self.bvh
            .query_ordered(frame.o, frame.d, t_near, &mut queue, |t_leaf, items| {
                let limit = t_leaf - self.pad;
                self.flush(
                    &value,
                    &mut pending,
                    limit,
                    stop,
                    &mut acc,
                    &mut counts,
                    scratch,
                );
                if acc.depth >= stop {
                    return false;
                }
                for &k in items {
                    if self.item_hit(k, frame.o, inv, t_near) {
                        counts[0] += 1;
                        self.cell_segments(
                            &frame,
                            self.ids[k as usize],
                            t_near,
                            grads,
                            scratch,
                            &mut pending,
                        );
                    }
                }
                true
            });
        if acc.depth < stop {
            let end = f64::INFINITY;
            self.flush(
                &value,
                &mut pending,
                end,
                stop,
                &mut acc,
                &mut counts,
                scratch,
            );
        }
        for (a, x) in self.counts.iter().zip(counts) {
            if x > 0 {
                a.fetch_add(x, Ordering::Relaxed);
            }
        }
        scratch.segs = pending;
        scratch.queue = queue;
        acc
    }

    /// Composites the complete runs at the front of `pending` (sorted here):
    /// those that end at or before `limit`, until the ray terminates.
    /// `counts[1]` and `counts[2]` count the segments integrated and those
    /// overlapping the ones before them.
    #[allow(clippy::too_many_arguments)]
    fn flush(
        &self,
        value: &impl Fn(&Part) -> SegmentValue,
        pending: &mut Vec<PieceSegment>,
        limit: f64,
        stop: f64,
        acc: &mut RayAccumulator,
        counts: &mut [u64; 3],
        scratch: &mut BruteScratch,
    ) {
        if pending.is_empty() {
            return;
        }
        pending.sort_unstable_by(|a, b| a.0.t_in.total_cmp(&b.0.t_in).then(a.1.cmp(&b.1)));
        let slack = BRUTE_OVERLAP_REPORT_REL * 2.0 * self.radius;
        let mut i = 0;
        while i < pending.len() && acc.depth < stop {
            // The run of segments that overlap pending[i] (transitively).
            let mut end = pending[i].0.t_out;
            let mut j = i + 1;
            let mut overlapping = 0;
            while j < pending.len() && pending[j].0.t_in < end {
                let s = &pending[j].0;
                if end.min(s.t_out) - s.t_in > slack {
                    overlapping += 1;
                }
                end = end.max(s.t_out);
                j += 1;
            }
            if end > limit {
                break;
            }
            if j == i + 1 {
                let (s, piece, g) = &pending[i];
                acc.add(&value(&Part {
                    piece: *piece,
                    cell: s.cell,
                    l: s.t_out - s.t_in,
                    s: [s.s_in, s.s_out],
                    g: *g,
                }));
            } else {
                composite_overlap(value, &pending[i..j], stop, acc, scratch);
            }
            counts[1] += (j - i) as u64;
            counts[2] += overlapping;
            i = j;
        }
        pending.drain(..i);
    }
}

/// Rendering an image: parallel tiles, as the walk.
impl RayTracer for Brute<'_> {
    type Scratch = BruteScratch;

    fn integrate<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut BruteScratch,
    ) -> RayAccumulator {
        self.trace(material, ray, t_near, opts, scratch)
    }
}

/// One candidate cell on one ray: its points projected onto the ray's
/// frame and the edge values between them, computed on first use.
struct CellRay<'r> {
    frame: &'r RayFrame,
    proj: &'r [(u32, DVec3, Proj)],
    /// By local node pair, `nodes.len()` squared (NaN: not yet).
    edges: &'r mut [f64],
    nodes: &'r [u32],
    scalars: Scalars<'r>,
    cell: u32,
    /// The points' gradients, interpolated at the crossings where given.
    grads: Option<&'r [DVec3]>,
}

impl CellRay<'_> {
    /// The value of edge `i -> j` (local nodes): [`RayFrame::edge`], cached
    /// for both directions.
    #[inline]
    fn edge(&mut self, i: usize, j: usize) -> f64 {
        let nn = self.nodes.len();
        let v = self.edges[i * nn + j];
        if !v.is_nan() {
            return v;
        }
        let (a, b) = (&self.proj[i], &self.proj[j]);
        let v = self.frame.edge(a.0, a.1, &a.2, b.0, b.1, &b.2);
        self.edges[i * nn + j] = v;
        self.edges[j * nn + i] = -v;
        v
    }

    /// The crossing of triangle `t` (local nodes, in the piece's winding):
    /// depth, sign along the winding normal, scalar, gradient.
    #[inline]
    fn crossing(&mut self, t: [usize; 3]) -> Option<(f64, i8, f64, DVec3)> {
        // The crossing test's own sign condition first (most triangles
        // fail it), then the test itself in the canonical order.
        let e = [
            self.edge(t[0], t[1]),
            self.edge(t[1], t[2]),
            self.edge(t[2], t[0]),
        ];
        if !(e.iter().all(|&x| x > 0.0) || e.iter().all(|&x| x < 0.0)) {
            return None;
        }
        let (k, parity) = canonical(t, self.nodes);
        let e = [
            self.edge(k[0], k[1]),
            self.edge(k[1], k[2]),
            self.edge(k[2], k[0]),
        ];
        let [p0, p1, p2] = k.map(|i| &self.proj[i].2);
        let x = self.frame.crossing(e, [p0, p1, p2])?;
        let nodes = self.nodes;
        let s = match self.scalars {
            Scalars::Point(v) => x.interpolate(k.map(|i| v[nodes[i] as usize])),
            Scalars::Cell(v) => v[self.cell as usize],
            Scalars::Constant(s) => s,
        };
        let g = self.grads.map_or(DVec3::ZERO, |g| {
            let [a, b, c] = x.order;
            let at = |i: usize| g.get(nodes[k[i]] as usize).copied().unwrap_or_default();
            at(a) * x.w[a] + at(b) * x.w[b] + at(c) * x.w[c]
        });
        Some((x.t, x.sign * parity, s, g))
    }
}

/// Pairs one piece's crossings (depth, sign, scalar) into segments where
/// their winding number is non-zero, clipped at `t_near`, and appends them
/// with the piece's index (see the module docs).
fn pair_crossings(
    crossings: &mut [(f64, i8, f64, DVec3)],
    cell: u32,
    piece: u32,
    t_near: f64,
    out: &mut Vec<PieceSegment>,
) {
    if crossings.len() < 2 {
        return;
    }
    crossings.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut winding = 0i32;
    let mut open = (0.0, 0.0, DVec3::ZERO);
    for &(t, sign, s, g) in crossings.iter() {
        let before = winding;
        winding += sign as i32;
        if before == 0 && winding != 0 {
            open = (t, s, g);
        } else if before != 0 && winding == 0 {
            let mut seg = Segment {
                cell,
                t_in: open.0,
                t_out: t,
                s_in: open.1,
                s_out: s,
            };
            if seg.t_out <= t_near || seg.t_out <= seg.t_in {
                continue;
            }
            let mut g_in = open.2;
            if seg.t_in < t_near {
                let x = (t_near - seg.t_in) / (seg.t_out - seg.t_in);
                seg.s_in += x * (seg.s_out - seg.s_in);
                seg.t_in = t_near;
                g_in = g_in.lerp(g, x);
            }
            out.push((seg, piece, [g_in, g]));
        }
    }
}

/// Scalar of segment `s` at depth `t` inside it (exact at its ends).
#[inline]
fn scalar_at(s: &Segment, t: f64) -> f64 {
    if t <= s.t_in {
        s.s_in
    } else if t >= s.t_out {
        s.s_out
    } else {
        s.s_in + (t - s.t_in) / (s.t_out - s.t_in) * (s.s_out - s.s_in)
    }
}

/// Composites a run of segments that overlap in depth (sorted by entry
/// depth, then piece): split at every segment boundary; within each
/// sub-interval the covering segments in their order.
fn composite_overlap(
    value: &impl Fn(&Part) -> SegmentValue,
    run: &[PieceSegment],
    stop: f64,
    acc: &mut RayAccumulator,
    scratch: &mut BruteScratch,
) {
    let cuts = &mut scratch.cuts;
    cuts.clear();
    for (s, _, _) in run {
        cuts.push(s.t_in);
        cuts.push(s.t_out);
    }
    cuts.sort_unstable_by(f64::total_cmp);
    cuts.dedup();
    let active = &mut scratch.active;
    active.clear();
    let mut next = 0;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        active.retain(|&k| run[k].0.t_out > a);
        while next < run.len() && run[next].0.t_in <= a {
            if run[next].0.t_out > a {
                active.push(next);
            }
            next += 1;
        }
        for &k in active.iter() {
            let (s, piece, g) = &run[k];
            let span = s.t_out - s.t_in;
            let at = |t: f64| g[0].lerp(g[1], ((t - s.t_in) / span).clamp(0.0, 1.0));
            acc.add(&value(&Part {
                piece: *piece,
                cell: s.cell,
                l: b - a,
                s: [scalar_at(s, a), scalar_at(s, b)],
                g: [at(a), at(b)],
            }));
            if acc.depth >= stop {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outward_f32_rounding() {
        for x in [0.1, -0.1, 1e-50, -1e-50, 0.0, 3.0, 1e300, -1e300] {
            assert!(f32_down(x) as f64 <= x && f32_up(x) as f64 >= x, "{x}");
        }
        assert_eq!(f32_down(0.5), 0.5);
    }

    #[test]
    fn canonical_order_and_parity() {
        let nodes = [7u32, 3, 9, 1];
        assert_eq!(canonical([0, 1, 2], &nodes), ([1, 0, 2], -1));
        assert_eq!(canonical([3, 1, 2], &nodes), ([3, 1, 2], 1));
        assert_eq!(canonical([2, 3, 1], &nodes), ([3, 1, 2], 1));
        assert_eq!(canonical([2, 1, 3], &nodes), ([3, 1, 2], -1));
    }
}
