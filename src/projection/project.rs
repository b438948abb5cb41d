//! [`Projector`]: one convex piece and a camera in, screen regions out.
//!
//! Steps (all scratch buffers live in the projector, so steady-state calls do
//! not allocate):
//! 1. clip the piece at the near plane when it reaches it (`clip`);
//! 2. project every point with [`Camera::view_to_pixel`] (a pure function of
//!    the view position: shared vertices of neighbouring pieces are
//!    bit-identical) and merge points with identical pixel positions;
//! 3. classify each boundary triangle by the exact orientation of its
//!    projection: front (clockwise in pixel coordinates, whose y grows
//!    downwards), back (counter-clockwise) or edge-on (skipped: zero area);
//! 4. build the arrangement of the front and back triangles' edges
//!    (`arrangement`), each piece remembering the front/back triangle on
//!    each of its sides;
//! 5. faces of the subdivision with positive area are the regions; each gets
//!    its front and back triangle from a bounding half-edge that lies on a
//!    front (back) edge, or, when it has none, from a neighbour across an
//!    edge that is not a front (back) edge (a region inside a triangle);
//! 6. one [`RegionVertex`] per subdivision vertex: front and back values by
//!    evaluating the region's triangles at the vertex (the corner's own data
//!    when the vertex is that corner, so profile vertices get `l = 0`
//!    exactly); regions are fan-triangulated, skipping triangles whose exact
//!    orientation is not positive (zero area).
//! 7. perspective only: conforming midpoint refinement (`refine`) until the
//!    screen-space interpolation error bound holds.

use glam::DVec2;

use super::arrangement::{is_outer, Arrangement, Piece};
use super::clip::{ClipValue, Clipper};
use super::polyhedron::Polyhedron;
use super::subdivision::NIL;
use super::{FaceTri, Projected, ProjectionError, RegionVertex, ViewMap};
use crate::camera::Camera;
use crate::numeric::predicates::{orient2d, Side};
use crate::numeric::tolerance::NEAR_CLIP_SCALE;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Facing {
    Front,
    Back,
    EdgeOn,
}

/// Reusable projection state (see module docs).
#[derive(Clone, Debug)]
pub struct Projector {
    /// Run [`Arrangement::sanity_check`] after every inserted edge and fail
    /// with [`ProjectionError::Topology`] on the first violation (tests).
    pub check_each_insertion: bool,
    /// Refine regions for perspective views (on by default).
    pub perspective_refine: bool,
    /// Maximum refinement depth for perspective views.
    pub max_refine_depth: u32,
    clipper: Clipper,
    clipped: Polyhedron,
    arr: Arrangement,
    pix: Vec<DVec2>,
    canon: Vec<u32>,
    facing: Vec<Facing>,
    segs: Vec<Piece>,
    mark: Vec<bool>,
    face_of: Vec<u32>,
    face_start: Vec<u32>,
    cycles: Vec<(u32, f64)>,
    face_fb: Vec<[u32; 2]>,
    vmap: Vec<u32>,
    on_hull: Vec<bool>,
    refine: super::refine::RefineScratch,
}

impl Default for Projector {
    fn default() -> Self {
        Projector {
            check_each_insertion: false,
            perspective_refine: true,
            max_refine_depth: 6,
            clipper: Clipper::default(),
            clipped: Polyhedron::default(),
            arr: Arrangement::default(),
            pix: Vec::new(),
            canon: Vec::new(),
            facing: Vec::new(),
            segs: Vec::new(),
            mark: Vec::new(),
            face_of: Vec::new(),
            face_start: Vec::new(),
            cycles: Vec::new(),
            face_fb: Vec::new(),
            vmap: Vec::new(),
            on_hull: Vec::new(),
            refine: Default::default(),
        }
    }
}

impl Projector {
    /// A projector with default settings.
    pub fn new() -> Projector {
        Projector::default()
    }

    /// The subdivision built by the last call (for inspection and tests).
    pub fn arrangement(&self) -> &Arrangement {
        &self.arr
    }

    /// Projects `poly` for `camera` into `out` (see the module docs).
    pub fn project(
        &mut self,
        poly: &Polyhedron,
        camera: &Camera,
        out: &mut Projected,
    ) -> Result<(), ProjectionError> {
        poly.validate()?;
        out.clear();
        out.view = ViewMap::of(camera);
        let zc = camera.near * NEAR_CLIP_SCALE;
        let needs_clip = poly.points.iter().any(|p| p.z < zc);
        if needs_clip {
            let mut clipped = std::mem::take(&mut self.clipped);
            let kept = self
                .clipper
                .clip(poly, ClipValue::Depth, zc, f64::INFINITY, &mut clipped);
            let r = match kept {
                Ok(true) => self.project_inner(&clipped, camera, out),
                Ok(false) => Ok(()),
                Err(e) => Err(e),
            };
            self.clipped = clipped;
            r
        } else {
            self.project_inner(poly, camera, out)
        }
    }

    fn project_inner(
        &mut self,
        poly: &Polyhedron,
        camera: &Camera,
        out: &mut Projected,
    ) -> Result<(), ProjectionError> {
        let n = poly.points.len();
        // 2. Pixel positions and merged ids.
        self.pix.clear();
        for &p in &poly.points {
            let (px, py, _) = camera
                .view_to_pixel(p)
                .ok_or(ProjectionError::BehindNearPlane)?;
            if !(px.is_finite() && py.is_finite()) {
                return Err(ProjectionError::NonFinite);
            }
            self.pix.push(DVec2::new(px, py));
        }
        self.canon.clear();
        for i in 0..n {
            let c = (0..i).find(|&j| self.pix[j] == self.pix[i]).unwrap_or(i);
            self.canon.push(c as u32);
        }
        // 3. Facing of each triangle.
        self.facing.clear();
        for t in &poly.triangles {
            let [a, b, c] = t.map(|i| self.pix[i as usize]);
            self.facing.push(match orient2d(a, b, c) {
                Side::Negative => Facing::Front,
                Side::Positive => Facing::Back,
                Side::On => Facing::EdgeOn,
            });
        }
        // 4. Segments with their side triangles, deduplicated.
        self.segs.clear();
        for (ti, t) in poly.triangles.iter().enumerate() {
            let f = self.facing[ti];
            if f == Facing::EdgeOn {
                continue;
            }
            for k in 0..3 {
                let (u, v) = (
                    self.canon[t[k] as usize],
                    self.canon[t[(k + 1) % 3] as usize],
                );
                if u == v {
                    continue;
                }
                // Front triangles are clockwise here: interior on the right
                // of u -> v; back triangles on the left.
                let mut side = [NIL; 4];
                match f {
                    Facing::Front => side[1] = ti as u32,
                    _ => side[2] = ti as u32,
                }
                let piece = if u < v {
                    Piece { a: u, b: v, side }
                } else {
                    Piece {
                        a: v,
                        b: u,
                        side: [side[1], side[0], side[3], side[2]],
                    }
                };
                if let Some(q) = self
                    .segs
                    .iter_mut()
                    .find(|q| q.a == piece.a && q.b == piece.b)
                {
                    for s in 0..4 {
                        if q.side[s] == NIL {
                            q.side[s] = piece.side[s];
                        }
                    }
                } else {
                    self.segs.push(piece);
                }
            }
        }
        if self.segs.is_empty() {
            return Ok(()); // everything edge-on: zero area
        }
        // Insert one by one.
        self.arr.prepare(&self.pix, &self.segs);
        while self.arr.insert_next() {
            if self.check_each_insertion {
                self.arr.sanity_check()?;
            }
        }
        // 5. Faces.
        self.trace_regions();
        self.assign_front_back()?;
        // 6. Output.
        self.emit(poly, out);
        // 7. Perspective refinement.
        if !camera.ortho && self.perspective_refine {
            let (smin, smax) = poly
                .scalars
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| {
                    (a.min(s), b.max(s))
                });
            let (lo, hi) = poly.points.iter().fold(
                (
                    glam::DVec3::splat(f64::INFINITY),
                    glam::DVec3::splat(f64::NEG_INFINITY),
                ),
                |(a, b), &p| (a.min(p), b.max(p)),
            );
            // A piece whose scalars are constant up to rounding (cell data)
            // has no scalar interpolation error: rounding noise in the
            // interpolated values must not drive the refinement.
            let srange = smax - smin;
            let srange = if srange <= 1e-12 * smax.abs().max(smin.abs()) {
                f64::INFINITY
            } else {
                srange
            };
            super::refine::refine_perspective(
                out,
                srange,
                (hi - lo).length(),
                self.max_refine_depth,
                &mut self.refine,
            );
        }
        Ok(())
    }

    /// Traces face cycles; bounded faces get ids (see
    /// [`super::arrangement::is_outer`]).
    fn trace_regions(&mut self) {
        let sub = &self.arr.sub;
        let nh = sub.half_edge_count();
        self.face_of.clear();
        self.face_of.resize(nh, NIL);
        self.face_start.clear();
        self.cycles.clear();
        let arr = &self.arr;
        let cycles = &mut self.cycles;
        sub.trace_faces(&mut self.mark, |h0| cycles.push((h0, arr.cycle_area(h0))));
        let amin = self.cycles.iter().fold(0.0, |m: f64, c| m.min(c.1));
        for &(h0, a) in &self.cycles {
            if is_outer(a, amin) {
                continue;
            }
            let id = self.face_start.len() as u32;
            self.face_start.push(h0);
            let mut h = h0;
            loop {
                self.face_of[h as usize] = id;
                h = sub.next(h);
                if h == h0 || self.face_of[h as usize] == id {
                    break;
                }
            }
        }
    }

    /// Front and back triangle of every bounded face.
    fn assign_front_back(&mut self) -> Result<(), ProjectionError> {
        let sub = &self.arr.sub;
        let nf = self.face_start.len();
        self.face_fb.clear();
        self.face_fb.resize(nf, [NIL, NIL]);
        // Side slots of half-edge h for the face on its left: [front, back].
        let slots = |h: u32| -> [u32; 2] {
            let p = self.arr.pieces[self.arr.edge_piece[(h >> 1) as usize] as usize];
            if h & 1 == 0 {
                [p.side[0], p.side[2]]
            } else {
                [p.side[1], p.side[3]]
            }
        };
        for h in 0..sub.half_edge_count() as u32 {
            let f = self.face_of[h as usize];
            if f == NIL {
                continue;
            }
            let s = slots(h);
            for (slot, &v) in self.face_fb[f as usize].iter_mut().zip(&s) {
                if *slot == NIL {
                    *slot = v;
                }
            }
        }
        // Propagate across edges that are not front (back) edges.
        loop {
            let mut changed = false;
            let mut missing = false;
            for h in 0..sub.half_edge_count() as u32 {
                let f = self.face_of[h as usize];
                let g = self.face_of[(h ^ 1) as usize];
                if f == NIL || g == NIL {
                    continue;
                }
                let (sf, sg) = (slots(h), slots(h ^ 1));
                for k in 0..2 {
                    if self.face_fb[f as usize][k] == NIL {
                        missing = true;
                        let other = self.face_fb[g as usize][k];
                        if sf[k] == NIL && sg[k] == NIL && other != NIL {
                            self.face_fb[f as usize][k] = other;
                            changed = true;
                        }
                    }
                }
            }
            if !missing {
                return Ok(());
            }
            if !changed {
                return Err(ProjectionError::UnassignedRegion);
            }
        }
    }

    /// Writes vertices, regions and fan triangles.
    fn emit(&mut self, poly: &Polyhedron, out: &mut Projected) {
        let sub = &self.arr.sub;
        let nv = sub.vertex_count();
        self.vmap.clear();
        self.vmap.resize(nv, NIL);
        // Vertices on the outer boundary.
        self.on_hull.clear();
        self.on_hull.resize(nv, false);
        for h in 0..sub.half_edge_count() as u32 {
            if self.face_of[h as usize] == NIL {
                self.on_hull[sub.origin(h) as usize] = true;
            }
        }
        for (f, &h0) in self.face_start.iter().enumerate() {
            let [ft, bt] = self.face_fb[f];
            let front = FaceTri::new(poly, &self.pix, ft);
            let back = FaceTri::new(poly, &self.pix, bt);
            let r = out.push_region();
            out.region_faces.push([front, back]);
            let mut h = h0;
            let mut k = 0;
            loop {
                let v = sub.origin(h);
                if self.vmap[v as usize] == NIL {
                    self.vmap[v as usize] = out.vertices.len() as u32;
                    let p = self.arr.pos[v as usize];
                    let rv = RegionVertex::evaluate(
                        &out.view,
                        &front,
                        &back,
                        p,
                        self.on_hull[v as usize],
                    );
                    out.vertices.push(rv);
                }
                out.regions[r].push(self.vmap[v as usize]);
                h = sub.next(h);
                k += 1;
                if h == h0 || k > sub.half_edge_count() {
                    break;
                }
            }
        }
        out.triangulate_regions();
    }
}
