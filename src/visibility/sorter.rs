//! The per-view sort: face classification, splitting, constraints, Kahn's
//! topological sort and cycle handling (see the module docs of
//! [`crate::visibility`] for the method).
//!
//! Piece ids: whole cell `c` is id `c`; the tets of the split cells follow,
//! id `cells + base(slot) + k`. Interior faces between two whole cells are
//! edges through `face_target` (the cell drawn later, or `NONE`); every other
//! edge (per triangle next to a split cell, inside a split cell, non-convex
//! constraints) is an edge of the round's [`RoundGraph`], a CSR list rebuilt
//! per round.
//!
//! Speed: the sort is bound by memory, not arithmetic. Kahn reads the
//! out-edges of a cell from `slot_target` (the face targets laid out by
//! cell, contiguous per cell) and keeps its ready cells on a stack whose top
//! is the ready neighbour nearest in id to the cell just emitted, so the walk
//! proceeds next door in memory (along rows of a grid) instead of jumping by
//! a layer's stride: on the 1M-hex grid this took the sort from 123 ms to
//! 25 ms per view (benches/visibility.rs).

use std::sync::Arc;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::geometry::{Geometry, BOUNDARY, CONCAVE, FLIP, PLANAR};
use super::raster::{exit_entry_pairs, rasterize};
use super::scc::tarjan;
use super::split::SplitPool;
use super::{Order, OrderStats, SplitPolicy, VisibilityError, MAX_SPLIT_ROUNDS};
use crate::camera::Camera;
use crate::mesh::topology::Topology;
use crate::mesh::{Cells, Mesh, NONE};
use crate::numeric::predicates::orient_dir;
use crate::numeric::predicates::{orient3d, Side};
use crate::numeric::tolerance::{FRUSTUM_MARGIN_PX, PLANE_FILTER_EPS};
use splice::BreakpointSplit;

/// Split reasons (bits of `want`).
const PROBLEM: u8 = 1;
const BREAKPOINT: u8 = 2;
const ALL: u8 = 4;
const CYCLE: u8 = 8;
const NONCONVEX_CELL: u8 = 16;

/// Where the eye is.
#[derive(Clone, Copy, Debug)]
enum View {
    /// Perspective: the eye position.
    Eye(DVec3),
    /// Orthographic: the direction of projection.
    Dir(DVec3),
}

impl super::bsp::EyeSide for View {
    fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> Side {
        View::side(self, a, b, c)
    }
}

impl View {
    /// Where `camera`'s eye is.
    fn of(camera: &Camera) -> View {
        if camera.ortho {
            View::Dir(camera.forward)
        } else {
            View::Eye(camera.position)
        }
    }

    /// Exact side of the eye relative to the plane of `a, b, c`.
    fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> Side {
        match *self {
            View::Eye(e) => orient3d(a, b, c, e),
            // The eye is at infinity behind the image: direction -dir.
            View::Dir(d) => orient_dir(a, b, c, -d),
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

/// How the constraints between cells that see each other through empty space
/// are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum NonConvex {
    /// Exact at image resolution: boundary crossings along every pixel-centre
    /// ray (the default).
    #[default]
    PixelConstraints,
    /// APPROXIMATE: adjacency graph only (MPVO). Wrong wherever the mesh
    /// sees itself across a gap; for comparisons and tests only.
    IgnoreApproximate,
}

mod finish;
mod splice;

/// Built once per geometry; call [`Sorter::order`] per view.
#[derive(Clone, Debug)]
pub struct Sorter {
    /// The mesh and its topology, shared with the caller (never copied).
    pub(super) mesh: Arc<Mesh>,
    pub(super) topo: Arc<Topology>,
    pub(super) geom: Geometry,
    pub(super) pool: SplitPool,
    pub(super) invalid: Option<VisibilityError>,
    /// How non-convex meshes are handled (default: exact pixel constraints).
    pub nonconvex: NonConvex,
    /// Whether cycles of tets are cut by planes through their members
    /// ([`super::bsp`]) before being left to per-pixel compositing
    /// (default: true).
    pub plane_split: bool,
    /// Leave out the cells outside the view frustum grown by this many
    /// pixels ([`super::frustum`]; default
    /// [`FRUSTUM_MARGIN_PX`]); `None` keeps every cell.
    pub frustum_margin: Option<f64>,
    // Per-view scratch.
    /// Cells outside the frustum in this view.
    culled: Vec<bool>,
    /// Per piece, scratch of [`Sorter::cycle_members`].
    dfs_state: Vec<u8>,
    tri_sign: Vec<i8>,
    face_target: Vec<u32>,
    /// `face_target` by cell-face slot (`topo.cell_faces` layout), kept only
    /// on the source cell's side: the out-edges of cell `c` are the
    /// non-`NONE` entries of its slots, read contiguously by Kahn (reading
    /// `face_target` through `cell_faces` costs a cache miss per face on
    /// large meshes).
    slot_target: Vec<u32>,
    want: Vec<u8>,
    indeg: Vec<u32>,
}

/// The constraint graph of one splitting round beyond `face_target`: the
/// ids of the split cells' tets, and the edges that `face_target` cannot
/// hold (per triangle next to a split cell, inside a split cell, non-convex
/// constraints) as a CSR list over piece ids.
#[derive(Default)]
struct RoundGraph {
    /// `base[k]`: first tet id of `pool.active[k]`.
    base: Vec<u32>,
    /// The same by storage slot (`pool.slot_of`).
    base_by_slot: Vec<u32>,
    /// Per tet id (offset by `cells`): index into `pool.active`.
    tet_slot: Vec<u32>,
    /// CSR over piece ids.
    off: Vec<u32>,
    to: Vec<u32>,
    pieces: usize,
}

impl Sorter {
    /// Prepares the plane equations and adjacency of `mesh` (whose topology
    /// is `topo`). Nothing is copied: the sorter keeps the two `Arc`s for
    /// its lifetime (pass an owned `Mesh` or `Topology` to move it in, an
    /// `Arc` to share it); the geometry must not change while it is in use,
    /// the values may. Invalid input (point ids out of range, non-finite
    /// points, a topology of another mesh) is reported by [`Sorter::order`].
    pub fn new(mesh: impl Into<Arc<Mesh>>, topo: impl Into<Arc<Topology>>) -> Sorter {
        Sorter::for_subset(mesh, topo, &[])
    }

    /// [`Sorter::new`] for a mesh of some of the cells of a larger one
    /// (the renderer's visible subset, `render::visible`): the boundary
    /// faces `f` with `cut[f]` were interior there. A problem face among
    /// them splits its cell as an interior problem face would (not only
    /// where the cell is concave along the diagonal, the rule of true
    /// boundary faces), so the cells the subset's orders draw as tets are
    /// those the whole mesh's would, but for cycles.
    pub fn for_subset(
        mesh: impl Into<Arc<Mesh>>,
        topo: impl Into<Arc<Topology>>,
        cut: &[bool],
    ) -> Sorter {
        let (mesh, topo) = (mesh.into(), topo.into());
        let n = mesh.cells.len();
        let invalid = super::input::check_input(&mesh, &topo);
        let (topo, geom) = if invalid.is_some() {
            (
                Arc::new(Topology::build(&Cells::default())),
                Geometry::default(),
            )
        } else {
            let geom = Geometry::build(&mesh, &topo, cut);
            (topo, geom)
        };
        let nf = topo.face_count();
        let nt = geom.planes.len();
        Sorter {
            mesh,
            pool: SplitPool::new(if invalid.is_some() { 0 } else { n }),
            invalid,
            nonconvex: NonConvex::PixelConstraints,
            plane_split: true,
            frustum_margin: Some(FRUSTUM_MARGIN_PX),
            culled: Vec::new(),
            dfs_state: Vec::new(),
            tri_sign: vec![0; nt],
            face_target: vec![NONE; nf],
            slot_target: Vec::new(),
            want: Vec::new(),
            indeg: Vec::new(),
            topo,
            geom,
        }
    }

    /// Takes `other`'s options ([`Self::nonconvex`], [`Self::plane_split`],
    /// [`Self::frustum_margin`]): a sorter of a subset of `other`'s mesh
    /// sorts as `other` would.
    pub fn copy_options(&mut self, other: &Sorter) {
        self.nonconvex = other.nonconvex;
        self.plane_split = other.plane_split;
        self.frustum_margin = other.frustum_margin;
    }

    /// Whether the boundary of the mesh is convex (no pixel constraints).
    pub fn convex_boundary(&self) -> bool {
        self.geom.convex
    }

    /// Number of cells currently split into tets.
    pub fn split_count(&self) -> usize {
        self.pool.active.len()
    }

    /// The back-to-front order of pieces for `camera`: the geometry's
    /// order ([`Sorter::base_order`]) with the values spliced in
    /// ([`Sorter::splice`]).
    pub fn order(
        &mut self,
        camera: &Camera,
        policy: &SplitPolicy,
    ) -> Result<Order, VisibilityError> {
        let base = self.base_order(camera, policy.all)?;
        self.splice(&base, camera, policy)
    }

    /// The order in one step: every split of `policy` made before the
    /// topological sort (the splice's fallback, and its base with no
    /// values).
    fn sort(&mut self, camera: &Camera, policy: &SplitPolicy) -> Result<Order, VisibilityError> {
        let t_start = Instant::now();
        if let Some(e) = &self.invalid {
            return Err(e.clone());
        }
        super::input::check_camera(camera)?;
        let n = self.mesh.cells.len();
        if let Some(s) = policy.point_scalars {
            if s.len() < self.mesh.points.len() {
                return Err(VisibilityError::ScalarCount {
                    got: s.len(),
                    points: self.mesh.points.len(),
                });
            }
        }
        let view = View::of(camera);
        let mut stats = OrderStats {
            cells: n,
            convex_boundary: self.geom.convex,
            ..Default::default()
        };

        // 0. Cells outside the frustum.
        stats.frustum_culled = match self.frustum_margin {
            Some(m) => super::frustum::outside_cells(camera, &self.mesh, m, &mut self.culled),
            None => {
                self.culled.clear();
                self.culled.resize(n, false);
                0
            }
        };

        // 1. Classify faces.
        let t0 = Instant::now();
        self.want.clear();
        self.want.resize(n, 0);
        self.classify(view, &mut stats);
        self.policy_splits(policy, &mut stats);
        for &c in &self.geom.nonconvex_cells {
            self.want[c as usize] |= NONCONVEX_CELL;
        }
        stats.nonconvex_cells = self.geom.nonconvex_cells.len();
        if stats.frustum_culled > 0 {
            // Nothing splits a cell that is not drawn.
            for (w, &out) in self.want.iter_mut().zip(&self.culled) {
                if out {
                    *w = 0;
                }
            }
        }
        stats.time_classify = t0.elapsed();

        // 2. Non-convex constraints at triangle level (once per view).
        let t1 = Instant::now();
        let tri_pairs = if self.geom.convex || self.nonconvex == NonConvex::IgnoreApproximate {
            Vec::new()
        } else {
            let crossings = rasterize(camera, &self.mesh.points, &self.geom.boundary, |i| {
                let bt = &self.geom.boundary[i];
                let t = self.geom.tri_off[bt.face as usize] as usize + bt.k as usize;
                let s = self.tri_sign[t];
                let flip = self.geom.face_flags[bt.face as usize] & FLIP != 0;
                // Outward side seen: enter.
                (s != 0).then_some((s > 0) != flip)
            });
            stats.boundary_crossings = crossings.len();
            exit_entry_pairs(&crossings)
        };
        stats.time_nonconvex = t1.elapsed();

        // 3. Rounds of split + sort.
        let mut first_round = true;
        loop {
            stats.rounds += 1;
            let ts = Instant::now();
            let change = self.pool.update(&self.mesh, &self.topo, &self.want);
            if first_round {
                stats.newly_split = change.newly_split;
                stats.restored = change.restored;
                first_round = false;
            } else {
                stats.newly_split += change.newly_split;
            }
            let mut graph = self.build_round_graph(view)?;
            stats.time_split += ts.elapsed();
            let tn = Instant::now();
            let nc = self.add_nonconvex(&tri_pairs, &mut graph);
            stats.nonconvex_constraints = nc;
            stats.time_nonconvex += tn.elapsed();

            let tk = Instant::now();
            let emitted = self.kahn(&graph);
            let total_alive =
                n - stats.frustum_culled - self.pool.active.len() + (graph.pieces - n);
            if emitted.len() == total_alive {
                let order = self.finish(emitted, Vec::new(), &graph, camera, policy, &mut stats);
                stats.time_sort += tk.elapsed();
                stats.time_total = t_start.elapsed();
                return Ok(Order { stats, ..order });
            }
            // Cycles: strongly connected components of what is left.
            let comps = self.components(&graph, &emitted);
            let cycles: Vec<&Vec<u32>> = comps.iter().filter(|c| c.len() > 1).collect();
            stats.cycles_found += cycles.len();
            let mut new_split = 0;
            if stats.rounds <= MAX_SPLIT_ROUNDS {
                let mut state = std::mem::take(&mut self.dfs_state);
                state.clear();
                state.resize(graph.pieces, 0);
                for comp in &cycles {
                    stats.cycle_component_cells +=
                        comp.iter().filter(|&&p| (p as usize) < n).count();
                    let mut any = false;
                    let members = if stats.rounds < MAX_SPLIT_ROUNDS {
                        self.cycle_members(&graph, comp, &mut state)
                    } else {
                        comp.to_vec()
                    };
                    for &p in members.iter() {
                        if (p as usize) < n && self.want[p as usize] == 0 {
                            self.want[p as usize] = CYCLE;
                            new_split += 1;
                            any = true;
                        }
                    }
                    if any {
                        stats.cycles_resolved_by_split += 1;
                    }
                }
                self.dfs_state = state;
            }
            stats.cycle_split_cells += new_split;
            if new_split == 0 {
                let order = self.finish(emitted, comps, &graph, camera, policy, &mut stats);
                stats.time_sort += tk.elapsed();
                stats.time_total = t_start.elapsed();
                return Ok(Order { stats, ..order });
            }
            stats.time_sort += tk.elapsed();
        }
    }

    /// Plane tests for every face triangle; face targets; problem faces.
    fn classify(&mut self, view: View, stats: &mut OrderStats) {
        let g = &self.geom;
        let p = &self.mesh.points;
        let (vx, vw, vmag) = match view {
            View::Eye(e) => (e, 1.0, e.abs().max_element()),
            View::Dir(d) => (d, 0.0, 0.0),
        };
        let dmag = vx.abs().max_element();
        let nf = self.topo.face_count();
        let mut fallbacks = 0usize;
        let mut problems = 0usize;
        let culled = &self.culled;
        for f in 0..nf {
            let r = g.tri_off[f] as usize..g.tri_off[f + 1] as usize;
            let [c0, c1] = self.topo.face_cells[f];
            let out = [culled[c0 as usize], c1 != NONE && culled[c1 as usize]];
            if out[0] && (c1 == NONE || out[1]) {
                // Only cells left out (frustum) touch it: no constraint,
                // and no side for the boundary rasteriser.
                self.tri_sign[r].fill(0);
                self.face_target[f] = NONE;
                continue;
            }
            let [m, amax] = g.face_err[f];
            let bound =
                PLANE_FILTER_EPS * m as f64 * if vw == 1.0 { vmag + amax as f64 } else { dmag };
            let mut pos = 0u8;
            let mut neg = 0u8;
            let planar = g.face_flags[f] & PLANAR != 0;
            let mut planar_sign = None;
            for t in r.clone() {
                if let Some(sg) = planar_sign {
                    self.tri_sign[t] = sg;
                    continue;
                }
                let pl = &g.planes[t];
                // Perspective: n . eye - d; orthographic: n . (-dir).
                let s = if vw == 1.0 {
                    pl[0] * vx.x + pl[1] * vx.y + pl[2] * vx.z - pl[3]
                } else {
                    -(pl[0] * vx.x + pl[1] * vx.y + pl[2] * vx.z)
                };
                let sg = if s > bound {
                    1
                } else if s < -bound {
                    -1
                } else {
                    fallbacks += 1;
                    let k = t - r.start;
                    let mut verts = [0u32; 3];
                    let mut idx = 0;
                    crate::mesh::tetra::triangulate_face(self.topo.face(f), |tri| {
                        if idx == k {
                            verts = tri;
                        }
                        idx += 1;
                    });
                    let [a, b, c] = verts.map(|v| p[v as usize]);
                    sign(view.side(a, b, c))
                };
                self.tri_sign[t] = sg;
                pos += (sg > 0) as u8;
                neg += (sg < 0) as u8;
                if planar {
                    planar_sign = Some(sg);
                }
            }
            let flags = g.face_flags[f];
            let problem = pos > 0 && neg > 0;
            if out[0] || out[1] {
                // Between a cell in view and one left out: no constraint
                // (the one left out is not drawn), but a problem face
                // splits the cell in view as it would without the cull,
                // so that the cells drawn are drawn the same.
                if problem {
                    problems += 1;
                    let c = if out[0] { c1 } else { c0 };
                    self.want[c as usize] |= PROBLEM;
                }
                self.tri_sign[r].fill(0);
                self.face_target[f] = NONE;
                continue;
            }
            if flags & BOUNDARY != 0 {
                self.face_target[f] = NONE;
                if problem && flags & CONCAVE != 0 {
                    problems += 1;
                    self.want[c0 as usize] |= PROBLEM;
                }
                continue;
            }
            if problem {
                problems += 1;
                self.want[c0 as usize] |= PROBLEM;
                self.want[c1 as usize] |= PROBLEM;
                self.face_target[f] = NONE;
            } else if pos == 0 && neg == 0 {
                self.face_target[f] = NONE;
            } else {
                // Eye on the normal side: the cell on that side is drawn later.
                let normal_side_is_c1 = flags & FLIP == 0;
                self.face_target[f] = if (pos > 0) == normal_side_is_c1 {
                    c1
                } else {
                    c0
                };
            }
        }
        stats.exact_fallbacks = fallbacks;
        stats.problem_faces = problems;
        stats.problem_cells = self.want.iter().filter(|&&w| w & PROBLEM != 0).count();
    }

    /// Breakpoint and `--split all` reasons.
    fn policy_splits(&mut self, policy: &SplitPolicy, stats: &mut OrderStats) {
        let n = self.mesh.cells.len();
        if policy.all {
            for w in self.want.iter_mut() {
                *w |= ALL;
            }
            stats.all_split_cells = n;
        }
        if let (Some(s), false) = (policy.point_scalars, policy.breakpoints.is_empty()) {
            let (mut count, mut dark) = (0, 0);
            for c in 0..n {
                match self.breakpoint_split(c as u32, s, policy) {
                    BreakpointSplit::No => {}
                    BreakpointSplit::Dark => dark += 1,
                    BreakpointSplit::Yes => {
                        self.want[c] |= BREAKPOINT;
                        count += 1;
                    }
                }
            }
            stats.breakpoint_cells = count;
            stats.dark_unsplit = dark;
        }
    }

    /// Piece id of the owner of triangle `k` of face `f` on cell `c`'s side.
    #[inline]
    fn piece_on(&self, graph: &RoundGraph, c: u32, f: u32, k: usize) -> u32 {
        let n = self.mesh.cells.len() as u32;
        let s = self.pool.slot_of[c as usize];
        if s == NONE {
            return c;
        }
        let sc = &self.pool.slots[s as usize];
        let side = (self.topo.face_cells[f as usize][0] != c) as usize;
        let li = self.topo.face_local[f as usize][side] as usize;
        n + graph.base_by_slot[s as usize] + sc.owner(li, k)
    }

    /// Tet ids, per-triangle edges next to split cells, edges inside split
    /// cells. Clears `face_target` of faces touching split cells.
    fn build_round_graph(&mut self, view: View) -> Result<RoundGraph, VisibilityError> {
        let n = self.mesh.cells.len();
        let mut graph = RoundGraph::default();
        let mut next = 0u32;
        graph.base_by_slot.resize(self.pool.slots.len(), 0);
        for (k, &c) in self.pool.active.iter().enumerate() {
            graph.base.push(next);
            graph.base_by_slot[self.pool.slot_of[c as usize] as usize] = next;
            let sc = self.pool.get(c).map_or(0, |s| s.tets.len());
            for _ in 0..sc {
                graph.tet_slot.push(k as u32);
            }
            next = next
                .checked_add(sc as u32)
                .ok_or(VisibilityError::TooManyPieces(usize::MAX))?;
        }
        let pieces = n + next as usize;
        if pieces > (u32::MAX - 1) as usize {
            return Err(VisibilityError::TooManyPieces(pieces));
        }
        graph.pieces = pieces;
        for &c in &self.pool.active {
            for &f in self.topo.faces_of(c as usize) {
                self.face_target[f as usize] = NONE;
            }
        }
        // The edges of each block of split cells on the thread pool, joined
        // in cell order (the same list as one pass over the cells).
        let this = &*self;
        let blocks: Vec<Vec<(u32, u32)>> = this
            .pool
            .active
            .par_chunks(ROUND_GRAPH_BLOCK)
            .map(|block| {
                let mut edges = Vec::new();
                for &c in block {
                    this.split_cell_edges(&graph, view, c, &mut edges);
                }
                edges
            })
            .collect();
        let edges = blocks.concat();
        graph.to = Vec::new();
        graph.off = Vec::new();
        self.set_edges(&mut graph, edges);
        Ok(graph)
    }

    /// Appends the edges of split cell `c` to `edges`: per triangle of its
    /// faces shared with another cell (a face between two split cells from
    /// its first cell only), and between its own tets.
    fn split_cell_edges(
        &self,
        graph: &RoundGraph,
        view: View,
        c: u32,
        edges: &mut Vec<(u32, u32)>,
    ) {
        let n = self.mesh.cells.len();
        let p = &self.mesh.points;
        for &f in self.topo.faces_of(c as usize) {
            let fu = f as usize;
            let [c0, c1] = self.topo.face_cells[fu];
            if c1 == NONE {
                continue;
            }
            let other = if c0 == c { c1 } else { c0 };
            // Handle a face between two split cells once (from c0).
            if self.pool.get(other).is_some() && c != c0 {
                continue;
            }
            let flip = self.geom.face_flags[fu] & FLIP != 0;
            for (k, t) in self.geom.tris(fu).enumerate() {
                let s = self.tri_sign[t];
                if s == 0 {
                    continue;
                }
                let p0 = self.piece_on(graph, c0, f, k);
                let p1 = self.piece_on(graph, c1, f, k);
                // Eye on c1's side: c1's piece is drawn later.
                if (s > 0) != flip {
                    edges.push((p0, p1));
                } else {
                    edges.push((p1, p0));
                }
            }
        }
        if let Some(sc) = self.pool.get(c) {
            let b = n as u32 + graph.base_by_slot[self.pool.slot_of[c as usize] as usize];
            for it in &sc.internal {
                let [a, bb, cc] = it.tri.map(|v| p[v as usize]);
                let se = view.side(a, bb, cc);
                if se == Side::On || it.side_i == Side::On {
                    continue;
                }
                let (pi, pj) = (b + it.i, b + it.j);
                // Eye on tet i's side: i occludes j, j first.
                if se == it.side_i {
                    edges.push((pj, pi));
                } else {
                    edges.push((pi, pj));
                }
            }
        }
    }

    /// Appends the non-convex constraints (mapped to pieces); returns their
    /// number.
    fn add_nonconvex(&self, tri_pairs: &[(u32, u32)], graph: &mut RoundGraph) -> usize {
        if tri_pairs.is_empty() {
            return 0;
        }
        let owner = |i: u32| {
            let bt = &self.geom.boundary[i as usize];
            let c0 = self.topo.face_cells[bt.face as usize][0];
            self.piece_on(graph, c0, bt.face, bt.k as usize)
        };
        let mut cons: Vec<(u32, u32)> = tri_pairs
            .iter()
            .map(|&(exit, entry)| (owner(entry), owner(exit)))
            .filter(|(a, b)| a != b)
            .collect();
        cons.sort_unstable();
        cons.dedup();
        let count = cons.len();
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(graph.to.len() + count);
        for v in 0..graph.pieces as u32 {
            for &w in self.graph_out(graph, v) {
                edges.push((v, w));
            }
        }
        edges.extend(cons);
        self.set_edges(graph, edges);
        count
    }

    /// Stores `edges` as the CSR of `graph`.
    fn set_edges(&self, graph: &mut RoundGraph, edges: Vec<(u32, u32)>) {
        if edges.is_empty() {
            graph.off.clear();
            graph.to.clear();
            return;
        }
        let mut off = vec![0u32; graph.pieces + 1];
        for &(a, _) in &edges {
            off[a as usize + 1] += 1;
        }
        for i in 0..graph.pieces {
            off[i + 1] += off[i];
        }
        let mut fill = off.clone();
        let mut to = vec![0u32; edges.len()];
        for &(a, b) in &edges {
            to[fill[a as usize] as usize] = b;
            fill[a as usize] += 1;
        }
        graph.off = off;
        graph.to = to;
    }

    #[inline]
    fn graph_out<'a>(&self, graph: &'a RoundGraph, v: u32) -> &'a [u32] {
        if graph.off.is_empty() {
            return &[];
        }
        &graph.to[graph.off[v as usize] as usize..graph.off[v as usize + 1] as usize]
    }

    /// Kahn's algorithm; returns the emitted piece ids (back to front).
    fn kahn(&mut self, graph: &RoundGraph) -> Vec<u32> {
        let n = self.mesh.cells.len();
        let pieces = graph.pieces;
        self.indeg.clear();
        self.indeg.resize(pieces, 0);
        let topo = &self.topo;
        self.slot_target.clear();
        self.slot_target.resize(topo.cell_faces.len(), NONE);
        for (f, &t) in self.face_target.iter().enumerate() {
            if t == NONE {
                continue;
            }
            let [c0, c1] = topo.face_cells[f];
            let [l0, l1] = topo.face_local[f];
            let (src, local) = if t == c1 { (c0, l0) } else { (c1, l1) };
            if src == NONE || src == t {
                continue;
            }
            let slot = topo.cell_face_offsets[src as usize] as usize + local as usize;
            self.slot_target[slot] = t;
            self.indeg[t as usize] += 1;
        }
        for &t in &graph.to {
            self.indeg[t as usize] += 1;
        }
        // A stack rather than a queue: any order Kahn can emit is valid, and
        // last-in-first-out keeps the work next to the cells just finished
        // (cache locality on large meshes).
        let mut out: Vec<u32> = Vec::with_capacity(pieces);
        let mut stack: Vec<u32> = (0..pieces as u32)
            .rev()
            .filter(|&v| {
                self.indeg[v as usize] == 0
                    && (v as usize >= n
                        || (self.pool.slot_of[v as usize] == NONE && !self.culled[v as usize]))
            })
            .collect();
        while let Some(v) = stack.pop() {
            out.push(v);
            if (v as usize) < n {
                let offs = &self.topo.cell_face_offsets;
                let slots = offs[v as usize] as usize..offs[v as usize + 1] as usize;
                let mark = stack.len();
                for &t in &self.slot_target[slots] {
                    if t != NONE {
                        let d = &mut self.indeg[t as usize];
                        *d -= 1;
                        if *d == 0 {
                            stack.push(t);
                        }
                    }
                }
                // The nearest id on top: the walk continues next door in
                // memory (for a grid, along rows first).
                let ready = &mut stack[mark..];
                if ready.len() > 1 {
                    ready.sort_unstable_by_key(|&t| std::cmp::Reverse(t.abs_diff(v)));
                }
            }
            if !graph.off.is_empty() {
                for &w in
                    &graph.to[graph.off[v as usize] as usize..graph.off[v as usize + 1] as usize]
                {
                    let d = &mut self.indeg[w as usize];
                    *d -= 1;
                    if *d == 0 {
                        stack.push(w);
                    }
                }
            }
        }
        out
    }

    /// The members of vertex-disjoint cycles of the strongly connected
    /// component `comp`, found by one depth-first search inside it: each
    /// back edge closes a cycle, whose members are taken and leave the
    /// search. Splitting them breaks every cycle the search met; one it did
    /// not meet (through members taken) is left to the next round. A large
    /// component held together by a few cycles splits a few cells, not all
    /// of it. `state` is zero per piece and is left zero.
    fn cycle_members(&self, graph: &RoundGraph, comp: &[u32], state: &mut [u8]) -> Vec<u32> {
        const UNSEEN: u8 = 1;
        const ON_PATH: u8 = 2;
        const DONE: u8 = 3;
        for &v in comp {
            state[v as usize] = UNSEEN;
        }
        let out_of = |v: u32, out: &mut Vec<u32>| {
            out.clear();
            self.successors(graph, v, out);
        };
        let mut members = Vec::new();
        // Frames: (piece, its out-neighbours, next one to look at).
        let mut path: Vec<(u32, Vec<u32>, usize)> = Vec::new();
        let mut spare: Vec<Vec<u32>> = Vec::new();
        for &root in comp {
            if state[root as usize] != UNSEEN {
                continue;
            }
            let mut nb = spare.pop().unwrap_or_default();
            out_of(root, &mut nb);
            state[root as usize] = ON_PATH;
            path.push((root, nb, 0));
            while let Some(top) = path.last_mut() {
                if top.2 == top.1.len() {
                    let (v, nb, _) = path.pop().expect("non-empty");
                    state[v as usize] = DONE;
                    spare.push(nb);
                    continue;
                }
                let w = top.1[top.2];
                top.2 += 1;
                match state[w as usize] {
                    UNSEEN => {
                        let mut nb = spare.pop().unwrap_or_default();
                        out_of(w, &mut nb);
                        state[w as usize] = ON_PATH;
                        path.push((w, nb, 0));
                    }
                    ON_PATH => {
                        // A cycle: the path from w to the top.
                        let at = path.iter().rposition(|f| f.0 == w).expect("on the path");
                        for (v, nb, _) in path.drain(at..) {
                            members.push(v);
                            state[v as usize] = DONE;
                            spare.push(nb);
                        }
                    }
                    _ => {}
                }
            }
        }
        for &v in comp {
            state[v as usize] = 0;
        }
        members
    }

    /// Strongly connected components of the pieces Kahn left (sinks first).
    fn components(&self, graph: &RoundGraph, emitted: &[u32]) -> Vec<Vec<u32>> {
        let mut done = vec![false; graph.pieces];
        for &v in emitted {
            done[v as usize] = true;
        }
        for &c in &self.pool.active {
            done[c as usize] = true;
        }
        for (d, &out) in done.iter_mut().zip(&self.culled) {
            *d |= out;
        }
        tarjan(
            graph.pieces,
            |v| !done[v as usize],
            |v, out| self.successors(graph, v, out),
        )
    }

    /// Appends to `out` the pieces drawn after piece `v` by this round's
    /// constraints: across the faces of a whole cell, and the round graph's
    /// edges.
    fn successors(&self, graph: &RoundGraph, v: u32, out: &mut Vec<u32>) {
        if (v as usize) < self.mesh.cells.len() {
            for &f in self.topo.faces_of(v as usize) {
                let t = self.face_target[f as usize];
                if t != NONE && t != v {
                    out.push(t);
                }
            }
        }
        out.extend_from_slice(self.graph_out(graph, v));
    }
}

/// Split cells per block of [`Sorter::build_round_graph`]'s parallel pass.
const ROUND_GRAPH_BLOCK: usize = 1 << 12;
