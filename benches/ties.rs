//! What the exact tie decisions cost ([`zoovr::render::ProjectedOptions::exact_ties`],
//! `src/render/ties.rs`): the exact mode on the hex_shell scene
//! (`synthetic/hex_shell_zlib.vtu`, bench_tf.json, azimuth 20, elevation
//! 35, zoom 1.25, perspective; a generated 40^3 warped grid without the
//! shared data) at 512 x 512, with the centres next to each part's outline
//! decided on the exact geometry (the default) and left to the
//! rasteriser. Prints the tie pixels and stage times of one frame of each,
//! then criterion times whole frames (the visibility order is reused
//! between frames of one camera, so the figures are projection, payload,
//! ties and drawing).
//!
//! Run: `cargo bench --bench ties`.

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::io::{self, ReadOptions};
use zoovr::render::{Mode, ProjectedOptions, RenderOptions, Renderer, Scene, SceneSpec};
use zoovr::testdata::shared_file;

fn scene() -> (&'static str, Scene, CameraParams) {
    let camera = CameraParams {
        width: 512,
        height: 512,
        azimuth: 20.0,
        elevation: 35.0,
        zoom: 1.25,
        ..Default::default()
    };
    if let (Some(p), Some(tf)) = (
        shared_file("synthetic/hex_shell_zlib.vtu"),
        shared_file("synthetic/bench_tf.json"),
    ) {
        let mesh = io::read(&p, &ReadOptions::default()).expect("hex_shell");
        let spec = SceneSpec {
            tf_file: Some(tf),
            ..Default::default()
        };
        return (
            "hex_shell",
            Scene::build(mesh, &spec).expect("scene"),
            camera,
        );
    }
    let mesh = warped_hex_grid(
        40,
        &Warp {
            amplitude: 0.05,
            seed: 1,
        },
    );
    (
        "grid_40",
        Scene::build(mesh, &SceneSpec::default()).expect("scene"),
        camera,
    )
}

fn bench(c: &mut Criterion) {
    let (name, scene, camera) = scene();
    let shading = scene.shading();
    let mut renderer = Renderer::new(scene.geometry());
    let opts = |ties: bool| RenderOptions {
        mode: Mode::Exact,
        camera,
        projected: ProjectedOptions {
            exact_ties: ties,
            ..Default::default()
        },
        ..Default::default()
    };
    for ties in [true, false] {
        match renderer.render(&shading, &opts(ties), |_, _| {}) {
            Ok((_, stats)) => {
                let p = stats.projected().expect("projected");
                eprintln!(
                    "{name} exact_ties={ties}: {} tie pixels, {} triangles, sort {:.3} s, project+draw {:.3} s, total {:.3} s",
                    p.tie_pixels, p.triangles, p.sort_s, p.project_s, stats.total_s
                );
            }
            Err(e) => {
                eprintln!("skipped: {e}");
                return;
            }
        }
    }
    let mut g = c.benchmark_group("exact_ties");
    g.sample_size(10);
    for ties in [true, false] {
        let label = if ties { "on" } else { "off" };
        g.bench_function(format!("{name}_{label}"), |b| {
            b.iter(|| {
                renderer
                    .render(&shading, &opts(ties), |_, _| {})
                    .expect("render")
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
