//! Every GPU mode end to end (`RENDER_BENCH_MODES=exact,exact-frag` picks),
//! with its error against the reference ray caster (`faces`, PNG values):
//! bluntfin (default field and TF), the hex_shell scene
//! (`synthetic/hex_shell_zlib.vtu`: 250,047 curvilinear hexahedra in a
//! twisted, C-shaped annular sector with nonplanar faces; bench_tf.json,
//! azimuth 20, elevation 35, zoom 1.25, perspective) and the generated
//! 1M-hex grid, at 512^2 and 1024^2, on every backend present (Vulkan
//! lavapipe with f32 accumulation, GL llvmpipe with f16). For every case one
//! frame is reported by stage (sort, project + integrals, GPU upload/draw,
//! wait, readback) with triangle counts; criterion then times whole frames
//! of bluntfin (the heavy scenes take seconds per frame; their per-frame
//! figure is the reported one). Skips scenes whose data is absent.
//!
//! Run: `cargo bench --bench render` (`-- bluntfin` to filter).
//!
//! exact-frag runs twice, as regions and with its pieces drawn whole
//! (`exact-frag-quads`, `--piece-draw quads`). Measured 2026-12-06
//! (lavapipe / GL, frame after the first, regions then quads): hex_shell
//! 512^2 1.16 / 1.22 s (projection 0.96 s) and 1.04 / 1.19 s (packing
//! 0.13 s, the rest the fragments' search); 1024^2 2.60 / 2.24 s and 2.73
//! / 2.20 s; bluntfin 512^2 0.34 / 0.30 s and 0.48 / 0.50 s (criterion);
//! grid_1m 512^2 5.64 / 7.30 s and 5.40 / 4.88 s, 1024^2 13.0 / 11.0 s and
//! 8.9 / 9.3 s. Errors: hex_shell RMS 1.55e-5 regions, 2.59e-6 quads (max
//! 4.2e-4 both). Since large pieces are drawn as their outline's hull
//! (`render::driver::whole`, later that day; paired whole-process runs,
//! hull against box): hex_shell 0.97 / 0.89 of those quad frames at 512^2
//! / 1024^2 on lavapipe (1.02 / 0.94 on GL), grid_1m 1.00 at 1024^2, the
//! images identical.
//!
//! Measured 2026-12-02 (Mesa 22.3.6, 2 idle cores), frame after the first
//! (Vulkan / GL): bluntfin 0.22 / 0.22 s at 512^2 (criterion), 0.39 / 0.39
//! s at 1024^2; hex_shell 2.24 / 2.31 s at 512^2 (2.95M triangles), 3.29 /
//! 3.34 s at 1024^2 (5.53M); grid_1m 4.15 / 4.15 s at 512^2 (9.69M), 6.12
//! / 6.32 s at 1024^2 (15.8M). Projection and integrals dominate (the draw
//! calls overlap them; GL's uploads take 0.7-4 s of that overlapped time).
//! Earlier the same day (before the chunk pipeline, the faster coverage
//! test and projection, the parallel sort stages): bluntfin 0.27 s,
//! hex_shell 3.32 s, grid_1m 5.28 s at 512^2. Before coverage culling
//! (2026-12-01): bluntfin 0.57 s, hex_shell 5.9 s (12.0M triangles),
//! grid_1m 6.7 s (20.5M).

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::gpu::{Backend, Context, GpuOptions};
use zoovr::image::compare_display;
use zoovr::io::{self, ReadOptions};
use zoovr::render::{Mode, PieceDraw, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::{hex_shell_scene, shared_file};

fn scenes() -> Vec<(&'static str, Scene, CameraParams)> {
    let mut out = Vec::new();
    if let Some(p) = shared_file("bluntfin/bluntfin_converted.vts") {
        let mesh = io::read(&p, &ReadOptions::default()).unwrap();
        out.push((
            "bluntfin",
            Scene::build(mesh, &SceneSpec::default()).unwrap(),
            CameraParams::default(),
        ));
    }
    if let Some(scene) = hex_shell_scene() {
        out.push((
            "hex_shell",
            scene,
            CameraParams {
                azimuth: 20.0,
                elevation: 35.0,
                zoom: 1.25,
                ..Default::default()
            },
        ));
    }
    let mesh = warped_hex_grid(100, &Warp::default());
    out.push((
        "grid_1m",
        Scene::build(mesh, &SceneSpec::default()).unwrap(),
        CameraParams {
            azimuth: 20.0,
            elevation: 35.0,
            ..Default::default()
        },
    ));
    out
}

fn backends() -> Vec<(&'static str, GpuOptions)> {
    [("vulkan", Backend::Vulkan), ("gl", Backend::Gl)]
        .into_iter()
        .map(|(n, b)| {
            (
                n,
                GpuOptions {
                    backend: Some(b),
                    cpu_adapter: false,
                },
            )
        })
        .filter(|(_, o)| Context::new(o).is_ok())
        .collect()
}

fn bench(c: &mut Criterion) {
    let backends = backends();
    if backends.is_empty() {
        eprintln!("no GPU adapter: nothing to bench");
        return;
    }
    // Every GPU volume mode of the registry (RENDER_BENCH_MODES=a,b to
    // pick; isosurfaces: benches/iso.rs).
    let picked = std::env::var("RENDER_BENCH_MODES").ok();
    let modes: Vec<Mode> = Mode::ALL
        .iter()
        .copied()
        .filter(|m| m.info().gpu && *m != Mode::Iso)
        .filter(|m| {
            picked
                .as_deref()
                .is_none_or(|p| p.split(',').any(|n| n == m.name()))
        })
        .collect();
    for (name, scene, cam) in scenes() {
        let mut renderer = Renderer::new(scene.geometry());
        let shading = scene.shading();
        for size in [512u32, 1024] {
            let camera = CameraParams {
                width: size,
                height: size,
                ..cam
            };
            // The reference image (faces model) for each mode's error.
            let reference = if name == "grid_1m" {
                None
            } else {
                let opts = RenderOptions {
                    camera,
                    mode: Mode::Raycast,
                    ..Default::default()
                };
                Some(renderer.render(&shading, &opts, |_, _| {}).unwrap().0)
            };
            // exact-frag both ways: regions, and whole-piece quads.
            let runs: Vec<(Mode, PieceDraw)> = modes
                .iter()
                .flat_map(|&m| {
                    let draws: &[PieceDraw] = if m == Mode::ExactFrag {
                        &[PieceDraw::Regions, PieceDraw::Quads]
                    } else {
                        &[PieceDraw::Auto]
                    };
                    draws.iter().map(move |&d| (m, d))
                })
                .collect();
            for &(bname, gpu) in &backends {
                for &(mode, draw) in &runs {
                    let opts = RenderOptions {
                        camera,
                        mode,
                        gpu,
                        projected: ProjectedOptions {
                            piece_draw: draw,
                            ..Default::default()
                        },
                        ..Default::default()
                    };
                    let mode = if draw == PieceDraw::Quads {
                        format!("{mode}-quads")
                    } else {
                        mode.to_string()
                    };
                    // The first frame builds the sorter and opens the device.
                    let (_, first) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
                    let (img, s) = renderer.render(&shading, &opts, |_, _| {}).unwrap();
                    let e = s.projected().unwrap();
                    let err = reference
                        .as_ref()
                        .map(|r| {
                            let (d, _) = compare_display(&img, r, [0.0; 3]).unwrap();
                            format!(
                                "max {:.2e} rms {:.2e} ({:.3}/255)",
                                d.max_abs,
                                d.rms,
                                d.rms * 255.0
                            )
                        })
                        .unwrap_or_default();
                    eprintln!(
                        "{name} {mode} {bname} {size}: frame {:.2} s (first {:.2} s) = sort {:.3} + project/payload {:.2} + gpu {:.2} (upload+draw {:.2}, wait {:.2}, readback {:.3}); {} pieces ({} whole), {} triangles, {} batches; error {err}",
                        s.total_s,
                        first.total_s,
                        e.sort_s,
                        e.project_s,
                        e.gpu_total_s,
                        e.gpu.upload_s,
                        e.gpu.gpu_wait_s,
                        e.gpu.readback_s,
                        e.pieces,
                        e.whole_pieces,
                        e.triangles,
                        e.gpu.batches
                    );
                    if name == "bluntfin" {
                        let mut g = c.benchmark_group(format!("{mode}/{name}/{bname}"));
                        g.sample_size(10).measurement_time(Duration::from_secs(8));
                        g.bench_function(format!("{size}"), |b| {
                            b.iter(|| renderer.render(&shading, &opts, |_, _| {}).unwrap())
                        });
                        g.finish();
                    }
                }
            }
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
