//! Clipping a triangulated convex piece to a band `lo <= f <= hi` of a
//! per-point value `f` that is linear on every triangle: the near plane
//! (`f = z`) and breakpoint slabs (`f = scalar`).
//!
//! Each boundary triangle is clipped (Sutherland-Hodgman) against both
//! levels. A new point is always computed from the two *original* points of
//! the triangle edge it lies on (a clipped polygon's edge that crosses a
//! level is part of an original edge: the other kind of edge lies on the
//! previous level), with the endpoints in a canonical order that depends only
//! on their positions, so two cells sharing the edge get bit-identical points;
//! its value is set to the level exactly (and a piece's point gradients,
//! when it has them, are interpolated there like the scalar). The caps are the boundary loops left
//! after cancelling opposite on-level edges of the kept polygons; they are
//! convex and fan-triangulated. A piece that only touches the band is empty.

use glam::DVec3;

use super::polyhedron::Polyhedron;
use super::ProjectionError;

/// What is clipped: the view depth `z` or the scalar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClipValue {
    Depth,
    Scalar,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Key {
    Orig(u32),
    /// On original edge (i, j), i < j, at level 0 (lo) or 1 (hi).
    Cut(u32, u32, u8),
}

#[derive(Clone, Copy, Debug)]
struct PV {
    key: Key,
    f: f64,
}

/// Pieces with at most this many points look output points up in a dense
/// table (`n + 2 n^2` slots: every original point and every edge cut at
/// either level); larger ones in a list.
const DENSE_MAX: usize = 16;

/// How output points are looked up (tests force either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Lookup {
    /// Dense up to [`DENSE_MAX`] points, a list beyond.
    #[default]
    Auto,
    #[cfg(test)]
    List,
    #[cfg(test)]
    Dense,
}

/// Scratch for [`Clipper::clip`].
#[derive(Clone, Debug, Default)]
pub struct Clipper {
    lookup: Lookup,
    map: Vec<(Key, u32)>,
    /// Dense lookup (pieces of at most [`DENSE_MAX`] points): output index
    /// + 1 per key slot, 0 when not made yet.
    dense: Vec<u32>,
    /// The clipped value of every source point.
    vals: Vec<f64>,
    poly: Vec<PV>,
    tmp: Vec<PV>,
    level_edges: Vec<(u32, u32)>,
}

impl Clipper {
    /// Clips `src` to `lo <= f <= hi` into `out` (cleared first). Returns
    /// `Ok(false)` when nothing of positive volume is left (then `out` is
    /// empty).
    pub fn clip(
        &mut self,
        src: &Polyhedron,
        what: ClipValue,
        lo: f64,
        hi: f64,
        out: &mut Polyhedron,
    ) -> Result<bool, ProjectionError> {
        out.clear();
        self.vals.clear();
        match what {
            ClipValue::Depth => self.vals.extend(src.points.iter().map(|p| p.z)),
            ClipValue::Scalar => self.vals.extend_from_slice(&src.scalars),
        }
        let (mut vmin, mut vmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for &v in &self.vals {
            vmin = vmin.min(v);
            vmax = vmax.max(v);
        }
        if !(vmax > lo && vmin < hi) {
            return Ok(false);
        }
        let n = src.points.len();
        self.map.clear();
        self.dense.clear();
        let dense = match self.lookup {
            Lookup::Auto => n <= DENSE_MAX,
            #[cfg(test)]
            Lookup::List => false,
            #[cfg(test)]
            Lookup::Dense => true,
        };
        if dense {
            self.dense.resize(n + 2 * n * n, 0);
        }
        self.level_edges.clear();
        let levels = [lo, hi];
        for t in &src.triangles {
            self.poly.clear();
            for &i in t {
                self.poly.push(PV {
                    key: Key::Orig(i),
                    f: self.vals[i as usize],
                });
            }
            for lev in 0..2u8 {
                let l = levels[lev as usize];
                if !l.is_finite() {
                    continue;
                }
                let inside = |f: f64| if lev == 0 { f >= l } else { f <= l };
                self.tmp.clear();
                let n = self.poly.len();
                for k in 0..n {
                    let (p, q) = (self.poly[k], self.poly[(k + 1) % n]);
                    if inside(p.f) {
                        self.tmp.push(p);
                    }
                    if (p.f < l && q.f > l) || (p.f > l && q.f < l) {
                        let (i, j) = original_edge(p.key, q.key);
                        self.tmp.push(PV {
                            key: Key::Cut(i.min(j), i.max(j), lev),
                            f: l,
                        });
                    }
                }
                std::mem::swap(&mut self.poly, &mut self.tmp);
            }
            if self.poly.len() < 3 {
                continue;
            }
            // Emit the kept polygon (convex) as a fan.
            let mut ids = [0u32; 9];
            let m = self.poly.len().min(ids.len());
            for (k, id) in ids.iter_mut().enumerate().take(m) {
                let key = self.poly[k].key;
                *id = self.point_of(key, src, what, levels, out);
            }
            for k in 1..m - 1 {
                if ids[0] != ids[k] && ids[k] != ids[k + 1] && ids[0] != ids[k + 1] {
                    out.triangles.push([ids[0], ids[k], ids[k + 1]]);
                }
            }
            // Directed edges lying on a level.
            for k in 0..m {
                let (p, q) = (self.poly[k], self.poly[(k + 1) % m]);
                let on_lo = p.f == lo && q.f == lo;
                let on_hi = p.f == hi && q.f == hi;
                if (on_lo || on_hi) && ids[k] != ids[(k + 1) % m] {
                    self.level_edges.push((ids[k], ids[(k + 1) % m]));
                }
            }
        }
        // Cancel opposite pairs; what is left bounds the caps.
        let mut k = 0;
        while k < self.level_edges.len() {
            let (a, b) = self.level_edges[k];
            if let Some(j) = self.level_edges.iter().position(|&e| e == (b, a)) {
                let (hi_i, lo_i) = (k.max(j), k.min(j));
                self.level_edges.swap_remove(hi_i);
                self.level_edges.swap_remove(lo_i);
                k = 0;
                continue;
            }
            k += 1;
        }
        // Chain the rest into loops; each cap runs opposite to them.
        while let Some((a0, b0)) = self.level_edges.pop() {
            let start = a0;
            let mut cur = b0;
            let mut loop_pts = [0u32; 64];
            loop_pts[0] = a0;
            let mut n = 1;
            while cur != start {
                if n >= loop_pts.len() {
                    return Err(ProjectionError::OpenSurface);
                }
                loop_pts[n] = cur;
                n += 1;
                match self.level_edges.iter().position(|e| e.0 == cur) {
                    Some(j) => {
                        cur = self.level_edges.swap_remove(j).1;
                    }
                    None => return Err(ProjectionError::OpenSurface),
                }
            }
            // Reverse loop: fan from loop_pts[0] over the reversed order.
            for k in 1..n.saturating_sub(1) {
                out.triangles
                    .push([loop_pts[0], loop_pts[n - k], loop_pts[n - k - 1]]);
            }
        }
        Ok(!out.triangles.is_empty())
    }

    /// Output index of the point with `key`, creating it on first use.
    fn point_of(
        &mut self,
        key: Key,
        src: &Polyhedron,
        what: ClipValue,
        levels: [f64; 2],
        out: &mut Polyhedron,
    ) -> u32 {
        let n = src.points.len();
        let slot = (!self.dense.is_empty()).then(|| match key {
            Key::Orig(i) => i as usize,
            Key::Cut(i, j, lev) => n + ((i as usize * n + j as usize) << 1) + lev as usize,
        });
        match slot {
            Some(k) if self.dense[k] != 0 => return self.dense[k] - 1,
            Some(_) => {}
            None => {
                if let Some(&(_, i)) = self.map.iter().find(|(k, _)| *k == key) {
                    return i;
                }
            }
        }
        let idx = out.points.len() as u32;
        match key {
            Key::Orig(i) => {
                out.points.push(src.points[i as usize]);
                out.scalars.push(src.scalars[i as usize]);
                if src.gradients.len() == n {
                    out.gradients.push(src.gradients[i as usize]);
                }
                if src.world.len() == n {
                    out.world.push(src.world[i as usize]);
                }
            }
            Key::Cut(i, j, lev) => {
                let l = levels[lev as usize];
                let (pi, pj) = (src.points[i as usize], src.points[j as usize]);
                // Canonical order by position, so that neighbours agree.
                let (a, b) = if lex_less(pi, pj) { (i, j) } else { (j, i) };
                let (pa, pb) = (src.points[a as usize], src.points[b as usize]);
                let (fa, fb) = (self.vals[a as usize], self.vals[b as usize]);
                let mu = ((l - fa) / (fb - fa)).clamp(0.0, 1.0);
                let mut p = pa + (pb - pa) * mu;
                let (sa, sb) = (src.scalars[a as usize], src.scalars[b as usize]);
                let mut s = sa + (sb - sa) * mu;
                match what {
                    ClipValue::Depth => p.z = l,
                    ClipValue::Scalar => s = l,
                }
                out.points.push(p);
                out.scalars.push(s);
                if src.gradients.len() == n {
                    let (ga, gb) = (src.gradients[a as usize], src.gradients[b as usize]);
                    out.gradients.push(ga + (gb - ga) * mu);
                }
                if src.world.len() == n {
                    let (wa, wb) = (src.world[a as usize], src.world[b as usize]);
                    out.world.push(wa + (wb - wa) * mu);
                }
            }
        }
        match slot {
            Some(k) => self.dense[k] = idx + 1,
            None => self.map.push((key, idx)),
        }
        idx
    }
}

fn lex_less(a: DVec3, b: DVec3) -> bool {
    (a.z, a.x, a.y) < (b.z, b.x, b.y)
}

/// The original edge a clipped-polygon edge that crosses a level lies on.
fn original_edge(p: Key, q: Key) -> (u32, u32) {
    match (p, q) {
        (Key::Cut(i, j, _), _) | (_, Key::Cut(i, j, _)) => (i, j),
        (Key::Orig(i), Key::Orig(j)) => (i, j),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testdata::Rng;

    /// A convex piece: the convex hull of `k` points on an ellipsoid
    /// (`crate::mesh::hull`; points off the hull are simply unused).
    fn piece(k: usize, seed: u64) -> Polyhedron {
        let mut rng = Rng(seed);
        let pts: Vec<DVec3> = (0..k)
            .map(|_| {
                let (u, v) = (rng.f64() * std::f64::consts::TAU, rng.f64() * 2.0 - 1.0);
                let r = (1.0 - v * v).sqrt();
                DVec3::new(2.0 * r * u.cos(), r * u.sin(), 0.7 * v + 3.0)
            })
            .collect();
        let tris = crate::mesh::hull::convex_hull(&pts, None)
            .expect("hull")
            .faces;
        let scalars = pts.iter().map(|p| p.x + 0.3 * p.y * p.z).collect();
        // World positions: the view ones moved, so that the clip's
        // interpolation of them is checked too.
        let world = pts
            .iter()
            .map(|p| *p + DVec3::new(10.0, -3.0, 0.5))
            .collect();
        let mut poly = Polyhedron {
            points: pts,
            scalars,
            triangles: tris,
            gradients: Vec::new(),
            holes: Vec::new(),
            world,
        };
        poly.orient_outward();
        poly
    }

    /// The dense and the list lookup give the same pieces, point for point,
    /// for small and large pieces, scalar and depth bands.
    #[test]
    fn dense_and_list_lookups_agree() {
        let mut made = 0;
        for (k, seed) in [(4, 1), (6, 2), (8, 3), (12, 4), (16, 5), (24, 6), (40, 7)] {
            let src = piece(k, seed);
            for (what, lo, hi) in [
                (ClipValue::Scalar, -0.5, 0.4),
                (ClipValue::Scalar, 0.1, f64::INFINITY),
                (ClipValue::Depth, 2.6, 3.3),
            ] {
                let mut out = Vec::new();
                for lookup in [Lookup::Auto, Lookup::List, Lookup::Dense] {
                    let mut c = Clipper {
                        lookup,
                        ..Default::default()
                    };
                    let mut poly = Polyhedron::default();
                    let kept = c.clip(&src, what, lo, hi, &mut poly).unwrap();
                    out.push((kept, poly));
                }
                assert_eq!(out[0], out[1], "{k} points, {what:?}");
                assert_eq!(out[0], out[2], "{k} points, {what:?}");
                made += out[0].0 as usize;
                if out[0].0 {
                    let v = out[0].1.volume();
                    assert!(v > 0.0 && v < src.volume(), "{v}");
                }
            }
        }
        assert!(made >= 15, "{made}");
    }
}
