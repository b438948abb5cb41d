//! Clipping a piece's projected regions to the image window, for
//! renderers ([`super::Projector::clip_to_image`]).
//!
//! Near-plane caps project to ~1e9 pixels, where no bounded refinement makes
//! screen-space interpolation accurate on screen; the rasteriser only
//! samples pixel centres, so regions are clipped to the image rectangle
//! grown by [`IMAGE_CLIP_MARGIN_PX`]. Regions are convex, so
//! Sutherland-Hodgman clipping against the four window lines gives convex
//! polygons. Every point of a clipped region has a key ([`WinKey`]: an
//! original vertex, the cut of an original edge by a window line, a window
//! corner), so regions sharing an edge share the points cut on it, with
//! bit-identical positions and one vertex. New vertices take their values
//! from the widest front and back triangles of the regions that produced
//! them, as the unclipped vertices do; then the regions are triangulated
//! again.

use glam::DVec2;

use super::subdivision::NIL;
use super::{Projected, RegionVertex, WidestFaces};
use crate::numeric::tolerance::IMAGE_CLIP_MARGIN_PX;

/// A point of a region polygon being clipped to the image window.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WinPt {
    key: WinKey,
    p: DVec2,
}

/// Identity of a point of a clipped region, so that regions sharing an edge
/// share the points cut on it (bit-identical positions and one vertex).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum WinKey {
    /// A region vertex (index into the unclipped vertices).
    V(u32),
    /// Where the region edge between vertices `(i, j)`, `i < j`, crosses
    /// window line `k`.
    Cut(u32, u32, u8),
    /// The window corner where lines `j < k` meet.
    Corner(u8, u8),
    /// A crossing of an edge that is neither (rounding only); not shared.
    Own(u32),
}

/// Scratch of [`WindowScratch::clip`].
#[derive(Clone, Debug, Default)]
pub(super) struct WindowScratch {
    poly: Vec<WinPt>,
    tmp: Vec<WinPt>,
    map: Vec<u32>,
    /// Shared new points: key, vertex id, and the regions (with widths)
    /// whose front and back triangles gave its values.
    keys: Vec<(WinKey, u32, WidestFaces)>,
    verts: Vec<RegionVertex>,
    /// The clipped regions.
    regions: super::RegionList,
    own: u32,
}

impl WindowScratch {
    /// Clips every region of `out` to the image rectangle grown by
    /// [`IMAGE_CLIP_MARGIN_PX`] (Sutherland-Hodgman: regions are convex, so
    /// are the results), renumbers the vertices that are still used and
    /// re-triangulates. Nothing happens when every vertex is inside.
    ///
    /// Window lines: 0 `x = lo.x`, 1 `x = hi.x`, 2 `y = lo.y`, 3 `y = hi.y`.
    /// A cut point on a region edge is computed from the edge's two original
    /// vertices, from the one nearer the line (the far one may be ~1e9 pixels
    /// away), the same way from both regions sharing the edge.
    pub(super) fn clip(&mut self, out: &mut Projected) {
        let m = IMAGE_CLIP_MARGIN_PX;
        let lo = DVec2::new(-m, -m);
        let hi = DVec2::new(out.view.width + m, out.view.height + m);
        let level = [lo.x, hi.x, lo.y, hi.y];
        let inside_all = |p: DVec2| p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y;
        if out.vertices.iter().all(|v| inside_all(v.pos())) {
            return;
        }
        // Signed distance to line k, inside >= 0.
        let dist = |k: usize, p: DVec2| match k {
            0 => p.x - lo.x,
            1 => hi.x - p.x,
            2 => p.y - lo.y,
            _ => hi.y - p.y,
        };
        let axis = |k: usize| k / 2;
        let get = |p: DVec2, a: usize| if a == 0 { p.x } else { p.y };
        let set = |p: &mut DVec2, a: usize, v: f64| {
            if a == 0 {
                p.x = v
            } else {
                p.y = v
            }
        };
        self.map.clear();
        self.map.resize(out.vertices.len(), NIL);
        self.keys.clear();
        self.verts.clear();
        self.regions.clear();
        self.own = 0;
        for r in 0..out.regions.len() {
            self.poly.clear();
            for &i in &out.regions[r] {
                self.poly.push(WinPt {
                    key: WinKey::V(i),
                    p: out.vertices[i as usize].pos(),
                });
            }
            for k in 0..4usize {
                if self.poly.len() < 3 {
                    break;
                }
                self.tmp.clear();
                let n = self.poly.len();
                for e in 0..n {
                    let (p, q) = (self.poly[e], self.poly[(e + 1) % n]);
                    let (fp, fq) = (dist(k, p.p), dist(k, q.p));
                    if fp >= 0.0 {
                        self.tmp.push(p);
                    }
                    if !((fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0)) {
                        continue;
                    }
                    let a = axis(k);
                    let o = 1 - a;
                    // Both ends on a window line of the other axis: a corner.
                    let corner = [2 * o, 2 * o + 1]
                        .into_iter()
                        .find(|&j| get(p.p, o) == level[j] && get(q.p, o) == level[j]);
                    let pt = if let Some(j) = corner {
                        let mut c = DVec2::ZERO;
                        set(&mut c, a, level[k]);
                        set(&mut c, o, level[j]);
                        WinPt {
                            key: WinKey::Corner(j.min(k) as u8, j.max(k) as u8),
                            p: c,
                        }
                    } else {
                        let edge = match (p.key, q.key) {
                            (WinKey::V(i), WinKey::V(j)) => Some((i.min(j), i.max(j))),
                            (WinKey::Cut(i, j, _), WinKey::V(x))
                            | (WinKey::V(x), WinKey::Cut(i, j, _))
                                if x == i || x == j =>
                            {
                                Some((i, j))
                            }
                            (WinKey::Cut(i, j, _), WinKey::Cut(x, y, _)) if (i, j) == (x, y) => {
                                Some((i, j))
                            }
                            _ => None,
                        };
                        let (u, v, key) = match edge {
                            Some((i, j)) => (
                                out.vertices[i as usize].pos(),
                                out.vertices[j as usize].pos(),
                                WinKey::Cut(i, j, k as u8),
                            ),
                            None => {
                                self.own += 1;
                                (p.p, q.p, WinKey::Own(self.own))
                            }
                        };
                        // From the end nearer the line.
                        let (b, t) = if dist(k, u).abs() <= dist(k, v).abs() {
                            (u, v)
                        } else {
                            (v, u)
                        };
                        let mu = (level[k] - get(b, a)) / (get(t, a) - get(b, a));
                        let w = get(b, o) + mu * (get(t, o) - get(b, o));
                        let (wl, wh) = (get(u, o).min(get(v, o)), get(u, o).max(get(v, o)));
                        let mut c = DVec2::ZERO;
                        set(&mut c, a, level[k]);
                        set(&mut c, o, w.clamp(wl, wh));
                        WinPt { key, p: c }
                    };
                    self.tmp.push(pt);
                }
                std::mem::swap(&mut self.poly, &mut self.tmp);
            }
            // Write the clipped polygon back with new vertex ids.
            let (front, back) = (out.region_face(r, 0), out.region_face(r, 1));
            let wr = [front.width(), back.width()];
            if self.poly.len() < 3 {
                self.regions.close();
                continue;
            }
            for w in &self.poly {
                let id = match w.key {
                    WinKey::V(i) => {
                        if self.map[i as usize] == NIL {
                            self.map[i as usize] = self.verts.len() as u32;
                            self.verts.push(out.vertices[i as usize]);
                        }
                        self.map[i as usize]
                    }
                    key => {
                        // A point shared by the regions on either side of
                        // an edge (or around a corner) takes its front
                        // (back) values from the widest front (back)
                        // triangle among them (`FaceTri::width`).
                        let found = self.keys.iter().position(|e| e.0 == key);
                        let (id, best, fresh) = match found {
                            Some(e) => {
                                let (_, id, mut best) = self.keys[e];
                                let mut better = false;
                                for side in 0..2 {
                                    if wr[side] > best[side].1 {
                                        best[side] = (r as u32, wr[side]);
                                        better = true;
                                    }
                                }
                                self.keys[e].2 = best;
                                (id, best, better)
                            }
                            None => {
                                let id = self.verts.len() as u32;
                                self.verts.push(RegionVertex::default());
                                let best = [(r as u32, wr[0]), (r as u32, wr[1])];
                                self.keys.push((key, id, best));
                                (id, best, true)
                            }
                        };
                        if fresh {
                            let mut v = RegionVertex::evaluate(
                                &out.view,
                                out.region_face(best[0].0 as usize, 0),
                                out.region_face(best[1].0 as usize, 1),
                                w.p,
                                false,
                            );
                            if let WinKey::Cut(i, j, _) = key {
                                let (vi, vj) = (out.vertices[i as usize], out.vertices[j as usize]);
                                if vi.profile && vj.profile {
                                    // On a silhouette edge (as refinement midpoints).
                                    v.z_back = v.z_front;
                                    v.s_back = v.s_front;
                                    v.l = 0.0;
                                    v.profile = true;
                                }
                            }
                            self.verts[id as usize] = v;
                        }
                        id
                    }
                };
                let open = self.regions.open();
                if open.last() != Some(&id) && open.first() != Some(&id) {
                    self.regions.push_vertex(id);
                }
            }
            if self.regions.open().len() < 3 {
                self.regions.discard_open();
            }
            self.regions.close();
        }
        std::mem::swap(&mut out.vertices, &mut self.verts);
        std::mem::swap(&mut out.regions, &mut self.regions);
        out.triangulate_regions();
        // The outline now runs along the image's edges too.
        out.outline_profile = false;
    }
}
