//! Cycles among tetrahedra broken by planes through their members (
//! MWS section IV's last exact step before per-pixel ordering).
//!
//! A cycle left after cells were split into tets (tets can overlap
//! cyclically, like three interlocked sticks) has no back-to-front order as
//! whole pieces. Cutting the pieces with the plane of a face of one member
//! always gives an order between the two sides: a ray crosses a plane once,
//! so everything on the eye's far side is drawn before everything on its
//! side. Recursively (an auto-partition BSP restricted to the group):
//! 1. at a node with more than one fragment, the planes of its fragments'
//!    tets not yet used by them are candidates (the first
//!    [`MAX_CANDIDATES`] scored, more while none is useful); the one with
//!    fragments on both sides and the fewest fragments straddling it is
//!    chosen (ties: the first);
//! 2. straddling fragments are cut in two (the cap polygon lies in the plane);
//!    both sides are ordered recursively; the far side is emitted first;
//! 3. a node whose fragments have used all their planes holds fragments that
//!    overlap in space (a fragment that used all its planes *is* the node's
//!    region): no order exists, and the whole group is left to the
//!    per-pixel compositing (`render::group`).
//!
//! Sides: a vertex's side of a plane through three mesh points is decided in
//! floating point with a band of half-width
//! [`crate::numeric::tolerance::BSP_ON_PLANE_REL`] of the group's size
//! (inside: on the plane), far above the rounding of the cut points, so a
//! later plane through (nearly) the same line never makes near-duplicate cut
//! points; mesh points exactly on a plane are decided by [`orient3d`]. Cut
//! vertices are computed once and shared by both halves, and each part's cap
//! is chained from its own faces' edges in the plane, so every fragment is a
//! closed surface. Fragments keep their
//! vertices as barycentric weights of their tet, so the renderer gets
//! positions and (linear) scalars from the tet's own corners. The number of
//! fragments is capped ([`MAX_FRAGMENTS_PER_PIECE`]); past it, or for groups
//! that hold anything but tets, the group is left whole. Cut parts of
//! (rounding-level) zero volume are dropped
//! ([`crate::numeric::tolerance::BSP_SLIVER_REL`]).

use glam::DVec3;

use super::Piece;
use crate::numeric::predicates::{orient3d, Side};
use crate::numeric::tolerance::{BSP_ON_PLANE_REL, BSP_SLIVER_REL};

/// Fragments allowed per group piece before the group is left to per-pixel
/// compositing (auto-partitions of `n` convex pieces can grow quadratically).
pub const MAX_FRAGMENTS_PER_PIECE: usize = 16;

/// Largest group tried (the work grows with the square of its size).
pub const MAX_GROUP: usize = 256;

/// Candidate planes scored per node (the first fragments' unused planes):
/// bounds a node's work by `MAX_CANDIDATES x fragments`.
pub const MAX_CANDIDATES: usize = 16;

/// A convex part of a tetrahedron: vertices as barycentric weights of the
/// tet's corners, boundary triangles wound outward (right-hand rule, world
/// space).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fragment {
    pub weights: Vec<[f64; 4]>,
    pub triangles: Vec<[u32; 3]>,
}

impl Fragment {
    /// World positions of the vertices for the tet with corners `q`.
    pub fn positions(&self, q: &[DVec3; 4]) -> Vec<DVec3> {
        self.weights.iter().map(|w| combine(w, q)).collect()
    }

    /// Values of a linear field with corner values `s`.
    pub fn values(&self, s: &[f64; 4]) -> Vec<f64> {
        self.weights
            .iter()
            .map(|w| w[0] * s[0] + w[1] * s[1] + w[2] * s[2] + w[3] * s[3])
            .collect()
    }
}

#[inline]
fn combine(w: &[f64; 4], q: &[DVec3; 4]) -> DVec3 {
    q[0] * w[0] + q[1] * w[1] + q[2] * w[2] + q[3] * w[3]
}

/// A plane through three mesh points (right-hand normal).
type Plane = [u32; 3];

/// A fragment under construction.
#[derive(Clone, Debug)]
struct Frag {
    /// Index of the group piece it comes from.
    src: usize,
    /// Barycentric weights and world positions of its vertices.
    w: Vec<[f64; 4]>,
    x: Vec<DVec3>,
    /// Faces as vertex loops, outward by the right-hand rule.
    faces: Vec<Vec<u32>>,
    /// Planes this fragment was cut by or lies inside of.
    used: Vec<Plane>,
}

/// The eye for side tests: a point (perspective) or a direction of
/// projection (orthographic).
pub trait EyeSide {
    /// Exact side of the eye relative to the plane through `a, b, c`.
    fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> Side;
}

/// Orders the tets of one cycle group back to front by cutting them with
/// the planes of their faces. Returns the fragments in drawing order with
/// the index of the group piece each comes from, or `None` when the group
/// holds other pieces, overlaps itself, or would need too many fragments.
pub fn order_group(
    pieces: &[Piece],
    points: &[DVec3],
    eye: &impl EyeSide,
) -> Option<Vec<(usize, Fragment)>> {
    if pieces.len() < 2 || pieces.len() > MAX_GROUP {
        return None;
    }
    let mut frags = Vec::with_capacity(pieces.len());
    let mut planes: Vec<Vec<Plane>> = Vec::with_capacity(pieces.len());
    for (i, p) in pieces.iter().enumerate() {
        let Piece::Tet { tet, .. } = *p else {
            return None;
        };
        let q = tet.map(|v| points.get(v as usize).copied());
        let q = [q[0]?, q[1]?, q[2]?, q[3]?];
        let (f, pl) = tet_fragment(i, tet, q)?;
        frags.push(f);
        planes.push(pl);
    }
    let budget = MAX_FRAGMENTS_PER_PIECE * pieces.len();
    let volumes = frags.iter().map(volume).collect();
    let (lo, hi) = frags.iter().flat_map(|f| f.x.iter()).fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &x| (lo.min(x), hi.max(x)),
    );
    let mut ctx = Bsp {
        points,
        scale: (hi - lo).length(),
        volumes,
        planes: &planes,
        made: pieces.len(),
        budget,
    };
    let mut out = Vec::with_capacity(frags.len());
    ctx.order(frags, eye, &mut out)?;

    Some(
        out.into_iter()
            .map(|f| {
                let mut triangles = Vec::new();
                for face in &f.faces {
                    for k in 1..face.len().saturating_sub(1) {
                        let t = [face[0], face[k], face[k + 1]];
                        let [a, b, c] = t.map(|v| f.x[v as usize]);
                        // Collinear corners (a vertex on an edge): no area.
                        if (b - a).cross(c - a) != DVec3::ZERO {
                            triangles.push(t);
                        }
                    }
                }
                (
                    f.src,
                    Fragment {
                        weights: f.w,
                        triangles,
                    },
                )
            })
            .collect(),
    )
}

/// The whole tet as a fragment, with its four face planes (outward).
fn tet_fragment(src: usize, tet: [u32; 4], q: [DVec3; 4]) -> Option<(Frag, Vec<Plane>)> {
    // Faces of a positively oriented tet (d on the negative side of a, b, c
    // means a, b, c is outward... fixed below by the orientation).
    let vol = orient3d(q[0], q[1], q[2], q[3]);
    let local: [[u32; 3]; 4] = match vol {
        // q3 on the normal side of (q0, q1, q2): that face points inward.
        Side::Positive => [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        Side::Negative => [[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]],
        Side::On => return None,
    };
    let mut w = Vec::with_capacity(4);
    for k in 0..4 {
        let mut e = [0.0; 4];
        e[k] = 1.0;
        w.push(e);
    }
    let faces = local.iter().map(|f| f.to_vec()).collect();
    let planes = local.iter().map(|f| f.map(|l| tet[l as usize])).collect();
    Some((
        Frag {
            src,
            w,
            x: q.to_vec(),
            faces,
            used: Vec::new(),
        },
        planes,
    ))
}

/// The cap of one part of a cut: its faces' edges with both ends on the
/// plane, reversed and chained into one loop; `None` when they do not form
/// exactly one loop of at least three vertices.
fn cap_loop(faces: &[Vec<u32>], on: &[bool]) -> Option<Vec<u32>> {
    let mut next: Vec<(u32, u32)> = Vec::new();
    for fc in faces {
        for k in 0..fc.len() {
            let (a, b) = (fc[k], fc[(k + 1) % fc.len()]);
            if on[a as usize] && on[b as usize] {
                if next.iter().any(|e| e.0 == b) {
                    return None;
                }
                next.push((b, a));
            }
        }
    }
    if next.len() < 3 {
        return None;
    }
    let start = next[0].0;
    let mut cap = vec![start];
    let mut v = next[0].1;
    while v != start {
        if cap.len() > next.len() {
            return None;
        }
        cap.push(v);
        v = next.iter().find(|e| e.0 == v)?.1;
    }
    (cap.len() == next.len()).then_some(cap)
}

/// Volume of a fragment (its faces are wound outward).
fn volume(f: &Frag) -> f64 {
    let Some(&o) = f.x.first() else {
        return 0.0;
    };
    let mut v = 0.0;
    for face in &f.faces {
        for k in 1..face.len().saturating_sub(1) {
            let [a, b, c] = [face[0], face[k], face[k + 1]].map(|i| f.x[i as usize] - o);
            v += a.dot(b.cross(c));
        }
    }
    v / 6.0
}

struct Bsp<'a> {
    points: &'a [DVec3],
    /// Diagonal of the group's bounding box.
    scale: f64,
    /// Volume of each group piece.
    volumes: Vec<f64>,
    /// Outward face planes of each group piece.
    planes: &'a [Vec<Plane>],
    made: usize,
    budget: usize,
}

impl Bsp<'_> {
    /// Side of `x`: exact for mesh points; cut points (rounded) within
    /// [`BSP_ON_PLANE_REL`] of the group's size from the plane are on it.
    fn side(&self, pl: &Plane, x: DVec3) -> Side {
        let [a, b, c] = pl.map(|v| self.points[v as usize]);
        let n = (b - a).cross(c - a);
        let d = n.dot(x - a);
        let band = BSP_ON_PLANE_REL * self.scale * n.length();
        if d > band {
            Side::Positive
        } else if d < -band {
            Side::Negative
        } else if band == 0.0 {
            orient3d(a, b, c, x)
        } else {
            Side::On
        }
    }

    /// Appends `frags` back to front to `out`; `None`: no order (overlap or
    /// budget).
    fn order(&mut self, frags: Vec<Frag>, eye: &impl EyeSide, out: &mut Vec<Frag>) -> Option<()> {
        if frags.len() <= 1 {
            out.extend(frags);
            return Some(());
        }
        // Candidate planes: each fragment's unused source planes.
        let mut best: Option<(usize, Plane)> = None;
        let mut scored = 0;
        for f in &frags {
            for pl in &self.planes[f.src] {
                if f.used.contains(pl) || (scored >= MAX_CANDIDATES && best.is_some()) {
                    continue;
                }
                scored += 1;
                let (mut pos, mut neg, mut both) = (0usize, 0usize, 0usize);
                for g in &frags {
                    let (p, n) = self.extent(g, pl);
                    match (p, n) {
                        (true, true) => both += 1,
                        (true, false) => pos += 1,
                        (false, true) => neg += 1,
                        // Flat fragment in the plane: either side.
                        (false, false) => neg += 1,
                    }
                }
                if both == 0 && (pos == 0 || neg == 0) {
                    continue;
                }
                if best.is_none_or(|(b, _)| both < b) {
                    best = Some((both, *pl));
                }
            }
        }
        let (_, pl) = best?;
        let mut front = Vec::new();
        let mut back = Vec::new();
        for mut f in frags {
            let (p, n) = self.extent(&f, &pl);
            match (p, n) {
                (true, true) => {
                    self.made += 1;
                    if self.made > self.budget {
                        return None;
                    }
                    let (a, b) = self.cut(&f, &pl)?;
                    let keep = BSP_SLIVER_REL * self.volumes[f.src];
                    if volume(&a) > keep {
                        front.push(a);
                    }
                    if volume(&b) > keep {
                        back.push(b);
                    }
                }
                (true, false) => {
                    f.used.push(pl);
                    front.push(f);
                }
                _ => {
                    f.used.push(pl);
                    back.push(f);
                }
            }
        }
        let [a, b, c] = pl.map(|v| self.points[v as usize]);
        // The side away from the eye is drawn first.
        let (first, second) = match eye.side(a, b, c) {
            Side::Positive => (back, front),
            _ => (front, back),
        };
        self.order(first, eye, out)?;
        self.order(second, eye, out)
    }

    /// Whether the fragment has vertices strictly on the positive and on
    /// the negative side of the plane.
    fn extent(&self, f: &Frag, pl: &Plane) -> (bool, bool) {
        let (mut p, mut n) = (false, false);
        for &x in &f.x {
            match self.side(pl, x) {
                Side::Positive => p = true,
                Side::Negative => n = true,
                Side::On => {}
            }
            if p && n {
                break;
            }
        }
        (p, n)
    }

    /// Cuts a straddling fragment into its positive and negative parts.
    fn cut(&self, f: &Frag, pl: &Plane) -> Option<(Frag, Frag)> {
        let [pa, pb, pc] = pl.map(|v| self.points[v as usize]);
        let normal = (pb - pa).cross(pc - pa);
        let dist = |x: DVec3| normal.dot(x - pa);
        let sides: Vec<Side> = f.x.iter().map(|&x| self.side(pl, x)).collect();
        // Shared vertex list: the originals, then one cut point per crossed
        // edge (computed once, from the edge's endpoints in a fixed order).
        let mut w = f.w.clone();
        let mut x = f.x.clone();
        let mut on: Vec<bool> = sides.iter().map(|&s| s == Side::On).collect();
        let mut cuts: Vec<((u32, u32), u32)> = Vec::new();
        let mut cut_point = |i: u32, j: u32, w: &mut Vec<[f64; 4]>, x: &mut Vec<DVec3>| {
            let key = (i.min(j), i.max(j));
            if let Some(&(_, k)) = cuts.iter().find(|(e, _)| *e == key) {
                return k;
            }
            let (a, b) = (key.0 as usize, key.1 as usize);
            let (da, db) = (dist(x[a]), dist(x[b]));
            let t = (da / (da - db)).clamp(0.0, 1.0);
            let wa = w[a];
            let wb = w[b];
            let mut wn = [0.0; 4];
            for k in 0..4 {
                wn[k] = wa[k] + (wb[k] - wa[k]) * t;
            }
            let xn = x[a] + (x[b] - x[a]) * t;
            w.push(wn);
            x.push(xn);
            on.push(true);
            let k = (x.len() - 1) as u32;
            cuts.push((key, k));
            k
        };
        let side_of =
            |v: u32, sides: &[Side]| -> Side { sides.get(v as usize).copied().unwrap_or(Side::On) };
        let mut pos_faces: Vec<Vec<u32>> = Vec::new();
        let mut neg_faces: Vec<Vec<u32>> = Vec::new();
        for face in &f.faces {
            let mut pf = Vec::new();
            let mut nf = Vec::new();
            for k in 0..face.len() {
                let (i, j) = (face[k], face[(k + 1) % face.len()]);
                let (si, sj) = (side_of(i, &sides), side_of(j, &sides));
                match si {
                    Side::Positive => pf.push(i),
                    Side::Negative => nf.push(i),
                    Side::On => {
                        pf.push(i);
                        nf.push(i);
                    }
                }
                if (si == Side::Positive && sj == Side::Negative)
                    || (si == Side::Negative && sj == Side::Positive)
                {
                    let c = cut_point(i, j, &mut w, &mut x);
                    pf.push(c);
                    nf.push(c);
                }
            }
            if pf.len() >= 3 && pf.iter().any(|&v| side_of(v, &sides) == Side::Positive) {
                pos_faces.push(pf);
            }
            if nf.len() >= 3 && nf.iter().any(|&v| side_of(v, &sides) == Side::Negative) {
                neg_faces.push(nf);
            }
        }
        // The caps: each part's boundary edges that lie in the plane, walked
        // reversed (so both parts stay closed, whatever the rounding of the
        // cut points).
        let neg_cap = cap_loop(&neg_faces, &on)?;
        let pos_cap = cap_loop(&pos_faces, &on)?;
        neg_faces.push(neg_cap);
        pos_faces.push(pos_cap);
        let part = |faces: Vec<Vec<u32>>| -> Frag {
            // Keep only the vertices the faces use.
            let mut map = vec![u32::MAX; x.len()];
            let mut pw = Vec::new();
            let mut px = Vec::new();
            let faces = faces
                .into_iter()
                .map(|fc| {
                    fc.into_iter()
                        .map(|v| {
                            if map[v as usize] == u32::MAX {
                                map[v as usize] = pw.len() as u32;
                                pw.push(w[v as usize]);
                                px.push(x[v as usize]);
                            }
                            map[v as usize]
                        })
                        .collect()
                })
                .collect();
            let mut used = f.used.clone();
            used.push(*pl);
            Frag {
                src: f.src,
                w: pw,
                x: px,
                faces,
                used,
            }
        };
        Some((part(pos_faces), part(neg_faces)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::interlocked_tets;

    struct Dir(DVec3);
    impl EyeSide for Dir {
        fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> Side {
            crate::numeric::predicates::orient_dir(a, b, c, -self.0)
        }
    }

    fn tets(m: &crate::mesh::Mesh) -> Vec<Piece> {
        (0..m.cells.len())
            .map(|c| {
                let n = m.cells.nodes(c);
                Piece::Tet {
                    cell: c as u32,
                    tet: [n[0], n[1], n[2], n[3]],
                }
            })
            .collect()
    }

    /// Whatever the order of the group's members and the view, the cuts
    /// give closed, outward fragments whose volumes add up to their tets'.
    #[test]
    fn interlocked_tets_are_cut_into_closed_fragments() {
        let m = interlocked_tets();
        let all = tets(&m);
        let perms = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        for perm in perms {
            let pieces: Vec<Piece> = perm.iter().map(|&k| all[k]).collect();
            for d in [DVec3::Z, -DVec3::Z, DVec3::new(0.3, 0.1, -1.0)] {
                let frags = order_group(&pieces, &m.points, &Dir(d)).expect("an order");
                assert!(frags.len() > 3 && frags.len() <= 3 * MAX_FRAGMENTS_PER_PIECE);
                let mut vol = [0.0; 3];
                for (src, f) in &frags {
                    let Piece::Tet { tet, .. } = pieces[*src] else {
                        unreachable!()
                    };
                    let x = f.positions(&tet.map(|v| m.points[v as usize]));
                    let o = x[0];
                    let mut edges = std::collections::HashSet::new();
                    for t in &f.triangles {
                        let [a, b, c] = t.map(|i| x[i as usize] - o);
                        vol[*src] += a.dot(b.cross(c)) / 6.0;
                        for k in 0..3 {
                            edges.insert((t[k], t[(k + 1) % 3]));
                        }
                    }
                    let open = edges.iter().filter(|&&(a, b)| !edges.contains(&(b, a)));
                    assert_eq!(open.count(), 0, "{perm:?} {d:?}: fragment not closed");
                }
                for v in vol {
                    assert!((v - 0.64).abs() < 1e-12, "{perm:?} {d:?}: {vol:?}");
                }
            }
        }
    }

    /// Overlapping tets have no order: left to per-pixel compositing.
    #[test]
    fn overlapping_tets_are_left_whole() {
        let mut m = interlocked_tets();
        // A copy of tet 0 shifted by a tenth of its size overlaps it.
        let n: Vec<u32> = m.cells.nodes(0).to_vec();
        let base = m.points.len() as u32;
        for &v in &n {
            let p = m.points[v as usize] + DVec3::splat(0.1);
            m.points.push(p);
        }
        m.cells.push(
            crate::mesh::CellKind::Tetra,
            &[base, base + 1, base + 2, base + 3],
        );
        let pieces = tets(&m);
        let pair = [pieces[0], pieces[3]];
        assert_eq!(order_group(&pair, &m.points, &Dir(DVec3::Z)), None);
        // A non-tet piece is never cut.
        assert_eq!(
            order_group(&[Piece::Cell(0), pieces[1]], &m.points, &Dir(DVec3::Z)),
            None
        );
    }
}
