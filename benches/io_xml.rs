//! VTK XML reader benchmarks.
//!
//! Data: `../shared/data/bluntfin/bluntfin_converted.vts` (37,479 hexes,
//! appended raw), `../shared/data/synthetic/hex_shell_zlib.vtu` (250,047
//! hexes, appended raw + zlib), and a generated 100^3 = 1,000,000-hex warped
//! curvilinear grid written like ParaView does (appended raw, zlib, 32 KiB
//! blocks, UInt64 headers, Float32 points, Int64 connectivity/offsets,
//! UInt8 types, one Float32 point scalar), cached in the system temp folder.
//!
//! Peak memory is measured outside criterion: run the bench binary with
//! `ZOOVR_XML_LOAD=FILE` under `/usr/bin/time -v`; it loads FILE once, prints
//! the time and exits. `ZOOVR_XML_GEN=1` only writes the 1M-hex file and
//! prints its path.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use criterion::{criterion_group, Criterion};
use rayon::prelude::*;
use zoovr::io::{self, ReadOptions};
use zoovr::mesh::lattice_hex;

const N: usize = 100;
const BLOCK: usize = 1 << 15;

/// Appends one zlib-compressed raw block set (VTK layout, UInt64 header).
fn append_zlib(out: &mut Vec<u8>, data: &[u8]) {
    let blocks: Vec<Vec<u8>> = data
        .par_chunks(BLOCK)
        .map(|b| {
            let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            e.write_all(b).unwrap();
            e.finish().unwrap()
        })
        .collect();
    for w in [blocks.len(), BLOCK, data.len() % BLOCK] {
        out.extend((w as u64).to_le_bytes());
    }
    for b in &blocks {
        out.extend((b.len() as u64).to_le_bytes());
    }
    for b in &blocks {
        out.extend(b);
    }
}

/// Writes the 1M-hex file (if absent) and returns its path.
fn million_hex_file() -> PathBuf {
    let path = std::env::temp_dir().join("zoovr_bench_1m_hex_zlib.vtu");
    if path.exists() {
        return path;
    }
    let n1 = N + 1;
    let np = n1 * n1 * n1;
    let nc = N * N * N;
    let mut pts = Vec::with_capacity(np * 12);
    let mut f = Vec::with_capacity(np * 4);
    for k in 0..n1 {
        for j in 0..n1 {
            for i in 0..n1 {
                let (x, y, z) = (
                    i as f32 / N as f32,
                    j as f32 / N as f32,
                    k as f32 / N as f32,
                );
                let r = 1.0 + x;
                let a = 4.7 * y;
                let w = 0.05 * (7.0 * z).sin() * (5.0 * x).sin();
                for v in [r * a.cos() + w, r * a.sin(), 2.0 * z + w] {
                    pts.extend(v.to_le_bytes());
                }
                f.extend(((x * y + z) / 2.0).to_le_bytes());
            }
        }
    }
    let mut conn = Vec::with_capacity(nc * 64);
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                for v in lattice_hex(n1, n1, [i, j, k]) {
                    conn.extend(i64::from(v).to_le_bytes());
                }
            }
        }
    }
    let offsets: Vec<u8> = (1..=nc as i64)
        .flat_map(|c| (8 * c).to_le_bytes())
        .collect();
    let types = vec![12u8; nc];
    let mut app = Vec::new();
    let mut offs = Vec::new();
    for d in [&f, &pts, &conn, &offsets, &types] {
        offs.push(app.len());
        append_zlib(&mut app, d);
    }
    let head = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">\n      <PointData Scalars=\"f\">\n        <DataArray type=\"Float32\" Name=\"f\" format=\"appended\" offset=\"{}\"/>\n      </PointData>\n      <Points>\n        <DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{}\"/>\n      </Points>\n      <Cells>\n        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{}\"/>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"{}\"/>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _",
        offs[0], offs[1], offs[2], offs[3], offs[4]
    );
    let tmp = path.with_extension("tmp");
    let mut file = std::fs::File::create(&tmp).unwrap();
    file.write_all(head.as_bytes()).unwrap();
    file.write_all(&app).unwrap();
    file.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
        .unwrap();
    drop(file);
    std::fs::rename(&tmp, &path).unwrap();
    path
}

fn load(p: &Path) -> usize {
    io::read(p, &ReadOptions::default()).unwrap().cells.len()
}

fn bench_xml(c: &mut Criterion) {
    let mut g = c.benchmark_group("xml_load");
    g.sample_size(10);
    for rel in [
        "bluntfin/bluntfin_converted.vts",
        "synthetic/hex_shell_zlib.vtu",
    ] {
        if let Some(p) = zoovr::testdata::shared_file(rel) {
            g.bench_function(rel, |b| b.iter(|| load(&p)));
        }
    }
    let big = million_hex_file();
    g.bench_function("generated_1m_hex_zlib.vtu", |b| b.iter(|| load(&big)));
    g.finish();
}

criterion_group!(benches, bench_xml);

fn main() {
    if std::env::var_os("ZOOVR_XML_GEN").is_some() {
        println!("{}", million_hex_file().display());
        return;
    }
    if let Some(f) = std::env::var_os("ZOOVR_XML_LOAD") {
        let t = Instant::now();
        let n = load(Path::new(&f));
        println!("loaded {n} cells in {:.3} s", t.elapsed().as_secs_f64());
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
