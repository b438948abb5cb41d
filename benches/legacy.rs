//! Reader throughput for the legacy VTK and PLOT3D readers on the shared
//! real data (skipped when `../shared/data` is absent):
//! `synthetic/mixed.vtk` (4.2 binary, 196,800 mixed cells),
//! `angular_sector/AngularSector.vtk` (3.0 ASCII), `office_kitchen/kitchen.vtk`
//! (1.0 ASCII structured) and `bluntfin/bluntfinxyz.bin` + `bluntfinq.bin`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use zoovr::testdata::shared_file;

fn legacy(c: &mut Criterion) {
    let mut g = c.benchmark_group("legacy_read");
    g.sample_size(10);
    for rel in [
        "synthetic/mixed.vtk",
        "angular_sector/AngularSector.vtk",
        "office_kitchen/kitchen.vtk",
    ] {
        let Some(p) = shared_file(rel) else { continue };
        let bytes = std::fs::read(&p).unwrap();
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        g.bench_function(rel, |b| {
            b.iter(|| zoovr::io::legacy::read_bytes(&p, &bytes).unwrap())
        });
    }
    g.finish();
}

fn plot3d(c: &mut Criterion) {
    let (Some(x), Some(q)) = (
        shared_file("bluntfin/bluntfinxyz.bin"),
        shared_file("bluntfin/bluntfinq.bin"),
    ) else {
        return;
    };
    let (xb, qb) = (std::fs::read(&x).unwrap(), std::fs::read(&q).unwrap());
    let mut g = c.benchmark_group("plot3d_read");
    g.sample_size(10);
    g.throughput(Throughput::Bytes((xb.len() + qb.len()) as u64));
    g.bench_function("bluntfin xyz+q", |b| {
        b.iter(|| zoovr::io::plot3d::read_bytes(&x, &xb, Some((&q, &qb))).unwrap())
    });
    g.finish();
}

criterion_group!(benches, legacy, plot3d);
criterion_main!(benches);
