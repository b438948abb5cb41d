//! What the exact tie decisions cost ([`zoovr::render::ProjectedOptions::exact_ties`],
//! `src/render/ties/`): the exact mode on the hex_shell scene
//! (`synthetic/hex_shell_zlib.vtu`, bench_tf.json, azimuth 20, elevation
//! 35, zoom 1.25, perspective; a generated 40^3 warped grid without the
//! shared data) at 512 x 512, with the centres next to each part's outline
//! decided on the exact geometry (the default) and left to the
//! rasteriser. Prints the tie pixels and stage times of one frame of each,
//! then criterion times whole frames (the visibility order is reused
//! between frames of one camera, so the figures are projection, payload,
//! ties and drawing). Before criterion, `TIES_PAIRS` (default 6) pairs of
//! frames with and without the decisions, alternated, give the median
//! wall and process CPU time of each and of their ratio: the figure to
//! quote on a shared, noisy machine. `TIES_ONLY=on` (or `off`) renders
//! `TIES_PAIRS` frames of that kind only and exits, for a profiler.
//! `TIES_SIZE=1024` renders 1024 x 1024 instead.
//!
//! Run: `cargo bench --bench ties`.

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::CameraParams;
use zoovr::render::{Mode, ProjectedOptions, RenderOptions, Renderer, Scene};
use zoovr::testdata::hex_shell_scene;

fn scene() -> (&'static str, Scene, CameraParams) {
    // `TIES_SIZE` (default 512) sets the image's width and height.
    let size = std::env::var("TIES_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(512);
    let camera = CameraParams {
        width: size,
        height: size,
        azimuth: 20.0,
        elevation: 35.0,
        zoom: 1.25,
        ..Default::default()
    };
    if let Some(scene) = hex_shell_scene() {
        return ("hex_shell", scene, camera);
    }
    let (name, scene) = zoovr::testdata::grid_40_scene();
    (name, scene, camera)
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
    paired(&mut renderer, &shading, &opts);
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

/// Frames with and without the decisions, alternated (`TIES_PAIRS` pairs,
/// default 6), so that drift of a shared, noisy machine falls on both
/// alike: prints the median wall and process CPU time of each and the
/// median of the pairs' ratios. Criterion's two groups run minutes apart,
/// which on the 2-core machines moved their ratio by several percent.
fn paired(
    renderer: &mut Renderer,
    shading: &zoovr::render::Shading,
    opts: &dyn Fn(bool) -> RenderOptions,
) {
    let pairs: usize = std::env::var("TIES_PAIRS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6);
    let cpu = || {
        let mut u: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: getrusage writes the struct it is given.
        unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
        let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
        t(u.ru_utime) + t(u.ru_stime)
    };
    let mut frame = |ties: bool| {
        let (w0, c0) = (std::time::Instant::now(), cpu());
        renderer
            .render(shading, &opts(ties), |_, _| {})
            .expect("render");
        (w0.elapsed().as_secs_f64(), cpu() - c0)
    };
    if let Ok(only) = std::env::var("TIES_ONLY") {
        for _ in 0..pairs {
            frame(only == "on");
        }
        std::process::exit(0);
    }
    let (mut on, mut off) = (Vec::new(), Vec::new());
    for k in 0..pairs {
        // Alternate which goes first.
        let (a, b) = if k % 2 == 0 {
            let a = frame(true);
            (a, frame(false))
        } else {
            let b = frame(false);
            (frame(true), b)
        };
        on.push(a);
        off.push(b);
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        (v[(n - 1) / 2] + v[n / 2]) / 2.0
    };
    let ratio =
        |f: fn(&(f64, f64)) -> f64| median(on.iter().zip(&off).map(|(a, b)| f(a) / f(b)).collect());
    eprintln!(
        "paired ({pairs} pairs): wall on {:.3} s, off {:.3} s, ratio {:.4}; cpu on {:.3} s, off {:.3} s, ratio {:.4}",
        median(on.iter().map(|p| p.0).collect()),
        median(off.iter().map(|p| p.0).collect()),
        ratio(|p| p.0),
        median(on.iter().map(|p| p.1).collect()),
        median(off.iter().map(|p| p.1).collect()),
        ratio(|p| p.1),
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
