//! From a sorted graph to the [`Order`]: the per-view sort's last step.
//!
//! Kahn's emitted ids become pieces (whole cells, tets of split cells), in
//! blocks on the thread pool joined in order; a tet holding breakpoints
//! becomes its slabs, back to front ([`slabs::tet_slabs`], through
//! [`OrderWriter`]). The leftover strongly connected components follow in
//! topological order: a single piece as itself, a cycle first by plane cuts
//! ([`bsp::order_group`], its fragments as [`Piece::Frag`]s) and otherwise as
//! a group of pieces ([`Order::groups`]) that the renderer composites per
//! pixel, listed by decreasing depth of their vertex centroids.

use glam::DVec3;
use rayon::prelude::*;

use super::super::slabs::{self, SlabScratch};
use super::super::{bsp, Order, OrderStats, Piece, SplitPolicy};
use super::{RoundGraph, Sorter, View};
use crate::camera::Camera;

/// Emitted pieces per block of [`Sorter::finish`]'s parallel pass.
const FINISH_BLOCK: usize = 1 << 14;

impl Sorter {
    /// Converts ids to pieces (tets holding breakpoints become their slabs,
    /// back to front); appends the leftover components (topological order,
    /// cycles as groups).
    pub(super) fn finish(
        &self,
        emitted: Vec<u32>,
        comps: Vec<Vec<u32>>,
        graph: &RoundGraph,
        camera: &Camera,
        policy: &SplitPolicy,
        stats: &mut OrderStats,
    ) -> Order {
        let levels = match policy.point_scalars {
            Some(_) => slabs::order_levels(policy.breakpoints),
            None => Vec::new(),
        };
        let writer = |capacity: usize| {
            OrderWriter::new(
                capacity,
                &levels,
                policy.point_scalars,
                &self.mesh.points,
                camera,
            )
        };
        // The emitted pieces in blocks on the thread pool (slicing a tet
        // into its ordered slabs is most of the work), joined in order.
        let blocks: Vec<OrderWriter> = emitted
            .par_chunks(FINISH_BLOCK)
            .map(|block| {
                let mut out = writer(block.len() + block.len() / 2);
                for &v in block {
                    out.push(self.piece(graph, v));
                }
                out
            })
            .collect();
        let mut out = writer(blocks.iter().map(|b| b.pieces.len()).sum::<usize>() + comps.len());
        for b in blocks {
            out.pieces.extend_from_slice(&b.pieces);
            out.sliced += b.sliced;
        }
        let view = View::of(camera);
        let mut fragments = Vec::new();
        let mut groups = Vec::new();
        for comp in comps.into_iter().rev() {
            if comp.len() == 1 {
                out.push(self.piece(graph, comp[0]));
                continue;
            }
            let start = out.pieces.len();
            let mut members: Vec<(f64, Piece)> = comp
                .iter()
                .map(|&v| {
                    let pc = self.piece(graph, v);
                    (self.depth(&pc, camera), pc)
                })
                .collect();
            members.sort_by(|a, b| b.0.total_cmp(&a.0));
            let members: Vec<Piece> = members.into_iter().map(|m| m.1).collect();
            if self.plane_split {
                if let Some(frags) = bsp::order_group(&members, &self.mesh.points, &view) {
                    stats.cycles_resolved_by_planes += 1;
                    stats.fragments += frags.len();
                    for (src, frag) in frags {
                        let Piece::Tet { cell, tet } = members[src] else {
                            continue;
                        };
                        out.pieces.push(Piece::Frag {
                            cell,
                            tet,
                            frag: fragments.len() as u32,
                        });
                        fragments.push(frag);
                    }
                    continue;
                }
            }
            for m in members {
                out.push(m);
            }
            groups.push(start..out.pieces.len());
        }
        let pieces = out.pieces;
        stats.cycle_groups = groups.len();
        stats.pieces_in_groups = groups.iter().map(|g| g.len()).sum();
        stats.pieces = pieces.len();
        stats.split_cells = self.pool.active.len();
        stats.tets = graph.pieces - self.mesh.cells.len();
        stats.sliced_tets = out.sliced;
        stats.slabs = pieces
            .iter()
            .filter(|p| matches!(p, Piece::Slab { .. }))
            .count();
        Order {
            pieces,
            fragments,
            levels,
            groups,
            stats: OrderStats::default(),
        }
    }

    /// The piece of id `v` (a whole cell, or a tet of a split cell).
    fn piece(&self, graph: &RoundGraph, v: u32) -> Piece {
        let n = self.mesh.cells.len() as u32;
        if v < n {
            return Piece::Cell(v);
        }
        let k = (v - n) as usize;
        let slot = graph.tet_slot[k] as usize;
        let c = self.pool.active[slot];
        let local = k - graph.base[slot] as usize;
        match self.pool.get(c).and_then(|s| s.tets.get(local)) {
            Some(&tet) => Piece::Tet { cell: c, tet },
            None => Piece::Cell(c),
        }
    }

    /// Depth of a piece's vertex centroid (for ordering inside groups).
    fn depth(&self, piece: &Piece, camera: &Camera) -> f64 {
        let p = &self.mesh.points;
        let (sum, cnt) = match piece {
            Piece::Cell(c) => {
                let nodes = self.mesh.cells.nodes(*c as usize);
                (
                    nodes.iter().map(|&v| p[v as usize]).sum::<DVec3>(),
                    nodes.len(),
                )
            }
            Piece::Tet { tet, .. } | Piece::Slab { tet, .. } | Piece::Frag { tet, .. } => {
                (tet.iter().map(|&v| p[v as usize]).sum::<DVec3>(), 4)
            }
        };
        let centre = sum / cnt.max(1) as f64;
        if camera.ortho {
            (centre - camera.position).dot(camera.forward)
        } else {
            (centre - camera.position).length()
        }
    }
}

/// Writes pieces into (one block of) an order, a tet holding breakpoints
/// as its slabs ([`slabs::tet_slabs`]).
pub(super) struct OrderWriter<'a> {
    pub(super) pieces: Vec<Piece>,
    levels: &'a [f64],
    scalars: Option<&'a [f64]>,
    points: &'a [DVec3],
    camera: &'a Camera,
    /// Tets written as slabs.
    pub(super) sliced: usize,
    scratch: SlabScratch,
}

impl<'a> OrderWriter<'a> {
    pub(super) fn new(
        capacity: usize,
        levels: &'a [f64],
        scalars: Option<&'a [f64]>,
        points: &'a [DVec3],
        camera: &'a Camera,
    ) -> Self {
        OrderWriter {
            pieces: Vec::with_capacity(capacity),
            levels,
            scalars,
            points,
            camera,
            sliced: 0,
            scratch: SlabScratch::default(),
        }
    }

    /// Writes `piece`; a tet holding breakpoints as its slabs.
    pub(super) fn push(&mut self, piece: Piece) {
        let (Piece::Tet { cell, tet }, Some(sc)) = (piece, self.scalars) else {
            self.pieces.push(piece);
            return;
        };
        let s = tet.map(|v| sc.get(v as usize).copied().unwrap_or(0.0));
        let (points, camera) = (self.points, self.camera);
        let view = || tet.map(|v| camera.to_view(points[v as usize]));
        let slabs = slabs::tet_slabs(&s, &s, view, self.levels, camera.ortho, &mut self.scratch);
        if slabs.is_empty() {
            self.pieces.push(piece);
            return;
        }
        self.sliced += 1;
        self.pieces.extend(
            slabs
                .iter()
                .map(|&(lo, hi)| Piece::Slab { cell, tet, lo, hi }),
        );
    }
}
