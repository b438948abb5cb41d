//! Visibility sort time per view on a generated 1M-hex grid (100^3, jittered
//! interior so faces are nonplanar), convex (planar boundary) and non-convex
//! (through-hole and cavity), with the problem-cell subdivision the view
//! needs, and without nonplanarity (no jitter: no problem cells); bluntfin
//! when the readers can load it. Fixed seeds; the views are fixed camera
//! angles at 512x512.

use std::sync::Arc;

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::mesh::Mesh;
use zoovr::visibility::synth::{grid, holed_grid, GridSpec};
use zoovr::visibility::{Sorter, SplitPolicy};

fn camera(mesh: &Mesh, k: usize, ortho: bool) -> Camera {
    let p = CameraParams {
        azimuth: 17.0 + 37.0 * k as f64,
        elevation: 23.0 - 11.0 * k as f64,
        ortho,
        ..Default::default()
    };
    Camera::fit(mesh.bounds(), &p)
}

fn bench_mesh(c: &mut Criterion, name: &str, mesh: Mesh) {
    let mesh = Arc::new(mesh);
    let topo = Topology::build(&mesh.cells);
    let mut sorter = Sorter::new(mesh.clone(), topo);
    let policy = SplitPolicy::default();
    // One report line with the stats of a typical view.
    let o = sorter
        .order(&camera(&mesh, 0, false), &policy)
        .expect("order");
    let s = &o.stats;
    eprintln!(
        "{name}: cells {} convex {} split {} problem faces {} nonconvex constraints {} \
         crossings {} fallbacks {} rounds {} cycles {} groups {} | classify {:?} split {:?} nonconvex {:?} sort {:?} total {:?}",
        s.cells,
        s.convex_boundary,
        s.split_cells,
        s.problem_faces,
        s.nonconvex_constraints,
        s.boundary_crossings,
        s.exact_fallbacks,
        s.rounds,
        s.cycles_found,
        s.cycle_groups,
        s.time_classify,
        s.time_split,
        s.time_nonconvex,
        s.time_sort,
        s.time_total
    );
    // CPU time of this thread per view (robust against a loaded machine);
    // the cameras are made first (fitting one reads every point).
    let views = 6;
    let cameras: Vec<Camera> = (0..views).map(|k| camera(&mesh, k, k % 2 == 1)).collect();
    let cpu0 = thread_cpu_seconds();
    let wall0 = std::time::Instant::now();
    let mut split = 0;
    for cam in &cameras {
        split += sorter.order(cam, &policy).expect("order").stats.split_cells;
    }
    if let (Some(a), Some(b)) = (cpu0, thread_cpu_seconds()) {
        let per = (b - a) / views as f64;
        eprintln!(
            "{name}: {views} views, thread CPU {:.1} ms/view ({:.2} M cells/s), wall {:.1} ms/view, mean split cells {}",
            per * 1e3,
            s.cells as f64 / per / 1e6,
            wall0.elapsed().as_secs_f64() * 1e3 / views as f64,
            split / views
        );
    }
    let mut g = c.benchmark_group(name);
    g.sample_size(10);
    let mut k = 0usize;
    g.bench_function("order_per_view", |b| {
        b.iter(|| {
            k += 1;
            sorter.order(&cameras[k % views], &policy).expect("order")
        })
    });
    g.finish();
}

/// User + system CPU seconds of the calling thread (Linux), if available.
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let after = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = after.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

fn visibility(c: &mut Criterion) {
    let n = std::env::var("ZOOVR_BENCH_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100usize);
    let planar = GridSpec {
        dims: [n, n, n],
        jitter: 0.0,
        seed: 1,
        planar_boundary: true,
    };
    let warped = GridSpec {
        jitter: 0.2,
        ..planar
    };
    bench_mesh(c, "grid_convex_planar_faces", grid(&planar, |_, _, _| true));
    bench_mesh(c, "grid_convex_warped", grid(&warped, |_, _, _| true));
    bench_mesh(c, "grid_nonconvex_planar_faces", holed_grid(&planar));
    bench_mesh(c, "grid_nonconvex_warped", holed_grid(&warped));
    if let Some(path) = zoovr::testdata::shared_file("bluntfin/bluntfin_converted.vts") {
        match zoovr::io::read(&path, &Default::default()) {
            Ok(mesh) => bench_mesh(c, "bluntfin", mesh),
            Err(e) => eprintln!("skipping bluntfin: {e}"),
        }
    }
}

criterion_group!(benches, visibility);
criterion_main!(benches);
