//! The reference software ray caster (issue 4).
//!
//! One ray per pixel centre ([`Camera::pixel_ray`]), walked through the cells
//! it crosses by face adjacency ([`walk`]), with exact crossing decisions and
//! a documented tie-breaking rule ([`geometry`]: simulation of simplicity on
//! the ray's origin, canonical edge orientation by point id). Each cell
//! segment is integrated exactly for the chosen [`FieldModel`] and composited
//! front to back in a [`RayAccumulator`]:
//! - [`FieldModel::Faces`] (default): entry and exit on the cell's face
//!   triangles, the scalar linear on each triangle (barycentric) and along the
//!   ray, integrated by `material.segment(l, s_in, s_out)`;
//! - [`FieldModel::Tets`]: the same walk over the consistent
//!   tetrahedralisation (`tetra::tetrahedralize_cell`), whose faces model is
//!   the linear field of each tet;
//! - [`FieldModel::Native`]: the faces walk gives the cell sequence and the
//!   entry/exit depths; inside hexahedra, wedges and pyramids the scalar is
//!   the iso-parametric field ([`native`]). Tets are linear; pentagonal and
//!   hexagonal prisms and general polyhedra fall back to `faces`.
//!   Known simplification: the cell boundary is the triangulated faces
//!   (shared by neighbours), not the bilinear patches; the field is
//!   evaluated (extrapolated) by inverting the map at those points.
//!
//! Cell data uses the homogeneous integral `segment(l, s, s)`; no field means
//! a constant scalar. The near plane is at the eye: only `t >= camera.near`
//! (perspective) or `t >= 0` (orthographic) is integrated; when the ray
//! origin is inside the mesh's bounding box the walk starts from the line's
//! first entry behind the eye and clips. Rendering is parallel over 16x16
//! tiles (rayon) with early termination at transmittance
//! [`RAY_TERMINATION_TRANSMITTANCE`] (`RaycastOptions::early_termination`).

pub mod bvh;
pub mod geometry;
pub mod native;
pub mod walk;

use std::borrow::Cow;

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use thiserror::Error;

use crate::camera::{Camera, Ray};
use crate::image::Image;
use crate::integrate::{RayAccumulator, RayMaterial};
use crate::mesh::tetra::tetrahedralize_cell;
use crate::mesh::topology::Topology;
use crate::mesh::{CellKind, Cells, Mesh};
use crate::numeric::tolerance::RAY_TERMINATION_TRANSMITTANCE;
use geometry::RayFrame;
use walk::{RawSegment, Scratch, WalkMesh};

/// Which scalar field is integrated inside a cell (DESIGN.md, Conventions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
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

/// Ray caster options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RaycastOptions {
    pub model: FieldModel,
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
        })
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
        let mut acc = RayAccumulator::default();
        let stop_depth = if opts.early_termination > 0.0 {
            -opts.early_termination.ln()
        } else {
            f64::INFINITY
        };
        let native = self.model == FieldModel::Native;
        self.for_each_segment(ray, t_near, scratch, |s, _| {
            let l = s.t_out - s.t_in;
            let v = if native {
                native::segment_value(self.scene, material, ray, s)
            } else {
                material.segment(l, s.s_in, s.s_out)
            };
            acc.add(&v);
            acc.depth < stop_depth
        });
        acc
    }

    /// Renders an image through `camera`.
    pub fn render<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
    ) -> Image {
        self.render_with_progress(material, camera, opts, |_, _| {})
    }

    /// [`Raycaster::render`], calling `progress(done, total)` (in tiles)
    /// from the calling thread about ten times a second while the tiles are
    /// traced on the rayon pool, and once at the end.
    pub fn render_with_progress<M: RayMaterial>(
        &self,
        material: &M,
        camera: &Camera,
        opts: &RaycastOptions,
        mut progress: impl FnMut(usize, usize),
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
                .map_init(Scratch::default, |scratch, k| {
                    let (tx, ty) = (k % tiles_x, k / tiles_x);
                    let mut px = Vec::with_capacity((tile * tile) as usize);
                    for j in ty * tile..((ty + 1) * tile).min(h) {
                        for i in tx * tile..((tx + 1) * tile).min(w) {
                            let ray = camera.pixel_ray(i, j);
                            px.push(self.trace(material, &ray, t_near, opts, scratch).rgba());
                        }
                    }
                    done.fetch_add(1, Ordering::Relaxed);
                    (tx, ty, px)
                })
                .collect()
        };
        let tiles = std::thread::scope(|scope| {
            let worker = scope.spawn(trace_tiles);
            while !worker.is_finished() {
                progress(done.load(Ordering::Relaxed), total);
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            worker.join()
        });
        let tiles = match tiles {
            Ok(t) => t,
            Err(panic) => std::panic::resume_unwind(panic),
        };
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
}

/// Renders `scene` through `camera` (validates and prepares the scene, then
/// [`Raycaster::render`]).
pub fn render<M: RayMaterial>(
    scene: &Scene,
    material: &M,
    camera: &Camera,
    opts: &RaycastOptions,
) -> Result<Image, RaycastError> {
    Ok(Raycaster::new(*scene, opts.model)?.render(material, camera, opts))
}

/// Integrates one ray (from its origin on) through `scene`.
pub fn trace_ray<M: RayMaterial>(
    scene: &Scene,
    material: &M,
    ray: &Ray,
    opts: &RaycastOptions,
) -> Result<RayAccumulator, RaycastError> {
    let rc = Raycaster::new(*scene, opts.model)?;
    Ok(rc.trace(material, ray, 0.0, opts, &mut Scratch::default()))
}
