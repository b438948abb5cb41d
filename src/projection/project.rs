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
//! 4. fast path ([`Projector::fast_path`]): when every point is distinct
//!    and no triangle is edge-on, a tetrahedron's regions come straight
//!    from its Shirley-Tuchman class (`tet`); other pieces that the exact
//!    checks of `overlay` find in general position get the intersections
//!    of a front and a back triangle, traced directly (no arrangement);
//!    anything else declines to the general path, step 5;
//! 5. general path: build the arrangement of the front and back triangles'
//!    edges (`arrangement`), each piece remembering the front/back triangle
//!    on each of its sides; faces of the subdivision with positive area are
//!    the regions; each gets its front and back triangle from a bounding
//!    half-edge that lies on a front (back) edge, or, when it has none, from
//!    a neighbour across an edge that is not a front (back) edge (a region
//!    inside a triangle);
//! 6. (both paths, from the regions as vertex lists) one [`RegionVertex`]
//!    per subdivision vertex (or point and crossing of the fast path):
//!    front and back values by
//!    evaluating, at the vertex, the widest front and the widest back
//!    triangle among the regions around it ([`FaceTri::width`]: a face seen
//!    nearly edge-on projects to a sliver whose plane, evaluated through
//!    rounded positions, gives meaningless depths; every region around the
//!    vertex holds it, so any of them gives the same exact value) -- the
//!    corner's own data when the vertex is that corner, so profile vertices
//!    get `l = 0` exactly. The fast path finds an original point's
//!    triangles without the search, from what it knows of the vertex
//!    ([`VertexKind`]: a corner of every triangle of its own facing around
//!    it, strictly inside one of the other facing), and so picks the same
//!    ones; a crossing of a front and a back edge takes its front (back)
//!    values along the front (back) edge, between the edge's ends, which is
//!    exact and well conditioned even when a triangle beside the edge is a
//!    sliver; each vertex records where its values came from (a point, a
//!    triangle's plane, an edge: [`super::KeptRegions`] evaluates them
//!    again for new scalars); regions are fan-triangulated, skipping triangles
//!    whose exact orientation is not positive (zero area); with
//!    [`Projector::clip_to_image`] the regions are then clipped to the image
//!    rectangle plus a margin (near-plane caps project ~1e9 pixels away;
//!    `window`);
//! 7. perspective only: conforming midpoint refinement (`refine`) until the
//!    screen-space interpolation error bound holds;
//! 8. with [`Projector::cull_to_pixels`] (renderers), what cannot colour a
//!    pixel centre is left out (`coverage`): the whole piece right after
//!    step 2 when its bounding box holds no centre, and triangles that
//!    contain none after step 6 and again after step 7 (refinement decides
//!    per edge from the edge's own vertices, so dropping a neighbour
//!    changes nothing in what is kept).

use glam::DVec2;

use super::arrangement::{is_outer, Arrangement, Segment};
use super::clip::{ClipValue, Clipper};
use super::coverage::PixelGrid;
use super::kept::{KeptRegions, ValueSource, VertexSource};
use super::overlay::Overlay;
use super::polyhedron::Polyhedron;
use super::subdivision::NIL;
use super::tet::TetRegions;
use super::window::WindowScratch;
use super::{FaceTri, Facing, Projected, ProjectionError, RegionVertex, VertexKind, ViewMap};
use crate::camera::Camera;
use crate::numeric::predicates::{orient2d, Side};
use crate::numeric::tolerance::CONSTANT_SCALAR_REL;
use crate::numeric::tolerance::NEAR_CLIP_SCALE;

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
    /// Clip the regions to the image rectangle grown by
    /// [`IMAGE_CLIP_MARGIN_PX`](crate::numeric::tolerance::IMAGE_CLIP_MARGIN_PX)
    /// (off by default: regions then tile the whole silhouette). Renderers turn it on: in perspective views a piece cut
    /// by the near plane projects to regions reaching ~1e9 pixels away,
    /// across which screen-space interpolation is wrong on screen whatever
    /// the (depth-limited) refinement does; clipped regions are at most
    /// image-sized. New vertices get exact values from their region's
    /// triangles, like refinement midpoints.
    pub clip_to_image: bool,
    /// Leave out what cannot colour a pixel centre of the image
    /// ([`super::coverage`]): a piece whose projected points' bounding box
    /// holds no centre yields nothing, and triangles that contain none are
    /// dropped (before and after the perspective refinement). Off by
    /// default (regions then tile the silhouette); renderers turn it on.
    pub cull_to_pixels: bool,
    /// Take the fast path (`overlay`) for pieces in general position (on by
    /// default; the general path, through the arrangement, is always taken
    /// when [`Self::check_each_insertion`] is set).
    pub fast_path: bool,
    /// Whether the last call took the fast path (tests).
    pub(crate) took_fast_path: bool,
    /// Give fast-path vertices that are original points their values by the
    /// general path's search among the regions around them, not by their
    /// [`VertexKind`] (tests: both must give the same bits; crossings are
    /// valued along their edges either way).
    pub(crate) vertex_faces_by_search: bool,
    clipper: Clipper,
    clipped: Polyhedron,
    /// Whether the last call projected `clipped` (the piece reached the
    /// near plane).
    used_clipped: bool,
    arr: Arrangement,
    pub(super) overlay: Overlay,
    tet: TetRegions,
    pix: Vec<DVec2>,
    canon: Vec<u32>,
    facing: Vec<Facing>,
    segs: Vec<Segment>,
    mark: Vec<bool>,
    /// Half-edges of the unbounded face's cycle.
    outer: Vec<bool>,
    face_of: Vec<u32>,
    face_start: Vec<u32>,
    /// Vertices of each bounded face (general path), flat.
    region_verts: Vec<u32>,
    region_start: Vec<u32>,
    cycles: Vec<(u32, f64)>,
    face_fb: Vec<[u32; 2]>,
    on_hull: Vec<bool>,
    emit: EmitScratch,
    refine: super::refine::RefineScratch,
    window: WindowScratch,
    /// The last camera's [`ViewMap`] and what it was computed from (its
    /// half extents take a `tan`; cameras repeat from piece to piece).
    view: Option<(ViewKey, ViewMap)>,
}

/// What [`ViewMap::of`] reads of a camera.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ViewKey {
    ortho: bool,
    view_angle: f64,
    parallel_scale: f64,
    width: u32,
    height: u32,
}

impl ViewKey {
    fn of(c: &Camera) -> ViewKey {
        ViewKey {
            ortho: c.ortho,
            view_angle: c.view_angle,
            parallel_scale: c.parallel_scale,
            width: c.width,
            height: c.height,
        }
    }
}

impl Default for Projector {
    fn default() -> Self {
        Projector {
            check_each_insertion: false,
            perspective_refine: true,
            max_refine_depth: 6,
            clip_to_image: false,
            cull_to_pixels: false,
            fast_path: true,
            took_fast_path: false,
            vertex_faces_by_search: false,
            clipper: Clipper::default(),
            clipped: Polyhedron::default(),
            used_clipped: false,
            arr: Arrangement::default(),
            overlay: Overlay::default(),
            tet: TetRegions::default(),
            pix: Vec::new(),
            canon: Vec::new(),
            facing: Vec::new(),
            segs: Vec::new(),
            mark: Vec::new(),
            outer: Vec::new(),
            face_of: Vec::new(),
            face_start: Vec::new(),
            region_verts: Vec::new(),
            region_start: Vec::new(),
            cycles: Vec::new(),
            face_fb: Vec::new(),
            on_hull: Vec::new(),
            emit: EmitScratch::default(),
            refine: Default::default(),
            window: Default::default(),
            view: None,
        }
    }
}

impl Projector {
    /// A projector with default settings.
    pub fn new() -> Projector {
        Projector::default()
    }

    /// The subdivision built by the last call that took the general path
    /// (for inspection and tests; see [`Self::fast_path`]).
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
        self.project_with(poly, camera, None, false, out)
            .map(|_| ())
    }

    /// [`Self::project`] with regions kept across frames whose scalars
    /// change and nothing else ([`KeptRegions`]): with `kept` (which must
    /// hold `poly`'s geometry, [`KeptRegions::holds`], projected for this
    /// camera by a projector with these settings) steps 2-6 are not run
    /// again: their regions take `poly`'s scalars, and the steps that
    /// follow run as always. Otherwise, with `keep`, what steps 2-6 found
    /// is returned, to be kept, where they found regions. The result is
    /// the same, bit for bit, either way.
    pub fn project_with(
        &mut self,
        poly: &Polyhedron,
        camera: &Camera,
        kept: Option<&KeptRegions>,
        keep: bool,
        out: &mut Projected,
    ) -> Result<Option<KeptRegions>, ProjectionError> {
        poly.validate()?;
        self.took_fast_path = false;
        out.clear();
        out.view = match self.view {
            Some((key, view)) if key == ViewKey::of(camera) => view,
            _ => {
                let view = ViewMap::of(camera);
                self.view = Some((ViewKey::of(camera), view));
                view
            }
        };
        let zc = camera.near * NEAR_CLIP_SCALE;
        let needs_clip = poly.points.iter().any(|p| p.z < zc);
        self.used_clipped = needs_clip;
        if needs_clip {
            let mut clipped = std::mem::take(&mut self.clipped);
            let beyond = self
                .clipper
                .clip(poly, ClipValue::Depth, zc, f64::INFINITY, &mut clipped);
            let r = match beyond {
                Ok(true) => self.project_part(poly, &clipped, camera, kept, keep, out),
                Ok(false) => Ok(None),
                Err(e) => Err(e),
            };
            self.clipped = clipped;
            r
        } else {
            self.project_part(poly, poly, camera, kept, keep, out)
        }
    }

    /// Steps 2-8 for `piece` (`poly`, or its part beyond the near plane),
    /// steps 2-6 taken from `kept` when given.
    fn project_part(
        &mut self,
        poly: &Polyhedron,
        piece: &Polyhedron,
        camera: &Camera,
        kept: Option<&KeptRegions>,
        keep: bool,
        out: &mut Projected,
    ) -> Result<Option<KeptRegions>, ProjectionError> {
        let (emitted, fresh) = match kept {
            Some(k) => {
                self.took_fast_path = k.fast_path();
                k.restore(piece, out);
                (true, None)
            }
            None => {
                let emitted = self.regions(piece, camera, out)?;
                // A piece without regions (its pixel box holds no centre,
                // or it is edge-on) is as quick to project again.
                let fresh = (keep && emitted)
                    .then(|| KeptRegions::new(poly, &self.pix, out, self.took_fast_path));
                (emitted, fresh)
            }
        };
        if emitted {
            self.finish(piece, camera, out);
        }
        Ok(fresh)
    }

    /// The polyhedron the last [`Self::project`] of `poly` projected:
    /// `poly` itself, or its part beyond the near plane. The face indices
    /// of the result ([`Projected::faces`], [`Projected::region_faces`])
    /// are this one's triangles.
    pub fn projected_piece<'a>(&'a self, poly: &'a Polyhedron) -> &'a Polyhedron {
        if self.used_clipped {
            &self.clipped
        } else {
            poly
        }
    }

    /// Steps 2-6: whether `poly` has regions that can reach a pixel
    /// centre (written to `out`).
    fn regions(
        &mut self,
        poly: &Polyhedron,
        camera: &Camera,
        out: &mut Projected,
    ) -> Result<bool, ProjectionError> {
        let n = poly.points.len();
        // 2. Pixel positions and merged ids.
        self.pix.clear();
        let extent = (out.view.half_width, out.view.half_height);
        for &p in &poly.points {
            let (px, py, _) = camera
                .view_to_pixel_with(p, extent)
                .ok_or(ProjectionError::BehindNearPlane)?;
            if !(px.is_finite() && py.is_finite()) {
                return Err(ProjectionError::NonFinite);
            }
            self.pix.push(DVec2::new(px, py));
        }
        let grid = PixelGrid::new(camera.width, camera.height);
        if self.cull_to_pixels {
            let (lo, hi) = self.pix.iter().fold(
                (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            );
            if !grid.box_reaches(lo, hi) {
                return Ok(false); // draws no pixel
            }
        }
        self.canon.clear();
        let mut distinct = true;
        for i in 0..n {
            let c = (0..i).find(|&j| self.pix[j] == self.pix[i]).unwrap_or(i);
            distinct &= c == i;
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
        let fast = distinct && self.fast_path && !self.check_each_insertion;
        let tet = fast && n == 4 && self.tet.build(&self.pix, &poly.triangles, &self.facing);
        self.took_fast_path =
            tet || (fast && self.overlay.build(&self.pix, &poly.triangles, &self.facing));
        if self.took_fast_path {
            // 4. Regions of a tetrahedron (`tet`) or another piece
            // (`overlay`) in general position.
            let mut regions = if tet {
                Regions::of_tet(&self.tet)
            } else {
                Regions::of_overlay(&self.overlay)
            };
            regions.search = self.vertex_faces_by_search;
            emit(poly, &self.pix, regions, true, &mut self.emit, out);
        } else {
            self.general_regions(poly, out)?;
        }
        // Empty: everything edge-on, zero area.
        Ok(!out.regions.is_empty())
    }

    /// Steps 7-8 and the window clip after the regions of `poly`.
    fn finish(&mut self, poly: &Polyhedron, camera: &Camera, out: &mut Projected) {
        let grid = PixelGrid::new(camera.width, camera.height);
        if self.clip_to_image {
            self.window.clip(out);
        }
        if self.cull_to_pixels {
            out.cull_to_pixels(&grid);
        }
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
            let srange = if srange <= CONSTANT_SCALAR_REL * smax.abs().max(smin.abs()) {
                f64::INFINITY
            } else {
                srange
            };
            let before = out.triangles.len();
            super::refine::refine_perspective(
                out,
                srange,
                (hi - lo).length(),
                self.max_refine_depth,
                &mut self.refine,
            );
            if self.cull_to_pixels && out.triangles.len() != before {
                out.cull_to_pixels(&grid);
            }
        }
    }

    /// Steps 5-6 through the arrangement (any piece, degenerate views
    /// included).
    fn general_regions(
        &mut self,
        poly: &Polyhedron,
        out: &mut Projected,
    ) -> Result<(), ProjectionError> {
        // 5. Segments with their side triangles, deduplicated.
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
                    Segment { a: u, b: v, side }
                } else {
                    Segment {
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
        // Faces.
        self.trace_regions();
        self.assign_front_back()?;
        // Vertices on the outer boundary.
        let sub = &self.arr.sub;
        self.on_hull.clear();
        self.on_hull.resize(sub.vertex_count(), false);
        for h in 0..sub.half_edge_count() as u32 {
            if self.face_of[h as usize] == NIL {
                self.on_hull[sub.origin(h) as usize] = true;
            }
        }
        // 6. Output.
        let regions = Regions {
            pos: &self.arr.pos,
            on_hull: &self.on_hull,
            verts: &self.region_verts,
            start: &self.region_start,
            faces: &self.face_fb,
            kinds: &[],
            search: true,
        };
        emit(poly, &self.pix, regions, false, &mut self.emit, out);
        Ok(())
    }

    /// Traces face cycles; bounded faces get ids: every cycle except the
    /// unbounded face's, found exactly ([`Arrangement::outer_half_edge`]),
    /// and except any other clearly negative one (a second component, a bug;
    /// `arrangement::is_outer`).
    fn trace_regions(&mut self) {
        let sub = &self.arr.sub;
        let nh = sub.half_edge_count();
        self.face_of.clear();
        self.face_of.resize(nh, NIL);
        self.face_start.clear();
        self.region_verts.clear();
        self.region_start.clear();
        self.region_start.push(0);
        self.cycles.clear();
        let arr = &self.arr;
        let cycles = &mut self.cycles;
        sub.trace_faces(&mut self.mark, |h0| cycles.push((h0, arr.cycle_area(h0))));
        let amin = self.cycles.iter().fold(0.0, |m: f64, c| m.min(c.1));
        let mut outer = std::mem::take(&mut self.outer);
        self.arr.outer_cycle(&mut outer);
        for &(h0, a) in &self.cycles {
            if outer[h0 as usize] || is_outer(a, amin) {
                continue;
            }
            let id = self.face_start.len() as u32;
            self.face_start.push(h0);
            let mut h = h0;
            loop {
                self.face_of[h as usize] = id;
                self.region_verts.push(sub.origin(h));
                h = sub.next(h);
                if h == h0 || self.face_of[h as usize] == id {
                    break;
                }
            }
            self.region_start.push(self.region_verts.len() as u32);
        }
        self.outer = outer;
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
}

/// Scratch of [`emit`].
#[derive(Clone, Debug, Default)]
struct EmitScratch {
    vmap: Vec<u32>,
    /// Per subdivision vertex, for its front and back values: the boundary
    /// triangle (of a region around it) that is widest, and that width
    /// (general path).
    best: Vec<[(u32, f64); 2]>,
    /// Per boundary triangle: its [`FaceTri`] and width (in the fast path,
    /// only when there are crossings).
    faces: Vec<FaceTri>,
    widths: Vec<f64>,
}

/// Regions as lists of subdivision vertices, with their front and back
/// triangles.
struct Regions<'a> {
    /// Position of every vertex.
    pos: &'a [DVec2],
    /// Vertices on the outer boundary (missing entries: not).
    on_hull: &'a [bool],
    /// Vertices of region `r`: `verts[start[r]..start[r + 1]]`, CCW.
    verts: &'a [u32],
    start: &'a [u32],
    /// Front and back triangle of each region.
    faces: &'a [[u32; 2]],
    /// What the fast path knows of each vertex (empty: the general path,
    /// search the regions around each vertex).
    kinds: &'a [VertexKind],
    /// Whether original points take the search (the general path; the
    /// fast path's own check in tests) even with `kinds`.
    search: bool,
}

impl<'a> Regions<'a> {
    /// The regions of a tetrahedron in general position.
    fn of_tet(t: &'a TetRegions) -> Regions<'a> {
        Regions {
            pos: &t.pos,
            on_hull: &t.on_hull,
            verts: &t.verts,
            start: &t.start,
            faces: &t.faces,
            kinds: &t.kinds,
            search: false,
        }
    }

    /// The regions the overlay traced.
    fn of_overlay(o: &'a Overlay) -> Regions<'a> {
        Regions {
            pos: &o.pos,
            on_hull: &o.on_hull,
            verts: &o.region_verts,
            start: &o.region_start,
            faces: &o.face_fb,
            kinds: &o.kinds,
            search: false,
        }
    }
}

/// Writes vertices, regions and fan triangles (step 6 of the module docs).
/// `fast`: the regions are a fast path's (a piece in general position),
/// whose outline is the silhouette ([`Projected::outline_profile`]).
fn emit(
    poly: &Polyhedron,
    pix: &[DVec2],
    regions: Regions,
    fast: bool,
    scratch: &mut EmitScratch,
    out: &mut Projected,
) {
    let EmitScratch {
        vmap,
        best,
        faces,
        widths,
    } = scratch;
    // Each boundary triangle as seen on screen, once.
    faces.clear();
    faces.extend((0..poly.triangles.len() as u32).map(|t| FaceTri::new(poly, pix, t)));
    widths.clear();
    let nv = regions.pos.len();
    vmap.clear();
    vmap.resize(nv, NIL);
    let verts = |f: usize| &regions.verts[regions.start[f] as usize..regions.start[f + 1] as usize];
    out.region_faces.extend_from_slice(regions.faces);
    if regions.search {
        // Every region around a vertex holds it under its front and back
        // triangles, whose planes all give the vertex's values; take them
        // from the widest ones (best conditioned, `FaceTri::width`), never
        // from a sliver left by a face seen (nearly) edge-on. (Regions are
        // visited in order and only a strictly wider triangle replaces one:
        // ties go to the first region's.)
        widths.extend(faces.iter().map(FaceTri::width));
        best.clear();
        best.resize(nv, [(NIL, -1.0); 2]);
        for (f, &ft) in regions.faces.iter().enumerate() {
            let w = ft.map(|t| widths[t as usize]);
            for &v in verts(f) {
                let best = &mut best[v as usize];
                for s in 0..2 {
                    if w[s] > best[s].1 {
                        best[s] = (ft[s], w[s]);
                    }
                }
            }
        }
    }
    let view = out.view;
    let mut profile_hull = true;
    for (f, &ft) in regions.faces.iter().enumerate() {
        for &v in verts(f) {
            let mut id = vmap[v as usize];
            if id == NIL {
                id = out.vertices.len() as u32;
                vmap[v as usize] = id;
                let q = regions.pos[v as usize];
                let on_hull = regions.on_hull.get(v as usize).copied().unwrap_or(false);
                let by_kind = regions
                    .kinds
                    .get(v as usize)
                    .is_some_and(|k| !regions.search || matches!(k, VertexKind::Crossing { .. }));
                let sources = if by_kind {
                    fast_sources(ft, v, regions.kinds)
                } else {
                    let [(tf, _), (tb, _)] = best[v as usize];
                    [ValueSource::Face(tf), ValueSource::Face(tb)]
                };
                let value = |src| source_value(poly, pix, &view, faces, src, q);
                out.vertices.push(RegionVertex::from_values(
                    &view,
                    value(sources[0]),
                    value(sources[1]),
                    q,
                    on_hull,
                ));
                out.sources.push(VertexSource { sources, on_hull });
                profile_hull &= !on_hull || out.vertices[id as usize].profile;
            }
            out.regions.push_vertex(id);
        }
        out.regions.close();
    }
    // The triangles go out (the old ones are the next call's scratch).
    std::mem::swap(faces, &mut out.faces);
    let complete = out.triangulate_regions();
    out.outline_profile = fast && profile_hull && complete;
    out.outline_inputs = [fast, complete];
}

/// Where fast-path vertex `v`, first met in a region with front and back
/// triangles `ft`, takes its values, from its [`VertexKind`] (no search
/// among the regions around it). An original point is a corner of every
/// triangle around it of its own facing (no point lies inside an edge it
/// does not end), where any of them gives the point's own data; a point of
/// one facing only lies strictly inside one triangle of the other facing,
/// the one of every region around it, and so the general path's search
/// picks the same triangles and gets the same bits. A crossing lies on a
/// front and a back edge, along which the front (back) surface is the
/// segment between the edge's ends ([`along_edge`]): exact whatever the
/// widths of the triangles on either side, one of which may be a sliver.
#[inline]
fn fast_sources(ft: [u32; 2], v: u32, kinds: &[VertexKind]) -> [ValueSource; 2] {
    use ValueSource::{Edge, Face, Own};
    match kinds[v as usize] {
        VertexKind::Front => [Own(v), Face(ft[1])],
        VertexKind::Back => [Face(ft[0]), Own(v)],
        VertexKind::Silhouette => [Own(v), Own(v)],
        VertexKind::Crossing { front, back } => [Edge(front), Edge(back)],
    }
}

/// Depth and scalar at pixel position `q` from `src` (step 6): a point's
/// own data, a boundary triangle's plane ([`FaceTri::eval`]) or the
/// boundary along an edge ([`along_edge`]). The one evaluation of region
/// vertex values, at projection and when kept regions take new scalars
/// ([`super::KeptRegions`]).
#[inline]
pub(super) fn source_value(
    poly: &Polyhedron,
    pix: &[DVec2],
    view: &ViewMap,
    faces: &[FaceTri],
    src: ValueSource,
    q: DVec2,
) -> (f64, f64) {
    match src {
        ValueSource::Own(v) => (poly.points[v as usize].z, poly.scalars[v as usize]),
        ValueSource::Face(t) => faces[t as usize].eval(view, q),
        ValueSource::Edge(e) => along_edge(poly, pix, view.ortho, e, q),
    }
}

/// Depth and scalar of the piece's boundary along its edge between points
/// `[a, b]`, on the ray through pixel position `q` (a point of the edge up
/// to rounding). The edge's parameter is that of `q`'s orthogonal
/// projection onto it, clamped to the edge: well conditioned however the
/// edge crosses others. Orthographic: linear interpolation;
/// perspective: `1 / z` and `s / z` are linear along a projected segment.
#[inline(always)]
fn along_edge(
    poly: &Polyhedron,
    pix: &[DVec2],
    ortho: bool,
    [a, b]: [u32; 2],
    q: DVec2,
) -> (f64, f64) {
    let (pa, pb) = (pix[a as usize], pix[b as usize]);
    let d = pb - pa;
    let t = ((q - pa).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    let (za, zb) = (poly.points[a as usize].z, poly.points[b as usize].z);
    let (sa, sb) = (poly.scalars[a as usize], poly.scalars[b as usize]);
    if ortho {
        (za + t * (zb - za), sa + t * (sb - sa))
    } else {
        let (wa, wb) = ((1.0 - t) / za, t / zb);
        let w = wa + wb;
        (1.0 / w, (wa * sa + wb * sb) / w)
    }
}
