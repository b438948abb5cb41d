//! A min/max hierarchy over the cells of a geometry (after Livnat and
//! Hansen's view-dependent isosurface extraction, whose octree keeps the
//! scalar range of each subtree and culls subtrees behind an occlusion
//! mask): what lets a frame skip the dark cells of a transfer function,
//! and whole groups of cells hidden behind opaque ones, without a test per
//! cell.
//!
//! **The tree.** Cells are put in the Morton order of their bounding
//! boxes' centres (21 bits per axis over the mesh's bounds), and cut into
//! leaves of [`LEAF_CELLS`] consecutive cells; each level above pairs the
//! nodes of the one below (an odd last node is carried up alone) up to one
//! root. A node holds a contiguous run of cells in that order, the range
//! of leaves below it and the world-space box of its cells' points. Built
//! once per geometry ([`CellTree::build`]: the boxes, a sort, the levels),
//! it does not depend on the field.
//!
//! **Min/max.** Per field ([`CellRanges::build`]) each cell gets the range
//! of its scalars (its points', or its own cell value), and each node the
//! union of its cells' ranges. A cell whose range is not finite (every
//! value NaN) makes its node's range infinite, so no test on the node can
//! decide it.
//!
//! **Dark cells** ([`CellTree::classify`]): a test on a scalar range that
//! is *monotone* (true for a range, true for every range inside it: the
//! transfer function's darkness, [`super::pieces::dark_range`], is, since
//! the extinction and emission are linear between its nodes and the test
//! looks at both sides of each node inside) is applied top down: a node
//! whose range passes holds only cells that pass, and is not looked into;
//! a leaf whose range fails has each of its cells tested. A transfer
//! function that covers a narrow band of a field that varies smoothly in
//! space visits a few nodes and tests the cells of the leaves near the
//! band only. The answer is the per-cell test's, cell for cell.
//!
//! **Occlusion** ([`super::occlusion`]): a node whose box, projected,
//! lies wholly behind opaque pixels hides every piece of its cells that
//! the front-to-back walk has not reached yet.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::Mesh;

use super::pieces::value_range;
use super::scene::ScalarsRef;

/// Cells per leaf: enough that a node test replaces several cell tests,
/// few enough that a leaf stays compact in space (a leaf of a structured
/// grid is a 4 x 2 x 2 block). On the generated 40^3 grid, a transfer
/// function over 5 % of the range made 3,493 node and 19,712 cell tests
/// with 16 (8: 5,957 and 16,584; 32: 2,025 and 23,488) of 64,000 cells.
pub const LEAF_CELLS: usize = 16;

/// One node: a run of cells in leaf order, the leaves below it and the box
/// of its cells' points.
#[derive(Clone, Debug)]
pub struct Node {
    /// Indices into [`CellTree::cells`].
    pub cells: Range<u32>,
    /// Indices of the leaves (level 0) below it.
    pub leaves: Range<u32>,
    /// World-space box of its cells' points (`lo`, `hi`); empty (`lo` >
    /// `hi`) when it has no point.
    pub lo: DVec3,
    pub hi: DVec3,
}

/// The hierarchy over a geometry's cells (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct CellTree {
    /// Cell ids in leaf order.
    pub cells: Vec<u32>,
    /// The leaf of each cell id.
    pub leaf_of: Vec<u32>,
    /// Nodes level by level, leaves first; `levels[k]` is the range of
    /// level `k`'s nodes. The children of node `i` of level `k + 1` are
    /// nodes `2 i` and `2 i + 1` (when it exists) of level `k`.
    pub nodes: Vec<Node>,
    pub levels: Vec<Range<usize>>,
    /// The parent of each node (`u32::MAX` for the root).
    pub parent: Vec<u32>,
}

/// Per field: each cell's scalar range in leaf order, and each node's.
#[derive(Clone, Debug, Default)]
pub struct CellRanges {
    /// Indexed like [`CellTree::cells`].
    pub cell: Vec<(f64, f64)>,
    /// Indexed like [`CellTree::nodes`].
    pub node: Vec<(f64, f64)>,
}

/// What a classification looked at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClassifyStats {
    /// Nodes whose range was tested.
    pub nodes_visited: usize,
    /// Cells tested one by one (those of the leaves whose range failed).
    pub cells_tested: usize,
    /// All nodes, all cells.
    pub nodes: usize,
    pub cells: usize,
}

/// The Morton code of a point with coordinates in `[0, 1]^3`, 21 bits
/// per axis.
fn morton(p: DVec3) -> u64 {
    fn spread(v: f64) -> u64 {
        // NaN maps to 0.
        let mut x = (v.clamp(0.0, 1.0) * ((1u64 << 21) - 1) as f64) as u64;
        x &= 0x1f_ffff;
        x = (x | x << 32) & 0x001f_0000_0000_ffff;
        x = (x | x << 16) & 0x001f_0000_ff00_00ff;
        x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
        x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
        x = (x | x << 2) & 0x1249_2492_4924_9249;
        x
    }
    spread(p.x) | spread(p.y) << 1 | spread(p.z) << 2
}

impl CellTree {
    /// The tree over `mesh`'s cells (see the module docs). Cells with a
    /// point id out of range or a non-finite point get an empty box (they
    /// are never drawn; a node's box is that of its other cells).
    pub fn build(mesh: &Mesh) -> CellTree {
        let n = mesh.cells.len();
        let pts = &mesh.points;
        let boxes: Vec<(DVec3, DVec3)> = (0..n)
            .into_par_iter()
            .map(|c| {
                let (mut lo, mut hi) =
                    (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
                for &p in mesh.cells.nodes(c) {
                    match pts.get(p as usize) {
                        Some(&q) if q.is_finite() => {
                            lo = lo.min(q);
                            hi = hi.max(q);
                        }
                        _ => {
                            return (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
                        }
                    }
                }
                (lo, hi)
            })
            .collect();
        let b = mesh.bounds();
        let (mlo, mhi) = (DVec3::new(b[0], b[2], b[4]), DVec3::new(b[1], b[3], b[5]));
        let ext = (mhi - mlo).max(DVec3::splat(f64::MIN_POSITIVE));
        let mut keyed: Vec<(u64, u32)> = boxes
            .par_iter()
            .enumerate()
            .map(|(c, (lo, hi))| (morton((((*lo + *hi) * 0.5) - mlo) / ext), c as u32))
            .collect();
        keyed.par_sort_unstable();
        let cells: Vec<u32> = keyed.into_iter().map(|(_, c)| c).collect();
        let mut leaf_of = vec![0u32; n];
        for (k, &c) in cells.iter().enumerate() {
            leaf_of[c as usize] = (k / LEAF_CELLS) as u32;
        }
        // Leaves.
        let mut nodes: Vec<Node> = (0..n.div_ceil(LEAF_CELLS))
            .into_par_iter()
            .map(|l| {
                let run = l * LEAF_CELLS..((l + 1) * LEAF_CELLS).min(n);
                let (mut lo, mut hi) =
                    (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
                for &c in &cells[run.clone()] {
                    let (a, b) = boxes[c as usize];
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                Node {
                    cells: run.start as u32..run.end as u32,
                    leaves: l as u32..l as u32 + 1,
                    lo,
                    hi,
                }
            })
            .collect();
        let mut levels: Vec<Range<usize>> = Vec::new();
        levels.push(0..nodes.len());
        // Levels above, pairing the nodes of the one below.
        while levels.last().is_some_and(|r| r.len() > 1) {
            let below = levels.last().cloned().unwrap_or(0..0);
            let start = nodes.len();
            for k in (below.start..below.end).step_by(2) {
                let a = nodes[k].clone();
                let node = match nodes.get(k + 1).filter(|_| k + 1 < below.end) {
                    Some(b) => Node {
                        cells: a.cells.start..b.cells.end,
                        leaves: a.leaves.start..b.leaves.end,
                        lo: a.lo.min(b.lo),
                        hi: a.hi.max(b.hi),
                    },
                    None => a,
                };
                nodes.push(node);
            }
            levels.push(start..nodes.len());
        }
        let mut parent = vec![u32::MAX; nodes.len()];
        for w in levels.windows(2) {
            for (i, p) in w[1].clone().enumerate() {
                for child in [w[0].start + 2 * i, w[0].start + 2 * i + 1] {
                    if child < w[0].end {
                        parent[child] = p as u32;
                    }
                }
            }
        }
        CellTree {
            cells,
            leaf_of,
            nodes,
            levels,
            parent,
        }
    }

    /// The root's index (`None` for a mesh without cells).
    pub fn root(&self) -> Option<usize> {
        self.levels
            .last()
            .and_then(|r| (r.len() == 1).then_some(r.start))
    }

    /// The children of node `i` (none for a leaf).
    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let level = self.levels.iter().position(|r| r.contains(&i));
        let below = level
            .and_then(|k| k.checked_sub(1))
            .map(|k| self.levels[k].clone());
        let first = below
            .as_ref()
            .map(|b| b.start + 2 * (i - self.levels[level.unwrap_or(0)].start));
        below
            .into_iter()
            .zip(first)
            .flat_map(|(b, f)| (f..f + 2).filter(move |c| *c < b.end))
    }

    /// Each cell's dark flag (by cell id) under the monotone test `dark` on
    /// scalar ranges (see the module docs): the per-cell test's answer,
    /// testing only the cells of the leaves whose range fails, and what
    /// was looked at.
    pub fn classify(
        &self,
        ranges: &CellRanges,
        dark: &(dyn Fn(f64, f64) -> bool + Sync),
    ) -> (Vec<bool>, ClassifyStats) {
        let n = self.cells.len();
        let mut stats = ClassifyStats {
            nodes: self.nodes.len(),
            cells: n,
            ..Default::default()
        };
        // Leaves whose cells are each tested; the others are dark whole.
        let leaves = self.levels.first().map_or(0, |r| r.len());
        let mut test_leaf = vec![false; leaves];
        let mut stack: Vec<usize> = self.root().into_iter().collect();
        while let Some(i) = stack.pop() {
            stats.nodes_visited += 1;
            let (lo, hi) = ranges.node.get(i).copied().unwrap_or((f64::NAN, f64::NAN));
            if dark(lo, hi) {
                continue;
            }
            if i < leaves {
                test_leaf[i] = true;
            } else {
                stack.extend(self.children(i));
            }
        }
        let mut sorted = vec![true; n];
        sorted
            .par_chunks_mut(LEAF_CELLS)
            .zip(ranges.cell.par_chunks(LEAF_CELLS))
            .zip(test_leaf.par_iter())
            .for_each(|((out, r), &test)| {
                if test {
                    for (o, &(lo, hi)) in out.iter_mut().zip(r) {
                        *o = dark(lo, hi);
                    }
                }
            });
        stats.cells_tested = test_leaf
            .iter()
            .enumerate()
            .filter(|(_, &t)| t)
            .map(|(l, _)| self.nodes[l].cells.len())
            .sum();
        let mut out = vec![true; n];
        for (k, &c) in self.cells.iter().enumerate() {
            if let Some(o) = out.get_mut(c as usize) {
                *o = sorted[k];
            }
        }
        (out, stats)
    }
}

impl CellRanges {
    /// The ranges of `scalars` over `tree`'s cells of `mesh` (see the
    /// module docs).
    pub fn build(tree: &CellTree, mesh: &Mesh, scalars: ScalarsRef) -> CellRanges {
        let cells = &mesh.cells;
        let cell: Vec<(f64, f64)> = tree
            .cells
            .par_iter()
            .map(|&c| {
                let c = c as usize;
                let (lo, hi) = match scalars {
                    ScalarsRef::Point(v) => value_range(
                        cells
                            .nodes(c)
                            .iter()
                            .map(|&p| v.get(p as usize).copied().unwrap_or(f64::NAN)),
                    ),
                    ScalarsRef::Cell(v) => {
                        let s = v.get(c).copied().unwrap_or(f64::NAN);
                        (s, s)
                    }
                    ScalarsRef::Constant(s) => (s, s),
                };
                (lo, hi)
            })
            .collect();
        let mut node = vec![(f64::INFINITY, f64::NEG_INFINITY); tree.nodes.len()];
        for (k, r) in tree.levels.iter().enumerate() {
            for i in r.clone() {
                node[i] = if k == 0 {
                    let run = &tree.nodes[i].cells;
                    cell[run.start as usize..run.end as usize]
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &b| union(a, b))
                } else {
                    tree.children(i)
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, c| union(a, node[c]))
                };
            }
        }
        CellRanges { cell, node }
    }
}

/// The union of two scalar ranges, infinite when either is not finite
/// (see the module docs).
fn union(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    let finite = |r: (f64, f64)| r.0.is_finite() && r.1.is_finite();
    if a.0 == f64::INFINITY && a.1 == f64::NEG_INFINITY {
        // The empty start of a fold.
        return if finite(b) {
            b
        } else {
            (f64::NEG_INFINITY, f64::INFINITY)
        };
    }
    if !finite(a) || !finite(b) {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    (a.0.min(b.0), a.1.max(b.1))
}

#[cfg(test)]
mod tests;
