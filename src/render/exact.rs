//! The exact mode (MWS): visibility order -> projection -> exact integrals at
//! region vertices -> wgpu compositing.
//!
//! Per view:
//! 1. [`Sorter::order`] gives the drawable pieces back to front (whole cells;
//!    consistent tets of problem cells and of cells whose nodal scalar range
//!    holds a TF breakpoint, a tet holding one as its slabs; every cell's
//!    tets with `--split all`).
//! 2. Pieces whose scalar range (a slab's: its band) maps to zero extinction
//!    everywhere are skipped (they neither emit nor absorb in the glow
//!    model).
//! 3. Each piece becomes a view-space [`Polyhedron`] (a slab: its tet
//!    clipped to the band, [`Clipper`]; the tet is built once for all its
//!    slabs); each is projected into regions ([`Projector`]), leaving out
//!    pieces and triangles that contain no pixel centre
//!    ([`crate::projection::coverage`],
//!    [`super::RenderOptions::cull_to_pixels`]).
//! 4. Region triangles whose vertices differ much in optical depth and glow
//!    colour are refined (math README 8.1: `C/alpha` is interpolated inside a
//!    region), see [`COLOR_REFINE_TOL`].
//! 5. At every region vertex a kept triangle uses, the closed-form
//!    integral gives the glow colour `C/alpha` and the mean extinction; the
//!    GPU evaluates `alpha = 1 - exp(-l tau)` per pixel from its
//!    exponential table and composites back to front.
//!
//! Pieces are processed in chunks of consecutive pieces by worker threads
//! (as many as the rayon pool has), which take chunks in order and run a
//! bounded number of chunks ahead of this thread; this thread uploads and
//! draws each chunk as soon as it and all before it are done, so memory
//! stays bounded whatever the mesh size and no worker waits for another
//! ([`pipeline`]); chunk buffers are reused.
//!
//! Interpolation: region vertices are sent with `w = 1` (positions already
//! divided), so the GPU interpolates linearly in screen space, which is the
//! model the projection's perspective refinement bounds (projection docs).
//!
//! Unresolved visibility cycles ([`crate::visibility::Order::groups`]) are
//! composited per pixel on the CPU into one layer each, drawn at the group's
//! place in the order ([`super::group`]).

use std::sync::{Condvar, Mutex};
use std::time::Instant;

use glam::DVec3;

use crate::camera::Camera;
use crate::gpu::cpu::CpuFrame;
use crate::gpu::{
    ClipMapper, Context, ExactVertex, Frame, FrameOptions, FrameStats, GpuError, PendingContext,
    MAX_PIECES,
};
use crate::image::Image;
use crate::integrate::{vertex_values, VertexValues};
use crate::mesh::Mesh;
use crate::numeric::tolerance::{COLOR_REFINE_MAX_DEPTH, COLOR_REFINE_TOL, TF_SLOPE_REL};
use crate::projection::coverage::PixelGrid;
use crate::projection::{refine, ClipValue, Clipper, Polyhedron, Projected, Projector};
use crate::tf::TransferFunction;
use crate::visibility::bsp::Fragment;
use crate::visibility::slabs::{bands as slab_bands, inner_levels, slab_order};
use crate::visibility::{Piece, Sorter, SplitPolicy, NO_LEVEL};

use super::group::composite_group;
use super::scene::{ScalarsRef, Scene};
use super::{Compositor, RenderError, RenderOptions};

/// Pieces processed per chunk (one worker's unit of work).
const CHUNK: usize = 2048;

/// Chunks a worker may run ahead of the GPU hand-over, per worker: bounds
/// the memory in flight (about 0.4 MB per chunk on a fine mesh) while
/// keeping every worker busy when chunk costs vary.
const AHEAD_PER_WORKER: usize = 4;

/// What the exact mode did, with times in seconds.
#[derive(Clone, Debug, Default)]
pub struct ExactStats {
    pub pieces: usize,
    pub culled_pieces: usize,
    pub slabs: usize,
    pub triangles: usize,
    pub refined_triangles: usize,
    /// Pixels of the per-pixel layers of cycle groups ([`composite_group`]).
    pub group_pixels: usize,
    pub sort_s: f64,
    /// Time spent opening (or waiting for) the GPU context.
    pub gpu_open_s: f64,
    /// Projection, integrals and the draw calls, which overlap (workers
    /// project later chunks while this thread uploads and draws finished
    /// ones, [`pipeline`]).
    pub project_s: f64,
    pub gpu: FrameStats,
    /// What the GPU had left after the last draw call: finishing and
    /// reading the image back.
    pub gpu_total_s: f64,
    pub order: crate::visibility::OrderStats,
    /// CPU twin with [`super::RenderOptions::watch`]: the fragments drawn
    /// at the watched pixel, in drawing order.
    pub watched: Vec<crate::gpu::cpu::Fragment>,
}

/// Where a frame's triangles go: the GPU, or its CPU twin.
enum Sink<'c> {
    Gpu(Box<Frame<'c>>),
    Cpu(Box<CpuFrame>),
}

impl Sink<'_> {
    fn push_triangles(
        &mut self,
        vertices: &[ExactVertex],
        indices: &[u32],
    ) -> Result<(), GpuError> {
        match self {
            Sink::Gpu(f) => f.push_triangles(vertices, indices),
            Sink::Cpu(f) => f.push_triangles(vertices, indices),
        }
    }
}

/// The smallest and largest of `values` (`(inf, -inf)` when empty).
pub(super) fn value_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// Output of one chunk: vertices and triangles ready for the GPU.
#[derive(Default)]
pub(super) struct ChunkOut {
    pub(super) vertices: Vec<ExactVertex>,
    pub(super) indices: Vec<u32>,
    pub(super) culled: usize,
    /// Pieces drawn, numbered from 0 in this chunk; [`push_out`] makes the
    /// numbers frame-wide (the shader colours a pixel once per piece).
    pub(super) pieces: u32,
    slabs: usize,
    refined: usize,
    /// Triangles dropped as degenerate on the sub-pixel grid
    /// ([`grid_area_positive`]).
    degenerate: usize,
    pub(super) error: Option<String>,
    /// Scratch of [`push_projected`]: vertices used by a triangle.
    scratch_used: Vec<bool>,
}

impl ChunkOut {
    /// Empties everything, keeping the buffers.
    fn clear(&mut self) {
        self.vertices.clear();
        self.indices.clear();
        self.culled = 0;
        self.pieces = 0;
        self.slabs = 0;
        self.refined = 0;
        self.degenerate = 0;
        self.error = None;
    }
}

pub(super) struct Ctx<'a> {
    mesh: &'a Mesh,
    scalars: ScalarsRef<'a>,
    pub(super) tf: &'a TransferFunction,
    pub(super) camera: &'a Camera,
    breakpoints: &'a [f64],
    /// The order's slab bounds ([`crate::visibility::Order::levels`]).
    levels: &'a [f64],
    /// The order's fragments ([`crate::visibility::Order::fragments`]).
    fragments: &'a [Fragment],
    /// The frame's length unit ([`FrameOptions::length_unit`]).
    pub(super) length_unit: f64,
    /// Leave out triangles that colour no pixel centre of `grid`
    /// ([`crate::projection::coverage`]).
    cull: bool,
    grid: PixelGrid,
}

impl Ctx<'_> {
    #[inline]
    fn scalar(&self, cell: u32, point: u32) -> f64 {
        match self.scalars {
            ScalarsRef::Point(v) => v.get(point as usize).copied().unwrap_or(0.0),
            ScalarsRef::Cell(v) => v.get(cell as usize).copied().unwrap_or(0.0),
            ScalarsRef::Constant(c) => c,
        }
    }

    /// The view-space polyhedron of a piece (whole, not sliced).
    pub(super) fn piece_polyhedron(
        &self,
        piece: &Piece,
        poly: &mut Polyhedron,
    ) -> Result<(), String> {
        let cell = piece.cell();
        match *piece {
            Piece::Cell(c) => poly
                .set_cell(
                    &self.mesh.cells,
                    c as usize,
                    &self.mesh.points,
                    |n| self.scalar(c, n),
                    self.camera,
                )
                .map_err(|e| format!("cell {c}: {e}")),
            Piece::Tet { tet, .. } => {
                let (p, s) = self.tet_view(cell, tet);
                poly.set_tet(p, s);
                Ok(())
            }
            Piece::Slab { tet, lo, hi, .. } => {
                let mut whole = Polyhedron::default();
                let mut clipper = Clipper::default();
                if !self.slab(cell, tet, lo, hi, &mut clipper, &mut whole, poly)? {
                    poly.clear();
                }
                Ok(())
            }
            Piece::Frag { tet, frag, .. } => self.fragment(cell, tet, frag, poly),
        }
    }

    /// Clips tet `tet` of `cell` to the band of a slab ([`Piece::Slab`]),
    /// through `whole` (scratch), into `poly`; `Ok(false)` when nothing of
    /// positive volume is left.
    #[allow(clippy::too_many_arguments)]
    fn slab(
        &self,
        cell: u32,
        tet: [u32; 4],
        lo: u32,
        hi: u32,
        clipper: &mut Clipper,
        whole: &mut Polyhedron,
        poly: &mut Polyhedron,
    ) -> Result<bool, String> {
        let (p, s) = self.tet_view(cell, tet);
        whole.set_tet(p, s);
        self.clip_band(cell, lo, hi, clipper, whole, poly)
    }

    /// Clips `whole` (the view-space tet of `cell`) to band `lo..hi` of
    /// the order's levels.
    fn clip_band(
        &self,
        cell: u32,
        lo: u32,
        hi: u32,
        clipper: &mut Clipper,
        whole: &Polyhedron,
        poly: &mut Polyhedron,
    ) -> Result<bool, String> {
        let (lo, hi) = self.band(lo, hi);
        clipper
            .clip(whole, ClipValue::Scalar, lo, hi, poly)
            .map_err(|e| format!("cell {cell}: {e}"))
    }

    /// The view-space polyhedron of fragment `frag` of a tet.
    fn fragment(
        &self,
        cell: u32,
        tet: [u32; 4],
        frag: u32,
        poly: &mut Polyhedron,
    ) -> Result<(), String> {
        let f = self
            .fragments
            .get(frag as usize)
            .ok_or_else(|| format!("cell {cell}: no fragment {frag}"))?;
        let (p, s) = self.tet_view(cell, tet);
        poly.clear();
        poly.points = f.positions(&p);
        poly.scalars = f.values(&s);
        poly.triangles.extend_from_slice(&f.triangles);
        poly.orient_outward();
        Ok(())
    }

    /// View-space corners and scalars of a tet of cell `cell`.
    fn tet_view(&self, cell: u32, tet: [u32; 4]) -> ([DVec3; 4], [f64; 4]) {
        let pts = &self.mesh.points;
        (
            tet.map(|n| self.camera.to_view(pts[n as usize])),
            tet.map(|n| self.scalar(cell, n)),
        )
    }

    /// The scalar bounds of a slab ([`Piece::Slab`]).
    fn band(&self, lo: u32, hi: u32) -> (f64, f64) {
        let level = |k: u32, open: f64| {
            if k == NO_LEVEL {
                open
            } else {
                self.levels.get(k as usize).copied().unwrap_or(open)
            }
        };
        (level(lo, f64::NEG_INFINITY), level(hi, f64::INFINITY))
    }

    /// Whether extinction is zero over the whole scalar interval.
    pub(super) fn invisible(&self, lo: f64, hi: f64) -> bool {
        if !(lo.is_finite() && hi.is_finite()) {
            return false;
        }
        if self.tf.tau_at(lo) > 0.0 || self.tf.tau_at(hi) > 0.0 {
            return false;
        }
        for &b in self.breakpoints {
            if b >= lo && b <= hi {
                let left = self.tf.tau_at(b - b.abs().max(1e-300) * 1e-15);
                if self.tf.tau_at(b) > 0.0 || left > 0.0 {
                    return false;
                }
            }
        }
        true
    }
}

/// Projects `piece` and appends what it draws to `out`.
fn draw(
    ctx: &Ctx,
    projector: &mut Projector,
    piece: &Polyhedron,
    proj: &mut Projected,
    vals: &mut Vec<VertexValues>,
    out: &mut ChunkOut,
) -> Result<(), crate::projection::ProjectionError> {
    projector.project(piece, ctx.camera, proj)?;
    push_projected(ctx, proj, depth_balance(ctx, piece), vals, out);
    Ok(())
}

/// Vertex integrals of the triangles of `proj` (`k`: [`depth_balance`]),
/// refined for colour where needed, appended to `out`.
fn push_projected(
    ctx: &Ctx,
    proj: &mut Projected,
    k: f64,
    vals: &mut Vec<VertexValues>,
    out: &mut ChunkOut,
) {
    if proj.triangles.is_empty() {
        return;
    }
    let tf = ctx.tf;
    // Values only where a triangle uses the vertex (coverage culling leaves
    // vertices of dropped triangles behind); `used` keeps the flags.
    let used = &mut out.scratch_used;
    used.clear();
    used.resize(proj.vertices.len(), false);
    for t in &proj.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    vals.clear();
    vals.extend(proj.vertices.iter().zip(used.iter()).map(|(v, &u)| {
        if u {
            vertex_values(tf, v.l, v.s_front, v.s_back)
        } else {
            VertexValues::default()
        }
    }));
    // Refine only pieces whose optical depth and glow spread could make the
    // interpolated C/alpha err (the common thin or uniform piece skips it).
    let depth = vals.iter().map(|v| v.depth).fold(0.0, f64::max).min(1.0);
    let spread = (0..3)
        .map(|k| {
            let (lo, hi) = value_range(
                vals.iter()
                    .zip(used.iter())
                    .filter(|(_, &u)| u)
                    .map(|(v, _)| v.glow[k]),
            );
            hi - lo
        })
        .fold(0.0, f64::max);
    if depth * spread > COLOR_REFINE_TOL {
        let before = proj.triangles.len();
        refine(proj, COLOR_REFINE_MAX_DEPTH, |a, b| {
            let va = vertex_values(tf, a.l, a.s_front, a.s_back);
            let vb = vertex_values(tf, b.l, b.s_front, b.s_back);
            let depth = va.depth.max(vb.depth).min(1.0);
            let spread = (0..3)
                .map(|k| (va.glow[k] - vb.glow[k]).abs())
                .fold(0.0, f64::max);
            depth * spread > COLOR_REFINE_TOL
        });
        if ctx.cull {
            proj.cull_to_pixels(&ctx.grid);
        }
        out.refined += proj.triangles.len().saturating_sub(before);
        let n = vals.len();
        used.resize(proj.vertices.len(), true);
        vals.extend(
            proj.vertices[n..]
                .iter()
                .map(|v| vertex_values(tf, v.l, v.s_front, v.s_back)),
        );
    }
    let mapper = ClipMapper::for_camera(ctx.camera);
    let piece = out.pieces;
    out.pieces += 1;
    // Each triangle gets its own three vertices: snapping moves its corners
    // (by up to 1/512 px), and the attributes at the snapped corners are
    // those of the exact triangle's affine interpolation there
    // ([`snapped_attributes`]), so that a covered centre gets the value the
    // exact triangle gives it. Shared corners with the exact corners'
    // values would shift the attributes with the corners: an error of
    // the thickness gradient times the shift, up to 0.1 where a face is
    // seen nearly edge-on.
    let snap = |v: &crate::projection::RegionVertex| mapper.ndc(v.px, v.py);
    for t in &proj.triangles {
        let v = t.map(|i| &proj.vertices[i as usize]);
        // Region positions are finite and on screen or clipped near it
        // (`clip_to_image`); one that is not cannot be drawn exactly.
        let (Some(s0), Some(s1), Some(s2)) = (snap(v[0]), snap(v[1]), snap(v[2])) else {
            out.degenerate += 1;
            continue;
        };
        let sn = [s0, s1, s2];
        if !grid_area_positive(sn[0].1, sn[1].1, sn[2].1) {
            out.degenerate += 1;
            continue;
        }
        let attrs = t.map(|i| {
            let (v, vv) = (&proj.vertices[i as usize], &vals[i as usize]);
            [v.l * k, vv.tau_mean / k, vv.glow[0], vv.glow[1], vv.glow[2]]
        });
        let at = snapped_attributes(
            v.map(|v| [v.px, v.py]),
            sn.map(|s| s.1.map(|g| g as f64 / crate::gpu::SUBPIXEL)),
            attrs,
        );
        let first = out.vertices.len() as u32;
        for c in 0..3 {
            let [x, y] = sn[c].0;
            let a = at[c];
            out.vertices.push(
                ExactVertex::new(
                    [x, y, 0.5, 1.0],
                    a[0] as f32,
                    a[1] as f32,
                    [a[2] as f32, a[3] as f32, a[4] as f32],
                )
                .with_piece(piece),
            );
        }
        out.indices
            .extend_from_slice(&[first, first + 1, first + 2]);
    }
}

/// The attributes at the snapped corners `q` of the affine interpolation
/// of `attrs` over the exact triangle `p` (pixel coordinates): drawn at
/// `q`, the triangle gives every point the value the exact triangle's
/// interpolation has there. A triangle of zero exact area keeps its corner
/// values.
fn snapped_attributes(p: [[f64; 2]; 3], q: [[f64; 2]; 3], attrs: [[f64; 5]; 3]) -> [[f64; 5]; 3] {
    let (e1, e2) = (
        [p[1][0] - p[0][0], p[1][1] - p[0][1]],
        [p[2][0] - p[0][0], p[2][1] - p[0][1]],
    );
    let det = e1[0] * e2[1] - e1[1] * e2[0];
    if det == 0.0 || !det.is_finite() {
        return attrs;
    }
    q.map(|q| {
        let d = [q[0] - p[0][0], q[1] - p[0][1]];
        let b1 = (d[0] * e2[1] - d[1] * e2[0]) / det;
        let b2 = (e1[0] * d[1] - e1[1] * d[0]) / det;
        let b0 = 1.0 - b1 - b2;
        [0, 1, 2, 3, 4].map(|k| b0 * attrs[0][k] + b1 * attrs[1][k] + b2 * attrs[2][k])
    })
}

/// Per-piece scale `k` sending `l k` and `tau / k` to the shader (their
/// product, the optical depth, is unchanged): it brings the piece's
/// diameter (a bound on `l`) and the largest extinction of the TF over its
/// scalar range to the same size, so neither table axis clamps. It depends
/// on the piece alone, not on which regions and triangles coverage culling
/// keeps, so culling changes no pixel.
fn depth_balance(ctx: &Ctx, piece: &Polyhedron) -> f64 {
    let (s_lo, s_hi) = value_range(piece.scalars.iter().copied());
    let (lo, hi) = piece.points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let l_max = (hi - lo).length();
    let tf = ctx.tf;
    let mut tau_max = tf.tau_at(s_lo).max(tf.tau_at(s_hi));
    for &b in ctx.breakpoints {
        if b > s_lo && b < s_hi {
            tau_max = tau_max.max(tf.tau_at(b));
        }
    }
    let (l_max, tau_max) = (l_max / ctx.length_unit, tau_max * ctx.length_unit);
    let k = (tau_max / l_max).sqrt();
    if l_max > 0.0 && tau_max > 0.0 && k.is_finite() && k > 0.0 {
        k
    } else {
        1.0
    }
}

/// Whether the GPU sees the triangle `a, b, c` (region triangles are CCW in
/// pixel coordinates, see [`crate::projection`]) with positive area: the
/// exact orientation of its corners on the rasteriser's sub-pixel grid
/// (which the GPU receives exactly, [`ClipMapper::ndc`]).
///
/// The projection keeps every triangle whose f64 pixel positions have a
/// positive exact orientation; a sliver region (e.g. next to a face seen
/// exactly edge-on) can become collinear or inverted once its corners are
/// snapped. A triangle of zero area covers nothing (and Mesa's rasteriser
/// gives NaN colour on pixel centres along such a triangle), so dropping it
/// loses nothing. An inverted one overlaps its neighbours, which cover
/// every centre it holds already: the snapped triangles still wind once
/// around every point of the snapped silhouette, so the positive ones
/// alone cover each centre at least once, and the depth test
/// (`shaders/exact.wgsl`) makes it exactly once.
fn grid_area_positive(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> bool {
    // Integer coordinates below 2^40: the cross product is exact in i128.
    let [a, b, c] = [a, b, c].map(|p| [p[0] as i128, p[1] as i128]);
    // Pixel y points down, as in the region triangles.
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0
}

/// Projects `pieces` into `out` (empty, its buffers possibly reused).
fn process_chunk(ctx: &Ctx, pieces: &[Piece], mut out: ChunkOut) -> ChunkOut {
    let mut projector = Projector::new();
    // Pieces cut by the near plane reach ~1e9 pixels off screen: clip their
    // regions to the image so that screen-space interpolation stays exact
    // up to the perspective refinement's bound.
    projector.clip_to_image = true;
    projector.cull_to_pixels = ctx.cull;
    let mut poly = Polyhedron::default();
    let mut whole = Polyhedron::default();
    // The (cell, tet) `whole` holds for slab pieces (fragments reuse
    // `whole` and reset this).
    let mut whole_of: Option<(u32, [u32; 4])> = None;
    let mut clipper = Clipper::default();
    let mut proj = Projected::default();
    let mut vals = Vec::new();
    let pts = &ctx.mesh.points;
    for piece in pieces {
        let cell = piece.cell();
        match *piece {
            Piece::Cell(c) => {
                let nodes = ctx.mesh.cells.nodes(c as usize);
                let (lo, hi) = value_range(nodes.iter().map(|&n| ctx.scalar(c, n)));
                if ctx.invisible(lo, hi) {
                    out.culled += 1;
                    continue;
                }
                if let Err(e) = poly.set_cell(
                    &ctx.mesh.cells,
                    c as usize,
                    pts,
                    |n| ctx.scalar(c, n),
                    ctx.camera,
                ) {
                    out.error = Some(format!("cell {c}: {e}"));
                    return out;
                }
                if let Err(e) = draw(ctx, &mut projector, &poly, &mut proj, &mut vals, &mut out) {
                    out.error = Some(format!("cell {c}: {e}"));
                    return out;
                }
            }
            Piece::Tet { tet, .. } => {
                let (p, s) = ctx.tet_view(cell, tet);
                let (lo, hi) = value_range(s);
                if ctx.invisible(lo, hi) {
                    out.culled += 1;
                    continue;
                }
                // A tet holding a breakpoint comes as its slabs
                // (`Piece::Slab`): the TF is linear on this one.
                poly.set_tet(p, s);
                if let Err(e) = draw(ctx, &mut projector, &poly, &mut proj, &mut vals, &mut out) {
                    out.error = Some(format!("cell {cell}: {e}"));
                    return out;
                }
            }
            Piece::Frag { tet, frag, .. } => {
                whole_of = None;
                if let Err(e) = ctx.fragment(cell, tet, frag, &mut whole) {
                    out.error = Some(e);
                    return out;
                }
                let (lo, hi) = value_range(whole.scalars.iter().copied());
                if ctx.invisible(lo, hi) {
                    out.culled += 1;
                    continue;
                }
                // Breakpoints inside: the fragment's bands, back to front
                // along the tet's gradient.
                let bands = slab_bands(&ctx.levels[inner_levels(&whole.scalars, ctx.levels)]);
                let (p, s) = ctx.tet_view(cell, tet);
                for i in slab_order(&p, &s, &bands, ctx.camera.ortho) {
                    let (blo, bhi) = bands[i];
                    let piece = if bands.len() == 1 {
                        &whole
                    } else {
                        match clipper.clip(&whole, ClipValue::Scalar, blo, bhi, &mut poly) {
                            Ok(true) => &poly,
                            Ok(false) => continue,
                            Err(e) => {
                                out.error = Some(format!("cell {cell}: {e}"));
                                return out;
                            }
                        }
                    };
                    if let Err(e) = draw(ctx, &mut projector, piece, &mut proj, &mut vals, &mut out)
                    {
                        out.error = Some(format!("cell {cell}: {e}"));
                        return out;
                    }
                }
            }
            Piece::Slab { tet, lo, hi, .. } => {
                let (blo, bhi) = ctx.band(lo, hi);
                let (smin, smax) = value_range(tet.map(|n| ctx.scalar(cell, n)));
                if ctx.invisible(smin.max(blo), smax.min(bhi)) {
                    out.culled += 1;
                    continue;
                }
                // The slabs of a tet come one after another: its view-space
                // piece is built once for them all.
                if whole_of != Some((cell, tet)) {
                    let (p, s) = ctx.tet_view(cell, tet);
                    whole.set_tet(p, s);
                    whole_of = Some((cell, tet));
                }
                match ctx.clip_band(cell, lo, hi, &mut clipper, &whole, &mut poly) {
                    Ok(true) => {}
                    Ok(false) => continue,
                    Err(e) => {
                        out.error = Some(e);
                        return out;
                    }
                }
                out.slabs += 1;
                if let Err(e) = draw(ctx, &mut projector, &poly, &mut proj, &mut vals, &mut out) {
                    out.error = Some(format!("cell {cell}: {e}"));
                    return out;
                }
            }
        }
    }
    out
}

/// The scalar values at which pieces must be split for the per-pixel opacity
/// to be exact: every breakpoint of the extinction (a kink or a jump) and
/// every jump of the colour. Colour kinks alone are not split: vertex values
/// stay exact there and the interpolated `C/alpha` is bounded by the colour
/// refinement ([`COLOR_REFINE_TOL`]).
pub fn split_points(tf: &TransferFunction) -> Vec<f64> {
    let nodes = tf.nodes();
    let mut out: Vec<f64> = Vec::new();
    let slope = |a: &crate::tf::Node, b: &crate::tf::Node| -> Option<f64> {
        let ds = b.s - a.s;
        (ds > 0.0).then(|| (b.tau - a.tau) / ds)
    };
    for i in 0..nodes.len() {
        let n = &nodes[i];
        if i + 1 < nodes.len() && nodes[i + 1].s == n.s {
            // A jump: two nodes at one scalar.
            let m = &nodes[i + 1];
            let colour_jump =
                (0..3).any(|k| n.color[k] != m.color[k] || n.emission[k] != m.emission[k]);
            if n.tau != m.tau || colour_jump {
                out.push(n.s);
            }
            continue;
        }
        if i == 0 || i + 1 >= nodes.len() || nodes[i - 1].s == n.s {
            // Ends of the node range, or the right node of a jump (handled).
            if i > 0 && i + 1 < nodes.len() && nodes[i - 1].s == n.s {
                continue;
            }
            // The TF is constant outside the node range: a kink at each end
            // when the extinction slopes inside.
            let inner = if i == 0 {
                nodes.get(1)
            } else {
                nodes.get(i.wrapping_sub(1))
            };
            if let Some(m) = inner {
                if m.tau != n.tau {
                    out.push(n.s);
                }
            }
            continue;
        }
        let (l, r) = (slope(&nodes[i - 1], n), slope(n, &nodes[i + 1]));
        let kink = match (l, r) {
            (Some(l), Some(r)) => (l - r).abs() > TF_SLOPE_REL * l.abs().max(r.abs()),
            _ => true,
        };
        if kink {
            out.push(n.s);
        }
    }
    out.dedup();
    out
}

/// Sends one chunk's triangles to the frame and adds up its counts; its
/// pieces are numbered on from `next_piece` (drawing order).
fn push_out(
    frame: &mut Sink,
    out: &mut ChunkOut,
    stats: &mut ExactStats,
    next_piece: &mut u32,
) -> Result<(), RenderError> {
    if let Some(e) = &out.error {
        return Err(RenderError::Projection(e.clone()));
    }
    let base = *next_piece;
    *next_piece = base
        .checked_add(out.pieces)
        .filter(|&n| n <= MAX_PIECES)
        .ok_or(RenderError::TooManyPieces(MAX_PIECES))?;
    if base > 0 {
        for v in &mut out.vertices {
            v.piece += base;
        }
    }
    stats.culled_pieces += out.culled;
    stats.slabs += out.slabs;
    stats.refined_triangles += out.refined;
    stats.triangles += out.indices.len() / 3;
    frame.push_triangles(&out.vertices, &out.indices)?;
    Ok(())
}

/// Chunk buffers of drawn chunks, reused: fresh multi-megabyte vectors
/// would be new pages for the kernel to fault in and zero, chunk after
/// chunk.
#[derive(Default)]
struct BufferPool(Mutex<Vec<ChunkOut>>);

impl BufferPool {
    fn take(&self) -> ChunkOut {
        self.0
            .lock()
            .ok()
            .and_then(|mut p| p.pop())
            .unwrap_or_default()
    }

    fn put(&self, mut out: ChunkOut) {
        out.clear();
        if let Ok(mut p) = self.0.lock() {
            p.push(out);
        }
    }
}

/// Shared state of [`pipeline`].
struct Flow {
    /// Next chunk a worker takes.
    next: usize,
    /// Chunks handed to the sink so far.
    handed: usize,
    /// Finished chunks waiting for the hand-over (`slots[i % len]`).
    slots: Vec<Option<ChunkOut>>,
    /// Set when the sink failed or a worker panicked: everyone stops.
    stop: bool,
    panic: Option<Box<dyn std::any::Any + Send>>,
}

/// Projects `pieces` in chunks of `chunk` pieces ([`CHUNK`]) on `workers`
/// threads and hands each chunk's output to `sink` on this thread, in
/// order, as soon as it and all before it are done. Workers take chunks in order and run at most
/// [`AHEAD_PER_WORKER`] per worker ahead of the hand-over, so memory stays
/// bounded; there is no barrier between groups of chunks, so no worker
/// waits for another's slow chunk. The first error of `sink` stops the
/// workers and is returned; a worker's panic is resumed here.
fn pipeline(
    ctx: &Ctx,
    pieces: &[Piece],
    chunk: usize,
    workers: usize,
    pool: &BufferPool,
    mut sink: impl FnMut(ChunkOut) -> Result<(), RenderError>,
) -> Result<(), RenderError> {
    let chunks: Vec<&[Piece]> = pieces.chunks(chunk.max(1)).collect();
    if chunks.is_empty() {
        return Ok(());
    }
    let ahead = workers * AHEAD_PER_WORKER;
    let flow = Mutex::new(Flow {
        next: 0,
        handed: 0,
        slots: (0..ahead).map(|_| None).collect(),
        stop: false,
        panic: None,
    });
    let changed = Condvar::new();
    let lock = || flow.lock().unwrap_or_else(|e| e.into_inner());
    let result = std::thread::scope(|s| {
        for _ in 0..workers.min(chunks.len()) {
            s.spawn(|| loop {
                let i = {
                    let mut f = lock();
                    while !f.stop && f.next < chunks.len() && f.next >= f.handed + ahead {
                        f = changed.wait(f).unwrap_or_else(|e| e.into_inner());
                    }
                    if f.stop || f.next >= chunks.len() {
                        return;
                    }
                    f.next += 1;
                    f.next - 1
                };
                let done = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    process_chunk(ctx, chunks[i], pool.take())
                }));
                let mut f = lock();
                match done {
                    Ok(out) => f.slots[i % ahead] = Some(out),
                    Err(p) => {
                        f.stop = true;
                        f.panic.get_or_insert(p);
                    }
                }
                drop(f);
                changed.notify_all();
            });
        }
        for i in 0..chunks.len() {
            let out = {
                let mut f = lock();
                loop {
                    if f.stop {
                        return Ok(());
                    }
                    if let Some(out) = f.slots[i % ahead].take() {
                        break out;
                    }
                    f = changed.wait(f).unwrap_or_else(|e| e.into_inner());
                }
            };
            let r = sink(out);
            let mut f = lock();
            f.handed += 1;
            if r.is_err() {
                f.stop = true;
            }
            drop(f);
            changed.notify_all();
            r?;
        }
        Ok(())
    });
    let panic = lock().panic.take();
    if let Some(p) = panic {
        std::panic::resume_unwind(p);
    }
    result
}

/// Renders the scene in the exact mode. The GPU context is `gpu`, or, when
/// that is empty, `pending` (a context opening on another thread, waited
/// for after the sort, which it overlaps) or a new one opened with
/// `gpu_opts`; it is left in `gpu`.
#[allow(clippy::too_many_arguments)]
pub fn render_exact(
    scene: &Scene,
    sorter: &mut Sorter,
    gpu: &mut Option<Context>,
    pending: &mut Option<PendingContext>,
    opts: &RenderOptions,
    camera: &Camera,
    mut progress: impl FnMut(usize, usize),
) -> Result<(Image, ExactStats), RenderError> {
    let mut stats = ExactStats::default();
    let breakpoints = split_points(&scene.tf);
    let point_scalars = match scene.scalars() {
        ScalarsRef::Point(v) => Some(v),
        _ => None,
    };
    let t0 = Instant::now();
    let policy = SplitPolicy {
        all: opts.split_all,
        breakpoints: &breakpoints,
        point_scalars,
    };
    let order = sorter.order(camera, &policy)?;
    stats.sort_s = t0.elapsed().as_secs_f64();
    stats.pieces = order.pieces.len();
    stats.order = order.stats.clone();

    let ctx = Ctx {
        mesh: &scene.mesh,
        scalars: scene.scalars(),
        tf: &scene.tf,
        camera,
        breakpoints: &breakpoints,
        levels: &order.levels,
        fragments: &order.fragments,
        length_unit: scene.unit_distance as f32 as f64,
        cull: opts.cull_to_pixels,
        grid: PixelGrid::new(camera.width, camera.height),
    };
    let t_open = Instant::now();
    let mut fopts = FrameOptions::new(camera.width, camera.height, opts.accum);
    fopts.length_unit = scene.unit_distance as f32;
    fopts.draw = opts.draw;
    let mut frame = match opts.compositor {
        Compositor::Gpu => {
            if gpu.is_none() {
                *gpu = Some(match pending.take() {
                    Some(p) if p.options() == &opts.gpu => p.wait()?,
                    _ => Context::new(&opts.gpu)?,
                });
            }
            let Some(gpu) = gpu.as_ref() else {
                unreachable!("opened above")
            };
            Sink::Gpu(Box::new(gpu.begin_frame_with(&fopts)?))
        }
        Compositor::Cpu => {
            let mut f = CpuFrame::new(
                camera.width,
                camera.height,
                opts.accum,
                opts.draw,
                fopts.length_unit,
            )?;
            if let Some((i, j)) = opts.watch {
                f.watch(i, j);
            }
            Sink::Cpu(Box::new(f))
        }
    };
    stats.gpu_open_s = t_open.elapsed().as_secs_f64();
    let t_gpu = Instant::now();
    let total = order.pieces.len();
    let mut done = 0;
    // Stretches of ordinary pieces, each followed by at most one group.
    let mut stretches: Vec<(std::ops::Range<usize>, Option<std::ops::Range<usize>>)> = Vec::new();
    let mut start = 0;
    for g in &order.groups {
        stretches.push((start..g.start, Some(g.clone())));
        start = g.end;
    }
    stretches.push((start..total, None));
    let tp = Instant::now();
    let pool = BufferPool::default();
    let workers = rayon::current_num_threads().max(1);
    let mut next_piece = 0u32;
    for (plain, group) in stretches {
        let pieces = &order.pieces[plain];
        let mut handed = 0;
        pipeline(&ctx, pieces, CHUNK, workers, &pool, |mut out| {
            push_out(&mut frame, &mut out, &mut stats, &mut next_piece)?;
            pool.put(out);
            handed += CHUNK;
            progress(done + handed.min(pieces.len()), total);
            Ok(())
        })?;
        done += pieces.len();
        if let Some(g) = group {
            let mut out = ChunkOut::default();
            stats.group_pixels += composite_group(&ctx, &order.pieces[g.clone()], &mut out);
            push_out(&mut frame, &mut out, &mut stats, &mut next_piece)?;
            done += g.len();
            progress(done, total);
        }
    }
    let project_s = tp.elapsed().as_secs_f64();
    let (image, fstats) = match frame {
        Sink::Gpu(f) => f.finish_with_stats()?,
        Sink::Cpu(f) => {
            stats.watched = f.covering().to_vec();
            let fs = FrameStats {
                triangles: f.triangles(),
                ..Default::default()
            };
            (f.finish(), fs)
        }
    };
    stats.gpu = fstats;
    stats.project_s = project_s;
    stats.gpu_total_s = t_gpu.elapsed().as_secs_f64() - project_s;
    Ok((image, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraParams;
    use crate::generate::{warped_hex_grid, Warp};
    use crate::render::SceneSpec;
    use crate::tf::EmissionModel;
    use crate::visibility::Order;

    /// The context of `order` for `scene` seen by `camera`.
    fn test_ctx<'a>(
        scene: &'a Scene,
        camera: &'a Camera,
        breakpoints: &'a [f64],
        order: &'a Order,
        cull: bool,
    ) -> Ctx<'a> {
        Ctx {
            mesh: &scene.mesh,
            scalars: scene.scalars(),
            tf: &scene.tf,
            camera,
            breakpoints,
            levels: &order.levels,
            fragments: &order.fragments,
            length_unit: scene.unit_distance,
            cull,
            grid: PixelGrid::new(camera.width, camera.height),
        }
    }

    /// An unwarped grid seen in perspective straight down an axis, every
    /// cell split into tets: the diagonal faces of the tets in the planes
    /// through the eye are seen exactly edge-on, and rounding the pixel
    /// positions leaves sliver regions that are collinear in f32 (Mesa gave
    /// NaN pixels on them, tests/stress_scenes.rs `edge_on_...`). None may
    /// reach the GPU.
    #[test]
    fn no_triangle_degenerate_in_f32_reaches_the_gpu() {
        let mesh = warped_hex_grid(
            2,
            &Warp {
                amplitude: 0.0,
                seed: 7,
            },
        );
        let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        scene.tf = TransferFunction::from_channels(
            &[(0.0, [0.0]), (0.5, [6.0]), (1.0, [10.0])],
            &[(0.0, [0.1, 0.2, 0.9]), (1.0, [1.0, 0.5, 0.1])],
            None,
            EmissionModel::Glow,
        )
        .unwrap();
        let params = CameraParams {
            width: 96,
            height: 96,
            azimuth: 0.0,
            elevation: 0.0,
            ortho: false,
            ..Default::default()
        };
        let camera = Camera::fit(scene.mesh.bounds(), &params);
        let breakpoints = split_points(&scene.tf);
        let point_scalars = match scene.scalars() {
            ScalarsRef::Point(v) => Some(v),
            _ => None,
        };
        let policy = SplitPolicy {
            all: true,
            breakpoints: &breakpoints,
            point_scalars,
        };
        let mut sorter = Sorter::new(&scene.mesh, &scene.topology);
        let order = sorter.order(&camera, &policy).unwrap();
        let ctx = test_ctx(&scene, &camera, &breakpoints, &order, false);
        // Piece by piece, up to the first one that makes such a sliver (the
        // whole view refines into ~1e5 triangles).
        let mut degenerate = 0;
        for piece in &order.pieces {
            let out = process_chunk(&ctx, std::slice::from_ref(piece), ChunkOut::default());
            assert_eq!(out.error, None);
            let mapper = ClipMapper::for_camera(&camera);
            let half = mapper.side as f32 * 0.5;
            for t in out.indices.chunks(3) {
                // The grid positions the rasteriser recovers from the NDC.
                let [a, b, c] = [0, 1, 2].map(|k| {
                    let p = out.vertices[t[k] as usize].pos;
                    let (x, y) = (p[0] * half + half, -p[1] * half + half);
                    [x, y].map(|v| ClipMapper::snap(v as f64).unwrap())
                });
                assert!(grid_area_positive(a, b, c), "{piece:?}: {a:?} {b:?} {c:?}");
            }
            degenerate += out.degenerate;
            if degenerate > 0 {
                break;
            }
        }
        // The view still makes the case this guards against.
        assert!(degenerate > 0, "no f32-degenerate sliver in this view");
    }

    /// The pipeline hands every chunk over in order, exactly as projecting
    /// the chunks one after another gives them, with whatever number of
    /// workers; an error of the hand-over stops it and is returned.
    #[test]
    fn pipeline_hands_chunks_over_in_order_and_stops_on_error() {
        let mesh = warped_hex_grid(
            12,
            &Warp {
                amplitude: 0.2,
                seed: 3,
            },
        );
        let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let camera = Camera::fit(
            scene.mesh.bounds(),
            &CameraParams {
                width: 64,
                height: 64,
                azimuth: 30.0,
                elevation: 20.0,
                ..Default::default()
            },
        );
        let breakpoints = split_points(&scene.tf);
        let policy = SplitPolicy {
            all: true,
            breakpoints: &breakpoints,
            point_scalars: None,
        };
        let mut sorter = Sorter::new(&scene.mesh, &scene.topology);
        let order = sorter.order(&camera, &policy).unwrap();
        let ctx = test_ctx(&scene, &camera, &breakpoints, &order, true);
        let chunk = 64;
        let chunks = order.pieces.chunks(chunk).count();
        assert!(chunks > 4 * 3 * AHEAD_PER_WORKER, "{chunks} chunks");
        let serial: Vec<(Vec<ExactVertex>, Vec<u32>)> = order
            .pieces
            .chunks(chunk)
            .map(|c| {
                let out = process_chunk(&ctx, c, ChunkOut::default());
                (out.vertices, out.indices)
            })
            .collect();
        assert!(serial.iter().filter(|c| !c.1.is_empty()).count() > chunks / 2);
        let pool = BufferPool::default();
        for workers in [1, 2, 3] {
            let mut got = Vec::new();
            pipeline(&ctx, &order.pieces, chunk, workers, &pool, |out| {
                got.push((out.vertices.clone(), out.indices.clone()));
                pool.put(out);
                Ok(())
            })
            .unwrap();
            assert!(got == serial, "{workers} workers");
            let mut calls = 0;
            let r = pipeline(&ctx, &order.pieces, chunk, workers, &pool, |_| {
                calls += 1;
                if calls == 3 {
                    Err(RenderError::Projection("stop".into()))
                } else {
                    Ok(())
                }
            });
            assert!(matches!(r, Err(RenderError::Projection(_))));
            assert_eq!(calls, 3);
        }
    }
}
