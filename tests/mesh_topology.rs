//! Topology, components, merge, quality and hull on generated meshes, each
//! checked against an independent computation (closed-form counts, a
//! brute-force hash-map face matcher, exact volumes).

use std::collections::HashMap;

use glam::DVec3;
use zoovr::generate::{
    ring_grid, single_cell, warped_hex_grid, warped_hex_grid_dims, zoo_grid, Warp,
};
use zoovr::mesh::components::connected_components;
use zoovr::mesh::hull::convex_hull_volume;
use zoovr::mesh::merge::merge_coincident_points;
use zoovr::mesh::orient::flip_cell;
use zoovr::mesh::quality::{cell_volumes, orientations, quality_counts, Orientation};
use zoovr::mesh::report::MeshReport;
use zoovr::mesh::topology::Topology;
use zoovr::mesh::{CellKind, Cells, Mesh, NONE};

const STRAIGHT: Warp = Warp {
    amplitude: 0.0,
    seed: 0,
};

/// Brute force: sorted vertex set -> the cells listing it.
fn brute_faces(cells: &Cells) -> HashMap<Vec<u32>, Vec<u32>> {
    let mut m: HashMap<Vec<u32>, Vec<u32>> = HashMap::new();
    for c in 0..cells.len() {
        cells.for_each_face(c, |_, f| {
            let mut k = f.to_vec();
            k.sort_unstable();
            m.entry(k).or_default().push(c as u32);
        });
    }
    m
}

fn assert_matches_brute_force(cells: &Cells) {
    let t = Topology::build(cells);
    t.sanity_check(cells).unwrap();
    let brute = brute_faces(cells);
    let manifold: usize = brute.values().map(|v| v.len().saturating_sub(2)).sum();
    assert_eq!(t.nonmanifold_faces, manifold);
    assert_eq!(t.face_count(), brute.len() + manifold);
    for f in 0..t.face_count() {
        let mut k = t.face(f).to_vec();
        k.sort_unstable();
        let owners = &brute[&k];
        let [a, b] = t.face_cells[f];
        assert!(owners.contains(&a));
        if b != NONE {
            assert!(owners.contains(&b) && a != b);
        }
    }
}

#[test]
fn grid_face_counts_match_closed_forms() {
    for (nx, ny, nz) in [(1, 1, 1), (3, 2, 4), (5, 5, 5)] {
        let m = warped_hex_grid_dims([nx, ny, nz], &Warp::default());
        let t = Topology::build(&m.cells);
        let faces = (nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * (nz + 1);
        let boundary = 2 * (nx * ny + ny * nz + nx * nz);
        assert_eq!(t.face_count(), faces);
        assert_eq!(t.boundary_face_count(), boundary);
        assert_eq!(t.nonmanifold_faces, 0);
        t.sanity_check(&m.cells).unwrap();
        assert_matches_brute_force(&m.cells);
        // neighbour across +x face of cell (i, j, k) is (i + 1, j, k)
        for c in 0..m.cells.len() {
            let f = t.faces_of(c)[1] as usize;
            let want = if (c % nx) + 1 < nx {
                (c + 1) as u32
            } else {
                NONE
            };
            assert_eq!(t.neighbour(f, c as u32), want);
        }
    }
}

#[test]
fn zoo_and_mixed_meshes_match_brute_force() {
    assert_matches_brute_force(&zoo_grid(4, &Warp::default()).cells);
    assert_matches_brute_force(&ring_grid(6, &Warp::default()).cells);
    // non-manifold: three tets on one triangle, a cell listing a face twice
    let mut cells = Cells::default();
    cells.push(CellKind::Tetra, &[0, 1, 2, 3]);
    cells.push(CellKind::Tetra, &[0, 2, 1, 4]);
    cells.push(CellKind::Tetra, &[0, 2, 1, 5]);
    cells.push(CellKind::Tetra, &[1, 0, 2, 6]);
    assert_matches_brute_force(&cells);
}

#[test]
fn components_of_disjoint_and_touching_grids() {
    let mut m = warped_hex_grid(2, &STRAIGHT);
    let shift = m.points.len() as u32;
    let other = warped_hex_grid(2, &STRAIGHT);
    m.points
        .extend(other.points.iter().map(|p| *p + DVec3::new(1.0, 0.0, 0.0)));
    for c in 0..other.cells.len() {
        let nodes: Vec<u32> = other.cells.nodes(c).iter().map(|&i| i + shift).collect();
        m.cells.push(CellKind::Hexahedron, &nodes);
    }
    let t = Topology::build(&m.cells);
    let comp = connected_components(&t);
    assert_eq!(comp.count, 2);
    assert!(comp.labels[..8].iter().all(|&l| l == 0));
    assert!(comp.labels[8..].iter().all(|&l| l == 1));
    // the two grids touch along x = 1 with duplicated points: merging joins them
    assert_eq!(merge_coincident_points(&mut m), 9);
    let t = Topology::build(&m.cells);
    t.sanity_check(&m.cells).unwrap();
    assert_eq!(connected_components(&t).count, 1);
    assert_eq!(t.boundary_face_count(), 2 * (4 * 2 + 2 * 2 + 4 * 2));
    // the merged point takes the smallest index of its group
    for &i in &m.cells.conn {
        let p = m.points[i as usize];
        assert!(m.points[..i as usize].iter().all(|q| *q != p));
    }
}

#[test]
fn volumes_orientation_and_nonplanarity() {
    // straight n^3 grid: unit total volume, all positive, all planar
    let m = warped_hex_grid(4, &STRAIGHT);
    let v = cell_volumes(&m);
    assert!(v.iter().all(|&x| (x - 1.0 / 64.0).abs() < 1e-15));
    let o = orientations(&m, &v);
    let q = quality_counts(&m, &v, &o);
    assert_eq!((q.inverted, q.degenerate, q.nonplanar_faces), (0, 0, 0));
    assert!((q.total_volume - 1.0).abs() < 1e-12);
    // the warp keeps total volume within the unit cube's +-... and bends faces
    let w = warped_hex_grid(4, &Warp::default());
    let vw = cell_volumes(&w);
    let ow = orientations(&w, &vw);
    assert!(ow.iter().all(|&o| o == Orientation::Positive));
    let qw = quality_counts(&w, &vw, &ow);
    assert!(qw.nonplanar_faces > 100, "{}", qw.nonplanar_faces);
    // per cell face: 6 * 64 quads in all
    assert!(qw.nonplanar_faces <= 6 * 64);
    // single cells of every kind are positive with the expected volume
    let want = [
        (CellKind::Tetra, 1.0 / 6.0),
        (CellKind::Pyramid, 1.0 / 3.0),
        (CellKind::Wedge, 0.5),
        (CellKind::Hexahedron, 1.0),
        // regular n-gon of radius 0.5: n/2 r^2 sin(2pi/n)
        (
            CellKind::PentagonalPrism,
            2.5 * 0.25 * (std::f64::consts::TAU / 5.0).sin(),
        ),
        (
            CellKind::HexagonalPrism,
            3.0 * 0.25 * (std::f64::consts::TAU / 6.0).sin(),
        ),
        (CellKind::Polyhedron, 1.0 + 0.6 / 3.0),
    ];
    for (kind, vol) in want {
        let m = single_cell(kind);
        let v = cell_volumes(&m)[0];
        assert!((v - vol).abs() < 1e-14, "{kind:?}: {v} vs {vol}");
        let r = MeshReport::compute(&m);
        assert_eq!(r.boundary_faces, m.cells.face_count(0), "{kind:?}");
        assert!((r.convexity.unwrap() - 1.0).abs() < 1e-12, "{kind:?}");
    }
}

#[test]
fn report_counts_inverted_degenerate_and_repeated_cells() {
    let mut m = warped_hex_grid(3, &Warp::default());
    flip_cell(&mut m.cells, 4);
    flip_cell(&mut m.cells, 13);
    // a flat hexahedron (top face on the bottom face) and a repeated index
    let base = m.points.len() as u32;
    for z in [0.0, 0.0] {
        for (x, y) in [(5., 5.), (6., 5.), (6., 6.), (5., 6.)] {
            m.points.push(DVec3::new(x, y, z));
        }
    }
    let flat: Vec<u32> = (base..base + 8).collect();
    m.cells.push(CellKind::Hexahedron, &flat);
    m.cells.push(CellKind::Tetra, &[0, 1, 1, 5]);
    let r = MeshReport::compute(&m);
    assert_eq!(r.inverted_cells, 2);
    assert_eq!(r.degenerate_cells, 2);
    assert_eq!(r.repeated_index_cells, 1);
    assert_eq!(r.inverted_tets, 0);
    assert_eq!(r.components, 3);
}

#[test]
fn hull_volume_of_ring_and_warped_grid() {
    let ring = ring_grid(9, &STRAIGHT);
    let r = MeshReport::compute(&ring);
    // 9x9x3 grid of unit cube scaled to 1x1x1, minus the 3x3 hole
    assert!((r.convexity.unwrap() - 72.0 / 81.0).abs() < 1e-12, "{r:?}");
    assert_eq!(r.components, 1);
    // hull of boundary points = hull of all points
    let w = warped_hex_grid(6, &Warp::default());
    let all = convex_hull_volume(&w.points, None);
    let rep = MeshReport::compute(&w);
    assert!((rep.hull_volume - all).abs() < 1e-12 * all);
    assert!(rep.volume <= all + 1e-12);
}

#[test]
fn empty_mesh_reports_zeroes() {
    let r = MeshReport::compute(&Mesh::default());
    assert_eq!((r.cells, r.faces, r.components, r.tets), (0, 0, 0, 0));
    assert_eq!(r.convexity, None);
}

/// 1M hexahedra: topology well under 3 s in a release build (run with
/// `cargo test --release --test mesh_topology -- --ignored`).
#[test]
#[ignore]
fn million_hexes_connect_quickly() {
    let m = warped_hex_grid(100, &Warp::default());
    let t0 = std::time::Instant::now();
    let t = Topology::build(&m.cells);
    let dt = t0.elapsed();
    eprintln!("topology of 1M hexes: {dt:?}");
    assert_eq!(t.boundary_face_count(), 6 * 100 * 100);
    assert_eq!(t.face_count(), 3 * 100 * 100 * 101);
    let t1 = std::time::Instant::now();
    let r = MeshReport::compute_with(&m, &t);
    eprintln!("report of 1M hexes: {:?}: {r:?}", t1.elapsed());
    assert_eq!(r.inverted_tets, 0);
}

/// `Mesh::sanity_check` accepts generated meshes and names each kind of
/// broken structure.
#[test]
fn mesh_sanity_check_catches_broken_structure() {
    let good = zoovr::generate::zoo_grid(3, &zoovr::generate::Warp::default());
    good.sanity_check().unwrap();
    type Breaker = Box<dyn Fn(&mut zoovr::mesh::Mesh)>;
    let breakers: Vec<(&str, Breaker)> = vec![
        ("node id", Box::new(|m| m.cells.conn[3] = 1 << 30)),
        (
            "offsets",
            Box::new(|m| m.cells.offsets.pop().map(|_| ()).unwrap()),
        ),
        ("not finite", Box::new(|m| m.points[2].y = f64::NAN)),
        ("tuples", Box::new(|m| m.points.push(glam::DVec3::ZERO))),
        (
            "nodes, expected",
            Box::new(|m| m.cells.kinds[0] = zoovr::mesh::CellKind::Pyramid),
        ),
    ];
    for (words, f) in breakers {
        let mut m = good.clone();
        f(&mut m);
        let e = m.sanity_check().expect_err(words);
        assert!(e.contains(words), "{words}: {e}");
    }
}
