//! 3D convex hull (quickhull) and its volume, for the convexity ratio
//! `mesh volume / hull volume` that `info` reports.
//!
//! How it works (Barber, Dobkin and Huhdanpaa's quickhull, triangles only):
//! 1. An initial tetrahedron from extreme points; every other point goes to
//!    the *outside set* of the first face it lies strictly above.
//! 2. Repeatedly take a face with a non-empty outside set and its farthest
//!    point `p`; collect the faces `p` sees (breadth-first over face
//!    neighbours), whose border with the unseen faces is the *horizon*; replace
//!    the seen faces by the triangles (horizon edge, `p`), linking neighbours;
//!    hand the seen faces' outside points to the new faces they lie strictly
//!    above, dropping the rest (they are inside).
//!
//! "Strictly above" is decided by the exact predicate
//! [`crate::numeric::predicates::orient3d`], so coplanar points (whole faces
//! of a structured grid) are never added and the loop cannot cycle; only the
//! choice of the farthest point uses floats. Flat hulls (all points coplanar
//! or collinear) have no volume: [`convex_hull`] returns `None`.
//!
//! For a mesh only the points of boundary faces can be hull vertices, so
//! callers pass those ([`super::report`]).

use std::collections::HashMap;

use glam::DVec3;

use crate::numeric::predicates::{orient3d, Side};

/// A closed triangulated convex hull: faces wind outward (right-hand rule).
#[derive(Clone, Debug, Default)]
pub struct Hull {
    /// Triangles as indices into the input points.
    pub faces: Vec<[u32; 3]>,
}

impl Hull {
    /// Enclosed volume.
    pub fn volume(&self, points: &[DVec3]) -> f64 {
        let o = self
            .faces
            .first()
            .map_or(DVec3::ZERO, |f| points[f[0] as usize]);
        self.faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|i| points[i as usize] - o);
                a.dot(b.cross(c))
            })
            .sum::<f64>()
            / 6.0
    }
}

struct Face {
    v: [u32; 3],
    /// Neighbour across edge `v[i] -> v[(i + 1) % 3]`.
    nb: [u32; 3],
    alive: bool,
    outside: Vec<u32>,
    /// Iteration stamp and whether the face was seen in that iteration.
    stamp: u32,
    seen: bool,
}

struct Builder<'a> {
    p: &'a [DVec3],
    faces: Vec<Face>,
}

impl Builder<'_> {
    fn above(&self, f: usize, q: u32) -> bool {
        let [a, b, c] = self.faces[f].v.map(|i| self.p[i as usize]);
        orient3d(a, b, c, self.p[q as usize]) == Side::Positive
    }

    fn add_face(&mut self, v: [u32; 3]) -> u32 {
        self.faces.push(Face {
            v,
            nb: [u32::MAX; 3],
            alive: true,
            outside: Vec::new(),
            stamp: 0,
            seen: false,
        });
        (self.faces.len() - 1) as u32
    }

    /// Farthest point of face `f`'s outside set (by float distance).
    fn farthest(&self, f: usize) -> Option<u32> {
        let [a, b, c] = self.faces[f].v.map(|i| self.p[i as usize]);
        let n = (b - a).cross(c - a);
        self.faces[f].outside.iter().copied().max_by(|&x, &y| {
            let dx = n.dot(self.p[x as usize] - a);
            let dy = n.dot(self.p[y as usize] - a);
            dx.total_cmp(&dy)
        })
    }

    /// Adds point `q` seen by face `f0`.
    fn add_point(&mut self, f0: usize, q: u32, iter: u32, stack: &mut Vec<u32>) {
        // 1. Seen faces and horizon (edge a->b of a seen face, unseen face h).
        let mut seen = vec![f0 as u32];
        self.faces[f0].stamp = iter;
        self.faces[f0].seen = true;
        let mut horizon: Vec<(u32, u32, u32)> = Vec::new();
        let mut k = 0;
        while k < seen.len() {
            let g = seen[k] as usize;
            k += 1;
            for i in 0..3 {
                let h = self.faces[g].nb[i] as usize;
                let visible = if self.faces[h].stamp == iter {
                    self.faces[h].seen
                } else {
                    let v = self.above(h, q);
                    self.faces[h].stamp = iter;
                    self.faces[h].seen = v;
                    if v {
                        seen.push(h as u32);
                    }
                    v
                };
                if !visible {
                    let v = self.faces[g].v;
                    horizon.push((v[i], v[(i + 1) % 3], h as u32));
                }
            }
        }
        // 2. New faces (a, b, q), linked to the unseen faces and each other.
        let mut by_start: HashMap<u32, u32> = HashMap::with_capacity(horizon.len());
        let mut new_faces = Vec::with_capacity(horizon.len());
        for &(a, b, h) in &horizon {
            let nf = self.add_face([a, b, q]);
            self.faces[nf as usize].nb[0] = h;
            let hf = &mut self.faces[h as usize];
            for j in 0..3 {
                if hf.v[j] == b && hf.v[(j + 1) % 3] == a {
                    hf.nb[j] = nf;
                }
            }
            by_start.insert(a, nf);
            new_faces.push(nf);
        }
        for &nf in &new_faces {
            let [a, b, _] = self.faces[nf as usize].v;
            // edge b->q borders the new face starting at b (its edge q->b)
            if let Some(&m) = by_start.get(&b) {
                self.faces[nf as usize].nb[1] = m;
                self.faces[m as usize].nb[2] = nf;
            }
            let _ = a;
        }
        // 3. Hand the seen faces' outside points on.
        for &g in &seen {
            self.faces[g as usize].alive = false;
            let pts = std::mem::take(&mut self.faces[g as usize].outside);
            for r in pts {
                if r == q {
                    continue;
                }
                if let Some(&nf) = new_faces.iter().find(|&&nf| self.above(nf as usize, r)) {
                    self.faces[nf as usize].outside.push(r);
                }
            }
        }
        for &nf in &new_faces {
            if !self.faces[nf as usize].outside.is_empty() {
                stack.push(nf);
            }
        }
    }
}

/// Picks four affinely independent points (exactly), or `None` when all
/// points are coplanar (or fewer than four).
fn initial_simplex(p: &[DVec3], idx: &[u32]) -> Option<[u32; 4]> {
    let pt = |i: u32| p[i as usize];
    let mut ext = [idx[0]; 6];
    for &i in idx {
        for axis in 0..3 {
            if pt(i)[axis] < pt(ext[2 * axis])[axis] {
                ext[2 * axis] = i;
            }
            if pt(i)[axis] > pt(ext[2 * axis + 1])[axis] {
                ext[2 * axis + 1] = i;
            }
        }
    }
    let (mut a, mut b, mut best) = (ext[0], ext[1], -1.0);
    for &i in &ext {
        for &j in &ext {
            let d = pt(i).distance_squared(pt(j));
            if d > best {
                (a, b, best) = (i, j, d);
            }
        }
    }
    let ab = pt(b) - pt(a);
    let c = *idx.iter().max_by(|&&x, &&y| {
        let dx = ab.cross(pt(x) - pt(a)).length_squared();
        let dy = ab.cross(pt(y) - pt(a)).length_squared();
        dx.total_cmp(&dy)
    })?;
    if ab.cross(pt(c) - pt(a)).length_squared() == 0.0 {
        return None;
    }
    let n = ab.cross(pt(c) - pt(a));
    let d = *idx.iter().max_by(|&&x, &&y| {
        let dx = n.dot(pt(x) - pt(a)).abs();
        let dy = n.dot(pt(y) - pt(a)).abs();
        dx.total_cmp(&dy)
    })?;
    if orient3d(pt(a), pt(b), pt(c), pt(d)) == Side::On {
        return None;
    }
    Some([a, b, c, d])
}

/// The convex hull of the finite points among `points[i]` for `i` in
/// `subset` (all points when `None`); `None` when the hull is flat.
pub fn convex_hull(points: &[DVec3], subset: Option<&[u32]>) -> Option<Hull> {
    let idx: Vec<u32> = match subset {
        Some(s) => s
            .iter()
            .copied()
            .filter(|&i| points.get(i as usize).is_some_and(|p| p.is_finite()))
            .collect(),
        None => (0..points.len() as u32)
            .filter(|&i| points[i as usize].is_finite())
            .collect(),
    };
    if idx.len() < 4 {
        return None;
    }
    let [a, b, c, d] = initial_simplex(points, &idx)?;
    let mut bld = Builder {
        p: points,
        faces: Vec::new(),
    };
    // Outward faces of the start tetrahedron.
    let (b, c) = if orient3d(
        points[a as usize],
        points[b as usize],
        points[c as usize],
        points[d as usize],
    ) == Side::Positive
    {
        (c, b)
    } else {
        (b, c)
    };
    // Now d is below (a, b, c).
    let f = [[a, b, c], [a, d, b], [b, d, c], [c, d, a]];
    for v in f {
        bld.add_face(v);
    }
    // Neighbours across each edge, found by matching reversed edges.
    for i in 0..4 {
        for e in 0..3 {
            let (x, y) = (f[i][e], f[i][(e + 1) % 3]);
            for (j, g) in f.iter().enumerate() {
                if (0..3).any(|k| g[k] == y && g[(k + 1) % 3] == x) {
                    bld.faces[i].nb[e] = j as u32;
                }
            }
        }
    }
    for &q in &idx {
        if [a, b, c, d].contains(&q) {
            continue;
        }
        if let Some(fi) = (0..4).find(|&fi| bld.above(fi, q)) {
            bld.faces[fi].outside.push(q);
        }
    }
    let mut stack: Vec<u32> = (0..4).collect();
    let mut iter = 0u32;
    while let Some(fi) = stack.pop() {
        let fi = fi as usize;
        if !bld.faces[fi].alive {
            continue;
        }
        let Some(q) = bld.farthest(fi) else {
            continue;
        };
        iter += 1;
        bld.add_point(fi, q, iter, &mut stack);
    }
    Some(Hull {
        faces: bld.faces.iter().filter(|f| f.alive).map(|f| f.v).collect(),
    })
}

/// Volume of the convex hull (0 when flat).
pub fn convex_hull_volume(points: &[DVec3], subset: Option<&[u32]>) -> f64 {
    convex_hull(points, subset).map_or(0.0, |h| h.volume(points))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(s: &mut u64) -> f64 {
        *s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*s >> 11) as f64 / (1u64 << 53) as f64
    }

    fn check_closed_convex(h: &Hull, p: &[DVec3], all: &[u32]) {
        // every directed edge appears once, reversed once
        let mut edges = HashMap::new();
        for f in &h.faces {
            for k in 0..3 {
                *edges.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1));
        }
        // no input point strictly outside any face
        for f in &h.faces {
            let [a, b, c] = f.map(|i| p[i as usize]);
            for &q in all {
                assert_ne!(orient3d(a, b, c, p[q as usize]), Side::Positive);
            }
        }
    }

    #[test]
    fn grid_cube_hull_is_the_cube() {
        // 6^3 lattice: many coplanar and collinear points
        let mut p = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                for k in 0..6 {
                    p.push(DVec3::new(i as f64, j as f64, k as f64) * 0.2);
                }
            }
        }
        let h = convex_hull(&p, None).unwrap();
        assert!((h.volume(&p) - 1.0).abs() < 1e-12, "{}", h.volume(&p));
        let all: Vec<u32> = (0..p.len() as u32).collect();
        check_closed_convex(&h, &p, &all);
    }

    #[test]
    fn random_ball_points_against_inclusion() {
        let mut s = 7u64;
        let p: Vec<DVec3> = (0..3000)
            .map(|_| {
                let v = DVec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 2.0 - 1.0;
                v.normalize_or_zero() * lcg(&mut s).cbrt()
            })
            .collect();
        let h = convex_hull(&p, None).unwrap();
        let all: Vec<u32> = (0..p.len() as u32).collect();
        check_closed_convex(&h, &p, &all);
        let v = h.volume(&p);
        assert!(v > 3.5 && v < 4.0 * std::f64::consts::PI / 3.0, "{v}");
    }

    #[test]
    fn flat_inputs_have_no_hull() {
        let p: Vec<DVec3> = (0..10)
            .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
            .collect();
        assert!(convex_hull(&p, None).is_none());
        let q: Vec<DVec3> = (0..10).map(|i| DVec3::splat(i as f64)).collect();
        assert!(convex_hull(&q, None).is_none());
        assert_eq!(convex_hull_volume(&q, Some(&[0, 1])), 0.0);
    }
}
