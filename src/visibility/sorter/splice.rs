//! The values' part of an order, spliced into the geometry's: what lets a
//! time step that changes only the values keep the sort.
//!
//! [`Sorter::order`] sorts in two steps:
//! 1. [`Sorter::base_order`] sorts the view with the splits the geometry
//!    asks for alone (problem faces, distorted cells, cycles, `--split
//!    all`). Its pieces are whole cells, tets and cycle fragments, no slabs.
//!    It depends on the camera and the mesh, not on the values.
//! 2. [`Sorter::splice`] puts the values in: every whole cell whose nodal
//!    range strictly holds a breakpoint (and is not dark,
//!    [`super::super::SplitPolicy::dark`]) is replaced, at its place in the
//!    base order, by its consistent tets in their own back-to-front order;
//!    then every tet holding breakpoints becomes its slabs, as
//!    [`Sorter::finish`] writes them.
//!
//! **Why the spliced order is exact.** A cell drawn whole is convex (cells
//! that are not, beyond their face diagonals, are split by the base sort),
//! so a ray meets it in one interval, which its tets tile. Every piece the
//! base order puts before (after) the cell is behind (in front of) that
//! whole interval on every ray that meets both. So the cell's tets, sorted
//! among themselves, can stand in the cell's place. The tets of one cell
//! are sorted by Kahn's algorithm over the triangles they share
//! ([`SplitCell::internal`]), with the same exact side tests the full sort
//! makes.
//!
//! **When it does not apply.** The tets of one cell could in principle see
//! each other in a cycle. Then [`Sorter::splice`] sorts the view again with
//! the breakpoint splits in it (the one-step sort, which resolves cycles),
//! so the order is exact either way.
//!
//! The renderer caches the base order per view (`render::order_cache`):
//! a series step with new values, or a transfer function with new
//! breakpoints, only splices (about a tenth of the sort on the 1M-hex
//! grid).

use std::time::Instant;

use rayon::prelude::*;

use super::super::split::SplitCell;
use super::super::{Order, Piece, SplitPolicy, VisibilityError};
use super::finish::OrderWriter;
use super::{Sorter, View};
use crate::camera::Camera;
use crate::numeric::predicates::Side;

/// Base pieces per block of the splice's parallel pass.
const SPLICE_BLOCK: usize = 1 << 14;

/// One block of the splice: its pieces, and per base piece how many it
/// became (only when the order has groups to move).
struct Block<'a> {
    out: OrderWriter<'a>,
    counts: Vec<u32>,
    /// Whole cells split at breakpoints, and their tets.
    spliced: usize,
    tets: usize,
    /// A cell whose tets see each other in a cycle.
    cycle: bool,
}

impl Sorter {
    /// The order of `camera`'s view with the splits the geometry asks for
    /// alone (and every cell split with `all`): no breakpoint splits, no
    /// slabs. [`Sorter::splice`] makes the order of any values from it.
    pub fn base_order(&mut self, camera: &Camera, all: bool) -> Result<Order, VisibilityError> {
        let policy = SplitPolicy {
            all,
            ..Default::default()
        };
        self.sort(camera, &policy)
    }

    /// The order of `policy` made from `base`, the [`Sorter::base_order`]
    /// of the same camera and `policy.all` (module docs). Falls back to a
    /// full sort when a cell's tets see each other in a cycle.
    pub fn splice(
        &mut self,
        base: &Order,
        camera: &Camera,
        policy: &SplitPolicy,
    ) -> Result<Order, VisibilityError> {
        let t0 = Instant::now();
        let Some(scalars) = policy.point_scalars else {
            return Ok(base.clone());
        };
        if policy.breakpoints.is_empty() {
            return Ok(base.clone());
        }
        if scalars.len() < self.mesh.points.len() {
            return Err(VisibilityError::ScalarCount {
                got: scalars.len(),
                points: self.mesh.points.len(),
            });
        }
        let levels = super::super::slabs::order_levels(policy.breakpoints);
        let view = View::of(camera);
        // The rule for every cell, once (the blocks look whole cells up;
        // the counts are over every cell, as the one-step sort's).
        let split: Vec<BreakpointSplit> = (0..self.mesh.cells.len() as u32)
            .into_par_iter()
            .map(|c| self.breakpoint_split(c, scalars, policy))
            .collect();
        let with_counts = !base.groups.is_empty();
        let this = &*self;
        let split_ref = &split;
        let levels_ref = &levels;
        let blocks: Vec<Block> = base
            .pieces
            .par_chunks(SPLICE_BLOCK)
            .map(|chunk| {
                let mut b = Block {
                    out: OrderWriter::new(
                        chunk.len() + chunk.len() / 2,
                        levels_ref,
                        Some(scalars),
                        &this.mesh.points,
                        camera,
                    ),
                    counts: Vec::new(),
                    spliced: 0,
                    tets: 0,
                    cycle: false,
                };
                let mut tets = Vec::new();
                for &piece in chunk {
                    let before = b.out.pieces.len();
                    match piece {
                        Piece::Cell(c) => match split_ref[c as usize] {
                            BreakpointSplit::No | BreakpointSplit::Dark => b.out.push(piece),
                            BreakpointSplit::Yes => {
                                b.spliced += 1;
                                if !this.cell_tets_in_order(c, view, &mut tets) {
                                    b.cycle = true;
                                    return b;
                                }
                                b.tets += tets.len();
                                for &tet in &tets {
                                    b.out.push(Piece::Tet { cell: c, tet });
                                }
                            }
                        },
                        Piece::Frag { .. } => b.out.pieces.push(piece),
                        _ => b.out.push(piece),
                    }
                    if with_counts {
                        b.counts.push((b.out.pieces.len() - before) as u32);
                    }
                }
                b
            })
            .collect();
        if blocks.iter().any(|b| b.cycle) {
            return self.sort(camera, policy);
        }
        let mut stats = base.stats.clone();
        stats.breakpoint_cells = split.iter().filter(|&&s| s == BreakpointSplit::Yes).count();
        stats.dark_unsplit = split
            .iter()
            .filter(|&&s| s == BreakpointSplit::Dark)
            .count();
        let total: usize = blocks.iter().map(|b| b.out.pieces.len()).sum();
        let mut pieces = Vec::with_capacity(total);
        let mut starts = Vec::with_capacity(if with_counts {
            base.pieces.len() + 1
        } else {
            0
        });
        stats.sliced_tets = 0;
        for b in blocks {
            let mut at = 0;
            for &k in &b.counts {
                starts.push(pieces.len() as u32);
                pieces.extend_from_slice(&b.out.pieces[at..at + k as usize]);
                at += k as usize;
            }
            if !with_counts {
                pieces.extend_from_slice(&b.out.pieces);
            }
            stats.split_cells += b.spliced;
            stats.spliced_cells += b.spliced;
            stats.tets += b.tets;
            stats.sliced_tets += b.out.sliced;
        }
        if with_counts {
            starts.push(pieces.len() as u32);
        }
        let groups = base
            .groups
            .iter()
            .map(|g| starts[g.start] as usize..starts[g.end] as usize)
            .collect();
        stats.pieces = pieces.len();
        stats.slabs = pieces
            .iter()
            .filter(|p| matches!(p, Piece::Slab { .. }))
            .count();
        stats.time_splice = t0.elapsed();
        stats.time_total += stats.time_splice;
        Ok(Order {
            pieces,
            fragments: base.fragments.clone(),
            levels,
            groups,
            stats,
        })
    }

    /// Whether cell `c` is split at breakpoints: its nodal range strictly
    /// holds one, and it is not dark (the one rule of the one-step sort's
    /// policy splits and of the splice).
    pub(super) fn breakpoint_split(
        &self,
        c: u32,
        scalars: &[f64],
        policy: &SplitPolicy,
    ) -> BreakpointSplit {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for &v in self.mesh.cells.nodes(c as usize) {
            let x = scalars[v as usize];
            lo = lo.min(x);
            hi = hi.max(x);
        }
        if !policy.breakpoints.iter().any(|&b| lo < b && b < hi) {
            BreakpointSplit::No
        } else if policy.dark.is_some_and(|d| (d.test)(lo, hi)) {
            BreakpointSplit::Dark
        } else {
            BreakpointSplit::Yes
        }
    }

    /// Cell `c`'s consistent tets back to front into `out`; false when they
    /// see each other in a cycle.
    fn cell_tets_in_order(&self, c: u32, view: View, out: &mut Vec<[u32; 4]>) -> bool {
        out.clear();
        let sc = SplitCell::build(&self.mesh, &self.topo, c as usize);
        let m = sc.tets.len();
        let p = &self.mesh.points;
        // Edges (earlier, later) over local tet indices.
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(sc.internal.len());
        for it in &sc.internal {
            let [a, b, cc] = it.tri.map(|v| p[v as usize]);
            let se = view.side(a, b, cc);
            if se == Side::On || it.side_i == Side::On {
                continue;
            }
            // Eye on tet i's side: i occludes j, j first.
            edges.push(if se == it.side_i {
                (it.j, it.i)
            } else {
                (it.i, it.j)
            });
        }
        let mut indeg = vec![0u32; m];
        for &(_, b) in &edges {
            indeg[b as usize] += 1;
        }
        let mut done = vec![false; m];
        for _ in 0..m {
            let Some(t) = (0..m).find(|&t| !done[t] && indeg[t] == 0) else {
                return false;
            };
            done[t] = true;
            out.push(sc.tets[t]);
            for &(a, b) in &edges {
                if a as usize == t {
                    indeg[b as usize] -= 1;
                }
            }
        }
        true
    }
}

/// What the breakpoints do to a cell.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum BreakpointSplit {
    No,
    /// Its range holds a breakpoint, but nothing is drawn for it.
    Dark,
    Yes,
}
