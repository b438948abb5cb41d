//! The projected-cell driver, shared by every mode that draws convex pieces
//! as screen triangles: visibility order -> pieces -> projection -> the
//! mode's per-vertex payload -> GPU batches (or the CPU twin).
//!
//! Per view:
//! 1. [`Sorter::order`] gives the drawable pieces back to front, sliced as
//!    the mode asks ([`ProjectedMode::split_points`]: a cell whose nodal
//!    scalar range holds one of those values comes as its consistent tets,
//!    a tet holding one as its slabs; every cell's tets with `--split all`).
//!    Pieces hidden behind opaque ones are then left out
//!    ([`super::occlusion`], a front-to-back pass over the order).
//! 2. Each piece becomes its view-space parts ([`PieceSource::parts`]:
//!    pieces with zero extinction over their range are skipped). A mode
//!    that draws a part whole ([`ProjectedMode::whole_part`]: exact-frag's
//!    quads) gets one polygon over the part's outline, its projected
//!    points' convex hull widened a little ([`whole`]); every other part is projected into regions
//!    ([`Projector`]), leaving out pieces and
//!    triangles that contain no pixel centre
//!    ([`crate::projection::coverage`],
//!    [`super::ProjectedOptions::cull_to_pixels`]).
//! 3. The mode computes its payload at the region vertices a kept triangle
//!    uses ([`ProjectedMode::payload`], which may refine the triangles), and
//!    makes each vertex ([`ProjectedMode::vertex`]).
//! 4. The driver snaps every corner to the rasteriser's sub-pixel grid
//!    ([`ClipMapper::ndc`]), drops triangles that are flat or inverted
//!    there ([`grid_area_positive`]), and numbers the part as one piece
//!    (each piece colours a pixel at most once, [`crate::gpu::frame`]).
//!    Pixel centres within snapping distance of the part's outline are
//!    decided on the exact geometry ([`super::ties`]): where the snapped
//!    triangles would take or leave a centre the exact part does not, a
//!    triangle inside the pixel drawn first in the part decides it. Corners are shared by
//!    the part's triangles and carry the payload of the exact (unsnapped)
//!    corner: snapping moves them by up to 1/512 px, which costs the
//!    payload's gradient times that shift. Where that gradient is steep
//!    enough to shift the optical depth by more than
//!    [`super::ties::SLIVER_DEPTH_TOL`], two rules take over:
//!    - in slivers (narrower than [`super::ties::SLIVER_TIE_PX`]) the
//!      centres are decided exactly, by pixel triangles, since extrapolating
//!      across a sliver is unbounded;
//!    - a wider triangle ([`super::ties::snap_is_steep`]: an optically
//!      thick piece seen nearly along a face) gets its own corners, each
//!      with the exact triangle's values at the snapped corner
//!      ([`GpuVertex::lerp3`], an extrapolation by at most 0.6 % of the
//!      triangle), so every centre inside it takes the exact triangle's
//!      values. On the stress scenes' extinction-1e3 grid this took the
//!      exact-frag mode from 4.8e-2 to 2.6e-5 against the ray caster.
//!
//!    One pass over the part's triangles ([`super::ties::scan_triangles`])
//!    finds both, from the same widths and thickness changes.
//!
//! Pieces are processed in chunks of consecutive pieces by worker threads,
//! handed to the GPU in order as soon as each chunk and all before it are
//! done ([`super::workers::run_ordered`]); chunk buffers are reused, so
//! memory stays bounded whatever the mesh size.
//!
//! Interpolation: region vertices are sent with `w = 1` (positions already
//! divided), so the GPU interpolates linearly in screen space, which is the
//! model the projection's perspective refinement bounds (projection docs).
//!
//! Unresolved visibility cycles ([`crate::visibility::Order::groups`]) are
//! composited per pixel on the CPU into one layer each ([`super::group`])
//! and drawn at the group's place in the order by the layer stage
//! ([`crate::gpu::layer`]), whatever the mode.

use std::sync::Mutex;

use std::time::Instant;

use glam::DVec2;

use crate::camera::Camera;
use crate::gpu::common::BLOCKER_Z;
use crate::gpu::cpu::CpuFrame;
use crate::gpu::layer::{LayerVertex, LAYER_STAGE};
use crate::gpu::{
    ClipMapper, Context, DrawKind, FrameOptions, GpuVertex, PendingContext, SUBPIXEL,
};
use crate::image::Image;
use crate::projection::coverage::PixelGrid;
use crate::projection::{Polyhedron, Projected, Projector};
use crate::visibility::{DarkRanges, Piece, Sorter, SplitPolicy};

pub use super::projected_mode::ProjectedMode;

use super::group::composite_group;
use super::pieces::{value_range, PartScratch, PieceError, PieceSource};
use super::scene::{ScalarsRef, Scene};
use super::stats::ProjectedStats;
use super::ties::{
    decide_ties, push_steep, scan_triangles, thin_outline, DrawnTriangle, PartTriangles, TieRays,
    TieScratch, SNAP_PX,
};
use super::workers::run_ordered;
use super::{Compositor, RenderError, RenderOptions};
use kept::{KeepKey, KeptCounts, KeptProjection};
use regions::{PartKey, RegionStore, StoreFrame};
use sink::{finish, push_out, take_pieces, Sink};
use whole::draw_whole;

/// Pieces processed per chunk (one worker's unit of work).
const CHUNK: usize = 2048;

/// Chunks a worker may run ahead of the GPU hand-over, per worker: bounds
/// the memory in flight (about 0.4 MB per chunk on a fine mesh) while
/// keeping every worker busy when chunk costs vary.
const AHEAD_PER_WORKER: usize = 4;

/// Output of one chunk: vertices and triangles ready for the GPU.
pub(super) struct ChunkOut<V> {
    pub(super) vertices: Vec<V>,
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
    /// Pixel triangles deciding centres next to a part's outline
    /// ([`super::ties`]).
    tie_pixels: usize,
    /// Triangles whose snapped corners took the exact triangle's values
    /// ([`super::ties::snap_is_steep`]).
    steep: usize,
    /// Parts whose outline was left to the rasteriser (`thin_outline`).
    thin: usize,
    /// Parts drawn whole, as one quad ([`ProjectedMode::whole_part`]).
    whole: usize,
    /// Of those, the parts drawn as their outline's hull ([`whole`]).
    hulls: usize,
    /// Parts whose regions were kept from an earlier frame ([`regions`]).
    regions_reused: usize,
    pub(super) error: Option<PieceError>,
}

impl<V> Default for ChunkOut<V> {
    fn default() -> Self {
        ChunkOut {
            vertices: Vec::new(),
            indices: Vec::new(),
            culled: 0,
            pieces: 0,
            slabs: 0,
            refined: 0,
            degenerate: 0,
            tie_pixels: 0,
            steep: 0,
            thin: 0,
            whole: 0,
            hulls: 0,
            regions_reused: 0,
            error: None,
        }
    }
}

impl<V> ChunkOut<V> {
    /// Empties everything, keeping the buffers.
    fn clear(&mut self) {
        self.vertices.clear();
        self.indices.clear();
        self.culled = 0;
        self.pieces = 0;
        self.slabs = 0;
        self.refined = 0;
        self.degenerate = 0;
        self.tie_pixels = 0;
        self.steep = 0;
        self.thin = 0;
        self.whole = 0;
        self.hulls = 0;
        self.regions_reused = 0;
        self.error = None;
    }
}

/// Scratch of one worker, reused from piece to piece.
struct Worker<P, V> {
    projector: Projector,
    parts: PartScratch,
    proj: Projected,
    payload: P,
    /// Vertices used by a kept triangle, their index in the output, and
    /// their snapped grid position.
    used: Vec<bool>,
    remap: Vec<u32>,
    grid: Vec<[i64; 2]>,
    /// How far the snap moved each vertex of the projection (pixels; the
    /// bound [`super::ties::SNAP_PX`] where it was not snapped).
    snap: Vec<f64>,
    /// Triangles drawn, with their snapped corners, and the pixel
    /// triangles of the centres next to the outline ([`super::ties`]).
    drawn: Vec<DrawnTriangle>,
    ties: TieScratch,
    /// Whether each boundary triangle of a part with holes holds one
    /// ([`leave_out_holes`]).
    hole_faces: Vec<bool>,
    /// The transfer function's largest rate anywhere (a bound on every
    /// part's, [`PieceSource::max_rate`]).
    rate_bound: f64,
    _vertex: std::marker::PhantomData<V>,
}

impl<P: Default, V> Worker<P, V> {
    fn new(src: &PieceSource, perspective_refine: bool) -> Self {
        let mut projector = Projector::new();
        // Pieces cut by the near plane reach ~1e9 pixels off screen: clip
        // their regions to the image so that screen-space interpolation
        // stays exact up to the perspective refinement's bound.
        projector.clip_to_image = true;
        projector.cull_to_pixels = src.cull;
        projector.perspective_refine = perspective_refine;
        Worker {
            projector,
            parts: PartScratch::default(),
            proj: Projected::default(),
            payload: P::default(),
            used: Vec::new(),
            remap: Vec::new(),
            grid: Vec::new(),
            snap: Vec::new(),
            drawn: Vec::new(),
            ties: TieScratch::default(),
            hole_faces: Vec::new(),
            rate_bound: {
                let (lo, hi) = src.tf.scalar_range();
                src.max_rate(lo, hi)
            },
            _vertex: std::marker::PhantomData,
        }
    }
}

/// Projects one part, and appends its triangles with the mode's payload
/// to `out` as one piece; with `store`, its regions are kept across
/// frames under `key` (its cell and which part of it, [`regions`]).
#[allow(clippy::too_many_arguments)]
fn draw_part<M: ProjectedMode>(
    mode: &M,
    src: &PieceSource,
    part: &Polyhedron,
    key: Option<(u32, PartKey)>,
    store: Option<&StoreFrame>,
    w: &mut Worker<M::Payload, M::Vertex>,
    out: &mut ChunkOut<M::Vertex>,
) -> Result<(), crate::projection::ProjectionError> {
    // The part's largest rate, computed once, where a bound on it does
    // not settle a question.
    let part_rate_once = std::cell::OnceCell::new();
    let rate = || *part_rate_once.get_or_init(|| part_rate(src, part));
    let holes = !part.holes.is_empty();
    if !holes {
        if let Some(v) = mode.whole_part(src, part, &mut w.payload, &rate) {
            draw_whole(src.camera, part, v, out);
            return Ok(());
        }
    }
    // A part with holes is projected afresh every frame (which regions it
    // draws depends on where its scalars are NaN).
    let store = store.filter(|_| !holes);
    match (store, key) {
        (Some(store), Some((cell, pk))) => {
            let kept = store.get(cell, pk, part);
            out.regions_reused += kept.is_some() as usize;
            let keep = kept.is_none() && store.has_room();
            let camera = src.camera;
            let fresh =
                w.projector
                    .project_with(part, camera, kept.as_deref(), keep, &mut w.proj)?;
            if let Some(k) = fresh {
                store.put(cell, pk, k);
            }
        }
        _ => w.projector.project(part, src.camera, &mut w.proj)?,
    }
    // The faces the regions index are those of the part beyond the near
    // plane when it reached it.
    let projected = w.projector.projected_piece(part);
    let proj = &mut w.proj;
    if holes {
        // Clipped at the near plane, the points are no longer the part's:
        // drawn empty, as a tet with a NaN corner is.
        if !std::ptr::eq(projected, part) {
            return Ok(());
        }
        leave_out_holes(part, proj, &mut w.hole_faces);
    }
    if proj.triangles.is_empty() {
        return Ok(());
    }
    // Values only where a triangle uses the vertex (coverage culling leaves
    // vertices of dropped triangles behind).
    let used = &mut w.used;
    used.clear();
    used.resize(proj.vertices.len(), false);
    for t in &proj.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    mode.payload(src, projected, proj, used, &mut w.payload, &mut out.refined);
    let mapper = ClipMapper::for_camera(src.camera);
    let piece = out.pieces;
    out.pieces += 1;
    // Index of each used vertex in `out.vertices` (u32::MAX: not emitted),
    // and its snapped grid position (from `first` on). Corners are shared
    // by the triangles of the part and carry the payload of the exact
    // corner (see the module docs on what snapping costs).
    let first = out.vertices.len() as u32;
    w.grid.clear();
    w.remap.clear();
    // The snap's moves, for the sliver tests of the tie decisions only
    // (without them a vertex counts as moved by the most, `SNAP_PX`).
    let ties = mode.decides_ties() && src.exact_ties;
    w.snap.clear();
    if ties {
        w.snap.resize(proj.vertices.len(), SNAP_PX);
    }
    for (i, v) in proj.vertices.iter().enumerate() {
        if !used[i] {
            w.remap.push(u32::MAX);
            continue;
        }
        // Region positions are finite and on screen or clipped near it
        // (`clip_to_image`); one that is not cannot be drawn exactly.
        let Some((ndc, g)) = mapper.ndc(v.px, v.py) else {
            w.remap.push(u32::MAX);
            continue;
        };
        w.remap.push(out.vertices.len() as u32);
        w.grid.push(g);
        if ties {
            let moved = DVec2::new(g[0] as f64, g[1] as f64) / SUBPIXEL - v.pos();
            w.snap[i] = moved.length();
        }
        out.vertices
            .push(mode.vertex(&w.payload, proj, i, ndc).with_piece(piece));
    }
    let drawn = &mut w.drawn;
    drawn.clear();
    for (k, t) in proj.triangles.iter().enumerate() {
        let idx = t.map(|i| w.remap[i as usize]);
        if idx.contains(&u32::MAX) {
            out.degenerate += 1;
            continue;
        }
        let g = idx.map(|i| w.grid[(i - first) as usize]);
        if grid_area_positive(g[0], g[1], g[2]) {
            drawn.push(DrawnTriangle {
                corners: *t,
                grid: g,
                exact: k as u32,
            });
        } else {
            out.degenerate += 1;
        }
    }
    let l_range = value_range(proj.vertices.iter().map(|v| v.l));
    // Centres next to the outline first (they decide their pixels), then
    // the triangles.
    let part_tris = PartTriangles {
        proj,
        drawn,
        exact: &proj.triangles,
        width: src.camera.width,
        height: src.camera.height,
        rate_bound: w.rate_bound,
        rate: &rate,
        l_range,
        snap: &w.snap,
        weighed: src.colour_draw && src.iso.is_none() && mode.fragment_isovalues().is_empty(),
        clipped: !std::ptr::eq(projected, part),
        isovalues: mode.part_isovalues(&w.payload),
        iso_origin: mode.fragment_iso_origin(src),
    };
    // Steep triangles (`snap_is_steep`) take the exact triangle's values
    // at their snapped corners; the others share the exact corners'. The
    // same pass finds the slivers the tie decisions look into.
    // An optically thin part's outline and slivers are left to the
    // rasteriser (`thin_outline`).
    let thin = ties && thin_outline(&part_tris);
    out.thin += thin as usize;
    scan_triangles(&part_tris, ties && !thin, &mut w.ties);
    if ties {
        decide_ties(&part_tris, !thin, part, &src.ties, &mut w.ties);
        if holes {
            // A centre whose ray enters or leaves through a triangle
            // holding a hole is empty: a blocker.
            for d in &mut w.ties.decisions {
                let hole = |f: &u32| w.hole_faces.get(*f as usize).copied().unwrap_or(true);
                if d.value.is_some() && d.faces.iter().any(hole) {
                    d.value = None;
                }
            }
        }
        out.tie_pixels += emit_tie_triangles(mode, src, part, piece, &mapper, w, out);
    }
    for d in w.drawn.iter() {
        let idx = d.corners.map(|i| w.remap[i as usize]);
        if w.ties.steep[d.exact as usize] {
            let p = d.corners.map(|i| w.proj.vertices[i as usize].pos());
            let exact = idx.map(|i| out.vertices[i as usize]);
            push_steep(p, d.grid, exact, &mut out.vertices, &mut out.indices);
            out.steep += 1;
        } else {
            out.indices.extend_from_slice(&idx);
        }
    }
    Ok(())
}

/// Leaves out of `proj` the regions in front of or behind a boundary
/// triangle of `part` that holds one of its holes ([`Polyhedron::holes`]):
/// no ray through them has a scalar at both ends. `hole_faces` is set to
/// whether each boundary triangle holds one. The part's outline then runs
/// along the holes too, so the centres next to them are decided on the
/// exact geometry (the ties, which give a centre whose ray meets a hole's
/// triangle a blocker), and the outline is not left to the rasteriser.
fn leave_out_holes(part: &Polyhedron, proj: &mut Projected, hole_faces: &mut Vec<bool>) {
    hole_faces.clear();
    hole_faces.extend(
        part.triangles
            .iter()
            .map(|t| t.iter().any(|i| part.holes.binary_search(i).is_ok())),
    );
    proj.leave_out_regions_on(hole_faces);
}

/// The largest rate on `part`'s scalar range.
fn part_rate(src: &PieceSource, part: &Polyhedron) -> f64 {
    let (lo, hi) = value_range(part.scalars.iter().copied());
    src.max_rate(lo, hi)
}

/// The corners of a tie's one triangle within its pixel (offsets from the
/// pixel's corner, on the rasteriser's sub-pixel grid, wound as the region
/// triangles): it holds the pixel's centre, 0.19 px inside its nearest
/// edge, and no other centre, with one triangle where a quad over the
/// pixel takes two.
const TIE_TRIANGLE: [(f64, f64); 3] = [(0.125, 0.25), (0.875, 0.25), (0.5, 0.875)];

/// Draws the pixel triangles of the part's tie decisions (`w.ties`, see
/// [`super::ties`]) into `out`, before the part's triangles: the mode's
/// payload of the exact segment at the centre, or a transparent blocker.
/// Returns the number of triangles.
fn emit_tie_triangles<M: ProjectedMode>(
    mode: &M,
    src: &PieceSource,
    part: &Polyhedron,
    piece: u32,
    mapper: &ClipMapper,
    w: &mut Worker<M::Payload, M::Vertex>,
    out: &mut ChunkOut<M::Vertex>,
) -> usize {
    let ties = &mut w.ties;
    if ties.decisions.is_empty() {
        return 0;
    }
    // The segments' payload, as the mode computes it for region vertices
    // (the part's own vertices are emitted already: the payload scratch is
    // free).
    let values = &mut ties.values;
    values.clear();
    values.view = w.proj.view;
    values
        .vertices
        .extend(ties.decisions.iter().filter_map(|d| d.value));
    values.tie_faces.extend(
        ties.decisions
            .iter()
            .filter(|d| d.value.is_some())
            .map(|d| d.faces),
    );
    let mut used = std::mem::take(&mut w.used);
    used.clear();
    used.resize(values.vertices.len(), true);
    let mut refined = 0;
    if !values.vertices.is_empty() {
        mode.payload(src, part, values, &mut used, &mut w.payload, &mut refined);
    }
    w.used = used;
    // A blocker is any vertex of the part, emptied.
    let blocker = w
        .drawn
        .first()
        .map(|d| out.vertices[w.remap[d.corners[0] as usize] as usize].transparent());
    let mut drawn = 0;
    let mut k = 0;
    for d in &ties.decisions {
        let (value, z) = match d.value {
            Some(_) => {
                k += 1;
                (mode.vertex(&w.payload, values, k - 1, [0.0, 0.0]), 0.5)
            }
            None => match blocker {
                Some(b) => (b, BLOCKER_Z),
                None => continue,
            },
        };
        let (i, j) = d.pixel;
        let base = out.vertices.len() as u32;
        for (di, dj) in TIE_TRIANGLE {
            let Some((ndc, _)) = mapper.ndc(i as f64 + di, j as f64 + dj) else {
                continue;
            };
            out.vertices
                .push(value.with_clip([ndc[0], ndc[1], z, 1.0]).with_piece(piece));
        }
        if out.vertices.len() as u32 == base + 3 {
            out.indices.extend_from_slice(&[base, base + 1, base + 2]);
            drawn += 1;
        } else {
            out.vertices.truncate(base as usize);
        }
    }
    drawn
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
/// (`shaders/common.wgsl` `piece_depth`) makes it exactly once.
pub(super) fn grid_area_positive(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> bool {
    // Integer coordinates below 2^40: the cross product is exact in i128.
    let [a, b, c] = [a, b, c].map(|p| [p[0] as i128, p[1] as i128]);
    // Pixel y points down, as in the region triangles.
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0
}

/// Projects `pieces` into `out` (empty, its buffers possibly reused).
fn process_chunk<M: ProjectedMode>(
    mode: &M,
    src: &PieceSource,
    store: Option<&StoreFrame>,
    pieces: &[Piece],
    mut out: ChunkOut<M::Vertex>,
) -> ChunkOut<M::Vertex> {
    let mut w = Worker::<M::Payload, M::Vertex>::new(src, mode.perspective_refine());
    for piece in pieces {
        let mut parts = std::mem::take(&mut w.parts);
        let key = store.and(PartKey::of(piece));
        let done = src.parts(piece, &mut parts, |part| {
            draw_part(mode, src, part, key, store, &mut w, &mut out).map_err(|source| {
                PieceError::Projection {
                    cell: piece.cell(),
                    source,
                }
            })
        });
        w.parts = parts;
        match done {
            Ok(d) => {
                out.culled += d.invisible as usize;
                out.slabs += d.slabs;
            }
            Err(e) => {
                out.error = Some(e);
                return out;
            }
        }
    }
    out
}

/// Chunk buffers of drawn chunks, reused: fresh multi-megabyte vectors
/// would be new pages for the kernel to fault in and zero, chunk after
/// chunk.
struct BufferPool<V>(Mutex<Vec<ChunkOut<V>>>);

impl<V> Default for BufferPool<V> {
    fn default() -> Self {
        BufferPool(Mutex::new(Vec::new()))
    }
}

impl<V> BufferPool<V> {
    fn take(&self) -> ChunkOut<V> {
        self.0
            .lock()
            .ok()
            .and_then(|mut p| p.pop())
            .unwrap_or_default()
    }

    fn put(&self, mut out: ChunkOut<V>) {
        out.clear();
        if let Ok(mut p) = self.0.lock() {
            p.push(out);
        }
    }
}

/// Projects `pieces` in chunks of `chunk` pieces on `workers` threads and
/// hands each chunk's output to `sink` on this thread, in order
/// ([`run_ordered`]).
#[allow(clippy::too_many_arguments)]
fn pipeline<M: ProjectedMode>(
    mode: &M,
    src: &PieceSource,
    store: Option<&StoreFrame>,
    pieces: &[Piece],
    chunk: usize,
    workers: usize,
    pool: &BufferPool<M::Vertex>,
    sink: impl FnMut(ChunkOut<M::Vertex>) -> Result<(), RenderError>,
) -> Result<(), RenderError> {
    let chunks: Vec<&[Piece]> = pieces.chunks(chunk.max(1)).collect();
    run_ordered(
        chunks.len(),
        workers,
        workers * AHEAD_PER_WORKER,
        |i| process_chunk(mode, src, store, chunks[i], pool.take()),
        sink,
    )
}

/// Renders the scene with a projected-cell mode. The GPU context is `gpu`,
/// or, when that is empty, `pending` (a context opening on another thread,
/// waited for after the sort, which it overlaps) or a new one opened with
/// `opts.gpu`; it is left in `gpu`. `whole` is the geometry's mesh
/// (`scene` may hold only its visible subset, [`super::visible`]): the
/// tie decisions take its bounding sphere, as the reference does, and the
/// tables its lengths.
#[allow(clippy::too_many_arguments)]
pub fn render_projected<M: ProjectedMode>(
    mode: &M,
    scene: &Scene,
    sorter: &mut Sorter,
    gpu: &mut Option<Context>,
    pending: &mut Option<PendingContext>,
    orders: &mut super::order_cache::OrderCache,
    opts: &RenderOptions,
    camera: &Camera,
    whole: &crate::mesh::Mesh,
    tree: Option<super::occlusion::TreeView>,
    kept_frame: &mut Option<KeptProjection>,
    (regions, ids): (&mut RegionStore, Option<&[u32]>),
    mut progress: impl FnMut(usize, usize),
) -> Result<(Image, ProjectedStats), RenderError> {
    let mut stats = ProjectedStats::default();
    let breakpoints = mode.split_points(&scene.tf);
    let point_scalars = match scene.scalars() {
        ScalarsRef::Point(v) => Some(v),
        _ => None,
    };
    let t0 = Instant::now();
    // Dark cells (drawn by no piece) are not split at breakpoints: the
    // same test as the pieces' skip, and only where that skip is on.
    let (iso, volume) = (mode.isosurfaces(), mode.draws_volume());
    let dark_test = |lo: f64, hi: f64| super::pieces::dark_range(&scene.tf, iso, volume, lo, hi);
    let dark = opts.projected.skip_invisible.then(|| DarkRanges {
        test: &dark_test,
        key: super::pieces::dark_key(&scene.tf, iso, volume),
    });
    let policy = SplitPolicy {
        all: opts.projected.split_all,
        breakpoints: &breakpoints,
        point_scalars,
        dark,
    };
    let (order, reused) = orders.order(sorter, camera, &policy)?;
    stats.order_reused = reused == super::order_cache::Reuse::Order;
    stats.sort_reused = reused == super::order_cache::Reuse::Sort;
    stats.sort_s = t0.elapsed().as_secs_f64();
    stats.pieces = order.pieces.len();
    stats.order = order.stats.clone();

    let src = PieceSource {
        mesh: &scene.mesh,
        whole,
        scalars: scene.scalars(),
        field_span: scene.field_span(),
        tf: &scene.tf,
        camera,
        breakpoints: &breakpoints,
        levels: &order.levels,
        fragments: &order.fragments,
        length_unit: scene.unit_distance as f32 as f64,
        cull: opts.projected.cull_to_pixels,
        skip_invisible: opts.projected.skip_invisible,
        grid: PixelGrid::new(camera.width, camera.height),
        ties: TieRays::new(camera, whole.bounds()),
        exact_ties: opts.projected.exact_ties,
        colour_draw: opts.projected.draw == DrawKind::Composite,
        iso: mode.isosurfaces(),
        volume: mode.draws_volume(),
        gradients: mode.point_gradients(),
    };
    let t_open = Instant::now();
    let mut sink = match opts.projected.compositor {
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
            let mut fopts = FrameOptions::new(camera.width, camera.height, opts.accum);
            fopts.draw = opts.projected.draw;
            Sink::Gpu {
                frame: Box::new(gpu.begin_frame_with(&fopts)?),
                stage: mode.bind(gpu, &src)?,
                layer: gpu.bind_stage(&LAYER_STAGE, &[])?,
            }
        }
        Compositor::Cpu => {
            let mut f =
                CpuFrame::new(camera.width, camera.height, opts.accum, opts.projected.draw)?;
            if let Some((i, j)) = opts.projected.watch {
                f.watch(i, j);
            }
            Sink::Cpu {
                frame: Box::new(f),
                twin: mode.twin(&src),
            }
        }
    };
    stats.gpu_open_s = t_open.elapsed().as_secs_f64();
    let t_gpu = Instant::now();
    // The frame's triangles, kept for (or taken from) a frame that differs
    // only in the transfer function's colours ([`kept`]).
    let keep_key = (opts.projected.keep_projection
        && matches!(sink, Sink::Gpu { .. })
        && opts.projected.draw == DrawKind::Composite
        && order.groups.is_empty()
        && mode.isosurfaces().is_none())
    .then(|| mode.stream_signature(&scene.tf))
    .flatten()
    .map(|tf| KeepKey {
        mode: std::any::type_name::<M>(),
        order: order.clone(),
        mesh: scene.mesh.clone(),
        field: scene.field.clone(),
        camera: *camera,
        options: opts.projected,
        unit_distance: scene.unit_distance.to_bits(),
        tf,
    });
    if let Some(key) = &keep_key {
        let batches = kept_frame
            .as_ref()
            .and_then(|k| k.batches_for::<M::Vertex>(key));
        if let Some(batches) = batches {
            let tp = Instant::now();
            for (v, i) in batches {
                sink.push(v, i)?;
            }
            if let Some(k) = kept_frame.as_ref() {
                k.counts.restore(&mut stats);
            }
            progress(order.pieces.len(), order.pieces.len());
            return finish(sink, stats, tp.elapsed().as_secs_f64(), t_gpu);
        }
    }
    let mut record = keep_key.map(KeptProjection::new);
    if record.is_none() {
        // Nothing to keep: free what an earlier frame kept.
        *kept_frame = None;
    }
    // Region geometry kept across frames whose values change ([`regions`]).
    if !opts.projected.keep_regions {
        regions.clear();
    }
    let cull = opts.projected.cull_to_pixels;
    let store = opts
        .projected
        .keep_regions
        .then(|| regions.frame(camera, cull, whole.cells.len(), ids));
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
    let mapper = ClipMapper::for_camera(camera);
    // Pieces hidden behind opaque ones are left out (not when counting
    // coverage, which counts every piece).
    let t_occ = Instant::now();
    let occlusion = opts
        .projected
        .occlusion
        .filter(|_| opts.projected.draw == DrawKind::Composite)
        .and_then(|t| super::occlusion::hidden_pieces(&src, &order, t, tree))
        .filter(|o| o.count > 0);
    stats.occlusion_s = t_occ.elapsed().as_secs_f64();
    stats.hidden_pieces = occlusion.as_ref().map_or(0, |o| o.count);
    stats.occlusion_nodes_hidden = occlusion.as_ref().map_or(0, |o| o.nodes_hidden);
    stats.hidden_by_nodes = occlusion.as_ref().map_or(0, |o| o.hidden_by_nodes);
    let mut kept: Vec<Piece> = Vec::new();
    for (plain, group) in stretches {
        let pieces = match &occlusion {
            Some(o) => {
                kept.clear();
                kept.extend(
                    plain
                        .clone()
                        .filter(|&k| !o.hidden[k])
                        .map(|k| order.pieces[k]),
                );
                done += plain.len() - kept.len();
                &kept[..]
            }
            None => &order.pieces[plain],
        };
        let mut handed = 0;
        pipeline(
            mode,
            &src,
            store.as_ref(),
            pieces,
            CHUNK,
            workers,
            &pool,
            |mut out| {
                push_out(
                    &mut sink,
                    &mut out,
                    &mut stats,
                    &mut next_piece,
                    record.as_mut(),
                )?;
                pool.put(out);
                handed += CHUNK;
                progress(done + handed.min(pieces.len()), total);
                Ok(())
            },
        )?;
        done += pieces.len();
        if let Some(g) = group {
            let layer = composite_group(&src, &order.pieces[g.clone()])?;
            stats.culled_pieces += layer.culled;
            stats.group_pixels += layer.pixels.len();
            // The group's layer is one piece (its pixel quads do not
            // overlap).
            let piece = take_pieces(&mut next_piece, 1)?;
            let (mut vertices, mut indices) = (Vec::new(), Vec::new());
            for &(i, j, rgba) in &layer.pixels {
                LayerVertex::pixel_quad(&mapper, i, j, rgba, piece, &mut vertices, &mut indices);
            }
            stats.triangles += indices.len() / 3;
            sink.push_layer(&vertices, &indices)?;
            done += g.len();
            progress(done, total);
        }
    }
    if let Some(mut r) = record {
        r.counts = KeptCounts::of(&stats);
        *kept_frame = r.complete();
    }
    stats.regions_kept_bytes = store.map_or(0, |s| s.bytes());
    finish(sink, stats, tp.elapsed().as_secs_f64(), t_gpu)
}

pub mod kept;
pub mod regions;
mod sink;
mod whole;

#[cfg(test)]
pub(crate) mod tests;
