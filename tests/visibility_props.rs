//! Property tests: random jittered grids (nonplanar faces, sometimes holed),
//! random views, both projections; after every view the split bookkeeping
//! passes `sanity_check` and the order passes the brute-force validator.

use proptest::prelude::*;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::visibility::synth::{grid, holed_grid, GridSpec};
use zoovr::visibility::{sample_pixels, validate, Sorter, SplitPolicy};

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    #[test]
    fn random_grids_random_views(
        nx in 2usize..6, ny in 2usize..6, nz in 2usize..5,
        jitter in 0.0f64..0.24, seed in any::<u64>(), holed in any::<bool>(),
        views in proptest::collection::vec((0.0f64..360.0, -89.0f64..89.0, any::<bool>()), 1..4),
        breakpoint in proptest::option::of(0.2f64..0.8),
    ) {
        let spec = GridSpec { dims: [nx, ny, nz], jitter, seed, planar_boundary: !holed };
        let mesh = if holed && nx >= 3 && ny >= 3 { holed_grid(&spec) } else { grid(&spec, |_, _, _| true) };
        prop_assume!(!mesh.cells.is_empty());
        let scalars: Vec<f64> = mesh.points.iter().map(|p| p.x + 0.5 * p.y).collect();
        let bps: Vec<f64> = breakpoint.into_iter().collect();
        let policy = SplitPolicy { all: false, breakpoints: &bps, point_scalars: Some(&scalars), dark: None };
        let topo = Topology::build(&mesh.cells);
        let mut sorter = Sorter::new(mesh.clone(), topo);
        for (az, el, ortho) in views {
            let p = CameraParams { width: 32, height: 32, azimuth: az, elevation: el, ortho, ..Default::default() };
            let cam = Camera::fit(mesh.bounds(), &p);
            let order = sorter.order(&cam, &policy).unwrap();
            prop_assert!(sorter.sanity_check().is_ok(), "{:?}", sorter.sanity_check());
            // The sort's splits are the sorter's; the splice's come on top.
            prop_assert_eq!(
                order.stats.split_cells,
                sorter.split_count() + order.stats.spliced_cells
            );
            if !bps.is_empty() {
                prop_assert!(order.stats.split_cells >= order.stats.breakpoint_cells);
            }
            let v = validate(&mesh, &order, &cam, &sample_pixels(&cam, usize::MAX, 0));
            prop_assert!(v.ok(), "{} violations {:?} stats {:?}", v.count, v.examples.first(), order.stats);
        }
    }

    /// One sort of the view serves any values: the splice of two fields
    /// (breakpoints at several levels) into the same base order passes the
    /// brute-force validator, and is the order `Sorter::order` makes.
    #[test]
    fn one_sort_serves_any_values(
        nx in 2usize..6, ny in 2usize..6, nz in 2usize..5,
        jitter in 0.0f64..0.24, seed in any::<u64>(), holed in any::<bool>(),
        view in (0.0f64..360.0, -89.0f64..89.0, any::<bool>()),
        bps in proptest::collection::vec(-0.5f64..1.5, 1..4),
    ) {
        let spec = GridSpec { dims: [nx, ny, nz], jitter, seed, planar_boundary: !holed };
        let mesh = if holed && nx >= 3 && ny >= 3 { holed_grid(&spec) } else { grid(&spec, |_, _, _| true) };
        prop_assume!(!mesh.cells.is_empty());
        let topo = Topology::build(&mesh.cells);
        let mut sorter = Sorter::new(mesh.clone(), topo);
        let (az, el, ortho) = view;
        let p = CameraParams { width: 32, height: 32, azimuth: az, elevation: el, ortho, ..Default::default() };
        let cam = Camera::fit(mesh.bounds(), &p);
        let base = sorter.base_order(&cam, false).unwrap();
        prop_assert_eq!(base.stats.slabs, 0);
        let fields: [Vec<f64>; 2] = [
            mesh.points.iter().map(|p| p.x + 0.5 * p.y).collect(),
            mesh.points.iter().map(|p| (3.0 * p.z).sin() - p.y * p.x).collect(),
        ];
        for scalars in &fields {
            let policy = SplitPolicy { all: false, breakpoints: &bps, point_scalars: Some(scalars), dark: None };
            let spliced = sorter.splice(&base, &cam, &policy).unwrap();
            let v = validate(&mesh, &spliced, &cam, &sample_pixels(&cam, usize::MAX, 0));
            prop_assert!(v.ok(), "{} violations {:?} stats {:?}", v.count, v.examples.first(), spliced.stats);
            prop_assert!(spliced.stats.pieces >= base.stats.pieces);
            let direct = sorter.order(&cam, &policy).unwrap();
            prop_assert_eq!(&direct.pieces, &spliced.pieces);
            prop_assert_eq!(direct.stats.breakpoint_cells, spliced.stats.breakpoint_cells);
        }
    }
}
