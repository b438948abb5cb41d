//! Region refinement with a caller's predicate (colour accuracy) and the
//! allocation-free steady state of the projector.

mod projection_util;

use std::collections::HashMap;

use projection_util::*;
use zoovr::mesh::CellKind;
use zoovr::projection::{refine, Polyhedron, Projected, Projector};

/// Every edge of the triangulation is shared by two triangles with opposite
/// directions, except silhouette edges (used once): no T-junctions.
fn assert_conforming(out: &Projected) {
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &out.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a, b)).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "edge {a}-{b} used {n} times in one direction");
        if !edges.contains_key(&(b, a)) {
            // A silhouette edge: no vertex of the triangulation lies on it.
            let (pa, pb) = (
                out.vertices[a as usize].pos(),
                out.vertices[b as usize].pos(),
            );
            for v in &out.vertices {
                let q = v.pos();
                if q == pa || q == pb {
                    continue;
                }
                let t = (q - pa).dot(pb - pa) / (pb - pa).length_squared();
                let d = (pa + (pb - pa) * t - q).length();
                assert!(
                    !(t > 1e-9 && t < 1.0 - 1e-9 && d < 1e-9),
                    "T-junction on a silhouette edge"
                );
            }
        }
    }
}

#[test]
fn refine_by_thickness_spread_keeps_values_exact() {
    let mut rng = Rng(2024);
    let mut pr = Projector::new();
    let mut out = Projected::default();
    for kind in [CellKind::Tetra, CellKind::Hexahedron, CellKind::Wedge] {
        for _ in 0..10 {
            let (pts, cells, sc) = random_cell(kind, &mut rng);
            let cam = random_camera(&mut rng, bounds(&pts), true);
            let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
            pr.project(&poly, &cam, &mut out).unwrap();
            let (n0, a0) = (out.triangles.len(), out.triangle_area());
            // A stand-in for "optical depth x colour spread too large":
            // split where the thickness differs by more than 5% of the max.
            let lmax = out.vertices.iter().map(|v| v.l).fold(0.0, f64::max);
            refine(&mut out, 12, |a, b| (a.l - b.l).abs() > 0.05 * lmax);
            assert!(out.triangles.len() > n0);
            assert!((out.triangle_area() - a0).abs() <= 1e-9 * a0);
            assert_eq!(out.triangles.len(), out.triangle_region.len());
            assert_conforming(&out);
            let (el, es, _) = check_values(&out, &poly, &mut rng, 2);
            assert!(el < 1e-9 && es < 1e-9, "{el:e} {es:e}");
            // After three levels, edges still over the threshold are at
            // most 1/8 of the original ones: the spread left is bounded.
            for t in &out.triangles {
                for k in 0..3 {
                    let (a, b) = (
                        out.vertices[t[k] as usize],
                        out.vertices[t[(k + 1) % 3] as usize],
                    );
                    assert!((a.l - b.l).abs() <= lmax / 8.0 + 1e-12);
                }
            }
        }
    }
}

#[test]
fn projector_reuses_its_buffers() {
    // Steady state: after a warm-up on the same pieces, capacities stop
    // growing (no reallocation happens).
    let mut rng = Rng(7);
    let mut set = Vec::new();
    for kind in KINDS {
        for _ in 0..5 {
            let (pts, cells, sc) = random_cell(kind, &mut rng);
            let cam = random_camera(&mut rng, bounds(&pts), false);
            let poly = Polyhedron::from_cell(&cells, 0, &pts, |i| sc[i as usize], &cam).unwrap();
            set.push((poly, cam));
        }
    }
    let mut pr = Projector::new();
    let mut out = Projected::default();
    for (p, c) in &set {
        pr.project(p, c, &mut out).unwrap();
    }
    let caps = |o: &Projected| {
        (
            o.vertices.capacity(),
            o.triangles.capacity(),
            o.region_faces.capacity(),
        )
    };
    let before = caps(&out);
    for (p, c) in &set {
        pr.project(p, c, &mut out).unwrap();
    }
    assert_eq!(before, caps(&out));
}
