//! Ray caster benchmark: the `hex_shell` scene (the shared dataset
//! `synthetic/hex_shell_zlib.vtu`), generated in memory with the same map
//! and field as that file (64^3 points, 250,047 curvilinear hexahedra,
//! twisted 270-degree annular sector, point scalar `f` normalised to
//! [0, 1], coordinates rounded to f32 like the file), camera
//! azimuth 20, elevation 35, zoom 1.25, 512 x 512, and the transfer function
//! of `bench_tf.json` (extinction = opacity / 0.5, glow colour).
//!
//! `cargo bench --bench raycast` prints setup time and memory, then criterion
//! timings per frame for faces/tets x perspective/ortho and native
//! (`RAYCAST_BENCH_MODELS`, default `faces,tets,native`), then walk against
//! brute-force traversal (`raycast_walk_vs_brute`: perspective, models
//! `RAYCAST_BENCH_BRUTE_MODELS`, default `faces,tets`; the largest
//! difference between the two images is printed), then early ray
//! termination on and off on an opaque front layer
//! (`raycast_early_termination`; `RAYCAST_BENCH_TERMINATION=none` skips
//! it). `RAYCAST_BENCH_SIZE` sets the image size (default 512).

use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::DVec3;
use zoovr::camera::{Camera, CameraParams};
use zoovr::mesh::topology::Topology;
use zoovr::mesh::{CellKind, Cells, Mesh};
use zoovr::raycast::brute::Brute;
use zoovr::raycast::{FieldModel, RayTracer, RaycastOptions, Raycaster, Scalars, Scene};
use zoovr::tf::TransferFunction;

const N: usize = 64;

fn shell_map(u: f64, v: f64, w: f64) -> DVec3 {
    let (twist, sector) = (std::f64::consts::FRAC_PI_2, 1.5 * std::f64::consts::PI);
    let theta = sector * u;
    let pi = std::f64::consts::PI;
    let dr = (v - 0.5) + 0.04 * (3.0 * pi * w).sin() * (4.0 * pi * u).sin();
    let dz = (w - 0.5) * 0.8;
    let phi = twist * u;
    let r = 1.5 + dr * phi.cos() - dz * phi.sin();
    let z = dr * phi.sin() + dz * phi.cos();
    DVec3::new(r * theta.cos(), r * theta.sin(), z)
}

fn field(p: DVec3) -> f64 {
    const G: [([f64; 3], f64, f64); 5] = [
        ([1.5, 0.0, 0.0], 0.35, 1.0),
        ([0.0, 1.6, 0.1], 0.30, 0.9),
        ([-1.4, 0.3, -0.1], 0.45, 0.8),
        ([-0.2, -1.5, 0.0], 0.25, 1.0),
        ([1.0, 1.1, 0.2], 0.20, 0.7),
    ];
    let mut f = 0.0;
    for (c, s, w) in G {
        let d2 = (p - DVec3::from_array(c)).length_squared();
        f += w * (-d2 / (2.0 * s * s)).exp();
    }
    let r = p.x.hypot(p.y);
    let dcore = (r - 1.5).hypot(p.z);
    f + 0.35 * (-(dcore * dcore) / (2.0 * 0.15 * 0.15)).exp()
}

/// The hex shell mesh and its normalised point scalar.
pub fn hex_shell() -> (Mesh, Vec<f64>) {
    let g = |i: usize| i as f64 / (N - 1) as f64;
    let mut points = Vec::with_capacity(N * N * N);
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                let p = shell_map(g(i), g(j), g(k));
                points.push(DVec3::new(
                    p.x as f32 as f64,
                    p.y as f32 as f64,
                    p.z as f32 as f64,
                ));
            }
        }
    }
    let f: Vec<f64> = points.iter().map(|&p| field(p)).collect();
    let (lo, hi) = f.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
        (a.0.min(v), a.1.max(v))
    });
    let f: Vec<f64> = f
        .iter()
        .map(|v| (((v - lo) / (hi - lo)) as f32) as f64)
        .collect();
    let mut cells = Cells::default();
    for k in 0..N - 1 {
        for j in 0..N - 1 {
            for i in 0..N - 1 {
                let c = (i + N * (j + N * k)) as u32;
                let (n, nn) = (N as u32, (N * N) as u32);
                cells.push(
                    CellKind::Hexahedron,
                    &[
                        c,
                        c + 1,
                        c + 1 + n,
                        c + n,
                        c + nn,
                        c + nn + 1,
                        c + nn + 1 + n,
                        c + nn + n,
                    ],
                );
            }
        }
    }
    let mesh = Mesh {
        points,
        cells,
        ..Default::default()
    };
    (mesh, f)
}

/// `bench_tf.json` (the copy in the shared `synthetic/` data), embedded so
/// the bench runs without the shared data: the real transfer function and
/// its closed-form segment integral.
const BENCH_TF: &str = r#"{
 "scalar": "f",
 "unit_distance": 0.5,
 "opacity_points": [
  {"s": 0.0, "opacity": 0.0}, {"s": 0.28, "opacity": 0.0}, {"s": 0.3, "opacity": 0.5},
  {"s": 0.4, "opacity": 0.5}, {"s": 0.45, "opacity": 0.02}, {"s": 0.6, "opacity": 0.02},
  {"s": 0.62, "opacity": 0.9}, {"s": 0.75, "opacity": 0.9}, {"s": 0.8, "opacity": 0.2},
  {"s": 1.0, "opacity": 0.2}
 ],
 "color_points": [
  {"s": 0.0, "rgb": [0.0, 0.0, 1.0]}, {"s": 0.3, "rgb": [0.0, 0.6, 1.0]},
  {"s": 0.45, "rgb": [0.1, 0.9, 0.3]}, {"s": 0.62, "rgb": [1.0, 0.9, 0.0]},
  {"s": 0.8, "rgb": [1.0, 0.3, 0.0]}, {"s": 1.0, "rgb": [0.8, 0.0, 0.3]}
 ]
}"#;

fn peak_rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// CPU seconds (user + system) used by this process so far: on a loaded
/// machine wall time says little, CPU time / cores is the idle-machine time.
fn cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let f: Vec<&str> = rest.split_whitespace().collect();
            let ut: f64 = f.get(11)?.parse().ok()?;
            let st: f64 = f.get(12)?.parse().ok()?;
            Some((ut + st) / 100.0)
        })
        .unwrap_or(0.0)
}

fn camera(mesh: &Mesh, ortho: bool, size: u32) -> Camera {
    let p = CameraParams {
        width: size,
        height: size,
        azimuth: 20.0,
        elevation: 35.0,
        zoom: 1.25,
        ortho,
        ..Default::default()
    };
    Camera::fit(mesh.bounds(), &p)
}

fn bench_size() -> u32 {
    std::env::var("RAYCAST_BENCH_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(512)
}

fn models(var: &str, default: &str) -> Vec<FieldModel> {
    std::env::var(var)
        .unwrap_or_else(|_| default.into())
        .split(',')
        .filter_map(|m| m.parse().ok())
        .collect()
}

fn bench(c: &mut Criterion) {
    let t = Instant::now();
    let (mesh, f) = hex_shell();
    let topology = Topology::build(&mesh.cells);
    eprintln!(
        "hex_shell: {} hexes, {} points; mesh + topology built in {:.2} s; peak RSS {:.0} MiB",
        mesh.cells.len(),
        mesh.points.len(),
        t.elapsed().as_secs_f64(),
        peak_rss_mib()
    );
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Point(&f),
    };
    let tf = TransferFunction::from_json_str(BENCH_TF, 0.5).expect("bench_tf");
    let size = bench_size();
    let mut g = c.benchmark_group("raycast_hex_shell");
    g.sample_size(10);
    for model in models("RAYCAST_BENCH_MODELS", "faces,tets,native") {
        let t = Instant::now();
        let rc = Raycaster::new(scene, model).unwrap();
        eprintln!(
            "{model:?}: setup {:.2} s, {:.1} MiB of ray-caster structures, peak RSS {:.0} MiB",
            t.elapsed().as_secs_f64(),
            rc.bytes() as f64 / 1048576.0,
            peak_rss_mib()
        );
        for ortho in [false, true] {
            if model == FieldModel::Native && ortho {
                continue;
            }
            let cam = camera(&mesh, ortho, size);
            let opts = RaycastOptions {
                model,
                ..Default::default()
            };
            let t = Instant::now();
            let cpu = cpu_seconds();
            let img = rc.render(&tf, &cam, &opts);
            let cover = img.pixels.iter().filter(|p| p[3] > 0.0).count();
            eprintln!(
                "{model:?} {}: first frame {:.3} s wall, {:.2} s CPU ({cover} covered pixels); peak RSS {:.0} MiB",
                if ortho { "ortho" } else { "persp" },
                t.elapsed().as_secs_f64(),
                cpu_seconds() - cpu,
                peak_rss_mib()
            );
            if let Ok(dir) = std::env::var("RAYCAST_BENCH_OUT") {
                let name = format!(
                    "{dir}/hex_shell_{model:?}_{}.png",
                    if ortho { "ortho" } else { "persp" }
                );
                let _ = img.write_png(std::path::Path::new(&name), [0.0; 3], false);
            }
            if model == FieldModel::Native {
                continue;
            }
            let id = format!("{model:?}_{}_{size}", if ortho { "ortho" } else { "persp" });
            g.bench_function(id, |b| b.iter(|| rc.render(&tf, &cam, &opts)));
        }
    }
    g.finish();
}

/// Walk against brute force on the hex_shell scene (perspective view):
/// setup, first-frame wall and CPU time, the largest pixel difference, and
/// criterion timings per frame.
fn walk_vs_brute(c: &mut Criterion) {
    let list = models("RAYCAST_BENCH_BRUTE_MODELS", "faces,tets");
    if list.is_empty() {
        return;
    }
    let (mesh, f) = hex_shell();
    let topology = Topology::build(&mesh.cells);
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Point(&f),
    };
    let tf = TransferFunction::from_json_str(BENCH_TF, 0.5).expect("bench_tf");
    let size = bench_size();
    let cam = camera(&mesh, false, size);
    let mut g = c.benchmark_group("raycast_walk_vs_brute");
    g.sample_size(10);
    for model in list {
        let opts = RaycastOptions {
            model,
            ..Default::default()
        };
        let t = Instant::now();
        let walk = Raycaster::new(scene, model).unwrap();
        let walk_setup = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let brute = Brute::new(scene, model).unwrap();
        eprintln!(
            "{model:?}: setup walk {walk_setup:.2} s, brute {:.2} s ({} pieces, {:.1} MiB); peak RSS {:.0} MiB",
            t.elapsed().as_secs_f64(),
            brute.piece_count(),
            brute.bytes() as f64 / 1048576.0,
            peak_rss_mib()
        );
        let (t, cpu) = (Instant::now(), cpu_seconds());
        let a = walk.render(&tf, &cam, &opts);
        let (walk_s, walk_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        let (t, cpu) = (Instant::now(), cpu_seconds());
        let b = brute.render(&tf, &cam, &opts);
        let (brute_s, brute_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        let diff = a
            .pixels
            .iter()
            .zip(&b.pixels)
            .flat_map(|(p, q)| (0..4).map(move |k| (p[k] - q[k]).abs()))
            .fold(0.0f32, f32::max);
        let st = brute.stats();
        eprintln!(
            "{model:?} persp {size}: first frame walk {walk_s:.3} s wall / {walk_cpu:.2} s CPU, \
             brute {brute_s:.3} s wall / {brute_cpu:.2} s CPU; max |walk - brute| {diff:e}; \
             brute tested {} cells for {} segments ({} overlapping)",
            st.cells_tested, st.segments, st.overlapping_segments
        );
        g.bench_function(format!("{model:?}_walk_{size}"), |bch| {
            bch.iter(|| walk.render(&tf, &cam, &opts))
        });
        g.bench_function(format!("{model:?}_brute_{size}"), |bch| {
            bch.iter(|| brute.render(&tf, &cam, &opts))
        });
    }
    g.finish();
}

/// Early ray termination (transmittance 1e-6) against none, `faces` walk,
/// perspective, on the hex_shell scene with an opaque front layer: the
/// `bench_tf.json` colours with extinction 40 per unit below f = 0.3
/// (where most rays enter) and 0.5 above. Prints the rays that stopped.
fn early_termination(c: &mut Criterion) {
    if std::env::var("RAYCAST_BENCH_TERMINATION").is_ok_and(|v| v == "none") {
        return;
    }
    let (mesh, f) = hex_shell();
    let topology = Topology::build(&mesh.cells);
    let scene = Scene {
        mesh: &mesh,
        topology: &topology,
        scalars: Scalars::Point(&f),
    };
    let tf = TransferFunction::from_channels(
        &[(0.0, [40.0]), (0.3, [40.0]), (0.31, [0.5]), (1.0, [0.5])],
        &[(0.0, [1.0, 0.9, 0.0]), (1.0, [0.0, 0.3, 1.0])],
        None,
        zoovr::tf::EmissionModel::Glow,
    )
    .expect("tf");
    let size = bench_size();
    let cam = camera(&mesh, false, size);
    let walk = Raycaster::new(scene, FieldModel::Faces).unwrap();
    let mut g = c.benchmark_group("raycast_early_termination");
    g.sample_size(10);
    for (name, t) in [("on", 1e-6), ("off", 0.0)] {
        let opts = RaycastOptions {
            model: FieldModel::Faces,
            early_termination: t,
            ..Default::default()
        };
        let (_, stopped) = walk.render_counting(&tf, &cam, &opts, |_, _| {});
        eprintln!(
            "termination {name}: {stopped} of {} rays stopped early",
            size * size
        );
        g.bench_function(format!("faces_walk_{size}_{name}"), |bch| {
            bch.iter(|| walk.render(&tf, &cam, &opts))
        });
    }
    g.finish();
}

criterion_group!(benches, bench, walk_vs_brute, early_termination);
criterion_main!(benches);
