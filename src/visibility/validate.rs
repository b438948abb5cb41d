//! Brute-force validation of an order (for tests and fuzzing).
//!
//! For every sampled pixel-centre ray (`Camera::pixel_ray`, the line through
//! its origin and origin + direction), every piece's triangles are tested
//! with the exact [`ray_triangle`]; the sorted crossing depths of one piece
//! pair up into the segments where the ray is inside it. A ray that touches
//! any triangle's edge or vertex, or lies in its plane, is skipped and counted
//! as degenerate (the tie rule of [`crate::visibility`]). Along each remaining
//! ray the segments, ordered by their midpoints, must have strictly
//! decreasing drawing positions (front pieces are drawn later); each pair of
//! consecutive segments out of order is a [`Violation`], unless both pieces
//! are in the same per-pixel group of [`Order::groups`], or their segments
//! overlap (intersecting pieces, from inverted cells: no order is right;
//! counted in [`Violations::overlap_pairs`]).

use std::collections::HashMap;

use glam::DVec3;

use super::geometry::line_plane_t;
use super::{Order, Piece};
use crate::camera::Camera;
use crate::mesh::tetra::triangulate_face;
use crate::mesh::Mesh;
use crate::numeric::predicates::{ray_triangle, RayHit};
use crate::numeric::tolerance::VALIDATE_OVERLAP_REL;

/// Two pieces drawn in the wrong order along one pixel ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Violation {
    pub pixel: (u32, u32),
    /// The piece nearer the eye along the ray (must be drawn later).
    pub front: Piece,
    /// The piece behind it (must be drawn earlier).
    pub back: Piece,
}

/// The result of [`validate`].
#[derive(Clone, Debug, Default)]
pub struct Violations {
    /// Rays checked (not degenerate).
    pub rays: usize,
    /// Rays skipped because they touch an edge or vertex exactly.
    pub degenerate_rays: usize,
    /// Consecutive segment pairs compared.
    pub pairs: usize,
    /// Pairs inside one per-pixel group (not checked).
    pub group_pairs: usize,
    /// Pieces the ray met an odd number of times (not closed; counted, and the
    /// ray is skipped).
    pub odd_rays: usize,
    /// Consecutive pairs whose segments overlap along the ray (pieces whose
    /// interiors intersect: inverted or self-overlapping cells, where no
    /// drawing order is right); counted, not violations.
    pub overlap_pairs: usize,
    /// Violations on rays that also cross intersecting pieces (where the
    /// mesh overlaps itself; included in `count`).
    pub violations_on_overlap_rays: usize,
    /// Total number of violations.
    pub count: usize,
    /// The first violations (at most 20).
    pub examples: Vec<Violation>,
}

impl Violations {
    /// Whether the order passed.
    pub fn ok(&self) -> bool {
        self.count == 0
    }
}

/// `count` distinct pixels chosen by a fixed-seed generator (all pixels when
/// `count` is at least the image size).
pub fn sample_pixels(camera: &Camera, count: usize, seed: u64) -> Vec<(u32, u32)> {
    let (w, h) = (camera.width, camera.height);
    let total = w as usize * h as usize;
    if count >= total {
        return (0..h).flat_map(|j| (0..w).map(move |i| (i, j))).collect();
    }
    let mut x = seed ^ 0x9E37_79B9_7F4A_7C15;
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::with_capacity(count);
    while out.len() < count {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let k = (x % total as u64) as u32;
        if seen.insert(k) {
            out.push((k % w, k / w));
        }
    }
    out
}

/// The triangles bounding a piece (corner positions); empty when the piece
/// refers to points or fragments that do not exist.
fn piece_triangles(mesh: &Mesh, order: &Order, piece: &Piece, out: &mut Vec<[DVec3; 3]>) {
    out.clear();
    let p = &mesh.points;
    let ok = |t: &[u32]| t.iter().all(|&v| (v as usize) < p.len());
    match *piece {
        Piece::Cell(c) => {
            if (c as usize) < mesh.cells.len() {
                let mut bad = false;
                mesh.cells.for_each_face(c as usize, |_, face| {
                    triangulate_face(face, |t| {
                        if ok(&t) {
                            out.push(t.map(|v| p[v as usize]));
                        } else {
                            bad = true;
                        }
                    });
                });
                if bad {
                    out.clear();
                }
            }
        }
        Piece::Tet { tet, .. } | Piece::Slab { tet, .. } => {
            if ok(&tet) {
                let [a, b, c, d] = tet.map(|v| p[v as usize]);
                out.extend_from_slice(&[[a, b, c], [a, b, d], [a, c, d], [b, c, d]]);
            }
        }
        Piece::Frag { tet, frag, .. } => {
            if let (true, Some(f)) = (ok(&tet), order.fragments.get(frag as usize)) {
                let x = f.positions(&tet.map(|v| p[v as usize]));
                for t in &f.triangles {
                    if t.iter().all(|&v| (v as usize) < x.len()) {
                        out.push(t.map(|v| x[v as usize]));
                    }
                }
            }
        }
    }
}

/// Checks `order` along the pixel-centre rays of `pixels`.
pub fn validate(mesh: &Mesh, order: &Order, camera: &Camera, pixels: &[(u32, u32)]) -> Violations {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut slot = vec![u32::MAX; w * h];
    let mut rays: Vec<(DVec3, DVec3)> = Vec::with_capacity(pixels.len());
    for (k, &(i, j)) in pixels.iter().enumerate() {
        if (i as usize) < w && (j as usize) < h {
            slot[j as usize * w + i as usize] = k as u32;
        }
        let r = camera.pixel_ray(i, j);
        rays.push((r.origin, r.origin + r.dir));
    }
    let mut group_of = vec![u32::MAX; order.pieces.len()];
    for (g, range) in order.groups.iter().enumerate() {
        for k in range.clone() {
            if let Some(x) = group_of.get_mut(k) {
                *x = g as u32;
            }
        }
    }
    let tmin = if camera.ortho { 0.0 } else { camera.near };
    // Per sampled ray: (midpoint t, position in order).
    let mut segs: HashMap<u32, Vec<(f64, f64, u32)>> = HashMap::new();
    let mut bad = vec![false; pixels.len()];
    let mut odd = vec![false; pixels.len()];
    let mut tris = Vec::new();
    let mut ts: Vec<f64> = Vec::new();
    for (pos, piece) in order.pieces.iter().enumerate() {
        // The slabs of one tet are consecutive: the tet is checked once, at
        // its first slab (the order of the slabs inside is along the
        // gradient, `super::slabs`).
        if let (Piece::Slab { tet, .. }, Some(prev)) = (piece, pos.checked_sub(1)) {
            if order.pieces[prev].tet() == Some(*tet)
                && matches!(order.pieces[prev], Piece::Slab { .. })
            {
                continue;
            }
        }
        piece_triangles(mesh, order, piece, &mut tris);
        if tris.is_empty() {
            continue;
        }
        // Candidate pixels: the projected bounding box, or everything.
        let proj: Option<Vec<(f64, f64)>> = tris
            .iter()
            .flatten()
            .map(|&v| camera.project(v).map(|(x, y, _)| (x, y)))
            .collect();
        let (i0, i1, j0, j1) = match proj {
            Some(pts) if !pts.is_empty() => {
                let (mut lx, mut ly, mut hx, mut hy) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
                for (x, y) in pts {
                    lx = lx.min(x);
                    ly = ly.min(y);
                    hx = hx.max(x);
                    hy = hy.max(y);
                }
                let cl = |v: f64, hi: usize| (v.max(-1.0).min(hi as f64 + 1.0)) as i64;
                (
                    (cl(lx.floor(), w) - 1).max(0),
                    (cl(hx.ceil(), w) + 1).min(w as i64 - 1),
                    (cl(ly.floor(), h) - 1).max(0),
                    (cl(hy.ceil(), h) + 1).min(h as i64 - 1),
                )
            }
            _ => (0, w as i64 - 1, 0, h as i64 - 1),
        };
        for j in j0..=j1 {
            for i in i0..=i1 {
                let k = slot[j as usize * w + i as usize];
                if k == u32::MAX || bad[k as usize] {
                    continue;
                }
                let (o, q) = rays[k as usize];
                ts.clear();
                let mut degenerate = false;
                for &[a, b, c] in &tris {
                    match ray_triangle(o, q, a, b, c) {
                        RayHit::Miss => {}
                        RayHit::Degenerate => degenerate = true,
                        RayHit::Inside => {
                            if let Some(tt) = line_plane_t(o, q, a, b, c) {
                                ts.push(tt);
                            }
                        }
                    }
                }
                if degenerate {
                    bad[k as usize] = true;
                    continue;
                }
                if ts.len() % 2 == 1 {
                    odd[k as usize] = true;
                    bad[k as usize] = true;
                    continue;
                }
                ts.sort_by(f64::total_cmp);
                for s in ts.chunks(2) {
                    let (t0, t1) = (s[0].max(tmin), s[1]);
                    if t1 > t0 {
                        segs.entry(k).or_default().push((t0, t1, pos as u32));
                    }
                }
            }
        }
    }
    let mut v = Violations::default();
    for (k, &b) in bad.iter().enumerate() {
        if b {
            v.degenerate_rays += 1;
            v.odd_rays += odd[k] as usize;
        } else {
            v.rays += 1;
        }
    }
    v.degenerate_rays -= v.odd_rays;
    let mut keys: Vec<u32> = segs.keys().copied().collect();
    keys.sort_unstable();
    for k in keys {
        if bad[k as usize] {
            continue;
        }
        let list = segs.get_mut(&k).map(std::mem::take).unwrap_or_default();
        let mut list = list;
        list.sort_by(|a, b| (a.0 + a.1).total_cmp(&(b.0 + b.1)));
        let overlap_ray = list.windows(2).any(|pair| {
            let slack = VALIDATE_OVERLAP_REL * pair[0].1.abs().max(pair[1].0.abs());
            pair[0].2 != pair[1].2 && pair[1].0 < pair[0].1 - slack
        });
        for pair in list.windows(2) {
            let (front, back) = (pair[0].2, pair[1].2);
            if front == back {
                continue;
            }
            v.pairs += 1;
            let slack = VALIDATE_OVERLAP_REL * pair[0].1.abs().max(pair[1].0.abs());
            if pair[1].0 < pair[0].1 - slack {
                v.overlap_pairs += 1;
                continue;
            }
            let (gf, gb) = (group_of[front as usize], group_of[back as usize]);
            if gf != u32::MAX && gf == gb {
                v.group_pairs += 1;
                continue;
            }
            if front < back {
                v.count += 1;
                v.violations_on_overlap_rays += overlap_ray as usize;
                if v.examples.len() < 20 {
                    v.examples.push(Violation {
                        pixel: pixels[k as usize],
                        front: order.pieces[front as usize],
                        back: order.pieces[back as usize],
                    });
                }
            }
        }
    }
    v
}
