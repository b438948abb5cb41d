//! Consistent tetrahedralisation (smallest-vertex rule) on every cell kind
//! and on generated meshes with shuffled point ids:
//! - tet volumes sum to the cell volume computed from the faces;
//! - every tet of a convex, positively oriented cell is positive;
//! - the tets form a conforming tetrahedralisation (shared quads get the
//!   same diagonal from both sides, interior triangles are used by exactly
//!   two tets, boundary triangles by one) — `check_tetrahedralisation`;
//! - after orientation repair, generated meshes have no non-positive tet;
//! - a flipped cell yields the same tets with the opposite orientation.

use glam::DVec3;
use zoovr::generate::{warped_hex_grid, zoo_grid, Warp};
use zoovr::mesh::orient::{flip_cell, repair_orientation};
use zoovr::mesh::quality::cell_volume;
use zoovr::mesh::report::MeshReport;
use zoovr::mesh::tetra::{check_tetrahedralisation, tetrahedralize, tetrahedralize_cell};
use zoovr::mesh::topology::Topology;
use zoovr::mesh::{CellKind, Cells, Mesh};

fn tet_volume(p: &[DVec3], t: [u32; 4]) -> f64 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    (b - a).cross(c - a).dot(d - a) / 6.0
}

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            let j = (self.next() % (i as u64 + 1)) as usize;
            v.swap(i, j);
        }
    }
}

/// Renumbers the points of `mesh` by a random permutation (new = perm[old]).
fn shuffle_ids(mesh: &mut Mesh, rng: &mut Rng) {
    let n = mesh.points.len();
    let mut perm: Vec<u32> = (0..n as u32).collect();
    rng.shuffle(&mut perm);
    let mut pts = vec![DVec3::ZERO; n];
    for (old, &new) in perm.iter().enumerate() {
        pts[new as usize] = mesh.points[old];
    }
    mesh.points = pts;
    for i in &mut mesh.cells.conn {
        *i = perm[*i as usize];
    }
    for f in mesh.cells.poly_faces.values_mut() {
        for i in f.iter_mut().flatten() {
            *i = perm[*i as usize];
        }
    }
    mesh.point_data.clear();
}

/// A regular `n`-gon prism (radius 1, height 1) as points, positively
/// oriented for the VTK prism face tables.
fn ngon_prism(n: usize) -> Vec<DVec3> {
    let mut p = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = i as f64 * std::f64::consts::TAU / n as f64;
            p.push(DVec3::new(a.cos(), a.sin(), z));
        }
    }
    p
}

/// A test cell: kind, points, and the faces of a general polyhedron.
type TestCell = (CellKind, Vec<DVec3>, Option<Vec<Vec<u32>>>);

/// One convex cell of every kind.
fn zoo_cells() -> Vec<TestCell> {
    let cube: Vec<DVec3> = (0..8)
        .map(|i| {
            let (x, y) = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)][i % 4];
            DVec3::new(x, y, (i / 4) as f64)
        })
        .collect();
    // a slightly irregular (still convex) hexahedron
    let mut hex = cube.clone();
    hex[6] += DVec3::new(0.2, 0.1, 0.15);
    hex[1] += DVec3::new(0.1, -0.1, 0.0);
    let tet = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    let pyr = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(1., 1., 0.),
        DVec3::Y,
        DVec3::new(0.4, 0.5, 0.9),
    ];
    // VTK parametric wedge: the first triangle's normal points at the second
    let wedge = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::new(1., 0., 1.),
        DVec3::new(0., 1., 1.),
    ];
    // Polyhedra: a cube (6 quads), an octahedron, a hexagonal prism.
    let cube_faces: Vec<Vec<u32>> = CellKind::Hexahedron
        .faces()
        .iter()
        .map(|f| f.iter().map(|&l| l as u32).collect())
        .collect();
    let octa = vec![
        DVec3::X,
        DVec3::Y,
        -DVec3::X,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let mut octa_faces = Vec::new();
    for i in 0..4u32 {
        let j = (i + 1) % 4;
        octa_faces.push(vec![i, j, 4]);
        octa_faces.push(vec![j, i, 5]);
    }
    let hp_faces: Vec<Vec<u32>> = CellKind::HexagonalPrism
        .faces()
        .iter()
        .map(|f| f.iter().map(|&l| l as u32).collect())
        .collect();
    vec![
        (CellKind::Tetra, tet, None),
        (CellKind::Pyramid, pyr, None),
        (CellKind::Wedge, wedge, None),
        (CellKind::Hexahedron, cube.clone(), None),
        (CellKind::Hexahedron, hex, None),
        (CellKind::PentagonalPrism, ngon_prism(5), None),
        (CellKind::HexagonalPrism, ngon_prism(6), None),
        (CellKind::Polyhedron, cube, Some(cube_faces)),
        (CellKind::Polyhedron, octa, Some(octa_faces)),
        (CellKind::Polyhedron, ngon_prism(6), Some(hp_faces)),
    ]
}

#[test]
fn every_kind_and_labelling_sums_to_the_cell_volume_with_positive_tets() {
    let mut rng = Rng(0x1234_5678);
    for (kind, pts, faces) in zoo_cells() {
        let n = pts.len();
        let mut counts = std::collections::BTreeSet::new();
        for _ in 0..200 {
            let mut perm: Vec<u32> = (0..n as u32).collect();
            rng.shuffle(&mut perm);
            let mut p = vec![DVec3::ZERO; n];
            for i in 0..n {
                p[perm[i] as usize] = pts[i];
            }
            let mut cells = Cells::default();
            match &faces {
                Some(fs) => cells.push_polyhedron(
                    fs.iter()
                        .map(|f| f.iter().map(|&l| perm[l as usize]).collect())
                        .collect(),
                ),
                None => cells.push(kind, &perm),
            }
            let vol = cell_volume(&cells, &p, 0);
            assert!(vol > 0.1, "{kind:?}: cell volume {vol}");
            let mut tets = Vec::new();
            tetrahedralize_cell(&cells, 0, &mut tets);
            counts.insert(tets.len());
            let sum: f64 = tets.iter().map(|&t| tet_volume(&p, t)).sum();
            assert!(
                (sum - vol).abs() < 1e-12 * vol.max(1.0),
                "{kind:?}: {sum} vs {vol}"
            );
            for &t in &tets {
                assert!(tet_volume(&p, t) > 1e-9, "{kind:?}: tet {t:?} of {perm:?}");
            }
            let topo = Topology::build(&cells);
            check_tetrahedralisation(&topo, &tets).unwrap();
        }
        // the paper's counts: pyramid 2, wedge 3, hexahedron 5 or 6
        let want: &[usize] = match kind {
            CellKind::Tetra => &[1],
            CellKind::Pyramid => &[2],
            CellKind::Wedge => &[3],
            CellKind::Hexahedron => &[5, 6],
            _ => &[],
        };
        if !want.is_empty() {
            assert_eq!(counts.iter().copied().collect::<Vec<_>>(), want, "{kind:?}");
        }
    }
}

fn assert_conforming_and_positive(mesh: &Mesh, what: &str) {
    let topo = Topology::build(&mesh.cells);
    topo.sanity_check(&mesh.cells).unwrap();
    let (tets, offs) = tetrahedralize(&mesh.cells);
    check_tetrahedralisation(&topo, &tets).unwrap_or_else(|e| panic!("{what}: {e}"));
    for c in 0..mesh.cells.len() {
        let v = cell_volume(&mesh.cells, &mesh.points, c);
        let ts = &tets[offs[c] as usize..offs[c + 1] as usize];
        let sum: f64 = ts.iter().map(|&t| tet_volume(&mesh.points, t)).sum();
        assert!(
            (sum - v).abs() < 1e-12 * v.abs().max(1e-3),
            "{what} cell {c}: {sum} vs {v}"
        );
        for &t in ts {
            assert!(
                tet_volume(&mesh.points, t) > 0.0,
                "{what} cell {c}: tet {t:?}"
            );
        }
    }
    let r = MeshReport::compute_with(mesh, &topo);
    assert_eq!(r.inverted_tets, 0, "{what}");
    assert_eq!(r.flat_tets, 0, "{what}");
}

#[test]
fn generated_grids_with_shuffled_ids_are_conforming() {
    let mut rng = Rng(99);
    for seed in 0..4 {
        let w = Warp {
            amplitude: 0.05,
            seed,
        };
        let mut hex = warped_hex_grid(4, &w);
        shuffle_ids(&mut hex, &mut rng);
        assert_conforming_and_positive(&hex, "warped hex grid");
        let mut zoo = zoo_grid(3, &w);
        shuffle_ids(&mut zoo, &mut rng);
        assert_conforming_and_positive(&zoo, "zoo grid");
    }
}

/// Column and honeycomb-free stacks of pentagonal and hexagonal prisms
/// sharing their n-gon caps and a polyhedron sharing a quad with a hexahedron.
#[test]
fn prisms_and_polyhedra_share_faces_consistently() {
    let mut rng = Rng(5);
    for _ in 0..20 {
        let mut m = Mesh::default();
        for (n, kind, x0) in [
            (5usize, CellKind::PentagonalPrism, 0.0),
            (6, CellKind::HexagonalPrism, 3.0),
        ] {
            let base = m.points.len() as u32;
            for z in 0..4 {
                for i in 0..n {
                    let a = i as f64 * std::f64::consts::TAU / n as f64;
                    m.points.push(DVec3::new(x0 + a.cos(), a.sin(), z as f64));
                }
            }
            for z in 0..3u32 {
                let nodes: Vec<u32> = (0..2 * n as u32).map(|k| base + z * n as u32 + k).collect();
                m.cells.push(kind, &nodes);
            }
        }
        // hexahedron + polyhedron cube sharing the quad at x = 10
        let base = m.points.len() as u32;
        for z in 0..2 {
            for y in 0..2 {
                for x in 0..3 {
                    m.points
                        .push(DVec3::new(9.0 + x as f64, y as f64, z as f64));
                }
            }
        }
        let id = |x: u32, y: u32, z: u32| base + x + 3 * y + 6 * z;
        let cube = |x: u32| {
            [
                id(x, 0, 0),
                id(x + 1, 0, 0),
                id(x + 1, 1, 0),
                id(x, 1, 0),
                id(x, 0, 1),
                id(x + 1, 0, 1),
                id(x + 1, 1, 1),
                id(x, 1, 1),
            ]
        };
        m.cells.push(CellKind::Hexahedron, &cube(0));
        let c1 = cube(1);
        m.cells.push_polyhedron(
            CellKind::Hexahedron
                .faces()
                .iter()
                .map(|f| f.iter().map(|&l| c1[l as usize]).collect())
                .collect(),
        );
        shuffle_ids(&mut m, &mut rng);
        let topo = Topology::build(&m.cells);
        // caps + side quads of each stack, and 12 - 2 faces of the cube pair
        assert_eq!(topo.boundary_face_count(), (2 + 15) + (2 + 18) + 10);
        assert_conforming_and_positive(&m, "prism stacks");
    }
}

#[test]
fn repair_makes_inverted_cells_positive_and_flips_their_tets() {
    let mut rng = Rng(77);
    let mut mesh = zoo_grid(3, &Warp::default());
    shuffle_ids(&mut mesh, &mut rng);
    let (before, _) = tetrahedralize(&mesh.cells);
    // invert every third cell
    let flipped: Vec<usize> = (0..mesh.cells.len()).step_by(3).collect();
    for &c in &flipped {
        flip_cell(&mut mesh.cells, c);
    }
    let r = MeshReport::compute(&mesh);
    assert_eq!(r.inverted_cells, flipped.len());
    // inverted_tets counts after (virtual) repair
    assert_eq!(r.inverted_tets, 0);
    let (mid, offs) = tetrahedralize(&mesh.cells);
    for &c in &flipped {
        for &t in &mid[offs[c] as usize..offs[c + 1] as usize] {
            assert!(tet_volume(&mesh.points, t) < 0.0, "cell {c}");
        }
    }
    assert_eq!(repair_orientation(&mut mesh), flipped.len());
    let (after, _) = tetrahedralize(&mesh.cells);
    // same tets as before the inversion, as vertex sets
    let norm = |v: &[[u32; 4]]| {
        let mut s: Vec<[u32; 4]> = v
            .iter()
            .map(|t| {
                let mut s = *t;
                s.sort_unstable();
                s
            })
            .collect();
        s.sort_unstable();
        s
    };
    assert_eq!(norm(&before), norm(&after));
    assert_eq!(norm(&before), norm(&mid));
    assert_conforming_and_positive(&mesh, "repaired zoo grid");
}

#[test]
fn distorted_cells_yield_counted_inverted_tets_without_failing() {
    // A hexahedron with one corner pushed through the opposite face: its
    // face volume is still positive but some consistent tets are inverted.
    let mut m = warped_hex_grid(
        1,
        &Warp {
            amplitude: 0.0,
            seed: 0,
        },
    );
    m.points[6] = DVec3::new(0.2, 0.2, 0.1);
    let r = MeshReport::compute(&m);
    assert_eq!(r.cells, 1);
    assert!(r.inverted_tets > 0, "{r:?}");
    assert!(r.inverted_tets < r.tets);
}
