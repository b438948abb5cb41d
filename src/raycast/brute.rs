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
//! **Candidates.** A [`Bvh`] over the pieces' boxes, plus a test of each
//! candidate's own box (rounded outwards to `f32`), gives the pieces whose
//! box the line meets at `t >= t_near`, leaf by leaf in order of depth
//! ([`Bvh::query_ordered`]).
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
//! The `native` model is not offered ([`RaycastError::BruteModel`]): its
//! pieces are bounded by bilinear patches, not triangles.

use std::borrow::Cow;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use super::bvh::{ray_hits_box, Bvh, NodeQueue};
use super::geometry::{Proj, RayFrame};
use super::{render_tiles, validate, FieldModel, RaycastError, RaycastOptions, Scalars, Scene};
use super::{stop_depth, Segment};
use crate::camera::{Camera, Ray};
use crate::image::Image;
use crate::integrate::{RayAccumulator, RayMaterial};
use crate::mesh::tetra::tetrahedralize_cell;
use crate::mesh::{CellKind, Cells};
use crate::numeric::predicates::{orient3d, Side};
use crate::numeric::tolerance::BRUTE_OVERLAP_REPORT_REL;

/// Counts of a brute-force render (summed over every ray traced so far).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BruteStats {
    /// Candidate pieces whose triangles were tested.
    pub pieces_tested: u64,
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
            pieces_tested: self.pieces_tested - before.pieces_tested,
            segments: self.segments - before.segments,
            overlapping_segments: self.overlapping_segments - before.overlapping_segments,
        }
    }
}

/// Per-thread scratch space for brute-force rays.
#[derive(Default)]
pub struct BruteScratch {
    stack: Vec<u32>,
    queue: NodeQueue,
    proj: Vec<(u32, DVec3, Proj)>,
    /// Edge values of the current piece by local node pair (NaN: not yet).
    edges: Vec<f64>,
    local: Vec<usize>,
    /// Crossings of the current piece: depth, sign, scalar.
    crossings: Vec<(f64, i8, f64)>,
    /// Segments of the ray with their piece.
    segs: Vec<(Segment, u32)>,
    cuts: Vec<f64>,
    active: Vec<usize>,
}

/// A scene prepared for brute-force ray casting with the `faces` or `tets`
/// model.
pub struct Brute<'a> {
    scene: Scene<'a>,
    model: FieldModel,
    /// The pieces as cells: the mesh's cells, or the consistent tets.
    pieces: Cow<'a, Cells>,
    /// `tets`: the mesh cell of each tet.
    parent: Option<Vec<u32>>,
    /// BVH item `k` is piece `ids[k]`, with box `boxes[k]` (lo, hi).
    ids: Vec<u32>,
    boxes: Vec<[f32; 6]>,
    bvh: Bvh,
    center: DVec3,
    radius: f64,
    /// Padding of the boxes (scene size x 1e-9, as the walk's BVH).
    pad: f64,
    flat: usize,
    counts: [AtomicU64; 3],
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

/// Whether every consistent tet of cell `c` is flat (exactly).
fn is_flat(points: &[DVec3], cells: &Cells, c: usize, buf: &mut Vec<[u32; 4]>) -> bool {
    buf.clear();
    tetrahedralize_cell(cells, c, buf);
    buf.iter().all(|t| {
        let [a, b, cc, d] = t.map(|v| points[v as usize]);
        orient3d(a, b, cc, d) == Side::On
    })
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
        let (pieces, parent) = if model == FieldModel::Tets {
            let mut cells = Cells::default();
            let mut parent = Vec::new();
            let mut buf = Vec::new();
            for c in 0..mesh.cells.len() {
                buf.clear();
                tetrahedralize_cell(&mesh.cells, c, &mut buf);
                for t in &buf {
                    cells.push(CellKind::Tetra, t);
                    parent.push(c as u32);
                }
            }
            (Cow::Owned(cells), Some(parent))
        } else {
            (Cow::Borrowed(&mesh.cells), None)
        };
        // The walk's bounding sphere (over every piece's nodes), so that the
        // ray frame and its tie-breaking far point are the walk's.
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for &n in &pieces.conn {
            lo = lo.min(points[n as usize]);
            hi = hi.max(points[n as usize]);
        }
        if lo.x > hi.x {
            lo = DVec3::ZERO;
            hi = DVec3::ZERO;
        }
        let center = (lo + hi) * 0.5;
        let radius = (hi - lo).length() * 0.5;
        let mut ids = Vec::with_capacity(pieces.len());
        let mut boxes = Vec::with_capacity(pieces.len());
        let mut dboxes = Vec::with_capacity(pieces.len());
        let mut buf = Vec::new();
        let mut flat = 0;
        for p in 0..pieces.len() {
            let nodes = pieces.nodes(p);
            let flat_piece = match model {
                FieldModel::Tets => {
                    let [a, b, c, d] = [0, 1, 2, 3].map(|k| points[nodes[k] as usize]);
                    orient3d(a, b, c, d) == Side::On
                }
                _ => is_flat(points, &pieces, p, &mut buf),
            };
            if flat_piece {
                flat += 1;
                continue;
            }
            let mut plo = DVec3::splat(f64::INFINITY);
            let mut phi = DVec3::splat(f64::NEG_INFINITY);
            for &n in nodes {
                plo = plo.min(points[n as usize]);
                phi = phi.max(points[n as usize]);
            }
            ids.push(p as u32);
            dboxes.push((plo, phi));
        }
        let pad = 1e-9 * (radius + center.abs().max_element()).max(f64::MIN_POSITIVE);
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
            pieces,
            parent,
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

    /// Number of pieces traced.
    pub fn piece_count(&self) -> usize {
        self.ids.len()
    }

    /// Bytes of memory the prepared structures hold (beyond the mesh).
    pub fn bytes(&self) -> usize {
        let mut b = self.bvh.bytes() + self.ids.len() * 4 + self.boxes.len() * 24;
        if let Cow::Owned(c) = &self.pieces {
            b += c.conn.len() * 4 + c.offsets.len() * 4 + c.kinds.len();
        }
        if let Some(p) = &self.parent {
            b += p.len() * 4;
        }
        b
    }

    /// The counts summed over every ray traced so far.
    pub fn stats(&self) -> BruteStats {
        let c = |k: usize| self.counts[k].load(Ordering::Relaxed);
        BruteStats {
            pieces_tested: c(0),
            segments: c(1),
            overlapping_segments: c(2),
        }
    }

    fn mesh_cell(&self, piece: u32) -> u32 {
        match &self.parent {
            Some(p) => p.get(piece as usize).copied().unwrap_or(piece),
            None => piece,
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
                self.piece_segments(&frame, self.ids[k as usize], t_near, scratch, &mut segs);
            }
        });
        segs.sort_unstable_by(|a, b| a.0.t_in.total_cmp(&b.0.t_in).then(a.1.cmp(&b.1)));
        scratch.segs = segs;
        scratch.stack = stack;
    }

    /// Appends the segments of piece `p` along the ray (see the module docs:
    /// non-zero winding, clipped at `t_near`).
    fn piece_segments(
        &self,
        frame: &RayFrame,
        p: u32,
        t_near: f64,
        scratch: &mut BruteScratch,
        out: &mut Vec<(Segment, u32)>,
    ) {
        let c = p as usize;
        let nodes = self.pieces.nodes(c);
        let points = &self.scene.mesh.points;
        let proj = &mut scratch.proj;
        proj.clear();
        // Quick reject: every vertex clearly on one side of the line.
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
        let edges = &mut scratch.edges;
        edges.clear();
        edges.resize(nn * nn, f64::NAN);
        let crossings = &mut scratch.crossings;
        crossings.clear();
        let scalars = self.scene.scalars;
        let cell = self.mesh_cell(p);
        let mut tri = |t: [usize; 3]| {
            let mut edge = |i: usize, j: usize| {
                let v = edges[i * nn + j];
                if !v.is_nan() {
                    return v;
                }
                let (a, b) = (&proj[i], &proj[j]);
                let v = frame.edge(a.0, a.1, &a.2, b.0, b.1, &b.2);
                edges[i * nn + j] = v;
                edges[j * nn + i] = -v;
                v
            };
            // The crossing test's own sign condition first (most triangles
            // fail it), then the test itself in the canonical order.
            let e = [edge(t[0], t[1]), edge(t[1], t[2]), edge(t[2], t[0])];
            if !(e.iter().all(|&x| x > 0.0) || e.iter().all(|&x| x < 0.0)) {
                return;
            }
            let (k, parity) = canonical(t, nodes);
            let e = [edge(k[0], k[1]), edge(k[1], k[2]), edge(k[2], k[0])];
            let Some(x) = RayFrame::crossing(e, k.map(|i| proj[i].2.z)) else {
                return;
            };
            let s = match scalars {
                Scalars::Point(v) => {
                    x.w[0] * v[nodes[k[0]] as usize]
                        + x.w[1] * v[nodes[k[1]] as usize]
                        + x.w[2] * v[nodes[k[2]] as usize]
                }
                Scalars::Cell(v) => v[cell as usize],
                Scalars::Constant(s) => s,
            };
            crossings.push((x.t, x.sign * parity, s));
        };
        let kind = self.pieces.kinds[c];
        if kind != CellKind::Polyhedron {
            for lf in kind.faces() {
                let n = lf.len();
                let k0 = (0..n).min_by_key(|&i| nodes[lf[i] as usize]).unwrap_or(0);
                for i in 1..n.saturating_sub(1) {
                    tri([
                        lf[k0] as usize,
                        lf[(k0 + i) % n] as usize,
                        lf[(k0 + i + 1) % n] as usize,
                    ]);
                }
            }
        } else {
            let local = &mut scratch.local;
            self.pieces.for_each_face(c, |_, face| {
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
                    tri([local[k0], local[(k0 + i) % n], local[(k0 + i + 1) % n]]);
                }
            });
        }
        if crossings.len() < 2 {
            return;
        }
        crossings.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut winding = 0i32;
        let mut open = (0.0, 0.0);
        for &(t, sign, s) in crossings.iter() {
            let before = winding;
            winding += sign as i32;
            if before == 0 && winding != 0 {
                open = (t, s);
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
                if seg.t_in < t_near {
                    let x = (t_near - seg.t_in) / (seg.t_out - seg.t_in);
                    seg.s_in += x * (seg.s_out - seg.s_in);
                    seg.t_in = t_near;
                }
                out.push((seg, p));
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
                    material,
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
                        self.piece_segments(
                            &frame,
                            self.ids[k as usize],
                            t_near,
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
                material,
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
    fn flush<M: RayMaterial>(
        &self,
        material: &M,
        pending: &mut Vec<(Segment, u32)>,
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
                let s = &pending[i].0;
                acc.add(&material.segment(s.t_out - s.t_in, s.s_in, s.s_out));
            } else {
                composite_overlap(material, &pending[i..j], stop, acc, scratch);
            }
            counts[1] += (j - i) as u64;
            counts[2] += overlapping;
            i = j;
        }
        pending.drain(..i);
    }

    /// Renders an image through `camera` (parallel tiles, as the walk).
    pub fn render<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
    ) -> Image {
        self.render_with_progress(material, camera, opts, |_, _| {})
    }

    /// [`Brute::render`] with progress reports, as
    /// [`super::Raycaster::render_with_progress`].
    pub fn render_with_progress<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
        progress: impl FnMut(usize, usize),
    ) -> Image {
        render_tiles(
            camera,
            opts,
            progress,
            |ray, t_near, scratch: &mut BruteScratch| {
                self.trace(material, ray, t_near, opts, scratch).rgba()
            },
        )
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
fn composite_overlap<M: RayMaterial>(
    material: &M,
    run: &[(Segment, u32)],
    stop: f64,
    acc: &mut RayAccumulator,
    scratch: &mut BruteScratch,
) {
    let cuts = &mut scratch.cuts;
    cuts.clear();
    for (s, _) in run {
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
            let s = &run[k].0;
            acc.add(&material.segment(b - a, scalar_at(s, a), scalar_at(s, b)));
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
