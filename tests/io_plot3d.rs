//! PLOT3D reader: the Blunt Fin grid and solution checked value for value
//! against VTK's own conversion of it, every framing / precision / IBLANK
//! variant written by a small independent writer, derived quantities against
//! their formulas, content sniffing, and seeded mutations.

use std::path::Path;
use std::time::{Duration, Instant};

use zoovr::field::{ArrayData, DataArray};
use zoovr::io::plot3d::{looks_like_grid, read, read_bytes};
use zoovr::mesh::Mesh;
use zoovr::testdata::shared_file;

fn arr<'a>(m: &'a Mesh, name: &str) -> &'a DataArray {
    m.point_data
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array {name}"))
}

#[test]
fn bluntfin_grid_and_q_match_vtk_conversion() {
    let (Some(xyz), Some(q), Some(vtk)) = (
        shared_file("bluntfin/bluntfinxyz.bin"),
        shared_file("bluntfin/bluntfinq.bin"),
        shared_file("bluntfin/bluntfin_converted_legacy42_binary.vtk"),
    ) else {
        return;
    };
    let m = read(&xyz, Some(&q)).unwrap();
    assert_eq!(m.points.len(), 40 * 32 * 32);
    assert_eq!(m.cells.len(), 37_479);
    assert_eq!(m.source.cells_by_type.get("hexahedron"), Some(&37_479));
    let (lo, hi) = arr(&m, "Density").range(Some(0)).unwrap();
    assert!(
        (lo - 0.19).abs() < 0.005 && (hi - 4.98).abs() < 0.005,
        "{lo} {hi}"
    );
    assert_eq!(m.active_point_scalars.as_deref(), Some("Density"));
    // VTK wrote the legacy copy from these files: same points, same cells,
    // and the same f32 bits in every array, derived ones included.
    let l = zoovr::io::legacy::read(&vtk).unwrap();
    assert_eq!(m.points, l.points);
    assert_eq!(m.cells.conn, l.cells.conn);
    for name in [
        "Density",
        "Momentum",
        "StagnationEnergy",
        "VelocityMagnitude",
        "Pressure",
    ] {
        let (a, b) = (arr(&m, name), arr(&l, name));
        assert_eq!(a.components, b.components, "{name}");
        let (ArrayData::F32(x), ArrayData::F32(y)) = (&a.data, &b.data) else {
            panic!("{name} not f32")
        };
        assert!(
            x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits()),
            "{name}"
        );
    }
    // Without the solution: geometry only.
    let g = read(&xyz, None).unwrap();
    assert!(g.point_data.is_empty());
    let head = std::fs::read(&xyz).unwrap();
    assert!(looks_like_grid(&head[..512]));
}

/// Options of the independent test writer.
#[derive(Clone, Copy, Debug)]
struct Opts {
    big: bool,
    markers: bool,
    nblocks: bool,
    double: bool,
    iblank: bool,
    padding: usize,
}

fn int(o: Opts, v: i32) -> [u8; 4] {
    if o.big {
        v.to_be_bytes()
    } else {
        v.to_le_bytes()
    }
}

fn real(o: Opts, v: f64, out: &mut Vec<u8>) {
    match (o.double, o.big) {
        (true, true) => out.extend_from_slice(&v.to_be_bytes()),
        (true, false) => out.extend_from_slice(&v.to_le_bytes()),
        (false, true) => out.extend_from_slice(&(v as f32).to_be_bytes()),
        (false, false) => out.extend_from_slice(&(v as f32).to_le_bytes()),
    }
}

fn record(o: Opts, body: Vec<u8>, out: &mut Vec<u8>) {
    if o.markers {
        out.extend_from_slice(&int(o, body.len() as i32));
    }
    out.extend_from_slice(&body);
    if o.markers {
        out.extend_from_slice(&int(o, body.len() as i32));
    }
}

fn header(o: Opts, dims: [usize; 3], out: &mut Vec<u8>) {
    if o.nblocks {
        record(o, int(o, 1).to_vec(), out);
    }
    let mut h = Vec::new();
    for d in dims {
        h.extend_from_slice(&int(o, d as i32));
    }
    record(o, h, out);
}

/// A warped grid with coordinates exactly representable in f32.
fn coords(dims: [usize; 3]) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let (x, y, z) = (i as f64, j as f64, k as f64);
                v.push([
                    x + 0.25 * (y * z % 3.0),
                    y * 1.5 - 0.125 * x,
                    z * 0.5 + 0.0625 * x * y,
                ]);
            }
        }
    }
    v
}

fn write_grid(o: Opts, dims: [usize; 3], blank: &[usize]) -> Vec<u8> {
    let mut out = Vec::new();
    header(o, dims, &mut out);
    let pts = coords(dims);
    let mut body = Vec::new();
    for c in 0..3 {
        for p in &pts {
            real(o, p[c], &mut body);
        }
    }
    if o.iblank {
        for i in 0..pts.len() {
            body.extend_from_slice(&int(o, i32::from(!blank.contains(&i))));
        }
    }
    record(o, body, &mut out);
    out.extend(std::iter::repeat_n(0u8, o.padding));
    out
}

fn write_q(o: Opts, dims: [usize; 3], vars: &[[f64; 5]]) -> Vec<u8> {
    let mut out = Vec::new();
    header(o, dims, &mut out);
    let mut c = Vec::new();
    for v in [0.5, 2.0, 1e5, 3.0] {
        real(o, v, &mut c);
    }
    record(o, c, &mut out);
    let mut body = Vec::new();
    for k in 0..5 {
        for v in vars {
            real(o, v[k], &mut body);
        }
    }
    record(o, body, &mut out);
    out.extend(std::iter::repeat_n(0u8, o.padding));
    out
}

fn all_opts() -> Vec<Opts> {
    let mut v = Vec::new();
    for bits in 0..32u32 {
        v.push(Opts {
            big: bits & 1 != 0,
            markers: bits & 2 != 0,
            nblocks: bits & 4 != 0,
            double: bits & 8 != 0,
            iblank: bits & 16 != 0,
            padding: if bits & 2 != 0 { 0 } else { 20 },
        });
    }
    v
}

#[test]
fn every_layout_variant_round_trips() {
    let dims = [3, 4, 5];
    let expect = coords(dims);
    for o in all_opts() {
        let b = write_grid(o, dims, &[]);
        assert!(looks_like_grid(&b), "{o:?}");
        let m = read_bytes(Path::new("g.xyz"), &b, None).unwrap_or_else(|e| panic!("{o:?}: {e}"));
        let got: Vec<[f64; 3]> = m.points.iter().map(|p| p.to_array()).collect();
        assert_eq!(got, expect, "{o:?}");
        assert_eq!(m.cells.len(), 2 * 3 * 4, "{o:?}");
        // VTK hexahedron order over (i, j, k).
        assert_eq!(m.cells.nodes(0), &[0, 1, 4, 3, 12, 13, 16, 15]);
        assert_eq!(m.point_data.iter().any(|a| a.name == "IBlank"), o.iblank);
    }
}

#[test]
fn iblank_zero_drops_the_cells_around_a_point() {
    let o = Opts {
        big: false,
        markers: true,
        nblocks: false,
        double: false,
        iblank: true,
        padding: 0,
    };
    let dims = [3, 3, 3];
    // Point 13 is the centre: all 8 cells touch it. Point 0 touches only cell 0.
    let m = read_bytes(Path::new("g.xyz"), &write_grid(o, dims, &[0]), None).unwrap();
    assert_eq!(m.cells.len(), 7);
    assert_eq!(m.source.cells_by_type.get("hexahedron"), Some(&7));
    let m = read_bytes(Path::new("g.xyz"), &write_grid(o, dims, &[13]), None).unwrap();
    assert_eq!(m.cells.len(), 0);
}

#[test]
fn q_solution_and_derived_quantities() {
    let dims = [2, 3, 2];
    let n = 12;
    let vars: Vec<[f64; 5]> = (0..n)
        .map(|i| {
            let f = i as f64;
            [1.0 + 0.25 * f, 0.5 * f, -0.25, 0.125 * f, 10.0 + f]
        })
        .collect();
    for o in all_opts().into_iter().filter(|o| !o.iblank) {
        let g = write_grid(o, dims, &[]);
        let q = write_q(o, dims, &vars);
        let m = read_bytes(Path::new("g.xyz"), &g, Some((Path::new("s.q"), &q)))
            .unwrap_or_else(|e| panic!("{o:?}: {e}"));
        let want_type = if o.double { "Float64" } else { "Float32" };
        for (i, v) in vars.iter().enumerate() {
            assert_eq!(arr(&m, "Density").component(i, 0), v[0], "{o:?}");
            for c in 0..3 {
                assert_eq!(arr(&m, "Momentum").component(i, c), v[1 + c]);
            }
            assert_eq!(arr(&m, "StagnationEnergy").component(i, 0), v[4]);
            let speed2 = (v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) / (v[0] * v[0]);
            let vm = arr(&m, "VelocityMagnitude").component(i, 0);
            assert!(
                (vm - speed2.sqrt()).abs() <= 1e-6 * speed2.sqrt().max(1.0),
                "{vm}"
            );
            let p = 0.4 * (v[4] - 0.5 * v[0] * speed2);
            let got = arr(&m, "Pressure").component(i, 0);
            assert!((got - p).abs() <= 1e-6 * p.abs().max(1.0), "{got} vs {p}");
            assert_eq!(arr(&m, "Pressure").vtk_type, want_type);
        }
    }
    // Dimensions must match; the error names the q file.
    let o = all_opts()[0];
    let e = read_bytes(
        Path::new("g.xyz"),
        &write_grid(o, dims, &[]),
        Some((Path::new("other.q"), &write_q(o, [2, 2, 3], &vars))),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("other.q") && e.contains("byte 0"), "{e}");
}

#[test]
fn sniffing_and_dispatch() {
    assert!(!looks_like_grid(b"# vtk DataFile Version 3.0\nx\nASCII\n"));
    assert!(!looks_like_grid(b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x10"));
    assert!(!looks_like_grid(&[0u8; 64]));
    let o = Opts {
        big: true,
        markers: false,
        nblocks: false,
        double: false,
        iblank: false,
        padding: 0,
    };
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("grid.dat");
    std::fs::write(&p, write_grid(o, [4, 3, 2], &[])).unwrap();
    assert_eq!(
        zoovr::io::detect_format(&p).unwrap(),
        zoovr::io::Format::Plot3d
    );
    let m = zoovr::io::read(&p, &zoovr::io::ReadOptions::default()).unwrap();
    assert_eq!(m.cells.len(), 6);
}

#[test]
fn seeded_mutations_never_panic() {
    let dims = [3, 2, 2];
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let t = Instant::now();
    for o in all_opts() {
        let base = write_grid(o, dims, &[]);
        let q = write_q(o, dims, &[[1.0, 0.0, 0.0, 0.0, 2.0]; 12]);
        for _ in 0..60 {
            let mut g = base.clone();
            let mut qq = q.clone();
            for buf in [&mut g, &mut qq] {
                match next() % 3 {
                    0 => buf.truncate((next() as usize) % (buf.len() + 1)),
                    1 => {
                        let i = (next() as usize) % buf.len();
                        buf[i] = next() as u8;
                    }
                    _ => buf.extend_from_slice(&[0xff; 7]),
                }
            }
            let r = std::panic::catch_unwind(|| {
                read_bytes(Path::new("m.xyz"), &g, Some((Path::new("m.q"), &qq)))
            });
            let Ok(r) = r else { panic!("panic on {o:?}") };
            if let Err(e) = r {
                let s = e.to_string();
                assert!(s.contains("byte "), "{s}");
            }
        }
    }
    assert!(t.elapsed() < Duration::from_secs(10));
}

/// A multi-grid file (`nblocks` grids, dimensions in one record, then
/// each grid's record; a q file: each grid's conditions and data) in
/// every layout.
fn write_multi(o: Opts, dims: &[[usize; 3]], q: bool) -> Vec<u8> {
    let mut out = Vec::new();
    record(o, int(o, dims.len() as i32).to_vec(), &mut out);
    let mut h = Vec::new();
    for d in dims.iter().flatten() {
        h.extend_from_slice(&int(o, *d as i32));
    }
    record(o, h, &mut out);
    for (g, &d) in dims.iter().enumerate() {
        let one = if q {
            write_q(o, d, &q_vars(d, g))
        } else {
            write_grid(o, d, &[g])
        };
        // The grid's own records, after its single-grid header.
        let mut skip = 12 + if o.markers { 8 } else { 0 };
        if o.nblocks {
            skip += 4 + if o.markers { 8 } else { 0 };
        }
        out.extend_from_slice(&one[skip..one.len() - o.padding]);
    }
    out.extend(std::iter::repeat_n(0u8, o.padding));
    out
}

fn q_vars(dims: [usize; 3], g: usize) -> Vec<[f64; 5]> {
    (0..dims.iter().product::<usize>())
        .map(|p| {
            let x = (p + 7 * g) as f64;
            [1.0 + 0.5 * x, 0.25 * x, -0.5, 0.125 * x, 4.0 + x]
        })
        .collect()
}

/// Multi-grid files read as their grids read one by one, merged: the same
/// points, the same cells (point ids offset per grid), the same IBLANK and
/// solution arrays; refused clearly where their data does not fit.
#[test]
fn multi_grid_files_read_as_their_grids() {
    let dims = [[2, 3, 2], [3, 2, 2], [2, 2, 4]];
    let mut n = 0;
    for o in all_opts().into_iter().filter(|o| o.nblocks) {
        let g = write_multi(o, &dims, false);
        let q = write_multi(o, &dims, true);
        let what = format!("{o:?}");
        let m = read_bytes(Path::new("m.xyz"), &g, Some((Path::new("m.q"), &q)))
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        let mut base = 0u32;
        let (mut points, mut cells) = (0, 0);
        for (k, &d) in dims.iter().enumerate() {
            let single = Opts {
                nblocks: false,
                ..o
            };
            let one = read_bytes(
                Path::new("one.xyz"),
                &write_grid(single, d, &[k]),
                Some((Path::new("one.q"), &write_q(single, d, &q_vars(d, k)))),
            )
            .unwrap();
            assert_eq!(
                &m.points[points..points + one.points.len()],
                &one.points[..],
                "{what}"
            );
            for c in 0..one.cells.len() {
                let want: Vec<u32> = one.cells.nodes(c).iter().map(|&p| p + base).collect();
                assert_eq!(m.cells.nodes(cells + c), &want[..], "{what} grid {k}");
            }
            for a in &one.point_data {
                let all = arr(&m, &a.name);
                let nc = a.components;
                for i in 0..one.points.len() * nc {
                    assert_eq!(
                        all.data.get(points * nc + i),
                        a.data.get(i),
                        "{what} {}",
                        a.name
                    );
                }
            }
            points += one.points.len();
            cells += one.cells.len();
            base += one.points.len() as u32;
        }
        assert_eq!((m.points.len(), m.cells.len()), (points, cells), "{what}");
        // Each grid blanks one point: some cells left out.
        assert_eq!(o.iblank, cells < 2 + 2 + 3, "{what}");
        assert!(
            m.source.notes.iter().any(|s| s.contains("3 grids")),
            "{what}"
        );
        n += 1;
    }
    assert_eq!(n, 16);
    // A header announcing more grid data than the file holds.
    let o = all_opts()[4 + 8];
    let mut b = write_multi(o, &dims, false);
    b.truncate(b.len() - 40);
    let e = read_bytes(Path::new("multi.xyz"), &b, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("multi.xyz") && e.contains("3 grids"), "{e}");
}
