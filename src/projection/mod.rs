//! Projection of one convex piece into screen regions (MWS section II).
//!
//! A [`Polyhedron`] (a cell, tetrahedron or breakpoint slab in camera view
//! space, its boundary triangulated) is projected onto the image plane and
//! cut into convex *regions*, the faces of a winged-edge (half-edge) planar
//! subdivision of its projected edges. Each region lies under exactly one
//! front and one back boundary triangle, so in orthographic views the
//! thickness `l` and the front and back scalars are exactly linear on it.
//!
//! Layers, one module each:
//! - `subdivision`: half-edge topology only (ids in arenas, `sanity_check`);
//! - `arrangement`: inserting segments one by one with exact predicates
//!   (the general path, any piece and view);
//! - `overlay`: the fast path for pieces in general position (checked
//!   exactly): regions as intersections of a front and a back triangle;
//! - `tet`: the fast path's shortcut for tetrahedra (Shirley-Tuchman
//!   classes, regions built directly);
//! - `project`: the [`Projector`] pipeline (near clip, projection, regions,
//!   per-vertex values, fan triangles);
//! - `kept`: regions kept across frames whose scalars change and nothing
//!   else ([`KeptRegions`]), which take the new scalars;
//! - `refine`: conforming midpoint refinement of region triangles, for the
//!   perspective error bound and for colour accuracy ([`refine`]);
//! - `coverage`: which triangles can colour a pixel centre (culling);
//! - `clip`: band clipping (near plane, slabs); `slabs`: [`slice_tet`];
//! - `polyhedron`: the input type and its builders.
//!
//! Conventions:
//! - Pixel coordinates are [`Camera::view_to_pixel`]'s continuous `(px, py)`
//!   (pixel centres at `i + 0.5`, `py` growing downwards). "CCW" below means
//!   a positive `orient2d` in `(px, py)` taken as ordinary x/y axes (which
//!   is clockwise as displayed, since `py` points down). Regions and output
//!   triangles are CCW in that sense; rasterisers should not cull.
//! - Perspective: vertex values are meant to be interpolated *linearly in
//!   screen space* (no perspective division). Regions are refined until that
//!   interpolation deviates from the perspective-correct value by at most
//!   [`crate::numeric::tolerance::PERSPECTIVE_INTERP_REL`] of each
//!   quantity's variation along an edge (see `refine`); `l` is the length
//!   of the actual ray segment, in world units.
//! - Profile vertices are silhouette vertices where the front and back
//!   surfaces meet: `l = 0`, `s_front = s_back`. (A silhouette vertex on a
//!   face seen exactly edge-on keeps the thickness along that face.)

mod arrangement;
mod clip;
pub mod coverage;
mod kept;
mod overlay;
mod polyhedron;
mod project;
mod refine;
mod slabs;
pub mod subdivision;
mod tet;
mod window;

use glam::DVec2;
use thiserror::Error;

pub use arrangement::{Arrangement, Segment};
pub use clip::{ClipValue, Clipper};
pub use kept::KeptRegions;
pub use polyhedron::Polyhedron;
pub use project::Projector;
pub use refine::{perspective_split, refine};
pub(crate) use refine::{refine_with, RefineScratch};
pub use slabs::slice_tet;
pub use subdivision::{Subdivision, TopologyError};

use crate::camera::Camera;
use crate::numeric::predicates::{orient2d, Side};

/// How a boundary triangle faces the viewer, from the exact orientation of
/// its projection: front (clockwise in pixel coordinates, whose y grows
/// downwards), back (counter-clockwise) or edge-on (zero area).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Facing {
    Front,
    Back,
    EdgeOn,
}

/// Errors of projection (bad input or an inconsistent subdivision).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ProjectionError {
    #[error("point index {0} out of range")]
    IndexOutOfRange(u32),
    #[error("{points} points but {scalars} scalars")]
    LengthMismatch { points: usize, scalars: usize },
    #[error("non-finite coordinate or scalar")]
    NonFinite,
    #[error("no cell {0}")]
    NoSuchCell(usize),
    #[error("a point is behind the near plane after clipping")]
    BehindNearPlane,
    #[error("the clipped surface is not closed")]
    OpenSurface,
    #[error("a region has no front or back triangle (non-convex piece?)")]
    UnassignedRegion,
    #[error("inconsistent subdivision: {0}")]
    Topology(#[from] TopologyError),
}

/// One vertex of the screen regions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RegionVertex {
    /// Continuous pixel coordinates ([`Camera::view_to_pixel`]).
    pub px: f64,
    pub py: f64,
    /// View depth where the ray through the vertex enters / leaves the piece.
    pub z_front: f64,
    pub z_back: f64,
    /// Length of the ray segment inside the piece, world units.
    pub l: f64,
    /// Scalar at the entry and exit points.
    pub s_front: f64,
    pub s_back: f64,
    /// Silhouette vertex with `l = 0` (see module docs).
    pub profile: bool,
}

/// What the projection needs of the camera to turn pixel positions back into
/// rays: view-plane extents and image size.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewMap {
    pub ortho: bool,
    pub half_width: f64,
    pub half_height: f64,
    pub width: f64,
    pub height: f64,
}

impl ViewMap {
    /// The map of `camera`.
    pub fn of(camera: &Camera) -> ViewMap {
        let (hw, hh) = camera.half_extent();
        ViewMap {
            ortho: camera.ortho,
            half_width: hw,
            half_height: hh,
            width: camera.width as f64,
            height: camera.height as f64,
        }
    }

    /// View-plane coordinates of a pixel position: `(x, y)` (orthographic)
    /// or `(x / z, y / z)` (perspective).
    #[inline]
    pub fn plane(&self, q: DVec2) -> DVec2 {
        DVec2::new(
            (2.0 * q.x / self.width - 1.0) * self.half_width,
            (1.0 - 2.0 * q.y / self.height) * self.half_height,
        )
    }

    /// Ray length per unit of depth at pixel position `q`.
    #[inline]
    pub fn length_per_depth(&self, q: DVec2) -> f64 {
        if self.ortho {
            1.0
        } else {
            let u = self.plane(q);
            (1.0 + u.length_squared()).sqrt()
        }
    }
}

/// For a point shared by several regions: the region whose front triangle,
/// and the one whose back triangle, is widest ([`FaceTri::width`]), with
/// those widths.
pub(crate) type WidestFaces = [(u32, f64); 2];

/// What the fast path knows of a region vertex in general position (see
/// `project`, step 6): which boundary triangles hold it, so that its values
/// need no search among the regions around it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum VertexKind {
    /// An original point used by front triangles only: a corner of every
    /// front triangle around it, strictly inside one back triangle.
    Front,
    /// An original point used by back triangles only.
    Back,
    /// An original point used by both (a silhouette vertex).
    Silhouette,
    /// The proper crossing of the edge between two front triangles with
    /// ends (original points) `front`, and the edge between two back
    /// triangles with ends `back`: its front values lie on the front edge,
    /// its back values on the back edge.
    Crossing { front: [u32; 2], back: [u32; 2] },
}

/// A seam given by its end points (pixel positions): the centres within
/// `band` pixels of it are decided on the exact geometry
/// ([`Projected::seam_lines`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamLine {
    pub ends: [DVec2; 2],
    pub band: f64,
}

/// A boundary triangle as seen on screen: pixel positions of its corners
/// with their depths and scalars.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceTri {
    pub p: [DVec2; 3],
    pub z: [f64; 3],
    pub s: [f64; 3],
}

impl FaceTri {
    #[inline]
    fn new(poly: &Polyhedron, pix: &[DVec2], t: u32) -> FaceTri {
        match poly.triangles.get(t as usize) {
            Some(&tri) => FaceTri {
                p: tri.map(|i| pix[i as usize]),
                z: tri.map(|i| poly.points[i as usize].z),
                s: tri.map(|i| poly.scalars[i as usize]),
            },
            None => FaceTri::default(),
        }
    }

    /// Smallest width of the projected triangle (twice its area over its
    /// longest edge), pixels; 0 when degenerate.
    ///
    /// Evaluating the triangle's plane at a point turns an error `d` in the
    /// point's (or the corners') pixel position into an error of about
    /// `d / width` of the triangle's depth and scalar variation: faces seen
    /// (nearly) edge-on have widths of rounding size (~1e-14 px) and give
    /// meaningless values. Among the triangles known to hold a point (the
    /// front or back triangles of the regions around a vertex), the widest
    /// gives the best-conditioned value.
    pub fn width(&self) -> f64 {
        let [a, b, c] = self.p;
        let area2 = (b - a).perp_dot(c - a).abs();
        let lmax = (b - a)
            .length_squared()
            .max((c - b).length_squared())
            .max((a - c).length_squared())
            .sqrt();
        if area2 > 0.0 && lmax > 0.0 {
            area2 / lmax
        } else {
            0.0
        }
    }

    /// The screen-space barycentric weights of pixel position `q` in the
    /// projected triangle (summing to 1, not clamped); `None` for a
    /// triangle of no area. In perspective a value linear on the triangle
    /// in space takes the weights `lambda_i / z_i`, normalised
    /// ([`FaceTri::eval`]).
    #[inline]
    pub fn barycentric(&self, q: DVec2) -> Option<[f64; 3]> {
        let [a, b, c] = self.p;
        let den = (b - a).perp_dot(c - a);
        if den == 0.0 {
            return None;
        }
        let lb = (q - a).perp_dot(c - a) / den;
        let lc = (b - a).perp_dot(q - a) / den;
        Some([1.0 - lb - lc, lb, lc])
    }

    /// Depth and scalar of the triangle's plane along the ray through pixel
    /// position `q` (exactly the corner's data when `q` is a corner).
    ///
    /// `q` is meant to lie in the projected triangle (every caller evaluates
    /// a region's own triangles at points of the region), where the exact
    /// depth and scalar lie between the corners' values (linear, or
    /// perspective-correct, interpolation with weights in `[0, 1]`). The
    /// results are clamped to those ranges, so rounding in the barycentric
    /// weights of a thin triangle cannot extrapolate far beyond its
    /// corners (see [`FaceTri::width`] for choosing a well-conditioned one).
    pub fn eval(&self, view: &ViewMap, q: DVec2) -> (f64, f64) {
        for k in 0..3 {
            if self.p[k] == q {
                return (self.z[k], self.s[k]);
            }
        }
        let Some(lam) = self.barycentric(q) else {
            return (self.z[0], self.s[0]);
        };
        let (z, s) = if view.ortho {
            let z = lam[0] * self.z[0] + lam[1] * self.z[1] + lam[2] * self.z[2];
            let s = lam[0] * self.s[0] + lam[1] * self.s[1] + lam[2] * self.s[2];
            (z, s)
        } else {
            // Perspective-correct: weights lambda_i / z_i.
            let w = [lam[0] / self.z[0], lam[1] / self.z[1], lam[2] / self.z[2]];
            let sw = w[0] + w[1] + w[2];
            let s = (w[0] * self.s[0] + w[1] * self.s[1] + w[2] * self.s[2]) / sw;
            (1.0 / sw, s)
        };
        let range = |v: [f64; 3]| (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
        let ((zl, zh), (sl, sh)) = (range(self.z), range(self.s));
        // `clamp` keeps a NaN (a degenerate perspective weight sum) as NaN;
        // fall back to the first corner then, as for `den == 0`.
        if z.is_nan() || s.is_nan() {
            return (self.z[0], self.s[0]);
        }
        (z.clamp(zl, zh), s.clamp(sl, sh))
    }
}

impl RegionVertex {
    /// Values at pixel position `q` of a region with triangles `front` and
    /// `back`; `on_hull` marks silhouette vertices.
    pub fn evaluate(
        view: &ViewMap,
        front: &FaceTri,
        back: &FaceTri,
        q: DVec2,
        on_hull: bool,
    ) -> RegionVertex {
        RegionVertex::from_values(view, front.eval(view, q), back.eval(view, q), q, on_hull)
    }

    /// The vertex at pixel position `q` with front and back depth and
    /// scalar `(zf, sf)` and `(zb, sb)` (as [`RegionVertex::evaluate`] after
    /// evaluating the triangles).
    #[inline]
    pub(crate) fn from_values(
        view: &ViewMap,
        (zf, sf): (f64, f64),
        (mut zb, mut sb): (f64, f64),
        q: DVec2,
        on_hull: bool,
    ) -> RegionVertex {
        let mut profile = false;
        if zb <= zf {
            zb = zf;
            if on_hull {
                profile = true;
                sb = sf;
            }
        }
        RegionVertex {
            px: q.x,
            py: q.y,
            z_front: zf,
            z_back: zb,
            l: (zb - zf) * view.length_per_depth(q),
            s_front: sf,
            s_back: sb,
            profile,
        }
    }

    /// Pixel position.
    #[inline]
    pub fn pos(&self) -> DVec2 {
        DVec2::new(self.px, self.py)
    }
}

/// Vertex lists (ids) of convex regions, stored one after the other.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegionList {
    verts: Vec<u32>,
    /// Region `r` is `verts[start[r]..start[r + 1]]` (`start[0] = 0`).
    start: Vec<u32>,
}

impl Default for RegionList {
    fn default() -> Self {
        RegionList {
            verts: Vec::new(),
            start: vec![0],
        }
    }
}

impl RegionList {
    /// Number of regions.
    #[inline]
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The regions' vertex lists, in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.start
            .windows(2)
            .map(|w| &self.verts[w[0] as usize..w[1] as usize])
    }

    /// Empties the list, keeping allocations.
    pub fn clear(&mut self) {
        self.verts.clear();
        self.start.clear();
        self.start.push(0);
    }

    /// Adds vertex `v` to the region being built (the one after the last
    /// [`Self::close`]).
    #[inline]
    pub(crate) fn push_vertex(&mut self, v: u32) {
        self.verts.push(v);
    }

    /// The vertices pushed since the last [`Self::close`].
    #[inline]
    pub(crate) fn open(&self) -> &[u32] {
        &self.verts[*self.start.last().unwrap_or(&0) as usize..]
    }

    /// Ends the region being built (empty when nothing was pushed); it
    /// gets the next index.
    #[inline]
    pub(crate) fn close(&mut self) {
        self.start.push(self.verts.len() as u32);
    }

    /// Empties the region being built.
    pub(crate) fn discard_open(&mut self) {
        let s = *self.start.last().unwrap_or(&0) as usize;
        self.verts.truncate(s);
    }
}

impl std::ops::Index<usize> for RegionList {
    type Output = [u32];

    #[inline]
    fn index(&self, r: usize) -> &[u32] {
        &self.verts[self.start[r] as usize..self.start[r + 1] as usize]
    }
}

/// The projection of one piece (reused between calls).
#[derive(Clone, Debug, Default)]
pub struct Projected {
    /// Region vertices (shared between the regions and triangles).
    pub vertices: Vec<RegionVertex>,
    /// Convex regions, CCW (see module docs), indices into `vertices`.
    pub regions: RegionList,
    /// Triangles for the rasteriser: a fan of each region, refined where
    /// needed (perspective, [`refine`]); CCW, positive area.
    pub triangles: Vec<[u32; 3]>,
    /// Region of each triangle.
    pub triangle_region: Vec<u32>,
    /// The piece's boundary triangles as seen on screen (in the piece's
    /// triangle order).
    pub faces: Vec<FaceTri>,
    /// Front and back triangle of each region (indices into `faces`).
    pub region_faces: Vec<[u32; 2]>,
    /// The camera mapping the values were computed for.
    pub view: ViewMap,
    /// Edges (vertex pairs) inside the piece's outline across which the
    /// mode's payload changes by more than interpolation (where a region
    /// holding an isosurface meets one that does not): the pixel centres
    /// next to them are decided on the exact geometry, as next to the
    /// outline ([`crate::render::ties`]). Set by the mode, empty otherwise.
    pub seams: Vec<(u32, u32)>,
    /// Seams given by their end points (pixel positions) rather than by
    /// vertices, each with its own band: the isosurface modes' lines where
    /// a boundary triangle's scalar equals an isovalue
    /// (`render::modes::iso_seams`). Decided as [`Projected::seams`].
    pub seam_lines: Vec<SeamLine>,
    /// For the values of tie decisions ([`crate::render::ties`], no
    /// regions): the piece's boundary triangles (indices into
    /// [`Polyhedron::triangles`]) where each vertex's ray enters and leaves.
    pub tie_faces: Vec<[u32; 2]>,
    /// Whether every vertex on the outline of [`Projected::triangles`]
    /// (the kept and the culled ones together) is a profile vertex, so
    /// that the thickness is 0 all along the outline: the fast path's
    /// regions (a piece in general position: no face edge-on), every
    /// silhouette vertex a profile vertex, no fan triangle skipped and
    /// nothing clipped to the image. False where it is not known.
    pub outline_profile: bool,
    /// Scratch of [`Projected::cull_to_pixels`]: each vertex's
    /// [`coverage::Span`].
    spans: Vec<coverage::Span>,
    /// The triangles [`Projected::cull_to_pixels`] dropped.
    culled: Vec<[u32; 3]>,
    /// Where step 6 took each vertex's values (`kept`: kept regions take
    /// new scalars through them); the vertices added after it have none.
    sources: Vec<kept::VertexSource>,
    /// What [`Projected::outline_profile`] took from step 6 besides the
    /// vertices' profiles: whether the fast path made the regions, and
    /// whether none of their fan triangles was skipped.
    outline_inputs: [bool; 2],
}

impl Projected {
    /// Empties everything, keeping allocations.
    pub fn clear(&mut self) {
        self.vertices.clear();
        self.regions.clear();
        self.triangles.clear();
        self.triangle_region.clear();
        self.faces.clear();
        self.region_faces.clear();
        self.seams.clear();
        self.seam_lines.clear();
        self.tie_faces.clear();
        self.outline_profile = false;
        self.spans.clear();
        self.culled.clear();
        self.sources.clear();
        self.outline_inputs = [false; 2];
    }

    /// Leaves out the triangles of the regions whose front or back
    /// boundary triangle is flagged in `faces` (indexed as
    /// [`Projected::faces`]; one beyond it counts as flagged), and marks
    /// the outline as no longer the piece's ([`Projected::outline_profile`]
    /// false): the rays through those regions are not drawn.
    pub fn leave_out_regions_on(&mut self, faces: &[bool]) {
        let flagged = |f: u32| faces.get(f as usize).copied().unwrap_or(true);
        let mut w = 0;
        for r in 0..self.triangles.len() {
            let region = self.triangle_region[r] as usize;
            let keep = self
                .region_faces
                .get(region)
                .is_some_and(|&[front, back]| !flagged(front) && !flagged(back));
            if keep {
                self.triangles[w] = self.triangles[r];
                self.triangle_region[w] = self.triangle_region[r];
                w += 1;
            }
        }
        self.triangles.truncate(w);
        self.triangle_region.truncate(w);
        self.outline_profile = false;
    }

    /// Each vertex's [`coverage::Span`]: the pixel centres within
    /// [`crate::numeric::tolerance::COVERAGE_MARGIN_PX`] of it per axis, as
    /// [`Projected::cull_to_pixels`] left them; `None` where the projection
    /// was not culled (or vertices were added since).
    pub fn vertex_spans(&self) -> Option<&[coverage::Span]> {
        (self.spans.len() == self.vertices.len()).then_some(&self.spans[..])
    }

    /// The triangles [`Projected::cull_to_pixels`] dropped: no pixel
    /// centre lies within
    /// [`crate::numeric::tolerance::COVERAGE_MARGIN_PX`] of any of them
    /// (nor of their edges); `None` where the projection was not culled
    /// (as [`Projected::vertex_spans`]).
    pub fn culled_triangles(&self) -> Option<&[[u32; 3]]> {
        self.vertex_spans().map(|_| &self.culled[..])
    }

    /// The front (`side` 0) or back (1) triangle of region `r`.
    #[inline]
    pub fn region_face(&self, r: usize, side: usize) -> &FaceTri {
        &self.faces[self.region_faces[r][side] as usize]
    }

    /// Fan-triangulates every region, skipping triangles whose exact
    /// orientation is not positive (zero area, or inverted by rounding of a
    /// crossing point); returns whether none was skipped.
    fn triangulate_regions(&mut self) -> bool {
        let mut complete = true;
        self.triangles.clear();
        self.triangle_region.clear();
        for (r, reg) in self.regions.iter().enumerate() {
            if reg.len() < 3 {
                continue;
            }
            let a = reg[0];
            for k in 1..reg.len() - 1 {
                let (b, c) = (reg[k], reg[k + 1]);
                let [pa, pb, pc] = [a, b, c].map(|i| self.vertices[i as usize].pos());
                if orient2d(pa, pb, pc) == Side::Positive {
                    self.triangles.push([a, b, c]);
                    self.triangle_region.push(r as u32);
                } else {
                    complete = false;
                }
            }
        }
        complete
    }

    /// Sum of the areas of the regions (pixel units).
    pub fn region_area(&self) -> f64 {
        self.regions
            .iter()
            .map(|r| {
                let mut a = 0.0;
                for k in 0..r.len() {
                    let p = self.vertices[r[k] as usize].pos();
                    let q = self.vertices[r[(k + 1) % r.len()] as usize].pos();
                    a += p.perp_dot(q);
                }
                0.5 * a
            })
            .sum()
    }

    /// Sum of the areas of the triangles (pixel units).
    pub fn triangle_area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize].pos());
                0.5 * (b - a).perp_dot(c - a)
            })
            .sum()
    }
}

thread_local! {
    static PROJECTOR: std::cell::RefCell<Projector> = std::cell::RefCell::new(Projector::new());
}

/// Projects `poly` for `camera` into `out` with a per-thread [`Projector`]
/// (allocation-free in steady state).
pub fn project(
    poly: &Polyhedron,
    camera: &Camera,
    out: &mut Projected,
) -> Result<(), ProjectionError> {
    PROJECTOR.with(|p| match p.try_borrow_mut() {
        Ok(mut p) => p.project(poly, camera, out),
        Err(_) => Projector::new().project(poly, camera, out),
    })
}
