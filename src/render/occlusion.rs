//! Occlusion culling: pieces hidden behind opaque ones are not drawn.
//!
//! The projected-cell driver draws the order back to front. Before it does,
//! this pass walks the order front to back with one number per pixel
//! centre: a lower bound on the optical depth that the pieces already
//! walked put in front of the centre, as drawn. A piece every centre of
//! whose screen box already lies behind more than [`cut_depth`] is hidden:
//! whatever it and the pieces behind it would add to such a pixel is at
//! most the transmittance in front (below
//! [`OCCLUSION_TRANSMITTANCE`] over the brightest colour) times that
//! colour, so leaving it out changes no channel by more than
//! `OCCLUSION_TRANSMITTANCE` (the image tests allow 1e-6).
//!
//! **Why the walk may use the order, not the geometry.** A pixel's value
//! is the pieces drawn at it, each attenuated by those drawn after it. The
//! pieces before a piece in the front-to-back walk are exactly those drawn
//! after it, so the bound, a sum over them, bounds the attenuation the
//! piece gets, whatever the geometry (cycle groups aside, below).
//!
//! **The bound.** A cell is credited once all its pieces have been walked
//! (its tets, slabs and fragments tile it, so at every centre they add up
//! to the cell's own segment). At each centre of its screen box, its
//! credit is the ray's chord through the intersection of the inner
//! half-spaces of its boundary triangles' planes (the `faces` field's
//! triangles, which are the cell's faces everywhere): for a convex cell
//! that is the cell, for any other a part of it (its kernel), so the chord
//! lies in the cell's segment. The inner side is the one the mean of the
//! cell's points lies on for every plane (a cell without such a point, or
//! with a degenerate triangle, credits nothing). The chord times the
//! transfer function's least extinction on the cell's scalar range, shrunk
//! by [`CREDIT_SHRINK`] for the rounding of the drawn segment, is the
//! credit.
//!
//! **The test.** A piece's pixels lie in the box of its projected corners:
//! its cell's points, or for a tet, a slab or a fragment its tet's corners
//! (the projection of a convex piece is the hull of its corners',
//! and the pixels the driver's exact decisions give it are on rays that
//! meet it), grown by [`FRUSTUM_MARGIN_PX`]. Pieces with a corner not in
//! front of the near plane are never hidden, cells with such a point never
//! credit.
//!
//! **Blocks.** The walk goes in blocks of a size fixed by the number of
//! pieces ([`BLOCKS`] of them, within [`BLOCK_MIN`] and [`BLOCK_MAX`]): the
//! pieces of a block are tested against the credits of the blocks before
//! it (in parallel), then the cells the block completes are credited (their
//! chords in parallel, the sums in order). Leaving a block's own credits
//! out of its tests only hides less, and the blocks do not depend on the
//! number of threads, so the result is the same on every run.
//!
//! **Opaque isosurfaces** (Livnat and Hansen's view-dependent culling)
//! hide what lies behind them, in every mode that draws surfaces mixed
//! with the volume, and in a frame of surfaces alone (`--mode iso`,
//! `--iso-only`) with at least [`ALONE_MIN_OPAQUE`] of them (with fewer
//! such a frame, which draws only the pieces holding a value, is cheaper
//! to draw than the pass): at a centre where a cell's chord enters it on one
//! side of an opaque surface's value and leaves it on the other
//! ([`Credit::crosses`], with the margin of
//! [`OCCLUSION_ISO_REL`], the entry and exit scalars the `faces` field's on
//! the triangles the chord enters and leaves by, [`ends`]), the stages draw
//! that crossing in the cell, and the cell credits the centre with an
//! infinite depth. Surfaces opaque on both sides count, mixed exactly (RKE's
//! blend weighs surfaces down); a chord shorter than
//! [`OCCLUSION_ISO_CHORD`] of the diagonal (a ray along the outline up to
//! rounding) credits nothing.
//!
//! **What it leaves alone.** Cycle groups are composited per pixel into
//! one layer: their pieces are never hidden, and their cells never
//! credited. Independent emission is not bounded by the opacity in front
//! (no culling of its volume), and neither is a frame that counts
//! coverage, nor a frame of surfaces alone with fewer opaque surfaces than
//! [`ALONE_MIN_OPAQUE`]. A transfer function whose largest extinction times the
//! mesh's diagonal cannot reach the cut credits no volume, and without
//! opaque surfaces skips the pass at once.

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::tetra::triangulate_face;
#[cfg(doc)]
use crate::numeric::tolerance::OCCLUSION_TRANSMITTANCE;
use crate::numeric::tolerance::{
    FRUSTUM_MARGIN_PX, OCCLUSION_ISO_BARY, OCCLUSION_ISO_CHORD, OCCLUSION_ISO_REL,
    OCCLUSION_NODE_MARGIN_PX,
};
use crate::render::gradients::barycentric_raw;
use crate::render::iso::IsoMix;
use crate::tf::EmissionModel;
use crate::visibility::{Order, Piece};

use super::cell_tree::CellTree;
use super::pieces::{value_range, PieceSource};

/// Credits are shrunk by this factor: the drawn segment differs from the
/// exact one by the snap of its corners and `f32` interpolation, far below
/// a tenth.
pub const CREDIT_SHRINK: f64 = 0.9;

/// Blocks per walk (see the module docs): a block's own credits do not
/// hide its pieces, so the walk needs many; blocks hold from
/// [`BLOCK_MIN`] to [`BLOCK_MAX`] pieces.
pub const BLOCKS: usize = 256;
/// The smallest block (parallel work worth the hand-over).
pub const BLOCK_MIN: usize = 32;
/// The largest block.
pub const BLOCK_MAX: usize = 4096;

/// The fewest surfaces opaque on both sides for which a frame of surfaces
/// alone (`--mode iso`, `--iso-only`) runs the pass. Such a frame draws
/// only the pieces holding a value, each cheaply, and the pass's credits
/// cost about as much per piece: one closed surface hides little more
/// than its own far side. Stacked surfaces hide nearly everything behind
/// the front one (512 x 512, `zoovr render --stats`, renderer total,
/// 2026-12-07, lavapipe; values spread evenly over the field's range):
/// bluntfin 0.20 / 0.25 / 0.28 / 0.52 s for 6 / 8 / 10 / 100 values
/// without the pass, 0.20 / 0.25 / 0.27 / 0.31 s with it (5 values: 0.19
/// s against 0.21 s); the generated 1M-hex grid 1.67 / 3.14 / 8.18 s for
/// 5 / 10 / 100 values without it, 1.51 / 2.40 / 2.11 s with it (one
/// value: 0.91 s either way).
pub const ALONE_MIN_OPAQUE: usize = 8;

/// The optical depth in front of a centre beyond which nothing behind it
/// can change a channel by more than `transmittance` (by default
/// [`OCCLUSION_TRANSMITTANCE`]): `ln(c / transmittance)` with `c` the
/// brightest colour (at least 1, the most an isosurface adds).
pub fn cut_depth(brightest: f64, transmittance: f64) -> f64 {
    (brightest.max(1.0) / transmittance).ln()
}

/// [`cut_depth`] for `tf`'s brightest colour.
fn tf_cut_depth(tf: &crate::tf::TransferFunction, transmittance: f64) -> f64 {
    let brightest = tf
        .nodes()
        .iter()
        .flat_map(|n| n.color)
        .fold(0.0f64, |a, c| a.max(c.abs()));
    cut_depth(brightest, transmittance)
}

/// Whether the pass can hide anything in a frame with transfer function
/// `tf`, surfaces `iso` and the volume when `volume` over a mesh of
/// diagonal `diagonal` (a superset of the frames [`hidden_pieces`] runs
/// for: the renderer builds the min/max tree for those only).
pub fn may_hide(
    tf: &crate::tf::TransferFunction,
    iso: Option<&crate::render::iso::IsoSet>,
    volume: bool,
    diagonal: f64,
    transmittance: f64,
) -> bool {
    let opaque = iso.map_or(0, |set| {
        set.sides
            .iter()
            .filter(|sides| sides.iter().all(|side| side[3] >= 1.0))
            .count()
    });
    if !volume {
        return opaque >= ALONE_MIN_OPAQUE && tf_cut_depth(tf, transmittance).is_finite();
    }
    if tf.model() != EmissionModel::Glow {
        return false;
    }
    let cut = tf_cut_depth(tf, transmittance);
    // The pass's own measure (`PieceSource::max_rate` over the whole
    // range): extinction and glow emission `tau c` at every node.
    let tau_max = tf.nodes().iter().fold(0.0f64, |a, n| {
        let c = n.color.iter().fold(1.0f64, |m, c| m.max(c.abs()));
        a.max(n.tau).max(n.tau * c)
    });
    // False for NaN too.
    cut.is_finite() && (tau_max * diagonal >= cut || opaque > 0)
}

/// What the pass found.
#[derive(Clone, Debug, Default)]
pub struct Occlusion {
    /// Per piece of the order: hidden behind opaque pieces.
    pub hidden: Vec<bool>,
    /// How many are.
    pub count: usize,
    /// Nodes of the min/max tree found hidden whole, and the pieces they
    /// hid without a test of their own.
    pub nodes_hidden: usize,
    pub hidden_by_nodes: usize,
}

/// The geometry's min/max tree as the pass reads it
/// ([`super::cell_tree`]): its nodes' boxes, and the geometry's id of each
/// cell of the mesh drawn (the visible subset's map,
/// [`super::visible::VisibleSubset::cells`]; `None`: the same ids).
#[derive(Clone, Copy)]
pub struct TreeView<'a> {
    pub tree: &'a CellTree,
    pub geometry_ids: Option<&'a [u32]>,
}

impl TreeView<'_> {
    /// The leaf of the drawn mesh's cell `c`.
    fn leaf(&self, c: u32) -> Option<usize> {
        let g = match self.geometry_ids {
            Some(ids) => *ids.get(c as usize)?,
            None => c,
        };
        self.tree.leaf_of.get(g as usize).map(|&l| l as usize)
    }
}

/// The frame's pixel rays and the points' pixel positions.
struct View {
    width: usize,
    /// Unit pixel-centre rays (origin, direction), row by row.
    rays: Vec<(DVec3, DVec3)>,
    /// Pixel position of each mesh point (`None`: not in front of the near
    /// plane).
    screen: Vec<Option<(f64, f64)>>,
}

/// Runs the pass over `order` for `src` (see the module docs), hiding what
/// can change no channel by more than `transmittance`; `None` when it does
/// not apply or cannot hide anything.
pub fn hidden_pieces(
    src: &PieceSource,
    order: &Order,
    transmittance: f64,
    tree: Option<TreeView>,
) -> Option<Occlusion> {
    let tf = src.tf;
    if (src.volume && tf.model() != EmissionModel::Glow) || order.pieces.is_empty() {
        return None;
    }
    let cut = tf_cut_depth(tf, transmittance);
    let (lo, hi) = tf.scalar_range();
    let tau_max = src.max_rate(lo.min(hi), hi.max(lo));
    let mesh = src.mesh;
    let credit = Credit {
        volume: src.volume && cut.is_finite() && tau_max * mesh.diagonal() >= cut,
        // A frame drawing the surfaces alone draws only the pieces holding
        // a value, so cheaply that the pass pays only for many stacked
        // surfaces ([`ALONE_MIN_OPAQUE`]).
        opaque: {
            let values = opaque_values(src);
            if src.volume || values.len() >= ALONE_MIN_OPAQUE {
                values
            } else {
                Vec::new()
            }
        },
        min_chord: OCCLUSION_ISO_CHORD * mesh.diagonal(),
        tf_range: (lo.min(hi), (hi - lo).abs()),
    };
    if !cut.is_finite() || (!credit.volume && credit.opaque.is_empty()) {
        return None;
    }
    let camera = src.camera;
    let (w, h) = (camera.width as usize, camera.height as usize);
    if w == 0 || h == 0 {
        return None;
    }
    // Pieces per cell (a cell is credited when its last one is walked);
    // the cells of cycle groups are never credited.
    let n = order.pieces.len();
    let mut left = vec![0u32; mesh.cells.len()];
    for p in &order.pieces {
        left[p.cell() as usize] += 1;
    }
    let mut in_group = vec![false; n];
    for g in &order.groups {
        for k in g.clone() {
            in_group[k] = true;
            left[order.pieces[k].cell() as usize] = u32::MAX;
        }
    }
    let he = camera.half_extent();
    let view = View {
        width: w,
        rays: (0..w * h)
            .into_par_iter()
            .map(|k| {
                let r = camera.pixel_ray((k % w) as u32, (k / w) as u32);
                (r.origin, r.dir)
            })
            .collect(),
        screen: mesh
            .points
            .par_iter()
            .map(|&p| screen_of(camera, he, p))
            .collect(),
    };
    let mut depth = vec![0.0f64; w * h];
    let mut hidden = vec![false; n];
    let mut count = 0;
    let mut any_opaque = false;
    let mut completed = Vec::new();
    // The tree's node boxes on screen (`None`: a corner not in front of
    // the near plane, never hidden), and what it has hidden.
    let boxes: Vec<Option<(usize, usize, usize, usize)>> = tree.map_or(Vec::new(), |t| {
        t.tree
            .nodes
            .par_iter()
            .map(|node| node_box(src, node.lo, node.hi))
            .collect()
    });
    let mut node_hidden = vec![false; boxes.len()];
    let leaves = tree.map_or(0, |t| t.tree.levels.first().map_or(0, |r| r.len()));
    let mut leaf_hidden = vec![false; leaves];
    let (mut nodes_hidden, mut hidden_by_nodes) = (0, 0);
    let mut touched = Vec::new();
    // Cells with a piece left to draw: only those are credited (every
    // centre of a hidden piece's box is behind the cut already).
    let mut shown = vec![false; mesh.cells.len()];
    let covered = |b: &Option<(usize, usize, usize, usize)>, depth: &[f64]| {
        b.is_some_and(|(x0, x1, y0, y1)| {
            (y0..y1).all(|j| depth[j * w + x0..j * w + x1].iter().all(|&d| d >= cut))
        })
    };
    // A node's test: `Ok` when its box lies behind the cut, else the first
    // pixel in row order that is not (the node's witness). Depths only
    // grow, so the pixels before the witness stay behind the cut and the
    // next test resumes there: each node's box is scanned once over the
    // whole walk, and a node in the open costs one look per block.
    let mut witness = vec![u32::MAX; boxes.len()];
    let node_test = |i: usize, witness: &[u32], depth: &[f64]| -> Result<(), u32> {
        let Some((x0, x1, y0, y1)) = boxes[i] else {
            return Err(u32::MAX);
        };
        let (mut j, mut x) = (y0, x0);
        if let Some(px) = (witness[i] != u32::MAX).then_some(witness[i] as usize) {
            (j, x) = (px / w, px % w);
        }
        while j < y1 {
            while x < x1 {
                if depth[j * w + x] < cut {
                    return Err((j * w + x) as u32);
                }
                x += 1;
            }
            (j, x) = (j + 1, x0);
        }
        Ok(())
    };
    let block = (n / BLOCKS).clamp(BLOCK_MIN, BLOCK_MAX);
    let mut end = n;
    while end > 0 {
        let start = end.saturating_sub(block);
        // Whole nodes first: the leaves of this block's pieces, then up
        // from each leaf found hidden while its parent is.
        if let (true, Some(t)) = (any_opaque, tree) {
            touched.clear();
            touched.extend(
                (start..end)
                    .filter(|&k| !in_group[k])
                    .filter_map(|k| t.leaf(order.pieces[k].cell()))
                    .filter(|&l| !leaf_hidden[l]),
            );
            touched.sort_unstable();
            touched.dedup();
            // In order, on this thread: with the witnesses most tests are
            // one look, less than handing them over would cost.
            for &l in &touched {
                if let Err(px) = node_test(l, &witness, &depth) {
                    witness[l] = px;
                    continue;
                }
                let mut at = l;
                loop {
                    node_hidden[at] = true;
                    nodes_hidden += 1;
                    let r = &t.tree.nodes[at].leaves;
                    leaf_hidden[r.start as usize..r.end as usize].fill(true);
                    let p = t.tree.parent.get(at).copied().unwrap_or(u32::MAX) as usize;
                    if p >= node_hidden.len() || node_hidden[p] {
                        break;
                    }
                    match node_test(p, &witness, &depth) {
                        Ok(()) => at = p,
                        Err(px) => {
                            witness[p] = px;
                            break;
                        }
                    }
                }
            }
        }
        // Tests against the blocks in front.
        if any_opaque {
            let by_node = |k: usize| {
                tree.and_then(|t| t.leaf(order.pieces[k].cell()))
                    .is_some_and(|l| leaf_hidden[l])
            };
            let found: Vec<(usize, bool)> = (start..end)
                .into_par_iter()
                .filter(|&k| !in_group[k])
                .filter_map(|k| {
                    if by_node(k) {
                        return Some((k, true));
                    }
                    piece_box(src, &order.pieces[k], &view.screen, FRUSTUM_MARGIN_PX)
                        .is_some_and(|b| covered(&Some(b), &depth))
                        .then_some((k, false))
                })
                .collect();
            count += found.len();
            for (k, node) in found {
                hidden[k] = true;
                hidden_by_nodes += node as usize;
            }
        }
        for (piece, _) in order.pieces[start..end]
            .iter()
            .zip(&hidden[start..end])
            .filter(|(_, &h)| !h)
        {
            if let Some(s) = shown.get_mut(piece.cell() as usize) {
                *s = true;
            }
        }
        // The cells this block completes, front to back.
        completed.clear();
        for k in (start..end).rev() {
            let c = order.pieces[k].cell() as usize;
            if left[c] == u32::MAX {
                continue;
            }
            left[c] -= 1;
            if left[c] == 0 && shown[c] {
                completed.push(c as u32);
            }
        }
        let credits: Vec<Vec<(u32, f64)>> = completed
            .par_iter()
            .fold(
                || (Vec::new(), Vec::new()),
                |(mut acc, mut planes), &c| {
                    cell_credit(src, &credit, &view, c, &depth, cut, &mut planes, &mut acc);
                    (acc, planes)
                },
            )
            .map(|(acc, _)| acc)
            .collect();
        for list in credits {
            for (at, d) in list {
                let v = &mut depth[at as usize];
                *v += d;
                any_opaque |= *v >= cut;
            }
        }
        end = start;
    }
    Some(Occlusion {
        hidden,
        count,
        nodes_hidden,
        hidden_by_nodes,
    })
}

/// The pixel-centre box ([`points_box`]) of a tree node's world box
/// `lo`..`hi`: its eight corners' projections, grown by
/// [`FRUSTUM_MARGIN_PX`] as a piece's box is and by
/// [`OCCLUSION_NODE_MARGIN_PX`] for the rounding of corners that are not
/// mesh points; `None` when a corner is not in front of the near plane or
/// the box is empty (a node without points).
fn node_box(src: &PieceSource, lo: DVec3, hi: DVec3) -> Option<(usize, usize, usize, usize)> {
    if !(lo.cmple(hi).all() && lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let camera = src.camera;
    let he = camera.half_extent();
    let corners: [Option<(f64, f64)>; 8] = std::array::from_fn(|k| {
        let p = DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        screen_of(camera, he, p)
    });
    points_box(
        src,
        &[0, 1, 2, 3, 4, 5, 6, 7],
        &corners,
        FRUSTUM_MARGIN_PX + OCCLUSION_NODE_MARGIN_PX,
    )
}

/// The pixel position of world point `p` (`he`: the camera's
/// half extent); `None` when it is not in front of the near plane or does
/// not map to a finite position.
fn screen_of(camera: &crate::camera::Camera, he: (f64, f64), p: DVec3) -> Option<(f64, f64)> {
    let v = camera.to_view(p);
    if v.z.is_nan() || v.z <= camera.near.max(0.0) {
        return None;
    }
    camera
        .view_to_pixel_with(v, he)
        .map(|(x, y, _)| (x, y))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
}

/// The box of [`points_box`] around a piece: its cell's points for a
/// whole cell, its tet's corners for a tet, a slab or a fragment (which lie
/// in their tet, so their pixels lie in the tet's projection).
fn piece_box(
    src: &PieceSource,
    piece: &Piece,
    screen: &[Option<(f64, f64)>],
    m: f64,
) -> Option<(usize, usize, usize, usize)> {
    match *piece {
        Piece::Cell(c) => points_box(src, src.mesh.cells.nodes(c as usize), screen, m),
        Piece::Tet { tet, .. } | Piece::Slab { tet, .. } | Piece::Frag { tet, .. } => {
            points_box(src, &tet, screen, m)
        }
    }
}

/// Pixel-centre index ranges `[x0, x1) x [y0, y1)` of the box of the
/// projections of `points` grown by `m` pixels (centres at `i + 0.5`);
/// `None` when a point is not in front of the near plane or the box holds
/// no centre.
fn points_box(
    src: &PieceSource,
    points: &[u32],
    screen: &[Option<(f64, f64)>],
    m: f64,
) -> Option<(usize, usize, usize, usize)> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &p in points {
        let (x, y) = screen.get(p as usize).copied().flatten()?;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let (w, h) = (src.camera.width as f64, src.camera.height as f64);
    // Centres i + 0.5 with x0 - m <= i + 0.5 <= x1 + m.
    let lo = |v: f64| (v - m - 0.5).ceil().max(0.0);
    let hi = |v: f64, n: f64| (v + m - 0.5).floor().min(n - 1.0);
    let (i0, i1, j0, j1) = (lo(x0), hi(x1, w), lo(y0), hi(y1, h));
    if !(i0 <= i1 && j0 <= j1) {
        return None;
    }
    Some((i0 as usize, i1 as usize + 1, j0 as usize, j1 as usize + 1))
}

/// What cells are credited with (see the module docs).
struct Credit {
    /// Their volume's least extinction times their chord.
    volume: bool,
    /// The values of the surfaces that are opaque on both sides (exact
    /// mixing), sorted: where a ray's chord through a cell surely crosses
    /// one ([`Credit::crosses`]), the cell hides what lies behind.
    opaque: Vec<f64>,
    /// [`OCCLUSION_ISO_CHORD`] times the mesh's diagonal.
    min_chord: f64,
    /// The transfer function's node range `(lo, span)`: the stages' level
    /// margin is relative to the normalised value.
    tf_range: (f64, f64),
}

impl Credit {
    /// Whether a chord entering a cell at scalar `a` and leaving it at `b`
    /// (the `faces` field's values on its entry and exit triangles) crosses
    /// an opaque value `V` as every mode draws it: `a` and `b` on opposite
    /// sides of `V` by [`OCCLUSION_ISO_REL`] of `|V - lo| + span`. The drawn
    /// scalars run continuously between values on the exact ones' side of
    /// `V` (the `faces` field, or the `tets` field through the cell's tets;
    /// see the tolerance), so the surface is drawn in this cell.
    fn crosses(&self, a: f64, b: f64) -> bool {
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        let (tf_lo, span) = self.tf_range;
        self.opaque.iter().any(|&v| {
            let m = OCCLUSION_ISO_REL * ((v - tf_lo).abs() + span);
            lo < v - m && hi > v + m
        })
    }
}

/// The scalar at `x` on a boundary triangle (its corners and their
/// scalars), by barycentric weights; `None` where `x` is not on it (a
/// kernel's face beyond a non-convex cell's).
fn scalar_on(tri: &([DVec3; 3], [f64; 3]), x: DVec3) -> Option<f64> {
    let (p, s) = tri;
    let w = barycentric_raw(*p, x)?;
    if w.iter().any(|&v| v.is_nan() || v < -OCCLUSION_ISO_BARY) {
        return None;
    }
    Some(w[0] * s[0] + w[1] * s[1] + w[2] * s[2])
}

/// The `faces` field's scalars where the ray `o + t dir` enters and leaves
/// the stretch of a cell that holds its chord through the cell's kernel
/// (`planes` with outward normals times `flip`, and their triangles): the
/// last entering triangle it meets before the chord and the first leaving
/// one after it (no leaving plane is met before the chord begins, nor an
/// entering one after it ends, so no boundary lies between). For a convex
/// cell the planes of the chord's own ends. `None` where either is not
/// found.
fn ends(
    planes: &[(DVec3, DVec3)],
    tris: &[([DVec3; 3], [f64; 3])],
    flip: f64,
    o: DVec3,
    dir: DVec3,
) -> Option<(f64, f64)> {
    let (mut a, mut ta) = (None, f64::NEG_INFINITY);
    let (mut b, mut tb) = (None, f64::INFINITY);
    for (&(n, p), tri) in planes.iter().zip(tris) {
        let n = n * flip;
        let nd = n.dot(dir);
        if nd == 0.0 || nd.is_nan() {
            continue;
        }
        let t = -n.dot(o - p) / nd;
        if nd < 0.0 && t > ta {
            if let Some(v) = scalar_on(tri, o + dir * t) {
                (a, ta) = (Some(v), t);
            }
        } else if nd > 0.0 && t < tb {
            if let Some(v) = scalar_on(tri, o + dir * t) {
                (b, tb) = (Some(v), t);
            }
        }
    }
    Some((a?, b?))
}

/// The values of `src`'s isosurfaces that hide what lies behind them: opaque
/// on both sides, mixed exactly (RKE's blend weighs surfaces down).
fn opaque_values(src: &PieceSource) -> Vec<f64> {
    let Some(set) = src.iso else {
        return Vec::new();
    };
    // Without the exact tie decisions (a library switch for measuring
    // them) the stages may draw a crossing next to a face's iso line in
    // the next piece instead ([`Credit::crosses`]).
    if set.mix != IsoMix::Exact || !src.exact_ties {
        return Vec::new();
    }
    set.values
        .iter()
        .zip(&set.sides)
        .filter(|(v, sides)| v.is_finite() && sides.iter().all(|side| side[3] >= 1.0))
        .map(|(&v, _)| v)
        .collect()
}

/// Appends cell `c`'s credit at each centre of its box (see the module
/// docs) to `out` as (pixel index, optical depth), leaving out centres
/// already behind `cut` in `depth` (`planes` is scratch).
#[allow(clippy::too_many_arguments)]
fn cell_credit(
    src: &PieceSource,
    credit: &Credit,
    view: &View,
    c: u32,
    depth: &[f64],
    cut: f64,
    planes: &mut Vec<(DVec3, DVec3)>,
    out: &mut Vec<(u32, f64)>,
) {
    let mesh = src.mesh;
    let nodes = mesh.cells.nodes(c as usize);
    // A cell with a non-finite scalar is drawn empty or with holes
    // (`PieceSource::parts`): it hides nothing.
    if src.field_span.is_none() && nodes.iter().any(|&p| !src.scalar(c, p).is_finite()) {
        return;
    }
    let (lo, hi) = value_range(nodes.iter().map(|&p| src.scalar(c, p)));
    let tau = if credit.volume {
        src.min_extinction(lo, hi) * CREDIT_SHRINK
    } else {
        0.0
    };
    // False for NaN too.
    let by_volume = tau.partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater);
    // A surface may only run through a cell whose range holds its value.
    let may_hide = credit.opaque.iter().any(|&v| lo < v && v < hi);
    if !by_volume && !may_hide {
        return;
    }
    // The chord is 0 outside the hull of the projected points.
    let Some((x0, x1, y0, y1)) =
        points_box(src, src.mesh.cells.nodes(c as usize), &view.screen, 0.0)
    else {
        return;
    };
    if (y0..y1).all(|j| {
        depth[j * view.width + x0..j * view.width + x1]
            .iter()
            .all(|&d| d >= cut)
    }) {
        return;
    }
    let centre = nodes
        .iter()
        .map(|&p| mesh.points[p as usize])
        .sum::<DVec3>()
        / nodes.len() as f64;
    // Planes (unit normal n, point a), the centre on one side of all.
    planes.clear();
    let mut tris: Vec<([DVec3; 3], [f64; 3])> = Vec::new();
    let mut sign = 0.0f64;
    let mut ok = true;
    mesh.cells.for_each_face(c as usize, |_, face| {
        triangulate_face(face, |t| {
            if may_hide {
                tris.push((
                    t.map(|i| mesh.points[i as usize]),
                    t.map(|i| src.scalar(c, i)),
                ));
            }
            let [a, b, d] = t.map(|i| mesh.points[i as usize]);
            let n = (b - a).cross(d - a);
            let len = n.length();
            let s = (centre - a).dot(n);
            if len.is_nan()
                || len <= 0.0
                || s.is_nan()
                || s == 0.0
                || (sign != 0.0 && s.signum() != sign)
            {
                ok = false;
                return;
            }
            sign = s.signum();
            planes.push((n / len, a));
        })
    });
    if !ok || planes.len() < 4 {
        return;
    }
    // Outward normals: the centre is on the negative side.
    let flip = -sign;
    let w = view.width;
    for j in y0..y1 {
        for i in x0..x1 {
            if depth[j * w + i] >= cut {
                continue;
            }
            let (o, dir) = view.rays[j * w + i];
            // The chord and the planes it enters and leaves by.
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            let (mut k0, mut k1) = (usize::MAX, usize::MAX);
            for (k, &(n, a)) in planes.iter().enumerate() {
                let n = n * flip;
                let nd = n.dot(dir);
                let no = n.dot(o - a);
                if nd > 0.0 {
                    let t = -no / nd;
                    if t < t1 {
                        (t1, k1) = (t, k);
                    }
                } else if nd < 0.0 {
                    let t = -no / nd;
                    if t > t0 {
                        (t0, k0) = (t, k);
                    }
                } else if no > 0.0 {
                    t1 = f64::NEG_INFINITY;
                }
            }
            if t1 > t0 {
                // An opaque surface across the chord hides everything
                // behind the centre; otherwise the volume's credit.
                let hides = may_hide
                    && t1 - t0 > credit.min_chord
                    && k0 != usize::MAX
                    && k1 != usize::MAX
                    && match ends(planes, &tris, flip, o, dir) {
                        Some((sa, sb)) => credit.crosses(sa, sb),
                        None => false,
                    };
                let d = if hides {
                    f64::INFINITY
                } else {
                    tau * (t1 - t0)
                };
                if d > 0.0 {
                    out.push(((j * w + i) as u32, d));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
