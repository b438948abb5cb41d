//! Exact ray / triangle crossing decisions for one ray.
//!
//! A ray is the line through two exact `f64` points: its origin `o` and a far
//! point `q = o + L d` beyond the bounding sphere of the mesh. Whether the line
//! crosses a triangle is decided by the signs of the three Plücker products
//! of the line with the triangle's edges, `det[q - o, a - o, b - o]`
//! ([`predicates::orient3d`]`(o, q, a, b)`): the line crosses the triangle
//! iff all three signs are equal and non-zero.
//!
//! **Speed.** Each vertex a cell walk touches is projected once onto the
//! ray's frame (`x = u·(p-o)`, `y = v·(p-o)`, depth `z = d·(p-o)`, with
//! `u × v = d`); the Plücker product of an edge is then the 2D cross product
//! `x_a y_b - y_a x_b`. That floating value is trusted only when it exceeds a
//! certified error bound ([`crate::numeric::tolerance::PLUCKER_FILTER_K`]
//! times `eps |a - o| |b - o|`); otherwise the exact predicate decides.
//!
//! **Tie-breaking (simulation of simplicity).** When the exact product is
//! zero (the line meets the edge's line: rays through vertices, edges, or
//! along faces) the origin is perturbed symbolically,
//! `o' = o + e (P1 - o) + e^2 (P2 - o)` with `P1 = o + s u`, `P2 = o + s v`,
//! and the sign of the first non-zero term decides: `orient3d(P1, q, a, b)`,
//! then `orient3d(P2, q, a, b)` (orient3d is affine in each argument). The
//! perturbed line is in general position with respect to every edge not
//! lying on the ray's own line; such edges get sign 0, and the triangles
//! holding them are not crossed (the perturbed line meets their plane at `q`,
//! outside the mesh). Every edge's sign is computed canonically, from its
//! smaller to its larger point id, so the two triangles on either side of an
//! edge always see opposite signs: a ray through an edge or vertex crosses
//! exactly one triangle of a closed fan, with no gap and no double count.
//!
//! The barycentric weights of the crossing point are the three edge values
//! (opposite edges), so the crossing depth and the interpolated scalar are
//! computed from the same numbers on both sides of a shared triangle.

use glam::DVec3;

use crate::camera::Ray;
use crate::numeric::predicates::{orient3d, Side};
use crate::numeric::tolerance::{EDGE_ON_CROSSING_K, PLUCKER_FILTER_K, TIE_BASIS_DEGENERATE_SQ};

/// A vertex in a ray's frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Proj {
    pub x: f64,
    pub y: f64,
    /// Depth along the ray (the ray parameter of the vertex's foot point).
    pub z: f64,
    /// `|p - o|^2`.
    pub n2: f64,
}

/// The orthonormal `u, v` (`u x v = d`) of a ray's frame, which are also
/// the directions of the symbolic perturbation. For a pixel ray `u` is the
/// image's right direction made orthogonal to the ray
/// ([`Ray::right`]), so `v = d x u` is the image's down direction, and
/// moving the origin by `e u + e^2 v` moves the point where the ray meets
/// any surface by a positive multiple of it on the image: a pixel centre on
/// a projected edge belongs to the triangle on its right, or below it for
/// a horizontal edge — the rasteriser's top-left rule (`gpu::cpu`).
/// For a ray with no image direction the basis is fixed by the ray's
/// direction alone.
pub fn tie_basis(ray: &Ray) -> (DVec3, DVec3) {
    let d = ray.dir;
    let r = ray.right - d * ray.right.dot(d);
    let u = if r.length_squared() > TIE_BASIS_DEGENERATE_SQ {
        r.normalize()
    } else {
        let helper = if d.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
        helper.cross(d).normalize()
    };
    (u, d.cross(u))
}

/// The sphere `(center, radius)` around the box `lo..hi` that every
/// [`RayFrame`] of the reference ray caster is built with (its far point
/// lies beyond it). One function, so that everything deciding on pixel
/// rays (the walk, the brute-force traversal, the projected modes' exact
/// pixel-centre decisions) frames the same line, bit for bit.
pub fn bounding_sphere(lo: DVec3, hi: DVec3) -> (DVec3, f64) {
    if !(lo.is_finite() && hi.is_finite()) || lo.cmpgt(hi).any() {
        return (DVec3::ZERO, 0.0);
    }
    ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
}

/// One ray with its frame and symbolic perturbation.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    pub o: DVec3,
    pub d: DVec3,
    u: DVec3,
    v: DVec3,
    q: DVec3,
    p1: DVec3,
    p2: DVec3,
    /// Squared error-bound factor of the floating filter for this ray.
    bound2: f64,
}

/// A triangle crossing: ray parameter and barycentric weights.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    pub t: f64,
    pub w: [f64; 3],
    /// +1 when the ray goes along the triangle's right-hand normal.
    pub sign: i8,
    /// The vertices in an order fixed by their coordinates: sums over the
    /// vertices (the depth, an interpolated scalar) taken in this order
    /// give the same bits whatever winding the triangle was read in.
    pub order: [usize; 3],
}

impl Crossing {
    /// `sum w_i v_i` over the vertices, in [`Crossing::order`].
    #[inline]
    pub fn interpolate(&self, v: [f64; 3]) -> f64 {
        let [a, b, c] = self.order;
        self.w[a] * v[a] + self.w[b] * v[b] + self.w[c] * v[c]
    }
}

impl RayFrame {
    /// The frame of `ray` (unit direction) for a mesh inside the sphere
    /// `(center, radius)`.
    pub fn new(ray: &Ray, center: DVec3, radius: f64) -> RayFrame {
        let d = ray.dir;
        let o = ray.origin;
        let (u, v) = tie_basis(ray);
        let l = 2.0 * ((o - center).length() + radius) + 1.0;
        let q = o + d * l;
        // The direction actually used by the exact predicate is (q - o) / l;
        // its distance from d grows with |o| / l and |q| / l (rounding of q).
        let k = PLUCKER_FILTER_K * (1.0 + (o.length() + q.length()) / l) * f64::EPSILON;
        RayFrame {
            o,
            d,
            u,
            v,
            q,
            p1: o + u * l,
            p2: o + v * l,
            bound2: k * k,
        }
    }

    /// Projects a point onto the frame.
    #[inline]
    pub fn project(&self, p: DVec3) -> Proj {
        let a = p - self.o;
        Proj {
            x: a.dot(self.u),
            y: a.dot(self.v),
            z: a.dot(self.d),
            n2: a.length_squared(),
        }
    }

    /// The sides of the ray a projected vertex is clearly on, as bits: 1
    /// for `x > 0`, 2 for `x < 0`, 4 for `y > 0`, 8 for `y < 0`, 16 for
    /// `x + y > 0`, 32 for `x + y < 0`, 64 for `x - y > 0`, 128 for
    /// `x - y < 0`; each set only when the value exceeds four times the
    /// filter's error bound at the vertex's distance (twice that for the
    /// sums), so that the vertex is on that side of a plane through the
    /// exact line (`o`, `q`). When every vertex of a polyhedron shares a
    /// bit, the line crosses none of its triangles (under any perturbation),
    /// so [`RayFrame::crossing`] need not be asked.
    #[inline]
    pub fn clear_sides(&self, p: &Proj) -> u8 {
        let m2 = 16.0 * self.bound2 * p.n2;
        let side = |v: f64, m2: f64, pos: u8| {
            if v * v > m2 {
                if v > 0.0 {
                    pos
                } else {
                    pos << 1
                }
            } else {
                0
            }
        };
        side(p.x, m2, 1)
            | side(p.y, m2, 4)
            | side(p.x + p.y, 4.0 * m2, 16)
            | side(p.x - p.y, 4.0 * m2, 64)
    }

    /// Signed Plücker value of edge `a -> b` (point ids `ia`, `ib`): its sign
    /// is the exact, symbolically perturbed sign; its magnitude the floating
    /// value (tiny when the exact predicate had to decide). 0 only for
    /// edges on the ray's line or of zero length.
    #[inline]
    pub fn edge(&self, ia: u32, a: DVec3, pa: &Proj, ib: u32, b: DVec3, pb: &Proj) -> f64 {
        if ia < ib {
            self.edge_canonical(a, pa, b, pb)
        } else if ia > ib {
            -self.edge_canonical(b, pb, a, pa)
        } else {
            0.0
        }
    }

    /// [`RayFrame::edge`] for points without ids: the canonical direction
    /// of the edge is from the lexicographically smaller point (x, then y,
    /// then z) to the larger, so polyhedra that share an edge's two points
    /// see opposite signs on their two sides of it whatever their local
    /// numbering. 0 for a zero-length edge or one on the ray's line.
    #[inline]
    pub fn edge_by_position(&self, a: DVec3, pa: &Proj, b: DVec3, pb: &Proj) -> f64 {
        let lex =
            a.x.total_cmp(&b.x)
                .then(a.y.total_cmp(&b.y))
                .then(a.z.total_cmp(&b.z));
        match lex {
            std::cmp::Ordering::Less => self.edge_canonical(a, pa, b, pb),
            std::cmp::Ordering::Greater => -self.edge_canonical(b, pb, a, pa),
            std::cmp::Ordering::Equal => 0.0,
        }
    }

    #[inline]
    fn edge_canonical(&self, a: DVec3, pa: &Proj, b: DVec3, pb: &Proj) -> f64 {
        let val = pa.x * pb.y - pa.y * pb.x;
        if val * val > self.bound2 * pa.n2 * pb.n2 {
            return val;
        }
        let tiny = f64::MIN_POSITIVE;
        for p in [self.o, self.p1, self.p2] {
            match orient3d(p, self.q, a, b) {
                Side::Positive => return if val > 0.0 { val } else { tiny },
                Side::Negative => return if val < 0.0 { val } else { -tiny },
                Side::On => {}
            }
        }
        0.0
    }

    /// Crossing of the triangle with the given edge values
    /// (`e_ab`, `e_bc`, `e_ca`) and projected vertices, if the ray crosses
    /// it. The weights are the edge values (opposite edges); where these
    /// may be noise (the triangle seen edge-on, [`EDGE_ON_CROSSING_K`]) the
    /// crossing is kept on the triangle's [`chord`] across from the ray.
    #[inline]
    pub fn crossing(&self, e: [f64; 3], p: [&Proj; 3]) -> Option<Crossing> {
        let [eab, ebc, eca] = e;
        let sign = if eab > 0.0 && ebc > 0.0 && eca > 0.0 {
            1
        } else if eab < 0.0 && ebc < 0.0 && eca < 0.0 {
            -1
        } else {
            return None;
        };
        // Weight of a vertex is the value of the opposite edge. Sums run
        // over the vertices in an order fixed by their coordinates, so that
        // every traversal gets the same bits whatever the winding it reads
        // the triangle in.
        let ws = [ebc.abs(), eca.abs(), eab.abs()];
        let k = vertex_order(p);
        let sum = ws[k[0]] + ws[k[1]] + ws[k[2]];
        let n = p.map(|q| q.n2.sqrt());
        let err = self.bound2.sqrt() * (n[k[0]] * n[k[1]] + n[k[1]] * n[k[2]] + n[k[2]] * n[k[0]]);
        let bary = (sum > 0.0 && sum.is_finite()).then(|| ws.map(|x| x / sum));
        let mut w = bary.unwrap_or([0.0; 3]);
        let mut t = w[k[0]] * p[k[0]].z + w[k[1]] * p[k[1]].z + w[k[2]] * p[k[2]].z;
        if bary.is_none() || sum <= EDGE_ON_CROSSING_K * err {
            // The crossing point lies on the chord; the depth from noisy
            // weights may not: take the chord's nearer end (its middle
            // without weights).
            let [(lo, wlo), (hi, whi)] = chord(k.map(|i| p[i]));
            let wk = if bary.is_none() {
                Some([0, 1, 2].map(|j| 0.5 * (wlo[j] + whi[j])))
            } else if t < lo {
                Some(wlo)
            } else if t > hi {
                Some(whi)
            } else {
                None
            };
            if let Some(wk) = wk {
                for j in 0..3 {
                    w[k[j]] = wk[j];
                }
                t = w[k[0]] * p[k[0]].z + w[k[1]] * p[k[1]].z + w[k[2]] * p[k[2]].z;
            }
        }
        Some(Crossing {
            t,
            w,
            sign,
            order: k,
        })
    }
}

/// The triangle's vertices ordered by depth, then `x`, then `y`.
fn vertex_order(p: [&Proj; 3]) -> [usize; 3] {
    let mut k = [0, 1, 2];
    k.sort_unstable_by(|&i, &j| {
        let (a, b) = (p[i], p[j]);
        a.z.total_cmp(&b.z)
            .then(a.x.total_cmp(&b.x))
            .then(a.y.total_cmp(&b.y))
    });
    k
}

/// The chord of a triangle across from the ray: its points in the plane
/// through the ray and the triangle's normal (`m = 0`, `m` the coordinate
/// across the ray in the triangle's plane). The exact crossing point is on
/// it; when the ray runs within rounding of the triangle's plane the chord
/// is the whole stretch of the ray the triangle's two sides share. Returns
/// its two ends as (depth, weights), nearer end first; a chord missed by
/// rounding is the vertex closest to the ray.
fn chord(p: [&Proj; 3]) -> [(f64, [f64; 3]); 2] {
    let [a, b, c] = p;
    let nx = (b.y - a.y) * (c.z - a.z) - (b.z - a.z) * (c.y - a.y);
    let ny = (b.z - a.z) * (c.x - a.x) - (b.x - a.x) * (c.z - a.z);
    let m = p.map(|q| ny * q.x - nx * q.y);
    let depth = |w: [f64; 3]| w[0] * a.z + w[1] * b.z + w[2] * c.z;
    let mut ends: Option<[(f64, [f64; 3]); 2]> = None;
    let mut add = |w: [f64; 3]| {
        let e = (depth(w), w);
        ends = Some(match ends {
            None => [e, e],
            Some([lo, hi]) => [
                if e.0 < lo.0 { e } else { lo },
                if e.0 > hi.0 { e } else { hi },
            ],
        });
    };
    for i in 0..3 {
        let j = (i + 1) % 3;
        let mut w = [0.0; 3];
        if m[i] == 0.0 {
            w[i] = 1.0;
            add(w);
        } else if (m[i] > 0.0) != (m[j] > 0.0) && m[j] != 0.0 {
            let s = m[i] / (m[i] - m[j]);
            w[i] = 1.0 - s;
            w[j] = s;
            add(w);
        }
    }
    ends.unwrap_or_else(|| {
        let k = (0..3)
            .min_by(|&i, &j| m[i].abs().total_cmp(&m[j].abs()))
            .unwrap_or(0);
        let mut w = [0.0; 3];
        w[k] = 1.0;
        [(depth(w), w); 2]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(o: DVec3, d: DVec3) -> RayFrame {
        RayFrame::new(&Ray::new(o, d.normalize()), DVec3::ZERO, 2.0)
    }

    fn cross(f: &RayFrame, ids: [u32; 3], p: [DVec3; 3]) -> Option<Crossing> {
        let pr = p.map(|x| f.project(x));
        let e = [
            f.edge(ids[0], p[0], &pr[0], ids[1], p[1], &pr[1]),
            f.edge(ids[1], p[1], &pr[1], ids[2], p[2], &pr[2]),
            f.edge(ids[2], p[2], &pr[2], ids[0], p[0], &pr[0]),
        ];
        f.crossing(e, [&pr[0], &pr[1], &pr[2]])
    }

    #[test]
    fn generic_crossing_depth_and_sign() {
        let f = frame(DVec3::new(0.2, 0.3, -1.0), DVec3::Z);
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let c = cross(&f, [0, 1, 2], p).unwrap();
        assert_eq!(c.sign, 1);
        assert!((c.t - 1.0).abs() < 1e-15);
        assert!((c.w[1] - 0.2).abs() < 1e-15 && (c.w[2] - 0.3).abs() < 1e-15);
        assert!(cross(&f, [0, 2, 1], [p[0], p[2], p[1]]).unwrap().sign == -1);
    }

    #[test]
    fn ray_through_shared_edge_and_vertex_hits_exactly_one() {
        // A fan of triangles around the origin in the z = 0 plane, and a
        // square split by a diagonal: rays through the vertex and the edge.
        let ring = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(-1.0, 0.5, 0.0),
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(0.5, -1.0, 0.0),
        ];
        let ids = [7u32, 3, 9, 1, 4];
        for o in [
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(0.5, 0.0, -1.0),
            DVec3::new(0.0, 0.5, -1.0),
            DVec3::new(-0.5, -0.5, -1.0),
        ] {
            for d in [DVec3::Z, DVec3::new(0.0, 0.0, 1.0) + DVec3::X * 0.0] {
                let f = frame(o, d);
                let mut hits = 0;
                for k in 0..5 {
                    let k1 = (k + 1) % 5;
                    if cross(&f, [5, ids[k], ids[k1]], [DVec3::ZERO, ring[k], ring[k1]]).is_some() {
                        hits += 1;
                    }
                }
                assert_eq!(hits, 1, "origin {o:?}");
            }
        }
    }

    #[test]
    fn ray_in_plane_of_triangle_misses() {
        let f = frame(DVec3::new(-1.0, 0.25, 0.0), DVec3::X);
        assert!(cross(&f, [0, 1, 2], [DVec3::ZERO, DVec3::X, DVec3::Y]).is_none());
    }
}
