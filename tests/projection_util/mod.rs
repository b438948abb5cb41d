//! Shared helpers of the projection tests: random convex cells, cameras, a
//! direct ray-polyhedron intersection and the convex hull area.
#![allow(dead_code)]

use glam::{DMat3, DVec2, DVec3};
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::{CellKind, Cells};
use zoovr::projection::{Polyhedron, Projected, ViewMap};
pub use zoovr::testdata::Rng;

pub const KINDS: [CellKind; 6] = CellKind::FIXED;

/// A random well-conditioned affine map.
pub fn random_affine(rng: &mut Rng) -> (DMat3, DVec3) {
    loop {
        let m = DMat3::from_cols_array(&std::array::from_fn(|_| rng.range(-1.0, 1.0)));
        let d = m.determinant().abs();
        if d > 0.15 {
            let t = DVec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            );
            return (m, t);
        }
    }
}

/// One random convex cell of `kind`: world points (ids shuffled so the
/// diagonals vary), cells, scalars.
pub fn random_cell(kind: CellKind, rng: &mut Rng) -> (Vec<DVec3>, Cells, Vec<f64>) {
    let r = kind.reference_corners();
    let (m, t) = random_affine(rng);
    let n = r.len();
    // Random global ids: a permutation of 0..n.
    let mut perm: Vec<u32> = (0..n as u32).collect();
    for i in (1..n).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        perm.swap(i, j);
    }
    let mut pts = vec![DVec3::ZERO; n];
    for i in 0..n {
        pts[perm[i] as usize] = m * r[i] + t;
    }
    let mut cells = Cells::default();
    cells.push(kind, &perm);
    let scalars = (0..n).map(|_| rng.range(-1.0, 2.0)).collect();
    (pts, cells, scalars)
}

pub fn bounds(pts: &[DVec3]) -> [f64; 6] {
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in pts {
        b[0] = b[0].min(p.x);
        b[1] = b[1].max(p.x);
        b[2] = b[2].min(p.y);
        b[3] = b[3].max(p.y);
        b[4] = b[4].min(p.z);
        b[5] = b[5].max(p.z);
    }
    b
}

pub fn random_camera(rng: &mut Rng, b: [f64; 6], ortho: bool) -> Camera {
    let p = CameraParams {
        width: 200,
        height: 150,
        azimuth: rng.range(-180.0, 180.0),
        elevation: rng.range(-80.0, 80.0),
        roll: rng.range(-180.0, 180.0),
        zoom: rng.range(0.8, 1.5),
        ortho,
        ..Default::default()
    };
    Camera::fit(b, &p)
}

/// Entry and exit of the ray through pixel position `q` (view space):
/// `(l, z_in, z_out, s_in, s_out)`, or `None` when it misses.
pub fn ray_hit(poly: &Polyhedron, view: &ViewMap, q: DVec2) -> Option<(f64, f64, f64, f64, f64)> {
    let uv = view.plane(q);
    let (o, d) = if view.ortho {
        (DVec3::new(uv.x, uv.y, 0.0), DVec3::Z)
    } else {
        (DVec3::ZERO, DVec3::new(uv.x, uv.y, 1.0).normalize())
    };
    let mut tin = (f64::INFINITY, 0.0);
    let mut tout = (f64::NEG_INFINITY, 0.0);
    for t in &poly.triangles {
        let [a, b, c] = t.map(|i| poly.points[i as usize]);
        let [sa, sb, sc] = t.map(|i| poly.scalars[i as usize]);
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-300 {
            continue;
        }
        let inv = 1.0 / det;
        let s = o - a;
        let u = s.dot(p) * inv;
        let qv = s.cross(e1);
        let v = d.dot(qv) * inv;
        if u < -1e-12 || v < -1e-12 || u + v > 1.0 + 1e-12 {
            continue;
        }
        let tt = e2.dot(qv) * inv;
        let sv = sa + u * (sb - sa) + v * (sc - sa);
        if tt < tin.0 {
            tin = (tt, sv);
        }
        if tt > tout.0 {
            tout = (tt, sv);
        }
    }
    if !tin.0.is_finite() {
        return None;
    }
    let zin = o.z + tin.0 * d.z;
    let zout = o.z + tout.0 * d.z;
    Some((tout.0 - tin.0, zin, zout, tin.1, tout.1))
}

/// Area of the convex hull of the projected points (monotone chain).
pub fn hull_area(pts: &[DVec2]) -> f64 {
    let mut p: Vec<DVec2> = pts.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return 0.0;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut h: Vec<DVec2> = Vec::new();
    for &q in &p {
        while h.len() >= 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
            h.pop();
        }
        h.push(q);
    }
    let lower = h.len() + 1;
    for &q in p.iter().rev().skip(1) {
        while h.len() >= lower && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
            h.pop();
        }
        h.push(q);
    }
    h.pop();
    let mut a = 0.0;
    for k in 0..h.len() {
        a += h[k].perp_dot(h[(k + 1) % h.len()]);
    }
    0.5 * a.abs()
}

/// Pixel positions of the points (those in front of the near plane).
pub fn pixels(poly: &Polyhedron, cam: &Camera) -> Vec<DVec2> {
    poly.points
        .iter()
        .filter_map(|&p| cam.view_to_pixel(p).map(|(x, y, _)| DVec2::new(x, y)))
        .collect()
}

/// Checks region values against direct ray casting at random points of each
/// triangle; returns the max errors `(l, s, s_weighted)` relative to the
/// piece's diameter and scalar range; `s_weighted` is the scalar error times
/// `l / diameter` (what the integral feels: a segment of length l).
pub fn check_values(
    proj: &Projected,
    poly: &Polyhedron,
    rng: &mut Rng,
    samples: usize,
) -> (f64, f64, f64) {
    let mut scale_l: f64 = 0.0;
    for p in &poly.points {
        for q in &poly.points {
            scale_l = scale_l.max((*p - *q).length());
        }
    }
    let smin = poly.scalars.iter().copied().fold(f64::INFINITY, f64::min);
    let smax = poly
        .scalars
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let scale_s = (smax - smin).max(1e-300);
    let (mut el, mut es, mut ew) = (0.0f64, 0.0f64, 0.0f64);
    // At most 64 triangles per piece (refined perspective pieces have many).
    let nt = proj.triangles.len();
    let picks: Vec<usize> = if nt <= 64 {
        (0..nt).collect()
    } else {
        (0..64)
            .map(|_| (rng.next_u64() % nt as u64) as usize)
            .collect()
    };
    for ti in picks {
        let t = proj.triangles[ti];
        let [a, b, c] = t.map(|i| proj.vertices[i as usize]);
        for _ in 0..samples {
            // Interior barycentric coordinates away from the edges.
            let (mut u, mut v) = (rng.range(0.05, 0.9), rng.range(0.05, 0.9));
            if u + v > 0.95 {
                u = 0.95 - u;
                v = 0.95 - v;
                u = u.max(0.025);
                v = v.max(0.025);
            }
            let w = 1.0 - u - v;
            let q = a.pos() * w + b.pos() * u + c.pos() * v;
            let l = a.l * w + b.l * u + c.l * v;
            let sf = a.s_front * w + b.s_front * u + c.s_front * v;
            let sb = a.s_back * w + b.s_back * u + c.s_back * v;
            let Some((lr, _, _, sfr, sbr)) = ray_hit(poly, &proj.view, q) else {
                // A sample so close to the silhouette that the ray misses
                // within the intersection tolerance: l must be ~0 there.
                el = el.max(l.abs() / scale_l);
                continue;
            };
            el = el.max((l - lr).abs() / scale_l);
            let e = (sf - sfr).abs().max((sb - sbr).abs()) / scale_s;
            es = es.max(e);
            ew = ew.max(e * lr / scale_l);
        }
    }
    (el, es, ew)
}
