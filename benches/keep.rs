//! What keeping a frame's triangles saves (`ProjectedOptions::keep_projection`,
//! `src/render/driver/kept.rs`): exact-frag and preint3d at 512 x 512 on the
//! hex_shell scene (shared data; a generated 40^3 warped grid without it),
//! bench_tf's camera. Prints, per mode, the frame that sorts and projects
//! (the order already cached, so projection and drawing only) and the
//! frame after a colour edit that draws the kept triangles, then criterion
//! times colour edits (alternating two colourings, every frame a kept one).
//!
//! Run: `cargo bench --bench keep`.

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::CameraParams;
use zoovr::render::{Mode, ProjectedOptions, RenderOptions, Renderer, Scene, Shading};
use zoovr::testdata::hex_shell_scene;
use zoovr::tf::TransferFunction;

fn scene() -> (&'static str, Scene) {
    if let Some(s) = hex_shell_scene() {
        return ("hex_shell", s);
    }
    zoovr::testdata::grid_40_scene()
}

/// `shading` with its colours rotated (extinction unchanged).
fn recoloured(shading: &Shading) -> Shading {
    let nodes: Vec<_> = shading
        .tf
        .nodes()
        .into_iter()
        .map(|mut n| {
            n.color = [n.color[1], n.color[2], n.color[0]];
            n
        })
        .collect();
    let mut s = shading.clone();
    s.tf = TransferFunction::from_nodes(&nodes, shading.tf.model()).expect("tf");
    s
}

fn bench(c: &mut Criterion) {
    let (name, scene) = scene();
    let base = scene.shading();
    let other = recoloured(&base);
    let mut g = c.benchmark_group("keep_projection");
    g.sample_size(10);
    for mode in [Mode::ExactFrag, Mode::Preint3d] {
        let opts = |keep: bool| RenderOptions {
            mode,
            camera: CameraParams {
                width: 512,
                height: 512,
                azimuth: 20.0,
                elevation: 35.0,
                zoom: 1.25,
                ..Default::default()
            },
            projected: ProjectedOptions {
                keep_projection: keep,
                ..Default::default()
            },
            ..Default::default()
        };
        let mut r = Renderer::new(scene.geometry());
        let mut frame = |s: &Shading, keep: bool| {
            let t = std::time::Instant::now();
            match r.render(s, &opts(keep), |_, _| {}) {
                Ok((_, st)) => {
                    let p = st.projected().expect("projected");
                    (t.elapsed().as_secs_f64(), p.projection_reused, p.triangles)
                }
                Err(e) => {
                    eprintln!("skipped: {e}");
                    (f64::NAN, false, 0)
                }
            }
        };
        // The first frame sorts and builds the table; the next ones reuse
        // the order and the table.
        frame(&base, false);
        let (fresh, _, tris) = frame(&other, false);
        frame(&base, true);
        let (kept, reused, _) = frame(&other, true);
        eprintln!(
            "{name} {mode:?} 512^2: colour edit {fresh:.3} s projecting ({tris} triangles), {kept:.3} s drawing the kept triangles (reused: {reused})"
        );
        if !reused {
            continue;
        }
        let mut flip = false;
        g.bench_function(format!("{name}_{mode:?}_kept"), |b| {
            b.iter(|| {
                flip = !flip;
                frame(if flip { &other } else { &base }, true)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
