//! Projection cost per cell kind (one core): microseconds per projected
//! piece, and regions / vertices per kind; and for regions kept across a
//! values-only frame (`KeptRegions`), the cost of keeping them and of
//! giving them new scalars (`restore_*`, against `project_*`). Fixed seeds; cells are random
//! affine images of the reference shapes, cameras random (orthographic and
//! perspective at the default 30-degree view angle) and fitted to a box 50
//! times the cell's size, as for one cell of a ~50^3 mesh.

use criterion::{black_box, criterion_group, Criterion};
use glam::{DMat3, DVec3};
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::{CellKind, Cells};
use zoovr::projection::{Polyhedron, Projected, Projector};
use zoovr::testdata::Rng;

/// 64 random pieces of `kind` with their cameras.
fn pieces(kind: CellKind, ortho: bool, seed: u64) -> Vec<(Polyhedron, Camera)> {
    let mut rng = Rng(seed);
    let r = kind.reference_corners();
    (0..64)
        .map(|_| {
            let m = loop {
                let m = DMat3::from_cols_array(&std::array::from_fn(|_| rng.range(-1.0, 1.0)));
                if m.determinant().abs() > 0.15 {
                    break m;
                }
            };
            let pts: Vec<DVec3> = r.iter().map(|&p| m * p).collect();
            let mut cells = Cells::default();
            cells.push(kind, &(0..r.len() as u32).collect::<Vec<_>>());
            let mut lo = DVec3::splat(f64::INFINITY);
            let mut hi = -lo;
            for p in &pts {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            let c = (lo + hi) * 0.5;
            let e = (hi - lo) * 25.0;
            let cam = Camera::fit(
                [
                    c.x - e.x,
                    c.x + e.x,
                    c.y - e.y,
                    c.y + e.y,
                    c.z - e.z,
                    c.z + e.z,
                ],
                &CameraParams {
                    azimuth: rng.range(-180.0, 180.0),
                    elevation: rng.range(-80.0, 80.0),
                    ortho,
                    ..Default::default()
                },
            );
            let s: Vec<f64> = (0..r.len()).map(|_| rng.f64()).collect();
            let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam).unwrap();
            (poly, cam)
        })
        .collect()
}

const KINDS: [(CellKind, &str); 6] = [
    (CellKind::Tetra, "tet"),
    (CellKind::Pyramid, "pyramid"),
    (CellKind::Wedge, "wedge"),
    (CellKind::Hexahedron, "hex"),
    (CellKind::PentagonalPrism, "penta_prism"),
    (CellKind::HexagonalPrism, "hexa_prism"),
];

fn bench(c: &mut Criterion) {
    let mut pr = Projector::new();
    let mut out = Projected::default();
    for (kind, name) in KINDS {
        for ortho in [true, false] {
            let set = pieces(kind, ortho, 42);
            let (mut regions, mut verts, mut tris) = (0, 0, 0);
            for (p, cam) in &set {
                pr.project(p, cam, &mut out).unwrap();
                regions += out.regions.len();
                verts += out.vertices.len();
                tris += out.triangles.len();
            }
            let n = set.len() as f64;
            let mode = if ortho { "ortho" } else { "persp" };
            println!(
                "{name} ({mode}): {:.2} regions, {:.2} vertices, {:.2} triangles per piece",
                regions as f64 / n,
                verts as f64 / n,
                tris as f64 / n
            );
            c.bench_function(&format!("project_{name}_{mode}"), |b| {
                let mut k = 0;
                b.iter(|| {
                    let (p, cam) = &set[k % set.len()];
                    k += 1;
                    pr.project(black_box(p), cam, &mut out).unwrap();
                    black_box(out.triangles.len())
                })
            });
            // Regions kept for a values-only frame: making them (projecting
            // and keeping), and giving them the next frame's scalars.
            let kept: Vec<_> = set
                .iter()
                .map(|(p, cam)| pr.project_with(p, cam, None, true, &mut out).unwrap())
                .collect();
            let next: Vec<Polyhedron> = set
                .iter()
                .map(|(p, _)| {
                    let mut q = p.clone();
                    for s in &mut q.scalars {
                        *s = 1.0 - 0.5 * *s;
                    }
                    q
                })
                .collect();
            c.bench_function(&format!("project_keep_{name}_{mode}"), |b| {
                let mut k = 0;
                b.iter(|| {
                    let (p, cam) = &set[k % set.len()];
                    k += 1;
                    black_box(
                        pr.project_with(black_box(p), cam, None, true, &mut out)
                            .unwrap(),
                    )
                })
            });
            c.bench_function(&format!("restore_{name}_{mode}"), |b| {
                let mut k = 0;
                b.iter(|| {
                    let i = k % set.len();
                    k += 1;
                    let kept = kept[i].as_ref();
                    pr.project_with(black_box(&next[i]), &set[i].1, kept, false, &mut out)
                        .unwrap();
                    black_box(out.triangles.len())
                })
            });
        }
    }
}

/// `PROJECTION_ITERS=n [PROJECTION_KIND=hex_ortho]`: project every set (or
/// the one named) `n` times over and exit, without criterion: a fixed
/// amount of work for instruction counts (`valgrind --tool=callgrind`) and
/// profiles, which a machine shared with other jobs cannot time reliably.
fn fixed_iterations(n: usize) {
    let kind = std::env::var("PROJECTION_KIND").ok();
    let mut pr = Projector::new();
    let mut out = Projected::default();
    let mut tris = 0;
    for (k, name) in KINDS {
        for ortho in [true, false] {
            let mode = if ortho { "ortho" } else { "persp" };
            if kind
                .as_ref()
                .is_some_and(|x| *x != format!("{name}_{mode}"))
            {
                continue;
            }
            let set = pieces(k, ortho, 42);
            for _ in 0..n {
                for (p, cam) in &set {
                    pr.project(black_box(p), cam, &mut out).unwrap();
                    tris += out.triangles.len();
                }
            }
        }
    }
    println!("{tris} triangles");
}

criterion_group!(benches, bench);

fn main() {
    if let Some(n) = std::env::var("PROJECTION_ITERS")
        .ok()
        .and_then(|n| n.parse().ok())
    {
        fixed_iterations(n);
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
