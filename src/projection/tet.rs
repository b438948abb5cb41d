//! The regions of a tetrahedron in general position, directly by its
//! Shirley-Tuchman class (no overlay walk).
//!
//! With its four points projected to distinct pixel positions and no face
//! seen edge-on (exact `orient2d` facings, checked by the caller), a
//! tetrahedron has either
//! - one face facing one way and three the other (classes 1 and 3 of
//!   Shirley and Tuchman): the lone face's triangle is the silhouette, the
//!   point opposite it, `d`, projects strictly inside it (each of the three
//!   other faces holds `d` and is strictly oriented), and the regions are
//!   the three triangles `(d, a, b)` over the lone face's edges `(a, b)`,
//!   each under the lone face and the face through `a, b, d`; or
//! - two front faces and two back faces (class 2): the front faces share an
//!   edge `(p, q)`, the back faces an edge `(r, s)`; `r` and `s` lie strictly
//!   on opposite sides of the line `pq` (the two front faces run along it in
//!   opposite directions and have the same facing), and likewise `p`, `q`
//!   of `rs`, so the two edges cross properly at `X`, computed once
//!   ([`segment_crossing`], the overlay's formula). The silhouette is the
//!   quadrilateral `p, r, q, s`; the regions are the four triangles
//!   `(X, u, v)` over its edges, each under the front and the back face
//!   holding `u` and `v`.
//!
//! These are exactly the regions the overlay finds for such a tet (one per
//! front/back pair that overlaps); each region is wound counter-clockwise by
//! one exact `orient2d`, and a zero orientation (impossible in general
//! position) declines to the overlay.

use glam::DVec2;

use super::arrangement::segment_crossing;
use super::{Facing, VertexKind};
use crate::numeric::predicates::{orient2d, Side};

/// Regions of a tetrahedron, in the layout of the projector's region
/// tables: positions (the four points, then the crossing in class 2),
/// silhouette flags, region vertex lists, each region's front and back
/// triangle, and what each vertex is ([`VertexKind`], for its values).
#[derive(Clone, Debug, Default)]
pub(crate) struct TetRegions {
    pub pos: Vec<DVec2>,
    pub on_hull: Vec<bool>,
    pub verts: Vec<u32>,
    pub start: Vec<u32>,
    pub faces: Vec<[u32; 2]>,
    pub kinds: Vec<VertexKind>,
}

impl TetRegions {
    /// Builds the regions of the tetrahedron with pixel positions `pix`,
    /// boundary triangles `tris` (four faces over points `0..4`) and
    /// `facing` (none edge-on, all positions distinct: the caller checks).
    /// Returns `false` (and leaves garbage) when the piece is not a
    /// tetrahedron in that form or a region turns out degenerate.
    pub fn build(&mut self, pix: &[DVec2], tris: &[[u32; 3]], facing: &[Facing]) -> bool {
        self.pos.clear();
        self.on_hull.clear();
        self.verts.clear();
        self.start.clear();
        self.faces.clear();
        self.kinds.clear();
        if pix.len() != 4 || tris.len() != 4 || facing.len() != 4 {
            return false;
        }
        if facing.contains(&Facing::EdgeOn) {
            return false;
        }
        // The point each face leaves out; faces must be four distinct ones.
        let mut opposite = [0u32; 4];
        let mut seen = 0u8;
        for (t, tri) in tris.iter().enumerate() {
            let mut mask = 0u8;
            for &i in tri {
                if i >= 4 {
                    return false;
                }
                mask |= 1 << i;
            }
            if mask.count_ones() != 3 {
                return false;
            }
            let o = (!mask & 0xF).trailing_zeros();
            opposite[t] = o;
            seen |= 1 << o;
        }
        if seen != 0xF {
            return false;
        }
        let face_of = |o: u32| opposite.iter().position(|&x| x == o).unwrap_or(0) as u32;
        let front = |t: u32| facing[t as usize] == Facing::Front;
        let nf = facing.iter().filter(|&&f| f == Facing::Front).count();
        self.pos.extend_from_slice(pix);
        match nf {
            1 | 3 => {
                // The lone face and the point opposite it.
                let lone = (0..4u32).find(|&t| front(t) == (nf == 1)).unwrap_or(0);
                let d = opposite[lone as usize];
                self.on_hull.extend((0..4).map(|i| i != d));
                // d lies strictly inside the lone face, under the three
                // others, of the other facing.
                let inner = if front(lone) {
                    VertexKind::Back
                } else {
                    VertexKind::Front
                };
                self.kinds.extend((0..4).map(|i| {
                    if i == d {
                        inner
                    } else {
                        VertexKind::Silhouette
                    }
                }));
                let [a, b, c] = tris[lone as usize];
                for (u, v, w) in [(a, b, c), (b, c, a), (c, a, b)] {
                    // The face through u, v and d leaves out w.
                    let other = face_of(w);
                    let pair = if front(lone) {
                        [lone, other]
                    } else {
                        [other, lone]
                    };
                    if !self.push_region([d, u, v], pair) {
                        return false;
                    }
                }
            }
            2 => {
                let (mut fr, mut bk) = ([0u32; 2], [0u32; 2]);
                let (mut nfr, mut nbk) = (0, 0);
                for t in 0..4u32 {
                    if front(t) {
                        fr[nfr] = t;
                        nfr += 1;
                    } else {
                        bk[nbk] = t;
                        nbk += 1;
                    }
                }
                // Front faces share the edge (p, q) leaving out the points
                // opposite the back faces, and vice versa.
                let (p, q) = (opposite[bk[0] as usize], opposite[bk[1] as usize]);
                let (r, s) = (opposite[fr[0] as usize], opposite[fr[1] as usize]);
                self.on_hull.extend([true; 4]);
                self.on_hull.push(false);
                self.kinds.extend([VertexKind::Silhouette; 4]);
                self.kinds.push(VertexKind::Crossing {
                    front: [p, q],
                    back: [r, s],
                });
                self.pos.push(segment_crossing(
                    pix[p as usize],
                    pix[q as usize],
                    pix[r as usize],
                    pix[s as usize],
                ));
                let x = 4;
                for (u, v) in [(p, r), (r, q), (q, s), (s, p)] {
                    // The front (back) face holding u and v leaves out one
                    // of the two other points.
                    // The two points that are neither u nor v.
                    let mut rest = [u32::MAX; 2];
                    let mut nr = 0;
                    for k in [p, q, r, s] {
                        if k != u && k != v && nr < 2 {
                            rest[nr] = k;
                            nr += 1;
                        }
                    }
                    let (Some(&f), Some(&b)) = (
                        fr.iter().find(|&&t| rest.contains(&opposite[t as usize])),
                        bk.iter().find(|&&t| rest.contains(&opposite[t as usize])),
                    ) else {
                        return false;
                    };
                    if !self.push_region([x, u, v], [f, b]) {
                        return false;
                    }
                }
            }
            _ => return false,
        }
        self.start.push(self.verts.len() as u32);
        true
    }

    /// Appends triangle region `v` (wound counter-clockwise) under faces
    /// `pair`; `false` when degenerate.
    fn push_region(&mut self, v: [u32; 3], pair: [u32; 2]) -> bool {
        let [a, b, c] = v.map(|i| self.pos[i as usize]);
        let v = match orient2d(a, b, c) {
            Side::Positive => v,
            Side::Negative => [v[0], v[2], v[1]],
            Side::On => return false,
        };
        self.start.push(self.verts.len() as u32);
        self.verts.extend_from_slice(&v);
        self.faces.push(pair);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both classes, each orientation of the lone face; bad input declines.
    #[test]
    fn classes_and_declines() {
        // Faces of points 0..4 (any consistent winding will do here: the
        // facings are given directly).
        let tris = [[0, 1, 3], [1, 2, 3], [2, 0, 3], [0, 2, 1]];
        let (f, b) = (Facing::Front, Facing::Back);
        // Class 1: point 3 inside triangle 0, 1, 2 (face 3 leaves out 3).
        let inner = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(0.0, 4.0),
            DVec2::new(1.0, 1.0),
        ];
        let mut t = TetRegions::default();
        for (lone, rest) in [(f, b), (b, f)] {
            assert!(t.build(&inner, &tris, &[rest, rest, rest, lone]));
            assert_eq!(t.faces.len(), 3);
            assert_eq!(t.pos.len(), 4);
            assert_eq!(t.on_hull, [true, true, true, false]);
            for (r, pair) in t.faces.iter().enumerate() {
                // Every region lies under the lone face, once as front or back.
                let lone_side = if lone == f { 0 } else { 1 };
                assert_eq!(pair[lone_side], 3, "region {r}");
                let v = &t.verts[t.start[r] as usize..t.start[r + 1] as usize];
                let [a, bb, c] = [v[0], v[1], v[2]].map(|i| t.pos[i as usize]);
                assert_eq!(orient2d(a, bb, c), Side::Positive);
            }
        }
        // Class 2: a convex quadrilateral; faces 0 and 3 share edge (0, 1).
        let quad = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(0.0, 4.0),
        ];
        assert!(t.build(&quad, &tris, &[f, b, b, f]));
        assert_eq!(t.faces.len(), 4);
        assert_eq!(t.pos[4], DVec2::new(2.0, 2.0));
        assert_eq!(t.on_hull, [true, true, true, true, false]);
        for pair in &t.faces {
            assert!([0, 3].contains(&pair[0]) && [1, 2].contains(&pair[1]));
        }
        // Declines: an edge-on face, a face repeated, not a tetrahedron.
        assert!(!t.build(&quad, &tris, &[f, b, Facing::EdgeOn, f]));
        assert!(!t.build(
            &quad,
            &[[0, 1, 3], [0, 1, 3], [2, 0, 3], [0, 2, 1]],
            &[f, b, b, f]
        ));
        assert!(!t.build(&quad[..3], &tris[..3], &[f, b, b]));
    }
}
