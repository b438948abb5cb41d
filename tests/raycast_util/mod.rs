//! Helpers shared by the ray caster tests: a test material with an
//! independently computed segment integral, in-memory meshes and exact chord
//! lengths of rays through convex shapes.
#![allow(dead_code)]

use glam::DVec3;
use zoovr::camera::Ray;
use zoovr::integrate::{Material, RayAccumulator, RayMaterial, SegmentValue};
use zoovr::mesh::tetra::tetrahedralize_cell;
use zoovr::mesh::topology::Topology;
use zoovr::mesh::{lattice_hex, CellKind, Cells, Mesh};
use zoovr::raycast::{FieldModel, RaycastOptions, Raycaster};

/// Options for `model` with early ray termination off (exact comparisons).
pub fn opts(model: FieldModel) -> RaycastOptions {
    RaycastOptions {
        model,
        early_termination: 0.0,
        ..Default::default()
    }
}

/// One ray traced by `rc` (built for `model`) from its origin, with fresh
/// scratch and early termination off.
pub fn trace_one(
    rc: &Raycaster,
    material: &impl RayMaterial,
    ray: &Ray,
    model: FieldModel,
) -> RayAccumulator {
    rc.trace(material, ray, 0.0, &opts(model), &mut Default::default())
}

/// Glow model with extinction and colour piecewise linear in `s` (nodes
/// `s_k`, constant outside). `segment` is computed here independently of the
/// closed forms: optical depth exactly (tau is linear in the distance on each
/// piece, so the trapezoid rule per piece is exact) and the colour integral by
/// composite 6-point Gauss-Legendre on 64 panels per piece (error < 1e-13).
pub struct TestMaterial {
    pub s: Vec<f64>,
    pub tau: Vec<f64>,
    pub color: Vec<[f64; 3]>,
}

impl TestMaterial {
    /// Constant extinction and colour.
    pub fn constant(tau: f64, color: [f64; 3]) -> TestMaterial {
        TestMaterial {
            s: vec![0.0],
            tau: vec![tau],
            color: vec![color],
        }
    }

    fn piece(&self, s: f64) -> (f64, [f64; 3]) {
        let n = self.s.len();
        if s <= self.s[0] {
            return (self.tau[0], self.color[0]);
        }
        if s >= self.s[n - 1] {
            return (self.tau[n - 1], self.color[n - 1]);
        }
        let k = self.s.iter().rposition(|&x| x <= s).unwrap_or(0).min(n - 2);
        let x = (s - self.s[k]) / (self.s[k + 1] - self.s[k]);
        let c = std::array::from_fn(|i| self.color[k][i] * (1.0 - x) + self.color[k + 1][i] * x);
        (self.tau[k] * (1.0 - x) + self.tau[k + 1] * x, c)
    }
}

const GL6: [(f64, f64); 6] = [
    (-0.932_469_514_203_152, 0.171_324_492_379_170),
    (-0.661_209_386_466_265, 0.360_761_573_048_139),
    (-0.238_619_186_083_197, 0.467_913_934_572_691),
    (0.238_619_186_083_197, 0.467_913_934_572_691),
    (0.661_209_386_466_265, 0.360_761_573_048_139),
    (0.932_469_514_203_152, 0.171_324_492_379_170),
];

impl RayMaterial for TestMaterial {
    fn segment(&self, l: f64, s_f: f64, s_b: f64) -> SegmentValue {
        // Cut points in x in [0, 1] at breakpoints.
        let mut xs = vec![0.0, 1.0];
        if s_f != s_b {
            for &b in &self.s {
                let x = (b - s_f) / (s_b - s_f);
                if x > 0.0 && x < 1.0 {
                    xs.push(x);
                }
            }
        }
        xs.sort_by(f64::total_cmp);
        let s_at = |x: f64| s_f + (s_b - s_f) * x;
        let mut depth = 0.0;
        let mut color = [0.0; 3];
        for w in xs.windows(2) {
            let (a, b) = (w[0], w[1]);
            let panels = 64;
            let h = (b - a) / panels as f64;
            for p in 0..panels {
                let (pa, pb) = (a + h * p as f64, a + h * (p + 1) as f64);
                let d0 = depth;
                for &(z, wt) in &GL6 {
                    let x = 0.5 * (pa + pb) + 0.5 * (pb - pa) * z;
                    let (tau, c) = self.piece(s_at(x));
                    // Depth from pa to x: tau linear in x on the piece.
                    let tau_a = self.piece(s_at(pa)).0;
                    let dx = d0 + l * (x - pa) * 0.5 * (tau_a + tau);
                    let e = (-dx).exp();
                    for k in 0..3 {
                        color[k] += 0.5 * (pb - pa) * wt * l * tau * c[k] * e;
                    }
                }
                let (ta, tb) = (self.piece(s_at(pa)).0, self.piece(s_at(pb)).0);
                depth += l * (pb - pa) * 0.5 * (ta + tb);
            }
        }
        SegmentValue {
            color,
            alpha: -(-depth).exp_m1(),
            depth,
        }
    }

    fn breakpoints(&self) -> &[f64] {
        &self.s
    }

    fn material(&self, s: f64) -> Material {
        let (tau, c) = self.piece(s);
        Material {
            tau,
            source: c.map(|x| x * tau),
        }
    }
}

/// A structured grid of `n[0] x n[1] x n[2]` hexahedra over the points
/// `map(i, j, k)`; point ids are `i + (n0+1)(j + (n1+1) k)` unless `perm`
/// relabels them (`new id = perm[old id]`).
pub fn grid(n: [usize; 3], map: impl Fn(f64, f64, f64) -> DVec3, perm: Option<&[u32]>) -> Mesh {
    let (px, py) = (n[0] + 1, n[1] + 1);
    let np = px * py * (n[2] + 1);
    let id = |i: usize, j: usize, k: usize| {
        let old = (i + px * (j + py * k)) as u32;
        perm.map_or(old, |p| p[old as usize])
    };
    let mut points = vec![DVec3::ZERO; np];
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                points[id(i, j, k) as usize] = map(i as f64, j as f64, k as f64);
            }
        }
    }
    let mut cells = Cells::default();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let c = lattice_hex(px, py, [i, j, k]).map(|v| perm.map_or(v, |p| p[v as usize]));
                cells.push(CellKind::Hexahedron, &c);
            }
        }
    }
    Mesh {
        points,
        cells,
        ..Default::default()
    }
}

/// The consistent tetrahedralisation of `mesh` as a tet mesh.
pub fn to_tets(mesh: &Mesh) -> Mesh {
    let mut cells = Cells::default();
    let mut buf = Vec::new();
    for c in 0..mesh.cells.len() {
        buf.clear();
        tetrahedralize_cell(&mesh.cells, c, &mut buf);
        for t in &buf {
            cells.push(CellKind::Tetra, t);
        }
    }
    Mesh {
        points: mesh.points.clone(),
        cells,
        ..Default::default()
    }
}

/// A deterministic permutation of `0..n` (xorshift shuffle).
pub fn shuffle(n: usize, seed: u64) -> Vec<u32> {
    let mut p: Vec<u32> = (0..n as u32).collect();
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    for i in (1..n).rev() {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        p.swap(i, (x % (i as u64 + 1)) as usize);
    }
    p
}

/// Chord length of the line `ray` (t >= t0) inside the convex polyhedron
/// given by outward planes `(normal, offset)`: `n . x <= offset`.
pub fn convex_chord(ray: &Ray, planes: &[(DVec3, f64)], t0: f64) -> f64 {
    let (mut lo, mut hi) = (t0, f64::INFINITY);
    for &(n, off) in planes {
        let dn = n.dot(ray.dir);
        let dist = off - n.dot(ray.origin);
        if dn.abs() < 1e-300 {
            if dist < 0.0 {
                return 0.0;
            }
            continue;
        }
        let t = dist / dn;
        if dn > 0.0 {
            hi = hi.min(t);
        } else {
            lo = lo.max(t);
        }
    }
    (hi - lo).max(0.0)
}

/// Planes of the axis-aligned box `lo..hi`.
pub fn box_planes(lo: DVec3, hi: DVec3) -> Vec<(DVec3, f64)> {
    vec![
        (DVec3::X, hi.x),
        (-DVec3::X, -lo.x),
        (DVec3::Y, hi.y),
        (-DVec3::Y, -lo.y),
        (DVec3::Z, hi.z),
        (-DVec3::Z, -lo.z),
    ]
}

/// Outward planes of a convex cell with planar faces (oriented away from
/// the centroid, whatever the cell's orientation).
pub fn cell_planes(mesh: &Mesh, c: usize) -> Vec<(DVec3, f64)> {
    let nodes = mesh.cells.nodes(c);
    let centroid: DVec3 = nodes
        .iter()
        .map(|&v| mesh.points[v as usize])
        .sum::<DVec3>()
        / nodes.len() as f64;
    let mut planes = Vec::new();
    mesh.cells.for_each_face(c, |_, f| {
        let p: Vec<DVec3> = f.iter().map(|&v| mesh.points[v as usize]).collect();
        let mut n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        if n.dot(centroid - p[0]) > 0.0 {
            n = -n;
        }
        planes.push((n, n.dot(p[0])));
    });
    planes
}

/// Topology of a mesh.
pub fn topo(mesh: &Mesh) -> Topology {
    Topology::build(&mesh.cells)
}

/// A unit-direction ray.
pub fn ray(o: DVec3, d: DVec3) -> Ray {
    Ray::new(o, d.normalize())
}
