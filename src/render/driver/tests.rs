//! The driver's unit tests.
use super::*;
use crate::camera::CameraParams;
use crate::generate::{warped_hex_grid, Warp};
use crate::render::breakpoints::split_points;
use crate::render::modes::exact::{ExactMode, ExactVertex};
use crate::render::SceneSpec;
use crate::tf::EmissionModel;
use crate::tf::TransferFunction;
use crate::visibility::Order;

/// The context of `order` for `scene` seen by `camera`.
pub(crate) fn test_ctx<'a>(
    scene: &'a Scene,
    camera: &'a Camera,
    breakpoints: &'a [f64],
    order: &'a Order,
    cull: bool,
) -> PieceSource<'a> {
    PieceSource {
        mesh: &scene.mesh,
        whole: &scene.mesh,
        scalars: scene.scalars(),
        field_span: scene.field_span(),
        tf: &scene.tf,
        camera,
        breakpoints,
        levels: &order.levels,
        fragments: &order.fragments,
        length_unit: scene.unit_distance,
        cull,
        skip_invisible: true,
        grid: PixelGrid::new(camera.width, camera.height),
        ties: TieRays::new(camera, scene.mesh.bounds()),
        exact_ties: true,
        colour_draw: true,
        iso: None,
        volume: true,
        gradients: None,
    }
}

/// An unwarped grid seen in perspective straight down an axis, every
/// cell split into tets: the diagonal faces of the tets in the planes
/// through the eye are seen exactly edge-on, and rounding the pixel
/// positions leaves sliver regions that are collinear in f32 (Mesa gave
/// NaN pixels on them, tests/stress_scenes.rs `edge_on_...`). None may
/// reach the GPU.
#[test]
fn no_triangle_degenerate_in_f32_reaches_the_gpu() {
    let mesh = warped_hex_grid(
        2,
        &Warp {
            amplitude: 0.0,
            seed: 7,
        },
    );
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(0.0, [0.0]), (0.5, [6.0]), (1.0, [10.0])],
        &[(0.0, [0.1, 0.2, 0.9]), (1.0, [1.0, 0.5, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let params = CameraParams {
        width: 96,
        height: 96,
        azimuth: 0.0,
        elevation: 0.0,
        ortho: false,
        ..Default::default()
    };
    let camera = Camera::fit(scene.mesh.bounds(), &params);
    let breakpoints = split_points(&scene.tf);
    let point_scalars = match scene.scalars() {
        ScalarsRef::Point(v) => Some(v),
        _ => None,
    };
    let policy = SplitPolicy {
        all: true,
        breakpoints: &breakpoints,
        point_scalars,
        dark: None,
    };
    let mut sorter = Sorter::new(scene.mesh.clone(), scene.topology.clone());
    let order = sorter.order(&camera, &policy).unwrap();
    let ctx = test_ctx(&scene, &camera, &breakpoints, &order, false);
    // Piece by piece, up to the first one that makes such a sliver (the
    // whole view refines into ~1e5 triangles).
    let mut degenerate = 0;
    for piece in &order.pieces {
        let out = process_chunk(
            &ExactMode::default(),
            &ctx,
            None,
            std::slice::from_ref(piece),
            ChunkOut::default(),
        );
        assert_eq!(out.error, None);
        let mapper = ClipMapper::for_camera(&camera);
        let half = mapper.side as f32 * 0.5;
        for t in out.indices.chunks(3) {
            // The grid positions the rasteriser recovers from the NDC.
            let [a, b, c] = [0, 1, 2].map(|k| {
                let p = out.vertices[t[k] as usize].pos;
                let (x, y) = (p[0] * half + half, -p[1] * half + half);
                [x, y].map(|v| ClipMapper::snap(v as f64).unwrap())
            });
            assert!(grid_area_positive(a, b, c), "{piece:?}: {a:?} {b:?} {c:?}");
        }
        degenerate += out.degenerate;
        if degenerate > 0 {
            break;
        }
    }
    // The view still makes the case this guards against.
    assert!(degenerate > 0, "no f32-degenerate sliver in this view");
}

/// The pipeline hands every chunk over in order, exactly as projecting
/// the chunks one after another gives them, with whatever number of
/// workers; an error of the hand-over stops it and is returned.
#[test]
fn pipeline_hands_chunks_over_in_order_and_stops_on_error() {
    let mesh = warped_hex_grid(
        12,
        &Warp {
            amplitude: 0.2,
            seed: 3,
        },
    );
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let camera = Camera::fit(
        scene.mesh.bounds(),
        &CameraParams {
            width: 64,
            height: 64,
            azimuth: 30.0,
            elevation: 20.0,
            ..Default::default()
        },
    );
    let breakpoints = split_points(&scene.tf);
    let policy = SplitPolicy {
        all: true,
        breakpoints: &breakpoints,
        point_scalars: None,
        dark: None,
    };
    let mut sorter = Sorter::new(scene.mesh.clone(), scene.topology.clone());
    let order = sorter.order(&camera, &policy).unwrap();
    let ctx = test_ctx(&scene, &camera, &breakpoints, &order, true);
    let chunk = 64;
    let chunks = order.pieces.chunks(chunk).count();
    assert!(chunks > 4 * 3 * AHEAD_PER_WORKER, "{chunks} chunks");
    let serial: Vec<(Vec<ExactVertex>, Vec<u32>)> = order
        .pieces
        .chunks(chunk)
        .map(|c| {
            let out = process_chunk(&ExactMode::default(), &ctx, None, c, ChunkOut::default());
            (out.vertices, out.indices)
        })
        .collect();
    assert!(serial.iter().filter(|c| !c.1.is_empty()).count() > chunks / 2);
    let pool = BufferPool::default();
    for workers in [1, 2, 3] {
        let mut got = Vec::new();
        pipeline(
            &ExactMode::default(),
            &ctx,
            None,
            &order.pieces,
            chunk,
            workers,
            &pool,
            |out| {
                got.push((out.vertices.clone(), out.indices.clone()));
                pool.put(out);
                Ok(())
            },
        )
        .unwrap();
        assert!(got == serial, "{workers} workers");
        let mut calls = 0;
        let r = pipeline(
            &ExactMode::default(),
            &ctx,
            None,
            &order.pieces,
            chunk,
            workers,
            &pool,
            |_| {
                calls += 1;
                if calls == 3 {
                    Err(RenderError::NoCells)
                } else {
                    Ok(())
                }
            },
        );
        assert!(matches!(r, Err(RenderError::NoCells)));
        assert_eq!(calls, 3);
    }
}
