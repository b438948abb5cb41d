//! Walking a ray through the cells of a mesh by face adjacency.
//!
//! The walk sees every cell as the closed surface of its face triangles
//! (quads split by the smallest-vertex diagonal, n-gons as fans from the
//! smallest vertex: `tetra::triangulate_face`), so neighbours always share
//! exactly the same triangles. A walk:
//! 1. collects the boundary triangles the ray line enters the mesh through
//!    ([`super::bvh`] finds candidates; [`super::geometry`] decides exactly),
//!    sorted by depth. "Enters" compares the crossing direction with the
//!    outward side of the boundary face, known from the sign of its cell's
//!    enclosed volume (so inverted cells are handled);
//! 2. from the first entry, repeatedly finds where the ray leaves the current
//!    cell: among the cell's triangles the ray crosses (other than the one it
//!    came in through), the first at or after the entry depth. Convex cells
//!    have exactly one; non-convex cells (nonplanar or inverted faces) may
//!    have several, and the ray then leaves and later re-enters the same cell;
//! 3. crosses to the neighbour across that triangle's face, or, at a boundary
//!    face, continues with the next entry at or after the exit depth (holes,
//!    cavities, disconnected parts).
//!
//! Each crossed triangle is identified by its face and the pair of its
//! non-smallest vertices, so the walk never re-selects the triangle it came
//! in through. A step limit bounds the walk on broken meshes.

use std::borrow::Cow;

use glam::DVec3;

use super::bvh::Bvh;
use super::geometry::{Proj, RayFrame};
use crate::mesh::tetra::triangulate_face;
use crate::mesh::topology::Topology;
use crate::mesh::{CellKind, Cells, NONE};
use crate::numeric::tolerance::BVH_PAD_REL;

/// One cell's part of a ray: the walk cell, entry and exit depth, and the
/// entry and exit points as barycentric weights of triangle vertices.
#[derive(Clone, Copy, Debug)]
pub struct RawSegment {
    pub cell: u32,
    pub t_in: f64,
    pub t_out: f64,
    pub v_in: [u32; 3],
    pub w_in: [f64; 3],
    pub v_out: [u32; 3],
    pub w_out: [f64; 3],
}

#[derive(Clone, Copy, Debug)]
struct BoundaryTri {
    verts: [u32; 3],
    face: u32,
    cell: u32,
    key: u64,
    /// +1 when the triangle's winding normal points out of the mesh.
    outward: i8,
}

/// Everything the walk needs, built once per scene.
pub struct WalkMesh<'a> {
    pub points: &'a [DVec3],
    pub cells: Cow<'a, Cells>,
    pub topo: Cow<'a, Topology>,
    boundary: Vec<BoundaryTri>,
    bvh: Bvh,
    pub center: DVec3,
    pub radius: f64,
    lo: DVec3,
    hi: DVec3,
}

/// Per-thread scratch space for walks.
#[derive(Default)]
pub struct Scratch {
    proj: Vec<(u32, DVec3, Proj)>,
    /// Boundary entries: depth, triangle, and the crossing's vertices and
    /// weights in [`super::geometry::Crossing::order`].
    entries: Vec<(f64, u32, [u32; 3], [f64; 3])>,
    stack: Vec<u32>,
    /// Edge values of the current cell by local node pair (NaN: not yet).
    edges: Vec<f64>,
}

#[inline]
fn tri_key(t: [u32; 3]) -> u64 {
    let (a, b) = (t[1].min(t[2]), t[1].max(t[2]));
    ((a as u64) << 32) | b as u64
}

struct Exit {
    face: u32,
    key: u64,
    t: f64,
    verts: [u32; 3],
    w: [f64; 3],
}

impl<'a> WalkMesh<'a> {
    /// Builds the boundary structure. Point ids must be valid (checked by
    /// the caller).
    pub fn new(
        points: &'a [DVec3],
        cells: Cow<'a, Cells>,
        topo: Cow<'a, Topology>,
    ) -> WalkMesh<'a> {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for &n in &cells.conn {
            lo = lo.min(points[n as usize]);
            hi = hi.max(points[n as usize]);
        }
        if lo.x > hi.x {
            lo = DVec3::ZERO;
            hi = DVec3::ZERO;
        }
        let (center, radius) = super::geometry::bounding_sphere(lo, hi);
        let mut boundary = Vec::new();
        let mut orient_cache: Vec<(u32, i8)> = Vec::new();
        for f in 0..topo.face_count() {
            if !topo.is_boundary(f) {
                continue;
            }
            let cell = topo.face_cells[f][0];
            let outward = match orient_cache.last() {
                Some(&(c, o)) if c == cell => o,
                _ => {
                    let o = cell_orientation(points, &cells, cell as usize);
                    orient_cache.clear();
                    orient_cache.push((cell, o));
                    o
                }
            };
            triangulate_face(topo.face(f), |t| {
                boundary.push(BoundaryTri {
                    verts: t,
                    face: f as u32,
                    cell,
                    key: tri_key(t),
                    outward,
                })
            });
        }
        let boxes: Vec<(DVec3, DVec3)> = boundary
            .iter()
            .map(|b| {
                let p = b.verts.map(|v| points[v as usize]);
                (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            })
            .collect();
        let pad = BVH_PAD_REL * (radius + center.abs().max_element()).max(f64::MIN_POSITIVE);
        let bvh = Bvh::build(&boxes, pad);
        WalkMesh {
            points,
            cells,
            topo,
            boundary,
            bvh,
            center,
            radius,
            lo,
            hi,
        }
    }

    /// Bytes held by the boundary structure.
    pub fn bytes(&self) -> usize {
        self.bvh.bytes() + self.boundary.len() * std::mem::size_of::<BoundaryTri>()
    }

    /// Whether `p` is inside the (closed) bounding box of the mesh.
    pub fn in_bounds(&self, p: DVec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }

    /// Walks the ray, calling `f` with each cell segment in order, for the
    /// part of the line from `t0` on (pass `-inf` when the origin may be
    /// inside the mesh: segments behind it are then reported too, and the
    /// caller clips). Stops when `f` returns false.
    pub fn walk(
        &self,
        frame: &RayFrame,
        t0: f64,
        scratch: &mut Scratch,
        mut f: impl FnMut(&RawSegment) -> bool,
    ) {
        let mut entries = std::mem::take(&mut scratch.entries);
        self.collect_entries(frame, t0, scratch, &mut entries);
        let slack = crate::numeric::tolerance::RAY_REENTRY_SLACK_REL * 2.0 * self.radius;
        let mut steps_left = 4 * self.cells.len() + 16;
        let mut t_cur = f64::NEG_INFINITY;
        'entries: for &(t, b, v, w) in &entries {
            if t < t_cur - slack {
                continue;
            }
            let bt = &self.boundary[b as usize];
            let mut cell = bt.cell;
            let mut entry = (bt.face, bt.key);
            let mut t_in = t;
            let mut v_in = v;
            let mut w_in = w;
            loop {
                if steps_left == 0 {
                    break 'entries;
                }
                steps_left -= 1;
                let Some(x) = self.exit_of(frame, cell as usize, entry, t_in, scratch) else {
                    t_cur = t_in;
                    break;
                };
                let t_out = x.t.max(t_in);
                let seg = RawSegment {
                    cell,
                    t_in,
                    t_out,
                    v_in,
                    w_in,
                    v_out: x.verts,
                    w_out: x.w,
                };
                if !f(&seg) {
                    break 'entries;
                }
                let next = self.topo.neighbour(x.face as usize, cell);
                if next == NONE || next as usize >= self.cells.len() {
                    t_cur = t_out;
                    break;
                }
                cell = next;
                entry = (x.face, x.key);
                t_in = t_out;
                v_in = x.verts;
                w_in = x.w;
            }
        }
        scratch.entries = entries;
    }

    fn collect_entries(
        &self,
        frame: &RayFrame,
        t0: f64,
        scratch: &mut Scratch,
        entries: &mut Vec<(f64, u32, [u32; 3], [f64; 3])>,
    ) {
        entries.clear();
        let pts = self.points;
        let bnd = &self.boundary;
        self.bvh
            .query(frame.o, frame.d, t0, &mut scratch.stack, |i| {
                let b = &bnd[i as usize];
                let p = b.verts.map(|v| pts[v as usize]);
                let pr = p.map(|x| frame.project(x));
                let [i0, i1, i2] = b.verts;
                let e = [
                    frame.edge(i0, p[0], &pr[0], i1, p[1], &pr[1]),
                    frame.edge(i1, p[1], &pr[1], i2, p[2], &pr[2]),
                    frame.edge(i2, p[2], &pr[2], i0, p[0], &pr[0]),
                ];
                if let Some(c) = frame.crossing(e, [&pr[0], &pr[1], &pr[2]]) {
                    if c.sign * b.outward < 0 && c.t >= t0 {
                        entries.push((
                            c.t,
                            i,
                            c.order.map(|k| b.verts[k]),
                            c.order.map(|k| c.w[k]),
                        ));
                    }
                }
            });
        entries.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    }

    /// Where the ray leaves cell `c` after entering it through triangle
    /// `entry` at depth `t_in`.
    fn exit_of(
        &self,
        frame: &RayFrame,
        c: usize,
        entry: (u32, u64),
        t_in: f64,
        scratch: &mut Scratch,
    ) -> Option<Exit> {
        let nodes = self.cells.nodes(c);
        let proj = &mut scratch.proj;
        proj.clear();
        for &n in nodes {
            let p = self.points[n as usize];
            proj.push((n, p, frame.project(p)));
        }
        // Each edge is shared by two triangles of the cell: cache its value
        // by local node pair (value of j -> i is minus that of i -> j).
        let nn = nodes.len();
        let edges = &mut scratch.edges;
        edges.clear();
        edges.resize(nn * nn, f64::NAN);
        let faces = self.topo.faces_of(c);
        let mut best: Option<Exit> = None;
        let mut consider = |fid: u32, tri: [usize; 3], proj: &[(u32, DVec3, Proj)]| {
            let g = tri.map(|k| proj[k].0);
            let key = tri_key(g);
            if (fid, key) == entry {
                return;
            }
            let mut edge = |i: usize, j: usize| {
                let v = edges[i * nn + j];
                if !v.is_nan() {
                    return v;
                }
                let (a, b) = (&proj[i], &proj[j]);
                let v = frame.edge(a.0, a.1, &a.2, b.0, b.1, &b.2);
                edges[i * nn + j] = v;
                edges[j * nn + i] = -v;
                v
            };
            let e = [
                edge(tri[0], tri[1]),
                edge(tri[1], tri[2]),
                edge(tri[2], tri[0]),
            ];
            let [a, b, cc] = tri.map(|k| &proj[k]);
            let Some(x) = frame.crossing(e, [&a.2, &b.2, &cc.2]) else {
                return;
            };
            let better = match &best {
                None => true,
                Some(bx) => {
                    let (ahead, bahead) = (x.t >= t_in, bx.t >= t_in);
                    match (ahead, bahead) {
                        (true, false) => true,
                        (false, true) => false,
                        (true, true) => x.t < bx.t,
                        (false, false) => x.t > bx.t,
                    }
                }
            };
            if better {
                best = Some(Exit {
                    face: fid,
                    key,
                    t: x.t,
                    verts: x.order.map(|k| g[k]),
                    w: x.order.map(|k| x.w[k]),
                });
            }
        };
        let kind = self.cells.kinds[c];
        if kind != CellKind::Polyhedron {
            for (fi, lf) in kind.faces().iter().enumerate() {
                let Some(&fid) = faces.get(fi) else { break };
                let n = lf.len();
                let k0 = (0..n).min_by_key(|&i| nodes[lf[i] as usize]).unwrap_or(0);
                for i in 1..n.saturating_sub(1) {
                    let tri = [
                        lf[k0] as usize,
                        lf[(k0 + i) % n] as usize,
                        lf[(k0 + i + 1) % n] as usize,
                    ];
                    consider(fid, tri, proj);
                }
            }
        } else {
            let mut local = Vec::new();
            self.cells.for_each_face(c, |fi, face| {
                let Some(&fid) = faces.get(fi) else { return };
                local.clear();
                for &g in face {
                    match nodes.iter().position(|&n| n == g) {
                        Some(k) => local.push(k),
                        None => return,
                    }
                }
                let n = local.len();
                let k0 = (0..n).min_by_key(|&i| nodes[local[i]]).unwrap_or(0);
                for i in 1..n.saturating_sub(1) {
                    let tri = [local[k0], local[(k0 + i) % n], local[(k0 + i + 1) % n]];
                    consider(fid, tri, proj);
                }
            });
        }
        best
    }
}

/// +1 when the closed surface of cell `c`'s face triangles (in the cell's
/// face winding) encloses positive volume, -1 when negative (inverted), +1
/// for zero volume.
pub fn cell_orientation(points: &[DVec3], cells: &Cells, c: usize) -> i8 {
    let nodes = cells.nodes(c);
    let Some(&r) = nodes.first() else { return 1 };
    let r = points[r as usize];
    let mut vol = 0.0;
    cells.for_each_face(c, |_, face| {
        triangulate_face(face, |t| {
            let [a, b, cc] = t.map(|v| points[v as usize] - r);
            vol += (b - a).cross(cc - a).dot(a);
        })
    });
    if vol < 0.0 {
        -1
    } else {
        1
    }
}
