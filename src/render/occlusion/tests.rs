//! The pass with and without the min/max tree: the same pieces hidden.

use super::*;
use crate::camera::{Camera, CameraParams};
use crate::generate::{warped_hex_grid, Warp};
use crate::numeric::tolerance::OCCLUSION_TRANSMITTANCE;
use crate::render::breakpoints::split_points;
use crate::render::driver::tests::test_ctx;
use crate::render::scene::{ScalarsRef, Scene};
use crate::render::SceneSpec;
use crate::tf::TransferFunction;
use crate::visibility::{Sorter, SplitPolicy};

/// A warped grid whose low values (one side of the smooth field) are
/// opaque: seen from several sides, whole nodes of the tree lie behind
/// them. The nodes hide exactly the pieces the per-piece test hides
/// (a node's box holds the boxes of its cells' pieces), so the pass
/// finds the same pieces with the tree as without, through nodes for
/// many of them; and cells whose pieces are all hidden are not credited,
/// which changes no test (their centres are behind the cut already).
#[test]
fn the_tree_hides_the_pieces_the_per_piece_test_hides() {
    let mesh = warped_hex_grid(16, &Warp::default());
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(0.0, [800.0]), (0.45, [800.0]), (0.5, [0.5]), (1.0, [2.0])],
        &[(0.0, [0.9, 0.3, 0.1]), (1.0, [0.2, 0.4, 0.9])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let tree = CellTree::build(&scene.mesh);
    let breakpoints = split_points(&scene.tf);
    let point_scalars = match scene.scalars() {
        ScalarsRef::Point(v) => Some(v),
        _ => None,
    };
    let mut sorter = Sorter::new(scene.mesh.clone(), scene.topology.clone());
    let mut by_nodes = 0;
    for (az, el, ortho) in [
        (0.0, 0.0, false),
        (130.0, 25.0, true),
        (250.0, -40.0, false),
    ] {
        let params = CameraParams {
            width: 80,
            height: 64,
            azimuth: az,
            elevation: el,
            ortho,
            ..Default::default()
        };
        let camera = Camera::fit(scene.mesh.bounds(), &params);
        let policy = SplitPolicy {
            all: false,
            breakpoints: &breakpoints,
            point_scalars,
            dark: None,
        };
        let order = sorter.order(&camera, &policy).unwrap();
        let src = test_ctx(&scene, &camera, &breakpoints, &order, true);
        let without = hidden_pieces(&src, &order, OCCLUSION_TRANSMITTANCE, None).unwrap();
        let view = TreeView {
            tree: &tree,
            geometry_ids: None,
        };
        let with = hidden_pieces(&src, &order, OCCLUSION_TRANSMITTANCE, Some(view)).unwrap();
        assert!(
            without.count * 10 > order.pieces.len(),
            "{az}: {}",
            without.count
        );
        assert_eq!(with.hidden, without.hidden, "{az} {el}");
        assert_eq!(with.count, without.count);
        assert_eq!(without.nodes_hidden, 0);
        assert!(with.hidden_by_nodes <= with.count);
        by_nodes += with.hidden_by_nodes;
        eprintln!(
            "view {az} {el}: {} of {} pieces hidden, {} through {} nodes",
            with.count,
            order.pieces.len(),
            with.hidden_by_nodes,
            with.nodes_hidden
        );
    }
    assert!(by_nodes > 0);
}
