//! A generated 5M-cell mesh through the exact mode at 512 x 512:
//! streamed in GPU batches, bounded memory, no NaN. Too slow for CI (about
//! two minutes on 2 cores); run it by hand:
//! `cargo test --release --test large_mesh -- --ignored --nocapture`.
//! It prints the time per stage and the peak resident memory.

use zoovr::camera::CameraParams;
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::gpu::{Context, GpuOptions};
use zoovr::render::{Mode, RenderOptions, Renderer, Scene, SceneSpec};

/// Peak resident memory of this process in bytes.
#[cfg(unix)]
fn peak_rss() -> u64 {
    // SAFETY: getrusage writes into the zeroed struct we pass.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    u.ru_maxrss as u64 * 1024
}

#[cfg(unix)]
#[test]
#[ignore = "about two minutes and 6 GB: run by hand"]
fn five_million_hexes_at_512() {
    if let Err(e) = Context::new(&GpuOptions::default()) {
        eprintln!("skipping: no GPU adapter ({e})");
        return;
    }
    let t = std::time::Instant::now();
    let mesh = warped_hex_grid(171, &Warp::default());
    let cells = mesh.cells.len();
    assert!(cells >= 5_000_000);
    let scene = Scene::build(mesh, &SceneSpec::default()).unwrap();
    eprintln!("{cells} hexes generated and connected in {:?}", t.elapsed());
    let opts = RenderOptions {
        mode: Mode::Exact,
        camera: CameraParams {
            width: 512,
            height: 512,
            azimuth: 20.0,
            elevation: 35.0,
            ..Default::default()
        },
        ..Default::default()
    };
    let (img, stats) = Renderer::new(scene.geometry())
        .render(&scene.shading(), &opts, |_, _| {})
        .unwrap();
    assert_eq!(img.count_non_finite(), 0);
    assert!(img.pixels.iter().filter(|p| p[3] > 1e-3).count() > 10_000);
    let e = stats.projected().unwrap();
    let rss = peak_rss();
    eprintln!(
        "sort {:.1} s, project {:.1} s ({} triangles, {} batches), gpu {:.1} s, total {:.1} s; \
         peak RSS {:.2} GB ({:.0} bytes per cell)",
        e.sort_s,
        e.project_s,
        e.triangles,
        e.gpu.batches,
        e.gpu_total_s,
        stats.total_s,
        rss as f64 / 1e9,
        rss as f64 / cells as f64
    );
    assert!(e.gpu.batches > 1, "a mesh this size is streamed in batches");
    // Measured 1.1 kB per cell (the warped grid splits 2.5M problem cells
    // into tets); the bound catches a regression to unbounded buffers.
    assert!(rss < 2_000 * cells as u64, "peak RSS {rss} bytes");
}
