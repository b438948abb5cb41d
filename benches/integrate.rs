//! Benchmarks of the exact segment integral and the pre-integration table
//! fills. Fixed seeds; transfer functions built in code (the
//! default viridis/ramp TF over [0, 1] and a 7-node TF with a jump).
//!
//! `cargo bench --bench integrate`. Per-segment figures: the batch benches
//! integrate 4096 segments per iteration (throughput in elements).
//!
//! Measurement: CPU time, not wall time, because the build machine is
//! shared (load averages of 20 on 2 cores make wall times meaningless).
//! Segment benches use the calling thread's CPU time
//! (`CLOCK_THREAD_CPUTIME_ID`); table fills use the whole process's CPU time
//! over all rayon threads (`CLOCK_PROCESS_CPUTIME_ID`), i.e. core-seconds:
//! the wall time on `k` idle cores is about that divided by `k`. Off Unix
//! both fall back to wall time.

mod common;

use common::{jump_tf, Rng};

use std::time::Instant;

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use zoovr::integrate::fast::FastColour;
use zoovr::integrate::table3d::Table3d;
use zoovr::integrate::{self, cylinder::CylinderTable, weights};
use zoovr::tf::TransferFunction;

const BATCH: usize = 4096;

/// Which CPU clock a [`CpuTime`] measurement reads.
#[derive(Clone, Copy)]
enum Clock {
    Thread,
    Process,
}

/// Criterion measurement of CPU time in nanoseconds (see the module docs).
struct CpuTime {
    clock: Clock,
    wall: WallTime,
    origin: Instant,
}

impl CpuTime {
    fn new(clock: Clock) -> Self {
        Self {
            clock,
            wall: WallTime,
            origin: Instant::now(),
        }
    }

    #[cfg(unix)]
    fn now(&self) -> u64 {
        let id = match self.clock {
            Clock::Thread => libc::CLOCK_THREAD_CPUTIME_ID,
            Clock::Process => libc::CLOCK_PROCESS_CPUTIME_ID,
        };
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: clock_gettime writes one timespec through a valid pointer.
        if unsafe { libc::clock_gettime(id, &mut ts) } == 0 {
            ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
        } else {
            self.origin.elapsed().as_nanos() as u64
        }
    }

    #[cfg(not(unix))]
    fn now(&self) -> u64 {
        self.origin.elapsed().as_nanos() as u64
    }
}

impl Measurement for CpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        self.now()
    }
    fn end(&self, i: u64) -> u64 {
        self.now().saturating_sub(i)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        self.wall.formatter()
    }
}

fn segments(c: &mut Criterion<CpuTime>) {
    let tf = TransferFunction::default_for((0.0, 1.0), 1.0); // unit distance 0.1
    let br = {
        use zoovr::integrate::RayMaterial;
        tf.breakpoints().to_vec()
    };
    let mut r = Rng(7);
    // No breakpoint inside: both scalars within one piece; lengths give
    // depths across the small / erfcx / dawson / constant regimes.
    let inside: Vec<(f64, f64, f64)> = (0..BATCH)
        .map(|i| {
            let p = (r.next() * (br.len() - 1) as f64) as usize;
            let (lo, hi) = (br[p], br[p + 1]);
            let sf = lo + (hi - lo) * r.next();
            let sb = if i % 8 == 0 {
                sf
            } else {
                lo + (hi - lo) * r.next()
            };
            (10f64.powf(r.next() * 3.0 - 2.0), sf, sb)
        })
        .collect();
    let crossing: Vec<(f64, f64, f64)> = (0..BATCH)
        .map(|_| {
            (
                10f64.powf(r.next() * 3.0 - 2.0),
                0.3 * r.next(),
                0.7 + 0.3 * r.next(),
            )
        })
        .collect();
    let ab: Vec<(f64, f64)> = (0..BATCH)
        .map(|_| {
            (
                10f64.powf(r.next() * 5.0 - 2.0),
                10f64.powf(r.next() * 5.0 - 2.0),
            )
        })
        .collect();

    let mut g = c.benchmark_group("segment");
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("no_breakpoint_inside", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(l, sf, sb) in &inside {
                acc += integrate::segment(&tf, l, sf, sb).alpha;
            }
            black_box(acc)
        })
    });
    g.bench_function("crossing_about_4_breakpoints", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(l, sf, sb) in &crossing {
                acc += integrate::segment(&tf, l, sf, sb).alpha;
            }
            black_box(acc)
        })
    });
    g.bench_function("weights_only", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(a, bb) in &ab {
                acc += weights(a, bb).w_b;
            }
            black_box(acc)
        })
    });
    g.bench_function("vertex_values", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(l, sf, sb) in &inside {
                acc += integrate::vertex_values(&tf, l, sf, sb).glow[0];
            }
            black_box(acc)
        })
    });
    g.finish();
}

fn tables(c: &mut Criterion<CpuTime>) {
    let tf = jump_tf();
    let mut g = c.benchmark_group("table");
    g.sample_size(10);
    let (ns, nl) = (128usize, 64usize);
    g.bench_with_input(
        BenchmarkId::new("3d_exact", format!("{ns}x{ns}x{nl}")),
        &(ns, nl),
        |b, &(ns, nl)| b.iter(|| Table3d::exact(&tf, ns, nl, (0.0, 1.0), 1.0).expect("table")),
    );
    g.bench_with_input(
        BenchmarkId::new("3d_integral_functions", format!("{ns}x{ns}x{nl}")),
        &(ns, nl),
        |b, &(ns, nl)| {
            b.iter(|| {
                Table3d::fast(&tf, ns, nl, (0.0, 1.0), 1.0, FastColour::MeanGlow).expect("table")
            })
        },
    );
    // A TF edit confined to [0.9, 1.0] touches about 19% of the (s_f, s_b) pairs.
    let mut t = Table3d::exact(&tf, 128, 64, (0.0, 1.0), 1.0).expect("table");
    g.bench_function("3d_exact_local_update_0.9_1.0", |b| {
        b.iter(|| t.update(&tf, 0.9, 1.0))
    });
    g.bench_function("cylinder_exact_64x64x256", |b| {
        b.iter(|| CylinderTable::new(&tf, 64, 256, (0.0, 1.0), 1.0).expect("table"))
    });
    g.finish();
}

criterion_group! {
    name = segment_benches;
    config = Criterion::default().with_measurement(CpuTime::new(Clock::Thread));
    targets = segments
}
criterion_group! {
    name = table_benches;
    config = Criterion::default().with_measurement(CpuTime::new(Clock::Process));
    targets = tables
}
criterion_main!(segment_benches, table_benches);
