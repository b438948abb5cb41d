//! Bookkeeping and input handling of the visibility sorter: subdivisions kept
//! and restored across views, breakpoint splits, typed errors on bad input.

use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::mesh::{CellKind, Mesh};
use zoovr::visibility::synth::{grid, GridSpec};
use zoovr::visibility::{Piece, Sorter, SplitPolicy, VisibilityError};

fn warped() -> Mesh {
    grid(
        &GridSpec {
            dims: [6, 6, 6],
            jitter: 0.22,
            seed: 4,
            planar_boundary: false,
        },
        |_, _, _| true,
    )
}

fn cam(mesh: &Mesh, az: f64, el: f64, ortho: bool) -> Camera {
    let p = CameraParams {
        width: 32,
        height: 32,
        azimuth: az,
        elevation: el,
        ortho,
        ..Default::default()
    };
    Camera::fit(mesh.bounds(), &p)
}

#[test]
fn splits_are_kept_restored_and_history_free() {
    let mesh = warped();
    let topo = Topology::build(&mesh.cells);
    let mut s = Sorter::new(&mesh, &topo);
    let pol = SplitPolicy::default();
    let a = cam(&mesh, 30.0, 20.0, false);
    let b = cam(&mesh, 200.0, -50.0, true);
    let o1 = s.order(&a, &pol).unwrap();
    assert!(o1.stats.split_cells > 0);
    assert_eq!(o1.stats.newly_split, o1.stats.split_cells);
    let o2 = s.order(&b, &pol).unwrap();
    s.sanity_check().unwrap();
    assert!(o2.stats.restored > 0, "{:?}", o2.stats);
    assert_eq!(
        o2.stats.split_cells,
        o1.stats.split_cells - o2.stats.restored + o2.stats.newly_split
    );
    // The same view again: the same order, whatever the pool went through.
    let o3 = s.order(&a, &pol).unwrap();
    s.sanity_check().unwrap();
    assert_eq!(o3.pieces, o1.pieces);
    // Same view twice in a row: nothing new to split.
    let o4 = s.order(&a, &pol).unwrap();
    assert_eq!((o4.stats.newly_split, o4.stats.restored), (0, 0));
}

#[test]
fn breakpoint_cells_match_brute_force() {
    let mesh = warped();
    let topo = Topology::build(&mesh.cells);
    let mut s = Sorter::new(&mesh, &topo);
    let scalars: Vec<f64> = mesh.points.iter().map(|p| p.x + p.y * p.z).collect();
    let bps = [0.3, 0.75];
    let want = (0..mesh.cells.len())
        .filter(|&c| {
            let v: Vec<f64> = mesh
                .cells
                .nodes(c)
                .iter()
                .map(|&i| scalars[i as usize])
                .collect();
            let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            bps.iter().any(|&b| lo < b && b < hi)
        })
        .count();
    let pol = SplitPolicy {
        all: false,
        breakpoints: &bps,
        point_scalars: Some(&scalars),
    };
    let o = s.order(&cam(&mesh, 10.0, 10.0, false), &pol).unwrap();
    assert_eq!(o.stats.breakpoint_cells, want);
    assert!(want > 0);
    let tet_cells: std::collections::HashSet<u32> = o
        .pieces
        .iter()
        .filter_map(|p| match p {
            Piece::Tet { cell, .. } => Some(*cell),
            _ => None,
        })
        .collect();
    assert!(tet_cells.len() >= want);
    assert_eq!(tet_cells.len(), o.stats.split_cells);
}

#[test]
fn bad_input_is_a_typed_error() {
    let mesh = warped();
    let topo = Topology::build(&mesh.cells);
    let c = cam(&mesh, 0.0, 0.0, false);
    // Point id out of range.
    let mut bad = Mesh {
        points: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        ..Default::default()
    };
    bad.cells.push(CellKind::Tetra, &[0, 1, 2, 7]);
    let bt = Topology::build(&bad.cells);
    let err = Sorter::new(&bad, &bt).order(&c, &SplitPolicy::default());
    assert!(matches!(
        err,
        Err(VisibilityError::PointOutOfRange { point: 7, .. })
    ));
    // Non-finite point.
    let mut nan = mesh.clone();
    nan.points[5].y = f64::NAN;
    let err = Sorter::new(&nan, &topo).order(&c, &SplitPolicy::default());
    assert_eq!(err.unwrap_err(), VisibilityError::NonFinitePoint(5));
    // Topology of another mesh.
    let err = Sorter::new(&mesh, &bt).order(&c, &SplitPolicy::default());
    assert!(matches!(err, Err(VisibilityError::TopologyMismatch { .. })));
    // Too few scalars; empty image.
    let mut s = Sorter::new(&mesh, &topo);
    let short = [1.0, 2.0];
    let pol = SplitPolicy {
        all: false,
        breakpoints: &[1.5],
        point_scalars: Some(&short),
    };
    assert!(matches!(
        s.order(&c, &pol),
        Err(VisibilityError::ScalarCount { got: 2, .. })
    ));
    let mut empty = c;
    empty.width = 0;
    assert!(matches!(
        s.order(&empty, &SplitPolicy::default()),
        Err(VisibilityError::BadCamera(_))
    ));
    // An empty mesh sorts to nothing.
    let none = Mesh::default();
    let nt = Topology::build(&none.cells);
    let o = Sorter::new(&none, &nt)
        .order(&c, &SplitPolicy::default())
        .unwrap();
    assert!(o.pieces.is_empty());
}
