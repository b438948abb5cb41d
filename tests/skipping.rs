//! Work a scene does not need, skipped with the image unchanged: pieces
//! whose scalar range maps to zero extinction are not projected (nor their
//! cells split at breakpoints by the sort), and the
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
    // The colours jump in the middle of the dark part (a discrete colour
    // map), where the exact mode splits at a colour jump.
    let b = lo + 0.9 * (hi - lo);
    let mid = lo + 0.5 * (hi - lo);
    shading.tf = TransferFunction::from_channels(
        &[(lo, [0.0]), (b, [0.0]), (hi, [8.0])],
        &[
            (lo, [0.2, 0.4, 1.0]),
            (mid, [0.3, 0.5, 0.9]),
            (mid, [0.9, 0.1, 0.1]),
            (hi, [1.0, 0.8, 0.1]),
        ],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let mut renderer = Renderer::new(scene.geometry());
    let mut compositors = vec![Compositor::Cpu];
    if render_util::gpu_available() {
        compositors.push(Compositor::Gpu);
    }
    let cells = scene.mesh.cells.len();
    let iso = zoovr::render::iso::IsoOptions {
        surfaces: zoovr::render::iso::parse_list(&format!("{}", lo + 0.5 * (hi - lo))).unwrap(),
        ..Default::default()
    };
    for mode in [
        Mode::Exact,
        Mode::ExactFrag,
        Mode::Preint3d,
        Mode::Preint2d,
        Mode::Iso,
    ] {
        for &compositor in &compositors {
            // skip: pieces skipped; subset: dark cells left out of the
            // sort (src/render/visible.rs).
            let render = |renderer: &mut Renderer, skip: bool, subset: bool| {
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
                        dark_subset: subset,
                        ..Default::default()
                    },
                    iso: if mode == Mode::Iso {
                        iso.clone()
                    } else {
                        Default::default()
                    },
                    ..Default::default()
                };
                renderer.render(&shading, &opts, |_, _| {}).unwrap()
            };
            let (left_out, s_left_out) = render(&mut renderer, true, true);
            let (with, s_with) = render(&mut renderer, true, false);
            let (without, s_without) = render(&mut renderer, false, false);
            let (p_left_out, p_with, p_without) = (
                s_left_out.projected().unwrap(),
                s_with.projected().unwrap(),
                s_without.projected().unwrap(),
            );
            assert_eq!(p_without.culled_pieces, 0, "{mode:?}");
            assert_eq!(p_with.dark_cells_left_out, 0, "{mode:?}");
            assert_eq!(p_without.dark_cells_left_out, 0, "{mode:?}");
            // Most cells are dark: the sort leaves them out, its order
            // holds only the others (each once at least).
            assert!(
                p_left_out.dark_cells_left_out * 10 >= cells * 6,
                "{mode:?} {compositor:?}: {} of {cells} dark cells left out",
                p_left_out.dark_cells_left_out
            );
            assert_eq!(
                p_left_out.order.cells + p_left_out.dark_cells_left_out,
                cells,
                "{mode:?}"
            );
            assert!(
                p_with.culled_pieces * 10 >= p_with.pieces * 7,
                "{mode:?} {compositor:?}: {} of {} pieces skipped",
                p_with.culled_pieces,
                p_with.pieces
            );
            assert!(p_with.triangles < p_without.triangles / 2, "{mode:?}");
            assert_eq!(p_left_out.triangles, p_with.triangles, "{mode:?}");
            // Dark cells are not split at breakpoints either (the sort's
            // share of the skip): the exact mode splits at the transfer
            // function's kinks, most of which lie in the dark range here.
            assert_eq!(p_without.order.dark_unsplit, 0, "{mode:?}");
            if mode == Mode::Exact {
                let (a, b) = (&p_with.order, &p_without.order);
                assert!(a.dark_unsplit > 0, "{mode:?}: {a:?}");
                assert_eq!(a.breakpoint_cells + a.dark_unsplit, b.breakpoint_cells);
            }
            for (what, image) in [
                ("pieces skipped", &with),
                ("dark cells left out", &left_out),
            ] {
                let (d, _) = compare_float(image, &without).unwrap();
                assert!(d.max_abs <= 1e-6, "{mode:?} {compositor:?} {what}: {d:?}");
            }
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
        let p = stats.projected().unwrap();
        assert!(!(p.order_reused && p.sort_reused));
        (img, p.order_reused, p.sort_reused)
    };
    let (first, reused, sort) = frame(&mut renderer, &shading, 30.0);
    assert!(!reused && !sort);
    let (again, reused, _) = frame(&mut renderer, &shading, 30.0);
    assert!(reused, "the same frame sorts again");
    assert_eq!(first.pixels, again.pixels);
    // Another camera.
    let (_, reused, sort) = frame(&mut renderer, &shading, 31.0);
    assert!(!reused && !sort);
    // New colours, same split points: the order stands.
    let mut recoloured = shading.clone();
    let nodes: Vec<_> = shading.tf.nodes();
    let tau: Vec<(f64, [f64; 1])> = nodes.iter().map(|n| (n.s, [n.tau])).collect();
    let col: Vec<(f64, [f64; 3])> = nodes
        .iter()
        .map(|n| (n.s, [n.color[2], n.color[1], n.color[0]]))
        .collect();
    recoloured.tf = TransferFunction::from_channels(&tau, &col, None, EmissionModel::Glow).unwrap();
    let (_, reused, _) = frame(&mut renderer, &recoloured, 31.0);
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
    let (spliced, reused, sort) = frame(&mut renderer, &revalued, 31.0);
    assert!(
        !reused,
        "new values make a new order where they decide splits"
    );
    assert!(
        sort,
        "new values keep the view's sort and splice the values in"
    );
    // The same image as a renderer that never saw the old values.
    let mut fresh = Renderer::new(scene.geometry());
    let (alone, reused, sort) = frame(&mut fresh, &revalued, 31.0);
    assert!(!reused && !sort);
    assert_eq!(spliced.pixels, alone.pixels);
    // A transfer function with other breakpoints: the sort stands too.
    let mut kinked = shading.clone();
    let (lo, hi) = shading.range;
    let at = |x: f64| lo + (hi - lo) * x;
    kinked.tf = TransferFunction::from_channels(
        &[
            (at(0.0), [0.0]),
            (at(0.35), [3.0]),
            (at(0.6), [0.5]),
            (at(1.0), [2.0]),
        ],
        &[(at(0.0), [0.2, 0.4, 0.9]), (at(1.0), [0.9, 0.5, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    let (spliced, reused, sort) = frame(&mut renderer, &kinked, 31.0);
    assert!(!reused && sort, "new breakpoints keep the view's sort");
    let mut fresh = Renderer::new(scene.geometry());
    let (alone, _, _) = frame(&mut fresh, &kinked, 31.0);
    assert_eq!(spliced.pixels, alone.pixels);
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

/// Cells outside the view frustum (zoomed into a detail) are left out of
/// the order before the sort (`zoovr::visibility::frustum`), with the image
/// unchanged: the CPU twin, perspective and orthographic, on a convex grid
/// and on a mesh with a hole (boundary constraints), the exact mode with
/// whole cells and `--split all`, exact-frag and preint2d. A frustum shrunk by a few pixels leaves out visible
/// cells, and that shows.
///
/// With whole cells, the one difference the cull may make is which cells
/// in view a cycle splits into tets: a cycle that runs through cells out of
/// view is not met any more. A cell drawn as its tets integrates the tets'
/// field, so its pixels may differ by that model difference (measured
/// 4e-4); the bound holds outside the pixels whose rays meet a cell split
/// in one order and not in the other, and everywhere with `--split all`.
#[test]
fn cells_outside_the_frustum_are_left_out_and_the_image_is_unchanged() {
    let grid = warped_hex_grid(
        12,
        &Warp {
            amplitude: 0.08,
            seed: 9,
        },
    );
    let ring = zoovr::io::read(
        std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/meshes/ring_hole.vtu")),
        &Default::default(),
    )
    .unwrap();
    let mut split_differs = 0;
    // The ring's 64 cells are large: a closer view leaves some out.
    for (name, mesh, closer) in [("grid", grid, 1.0), ("ring_hole", ring, 2.0)] {
        let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
        let shading = scene.shading();
        let cells = scene.mesh.cells.len();
        let mut renderer = Renderer::new(scene.geometry());
        for (ortho, azimuth, zoom) in [(false, 30.0, 3.0), (true, 200.0, 2.5), (false, 120.0, 4.0)]
        {
            let runs = [
                (Mode::Exact, false),
                (Mode::Exact, true),
                (Mode::ExactFrag, false),
                (Mode::Preint2d, false),
            ];
            for (mode, split_all) in runs {
                let params = zoovr::camera::CameraParams {
                    width: 56,
                    height: 48,
                    azimuth,
                    elevation: 20.0,
                    zoom: zoom * closer,
                    ortho,
                    ..Default::default()
                };
                let opts = RenderOptions {
                    mode,
                    camera: params,
                    projected: ProjectedOptions {
                        compositor: Compositor::Cpu,
                        split_all,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let mut frame = |margin: Option<f64>| {
                    renderer.sorter().frustum_margin = margin;
                    let (img, stats) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
                    let culled = stats.projected().unwrap().order.frustum_culled;
                    (img, culled, render_util::split_cells(&renderer, cells))
                };
                let case = format!(
                    "{name} ortho {ortho} azimuth {azimuth} zoom {zoom} split all {split_all}"
                );
                let (all, none_culled, split_a) = frame(None);
                assert_eq!(none_culled, 0);
                let (culled, n, split_b) =
                    frame(Some(zoovr::numeric::tolerance::FRUSTUM_MARGIN_PX));
                assert!(
                    n >= 3 && n * 20 >= cells,
                    "{case}: {n} of {cells} cells left out"
                );
                // Cells in view that one order splits and the other not.
                let camera = zoovr::camera::Camera::fit(scene.mesh.bounds(), &params);
                let in_view: Vec<bool> = {
                    let mut out = Vec::new();
                    zoovr::visibility::frustum::outside_cells(&camera, &scene.mesh, 1.0, &mut out);
                    out.iter().map(|o| !o).collect()
                };
                let differs: Vec<bool> = (0..cells)
                    .map(|c| in_view[c] && split_a[c] != split_b[c])
                    .collect();
                let k = differs.iter().filter(|&&d| d).count();
                if split_all {
                    assert_eq!(k, 0, "{case}");
                }
                split_differs += k;
                let mask = render_util::split_mask(&scene, &camera, &differs);
                let (d, at) = render_util::max_outside(&culled, &all, &mask);
                assert!(
                    d <= 1e-6,
                    "{case}: {d} at {at:?} ({k} cells split differently)"
                );
                let lit = all.pixels.iter().filter(|p| p[3] > 0.05).count();
                assert!(lit > 200, "{case}: {lit} lit pixels");
                // Shrunk by 14 pixels: cells seen near the image's edges go.
                let (wrong, m, _) = frame(Some(-14.0));
                assert!(m > n, "{case}");
                let (d, _) = compare_float(&wrong, &all).unwrap();
                assert!(
                    d.max_abs > 0.01,
                    "{case}: culling visible cells went unseen"
                );
            }
        }
    }
    // The whole-cell exception is the one measured above, not the rule.
    assert!(
        split_differs < 100,
        "{split_differs} cells split differently"
    );
}

/// A warped grid whose field rises with depth along `camera`'s view: the
/// front layer (the lowest third of the values) is opaque.
fn front_opaque_scene(camera_params: &zoovr::camera::CameraParams) -> Scene {
    let mut mesh = warped_hex_grid(
        14,
        &Warp {
            amplitude: 0.08,
            seed: 5,
        },
    );
    let camera = zoovr::camera::Camera::fit(mesh.bounds(), camera_params);
    let depth: Vec<f64> = mesh.points.iter().map(|&p| camera.to_view(p).z).collect();
    let (lo, hi) = depth
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &d| (a.min(d), b.max(d)));
    let f = mesh
        .point_data
        .iter_mut()
        .find(|a| a.name == "f")
        .expect("generated field");
    f.data = zoovr::field::ArrayData::F64(depth.iter().map(|d| (d - lo) / (hi - lo)).collect());
    f.vtk_type = "Float64".into();
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(0.0, [400.0]), (0.3, [400.0]), (0.35, [2.0]), (1.0, [3.0])],
        &[
            (0.0, [0.9, 0.3, 0.2]),
            (0.5, [0.2, 0.8, 0.3]),
            (1.0, [0.2, 0.3, 1.0]),
        ],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    scene
}

#[test]
fn pieces_behind_opaque_ones_are_left_out_and_the_image_is_unchanged() {
    for (ortho, azimuth, elevation) in [
        (false, 30.0, 20.0),
        (true, 200.0, -35.0),
        (false, 110.0, 60.0),
    ] {
        let params = zoovr::camera::CameraParams {
            width: 48,
            height: 40,
            azimuth,
            elevation,
            ortho,
            ..Default::default()
        };
        let scene = front_opaque_scene(&params);
        let shading = scene.shading();
        let mut renderer = Renderer::new(scene.geometry());
        let runs = [
            (Mode::Exact, false),
            (Mode::Exact, true),
            (Mode::ExactFrag, false),
            (Mode::Preint2d, false),
        ];
        for (mode, split_all) in runs {
            let case = format!("ortho {ortho} azimuth {azimuth} {mode:?} split all {split_all}");
            let mut frame = |occlusion: Option<f64>| {
                let opts = RenderOptions {
                    mode,
                    camera: params,
                    projected: ProjectedOptions {
                        compositor: Compositor::Cpu,
                        split_all,
                        occlusion,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let (img, stats) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
                let p = stats.projected().unwrap();
                (img, p.hidden_pieces, p.pieces)
            };
            let (all, none, pieces) = frame(None);
            assert_eq!(none, 0, "{case}");
            let (culled, hidden, _) =
                frame(Some(zoovr::numeric::tolerance::OCCLUSION_TRANSMITTANCE));
            eprintln!("{case}: {hidden} of {pieces} pieces hidden");
            assert!(
                hidden * 5 >= pieces,
                "{case}: {hidden} of {pieces} pieces hidden"
            );
            let (d, _) = compare_float(&culled, &all).unwrap();
            assert!(d.max_abs <= 1e-6, "{case}: {:e}", d.max_abs);
            let lit = all.pixels.iter().filter(|p| p[3] > 0.5).count();
            assert!(lit > 300, "{case}: {lit} lit pixels");
            // Hiding what lies behind half the light is visible.
            let (wrong, more, _) = frame(Some(0.5));
            assert!(more > hidden, "{case}");
            let (d, _) = compare_float(&wrong, &all).unwrap();
            assert!(
                d.max_abs > 0.01,
                "{case}: hiding visible pieces went unseen ({:e})",
                d.max_abs
            );
        }
    }
}

/// The min/max tree's whole nodes in the occlusion pass
/// (`render::cell_tree`): with the front opaque, the middle dark (so the
/// visible subset is drawn, and the pass maps its cells to the geometry's
/// tree) and the back translucent, the pass hides the same pieces with the
/// nodes as without, some through nodes, and the image is the same; a
/// wrong map from the subset's cells to the tree's would hide other
/// pieces.
#[test]
fn tree_nodes_hide_the_same_pieces_with_the_visible_subset() {
    for (ortho, azimuth, elevation) in [(false, 30.0, 20.0), (true, 200.0, -35.0)] {
        let params = zoovr::camera::CameraParams {
            width: 96,
            height: 80,
            azimuth,
            elevation,
            ortho,
            ..Default::default()
        };
        let mut scene = front_opaque_scene(&params);
        scene.tf = TransferFunction::from_channels(
            &[
                (0.0, [400.0]),
                (0.4, [400.0]),
                (0.4, [0.0]),
                (0.9, [0.0]),
                (0.9, [3.0]),
                (1.0, [3.0]),
            ],
            &[(0.0, [0.9, 0.3, 0.2]), (1.0, [0.2, 0.3, 1.0])],
            None,
            EmissionModel::Glow,
        )
        .unwrap();
        let shading = scene.shading();
        let mut renderer = Renderer::new(scene.geometry());
        for mode in [Mode::Exact, Mode::ExactFrag] {
            let case = format!("ortho {ortho} azimuth {azimuth} {mode:?}");
            let mut frame = |occlusion: Option<f64>, tree: bool| {
                let opts = RenderOptions {
                    mode,
                    camera: params,
                    projected: ProjectedOptions {
                        compositor: Compositor::Cpu,
                        occlusion,
                        occlusion_tree: tree,
                        ..Default::default()
                    },
                    ..Default::default()
                };
                let (img, stats) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
                let p = stats.projected().unwrap().clone();
                (img, p)
            };
            let on = Some(zoovr::numeric::tolerance::OCCLUSION_TRANSMITTANCE);
            let (all, _) = frame(None, true);
            let (with, p_with) = frame(on, true);
            let (without, p_without) = frame(on, false);
            eprintln!(
                "{case}: {} dark cells left out, {} of {} pieces hidden, {} through {} nodes",
                p_with.dark_cells_left_out,
                p_with.hidden_pieces,
                p_with.pieces,
                p_with.hidden_by_nodes,
                p_with.occlusion_nodes_hidden
            );
            assert!(p_with.dark_cells_left_out > 0, "{case}");
            assert!(p_with.hidden_by_nodes > 0, "{case}");
            assert_eq!(p_without.hidden_by_nodes, 0, "{case}");
            assert_eq!(p_with.hidden_pieces, p_without.hidden_pieces, "{case}");
            let (d, _) = compare_float(&with, &without).unwrap();
            assert_eq!(d.max_abs, 0.0, "{case}");
            let (d, _) = compare_float(&with, &all).unwrap();
            assert!(d.max_abs <= 1e-6, "{case}: {:e}", d.max_abs);
        }
    }
}

/// A warped grid whose field is the distance from a point inside it, with
/// a transfer function whose extinction is `tau` everywhere: surfaces of
/// the field are closed, nested shells.
fn shells_scene(tau: f64) -> Scene {
    let mut mesh = warped_hex_grid(
        14,
        &Warp {
            amplitude: 0.08,
            seed: 7,
        },
    );
    let c = glam::DVec3::new(0.48, 0.52, 0.5);
    render_util::set_point_field(&mut mesh, |p| (p - c).length());
    let mut scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    scene.tf = TransferFunction::from_channels(
        &[(0.0, [tau]), (1.0, [tau])],
        &[(0.0, [0.9, 0.3, 0.2]), (1.0, [0.2, 0.3, 1.0])],
        None,
        EmissionModel::Glow,
    )
    .unwrap();
    scene
}

/// An opaque isosurface hides what lies behind it (LH's view-dependent
/// culling): a cell whose chord at a pixel centre enters below the value
/// and leaves above it (or the other way round, with a margin) credits that
/// centre as opaque, so the far half of a closed shell and the volume
/// behind it are left out, in every mode that mixes surfaces with the
/// volume, and the image is the same to 1e-6; in a frame of surfaces
/// alone, from `ALONE_MIN_OPAQUE` (8) opaque surfaces on (with fewer, such
/// a frame is cheaper to draw than the pass). A translucent surface and
/// RKE's blended mixing (which weighs surfaces down) hide nothing.
#[test]
fn pieces_behind_an_opaque_surface_are_left_out_and_the_image_is_unchanged() {
    use zoovr::render::iso::{parse_list, IsoMix, IsoOptions};
    for (ortho, azimuth, elevation) in [(false, 30.0, 20.0), (true, 200.0, -35.0)] {
        let params = zoovr::camera::CameraParams {
            width: 96,
            height: 80,
            azimuth,
            elevation,
            ortho,
            ..Default::default()
        };
        for (mode, alone, tau) in [
            (Mode::Iso, true, 0.0),
            (Mode::ExactFrag, false, 0.5),
            (Mode::Exact, false, 0.5),
            (Mode::ExactFrag, true, 0.5),
        ] {
            let scene = shells_scene(tau);
            let shading = scene.shading();
            let mut renderer = Renderer::new(scene.geometry());
            let stack = "0.1,0.14,0.18,0.22,0.26,0.3,0.34,0.38";
            assert_eq!(
                stack.split(',').count(),
                zoovr::render::occlusion::ALONE_MIN_OPAQUE
            );
            // (the list, the mixing, whether it hides with the volume and
            // alone)
            for (list, mix, hides, hides_alone) in [
                ("0.3", IsoMix::Exact, true, false),
                ("0.2:tf:1,0.35", IsoMix::Exact, true, false),
                (stack, IsoMix::Exact, true, true),
                ("0.3:tf:0.99", IsoMix::Exact, false, false),
                ("0.3", IsoMix::Blend, false, false),
            ] {
                if mix == IsoMix::Blend && mode == Mode::Exact {
                    continue;
                }
                let case = format!("ortho {ortho} {mode:?} alone {alone} --iso {list} {mix:?}");
                let mut frame = |occlusion: Option<f64>| {
                    let opts = RenderOptions {
                        mode,
                        camera: params,
                        projected: ProjectedOptions {
                            compositor: Compositor::Cpu,
                            occlusion,
                            ..Default::default()
                        },
                        iso: IsoOptions {
                            surfaces: parse_list(list).unwrap(),
                            alone,
                            mix,
                            ..Default::default()
                        },
                        ..Default::default()
                    };
                    let (img, stats) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
                    let p = stats.projected().unwrap();
                    (img, p.hidden_pieces, p.pieces)
                };
                let (all, none, pieces) = frame(None);
                assert_eq!(none, 0, "{case}");
                let (culled, hidden, _) =
                    frame(Some(zoovr::numeric::tolerance::OCCLUSION_TRANSMITTANCE));
                eprintln!("{case}: {hidden} of {pieces} pieces hidden");
                // The volume alone (optical depth 0.5 per unit, a unit
                // cube) hides nothing.
                if (hides && !alone) || (hides_alone && alone) {
                    assert!(hidden * 20 >= pieces, "{case}: {hidden} of {pieces}");
                } else {
                    assert_eq!(hidden, 0, "{case}");
                }
                let (d, _) = compare_float(&culled, &all).unwrap();
                assert!(d.max_abs <= 1e-6, "{case}: {:e}", d.max_abs);
                let lit = all.pixels.iter().filter(|p| p[3] > 0.5).count();
                assert!(lit > 200, "{case}: {lit} lit pixels");
            }
        }
    }
}
