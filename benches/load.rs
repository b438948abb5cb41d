//! Load + topology benchmarks: a generated warped 100^3 (1M) hex
//! grid in memory (`generate::warped_hex_grid(100, Warp::default())`, seed 1),
//! the same grid read back from a zlib `.vtu` written to a temp dir, and
//! `../shared/data/bluntfin/bluntfin_converted.vts` when present and
//! readable. Per-cell times are printed by `examples/gen_mesh` runs and in
//! the report; criterion reports the totals.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::generate::{warped_hex_grid, Warp};
use zoovr::io::writer::{write_vtu, Compression};
use zoovr::io::{read, ReadOptions};
use zoovr::mesh::report::MeshReport;
use zoovr::mesh::topology::Topology;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("load");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let mesh = warped_hex_grid(100, &Warp::default());
    g.bench_function("topology_1m_hex", |b| {
        b.iter(|| Topology::build(&mesh.cells))
    });
    let topo = Topology::build(&mesh.cells);
    g.bench_function("report_1m_hex", |b| {
        b.iter(|| MeshReport::compute_with(&mesh, &topo))
    });
    drop(topo);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("hex1m.vtu");
    if write_vtu(&path, &mesh, Compression::Zlib).is_ok()
        && read(&path, &ReadOptions::default()).is_ok()
    {
        g.bench_function("read_and_connect_1m_hex_vtu_zlib", |b| {
            b.iter(|| {
                let m = read(&path, &ReadOptions::default()).expect("read");
                Topology::build(&m.cells)
            })
        });
    } else {
        eprintln!("skipping read_and_connect_1m_hex_vtu_zlib: no .vtu reader yet");
    }
    drop(mesh);
    if let Some(p) = zoovr::testdata::shared_file("bluntfin/bluntfin_converted.vts") {
        match read(&p, &ReadOptions::default()) {
            Ok(m) => {
                g.bench_function("read_and_connect_bluntfin", |b| {
                    b.iter(|| {
                        let m = read(&p, &ReadOptions::default()).expect("read");
                        Topology::build(&m.cells)
                    })
                });
                g.bench_function("report_bluntfin", |b| b.iter(|| MeshReport::compute(&m)));
            }
            Err(e) => eprintln!("skipping bluntfin: {e}"),
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
