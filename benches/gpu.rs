//! Exact-mode compositor throughput: frames of 1e5 and 1e6 random small
//! triangles (fixed seed, perspective w, sides 1-6 px, random l, tau, glow),
//! pushed in chunks of 65 536 triangles, at 512^2 and 1024^2, on every backend
//! present (Vulkan lavapipe, GL llvmpipe), each with its automatic
//! accumulation format. Criterion times whole frames (begin, push, finish) of
//! the 1e5 cases (and of the 1e6 cases with `ZOOVR_BENCH_FULL=1`); for every
//! case a summary line gives wall and process CPU time per frame (the CPU
//! time includes the software driver's threads and is robust to a loaded
//! machine), triangles/s, and the split into upload, GPU wait and readback
//! (`FrameStats`). On lavapipe `queue.submit` rasterises synchronously, so
//! "upload" there includes drawing.
//!
//! Run: `cargo bench --bench gpu` (add `-- 1e5` to filter).
//!
//! Measured 2026-11-25 (Mesa 22.3.6, 2 cores shared with other builds, load
//! average ~20, so wall times are inflated ~3-4x; CPU time is the better
//! figure): 1e6 triangles per frame take 0.78 s CPU on lavapipe and 0.70 s
//! on llvmpipe GL (0.7-0.8 us per triangle, 512^2 and 1024^2 alike), wall
//! 2.6-3.3 s; 1e5 triangles 0.07-0.08 s CPU, wall 0.29-0.38 s. Readback:
//! 1-9 ms at 512^2, 8-53 ms at 1024^2 (f32 on Vulkan, f16 on GL).

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use zoovr::gpu::{AccumFormat, Backend, ClipMapper, Context, GpuOptions, GpuVertex};
use zoovr::render::modes::exact::{bind_exact_stage, ExactVertex};
use zoovr::testdata::Rng;

const CHUNK: usize = 1 << 16;

fn scene(count: usize, size: u32) -> Vec<ExactVertex> {
    let mut r = Rng(0x5eed_1234);
    let m = ClipMapper::new(size, size, false);
    let mut v = Vec::with_capacity(3 * count);
    for piece in 0..count {
        let cx = r.f64() * size as f64;
        let cy = r.f64() * size as f64;
        let s = 1.0 + 5.0 * r.f64();
        let glow = [r.f64() as f32, r.f64() as f32, r.f64() as f32];
        let tau = (0.1 + r.f64()) as f32;
        for _ in 0..3 {
            let p = m
                .clip(
                    cx + s * (r.f64() - 0.5),
                    cy + s * (r.f64() - 0.5),
                    1.0 + r.f64(),
                )
                .unwrap_or([0.0, 0.0, 0.5, 1.0]);
            // Every triangle a piece of its own (all are blended).
            v.push(ExactVertex::new(p, r.f64() as f32, tau, glow).with_piece(piece as u32));
        }
    }
    v
}

/// User + system CPU seconds of this process (all threads), from /proc.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

fn frame(ctx: &Context, verts: &[ExactVertex], idx: &[u32], size: u32) -> zoovr::gpu::FrameStats {
    let mut f = ctx
        .begin_frame(size, size, AccumFormat::Auto)
        .expect("frame");
    let stage = bind_exact_stage(ctx, 1.0).expect("stage");
    for chunk in verts.chunks(3 * CHUNK) {
        f.push_triangles(&stage, chunk, &idx[..chunk.len()])
            .expect("push");
    }
    f.finish_with_stats().expect("finish").1
}

fn bench(c: &mut Criterion) {
    let idx: Vec<u32> = (0..3 * CHUNK as u32).collect();
    for backend in [Backend::Vulkan, Backend::Gl] {
        let ctx = match Context::new(&GpuOptions {
            backend: Some(backend),
            cpu_adapter: false,
        }) {
            Ok(c) => c,
            Err(e) => {
                eprintln!("{backend}: skipped ({e})");
                continue;
            }
        };
        eprintln!("{backend}: {}", ctx.info());
        let mut group = c.benchmark_group(format!("exact_{backend}"));
        group.sample_size(10);
        group.measurement_time(Duration::from_secs(8));
        group.warm_up_time(Duration::from_secs(1));
        for count in [100_000usize, 1_000_000] {
            for size in [512u32, 1024] {
                let verts = scene(count, size);
                let name = format!(
                    "{}tri_{size}px",
                    if count == 100_000 { "1e5" } else { "1e6" }
                );
                if count == 100_000 || std::env::var_os("ZOOVR_BENCH_FULL").is_some() {
                    group.bench_function(&name, |b| b.iter(|| frame(&ctx, &verts, &idx, size)));
                }
                let reps = if count == 100_000 { 5 } else { 2 };
                let (t, c0) = (Instant::now(), cpu_seconds());
                let mut s = Vec::new();
                for _ in 0..reps {
                    s.push(frame(&ctx, &verts, &idx, size));
                }
                let wall = t.elapsed().as_secs_f64() / reps as f64;
                let cpu = (cpu_seconds() - c0) / reps as f64;
                let mean = |f: fn(&zoovr::gpu::FrameStats) -> f64| {
                    s.iter().map(f).sum::<f64>() / reps as f64
                };
                eprintln!(
                    "{backend} {name}: {wall:.3} s/frame wall, {cpu:.3} s CPU, {:.2e} tri/s; \
                     upload {:.3} s, gpu wait {:.3} s, readback {:.4} s, {} batches",
                    count as f64 / wall,
                    mean(|x| x.upload_s),
                    mean(|x| x.gpu_wait_s),
                    mean(|x| x.readback_s),
                    s[0].batches
                );
            }
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
