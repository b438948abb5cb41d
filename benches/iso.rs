//! Isosurfaces: frame time against the number of isovalues (1, 2, 10, 100,
//! spread over the field's range; translucent, and opaque, `-opaque`),
//! alone (`--mode iso`) and mixed with the
//! volume (`--iso` with exact-frag; the exact mode with surfaces draws
//! the same frame), on bluntfin (default field, TF and camera; skipped when the shared data is absent) and a generated 40^3
//! warped hex grid, at 512^2 on the default adapter. The fragment visits
//! only the isovalues its segment crosses, so the time should stay flat in
//! their number; `--mode iso` skips the pieces whose range holds no
//! isovalue (the saving is the full exact-frag frame against `iso` with one
//! value, also printed with the pieces culled).
//!
//! Run: `cargo bench --bench iso` (`-- bluntfin` to filter).
//!
//! Measured 2026-12-04 (Mesa llvmpipe/lavapipe, 2 cores): see the numbers
//! in the project notes of that day (ARCHITECTURE.md "Isosurfaces").

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::gpu::{Context, GpuOptions};
use zoovr::io::{self, ReadOptions};
use zoovr::render::iso::{IsoOptions, IsoSpec, Lighting, SideStyle};
use zoovr::render::{Mode, ModeStats, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::shared_file;

fn scenes() -> Vec<(&'static str, Scene)> {
    let mut out = Vec::new();
    if let Some(p) = shared_file("bluntfin/bluntfin_converted.vts") {
        let mesh = io::read(&p, &ReadOptions::default()).unwrap();
        out.push((
            "bluntfin",
            Scene::build(mesh, &SceneSpec::default()).unwrap(),
        ));
    }
    let mesh = warped_hex_grid(40, &Warp::default());
    out.push((
        "grid_64k",
        Scene::build(mesh, &SceneSpec::default()).unwrap(),
    ));
    out
}

/// `n` isovalues spread over `(lo, hi)`, of opacity `opacity` on both
/// sides.
fn isovalues(n: usize, (lo, hi): (f64, f64), opacity: f64) -> IsoOptions {
    IsoOptions {
        surfaces: (1..=n)
            .map(|k| IsoSpec {
                value: lo + (hi - lo) * k as f64 / (n + 1) as f64,
                front: SideStyle {
                    color: None,
                    opacity,
                },
                back: SideStyle {
                    color: None,
                    opacity,
                },
            })
            .collect(),
        lighting: Lighting::Smooth,
        alone: false,
        mix: Default::default(),
    }
}

fn options(mode: Mode, iso: IsoOptions) -> RenderOptions {
    RenderOptions {
        camera: CameraParams {
            azimuth: 20.0,
            elevation: 35.0,
            ..Default::default()
        },
        mode,
        iso,
        ..Default::default()
    }
}

fn bench(c: &mut Criterion) {
    if Context::new(&GpuOptions::default()).is_err() {
        eprintln!("no GPU adapter: skipped");
        return;
    }
    let mut group = c.benchmark_group("iso");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(6));
    for (name, scene) in scenes() {
        let mut r = Renderer::new(scene.geometry());
        let shading = scene.shading();
        // The skip: one isovalue alone against the full volume.
        for (label, opts) in [
            ("volume", options(Mode::ExactFrag, IsoOptions::default())),
            ("iso-1", options(Mode::Iso, isovalues(1, scene.range, 0.3))),
        ] {
            let (_, stats) = r.render(&shading, &opts, |_, _| {}).unwrap();
            if let ModeStats::Projected(p) = &stats.detail {
                eprintln!(
                    "{name} {label}: {:.3} s, {} pieces, {} culled, {} dark cells left out of the sort",
                    stats.total_s, p.pieces, p.culled_pieces, p.dark_cells_left_out
                );
            }
        }
        // Translucent (0.3), and opaque (the default style: pieces behind
        // the surfaces are left out, `render::occlusion`).
        for (opacity, suffix) in [(0.3, ""), (1.0, "-opaque")] {
            for mode in [Mode::Iso, Mode::ExactFrag] {
                for n in [1, 2, 10, 100] {
                    let opts = options(mode, isovalues(n, scene.range, opacity));
                    group.bench_function(format!("{name}/{mode}/{n}{suffix}"), |b| {
                        b.iter(|| r.render(&shading, &opts, |_, _| {}).unwrap())
                    });
                }
            }
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
