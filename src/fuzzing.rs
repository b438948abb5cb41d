//! The bodies of the fuzz targets (`fuzz/fuzz_targets/`), kept in the
//! library so that every input a fuzzer ever crashed on is replayed by
//! `cargo test` (`tests/fuzz_regressions.rs` runs `fuzz/regressions/TARGET/*`
//! through these functions). Each function takes arbitrary bytes and panics
//! only when an invariant is broken: a reader returns a mesh or an error,
//! projection of a convex piece gives a consistent subdivision, a sort passes
//! the brute-force validator. Time-capped runs: `.ci/fuzz`.

use std::path::Path;
use std::sync::Arc;

use glam::{DMat3, DVec3};

use crate::camera::{Camera, CameraParams};
use crate::integrate::{self, RayMaterial};
use crate::io::collection::{parse_pvd, parse_series_json};
use crate::io::{self, xml, Format};
use crate::mesh::topology::Topology;
use crate::mesh::{CellKind, Cells};
use crate::projection::{slice_tet, Polyhedron, Projected, ProjectionError, Projector};
use crate::tf::TransferFunction;
use crate::visibility::synth::{grid, holed_grid, GridSpec};
use crate::visibility::{sample_pixels, validate, Sorter, SplitPolicy};

/// A fuzz target's body.
pub type Target = fn(&[u8]);

/// The targets by name, as `fuzz/Cargo.toml` lists them.
pub const TARGETS: &[(&str, Target)] = &[
    ("legacy", legacy),
    ("xml", xml),
    ("collection", collection),
    ("plot3d", plot3d),
    ("tf_json", tf_json),
    ("projection", projection),
    ("visibility", visibility),
    ("cycles", cycles),
];

/// Legacy VTK reader: a mesh that comes back only references existing points.
pub fn legacy(data: &[u8]) {
    let path = Path::new("fuzz.vtk");
    if let Ok(mesh) = io::legacy::read_bytes(path, data) {
        mesh.sanity_check()
            .expect("a mesh a reader returns is well formed");
        let n = mesh.points.len();
        assert!(mesh.cells.conn.iter().all(|&p| (p as usize) < n));
        let c = &mesh.cells;
        assert!(c.offsets.len() == c.len() + 1 || (c.is_empty() && c.offsets.is_empty()));
    }
}

/// VTK XML readers (each dataset format): a mesh that comes back is
/// structurally valid.
pub fn xml(data: &[u8]) {
    for format in [
        Format::XmlUnstructured,
        Format::XmlStructured,
        Format::XmlImage,
    ] {
        if let Ok(m) = xml::read_bytes(Path::new("fuzz.vtu"), data, format) {
            m.sanity_check()
                .expect("a mesh a reader returns is well formed");
            for c in 0..m.cells.len() {
                assert!(m
                    .cells
                    .nodes(c)
                    .iter()
                    .all(|&p| (p as usize) < m.points.len()));
            }
            for a in &m.point_data {
                assert_eq!(a.tuples(), m.points.len());
            }
            for a in &m.cell_data {
                assert_eq!(a.tuples(), m.cells.len());
            }
        }
    }
}

/// `.pvd` and `.series` collections: a list that comes back is non-empty,
/// sorted by time and names existing files (entries resolve next to the
/// project's `meshes/series/`, so valid step files are reachable).
pub fn collection(data: &[u8]) {
    let dir = crate::testdata::mesh_file("series");
    for steps in [
        parse_pvd(&dir.join("fuzz.pvd"), data),
        parse_series_json(&dir.join("fuzz.vtu.series"), data),
    ]
    .into_iter()
    .flatten()
    {
        assert!(!steps.is_empty());
        assert!(steps.windows(2).all(|w| w[0].time <= w[1].time));
        assert!(steps.iter().all(|s| s.time.is_finite() && s.path.exists()));
    }
}

/// PLOT3D: the input is split into a grid and a q file at a position given
/// by its first byte.
pub fn plot3d(data: &[u8]) {
    let Some((&cut, rest)) = data.split_first() else {
        return;
    };
    let path = Path::new("fuzz.xyz");
    let _ = io::plot3d::looks_like_grid(rest);
    let (grid, q) = if cut == 0 {
        (rest, None)
    } else {
        let at = (cut as usize * rest.len()) / 255;
        let (g, q) = rest.split_at(at.min(rest.len()));
        (g, Some((Path::new("fuzz.q"), q)))
    };
    if let Ok(mesh) = io::plot3d::read_bytes(path, grid, q) {
        mesh.sanity_check()
            .expect("a mesh a reader returns is well formed");
        let n = mesh.points.len();
        assert!(mesh.cells.conn.iter().all(|&p| (p as usize) < n));
    }
}

/// Transfer-function files: a loaded TF integrates to finite values and
/// round-trips through the project format.
pub fn tf_json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(tf) = TransferFunction::from_json_str(text, 0.5) else {
        return;
    };
    let (lo, hi) = tf.scalar_range();
    let mid = 0.5 * (lo + hi);
    for (l, sf, sb) in [
        (1.0, lo, hi),
        (1e-9, mid, mid),
        (1e6, hi, lo),
        (0.5, lo - 1.0, hi + 1.0),
    ] {
        let v = tf.segment(l, sf, sb);
        assert!(v.alpha.is_finite() && (0.0..=1.0).contains(&v.alpha));
        assert!(v.color.iter().all(|c| c.is_finite()));
        let vv = integrate::vertex_values(&tf, l, sf, sb);
        assert!(vv.glow.iter().all(|c| c.is_finite()));
    }
    // Round trip through the project format.
    let again = TransferFunction::from_json_str(&tf.to_json(), 0.5).expect("own output loads");
    assert_eq!(again.nodes(), tf.nodes());
}

fn quantised(data: &[u8], i: usize) -> f64 {
    // Quantised to 1/16 so exact degeneracies (coincident and collinear
    // projections, edge-on faces) are frequent.
    let b = data.get(i).copied().unwrap_or(0) as i8;
    b as f64 / 16.0
}

/// Random convex polyhedra (affine images of the zoo cells, or breakpoint
/// slabs of a tet) under random views: a consistent subdivision after every
/// insertion; the renderer's projector (fast path where it applies) covers
/// the same area.
pub fn projection(data: &[u8]) {
    if data.len() < 20 {
        return;
    }
    let kinds = CellKind::FIXED;
    let kind = kinds[data[0] as usize % kinds.len()];
    let m = DMat3::from_cols_array(&std::array::from_fn(|k| quantised(data, 1 + k)));
    let params = CameraParams {
        width: 64,
        height: 48,
        azimuth: quantised(data, 10) * 11.25,
        elevation: quantised(data, 11) * 11.25,
        roll: quantised(data, 12) * 11.25,
        ortho: data[13] & 1 == 0,
        ..Default::default()
    };
    let reference = kind.reference_corners();
    let pts: Vec<DVec3> = reference.iter().map(|&p| m * p).collect();
    if m.determinant().abs() < 1e-3 {
        return;
    }
    let mut cells = Cells::default();
    cells.push(kind, &(0..pts.len() as u32).collect::<Vec<_>>());
    let cam = Camera::fit([-8.0, 8.0, -8.0, 8.0, -8.0, 8.0], &params);
    let s: Vec<f64> = (0..pts.len())
        .map(|i| quantised(data, 14 + i % 6))
        .collect();
    let Ok(poly) = Polyhedron::from_cell(&cells, 0, &pts, |i| s[i as usize], &cam) else {
        return;
    };
    let mut pieces = vec![poly];
    if kind == CellKind::Tetra {
        let v: [DVec3; 4] = std::array::from_fn(|i| pieces[0].points[i]);
        let sc: [f64; 4] = std::array::from_fn(|i| pieces[0].scalars[i]);
        pieces = slice_tet(v, sc, &[0.0, 0.5], &cam);
    }
    let mut pr = Projector::new();
    pr.check_each_insertion = true;
    // The renderer's projector: the fast path for pieces in general position
    // (`check_each_insertion` forces the general path above).
    let mut fast = Projector::new();
    let mut fast_out = Projected::default();
    let mut out = Projected::default();
    for p in &pieces {
        let fast_result = fast.project(p, &cam, &mut fast_out);
        if let Err(e @ (ProjectionError::Topology(_) | ProjectionError::UnassignedRegion)) =
            &fast_result
        {
            panic!("{kind:?} (fast path): {e}")
        }
        match pr.project(p, &cam, &mut out) {
            Ok(()) => {
                pr.arrangement().sanity_check().expect("sanity_check");
                let area = out.region_area();
                if fast_result.is_ok() {
                    let fa = fast_out.region_area();
                    assert!(
                        (fa - area).abs() <= 1e-9 * area.max(1.0),
                        "{kind:?}: fast path regions {fa} vs general {area}"
                    );
                }
                assert!(area.is_finite() && area >= 0.0);
                // Orthographic, whole cell (nothing clipped): the regions
                // tile the silhouette, the hull of the projected corners.
                if cam.ortho && kind != CellKind::Tetra {
                    let px: Vec<(f64, f64)> = pts
                        .iter()
                        .filter_map(|&p| cam.project(p).map(|(x, y, _)| (x, y)))
                        .collect();
                    let hull = hull_area(&px);
                    assert!(
                        (area - hull).abs() <= 1e-9 * hull.max(1.0),
                        "{kind:?}: regions {area} vs silhouette {hull}"
                    );
                }
            }
            // A convex piece always gets a consistent subdivision in which
            // every region has one front and one back triangle.
            Err(e @ (ProjectionError::Topology(_) | ProjectionError::UnassignedRegion)) => {
                panic!("{kind:?}: {e}")
            }
            // Clipping by the near plane may leave nothing to draw.
            Err(_) => {}
        }
    }
}

/// A jittered (optionally holed) grid and views from the bytes: the split
/// bookkeeping passes `sanity_check` and the order passes the validator at
/// every pixel centre.
pub fn visibility(data: &[u8]) {
    if data.len() < 12 {
        return;
    }
    let b = |i: usize| data[i] as f64 / 255.0;
    let spec = GridSpec {
        dims: [
            2 + data[0] as usize % 4,
            2 + data[1] as usize % 4,
            2 + data[2] as usize % 3,
        ],
        jitter: 0.24 * b(3),
        seed: u64::from_le_bytes([data[4], data[5], data[6], data[7], 1, 2, 3, 4]),
        planar_boundary: data[8] & 1 == 0,
    };
    let mesh = if data[8] & 2 != 0 {
        holed_grid(&spec)
    } else {
        grid(&spec, |_, _, _| true)
    };
    if mesh.cells.is_empty() {
        return;
    }
    let mesh = Arc::new(mesh);
    let topo = Topology::build(&mesh.cells);
    let mut sorter = Sorter::new(mesh.clone(), topo);
    let policy = SplitPolicy {
        all: data[8] & 4 != 0,
        ..Default::default()
    };
    for view in data[9..].chunks(3).take(3) {
        if view.len() < 3 {
            break;
        }
        let p = CameraParams {
            width: 24,
            height: 24,
            azimuth: view[0] as f64 * 360.0 / 255.0,
            elevation: view[1] as f64 * 178.0 / 255.0 - 89.0,
            ortho: view[2] & 1 != 0,
            zoom: 1.0 + (view[2] >> 1) as f64 / 64.0,
            ..Default::default()
        };
        let cam = Camera::fit(mesh.bounds(), &p);
        let order = sorter.order(&cam, &policy).expect("valid input must sort");
        sorter.sanity_check().expect("sanity");
        let v = validate(&mesh, &order, &cam, &sample_pixels(&cam, usize::MAX, 0));
        assert!(v.ok(), "{} violations: {:?}", v.count, v.examples.first());
    }
}

/// Plane cuts of a group of tets (`visibility::bsp`): 2 to 6 tets with
/// corners on a 1/16 lattice (coincident points, shared planes and
/// degenerate tets are common) and an eye point or direction. When the cuts
/// give an order, every fragment must be a closed surface inside its tet,
/// and the fragments of a tet must fill it.
pub fn cycles(data: &[u8]) {
    use crate::numeric::predicates::Side;
    use crate::visibility::bsp::{order_group, EyeSide};
    use crate::visibility::Piece;
    struct Eye(DVec3, bool);
    impl EyeSide for Eye {
        fn side(&self, a: DVec3, b: DVec3, c: DVec3) -> Side {
            if self.1 {
                crate::numeric::predicates::orient_dir(a, b, c, -self.0)
            } else {
                crate::numeric::predicates::orient3d(a, b, c, self.0)
            }
        }
    }
    let Some((&head, rest)) = data.split_first() else {
        return;
    };
    let n = 2 + head as usize % 5;
    if rest.len() < 12 * n + 4 {
        return;
    }
    let c = |b: u8| b as f64 / 16.0;
    let points: Vec<DVec3> = rest[..12 * n]
        .chunks(3)
        .map(|b| DVec3::new(c(b[0]), c(b[1]), c(b[2])))
        .collect();
    let e = &rest[12 * n..];
    let eye = Eye(
        DVec3::new(c(e[0]) - 8.0, c(e[1]) - 8.0, c(e[2]) - 8.0),
        e[3] & 1 == 0,
    );
    if eye.1 && eye.0 == DVec3::ZERO {
        return;
    }
    let pieces: Vec<Piece> = (0..n as u32)
        .map(|k| Piece::Tet {
            cell: k,
            tet: [4 * k, 4 * k + 1, 4 * k + 2, 4 * k + 3],
        })
        .collect();
    let Some(frags) = order_group(&pieces, &points, &eye) else {
        return;
    };
    let mut vol = vec![0.0; n];
    for (src, f) in &frags {
        let k = *src;
        let q = [0, 1, 2, 3].map(|i| points[4 * k + i]);
        let x = f.positions(&q);
        for w in &f.weights {
            let sum: f64 = w.iter().sum();
            assert!((sum - 1.0).abs() < 1e-9, "weights {w:?}");
            assert!(w.iter().all(|&v| v > -1e-9), "outside its tet: {w:?}");
        }
        let o = x[0];
        for t in &f.triangles {
            let [a, b, cc] = t.map(|i| x[i as usize] - o);
            vol[k] += a.dot(b.cross(cc)) / 6.0;
        }
    }
    for k in 0..n {
        let q = [0, 1, 2, 3].map(|i| points[4 * k + i]);
        let want = ((q[1] - q[0]).dot((q[2] - q[0]).cross(q[3] - q[0])) / 6.0).abs();
        let scale = 16.0f64.powi(3);
        assert!(
            (vol[k] - want).abs() <= 1e-9 * scale,
            "tet {k}: fragments hold {} of {want}",
            vol[k]
        );
    }
}

/// Area of the convex hull of `pts` (Andrew's monotone chain).
fn hull_area(pts: &[(f64, f64)]) -> f64 {
    let mut p: Vec<(f64, f64)> = pts.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    p.dedup();
    if p.len() < 3 {
        return 0.0;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let n = hull.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            a.0 * b.1 - a.1 * b.0
        })
        .sum::<f64>()
        .abs()
}
