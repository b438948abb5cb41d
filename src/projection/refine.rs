//! Conforming midpoint refinement of the region triangles.
//!
//! The decision to split is made per *edge*, from the edge's two vertices
//! only, so the two triangles sharing an edge always agree (no T-junctions
//! inside a piece; across pieces, silhouette edges between profile vertices
//! carry the same data in both pieces, hence the same decision). A triangle
//! with one, two or three split edges becomes two, three or four triangles;
//! a new vertex sits at the pixel midpoint `(a + b) / 2` (bit-identical from
//! either side) and gets exact values from the front and back triangles of
//! the regions on either side of the edge, like every other vertex (the
//! widest ones, `FaceTri::width`). Levels repeat until no edge asks for a
//! split or the depth limit is reached.
//!
//! Triangles narrower than [`SLIVER_WIDTH_PX`] (slivers of faces seen
//! edge-on, whose own triangles' values are meaningless) never ask for a
//! split themselves: their edges are split only where a wider neighbour asks,
//! which keeps the triangulation conforming without refining a sliver to the
//! depth limit.
//!
//! Two uses:
//! - perspective views ([`perspective_split`], applied by the projector):
//!   screen-space linear interpolation of values that are linear on a face
//!   in 3D deviates from the perspective-correct value by at most
//!   `|dz| / (4 min z)` of their variation along an edge, and the ray-length
//!   factor `sqrt(1 + u^2 + v^2)` by at most `|d(u, v)|^2 / 8`; edges whose
//!   resulting error bound exceeds [`PERSPECTIVE_INTERP_REL`] of the piece's
//!   scalar range (diameter, for `l`) are split. The projector's
//!   refinement computes each vertex's view-plane position and ray-length
//!   factor once, and compares with the denominators multiplied out (no
//!   square root or division per edge; [`perspective_split`] decides the
//!   same way);
//! - colour accuracy in the exact mode ([`refine`] with the caller's
//!   predicate, e.g. optical depth times colour spread, docs/math.md 8.1).

use glam::DVec2;

use super::subdivision::NIL;
use super::{Projected, RegionVertex, ViewMap};
use crate::numeric::tolerance::{PERSPECTIVE_INTERP_REL, SLIVER_WIDTH_PX};

/// Scratch buffers of the refinement.
#[derive(Clone, Debug, Default)]
pub struct RefineScratch {
    edges: Vec<(u32, u32)>,
    mids: Vec<u32>,
    tris: Vec<[u32; 3]>,
    regs: Vec<u32>,
    /// `FaceTri::width` of each region's front and back triangle.
    widths: Vec<[f64; 2]>,
    /// Per split edge: the region with the widest front (back) triangle.
    best: Vec<super::WidestFaces>,
    /// Per vertex (perspective): view-plane position and ray length per
    /// unit of depth.
    plane: Vec<(DVec2, f64)>,
}

/// Whether the perspective interpolation bound asks to split edge `a`-`b`
/// of a piece with scalar range `scalar_range` and diameter `diameter` (see
/// module docs). Always `false` for orthographic views.
///
/// With `dev = |dz| / (4 min z)` the deviation of the screen-space parameter
/// on the front (back) face and `curv = |d(u, v)|^2 / 8` that of the
/// ray-length factor, the interpolation errors along the edge are at most
/// `dev * |d s|` for the scalars and `g (dev_f |dz_f| + dev_b |dz_b|) +
/// curv * l` for the thickness (`g` the ray-length factor). The edge is split
/// when either exceeds [`PERSPECTIVE_INTERP_REL`] of `scalar_range`
/// (`diameter`). Edges between two profile vertices (silhouette edges, shared
/// with neighbouring pieces) are never split: `l = 0` all along them, so
/// their values have no weight in the integral, and neighbours agree.
pub fn perspective_split(
    view: &ViewMap,
    scalar_range: f64,
    diameter: f64,
    a: &RegionVertex,
    b: &RegionVertex,
) -> bool {
    if view.ortho {
        return false;
    }
    let at = |v: &RegionVertex| (view.plane(v.pos()), view.length_per_depth(v.pos()));
    split_at(scalar_range, diameter, a, b, at(a), at(b))
}

/// [`perspective_split`] with each vertex's view-plane position and ray
/// length per unit of depth given.
#[inline]
fn split_at(
    scalar_range: f64,
    diameter: f64,
    a: &RegionVertex,
    b: &RegionVertex,
    (ua, ga): (DVec2, f64),
    (ub, gb): (DVec2, f64),
) -> bool {
    if a.profile && b.profile {
        // l = 0 all along a silhouette edge: its values carry no weight.
        return false;
    }
    // dev = |dz| / (4 min z) on each face, compared with the denominators
    // multiplied out (depths are positive): no division per edge.
    let (dzf, dzb) = ((a.z_front - b.z_front).abs(), (a.z_back - b.z_back).abs());
    let (mf, mb) = (4.0 * a.z_front.min(b.z_front), 4.0 * a.z_back.min(b.z_back));
    let ts = PERSPECTIVE_INTERP_REL * scalar_range;
    if dzf * (a.s_front - b.s_front).abs() > ts * mf || dzb * (a.s_back - b.s_back).abs() > ts * mb
    {
        return true;
    }
    let curv = (ua - ub).length_squared() / 8.0;
    let g = ga.max(gb);
    // el = g (dzf^2 / mf + dzb^2 / mb) + curv l, times mf mb.
    let el = g * (dzf * dzf * mb + dzb * dzb * mf) + curv * a.l.max(b.l) * mf * mb;
    el > PERSPECTIVE_INTERP_REL * diameter * mf * mb
}

pub(crate) fn refine_perspective(
    out: &mut Projected,
    scalar_range: f64,
    diameter: f64,
    max_depth: u32,
    s: &mut RefineScratch,
) {
    let view = out.view;
    if view.ortho {
        return;
    }
    // View-plane positions and ray-length factors once per vertex (the
    // same values `perspective_split` computes per edge).
    let mut plane = std::mem::take(&mut s.plane);
    plane.clear();
    refine_with(
        out,
        max_depth,
        |v: &[RegionVertex], a: u32, b: u32| {
            for w in &v[plane.len()..] {
                plane.push((view.plane(w.pos()), view.length_per_depth(w.pos())));
            }
            let (a, b) = (a as usize, b as usize);
            split_at(scalar_range, diameter, &v[a], &v[b], plane[a], plane[b])
        },
        s,
    );
    s.plane = plane;
}

/// Splits region triangles at edge midpoints, recursively (at most
/// `max_depth` levels), wherever `split(a, b)` says so for an edge's two
/// vertices. `regions` keeps the unrefined polygons; `triangles` and
/// `triangle_region` are replaced.
pub fn refine(
    out: &mut Projected,
    max_depth: u32,
    mut split: impl FnMut(&RegionVertex, &RegionVertex) -> bool,
) {
    let mut s = RefineScratch::default();
    refine_with(
        out,
        max_depth,
        |v: &[RegionVertex], a: u32, b: u32| split(&v[a as usize], &v[b as usize]),
        &mut s,
    );
}

/// [`refine`] with scratch buffers; `split(vertices, a, b)` decides for the
/// edge between vertices `a < b`.
pub(crate) fn refine_with(
    out: &mut Projected,
    max_depth: u32,
    mut split: impl FnMut(&[RegionVertex], u32, u32) -> bool,
    s: &mut RefineScratch,
) {
    s.widths.clear();
    // Vertices from this index on are new since the edges were last
    // tested. `split` depends on an edge's two vertices alone, and every
    // edge a level creates has a new vertex (a midpoint), so an edge of
    // two older vertices was tested and kept whole before: it is not asked
    // again.
    let mut fresh = 0u32;
    for _ in 0..max_depth {
        s.edges.clear();
        for t in &out.triangles {
            if t.iter().all(|&i| i < fresh) {
                continue;
            }
            let [a, b, c] = t.map(|i| out.vertices[i as usize].pos());
            if is_sliver(a, b, c) {
                // Negligible: split only where a neighbour asks (conforming).
                continue;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                if key.1 >= fresh && split(&out.vertices, key.0, key.1) {
                    s.edges.push(key);
                }
            }
        }
        if s.edges.is_empty() {
            return;
        }
        s.edges.sort_unstable();
        s.edges.dedup();
        if s.widths.is_empty() {
            s.widths.extend(
                out.region_faces
                    .iter()
                    .map(|f| f.map(|t| out.faces[t as usize].width())),
            );
        }
        let prev = fresh;
        fresh = out.vertices.len() as u32;
        s.mids.clear();
        s.mids.resize(s.edges.len(), NIL);
        // Front and back values of a midpoint come from the widest front
        // (back) triangle of the regions on either side of its edge (see
        // `FaceTri::width`).
        s.best.clear();
        s.best.resize(s.edges.len(), [(NIL, -1.0); 2]);
        // Only edges with a vertex from `old` on were asked, so triangles
        // of older vertices alone keep all their edges.
        let old = prev;
        for ti in 0..out.triangles.len() {
            let t = out.triangles[ti];
            if t.iter().all(|&i| i < old) {
                continue;
            }
            let r = out.triangle_region[ti];
            let w = s.widths[r as usize];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if let Ok(i) = s.edges.binary_search(&(a.min(b), a.max(b))) {
                    for (best, &ws) in s.best[i].iter_mut().zip(&w) {
                        if ws > best.1 {
                            *best = (r, ws);
                        }
                    }
                }
            }
        }
        s.tris.clear();
        s.regs.clear();
        for ti in 0..out.triangles.len() {
            let t = out.triangles[ti];
            let r = out.triangle_region[ti];
            if t.iter().all(|&i| i < old) {
                s.tris.push(t);
                s.regs.push(r);
                continue;
            }
            let mut m = [NIL; 3];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if let Ok(i) = s.edges.binary_search(&(a.min(b), a.max(b))) {
                    if s.mids[i] == NIL {
                        let [(rf, _), (rb, _)] = s.best[i];
                        s.mids[i] = midpoint(out, [rf, rb], a.min(b), a.max(b));
                    }
                    m[k] = s.mids[i];
                }
            }
            emit_split(t, m, r, &mut s.tris, &mut s.regs);
        }
        std::mem::swap(&mut out.triangles, &mut s.tris);
        std::mem::swap(&mut out.triangle_region, &mut s.regs);
    }
}

/// Whether the triangle's smallest width (twice its area over its longest
/// edge) is below [`SLIVER_WIDTH_PX`] (compared squared: no square root or
/// division per triangle).
#[inline]
fn is_sliver(a: DVec2, b: DVec2, c: DVec2) -> bool {
    let area2 = (b - a).perp_dot(c - a);
    let lmax2 = (b - a)
        .length_squared()
        .max((c - b).length_squared())
        .max((a - c).length_squared());
    lmax2 == 0.0 || area2 * area2 < SLIVER_WIDTH_PX * SLIVER_WIDTH_PX * lmax2
}

/// Creates the midpoint vertex of edge `a`-`b`, with its front values from
/// region `r[0]`'s front triangle and its back values from region `r[1]`'s
/// back triangle.
fn midpoint(out: &mut Projected, r: [u32; 2], a: u32, b: u32) -> u32 {
    let (va, vb) = (out.vertices[a as usize], out.vertices[b as usize]);
    let q = (DVec2::new(va.px, va.py) + DVec2::new(vb.px, vb.py)) * 0.5;
    let (front, back) = (
        out.region_face(r[0] as usize, 0),
        out.region_face(r[1] as usize, 1),
    );
    let mut v = RegionVertex::evaluate(&out.view, front, back, q, false);
    if va.profile && vb.profile {
        v.z_back = v.z_front;
        v.s_back = v.s_front;
        v.l = 0.0;
        v.profile = true;
    }
    out.vertices.push(v);
    (out.vertices.len() - 1) as u32
}

/// The triangles of `t = [a, b, c]` with midpoints `m = [ab, bc, ca]`
/// (`NIL` where the edge is not split).
fn emit_split(t: [u32; 3], m: [u32; 3], r: u32, tris: &mut Vec<[u32; 3]>, regs: &mut Vec<u32>) {
    let n = m.iter().filter(|&&x| x != NIL).count();
    let mut push = |x: [u32; 3]| {
        tris.push(x);
        regs.push(r);
    };
    match n {
        0 => push(t),
        3 => {
            let [a, b, c] = t;
            let [ab, bc, ca] = m;
            push([a, ab, ca]);
            push([ab, b, bc]);
            push([ca, bc, c]);
            push([ab, bc, ca]);
        }
        _ => {
            // Rotate so that edge 0 (a-b) is split.
            let k = (0..3).find(|&k| m[k] != NIL).unwrap_or(0);
            let k = if n == 2 && m[(k + 2) % 3] != NIL {
                (k + 2) % 3
            } else {
                k
            };
            let a = t[k];
            let b = t[(k + 1) % 3];
            let c = t[(k + 2) % 3];
            let ab = m[k];
            let bc = m[(k + 1) % 3];
            if bc == NIL {
                push([a, ab, c]);
                push([ab, b, c]);
            } else {
                push([ab, b, bc]);
                push([a, ab, bc]);
                push([a, bc, c]);
            }
        }
    }
}
