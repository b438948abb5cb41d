//! The reference software ray caster.
//!
//! One ray per pixel centre ([`Camera::pixel_ray`]), walked through the cells
//! it crosses by face adjacency ([`walk`]), with exact crossing decisions and
//! a documented tie-breaking rule ([`geometry`]: simulation of simplicity on
//! the ray's origin, canonical edge orientation by point id). Each cell
//! segment is integrated exactly for the chosen [`FieldModel`] and composited
//! front to back in a [`RayAccumulator`]. [`Traversal::Brute`] replaces the
//! walk by a search of every piece the ray meets ([`brute`]: a BVH over the
//! cells, each crossed whole or as its tets with the same crossing
//! predicate, no adjacency), the reference
//! for meshes whose adjacency cannot be trusted (`faces` and `tets` only).
//! Both traversals are [`RayTracer`]s: each integrates one ray, and the
//! trait renders an image from them in parallel tiles.
//! Field models:
//! - [`FieldModel::Faces`] (default): entry and exit on the cell's face
//!   triangles, the scalar linear on each triangle (barycentric) and along the
//!   ray, integrated by `material.segment(l, s_in, s_out)`;
//! - [`FieldModel::Tets`]: the same walk over the consistent
//!   tetrahedralisation (`tetra::tetrahedralize_cell`), whose faces model is
//!   the linear field of each tet;
//! - [`FieldModel::Native`] (point data): each hexahedron, wedge and pyramid
//!   is integrated between the ray's intersections with its true boundary,
//!   the bilinear patches of its quad faces and its planar triangles, with
//!   the iso-parametric scalar inside ([`native`]). The walk over the
//!   triangulated faces still gives the cells (it is watertight); the
//!   integration intervals come from the cells' own boundaries: every walk
//!   cell of a native kind, plus (transitively) every native neighbour
//!   across a face whose bilinear patch the ray crosses (a ray through the
//!   sliver between a bulging patch and its two triangles may enter a cell
//!   the walk does not visit; counted in [`native::NativeStats::extra_cells`]).
//!   Shared faces are parameterised canonically, so neighbouring cells get
//!   bit-identical crossing depths: no gap, no double count. A point of the
//!   ray belongs to a cell iff its inverted parametric coordinates are in the
//!   reference element. The intervals of all cells are sorted by depth and
//!   composited. Tets, pentagonal and hexagonal prisms and polyhedra keep
//!   their walk segments and `faces` field. Known limits: a quad face shared
//!   by a native cell and a prism or polyhedron is a bilinear patch on one
//!   side and two triangles on the other (the sliver between them is counted
//!   twice or not at all); a boundary patch that bulges out where the ray
//!   misses the walk's triangles and every walk cell's patches is not seen.
//!   For cell data and constant scalars `native` equals `faces` (segments
//!   bounded by the triangulated faces). [`Raycaster::segments`] reports the
//!   walk's segments; [`Raycaster::native_segments`] the native intervals.
//!   Fallbacks (Newton failures, linear fallback intervals, parity
//!   classification, subdivision depth limits) are counted per render:
//!   [`Raycaster::native_stats`].
//!
//! Cell data uses the homogeneous integral `segment(l, s, s)`; no field means
//! a constant scalar. The near plane is at the eye: only `t >= camera.near`
//! (perspective) or `t >= 0` (orthographic) is integrated; when the ray
//! origin is inside the mesh's bounding box the walk starts from the line's
//! first entry behind the eye and clips. Rendering is parallel over 16x16
//! tiles (rayon) with early termination at transmittance
//! [`RAY_TERMINATION_TRANSMITTANCE`] (`RaycastOptions::early_termination`).

pub mod brute;
pub mod bvh;
pub mod geometry;
pub mod iso;
pub mod native;
pub mod walk;

use std::borrow::Cow;

use std::collections::HashSet;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::mpsc;

use rayon::prelude::*;
use thiserror::Error;

use crate::camera::{Camera, Ray};
use crate::image::Image;
use crate::integrate::{RayAccumulator, RayMaterial};
use crate::mesh::tetra::tetrahedralize_cell;
use crate::mesh::topology::Topology;
use crate::mesh::{CellKind, Cells, Mesh, NONE};
use crate::numeric::tolerance::RAY_TERMINATION_TRANSMITTANCE;
use geometry::RayFrame;
use walk::{RawSegment, Scratch, WalkMesh};

/// Which scalar field is integrated inside a cell (docs/conventions.md, Conventions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldModel {
    #[default]
    Faces,
    Tets,
    Native,
}

impl FieldModel {
    /// The name `--model` takes.
    pub fn name(self) -> &'static str {
        match self {
            FieldModel::Faces => "faces",
            FieldModel::Tets => "tets",
            FieldModel::Native => "native",
        }
    }
}

impl std::str::FromStr for FieldModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "faces" => Ok(FieldModel::Faces),
            "tets" => Ok(FieldModel::Tets),
            "native" => Ok(FieldModel::Native),
            _ => Err(format!("unknown field model '{s}' (faces, tets, native)")),
        }
    }
}

/// How the ray caster finds the pieces along a ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Traversal {
    /// From cell to cell by face adjacency ([`walk`]; [`Raycaster`]).
    #[default]
    Walk,
    /// Every cell or tet the ray meets, through a BVH, without adjacency
    /// ([`brute`]; [`brute::Brute`]); `faces` and `tets` only.
    Brute,
}

impl Traversal {
    /// The name `--traversal` takes.
    pub fn name(self) -> &'static str {
        match self {
            Traversal::Walk => "walk",
            Traversal::Brute => "brute",
        }
    }
}

impl std::str::FromStr for Traversal {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "walk" => Ok(Traversal::Walk),
            "brute" => Ok(Traversal::Brute),
            _ => Err(format!("unknown traversal '{s}' (walk, brute)")),
        }
    }
}

/// Ray caster options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaycastOptions {
    pub model: FieldModel,
    /// Walk by adjacency (default) or test every piece ([`Traversal`]);
    /// used by [`render`] and [`trace_ray`] (a prepared [`Raycaster`]
    /// always walks).
    pub traversal: Traversal,
    /// A ray stops when its transmittance drops below this (default
    /// [`RAY_TERMINATION_TRANSMITTANCE`] = 1e-6); 0 disables it.
    pub early_termination: f64,
    /// Tile edge in pixels for the parallel loop.
    pub tile: u32,
}

impl Default for RaycastOptions {
    fn default() -> Self {
        RaycastOptions {
            model: FieldModel::Faces,
            traversal: Traversal::Walk,
            early_termination: RAY_TERMINATION_TRANSMITTANCE,
            tile: 16,
        }
    }
}

/// The scalar field integrated.
#[derive(Clone, Copy, Debug)]
pub enum Scalars<'a> {
    /// One value per point.
    Point(&'a [f64]),
    /// One value per cell (constant in the cell).
    Cell(&'a [f64]),
    /// The same value everywhere (no field).
    Constant(f64),
}

/// What is rendered.
#[derive(Clone, Copy, Debug)]
pub struct Scene<'a> {
    pub mesh: &'a Mesh,
    pub topology: &'a Topology,
    pub scalars: Scalars<'a>,
}

/// Errors of the ray caster (bad input; it never panics).
#[derive(Debug, Error)]
pub enum RaycastError {
    #[error("{what} has {got} values but the mesh has {want}")]
    ScalarLength {
        what: &'static str,
        got: usize,
        want: usize,
    },
    #[error("cell {cell} refers to point {point}, but the mesh has {points} points")]
    BadPointId {
        cell: usize,
        point: u32,
        points: usize,
    },
    #[error("cell {cell} ({kind:?}) has {got} nodes, expected {want}")]
    BadNodeCount {
        cell: usize,
        kind: CellKind,
        got: usize,
        want: usize,
    },
    #[error("point {0} has a non-finite coordinate")]
    NonFinitePoint(usize),
    #[error("the topology does not belong to this mesh ({0} cells vs {1})")]
    TopologyMismatch(usize, usize),
    #[error("the brute-force traversal supports the `faces` and `tets` models, not `{0}`")]
    BruteModel(&'static str),
}

/// One cell's part of a ray (front to back), as integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// The mesh cell (for `tets`, the cell the tet came from).
    pub cell: u32,
    pub t_in: f64,
    pub t_out: f64,
    /// Scalar at entry and exit (faces/tets field; for cell data the cell
    /// value).
    pub s_in: f64,
    pub s_out: f64,
}

/// A scene prepared for ray casting with one field model: validated input,
/// the boundary structure and, for `tets`, the tetrahedral mesh.
pub struct Raycaster<'a> {
    scene: Scene<'a>,
    model: FieldModel,
    /// Tets model: the mesh cell of each tet.
    parent: Option<Vec<u32>>,
    walker: WalkMesh<'a>,
    /// Native-model counters summed over all traced rays (see
    /// [`native::NativeStats`], same field order).
    native_counts: [AtomicU64; 6],
}

fn validate(scene: &Scene) -> Result<(), RaycastError> {
    let mesh = scene.mesh;
    let np = mesh.points.len();
    if let Some(i) = mesh.points.iter().position(|p| !p.is_finite()) {
        return Err(RaycastError::NonFinitePoint(i));
    }
    let cells = &mesh.cells;
    if cells.offsets.len() != cells.len() + 1 && !cells.is_empty() {
        return Err(RaycastError::TopologyMismatch(
            cells.offsets.len(),
            cells.len(),
        ));
    }
    for c in 0..cells.len() {
        let (a, b) = (cells.offsets[c] as usize, cells.offsets[c + 1] as usize);
        if a > b || b > cells.conn.len() {
            return Err(RaycastError::TopologyMismatch(b, cells.conn.len()));
        }
        let nodes = &cells.conn[a..b];
        if let Some(want) = cells.kinds[c].corner_count() {
            if nodes.len() != want {
                return Err(RaycastError::BadNodeCount {
                    cell: c,
                    kind: cells.kinds[c],
                    got: nodes.len(),
                    want,
                });
            }
        }
        if let Some(&p) = nodes.iter().find(|&&p| p as usize >= np) {
            return Err(RaycastError::BadPointId {
                cell: c,
                point: p,
                points: np,
            });
        }
    }
    for faces in cells.poly_faces.values() {
        if let Some(&p) = faces.iter().flatten().find(|&&p| p as usize >= np) {
            return Err(RaycastError::BadPointId {
                cell: 0,
                point: p,
                points: np,
            });
        }
    }
    let t = scene.topology;
    if t.cell_face_offsets.len() != cells.len() + 1 {
        return Err(RaycastError::TopologyMismatch(
            t.cell_face_offsets.len().saturating_sub(1),
            cells.len(),
        ));
    }
    match scene.scalars {
        Scalars::Point(v) if v.len() != np => Err(RaycastError::ScalarLength {
            what: "point scalars",
            got: v.len(),
            want: np,
        }),
        Scalars::Cell(v) if v.len() != cells.len() => Err(RaycastError::ScalarLength {
            what: "cell scalars",
            got: v.len(),
            want: cells.len(),
        }),
        _ => Ok(()),
    }
}

impl<'a> Raycaster<'a> {
    /// Validates the scene and builds what the model needs.
    pub fn new(scene: Scene<'a>, model: FieldModel) -> Result<Raycaster<'a>, RaycastError> {
        validate(&scene)?;
        let mesh = scene.mesh;
        if model == FieldModel::Tets {
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
            let topo = Topology::build(&cells);
            let walker = WalkMesh::new(&mesh.points, Cow::Owned(cells), Cow::Owned(topo));
            return Ok(Raycaster {
                scene,
                model,
                parent: Some(parent),
                walker,
                native_counts: Default::default(),
            });
        }
        let walker = WalkMesh::new(
            &mesh.points,
            Cow::Borrowed(&mesh.cells),
            Cow::Borrowed(scene.topology),
        );
        Ok(Raycaster {
            scene,
            model,
            parent: None,
            walker,
            native_counts: Default::default(),
        })
    }

    /// The native model's counters summed over every ray traced so far.
    pub fn native_stats(&self) -> native::NativeStats {
        let c = |k: usize| self.native_counts[k].load(Ordering::Relaxed);
        native::NativeStats {
            intervals: c(0),
            extra_cells: c(1),
            newton_failures: c(2),
            fallback_intervals: c(3),
            parity_classified: c(4),
            bracket_depth_limited: c(5),
        }
    }

    fn record_native(&self, s: &native::NativeStats) {
        let v = [
            s.intervals,
            s.extra_cells,
            s.newton_failures,
            s.fallback_intervals,
            s.parity_classified,
            s.bracket_depth_limited,
        ];
        for (a, x) in self.native_counts.iter().zip(v) {
            if x > 0 {
                a.fetch_add(x, Ordering::Relaxed);
            }
        }
    }

    /// The native model's intervals of `ray` with `t_out > t_near`, sorted
    /// by entry depth (not clipped): for hexahedra, wedges and pyramids
    /// bounded by their bilinear / planar faces, for other kinds the walk's
    /// segments (`faces` entry and exit scalars). `None` unless the scene
    /// has point scalars.
    pub fn native_intervals(
        &self,
        ray: &Ray,
        t_near: f64,
        scratch: &mut Scratch,
        stats: &mut native::NativeStats,
    ) -> Option<Vec<native::Interval>> {
        self.native_intervals_with(ray, t_near, scratch, stats, None)
    }

    /// [`Raycaster::native_intervals`], also collecting into `raws` the
    /// walk segments of the cells without a native field (in walk order).
    pub(crate) fn native_intervals_with(
        &self,
        ray: &Ray,
        t_near: f64,
        scratch: &mut Scratch,
        stats: &mut native::NativeStats,
        mut raws: Option<&mut Vec<RawSegment>>,
    ) -> Option<Vec<native::Interval>> {
        let vals = native::point_values(&self.scene)?;
        let cells = &self.scene.mesh.cells;
        let topo = self.scene.topology;
        let mut out = Vec::new();
        let mut queue: Vec<u32> = Vec::new();
        let mut seen: HashSet<u32> = HashSet::new();
        let frame = RayFrame::new(ray, self.walker.center, self.walker.radius);
        let t0 = self.start_t(ray);
        self.walker.walk(&frame, t0, scratch, |raw| {
            let c = raw.cell as usize;
            if c < cells.len() && native::is_native_kind(cells.kinds[c]) {
                if seen.insert(raw.cell) {
                    queue.push(raw.cell);
                }
            } else if raw.t_out > t_near {
                if let Some(r) = raws.as_deref_mut() {
                    r.push(*raw);
                }
                let s = self.to_segment(raw);
                out.push(native::Interval {
                    cell: s.cell,
                    t_a: s.t_in,
                    t_b: s.t_out,
                    s_a: s.s_in,
                    s_b: s.s_out,
                });
            }
            true
        });
        let walked = queue.len();
        let axes = native::axes_of(ray);
        let mut crossed = Vec::new();
        let limit = 4 * cells.len() + 16;
        let mut k = 0;
        while k < queue.len() && k < limit {
            let c = queue[k];
            let before = out.len();
            crossed.clear();
            native::cell_intervals(
                &self.scene,
                vals,
                c as usize,
                ray,
                axes,
                &mut out,
                &mut crossed,
                stats,
            );
            if k >= walked && out.len() > before {
                stats.extra_cells += 1;
            }
            for &f in &crossed {
                if f as usize >= topo.face_count() {
                    continue;
                }
                let n = topo.neighbour(f as usize, c);
                if n != NONE
                    && (n as usize) < cells.len()
                    && native::is_native_kind(cells.kinds[n as usize])
                    && seen.insert(n)
                {
                    queue.push(n);
                }
            }
            k += 1;
        }
        out.retain(|iv| iv.t_b > t_near);
        out.sort_by(|a, b| a.t_a.total_cmp(&b.t_a).then(a.cell.cmp(&b.cell)));
        Some(out)
    }

    /// [`Raycaster::native_intervals`] as segments clipped at `t_near`
    /// (entry and exit scalars exact on the true boundary); the walk's
    /// [`Raycaster::segments`] when the scene has no point scalars.
    pub fn native_segments(&self, ray: &Ray, t_near: f64) -> Vec<Segment> {
        let mut stats = native::NativeStats::default();
        match self.native_intervals(ray, t_near, &mut Scratch::default(), &mut stats) {
            Some(ivs) => ivs
                .iter()
                .map(|iv| {
                    let mut s = Segment {
                        cell: iv.cell,
                        t_in: iv.t_a,
                        t_out: iv.t_b,
                        s_in: iv.s_a,
                        s_out: iv.s_b,
                    };
                    if s.t_in < t_near {
                        let x = (t_near - s.t_in) / (s.t_out - s.t_in);
                        s.s_in += x * (s.s_out - s.s_in);
                        s.t_in = t_near;
                    }
                    s
                })
                .collect(),
            None => self.segments(ray, t_near),
        }
    }

    fn trace_native<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        stop_depth: f64,
        scratch: &mut Scratch,
    ) -> Option<RayAccumulator> {
        let vals = native::point_values(&self.scene)?;
        let mut stats = native::NativeStats::default();
        let ivs = self.native_intervals(ray, t_near, scratch, &mut stats)?;
        let cells = &self.scene.mesh.cells;
        let mut acc = RayAccumulator::default();
        for iv in &ivs {
            let v = if native::is_native_kind(cells.kinds[iv.cell as usize]) {
                native::interval_value(&self.scene, vals, material, ray, iv, t_near, &mut stats)
            } else {
                let (mut ta, mut sa) = (iv.t_a, iv.s_a);
                if ta < t_near {
                    sa += (t_near - ta) / (iv.t_b - ta) * (iv.s_b - sa);
                    ta = t_near;
                }
                material.segment(iv.t_b - ta, sa, iv.s_b)
            };
            acc.add(&v);
            if acc.depth >= stop_depth {
                break;
            }
        }
        self.record_native(&stats);
        Some(acc)
    }

    /// Bytes of memory the prepared structures hold (beyond the mesh).
    pub fn bytes(&self) -> usize {
        let mut b = self.walker.bytes();
        if let Some(p) = &self.parent {
            let (c, t) = (&self.walker.cells, &self.walker.topo);
            b += c.conn.len() * 4 + c.offsets.len() * 4 + c.kinds.len();
            b += p.len() * 4;
            b += t.face_verts.len() * 4
                + t.face_offsets.len() * 4
                + t.face_cells.len() * 8
                + t.face_local.len() * 2
                + t.cell_faces.len() * 4
                + t.cell_face_offsets.len() * 4;
        }
        b
    }

    fn mesh_cell(&self, walk_cell: u32) -> u32 {
        match &self.parent {
            Some(p) => p.get(walk_cell as usize).copied().unwrap_or(walk_cell),
            None => walk_cell,
        }
    }

    fn start_t(&self, ray: &Ray) -> f64 {
        if self.walker.in_bounds(ray.origin) {
            f64::NEG_INFINITY
        } else {
            0.0
        }
    }

    fn point_scalar(&self, v: [u32; 3], w: [f64; 3]) -> f64 {
        match self.scene.scalars {
            Scalars::Point(s) => {
                w[0] * s[v[0] as usize] + w[1] * s[v[1] as usize] + w[2] * s[v[2] as usize]
            }
            Scalars::Cell(_) | Scalars::Constant(_) => 0.0,
        }
    }

    fn to_segment(&self, r: &RawSegment) -> Segment {
        let cell = self.mesh_cell(r.cell);
        let (s_in, s_out) = match self.scene.scalars {
            Scalars::Point(_) => (
                self.point_scalar(r.v_in, r.w_in),
                self.point_scalar(r.v_out, r.w_out),
            ),
            Scalars::Cell(v) => {
                let s = v[cell as usize];
                (s, s)
            }
            Scalars::Constant(s) => (s, s),
        };
        Segment {
            cell,
            t_in: r.t_in,
            t_out: r.t_out,
            s_in,
            s_out,
        }
    }

    /// Calls `f` with the segments of `ray` from depth `t_near` on (clipped
    /// there, scalar interpolated linearly), front to back; stops when `f`
    /// returns false.
    pub fn for_each_segment(
        &self,
        ray: &Ray,
        t_near: f64,
        scratch: &mut Scratch,
        mut f: impl FnMut(&Segment, &RawSegment) -> bool,
    ) {
        let frame = RayFrame::new(ray, self.walker.center, self.walker.radius);
        let t0 = self.start_t(ray);
        self.walker.walk(&frame, t0, scratch, |raw| {
            if raw.t_out <= t_near {
                return true;
            }
            let mut s = self.to_segment(raw);
            if s.t_in < t_near {
                let x = (t_near - s.t_in) / (s.t_out - s.t_in);
                s.s_in += x * (s.s_out - s.s_in);
                s.t_in = t_near;
            }
            f(&s, raw)
        });
    }

    /// All segments of `ray` with `t >= t_near`, in order.
    pub fn segments(&self, ray: &Ray, t_near: f64) -> Vec<Segment> {
        let mut out = Vec::new();
        self.for_each_segment(ray, t_near, &mut Scratch::default(), |s, _| {
            out.push(*s);
            true
        });
        out
    }

    /// Integrates one ray from `t_near` on.
    pub fn trace<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut Scratch,
    ) -> RayAccumulator {
        let acc = RayAccumulator::default();
        let stop_depth = stop_depth(opts);
        if self.model == FieldModel::Native {
            if let Some(acc) = self.trace_native(material, ray, t_near, stop_depth, scratch) {
                return acc;
            }
        }
        self.composite(ray, t_near, stop_depth, scratch, acc, |s, _| {
            material.segment(s.t_out - s.t_in, s.s_in, s.s_out)
        })
    }

    /// Composites onto `acc` the value `value` gives each walk segment of
    /// `ray` from `t_near` on, front to back, until the optical depth
    /// reaches `stop_depth`.
    pub(crate) fn composite(
        &self,
        ray: &Ray,
        t_near: f64,
        stop_depth: f64,
        scratch: &mut Scratch,
        mut acc: RayAccumulator,
        mut value: impl FnMut(&Segment, &RawSegment) -> crate::integrate::SegmentValue,
    ) -> RayAccumulator {
        self.for_each_segment(ray, t_near, scratch, |s, raw| {
            acc.add(&value(s, raw));
            acc.depth < stop_depth
        });
        acc
    }
}

/// A traversal of the mesh by pixel rays: the walk ([`Raycaster`]) or the
/// brute force ([`brute::Brute`]). Each integrates one ray; rendering an
/// image (parallel tiles) is the same for both.
pub trait RayTracer: Sync {
    /// Per-thread scratch of one traversal.
    type Scratch: Default + Send;

    /// Integrates one ray from `t_near` on (the traversal's `trace`).
    fn integrate<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut Self::Scratch,
    ) -> RayAccumulator;

    /// Renders an image through `camera`.
    fn render<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
    ) -> Image {
        self.render_with_progress(material, camera, opts, |_, _| {})
    }

    /// [`RayTracer::render`], calling `progress(done, total)` (in tiles)
    /// from the calling thread about ten times a second while the tiles are
    /// traced on the rayon pool, and once at the end.
    fn render_with_progress<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
        progress: impl FnMut(usize, usize),
    ) -> Image {
        self.render_counting(material, camera, opts, progress).0
    }

    /// [`RayTracer::render_with_progress`], also counting the rays that
    /// stopped early: those whose optical depth reached the termination
    /// depth of `opts.early_termination` (0 when it is off).
    fn render_counting<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
        progress: impl FnMut(usize, usize),
    ) -> (Image, u64) {
        let stop = stop_depth(opts);
        let terminated = std::sync::atomic::AtomicU64::new(0);
        let img = render_tiles(camera, opts, progress, |ray, t_near, scratch| {
            let acc = self.integrate(material, ray, t_near, opts, scratch);
            if acc.depth >= stop {
                terminated.fetch_add(1, Ordering::Relaxed);
            }
            acc.rgba()
        });
        (img, terminated.into_inner())
    }
}

impl RayTracer for Raycaster<'_> {
    type Scratch = Scratch;

    fn integrate<M: RayMaterial>(
        &self,
        material: &M,
        ray: &Ray,
        t_near: f64,
        opts: &RaycastOptions,
        scratch: &mut Scratch,
    ) -> RayAccumulator {
        self.trace(material, ray, t_near, opts, scratch)
    }
}

/// The optical depth at which a ray stops (`opts.early_termination`).
fn stop_depth(opts: &RaycastOptions) -> f64 {
    if opts.early_termination > 0.0 {
        -opts.early_termination.ln()
    } else {
        f64::INFINITY
    }
}

/// The parallel render loop of both traversals: `opts.tile`-square tiles
/// traced on the rayon pool (one scratch `S` per worker) by
/// `trace(ray, t_near, scratch)`, with `t_near` the near plane (0 for
/// orthographic cameras); `progress(done, total)` (in tiles) is called from
/// the calling thread about ten times a second and once at the end.
fn render_tiles<S: Default + Send>(
    camera: &Camera,
    opts: &RaycastOptions,
    mut progress: impl FnMut(usize, usize),
    trace: impl Fn(&Ray, f64, &mut S) -> [f32; 4] + Sync,
) -> Image {
    let (w, h) = (camera.width, camera.height);
    let tile = opts.tile.max(1);
    let tiles_x = w.div_ceil(tile);
    let tiles_y = h.div_ceil(tile);
    let total = (tiles_x * tiles_y) as usize;
    let t_near = if camera.ortho { 0.0 } else { camera.near };
    let done = AtomicUsize::new(0);
    let trace_tiles = || -> Vec<(u32, u32, Vec<[f32; 4]>)> {
        (0..tiles_x * tiles_y)
            .into_par_iter()
            .map_init(S::default, |scratch, k| {
                let (tx, ty) = (k % tiles_x, k / tiles_x);
                let mut px = Vec::with_capacity((tile * tile) as usize);
                for j in ty * tile..((ty + 1) * tile).min(h) {
                    for i in tx * tile..((tx + 1) * tile).min(w) {
                        let ray = camera.pixel_ray(i, j);
                        px.push(trace(&ray, t_near, scratch));
                    }
                }
                done.fetch_add(1, Ordering::Relaxed);
                (tx, ty, px)
            })
            .collect()
    };
    // The tiles are traced on another thread; this one reports progress
    // every 100 ms until they arrive (at once when they are done).
    let tiles = std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        let worker = scope.spawn(move || {
            let _ = tx.send(trace_tiles());
        });
        loop {
            match rx.recv_timeout(std::time::Duration::from_millis(100)) {
                Ok(tiles) => return tiles,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    progress(done.load(Ordering::Relaxed), total)
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    // The worker panicked before sending: pass the panic on.
                    if let Err(panic) = worker.join() {
                        std::panic::resume_unwind(panic);
                    }
                    return Vec::new();
                }
            }
        }
    });
    progress(total, total);
    let mut img = Image::new(w, h);
    for (tx, ty, px) in tiles {
        let mut it = px.into_iter();
        for j in ty * tile..((ty + 1) * tile).min(h) {
            for i in tx * tile..((tx + 1) * tile).min(w) {
                if let Some(p) = it.next() {
                    img.set(i, j, p);
                }
            }
        }
    }
    img
}

/// Renders `scene` through `camera` (validates and prepares the scene, then
/// [`RayTracer::render`]).
pub fn render<M: RayMaterial>(
    scene: &Scene,
    material: &M,
    camera: &Camera,
    opts: &RaycastOptions,
) -> Result<Image, RaycastError> {
    Ok(match opts.traversal {
        Traversal::Walk => Raycaster::new(*scene, opts.model)?.render(material, camera, opts),
        Traversal::Brute => brute::Brute::new(*scene, opts.model)?.render(material, camera, opts),
    })
}

/// Integrates one ray (from its origin on) through `scene`.
pub fn trace_ray<M: RayMaterial>(
    scene: &Scene,
    material: &M,
    ray: &Ray,
    opts: &RaycastOptions,
) -> Result<RayAccumulator, RaycastError> {
    Ok(match opts.traversal {
        Traversal::Walk => {
            let rc = Raycaster::new(*scene, opts.model)?;
            rc.trace(material, ray, 0.0, opts, &mut Scratch::default())
        }
        Traversal::Brute => {
            let b = brute::Brute::new(*scene, opts.model)?;
            b.trace(material, ray, 0.0, opts, &mut Default::default())
        }
    })
}
