//! Pre-integration tables of the table modes: build time per method and
//! resolution, and the error of each table mode against the exact integral
//! as a function of resolution (printed once, before the timings).
//!
//! `cargo bench --bench tables`. Transfer functions built in code (a
//! 7-node TF with a jump, extinction up to 8 per unit length; and the
//! default viridis/ramp TF); segments from a fixed-seed generator. Build
//! times are wall times (the GPU build: dispatch into the table's buffer
//! and the wait for the device; the CPU builds on all cores). The error
//! curve uses each mode's CPU twin (`f32`, the shader's arithmetic) at
//! 20000 random segments `(s_f, s_b, l)`, `s in [0, 1]`,
//! `l in [0, l_max]`, against `integrate::segment` in `f64`: the max and
//! RMS over the four premultiplied channels.

mod common;

use common::{jump_tf, Rng};

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use zoovr::gpu::{Context, GpuOptions, Table};
use zoovr::integrate::table2d::{Table2d, Table2dKind};
use zoovr::integrate::{self};
use zoovr::render::modes::preint::{preint_segment, CpuTable, LookupFn, PreintParams};
use zoovr::render::modes::preint_tables::{fill_cpu, gpu_build, TableKind, TableSpec};
use zoovr::render::modes::{preint2d, preint2d_cyl, preint3d};
use zoovr::render::TableBuild;
use zoovr::tf::TransferFunction;

const L_MAX: f64 = 1.0;

/// `(max, rms)` of a lookup against the exact integral.
fn error(tf: &TransferFunction, lookup: impl Fn(f32, f32, f32) -> [f32; 4]) -> (f64, f64) {
    let mut r = Rng(0x1234_5678_9ABC_DEF1);
    let (mut max, mut sq, n) = (0.0f64, 0.0f64, 20_000);
    for _ in 0..n {
        let (sf, sb, l) = (r.next(), r.next(), r.next() * L_MAX);
        let e = integrate::segment(tf, l, sf, sb);
        let want = [e.color[0], e.color[1], e.color[2], e.alpha];
        let got = lookup(sf as f32, sb as f32, l as f32);
        for k in 0..4 {
            let d = (got[k] as f64 - want[k]).abs();
            max = max.max(d);
            sq += d * d / 4.0;
        }
    }
    (max, (sq / n as f64).sqrt())
}

fn mode_error(tf: &TransferFunction, kind: TableKind, n: u32) -> (f64, f64) {
    // The 2D table's reference length: the mean of the lengths sampled.
    let l = if kind == TableKind::Flat {
        0.5 * L_MAX
    } else {
        L_MAX
    };
    let spec = TableSpec::new(kind, Some(n), l).unwrap();
    let mut data = vec![0.0; 4 * spec.texels()];
    fill_cpu(
        &spec,
        tf,
        TableBuild::Exact,
        (f64::NEG_INFINITY, f64::INFINITY),
        &mut data,
    );
    let t = CpuTable {
        size: spec.size,
        data,
    };
    let p = PreintParams::new(tf, &spec);
    let lookup: LookupFn = match kind {
        TableKind::Cube => preint3d::table_rgba,
        TableKind::Flat => preint2d::table_rgba,
        TableKind::Cylinder => preint2d_cyl::table_rgba,
    };
    error(tf, |sf, sb, l| {
        preint_segment(&p, &t, lookup, true, sf, sb, l)
    })
}

fn print_error_curve() {
    eprintln!("error against the exact integral (20000 segments, l in [0, 1]):");
    eprintln!("| TF | table mode | N | texels | max | RMS |");
    eprintln!("| --- | --- | --- | --- | --- | --- |");
    for (name, tf) in [
        ("jump", jump_tf()),
        ("default", TransferFunction::default_for((0.0, 1.0), 10.0)),
    ] {
        for (kind, mode, sizes) in [
            (TableKind::Cube, "preint3d", &[16u32, 32, 64, 128][..]),
            (TableKind::Cylinder, "preint2d-cyl", &[16, 32, 64, 128][..]),
            (TableKind::Flat, "preint2d", &[64, 256, 512, 1024][..]),
        ] {
            for &n in sizes {
                let (max, rms) = mode_error(&tf, kind, n);
                let texels: u64 = kind.extent(n).iter().map(|&v| v as u64).product();
                eprintln!("| {name} | {mode} | {n} | {texels} | {max:.2e} | {rms:.2e} |");
            }
        }
        // RKE's literal 2D approximation (colour and opacity linear in
        // l / l_ref), for comparison with preint2d's scaling.
        for n in [256usize, 1024] {
            let t = Table2d::new(&tf, n, (0.0, 1.0), 0.5 * L_MAX, Table2dKind::LinearInL).unwrap();
            let (max, rms) = error(&tf, |sf, sb, l| {
                t.lookup(sf as f64, sb as f64, l as f64).map(|v| v as f32)
            });
            eprintln!(
                "| {name} | RKE 2D linear in l | {n} | {} | {max:.2e} | {rms:.2e} |",
                n * n
            );
        }
    }
}

fn builds(c: &mut Criterion) {
    print_error_curve();
    let tf = jump_tf();
    let gpu = Context::new(&GpuOptions::default()).ok();
    let mut g = c.benchmark_group("table build");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(3));
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    for (kind, sizes) in [
        (TableKind::Cube, &[32u32, 64, 128][..]),
        (TableKind::Cylinder, &[64, 128][..]),
        (TableKind::Flat, &[512][..]),
    ] {
        for &n in sizes {
            let spec = TableSpec::new(kind, Some(n), L_MAX).unwrap();
            let label = format!("{kind:?} {n}");
            for method in [TableBuild::Exact, TableBuild::Fast] {
                let mut data = vec![0.0; 4 * spec.texels()];
                g.bench_with_input(BenchmarkId::new(method.name(), &label), &spec, |b, spec| {
                    b.iter(|| fill_cpu(spec, &tf, method, all, &mut data))
                });
            }
            if let Some(ctx) = &gpu {
                let table = Table::empty_rgba(ctx, "bench", kind.dim(), spec.size).unwrap();
                // Compile the kernel once before timing.
                gpu_build(ctx, &spec, &tf, all, &table).unwrap();
                ctx.finish().unwrap();
                g.bench_with_input(BenchmarkId::new("gpu", &label), &spec, |b, spec| {
                    b.iter_custom(|iters| {
                        let t0 = Instant::now();
                        for _ in 0..iters {
                            gpu_build(ctx, spec, &tf, all, &table).unwrap();
                            ctx.finish().unwrap();
                        }
                        t0.elapsed()
                    })
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, builds);
criterion_main!(benches);
