//! Per-geometry data of the visibility sort, built once and reused for every
//! view: the smallest-vertex triangles of every unique face with their plane
//! equations and float-filter error bounds, which side of each face its first
//! cell lies on, and whether the boundary surface is convex.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::tetra::triangulate_face;
use crate::mesh::topology::Topology;
use crate::mesh::{Mesh, NONE};
use crate::numeric::predicates::{orient3d, Plane3, Side};
use crate::numeric::tolerance::F32_ROUND_UP_REL;

/// Face flag: the stored winding of the face points *into* its first cell
/// (the first cell has negative volume).
pub const FLIP: u8 = 1;
/// Face flag: boundary face with a concave diagonal (can be a problem face).
pub const CONCAVE: u8 = 2;
/// Face flag: boundary face.
pub const BOUNDARY: u8 = 4;
/// Face flag: a face of several triangles whose vertices are exactly
/// coplanar (one plane test decides all its triangles).
pub const PLANAR: u8 = 8;

/// One boundary triangle: its face, its index in the face's triangulation
/// and its vertices, wound outward.
#[derive(Clone, Copy, Debug)]
pub struct BoundaryTri {
    pub face: u32,
    pub k: u8,
    pub verts: [u32; 3],
}

/// Plane data of every face triangle, flags of every face.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// `tri_off[f]..tri_off[f + 1]`: the triangles of face `f`.
    pub tri_off: Vec<u32>,
    /// Per triangle: normal (stored winding) and `d = n . a`.
    pub planes: Vec<[f64; 4]>,
    /// Per face: `(m, amax)` of the filter bound, rounded up.
    pub face_err: Vec<[f32; 2]>,
    /// Per face: [`FLIP`], [`CONCAVE`], [`BOUNDARY`].
    pub face_flags: Vec<u8>,
    /// Boundary triangles (outward winding).
    pub boundary: Vec<BoundaryTri>,
    /// Whether the boundary is one closed convex surface.
    pub convex: bool,
    /// Cells that are non-convex beyond their face diagonals (a vertex
    /// outside the plane of a face triangle it is not on the face of):
    /// always drawn as tets.
    pub nonconvex_cells: Vec<u32>,
}

/// Whether some vertex of cell `c` that is not on a face lies strictly
/// outside the outward plane of one of that face's triangles.
fn cell_nonconvex(mesh: &Mesh, c: usize, negative: bool) -> bool {
    let p = &mesh.points;
    let nodes = mesh.cells.nodes(c);
    let outside = if negative {
        Side::Negative
    } else {
        Side::Positive
    };
    let mut bad = false;
    mesh.cells.for_each_face(c, |_, face| {
        if bad {
            return;
        }
        triangulate_face(face, |t| {
            let [a, b, cc] = t.map(|i| p[i as usize]);
            let plane = Plane3::new(a, b, cc);
            for &v in nodes {
                if !face.contains(&v) && plane.side(p[v as usize]) == outside {
                    bad = true;
                }
            }
        });
    });
    bad
}

fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        y * (1.0 + F32_ROUND_UP_REL)
    } else {
        y
    }
}

/// Signed volume of cell `c` (six times, from its triangulated faces).
fn cell_volume6(mesh: &Mesh, c: usize) -> f64 {
    let p = &mesh.points;
    let nodes = mesh.cells.nodes(c);
    let Some(&n0) = nodes.first() else {
        return 0.0;
    };
    let o = p[n0 as usize];
    let mut v = 0.0;
    mesh.cells.for_each_face(c, |_, face| {
        triangulate_face(face, |t| {
            let [a, b, cc] = t.map(|i| p[i as usize] - o);
            v += a.dot(b.cross(cc));
        });
    });
    v
}

/// The per-face data of a block of faces (see [`Geometry::build`]).
#[derive(Default)]
struct FaceBlock {
    /// End of each face's triangles, counted from the block's first.
    tri_end: Vec<u32>,
    planes: Vec<[f64; 4]>,
    face_err: Vec<[f32; 2]>,
    face_flags: Vec<u8>,
    boundary: Vec<BoundaryTri>,
}

/// Planes, filter bounds, flags and boundary triangles of faces `range`
/// (`vol`: six times each cell's signed volume).
fn face_block(
    mesh: &Mesh,
    topo: &Topology,
    vol: &[f64],
    cut: &[bool],
    range: std::ops::Range<usize>,
) -> FaceBlock {
    let p = &mesh.points;
    let mut out = FaceBlock {
        tri_end: Vec::with_capacity(range.len()),
        planes: Vec::with_capacity(range.len() * 2),
        face_err: Vec::with_capacity(range.len()),
        face_flags: Vec::with_capacity(range.len()),
        boundary: Vec::new(),
    };
    for f in range {
        let [c0, c1] = topo.face_cells[f];
        let v0 = vol.get(c0 as usize).copied().unwrap_or(0.0);
        let v1 = if c1 == NONE {
            0.0
        } else {
            vol.get(c1 as usize).copied().unwrap_or(0.0)
        };
        let mut flags = 0u8;
        if v0 < 0.0 || (v0 == 0.0 && v1 < 0.0) {
            flags |= FLIP;
        }
        if c1 == NONE {
            flags |= BOUNDARY;
        }
        let face = topo.face(f);
        let mut m = 0.0f64;
        let mut amax = 0.0f64;
        let mut k = 0u8;
        triangulate_face(face, |t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            let n = (b - a).cross(c - a);
            out.planes.push([n.x, n.y, n.z, n.dot(a)]);
            m = m.max(2.0 * (b - a).abs().max_element() * (c - a).abs().max_element());
            amax = amax.max(a.abs().max_element());
            if c1 == NONE {
                let verts = if flags & FLIP != 0 {
                    [t[0], t[2], t[1]]
                } else {
                    t
                };
                out.boundary.push(BoundaryTri {
                    face: f as u32,
                    k,
                    verts,
                });
            }
            k += 1;
        });
        if face.len() > 3 && face_planar(p, face) {
            flags |= PLANAR;
        }
        let was_interior = cut.get(f).copied().unwrap_or(false);
        if c1 == NONE
            && face.len() > 3
            && (was_interior || boundary_face_concave(p, face, flags & FLIP != 0))
        {
            flags |= CONCAVE;
        }
        out.face_err.push([round_up(m), round_up(amax)]);
        out.face_flags.push(flags);
        out.tri_end.push(out.planes.len() as u32);
    }
    out
}

impl Geometry {
    /// Builds the data for `mesh` (point ids already checked in range).
    /// For a mesh cut out of a larger one, the boundary faces `f` with
    /// `cut[f]` were interior faces there, and are flagged [`CONCAVE`]
    /// whatever their shape, so that a problem face there splits its cell
    /// as the interior face did ([`super::Sorter::for_subset`]); `cut` is
    /// empty for a whole mesh.
    pub fn build(mesh: &Mesh, topo: &Topology, cut: &[bool]) -> Geometry {
        let p = &mesh.points;
        let nf = topo.face_count();
        let vol: Vec<f64> = (0..mesh.cells.len())
            .into_par_iter()
            .map(|c| cell_volume6(mesh, c))
            .collect();
        // Faces in parallel blocks (each block's planes, flags and boundary
        // triangles in face order), concatenated in block order: the same
        // arrays as one serial pass.
        const BLOCK: usize = 8192;
        let blocks: Vec<FaceBlock> = (0..nf.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| face_block(mesh, topo, &vol, cut, b * BLOCK..((b + 1) * BLOCK).min(nf)))
            .collect();
        let mut g = Geometry {
            tri_off: Vec::with_capacity(nf + 1),
            planes: Vec::with_capacity(nf * 2),
            face_err: Vec::with_capacity(nf),
            face_flags: Vec::with_capacity(nf),
            ..Default::default()
        };
        g.tri_off.push(0);
        for b in blocks {
            let base = g.planes.len() as u32;
            g.tri_off.extend(b.tri_end.iter().map(|&e| base + e));
            g.planes.extend_from_slice(&b.planes);
            g.face_err.extend_from_slice(&b.face_err);
            g.face_flags.extend_from_slice(&b.face_flags);
            g.boundary.extend_from_slice(&b.boundary);
        }
        g.nonconvex_cells = (0..mesh.cells.len())
            .into_par_iter()
            .filter(|&c| mesh.cells.kinds[c] != crate::mesh::CellKind::Tetra)
            .filter(|&c| cell_nonconvex(mesh, c, vol[c] < 0.0))
            .map(|c| c as u32)
            .collect();
        g.convex = topo.nonmanifold_faces == 0 && boundary_convex(p, &g.boundary);
        g
    }

    /// Triangles of face `f` as a range of triangle ids.
    #[inline]
    pub fn tris(&self, f: usize) -> std::ops::Range<usize> {
        self.tri_off[f] as usize..self.tri_off[f + 1] as usize
    }
}

/// Whether every vertex of `face` lies exactly on the plane of its first
/// three vertices (and those are not collinear).
fn face_planar(p: &[DVec3], face: &[u32]) -> bool {
    let [a, b, c] = [face[0], face[1], face[2]].map(|i| p[i as usize]);
    if (b - a).cross(c - a) == DVec3::ZERO {
        return false;
    }
    face[3..]
        .iter()
        .all(|&v| orient3d(a, b, c, p[v as usize]) == Side::On)
}

/// Whether some vertex of a boundary face lies strictly outside the outward
/// plane of one of its triangles (a concave diagonal seen from the cell).
fn boundary_face_concave(p: &[DVec3], face: &[u32], flip: bool) -> bool {
    let mut concave = false;
    triangulate_face(face, |t| {
        let [a, b, c] = t.map(|i| p[i as usize]);
        for &v in face {
            if t.contains(&v) {
                continue;
            }
            let s = orient3d(a, b, c, p[v as usize]);
            let outside = if flip { Side::Negative } else { Side::Positive };
            if s == outside {
                concave = true;
            }
        }
    });
    concave
}

/// Whether the boundary triangles form closed, connected, locally convex
/// surfaces (one component): then every line meets the mesh in one segment.
fn boundary_convex(p: &[DVec3], tris: &[BoundaryTri]) -> bool {
    if tris.is_empty() {
        return false;
    }
    // Edge (min, max) -> (triangle, opposite vertex, edge runs min -> max).
    type Uses = Vec<(u32, u32, bool)>;
    let mut edges: HashMap<(u32, u32), Uses> = HashMap::with_capacity(tris.len() * 2);
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b, opp) = (t.verts[k], t.verts[(k + 1) % 3], t.verts[(k + 2) % 3]);
            edges
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push((i as u32, opp, a < b));
        }
    }
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let g = parent[parent[x as usize] as usize];
            parent[x as usize] = g;
            x = g;
        }
        x
    }
    for list in edges.values() {
        // Closed, consistently wound: each edge used once in each direction.
        if list.len() != 2 || list[0].2 == list[1].2 {
            return false;
        }
        let (t0, _, _) = list[0];
        let (t1, opp1, _) = list[1];
        let [a, b, c] = tris[t0 as usize].verts.map(|i| p[i as usize]);
        if orient3d(a, b, c, p[opp1 as usize]) == Side::Positive {
            return false;
        }
        let (r0, r1) = (find(&mut parent, t0), find(&mut parent, t1));
        parent[r0 as usize] = r1;
    }
    let root = find(&mut parent, 0);
    (0..tris.len() as u32).all(|i| find(&mut parent, i) == root)
}

/// Parameter `t` (in units of `q - o`) where the line `o + t (q - o)` meets
/// the plane of `a, b, c`. The vertices are sorted first so the result does
/// not depend on their order (coincident triangles give identical `t`).
/// Returns `None` for a line parallel to the plane.
pub fn line_plane_t(o: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let mut p = [a, b, c];
    p.sort_by(|x, y| {
        x.x.total_cmp(&y.x)
            .then(x.y.total_cmp(&y.y))
            .then(x.z.total_cmp(&y.z))
    });
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let den = n.dot(q - o);
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    Some(n.dot(p[0] - o) / den)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_plane_parameter() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 0.0, 0.0);
        let c = DVec3::new(0.0, 1.0, 0.0);
        let o = DVec3::new(0.25, 0.25, 5.0);
        let t = line_plane_t(o, o - DVec3::Z, a, b, c).unwrap();
        assert!((t - 5.0).abs() < 1e-15);
        assert_eq!(line_plane_t(o, o + DVec3::X, a, b, c), None);
    }
}
