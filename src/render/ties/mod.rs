//! Pixel centres next to a part's outline, decided on the exact geometry.
//!
//! The driver snaps every region corner to the rasteriser's sub-pixel grid
//! (1/256 pixel, [`crate::gpu::ClipMapper::ndc`]), which moves it by up to
//! `sqrt(2)/512` pixel. A pixel centre farther than that from every edge of
//! a part's outline is inside the snapped part exactly when it is inside
//! the exact one; a centre closer may change sides. Where the ray through
//! it crosses the piece for a length that is not small (a sliver seen
//! nearly edge-on, an opaque cell next to another), that is a visibly
//! wrong pixel: the piece's whole segment missing, or taken where the ray
//! caster says the ray misses the piece.
//!
//! So for each part the centres within [`TIE_BAND_PX`] of its outline
//! (edges of its triangles that are not shared by two drawn triangles) are
//! decided twice:
//!
//! - **exactly, in 3D, by the ray caster's rule**
//!   ([`crate::raycast::geometry`]): the pixel ray, the ray caster's line
//!   through two `f64` points in world space ([`TieRays`]), crosses the
//!   convex part when it crosses two of its boundary triangles, taken on
//!   the part's world-space points ([`Polyhedron::world`]). Each crossing is
//!   decided by the exact signs of the Plücker products of the line with
//!   the triangles' edges, with the same symbolic perturbation of the ray
//!   (right, then down on the image: the top-left rule) and every edge
//!   oriented by its end points' coordinates. Neighbouring parts share
//!   their faces' corner points bit for bit, so a ray through a shared
//!   edge, a shared vertex or along a shared face seen edge-on is given to
//!   exactly one part of every stack, as in the ray caster. A decision on
//!   the projected 2D positions could not do this: their rounding makes
//!   points that lie on one line on screen (a face seen edge-on, its edges
//!   from different parts) fall on both sides of a centre on it;
//! - **as the GPU will draw it**: inside one of the snapped triangles
//!   (integer grid, the rasteriser's top-left rule).
//!
//! Where the two disagree, a triangle inside the pixel (holding its centre
//! and no other) is drawn first in the part: with
//! the mode's payload of the exact segment the ray cuts from the part
//! (entry and exit depth and scalar from the crossings, the ray caster's
//! numbers) where the exact part holds the centre, or transparent where it
//! does not (a blocker, drawn at [`crate::gpu::common::BLOCKER_Z`], which counting draws do
//! not count). Each piece colours a pixel once (its depth key), so the
//! quad decides the pixel and the triangles drawn after it leave it alone.
//!
//! Most centres in the band are far from the outline by rounding
//! standards (1/256 px against rounding of 1e-12 px): where the float test
//! on the exact triangles is certain ([`TieRays::filter_px`], at least
//! [`RASTER_FILTER_PX`] from every edge that decides it) and agrees with
//! the rasteriser, there is nothing to decide and the exact test is not
//! run; it decides the rest, as the visibility rasteriser does.
//!
//! Two more kinds of centre are decided exactly, and get the exact
//! segment's triangle wherever the part holds them (not only where the two
//! tests disagree):
//! - next to a mode's **seams** ([`Projected::seams`],
//!   [`Projected::seam_lines`]): edges inside the outline across which the
//!   payload jumps, or lines where a face's scalar is an isovalue (the
//!   isosurface modes, whose two pieces on either side of the face
//!   interpolate its scalar on different snapped triangles), where a
//!   centre must go to the same side in every part that shares the edge;
//!   a line's band grows by the distance over which the face's scalar
//!   changes by the `f32` stage's margin ([`iso_margin`]: its level below
//!   the value and its rounding, relative to the distance from the
//!   scalar the stage maps to 0), which can be far wider than the snap's
//!   where the field is gentle;
//! - inside **slivers**, exact triangles narrower than [`SLIVER_TIE_PX`]:
//!   the snap of their corners shifts the interpolated values by their
//!   screen gradient times the snap, which across a sliver is a large part
//!   of the values' change (a region of a face seen nearly edge-on; an
//!   optically thick tet seen almost along a face); a sliver whose corners
//!   collapse on the grid is not drawn at all, and its centres would take
//!   the values of the triangle beside it. In the isosurface modes the
//!   same shift of the entry or exit scalar can put a centre on the other
//!   side of an isovalue than the piece beside it puts it: a sliver's
//!   centres whose exact scalars come within that shift of an isovalue
//!   are decided too ([`PartTriangles::isovalues`]). A sliver is weighed
//!   by how far the snap actually moved its corners
//!   ([`PartTriangles::snap`]), not by the most it can. A wider triangle
//!   holding a centre whose exact entry or exit scalar comes within the
//!   snap's shift of an isovalue is drawn **steep** instead
//!   ([`snap_is_steep`]: the exact triangle's values at its snapped
//!   corners), so that every centre in it takes the exact triangle's
//!   scalars, whatever the volume's rate (a surface on a face of a
//!   zero-extinction volume was otherwise missed at 2 of 9,080 centres in
//!   perspective, `tests/iso.rs`). Only such centres can change side: with
//!   many isovalues nearly every triangle holds one, but few hold such a
//!   centre (bluntfin, 100 values: 26,914 steep triangles of 335,392,
//!   against about 101,000 when every triangle holding a value was).
//!
//! **Optically thin parts** ([`thin_outline`]) need none of this. Where
//! the thickness is 0 all along a part's outline (a piece in general
//! position: [`Projected::outline_profile`]), a centre close enough to the
//! outline for the decisions to change its side has a segment at most
//! the thickness's largest gradient times that distance long, by the
//! GPU's interpolation and by the ray caster alike; where that times the
//! part's largest rate is at most [`SLIVER_DEPTH_TOL`], either side
//! changes the pixel by at most that, and the same bound covers what the
//! snap does to a sliver's values. Such a part's outline and slivers are
//! left to the rasteriser (most parts of a fine mesh: it made the
//! decisions about half as dear on the hex_shell scene). Counting draws
//! (where every centre counts one), isosurfaces and seams are always
//! decided.

mod band;
mod scan;

use glam::{DVec2, DVec3};

pub(crate) use band::affine_gradient;
use band::{centres_within, inside_by_float, near_centres, near_edge, within_band};
pub use scan::scan_triangles;

use crate::camera::Camera;
use crate::gpu::{GpuVertex, SUBPIXEL};
use crate::numeric::tolerance::{
    ISO_SLIVER_REL, PLUCKER_FILTER_K, RASTER_FILTER_MAX_COORD_PX, RASTER_FILTER_PX, THIN_OUTLINE_PX,
};
use crate::projection::coverage::PixelGrid;
use crate::projection::{Polyhedron, Projected, RegionVertex};
use crate::raycast::geometry::{bounding_sphere, Proj, RayFrame};

/// Centres within this distance (pixels) of an outline edge are decided
/// exactly: the largest move of a snapped corner is `sqrt(2)/512` = 2.8e-3
/// px; 1/256 leaves a margin.
pub const TIE_BAND_PX: f64 = 1.0 / 256.0;

/// Triangles narrower than this (pixels: twice the area over the longest
/// edge) have the centres they may hold decided exactly too, with the
/// segment's exact values: the snap of a corner (up to `sqrt(2)/512` px)
/// shifts an interpolated value by its screen gradient times that, which
/// across a sliver of width `w` is `0.0028 / w` of the value's change over
/// the sliver (0.6 % at half a pixel; a sliver region of a face seen nearly
/// edge-on can be far thinner). Only slivers where that can matter are
/// decided ([`SLIVER_DEPTH_TOL`]): a dense mesh has narrow triangles holding
/// centres by the hundred thousand, nearly all optically thin.
pub const SLIVER_TIE_PX: f64 = 1.0 / 2.0;

/// The largest move of a snapped corner, pixels (`sqrt(2)/512`).
pub const SNAP_PX: f64 = std::f64::consts::SQRT_2 / 512.0;

/// A sliver's centres are decided exactly where the snap could change the
/// optical depth (or emitted colour) by more than this: a quarter of an
/// 8-bit step.
pub const SLIVER_DEPTH_TOL: f64 = 1e-3;

/// Whether the part's outline can be left to the rasteriser: every
/// centre there has a segment too thin to matter. Where the thickness is
/// 0 all along the outline ([`Projected::outline_profile`]), a centre
/// within [`THIN_OUTLINE_PX`] of it has, by the GPU's interpolation and
/// by the ray caster alike, a thickness of at most the largest gradient
/// of the thickness over the part's triangles times that distance (every
/// triangle between the centre and the outline holds a point that close
/// to a centre, so coverage culling kept it). Where that times the part's
/// rate is at most [`SLIVER_DEPTH_TOL`], the pixel's optical depth and
/// colour change by at most that whichever side the centre goes to
/// ([`thickness_gradient`]; in perspective, refinement's triangles carry
/// the exact values at their corners, within the doubled distance's
/// slack). The same bound settles the part's slivers: the snap shifts
/// the values at a centre by the gradient times at most [`SNAP_PX`], less
/// than the distance above, so [`scan_triangles`] need not look for them.
/// Not for counting draws,
/// isosurfaces or seams (`part.weighed` false) or parts clipped at the
/// near plane. Triangles collapsed by the snap are still decided
/// ([`outline_centres`]).
pub fn thin_outline(part: &PartTriangles) -> bool {
    if !part.weighed
        || part.clipped
        || !part.proj.outline_profile
        || !part.proj.seams.is_empty()
        || !part.proj.seam_lines.is_empty()
    {
        return false;
    }
    let g = thickness_gradient(part);
    let thin = |rate: f64| rate * g * THIN_OUTLINE_PX <= SLIVER_DEPTH_TOL;
    // False for NaN too.
    thin(part.rate_bound) || thin((part.rate)())
}

/// The largest gradient of the thickness `l` over the part's triangles
/// that reach a pixel centre (world units per pixel; NaN where a value is
/// not a number): the triangles coverage culling keeps, also where it did
/// not run, so that culling changes no decision. (Culled triangles need
/// not count: a triangle between a decided centre and the outline lies
/// within the culling's margin of that centre.) The largest ratio is kept
/// as a fraction, without a division per triangle (the hot loop of
/// [`thin_outline`]).
fn thickness_gradient(part: &PartTriangles) -> f64 {
    let culled = part.proj.vertex_spans().is_some();
    let grid = PixelGrid::new(part.width, part.height);
    let (mut num, mut den) = (0.0f64, 1.0f64);
    let mut finite = true;
    for t in part.exact {
        let v = t.map(|i| &part.proj.vertices[i as usize]);
        let p = v.map(|v| v.pos());
        if !culled && !grid.triangle_reaches(p[0], p[1], p[2]) {
            continue;
        }
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let area2 = e1.perp_dot(e2);
        let g = e2 * (v[1].l - v[0].l) - e1 * (v[2].l - v[0].l);
        let (n, d) = (g.length_squared(), area2 * area2);
        // Positive areas (fan triangles), finite values: false for NaN.
        finite &= n >= 0.0 && d > 0.0;
        if n * den > num * d {
            (num, den) = (n, d);
        }
    }
    if finite {
        (num / den).sqrt()
    } else {
        f64::NAN
    }
}

/// Whether the snap of the corners of the drawn triangle at `p` (pixels),
/// with thickness `l` at its corners, can shift the optical depth at a
/// centre inside it by more than [`SLIVER_DEPTH_TOL`] at rate `rate`, where
/// the sliver decisions leave that centre to the triangle: a triangle at
/// least [`SLIVER_TIE_PX`] wide (narrower ones are slivers, whose centres
/// [`decide_ties`] takes exactly) across which the thickness changes
/// steeply (an optically thick piece seen nearly along a face: thickness
/// from 0 to 0.17 across 1.6 px at extinction 1e3 is 0.06 of optical
/// depth per 1/512 px). The driver gives such a triangle's snapped corners
/// the exact triangle's values there ([`crate::gpu::GpuVertex::lerp3`]):
/// at that width the corners move by at most 0.6 % of it, so the
/// extrapolation is bounded, and the interpolated values at every centre
/// are the exact triangle's.
pub fn snap_is_steep(p: [DVec2; 3], l: [f64; 3], rate: f64) -> bool {
    let area2 = (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
    let longest = [0, 1, 2]
        .map(|k| (p[(k + 1) % 3] - p[k]).length_squared())
        .into_iter()
        .fold(0.0, f64::max)
        .sqrt();
    snap_is_steep_at(area2, longest, l, rate)
}

/// [`snap_is_steep`] of a triangle with twice the area `area2` and
/// longest edge `longest`.
#[inline]
fn snap_is_steep_at(area2: f64, longest: f64, l: [f64; 3], rate: f64) -> bool {
    let dl = l[0].max(l[1]).max(l[2]) - l[0].min(l[1]).min(l[2]);
    // False for NaN too.
    longest > 0.0
        && area2 >= SLIVER_TIE_PX * longest
        && rate * dl * SNAP_PX > SLIVER_DEPTH_TOL * area2 / longest
}

/// Appends the drawn triangle at `p` (pixels; snapped to grid positions
/// `g`, sub-pixel units) whose corners in `vertices` are `exact` as three
/// new corners, each with the exact triangle's values at its snapped
/// position and `exact`'s clip position (see [`snap_is_steep`]).
pub fn push_steep<V: GpuVertex>(
    p: [DVec2; 3],
    g: [[i64; 2]; 3],
    exact: [V; 3],
    vertices: &mut Vec<V>,
    indices: &mut Vec<u32>,
) {
    let base = vertices.len() as u32;
    let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
    for k in 0..3 {
        let q = DVec2::new(g[k][0] as f64, g[k][1] as f64) / SUBPIXEL;
        let b1 = (q - p[0]).perp_dot(p[2] - p[0]) / area;
        let b2 = (p[1] - p[0]).perp_dot(q - p[0]) / area;
        let v = V::lerp3([&exact[0], &exact[1], &exact[2]], [1.0 - b1 - b2, b1, b2])
            .with_clip(exact[k].clip())
            .with_piece(exact[k].piece());
        vertices.push(v);
    }
    indices.extend_from_slice(&[base, base + 1, base + 2]);
}

/// Whether the snapped triangle `g` (grid units) covers the centre `q`
/// (grid units): the rasteriser's test ([`crate::gpu::cpu`]).
pub fn covers_grid(g: [[i64; 2]; 3], q: [i64; 2]) -> bool {
    let [a, b, c] = g.map(|p| [p[0] as i128, p[1] as i128]);
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if area == 0 {
        return false;
    }
    let s = area.signum();
    let q = [q[0] as i128, q[1] as i128];
    for (u, v) in [(b, c), (c, a), (a, b)] {
        let (dx, dy) = ((v[0] - u[0]) * s, (v[1] - u[1]) * s);
        let e = dx * (q[1] - u[1]) - dy * (q[0] - u[0]);
        let top_left = -dy > 0 || (-dy == 0 && dx > 0);
        if e < 0 || (e == 0 && !top_left) {
            return false;
        }
    }
    true
}

/// The pixel rays of one frame, for the exact decisions: the reference
/// ray caster's rays, bit for bit.
///
/// Each is [`Camera::ray_at`] of the pixel position, framed
/// ([`RayFrame::new`]) with the bounding sphere the ray caster's walk uses
/// ([`crate::raycast::geometry::bounding_sphere`] of the mesh bounds), and
/// tested against the parts' world-space points ([`Polyhedron::world`]),
/// which are the mesh's points bit for bit where a part's corner is a mesh
/// point. So the exact predicates get the ray caster's very inputs and give
/// its answers, also where a centre lies on a projected edge or an edge-on
/// face only up to rounding: a decision on view-space positions, rounded
/// differently, could give such a centre to the other side.
#[derive(Clone, Debug)]
pub struct TieRays {
    camera: Camera,
    /// The ray caster's bounding sphere of the mesh: the same for every
    /// part, so every part sees the same line.
    center: DVec3,
    radius: f64,
    /// A bound on the world-space distance between a pixel's exact ray and
    /// the point a part's projected position rounds to, from the
    /// magnitudes of the eye and the mesh ([`TieRays::filter_px`]).
    world_err: f64,
}

impl TieRays {
    /// The rays of `camera` for parts within the mesh bounds `bounds`
    /// ([`crate::mesh::Mesh::bounds`]).
    pub fn new(camera: &Camera, bounds: [f64; 6]) -> TieRays {
        let lo = DVec3::new(bounds[0], bounds[2], bounds[4]);
        let hi = DVec3::new(bounds[1], bounds[3], bounds[5]);
        let (center, radius) = bounding_sphere(lo, hi);
        let magnitude = camera
            .position
            .abs()
            .max_element()
            .max(center.abs().max_element() + radius);
        TieRays {
            camera: *camera,
            center,
            radius,
            world_err: PLUCKER_FILTER_K * f64::EPSILON * magnitude,
        }
    }

    /// How far (pixels) a pixel centre must be from a part's projected
    /// edges for the float test on the projected positions to give the
    /// exact test's answer ([`ray_through`]), for a part whose nearest
    /// depth is `z_min` and whose projected coordinates reach `coord_max`
    /// pixels; `None` where no margin can be trusted (coordinates beyond
    /// [`RASTER_FILTER_MAX_COORD_PX`], or no positive depth in
    /// perspective). The projected positions and the ray caster's rays
    /// both round the camera transform of the same points: at most a few
    /// ulps of the largest coordinate of the eye and the mesh (`world_err`,
    /// with [`PLUCKER_FILTER_K`]'s margin) seen at the part's depth, and
    /// of the pixel coordinates themselves; at least
    /// [`RASTER_FILTER_PX`], the margin the visibility rasteriser trusts.
    pub fn filter_px(&self, z_min: f64, coord_max: f64) -> Option<f64> {
        let cam = &self.camera;
        let px_per_world = if cam.ortho {
            cam.height as f64 / (2.0 * cam.parallel_scale)
        } else {
            cam.height as f64 / (2.0 * z_min * cam.tan_half())
        };
        // False for NaN too (no depth in front of the eye, or none at all).
        if !(px_per_world > 0.0 && px_per_world.is_finite()) {
            return None;
        }
        let m = (self.world_err * px_per_world)
            .max(PLUCKER_FILTER_K * f64::EPSILON * coord_max)
            .max(RASTER_FILTER_PX);
        // False for NaN too.
        (coord_max <= RASTER_FILTER_MAX_COORD_PX && m.is_finite() && m > 0.0 && m < TIE_BAND_PX)
            .then_some(m)
    }

    /// The ray through pixel position `c` and its depth per unit of
    /// length.
    fn frame(&self, c: DVec2) -> (RayFrame, f64) {
        let ray = self.camera.ray_at(c.x, c.y);
        let dz = ray.dir.dot(self.camera.forward);
        (RayFrame::new(&ray, self.center, self.radius), dz)
    }
}

/// What the exact test says of one ray and one part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayThrough {
    /// The ray misses the part, or meets it for no length (in a point or
    /// along an edge).
    Misses,
    /// The ray crosses the part: the segment's values at pixel position
    /// `c` (the region vertex the ray caster's numbers give), and the
    /// part's boundary triangles where it enters and leaves.
    Crosses(RegionVertex, [u32; 2]),
    /// The boundary did not give two crossings (a degenerate part): left
    /// to the rasteriser.
    Undecided,
}

/// The exact test of the ray through pixel position `c` against `part`
/// (see the module docs); `proj` is scratch.
pub fn ray_through(
    part: &Polyhedron,
    rays: &TieRays,
    c: DVec2,
    proj: &mut Vec<Proj>,
) -> RayThrough {
    if part.world.len() != part.points.len() {
        // No world positions: nothing to decide on (every part source of
        // the driver gives them).
        return RayThrough::Undecided;
    }
    let (frame, dz) = rays.frame(c);
    proj.clear();
    proj.extend(part.world.iter().map(|&p| frame.project(p)));
    let mut hits = [(0.0, 0.0, 0u32); 2];
    let mut n = 0;
    for (k, t) in part.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| i as usize);
        let (pa, pb, pc) = (part.world[a], part.world[b], part.world[c]);
        let e = [
            frame.edge_by_position(pa, &proj[a], pb, &proj[b]),
            frame.edge_by_position(pb, &proj[b], pc, &proj[c]),
            frame.edge_by_position(pc, &proj[c], pa, &proj[a]),
        ];
        if let Some(x) = frame.crossing(e, [&proj[a], &proj[b], &proj[c]]) {
            if n == 2 {
                return RayThrough::Undecided;
            }
            let s = x.interpolate([part.scalars[a], part.scalars[b], part.scalars[c]]);
            hits[n] = (x.t, s, k as u32);
            n += 1;
        }
    }
    match n {
        0 => RayThrough::Misses,
        // The line meets the part in a point or along an edge only (the
        // perturbed line crosses it for no length): no segment, as in the
        // ray caster's brute force, which keeps segments of positive
        // length only. The same crossings give the same depths in the
        // walk and the brute force, so all three agree on which segments
        // have a length.
        2 if hits[0].0 == hits[1].0 => RayThrough::Misses,
        2 => {
            let [(t0, s0, k0), (t1, s1, k1)] = hits;
            let ((ti, si, ki), (to, so, ko)) = if t0 <= t1 {
                ((t0, s0, k0), (t1, s1, k1))
            } else {
                ((t1, s1, k1), (t0, s0, k0))
            };
            let v = RegionVertex {
                px: c.x,
                py: c.y,
                z_front: ti * dz,
                z_back: to * dz,
                l: to - ti,
                s_front: si,
                s_back: so,
                profile: false,
            };
            RayThrough::Crosses(v, [ki, ko])
        }
        _ => RayThrough::Undecided,
    }
}

/// One pixel whose centre the exact test and the rasteriser decide
/// differently for a part: `value` is the segment there (the part holds
/// the centre), or `None` (it does not: a blocker).
#[derive(Clone, Copy, Debug)]
pub struct TieDecision {
    pub pixel: (u32, u32),
    pub value: Option<RegionVertex>,
    /// With a value: the part's boundary triangles where the ray enters
    /// and leaves it.
    pub faces: [u32; 2],
}

/// Scratch of [`decide_ties`], reused from part to part.
#[derive(Default)]
pub struct TieScratch {
    /// Each vertex's outgoing edges, as bits (parts of up to 64 vertices).
    bits: Vec<u64>,
    edges: Vec<((u32, u32), bool)>,
    centres: Vec<(u32, u32)>,
    /// Sliver centres ([`scan_triangles`]), then seam centres.
    forced: Vec<(u32, u32)>,
    /// Whether each exact triangle is steep ([`scan_triangles`]).
    pub steep: Vec<bool>,
    near: Vec<(u32, u32)>,
    proj: Vec<Proj>,
    pub decisions: Vec<TieDecision>,
    /// The values of the decisions that hold a segment, as a projection
    /// for the mode's payload.
    pub values: Projected,
}

/// A triangle the GPU draws.
#[derive(Clone, Copy, Debug)]
pub struct DrawnTriangle {
    /// Its corners (indices into the projection's vertices).
    pub corners: [u32; 3],
    /// Their snapped grid positions ([`crate::gpu::ClipMapper::ndc`]).
    pub grid: [[i64; 2]; 3],
    /// Its index among the exact triangles ([`PartTriangles::exact`]).
    pub exact: u32,
}

/// What [`decide_ties`] needs of one part about to be drawn.
pub struct PartTriangles<'a> {
    pub proj: &'a Projected,
    /// Triangles the GPU draws.
    pub drawn: &'a [DrawnTriangle],
    /// Every triangle of the exact part (after coverage culling, which
    /// leaves out only triangles holding no centre).
    pub exact: &'a [[u32; 3]],
    pub width: u32,
    pub height: u32,
    /// The largest extinction or emission rate on the part's scalar range
    /// ([`crate::render::pieces::PieceSource::max_rate`]): what a sliver's
    /// thickness error is weighed by.
    /// Called only where [`Self::rate_bound`] does not settle a question,
    /// possibly many times: the caller keeps the value.
    pub rate: &'a dyn Fn() -> f64,
    /// A bound on `rate` for every part.
    pub rate_bound: f64,
    /// The least and the largest thickness at the part's vertices.
    pub l_range: (f64, f64),
    /// Whether the projection is of the part clipped at the near plane
    /// (its outline is then not the whole part's): every centre goes to
    /// the exact test.
    pub clipped: bool,
    /// Whether a centre next to the outline may be left to the rasteriser
    /// where its segment is optically thin ([`thin_outline`]): colour
    /// draws without isosurfaces, where a centre's side changes the pixel
    /// by the segment's colour only (a counting draw counts every centre).
    pub weighed: bool,
    /// How far the snap to the rasteriser's grid moved each vertex of
    /// `proj` (pixels), where it is known: the sliver tests weigh a
    /// triangle by the largest move of its corners rather than by the
    /// largest move of any corner ([`SNAP_PX`], taken for vertices past
    /// the slice's end, and for every vertex when it is empty).
    pub snap: &'a [f64],
    /// The isovalues the mode finds per fragment (sorted; empty for the
    /// others): in a sliver, the snap of the corners shifts the
    /// interpolated entry and exit scalars by their change across it
    /// times the snap over its width, which can put a centre on the other
    /// side of an isovalue than the piece beside it puts it; those centres
    /// are decided exactly too.
    pub isovalues: &'a [f64],
    /// The scalar the mode's `f32` stage maps to 0 (the middle of the
    /// isovalues: [`crate::render::modes::segment::ScalarMap::centred`]):
    /// the stage's rounding, and the margin of its levels below the
    /// isovalues ([`crate::numeric::tolerance::ISO_LEVEL_F32`]), are
    /// relative to a scalar's distance from it, not to the scalar itself
    /// ([`iso_margin`]).
    pub iso_origin: f64,
}

/// How close (raw scalar) an entry or exit scalar of the `f32` isosurface
/// stages in `[lo, hi]` may come to an isovalue and still be read on the
/// other side of it than the exact scalar lies, beyond what the snap of
/// the corners does: the stage compares the normalised scalar with a level
/// [`crate::numeric::tolerance::ISO_LEVEL_F32`] of the normalised value
/// below it, and rounds the interpolated scalar to a few ulps of the
/// largest normalised corner scalar; both are relative to the distance
/// from `origin` ([`PartTriangles::iso_origin`]), and [`ISO_SLIVER_REL`]
/// of the farther of `lo` and `hi` holds them. In raw terms this is large
/// where the isovalue lies far from the origin against the field's change
/// near it: normalised from the first node of a field from -1000 to 1000,
/// a surface at 0 where the field changes by 4e-3 per pixel has the
/// stage's level a quarter of a pixel from the value, and its rounding a
/// tenth; so the isosurface stages are centred on the isovalues
/// ([`crate::render::modes::segment::ScalarMap::centred`]).
#[inline]
pub fn iso_margin(origin: f64, lo: f64, hi: f64) -> f64 {
    ISO_SLIVER_REL * (lo - origin).abs().max((hi - origin).abs())
}

impl PartTriangles<'_> {
    /// The largest move of the snapped corners of triangle `t`, pixels
    /// (see [`PartTriangles::snap`]).
    #[inline]
    fn snap_of(&self, t: &[u32; 3]) -> f64 {
        let at = |i: u32| self.snap.get(i as usize).copied().unwrap_or(SNAP_PX);
        at(t[0]).max(at(t[1])).max(at(t[2]))
    }
}

/// Decides the centres near the part's outline (see the module docs) into
/// `scratch.decisions`: the pixels where a quad must be drawn first. The
/// sliver centres are those [`scan_triangles`] (with `slivers`) left in
/// `scratch`. Without `outline` (a [`thin_outline`]) only the sliver and
/// seam centres, and those of triangles the snap collapsed.
pub fn decide_ties(
    part: &PartTriangles,
    outline: bool,
    poly: &Polyhedron,
    rays: &TieRays,
    scratch: &mut TieScratch,
) {
    scratch.decisions.clear();
    let pos = |i: u32| part.proj.vertices[i as usize].pos();
    let centres = &mut scratch.centres;
    centres.clear();
    outline_centres(
        part,
        outline,
        centres,
        &mut scratch.bits,
        &mut scratch.edges,
    );
    // Centres next to the mode's seams: decided exactly wherever the part
    // holds them, since the two sides carry different values.
    // With the sliver centres ([`scan_triangles`]): both take the exact
    // segment wherever the part holds them.
    let forced = &mut scratch.forced;
    for &(ia, ib) in &part.proj.seams {
        near_centres(pos(ia), pos(ib), part.width, part.height, forced);
    }
    for line in &part.proj.seam_lines {
        let [a, b] = line.ends;
        let from = forced.len();
        if line.band <= TIE_BAND_PX {
            near_centres(a, b, part.width, part.height, forced);
        } else {
            centres_within(a, b, line.band, part.width, part.height, forced);
        }
        // The searches return a superset (up to `sqrt(2)` times the band
        // across the line): only the centres within the band are forced.
        within_band(forced, from, a, b, line.band.max(TIE_BAND_PX));
    }
    centres.extend_from_slice(forced);
    if centres.is_empty() {
        return;
    }
    centres.sort_unstable();
    centres.dedup();
    forced.sort_unstable();
    // The float filter's margin: only where the part has a positive
    // thickness (a flat part's rays cross it for no length, which only
    // the exact test sees) and its whole outline was projected.
    let margin = if part.clipped || part.l_range.1.is_nan() || part.l_range.1 <= 0.0 {
        None
    } else {
        let (z_min, coord_max) = part
            .proj
            .vertices
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(z, m), v| {
                (z.min(v.z_front), m.max(v.px.abs()).max(v.py.abs()))
            });
        rays.filter_px(z_min, coord_max)
    };
    for &(i, j) in centres.iter() {
        let c = DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
        let sub = SUBPIXEL as i64;
        let q = [i as i64 * sub + sub / 2, j as i64 * sub + sub / 2];
        let grid_in = part.drawn.iter().any(|d| covers_grid(d.grid, q));
        // A seam or sliver centre needs the exact segment wherever the part
        // holds it.
        let forced = !forced.is_empty() && forced.binary_search(&(i, j)).is_ok();
        // Elsewhere, where the float test on the exact triangles is
        // certain and agrees with the rasteriser, there is nothing to
        // decide (most centres in the band).
        if let (Some(m), false) = (margin, forced) {
            if inside_by_float(part.exact, &pos, c, m) == Some(grid_in) {
                continue;
            }
        }
        // Here the float test is not certain (or the centre is forced):
        // the centre lies on an edge of the part's projection up to
        // rounding. Where the part holds it, the exact segment is drawn
        // even where the rasteriser agrees: on such an edge the projection
        // may have regions of no area (a face seen edge-on up to the
        // rounding of its points' coordinates, which fan triangulation
        // leaves out), and the ray through the centre can cross the part
        // for a length the drawn triangle's values at its edge do not
        // give (a face tilted by 1e-15 against the ray leaves the ray
        // inside the part for part of the face only).
        let (value, faces) = match ray_through(poly, rays, c, &mut scratch.proj) {
            RayThrough::Crosses(v, f) => (Some(v), f),
            RayThrough::Misses if grid_in => (None, [0; 2]),
            _ => continue,
        };
        scratch.decisions.push(TieDecision {
            pixel: (i, j),
            value,
            faces,
        });
    }
}

/// Appends the centres within the band of the part's outline: edges of
/// drawn triangles not shared by two of them (with `outline`), and every
/// edge of an exact triangle that is not drawn. Each is tested for
/// centres within the band as it is found.
fn outline_centres(
    part: &PartTriangles,
    outline: bool,
    centres: &mut Vec<(u32, u32)>,
    bits: &mut Vec<u64>,
    edges: &mut Vec<((u32, u32), bool)>,
) {
    let pos = |i: u32| part.proj.vertices[i as usize].pos();
    let spans = part.proj.vertex_spans();
    let (width, height) = (part.width, part.height);
    let near = |ia: u32, ib: u32, out: &mut Vec<(u32, u32)>| {
        let span = spans.map(|s| s[ia as usize].join(&s[ib as usize]));
        near_edge(pos(ia), pos(ib), span, width, height, out);
    };
    // Edges shared with a triangle coverage culling dropped have no centre
    // within the band (it would be within the culling's margin of that
    // triangle, which would then have been kept): not candidates.
    let culled = part.proj.culled_triangles().unwrap_or(&[]);
    if !outline {
        // Only the triangles not drawn, below.
    } else if part.proj.vertices.len() <= 64 {
        // Small parts (almost all): each directed edge in a bit matrix, no
        // sort. The triangles wind the same way (CCW in pixel
        // coordinates), so an edge shared by two of them appears once in
        // each direction, and an outline edge in one direction only.
        let n = part.proj.vertices.len();
        bits.clear();
        bits.resize(n, 0);
        // A slice: its pointer and length stay in registers across the
        // stores.
        let bits = &mut bits[..n];
        let tris = part.drawn.iter().map(|d| &d.corners).chain(culled);
        for t in tris {
            bits[t[0] as usize] |= 1 << t[1];
            bits[t[1] as usize] |= 1 << t[2];
            bits[t[2] as usize] |= 1 << t[0];
        }
        for d in part.drawn {
            let t = d.corners;
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                if bits[b as usize] >> a & 1 == 0 {
                    near(a, b, centres);
                }
            }
        }
    } else {
        // Each undirected edge with whether a drawn triangle has it.
        let key = |a: u32, b: u32| if a < b { (a, b) } else { (b, a) };
        edges.clear();
        for (t, drawn) in part
            .drawn
            .iter()
            .map(|d| (&d.corners, true))
            .chain(culled.iter().map(|t| (t, false)))
        {
            for k in 0..3 {
                edges.push((key(t[k], t[(k + 1) % 3]), drawn));
            }
        }
        edges.sort_unstable();
        let mut k = 0;
        while k < edges.len() {
            let mut n = 1;
            while k + n < edges.len() && edges[k + n].0 == edges[k].0 {
                n += 1;
            }
            if n == 1 && edges[k].1 {
                near(edges[k].0 .0, edges[k].0 .1, centres);
            }
            k += n;
        }
    }
    if part.drawn.len() != part.exact.len() {
        for t in part.exact {
            if !part.drawn.iter().any(|d| d.corners == *t) {
                for k in 0..3 {
                    near(t[k], t[(k + 1) % 3], centres);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
