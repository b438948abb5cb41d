//! Writes generated meshes.
//!
//! ```text
//! cargo run --release --example gen_mesh -- --hexes 1000000 -o /tmp/hex1m.vtu [--raw]
//! cargo run --example gen_mesh -- --meshes meshes      # the committed small meshes
//! ```
//! cargo run --release --example gen_mesh -- --hexes 1000000 --connect [-i FILE.vtu]
//! cargo run --release --example gen_mesh -- --hexes 1000000 --steps 3 -o /tmp/s/series.pvd
//! `--steps K` writes K time steps of the grid (same cells and points, the
//! field `f` at t = 0, 0.5, ...) as `step_K.vtu` beside the `.pvd` given.
//! `--connect` builds the topology and the `info` report of the generated
//! grid (or of `-i FILE` read with `zoovr::io::read`) and prints the times;
//! run it under `/usr/bin/time -v` for the peak resident memory.
//! `--hexes N` writes the warped hexahedral grid with `round(cbrt(N))^3`
//! cells (zlib-compressed unless `--raw`); `--meshes DIR` (re)writes the
//! project's own small meshes (see `meshes/README.md`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use glam::DVec3;
use zoovr::generate::{
    flow_series, ring_grid, single_cell, time_series, warped_hex_grid, zoo_grid, Warp,
};
use zoovr::io::writer::{write_legacy_ascii, write_pvd, write_series, write_vtu, Compression};
use zoovr::mesh::{CellKind, Mesh};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut hexes = None;
    let mut out = None;
    let mut meshes = None;
    let mut compression = Compression::Zlib;
    let mut connect = false;
    let mut steps: Option<usize> = None;
    let mut input: Option<PathBuf> = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--hexes" => {
                hexes = Some(args.get(i + 1).context("--hexes N")?.parse::<usize>()?);
                i += 1;
            }
            "-o" => {
                out = Some(PathBuf::from(args.get(i + 1).context("-o FILE")?));
                i += 1;
            }
            "--meshes" => {
                meshes = Some(PathBuf::from(args.get(i + 1).context("--meshes DIR")?));
                i += 1;
            }
            "--steps" => {
                steps = Some(args.get(i + 1).context("--steps K")?.parse::<usize>()?);
                i += 1;
            }
            "--raw" => compression = Compression::None,
            "--connect" => connect = true,
            "-i" => {
                input = Some(PathBuf::from(args.get(i + 1).context("-i FILE")?));
                i += 1;
            }
            a => bail!("unknown argument {a}"),
        }
        i += 1;
    }
    if let Some(dir) = meshes {
        return write_meshes(&dir);
    }
    if connect {
        return connect_and_report(hexes, input.as_deref());
    }
    let (Some(n), Some(out)) = (hexes, out) else {
        bail!("usage: gen_mesh --hexes N -o FILE.vtu [--raw] | --meshes DIR");
    };
    let side = (n as f64).cbrt().round().max(1.0) as usize;
    if let Some(k) = steps {
        let dir = out.parent().unwrap_or(Path::new("."));
        let mut entries = Vec::new();
        for (i, (t, m)) in time_series(side, k).iter().enumerate() {
            let name = format!("step_{i}.vtu");
            write_vtu(&dir.join(&name), m, compression)?;
            entries.push((*t, name));
        }
        write_pvd(&out, &entries)?;
        eprintln!(
            "{k} steps of {} hexes: {}",
            side * side * side,
            out.display()
        );
        return Ok(());
    }
    let t0 = std::time::Instant::now();
    let mesh = warped_hex_grid(side, &Warp::default());
    let t1 = std::time::Instant::now();
    write_vtu(&out, &mesh, compression)?;
    eprintln!(
        "{} hexes, {} points: generated in {:?}, written in {:?} to {}",
        mesh.cells.len(),
        mesh.points.len(),
        t1 - t0,
        t1.elapsed(),
        out.display()
    );
    Ok(())
}

/// CPU time (user + system) of this process so far, from `/proc/self/stat`
/// (Linux; clock ticks of 10 ms). Wall times on a busy machine say little;
/// CPU time says what the work costs.
fn cpu_time() -> Option<std::time::Duration> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let after = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(std::time::Duration::from_millis(ticks * 10))
}

fn connect_and_report(hexes: Option<usize>, input: Option<&Path>) -> Result<()> {
    use zoovr::mesh::report::MeshReport;
    use zoovr::mesh::topology::Topology;
    let t0 = std::time::Instant::now();
    let c0 = cpu_time();
    let mesh = match input {
        Some(p) => zoovr::io::read(p, &zoovr::io::ReadOptions::default())?,
        None => {
            let n = hexes.context("--hexes N or -i FILE")?;
            warped_hex_grid(
                (n as f64).cbrt().round().max(1.0) as usize,
                &Warp::default(),
            )
        }
    };
    let (t1, c1) = (std::time::Instant::now(), cpu_time());
    let topo = Topology::build(&mesh.cells);
    let (t2, c2) = (std::time::Instant::now(), cpu_time());
    let r = MeshReport::compute_with(&mesh, &topo);
    let (t3, c3) = (std::time::Instant::now(), cpu_time());
    if let (Some(c0), Some(c1), Some(c2), Some(c3)) = (c0, c1, c2, c3) {
        eprintln!(
            "cpu time: load {:?}, topology {:?}, report {:?}",
            c1 - c0,
            c2 - c1,
            c3 - c2
        );
    }
    let n = mesh.cells.len().max(1) as f64;
    eprintln!(
        "{} cells: {} {:?}, topology {:?} ({:.0} ns/cell), report {:?} ({:.0} ns/cell)",
        mesh.cells.len(),
        if input.is_some() { "read" } else { "generated" },
        t1 - t0,
        t2 - t1,
        (t2 - t1).as_nanos() as f64 / n,
        t3 - t2,
        (t3 - t2).as_nanos() as f64 / n
    );
    eprintln!("{r:?}");
    Ok(())
}

fn both(dir: &Path, name: &str, mesh: &Mesh) -> Result<()> {
    write_legacy_ascii(&dir.join(format!("{name}.vtk")), mesh, name)?;
    write_vtu(&dir.join(format!("{name}.vtu")), mesh, Compression::None)?;
    Ok(())
}

fn write_meshes(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    for (name, kind) in [
        ("tetra", CellKind::Tetra),
        ("pyramid", CellKind::Pyramid),
        ("wedge", CellKind::Wedge),
        ("hexahedron", CellKind::Hexahedron),
        ("pentagonal_prism", CellKind::PentagonalPrism),
        ("hexagonal_prism", CellKind::HexagonalPrism),
        ("polyhedron", CellKind::Polyhedron),
    ] {
        both(dir, name, &single_cell(kind))?;
    }
    std::fs::write(dir.join("voxel.vtk"), voxel_legacy())?;
    let w = Warp::default();
    let curv = warped_hex_grid(4, &w);
    write_legacy_ascii(&dir.join("curvilinear_4x4x4.vtk"), &curv, "warped 4x4x4")?;
    write_vtu(&dir.join("curvilinear_4x4x4.vtu"), &curv, Compression::Zlib)?;
    both(dir, "ring_hole", &ring_grid(6, &w))?;
    write_vtu(
        &dir.join("zoo_3x3x3.vtu"),
        &zoo_grid(3, &w),
        Compression::Zlib,
    )?;
    let sdir = dir.join("series");
    std::fs::create_dir_all(&sdir)?;
    let mut steps = Vec::new();
    for (k, (t, m)) in time_series(3, 3).into_iter().enumerate() {
        let f = format!("step_{k}.vtu");
        write_vtu(&sdir.join(&f), &m, Compression::Zlib)?;
        steps.push((t, f));
    }
    write_pvd(&sdir.join("series.pvd"), &steps)?;
    write_series(&sdir.join("series.vtu.series"), &steps)?;
    let fdir = dir.join("flow");
    std::fs::create_dir_all(&fdir)?;
    let mut fsteps = Vec::new();
    for (k, (t, m)) in flow_series(12, 36, 6, 16).into_iter().enumerate() {
        let name = format!("flow_{k:02}.vtu");
        write_vtu(&fdir.join(&name), &m, Compression::Zlib)?;
        fsteps.push((t, name));
    }
    write_pvd(&fdir.join("flow.pvd"), &fsteps)?;
    both(dir, "degenerate", &degenerate())?;
    Ok(())
}

/// One unit voxel (VTK type 11, voxel node order) with a point scalar.
fn voxel_legacy() -> String {
    let mut s = String::from(
        "# vtk DataFile Version 4.2\nvoxel\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 double\n",
    );
    let mut f = Vec::new();
    for k in 0..8 {
        // voxel order: x fastest, then y, then z
        let p = DVec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, (k >> 2) as f64);
        s += &format!("{} {} {}\n", p.x, p.y, p.z);
        f.push(zoovr::generate::scalar_f(p, 0.0) as f32);
    }
    s += "CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1\n11\nPOINT_DATA 8\nSCALARS f float 1\nLOOKUP_TABLE default\n";
    for v in f {
        s += &format!("{v}\n");
    }
    s
}

/// Cells with problems, each counted by `info`: 0 a good hexahedron, 1 an
/// inverted hexahedron, 2 an inverted wedge, 3 a flat (zero-volume)
/// hexahedron, 4 a tetrahedron with a repeated index (zero volume).
fn degenerate() -> Mesh {
    let mut m = Mesh::default();
    let square = |z: f64, x0: f64| {
        [(0., 0.), (1., 0.), (1., 1.), (0., 1.)].map(|(x, y)| DVec3::new(x + x0, y, z))
    };
    let mut add = |pts: &[DVec3]| {
        let b = m.points.len() as u32;
        m.points.extend_from_slice(pts);
        (b..b + pts.len() as u32).collect::<Vec<u32>>()
    };
    let good = add(&[square(0.0, 0.0), square(1.0, 0.0)].concat());
    let inv = add(&[square(1.0, 2.0), square(0.0, 2.0)].concat());
    // (0, 1, 2) clockwise seen from (3, 4, 5): inverted
    let wedge = add(&[
        DVec3::new(4., 0., 0.),
        DVec3::new(4., 1., 0.),
        DVec3::new(5., 0., 0.),
        DVec3::new(4., 0., 1.),
        DVec3::new(4., 1., 1.),
        DVec3::new(5., 0., 1.),
    ]);
    let flat = add(&[square(0.0, 6.0), square(0.0, 6.0)].concat());
    let tet = add(&[
        DVec3::new(8., 0., 0.),
        DVec3::new(9., 0., 0.),
        DVec3::new(8., 1., 0.),
    ]);
    let mut cells = zoovr::mesh::Cells::default();
    cells.push(CellKind::Hexahedron, &good);
    cells.push(CellKind::Hexahedron, &inv);
    cells.push(CellKind::Wedge, &wedge);
    cells.push(CellKind::Hexahedron, &flat);
    cells.push(CellKind::Tetra, &[tet[0], tet[1], tet[1], tet[2]]);
    m.cells = cells;
    let f: Vec<f32> = m
        .points
        .iter()
        .map(|&p| zoovr::generate::scalar_f(p, 0.0) as f32)
        .collect();
    m.point_data.push(zoovr::field::DataArray {
        name: "f".into(),
        components: 1,
        data: zoovr::field::ArrayData::F32(f),
        vtk_type: "Float32".into(),
    });
    m.active_point_scalars = Some("f".into());
    m
}
