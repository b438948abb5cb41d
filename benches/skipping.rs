//! What skipping dark pieces saves: the exact mode at 512 x 512 on the
//! Blunt Fin (shared data; a generated 40^3 grid without it), default
//! camera, with the default transfer function's colours and an extinction
//! that is zero below 90 % of the range (about nine pieces in ten dark),
//! pieces skipped (the default) and all drawn; and the default transfer
//! function for comparison. Prints pieces, skipped pieces and triangles of
//! each, then criterion times whole frames.
//!
//! Frustum culling (`zoovr::visibility::frustum`): the exact mode at 512 x
//! 512 zoomed 4x into the hex_shell scene (shared data; a generated 60^3
//! grid without it), cells outside the view left out before the sort (the
//! default) and kept. Each frame nudges the azimuth by 1e-6 degree so that
//! it sorts again (the renderer reuses the order of an unchanged view).
//!
//! Occlusion culling (`zoovr::render::occlusion`): the exact-frag mode at
//! 512 x 512 on the same scene with a transfer function opaque below 20 %
//! of the range (extinction 500 per unit length, the hex_shell's front
//! layer) and thin above, pieces hidden behind opaque ones left out (the
//! default), left out without the min/max tree's whole nodes, and drawn.
//!
//! Dark cells left out of the sort (`zoovr::render::visible`): the exact
//! mode at 512 x 512 on the generated 1M-hex grid, the default TF against
//! one dark below 90 % of the range (see `dark_cells`).
//!
//! Finding the dark cells with the min/max tree
//! (`zoovr::render::cell_tree`) against testing every cell: see
//! `dark_classify`.
//!
//! Run: `cargo bench --bench skipping` (one group: `-- occlusion`,
//! `-- dark_cells`, `-- dark_classify`).

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::io::{self, ReadOptions};
use zoovr::render::{Mode, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec, Shading};
use zoovr::testdata::{hex_shell_scene, shared_file};
use zoovr::tf::{EmissionModel, TransferFunction};

fn scene() -> (&'static str, Scene) {
    if let Some(p) = shared_file("bluntfin/bluntfin_converted.vts") {
        let mesh = io::read(&p, &ReadOptions::default()).expect("bluntfin");
        return (
            "bluntfin",
            Scene::build(mesh, &SceneSpec::default()).expect("scene"),
        );
    }
    zoovr::testdata::grid_40_scene()
}

/// The scene's shading with extinction only in the top tenth of the range.
fn narrow(shading: &Shading) -> Shading {
    let mut s = shading.clone();
    let (lo, hi) = s.range;
    let b = lo + 0.9 * (hi - lo);
    let tau = shading.tf.max_tau().max(1e-9);
    let c = |x: f64| shading.tf.color_at(x);
    s.tf = TransferFunction::from_channels(
        &[(lo, [0.0]), (b, [0.0]), (hi, [tau])],
        &[(lo, c(lo)), (b, c(b)), (hi, c(hi))],
        None,
        EmissionModel::Glow,
    )
    .expect("tf");
    s
}

fn bench(c: &mut Criterion) {
    let (name, scene) = scene();
    let full = scene.shading();
    let narrow = narrow(&full);
    let mut renderer = Renderer::new(scene.geometry());
    let opts = |skip: bool| RenderOptions {
        mode: Mode::Exact,
        camera: CameraParams {
            width: 512,
            height: 512,
            ..Default::default()
        },
        projected: ProjectedOptions {
            skip_invisible: skip,
            ..Default::default()
        },
        ..Default::default()
    };
    let cases = [
        ("full_tf", &full, true),
        ("narrow_tf_skip", &narrow, true),
        ("narrow_tf_all", &narrow, false),
    ];
    for (label, shading, skip) in cases {
        match renderer.render(shading, &opts(skip), |_, _| {}) {
            Ok((_, stats)) => {
                let p = stats.projected().expect("projected");
                eprintln!(
                    "{name} {label}: {} pieces, {} skipped, {} triangles, sort {:.3} s, project+draw {:.3} s, total {:.3} s",
                    p.pieces, p.culled_pieces, p.triangles, p.sort_s, p.project_s, stats.total_s
                );
            }
            Err(e) => {
                eprintln!("skipped: {e}");
                return;
            }
        }
    }
    let mut g = c.benchmark_group("skip_invisible");
    g.sample_size(10);
    for (label, shading, skip) in cases {
        g.bench_function(format!("{name}_{label}"), |b| {
            b.iter(|| {
                renderer
                    .render(shading, &opts(skip), |_, _| {})
                    .expect("render")
            })
        });
    }
    g.finish();
}

fn frustum_scene() -> (&'static str, Scene) {
    if let Some(scene) = hex_shell_scene() {
        return ("hex_shell", scene);
    }
    let mesh = warped_hex_grid(
        60,
        &Warp {
            amplitude: 0.05,
            seed: 1,
        },
    );
    (
        "grid_60",
        Scene::build(mesh, &SceneSpec::default()).expect("scene"),
    )
}

fn frustum(c: &mut Criterion) {
    let (name, scene) = frustum_scene();
    let shading = scene.shading();
    let mut renderer = Renderer::new(scene.geometry());
    let opts = |nudge: bool| RenderOptions {
        mode: Mode::Exact,
        camera: CameraParams {
            width: 512,
            height: 512,
            azimuth: 20.0 + if nudge { 1e-6 } else { 0.0 },
            elevation: 35.0,
            zoom: 4.0,
            ..Default::default()
        },
        ..Default::default()
    };
    let default_margin = renderer.sorter().frustum_margin;
    let mut g = c.benchmark_group("frustum");
    g.sample_size(10);
    for (label, margin) in [("culled", default_margin), ("kept", None)] {
        renderer.sorter().frustum_margin = margin;
        match renderer.render(&shading, &opts(false), |_, _| {}) {
            Ok((_, stats)) => {
                let p = stats.projected().expect("projected");
                eprintln!(
                    "{name} zoom 4 {label}: {} cells outside the view, {} pieces, {} triangles, sort {:.3} s (classify {:.3} s), project+draw {:.3} s, total {:.3} s",
                    p.order.frustum_culled,
                    p.pieces,
                    p.triangles,
                    p.sort_s,
                    p.order.time_classify.as_secs_f64(),
                    p.project_s,
                    stats.total_s
                );
            }
            Err(e) => {
                eprintln!("skipped: {e}");
                return;
            }
        }
        let mut nudge = false;
        g.bench_function(format!("{name}_zoom4_{label}"), |b| {
            b.iter(|| {
                nudge = !nudge;
                renderer
                    .render(&shading, &opts(nudge), |_, _| {})
                    .expect("render")
            })
        });
    }
    g.finish();
}

/// Opaque (extinction 500 per unit length) below 20 % of the range, thin
/// (10) above 25 %.
fn opaque_front(shading: &Shading) -> Shading {
    let (lo, hi) = shading.range;
    let at = |x: f64| lo + (hi - lo) * x;
    let mut out = shading.clone();
    out.tf = TransferFunction::from_channels(
        &[
            (at(0.0), [500.0]),
            (at(0.2), [500.0]),
            (at(0.25), [10.0]),
            (at(1.0), [10.0]),
        ],
        &[(at(0.0), [0.2, 0.3, 0.9]), (at(1.0), [1.0, 0.6, 0.1])],
        None,
        EmissionModel::Glow,
    )
    .expect("tf");
    out
}

fn occlusion(c: &mut Criterion) {
    let (name, scene) = frustum_scene();
    let shading = opaque_front(&scene.shading());
    let mut renderer = Renderer::new(scene.geometry());
    let opts = |occlusion: Option<f64>, tree: bool| RenderOptions {
        mode: Mode::ExactFrag,
        camera: CameraParams {
            width: 512,
            height: 512,
            azimuth: 20.0,
            elevation: 35.0,
            zoom: 1.25,
            ..Default::default()
        },
        projected: ProjectedOptions {
            occlusion,
            occlusion_tree: tree,
            ..Default::default()
        },
        ..Default::default()
    };
    let on = ProjectedOptions::default().occlusion;
    // The pass with and without the tree's whole nodes, alternated (6
    // pairs): the median pass time of each (criterion's frame times are
    // too coarse for a pass of a tenth of a second).
    let mut pass = |tree: bool| {
        let (_, stats) = renderer.render(&shading, &opts(on, tree), |_, _| {}).ok()?;
        Some(stats.projected()?.occlusion_s)
    };
    let (mut with, mut without) = (Vec::new(), Vec::new());
    for k in 0..6 {
        let order = if k % 2 == 0 {
            [true, false]
        } else {
            [false, true]
        };
        for tree in order {
            let v = if tree { &mut with } else { &mut without };
            v.extend(pass(tree));
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    eprintln!(
        "{name} opaque front: occlusion pass {:.4} s with the tree, {:.4} s without (medians of 6)",
        median(with),
        median(without)
    );
    let mut g = c.benchmark_group("occlusion");
    g.sample_size(10);
    for (label, occ, tree) in [
        ("hidden_left_out", on, true),
        ("hidden_left_out_no_tree", on, false),
        ("all_drawn", None, false),
    ] {
        match renderer.render(&shading, &opts(occ, tree), |_, _| {}) {
            Ok((_, stats)) => {
                let p = stats.projected().expect("projected");
                eprintln!(
                    "{name} opaque front {label}: {} of {} pieces hidden ({} through {} tree nodes; pass {:.3} s), {} triangles, project+draw {:.3} s, total {:.3} s",
                    p.hidden_pieces, p.pieces, p.hidden_by_nodes, p.occlusion_nodes_hidden, p.occlusion_s, p.triangles, p.project_s, stats.total_s
                );
            }
            Err(e) => {
                eprintln!("skipped: {e}");
                return;
            }
        }
        g.bench_function(format!("{name}_opaque_front_{label}"), |b| {
            b.iter(|| {
                renderer
                    .render(&shading, &opts(occ, tree), |_, _| {})
                    .expect("render")
            })
        });
    }
    g.finish();
}

/// Dark cells left out of the sort (`zoovr::render::visible`): the exact
/// mode at 512 x 512 on the generated 1M-hex grid (100^3 warped cells),
/// the default TF against one dark below 90 % of the range, with the dark
/// cells left out of the sort (the default), only their pieces skipped,
/// and nothing skipped. Each frame nudges the azimuth by 1e-6 degree so
/// that it sorts again, as a new view does (the subset itself is reused
/// while the field and the TF's darkness hold).
fn dark_cells(c: &mut Criterion) {
    let mesh = warped_hex_grid(
        100,
        &Warp {
            amplitude: 0.05,
            seed: 1,
        },
    );
    let scene = Scene::build(mesh, &SceneSpec::default()).expect("scene");
    let full = scene.shading();
    let narrow = narrow(&full);
    let mut renderer = Renderer::new(scene.geometry());
    let opts = |nudge: bool, skip: bool, subset: bool| RenderOptions {
        mode: Mode::Exact,
        camera: CameraParams {
            width: 512,
            height: 512,
            azimuth: if nudge { 1e-6 } else { 0.0 },
            ..Default::default()
        },
        projected: ProjectedOptions {
            skip_invisible: skip,
            dark_subset: subset,
            ..Default::default()
        },
        ..Default::default()
    };
    let cases = [
        ("full_tf", &full, true, true),
        ("narrow_tf_left_out", &narrow, true, true),
        ("narrow_tf_pieces_skipped", &narrow, true, false),
        ("narrow_tf_all", &narrow, false, false),
    ];
    let mut g = c.benchmark_group("dark_cells");
    g.sample_size(10);
    for (label, shading, skip, subset) in cases {
        match renderer.render(shading, &opts(false, skip, subset), |_, _| {}) {
            Ok((_, stats)) => {
                let p = stats.projected().expect("projected");
                eprintln!(
                    "grid_100 {label}: {} dark cells left out (subset {:.3} s), {} pieces, {} skipped, {} triangles, sort {:.3} s, project+draw {:.3} s, total {:.3} s",
                    p.dark_cells_left_out, p.visible_subset_s, p.pieces, p.culled_pieces, p.triangles, p.sort_s, p.project_s, stats.total_s
                );
            }
            Err(e) => {
                eprintln!("skipped: {e}");
                return;
            }
        }
        let mut nudge = false;
        g.bench_function(format!("grid_100_{label}"), |b| {
            b.iter(|| {
                nudge = !nudge;
                renderer
                    .render(shading, &opts(nudge, skip, subset), |_, _| {})
                    .expect("render")
            })
        });
    }
    g.finish();
}

/// Finding the dark cells (`zoovr::render::cell_tree`): on the generated
/// 1M-hex grid, the min/max tree's walk against a test of every cell,
/// for transfer functions visible on 5 % and on 50 % of the range (the
/// cells' ranges are kept per field either way; building them and the
/// tree is timed once and printed).
fn dark_classify(c: &mut Criterion) {
    use zoovr::render::cell_tree::{CellRanges, CellTree};
    use zoovr::render::pieces::dark_range;
    let mesh = warped_hex_grid(
        100,
        &Warp {
            amplitude: 0.05,
            seed: 1,
        },
    );
    let scene = Scene::build(mesh, &SceneSpec::default()).expect("scene");
    let t0 = std::time::Instant::now();
    let tree = CellTree::build(&scene.mesh);
    let t1 = std::time::Instant::now();
    let ranges = CellRanges::build(&tree, &scene.mesh, scene.scalars());
    eprintln!(
        "1M hexes: tree built in {:.3} s, ranges in {:.3} s, {} nodes",
        (t1 - t0).as_secs_f64(),
        t1.elapsed().as_secs_f64(),
        tree.nodes.len()
    );
    let (lo, hi) = scene.shading().tf.scalar_range();
    let mut g = c.benchmark_group("dark_classify");
    g.sample_size(10);
    for frac in [0.05, 0.5] {
        let a = lo + (hi - lo) * 0.4;
        let w = (hi - lo) * frac;
        let tf = TransferFunction::from_channels(
            &[(a, [0.0]), (a + w * 0.5, [5.0]), (a + w, [0.0])],
            &[(lo, [0.2, 0.4, 0.9]), (hi, [1.0, 0.5, 0.1])],
            None,
            EmissionModel::Glow,
        )
        .expect("tf");
        let test = |l: f64, h: f64| dark_range(&tf, None, true, l, h);
        let (dark, stats) = tree.classify(&ranges, &test);
        eprintln!(
            "band {frac}: {} visible cells; tree: {} of {} nodes visited, {} cells tested",
            dark.iter().filter(|&&d| !d).count(),
            stats.nodes_visited,
            stats.nodes,
            stats.cells_tested
        );
        g.bench_function(format!("grid_100_band_{frac}_tree"), |b| {
            b.iter(|| tree.classify(&ranges, &test))
        });
        g.bench_function(format!("grid_100_band_{frac}_every_cell"), |b| {
            b.iter(|| {
                use rayon::prelude::*;
                ranges
                    .cell
                    .par_iter()
                    .map(|&(l, h)| test(l, h))
                    .collect::<Vec<bool>>()
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    bench,
    frustum,
    occlusion,
    dark_cells,
    dark_classify
);
criterion_main!(benches);
