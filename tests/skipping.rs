//! Work a scene does not need, skipped with the image unchanged: pieces
//! whose scalar range maps to zero extinction are not projected, and the
//! image is the same bit for bit (within 1e-6 in float) as with every piece
//! drawn, in every projected mode, through the CPU twin and on the GPU
//! where there is one. A skip that left out a visible piece would change
//! some pixel by far more. (Early ray termination: tests/raycast_options.rs.)

mod render_util;

use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::image::compare_float;
use zoovr::render::{
    Compositor, Mode, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec,
};
use zoovr::tf::{EmissionModel, TransferFunction};

#[test]
fn dark_pieces_are_skipped_and_the_image_is_unchanged() {
    let mesh = warped_hex_grid(
        10,
        &Warp {
            amplitude: 0.08,
            seed: 3,
        },
    );
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let mut shading = scene.shading();
    let (lo, hi) = shading.range;
    // Visible only in the top tenth of the range: most cells are dark.
    let b = lo + 0.9 * (hi - lo);
    shading.tf = TransferFunction::from_channels(
        &[(lo, [0.0]), (b, [0.0]), (hi, [8.0])],
        &[(lo, [0.2, 0.4, 1.0]), (hi, [1.0, 0.8, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let mut renderer = Renderer::new(scene.geometry());
    let mut compositors = vec![Compositor::Cpu];
    if render_util::gpu_available() {
        compositors.push(Compositor::Gpu);
    }
    for mode in [Mode::Exact, Mode::ExactFrag, Mode::Preint3d, Mode::Preint2d] {
        for &compositor in &compositors {
            let render = |renderer: &mut Renderer, skip: bool| {
                let opts = RenderOptions {
                    mode,
                    camera: zoovr::camera::CameraParams {
                        width: 64,
                        height: 64,
                        azimuth: 25.0,
                        elevation: 15.0,
                        ..Default::default()
                    },
                    projected: ProjectedOptions {
                        compositor,
                        skip_invisible: skip,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                renderer.render(&shading, &opts, |_, _| {}).unwrap()
            };
            let (with, s_with) = render(&mut renderer, true);
            let (without, s_without) = render(&mut renderer, false);
            let (p_with, p_without) = (s_with.projected().unwrap(), s_without.projected().unwrap());
            assert_eq!(p_without.culled_pieces, 0, "{mode:?}");
            assert!(
                p_with.culled_pieces * 10 >= p_with.pieces * 7,
                "{mode:?} {compositor:?}: {} of {} pieces skipped",
                p_with.culled_pieces,
                p_with.pieces
            );
            assert!(p_with.triangles < p_without.triangles / 2, "{mode:?}");
            let (d, _) = compare_float(&with, &without).unwrap();
            assert!(d.max_abs <= 1e-6, "{mode:?} {compositor:?}: {d:?}");
            // Something is drawn at all (the test could not fail otherwise).
            let lit = with.pixels.iter().filter(|p| p[3] > 0.05).count();
            assert!(lit > 50, "{mode:?}: {lit} lit pixels");
        }
    }
}

/// A frame that asks for the order of the frame before (same camera, split
/// policy, scalars) takes it without sorting again, with the image the same
/// bit for bit; a new camera, new split points or new values sort again.
#[test]
fn the_last_order_is_reused_only_when_nothing_it_depends_on_changed() {
    let mesh = warped_hex_grid(
        6,
        &Warp {
            amplitude: 0.08,
            seed: 5,
        },
    );
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    let shading = scene.shading();
    let mut renderer = Renderer::new(scene.geometry());
    let opts = |mode: Mode, azimuth: f64| RenderOptions {
        mode,
        camera: zoovr::camera::CameraParams {
            width: 48,
            height: 48,
            azimuth,
            ..Default::default()
        },
        projected: ProjectedOptions {
            compositor: Compositor::Cpu,
            ..Default::default()
        },
        ..Default::default()
    };
    let frame = |renderer: &mut Renderer, shading: &zoovr::render::Shading, az: f64| {
        let (img, stats) = renderer
            .render(shading, &opts(Mode::Exact, az), |_, _| {})
            .unwrap();
        (img, stats.projected().unwrap().order_reused)
    };
    let (first, reused) = frame(&mut renderer, &shading, 30.0);
    assert!(!reused);
    let (again, reused) = frame(&mut renderer, &shading, 30.0);
    assert!(reused, "the same frame sorts again");
    assert_eq!(first.pixels, again.pixels);
    // Another camera.
    let (_, reused) = frame(&mut renderer, &shading, 31.0);
    assert!(!reused);
    // New colours, same split points: the order stands.
    let mut recoloured = shading.clone();
    let nodes: Vec<_> = shading.tf.nodes();
    let tau: Vec<(f64, [f64; 1])> = nodes.iter().map(|n| (n.s, [n.tau])).collect();
    let col: Vec<(f64, [f64; 3])> = nodes
        .iter()
        .map(|n| (n.s, [n.color[2], n.color[1], n.color[0]]))
        .collect();
    recoloured.tf = TransferFunction::from_channels(&tau, &col, None, EmissionModel::Glow).unwrap();
    let (_, reused) = frame(&mut renderer, &recoloured, 31.0);
    assert!(reused, "colours alone do not change the order");
    // New values: sorted again.
    let mut revalued = shading.clone();
    if let Some(f) = &shading.field {
        let mut f2 = (**f).clone();
        for v in &mut f2.values {
            *v = 1.0 - *v;
        }
        revalued.field = Some(std::sync::Arc::new(f2));
    }
    let (_, reused) = frame(&mut renderer, &revalued, 31.0);
    assert!(!reused, "new values sort again where they decide splits");
    // exact-frag splits at no value: new values keep its order.
    let mut frag = |shading: &zoovr::render::Shading| {
        let (_, stats) = renderer
            .render(shading, &opts(Mode::ExactFrag, 31.0), |_, _| {})
            .unwrap();
        stats.projected().unwrap().order_reused
    };
    frag(&shading);
    assert!(frag(&revalued), "exact-frag: values alone keep the order");
}
