//! Exactness of the visibility order on generated meshes, checked by the
//! brute-force validator at every pixel centre of small images.

use std::sync::Arc;

use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::mesh::Mesh;
use zoovr::visibility::synth::{grid, holed_grid, notched_grid, GridSpec};
use zoovr::visibility::{sample_pixels, validate, Order, Piece, Sorter, SplitPolicy};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn random_camera(mesh: &Mesh, rng: &mut Rng, ortho: bool, size: u32) -> Camera {
    let p = CameraParams {
        width: size,
        height: size,
        azimuth: rng.f() * 360.0,
        elevation: rng.f() * 170.0 - 85.0,
        roll: rng.f() * 360.0,
        zoom: 1.0 + rng.f(),
        ortho,
        ..Default::default()
    };
    Camera::fit(mesh.bounds(), &p)
}

/// Every piece id appears once, every cell in view is covered exactly
/// once, and the cells outside the view frustum not at all.
fn check_cover(mesh: &Mesh, order: &Order, camera: &Camera) {
    let mut outside = Vec::new();
    let n = zoovr::visibility::frustum::outside_cells(
        camera,
        mesh,
        zoovr::numeric::tolerance::FRUSTUM_MARGIN_PX,
        &mut outside,
    );
    assert_eq!(order.stats.frustum_culled, n);
    let mut whole = vec![0u32; mesh.cells.len()];
    let mut tets = vec![0u32; mesh.cells.len()];
    for p in &order.pieces {
        match p {
            Piece::Cell(c) => whole[*c as usize] += 1,
            Piece::Tet { cell, .. } | Piece::Slab { cell, .. } | Piece::Frag { cell, .. } => {
                tets[*cell as usize] += 1
            }
        }
    }
    for c in 0..mesh.cells.len() {
        if outside[c] {
            assert_eq!((whole[c], tets[c]), (0, 0), "cell {c} is outside the view");
            continue;
        }
        assert!(
            (whole[c] == 1 && tets[c] == 0) || (whole[c] == 0 && tets[c] >= 2),
            "cell {c}: {} whole, {} tets",
            whole[c],
            tets[c]
        );
    }
}

fn run_views(mesh: &Mesh, views: usize, size: u32, seed: u64, policy: &SplitPolicy) -> usize {
    let topo = Topology::build(&mesh.cells);
    let mut sorter = Sorter::new(mesh.clone(), topo);
    let mut rng = Rng(seed);
    let mut split_seen = 0;
    for v in 0..views {
        let ortho = v % 2 == 1;
        let cam = random_camera(mesh, &mut rng, ortho, size);
        let order = sorter.order(&cam, policy).expect("order");
        sorter.sanity_check().expect("sanity");
        check_cover(mesh, &order, &cam);
        assert!(
            order.groups.is_empty(),
            "unresolved cycles: {:?}",
            order.stats
        );
        split_seen += order.stats.split_cells;
        let px = sample_pixels(&cam, usize::MAX, 0);
        let viol = validate(mesh, &order, &cam, &px);
        assert!(
            viol.ok(),
            "view {v} ortho {ortho}: {} violations, e.g. {:?}; stats {:?}",
            viol.count,
            &viol.examples[..viol.examples.len().min(3)],
            order.stats
        );
        assert!(viol.pairs > 0, "validator compared nothing");
        assert!(viol.degenerate_rays * 20 < viol.rays);
    }
    split_seen
}

#[test]
fn convex_warped_grid_is_exact() {
    let spec = GridSpec {
        dims: [8, 7, 6],
        jitter: 0.2,
        seed: 3,
        planar_boundary: true,
    };
    let mesh = grid(&spec, |_, _, _| true);
    let topo = Topology::build(&mesh.cells);
    assert!(Sorter::new(mesh.clone(), topo).convex_boundary());
    let split = run_views(&mesh, 20, 48, 11, &SplitPolicy::default());
    assert!(split > 0, "the jittered grid should have problem cells");
}

#[test]
fn warped_grid_12_cubed_is_exact() {
    let spec = GridSpec {
        dims: [12, 12, 12],
        jitter: 0.22,
        seed: 5,
        planar_boundary: false,
    };
    let mesh = grid(&spec, |_, _, _| true);
    run_views(&mesh, 20, 40, 12, &SplitPolicy::default());
}

#[test]
fn grid_with_hole_and_cavity_is_exact() {
    let spec = GridSpec {
        dims: [8, 8, 8],
        jitter: 0.15,
        seed: 7,
        planar_boundary: true,
    };
    let mesh = holed_grid(&spec);
    let topo = Topology::build(&mesh.cells);
    assert!(!Sorter::new(mesh.clone(), topo).convex_boundary());
    run_views(&mesh, 20, 48, 13, &SplitPolicy::default());
}

#[test]
fn notched_grid_is_exact() {
    let spec = GridSpec {
        dims: [9, 4, 6],
        jitter: 0.15,
        seed: 9,
        planar_boundary: false,
    };
    let mesh = notched_grid(&spec);
    run_views(&mesh, 20, 48, 14, &SplitPolicy::default());
}

#[test]
fn split_all_is_exact() {
    let spec = GridSpec {
        dims: [5, 5, 4],
        jitter: 0.2,
        seed: 21,
        planar_boundary: false,
    };
    let mesh = holed_grid(&spec);
    let policy = SplitPolicy {
        all: true,
        ..Default::default()
    };
    let split = run_views(&mesh, 4, 40, 15, &policy);
    assert_eq!(split, 4 * mesh.cells.len());
}

#[test]
fn validator_catches_wrong_orders() {
    let spec = GridSpec {
        dims: [6, 5, 4],
        jitter: 0.1,
        seed: 2,
        planar_boundary: true,
    };
    let mesh = Arc::new(notched_grid(&spec));
    let topo = Topology::build(&mesh.cells);
    let mut sorter = Sorter::new(mesh.clone(), topo);
    let mut rng = Rng(77);
    let mut mpvo_only_failures = 0;
    let mut constraints = 0;
    for v in 0..6 {
        let cam = random_camera(&mesh, &mut rng, v % 2 == 0, 40);
        let px = sample_pixels(&cam, usize::MAX, 0);
        sorter.nonconvex = zoovr::visibility::NonConvex::PixelConstraints;
        let mut order = sorter.order(&cam, &SplitPolicy::default()).unwrap();
        constraints += order.stats.nonconvex_constraints;
        assert!(validate(&mesh, &order, &cam, &px).ok());
        order.pieces.reverse();
        let bad = validate(&mesh, &order, &cam, &px);
        assert!(
            bad.count > 100,
            "reversed order: only {} violations",
            bad.count
        );
        sorter.nonconvex = zoovr::visibility::NonConvex::IgnoreApproximate;
        let approx = sorter.order(&cam, &SplitPolicy::default()).unwrap();
        mpvo_only_failures += validate(&mesh, &approx, &cam, &px).count;
    }
    assert!(constraints > 0);
    assert!(
        mpvo_only_failures > 0,
        "MPVO alone should fail on a notched mesh for some view"
    );
}

/// Cycles in a large component split only the cells on them: on a warped
/// generated grid whose whole-cell graph has cycles in several views, the
/// orders are exact (every pixel-centre ray validated) and the cells split
/// to break cycles are far fewer than the components' whole cells, which
/// is what splitting every member would split.
#[test]
fn cycles_split_their_members_not_their_components() {
    let mesh = zoovr::generate::warped_hex_grid(
        20,
        &zoovr::generate::Warp {
            amplitude: 0.05,
            seed: 1,
        },
    );
    let topo = Topology::build(&mesh.cells);
    let mut sorter = Sorter::new(mesh.clone(), topo);
    let mut rng = Rng(21);
    let (mut split, mut members) = (0, 0);
    for v in 0..8 {
        let cam = random_camera(&mesh, &mut rng, v % 2 == 1, 64);
        let order = sorter.order(&cam, &SplitPolicy::default()).expect("order");
        sorter.sanity_check().expect("sanity");
        check_cover(&mesh, &order, &cam);
        let px = sample_pixels(&cam, usize::MAX, 0);
        let viol = validate(&mesh, &order, &cam, &px);
        assert!(
            viol.ok(),
            "view {v}: {} violations; {:?}",
            viol.count,
            order.stats
        );
        split += order.stats.cycle_split_cells;
        members += order.stats.cycle_component_cells;
    }
    eprintln!("cells split for cycles: {split} of {members} in their components");
    assert!(members > 0, "no cycles: the test checks nothing");
    assert!(
        split * 2 < members,
        "{split} cells split of {members} in components"
    );
}
