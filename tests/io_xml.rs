//! VTK XML readers and time collections, on files made here (the real
//! datasets are `tests/io_xml_real.rs`).
//!
//! - Round trips: a small mixed mesh is written by an encoder in this file
//!   (independent of the reader) in every encoding (ascii, inline base64,
//!   appended raw and base64; no compression, zlib, LZ4, LZMA; UInt32/UInt64
//!   headers; little/big endian; several integer widths) and read back.
//! - Hand-written `.vti`, `.vtr`, `.vts`, polyhedron and multi-piece files.
//! - Every `meshes/corrupt/xml_*` file fails with an error naming it, and a
//!   seeded mutation test (byte flips, truncations) never panics.

mod xml_util;

use std::io::Write;
use std::path::Path;

use base64::engine::general_purpose::STANDARD as B64;
use base64::Engine;
use xml_util::{array, by_type, check_mesh, tmp, write, POLY};
use zoovr::field::ArrayData;
use zoovr::io::{self, collection, xml, Format, ReadOptions};
use zoovr::mesh::{CellKind, Mesh};
use zoovr::testdata::Rng;

// ---------------------------------------------------------------- encoder

#[derive(Clone, Copy, Debug, PartialEq)]
enum Fmt {
    Ascii,
    Binary,
    AppRaw,
    AppB64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Comp {
    None,
    Zlib,
    Lz4,
    Lzma,
}

#[derive(Clone, Copy, Debug)]
struct Enc {
    fmt: Fmt,
    comp: Comp,
    h64: bool,
    be: bool,
    block: usize,
    /// Compressed base64 as one stream (header and blocks together).
    joined: bool,
}

fn value_bytes(ty: &str, v: f64, be: bool) -> Vec<u8> {
    macro_rules! b {
        ($t:ty) => {{
            let x = v as $t;
            if be {
                x.to_be_bytes().to_vec()
            } else {
                x.to_le_bytes().to_vec()
            }
        }};
    }
    match ty {
        "Int8" => b!(i8),
        "UInt8" => b!(u8),
        "Int16" => b!(i16),
        "UInt16" => b!(u16),
        "Int32" => b!(i32),
        "UInt32" => b!(u32),
        "Int64" => b!(i64),
        "UInt64" => b!(u64),
        "Float32" => b!(f32),
        _ => b!(f64),
    }
}

impl Enc {
    fn word(&self, v: usize) -> Vec<u8> {
        match (self.h64, self.be) {
            (true, true) => (v as u64).to_be_bytes().to_vec(),
            (true, false) => (v as u64).to_le_bytes().to_vec(),
            (false, true) => (v as u32).to_be_bytes().to_vec(),
            (false, false) => (v as u32).to_le_bytes().to_vec(),
        }
    }

    /// (header, body) of a binary payload.
    fn payload(&self, data: &[u8]) -> (Vec<u8>, Vec<u8>) {
        if self.comp == Comp::None {
            return (self.word(data.len()), data.to_vec());
        }
        let blocks: Vec<&[u8]> = data.chunks(self.block).collect();
        let mut hdr = self.word(blocks.len());
        hdr.extend(self.word(self.block));
        let last = data.len() % self.block;
        hdr.extend(self.word(last));
        let mut body = Vec::new();
        for b in &blocks {
            let c = match self.comp {
                Comp::Zlib => {
                    let mut e =
                        flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                    e.write_all(b).unwrap();
                    e.finish().unwrap()
                }
                Comp::Lzma => {
                    // As VTK's `vtkLZMADataCompressor`: one `.xz` stream
                    // per block (liblzma's easy encoder).
                    let mut e = xz2::write::XzEncoder::new(Vec::new(), 6);
                    e.write_all(b).unwrap();
                    e.finish().unwrap()
                }
                _ => lz4_flex::block::compress(b),
            };
            hdr.extend(self.word(c.len()));
            body.extend(c);
        }
        (hdr, body)
    }

    fn array(&self, name: &str, ty: &str, nc: usize, vals: &[f64], app: &mut Vec<u8>) -> String {
        let head = format!("<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{nc}\"");
        let bytes: Vec<u8> = vals
            .iter()
            .flat_map(|&v| value_bytes(ty, v, self.be))
            .collect();
        let (h, b) = self.payload(&bytes);
        let b64 = |h: &[u8], b: &[u8]| {
            if self.comp == Comp::None || self.joined {
                B64.encode([h, b].concat())
            } else {
                B64.encode(h) + &B64.encode(b)
            }
        };
        match self.fmt {
            Fmt::Ascii => {
                let t: Vec<String> = vals
                    .iter()
                    .map(|v| {
                        if ty.starts_with("Float32") {
                            format!("{}", *v as f32)
                        } else {
                            format!("{v}")
                        }
                    })
                    .collect();
                format!("{head} format=\"ascii\">\n{}\n</DataArray>\n", t.join(" "))
            }
            Fmt::Binary => format!(
                "{head} format=\"binary\">\n  {}\n</DataArray>\n",
                b64(&h, &b)
            ),
            Fmt::AppRaw => {
                let off = app.len();
                app.extend(h);
                app.extend(b);
                format!("{head} format=\"appended\" offset=\"{off}\"/>\n")
            }
            Fmt::AppB64 => {
                let off = app.len();
                app.extend(b64(&h, &b).into_bytes());
                format!("{head} format=\"appended\" offset=\"{off}\"/>\n")
            }
        }
    }

    fn file(&self, body: &str, app: &[u8]) -> Vec<u8> {
        let mut f = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" header_type=\"{}\"{}>\n<UnstructuredGrid>\n{body}</UnstructuredGrid>\n",
            if self.be { "BigEndian" } else { "LittleEndian" },
            if self.h64 { "UInt64" } else { "UInt32" },
            match self.comp {
                Comp::None => "",
                Comp::Zlib => " compressor=\"vtkZLibDataCompressor\"",
                Comp::Lz4 => " compressor=\"vtkLZ4DataCompressor\"",
                Comp::Lzma => " compressor=\"vtkLZMADataCompressor\"",
            }
        )
        .into_bytes();
        if matches!(self.fmt, Fmt::AppRaw | Fmt::AppB64) {
            let enc = if self.fmt == Fmt::AppRaw {
                "raw"
            } else {
                "base64"
            };
            f.extend(format!("<AppendedData encoding=\"{enc}\">\n   _").into_bytes());
            f.extend(app);
            f.extend(b"\n</AppendedData>\n");
        }
        f.extend(b"</VTKFile>\n");
        f
    }
}

/// The test mesh: a 3 x 2 x 2 lattice plus 7 extra points; cells: hex,
/// voxel, triangle (dropped), tet, quadratic tet, wedge.
struct Sample {
    points: Vec<f64>,
    conn: Vec<f64>,
    offsets: Vec<f64>,
    types: Vec<f64>,
}

fn sample() -> Sample {
    let mut points = Vec::new();
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..3 {
                points.extend([i as f64 * 0.5, j as f64 + 0.25, k as f64 * 0.1]);
            }
        }
    }
    for e in 0..7 {
        points.extend([-1.0 - e as f64, 0.125 * e as f64, -0.3]);
    }
    let cells: Vec<(u8, Vec<u32>)> = vec![
        (12, vec![0, 1, 4, 3, 6, 7, 10, 9]),
        (11, vec![1, 2, 4, 5, 7, 8, 10, 11]),
        (5, vec![0, 1, 3]),
        (10, vec![0, 1, 3, 12]),
        (24, vec![0, 1, 3, 12, 13, 14, 15, 16, 17, 18]),
        (13, vec![0, 1, 3, 6, 7, 9]),
    ];
    let mut conn = Vec::new();
    let mut offsets = Vec::new();
    let mut types = Vec::new();
    for (t, n) in cells {
        conn.extend(n.iter().map(|&x| x as f64));
        offsets.push(conn.len() as f64);
        types.push(t as f64);
    }
    Sample {
        points,
        conn,
        offsets,
        types,
    }
}

fn write_sample(enc: &Enc, int_ty: &str, types_ty: &str) -> Vec<u8> {
    let s = sample();
    let mut app = Vec::new();
    let np = s.points.len() / 3;
    let temp: Vec<f64> = (0..np).map(|i| (i as f32 * 0.1f32) as f64).collect();
    let vel: Vec<f64> = (0..np * 3).map(|i| i as f64 / 3.0).collect();
    let cid: Vec<f64> = (0..6).map(|i| (i * 10) as f64 - 20.0).collect();
    let mut body = format!(
        "<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"6\">\n<PointData Scalars=\"temp\">\n"
    );
    body += &enc.array("temp", "Float32", 1, &temp, &mut app);
    body += &enc.array("vel", "Float64", 3, &vel, &mut app);
    body += "</PointData>\n<CellData Scalars=\"cid\">\n";
    body += &enc.array("cid", "Int16", 1, &cid, &mut app);
    body += "</CellData>\n<Points>\n";
    body += &enc.array("Points", "Float64", 3, &s.points, &mut app);
    body += "</Points>\n<Cells>\n";
    body += &enc.array("connectivity", int_ty, 1, &s.conn, &mut app);
    body += &enc.array("offsets", int_ty, 1, &s.offsets, &mut app);
    body += &enc.array("types", types_ty, 1, &s.types, &mut app);
    body += "</Cells>\n</Piece>\n";
    enc.file(&body, &app)
}

fn check_sample(m: &Mesh, what: &str) {
    check_mesh(m);
    let s = sample();
    assert_eq!(m.points.len(), 19, "{what}");
    assert_eq!(m.points[5].to_array(), [1.0, 1.25, 0.0], "{what}");
    assert_eq!(m.cells.len(), 5, "{what}");
    assert_eq!(m.source.ignored_cells, 1, "{what}");
    assert_eq!(m.cells.nodes(0), &[0, 1, 4, 3, 6, 7, 10, 9], "{what}");
    assert_eq!(
        m.cells.nodes(1),
        &[1, 2, 5, 4, 7, 8, 11, 10],
        "{what}: voxel to hex order"
    );
    assert_eq!(
        m.cells.nodes(3),
        &[0, 1, 3, 12],
        "{what}: quadratic tet corners"
    );
    assert_eq!(
        m.cells.kinds,
        vec![
            CellKind::Hexahedron,
            CellKind::Hexahedron,
            CellKind::Tetra,
            CellKind::Tetra,
            CellKind::Wedge
        ]
    );
    for (name, n) in [
        ("hexahedron", 1),
        ("voxel", 1),
        ("tetra", 1),
        ("quadratic_tetra", 1),
        ("wedge", 1),
    ] {
        assert_eq!(by_type(m, name), n, "{what}: {name}");
    }
    let t = array(m, "temp");
    assert_eq!(t.vtk_type, "Float32");
    match &t.data {
        ArrayData::F32(v) => assert!(
            v.iter()
                .enumerate()
                .all(|(i, x)| x.to_bits() == (i as f32 * 0.1f32).to_bits()),
            "{what}"
        ),
        other => panic!("{what}: temp is {other:?}"),
    }
    assert_eq!(array(m, "vel").component(4, 2), 14.0 / 3.0, "{what}");
    match &array(m, "cid").data {
        ArrayData::Int(v) => assert_eq!(v, &[-20, -10, 10, 20, 30], "{what}: cell data filtered"),
        other => panic!("{what}: cid is {other:?}"),
    }
    assert_eq!(m.active_point_scalars.as_deref(), Some("temp"));
    assert_eq!(m.active_cell_scalars.as_deref(), Some("cid"));
    assert_eq!(s.types.len(), 6);
}

#[test]
fn every_encoding_round_trips() {
    let mut n = 0;
    for fmt in [Fmt::Ascii, Fmt::Binary, Fmt::AppRaw, Fmt::AppB64] {
        for comp in [Comp::None, Comp::Zlib, Comp::Lz4, Comp::Lzma] {
            if fmt == Fmt::Ascii && comp != Comp::None {
                continue;
            }
            for h64 in [false, true] {
                for be in [false, true] {
                    for (int_ty, types_ty, block) in [
                        ("Int32", "UInt8", 64),
                        ("Int64", "Int8", 40),
                        ("UInt16", "Int32", 7),
                        ("Int8", "Int64", 1 << 15),
                    ] {
                        let enc = Enc {
                            fmt,
                            comp,
                            h64,
                            be,
                            block,
                            joined: block == 7,
                        };
                        let bytes = write_sample(&enc, int_ty, types_ty);
                        let what = format!("{enc:?} {int_ty} {types_ty}");
                        let m = xml::read_bytes(
                            Path::new("sample.vtu"),
                            &bytes,
                            Format::XmlUnstructured,
                        )
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                        check_sample(&m, &what);
                        n += 1;
                    }
                }
            }
        }
    }
    assert_eq!(n, 16 + 3 * 4 * 2 * 2 * 4);
}

/// LZMA blocks: a corrupt stream, a truncated one and one that decodes to
/// fewer bytes than its header says each fail naming the file, the array
/// and the block; a whole real-sized array of zeros (the best case of the
/// ratio) still reads.
#[test]
fn lzma_blocks_are_checked() {
    let enc = Enc {
        fmt: Fmt::AppRaw,
        comp: Comp::Lzma,
        h64: false,
        be: false,
        block: 1 << 15,
        joined: false,
    };
    let np = 40_000;
    let points = |h: &[u8], b: &[u8]| {
        let body = format!(
            "<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"0\"><Points>\
             <DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points></Piece>"
        );
        let app = [h, b].concat();
        xml::read_bytes(
            Path::new("lzma.vtu"),
            &enc.file(&body, &app),
            Format::XmlUnstructured,
        )
    };
    let (h, b) = enc.payload(&vec![0u8; np * 12]);
    let m = points(&h, &b).unwrap();
    assert_eq!(m.points.len(), np);
    assert!(m.points.iter().all(|p| *p == glam::DVec3::ZERO));
    // 480 kB of zeros in 15 blocks of at most 32 KiB: the ratio stays far
    // below the bound the reader allows.
    assert!(b.len() * 100 < np * 12, "{} compressed bytes", b.len());
    let fails = |h: &[u8], b: &[u8], what: &str| {
        let e = points(h, b).unwrap_err().to_string();
        assert!(
            e.contains("lzma.vtu") && e.contains("Points") && e.contains("block"),
            "{what}: {e}"
        );
    };
    // A flipped byte in the middle of the first block's stream.
    let mut bad = b.clone();
    bad[30] ^= 0x55;
    fails(&h, &bad, "flipped byte");
    // The first block's stream cut short (its size in the header too).
    let first = u32::from_le_bytes(h[12..16].try_into().unwrap()) as usize;
    let mut hc = h.clone();
    hc[12..16].copy_from_slice(&((first - 8) as u32).to_le_bytes());
    let bc = [&b[..first - 8], &b[first..]].concat();
    fails(&hc, &bc, "truncated stream");
    // A header claiming a larger last block than its stream holds.
    let mut hl = h.clone();
    let last = u32::from_le_bytes(hl[8..12].try_into().unwrap());
    hl[8..12].copy_from_slice(&(last + 12).to_le_bytes());
    let e = points(&hl, &b).unwrap_err().to_string();
    assert!(e.contains("lzma.vtu"), "{e}");
}

#[test]
fn hostile_header_is_refused_before_allocating() {
    // A zlib header claiming 2^40-byte blocks and 10^12 points.
    let enc = Enc {
        fmt: Fmt::AppRaw,
        comp: Comp::Zlib,
        h64: true,
        be: false,
        block: 64,
        joined: false,
    };
    let mut app = enc.word(1);
    app.extend(enc.word(1 << 40));
    app.extend(enc.word(0));
    app.extend(enc.word(16));
    app.extend([0u8; 16]);
    let body = "<Piece NumberOfPoints=\"1000000000000\" NumberOfCells=\"0\"><Points>\
        <DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points></Piece>";
    let e = xml::read_bytes(
        Path::new("huge.vtu"),
        &enc.file(body, &app),
        Format::XmlUnstructured,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("huge.vtu"), "{e}");
    let body = "<Piece NumberOfPoints=\"300000000\" NumberOfCells=\"0\"><Points>\
        <DataArray type=\"Float32\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points></Piece>";
    let e = xml::read_bytes(
        Path::new("huge.vtu"),
        &enc.file(body, &app),
        Format::XmlUnstructured,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("huge.vtu") && e.contains("Points") && e.contains("ratio"),
        "{e}"
    );
}

#[test]
fn reused_offsets_cannot_amplify_memory() {
    // 100 arrays all pointing at one zlib block of 1 MB of zeros: each is a
    // valid array, but together they would decode to 100 MB from a ~30 KB file.
    let enc = Enc {
        fmt: Fmt::AppRaw,
        comp: Comp::Zlib,
        h64: false,
        be: false,
        block: 1 << 20,
        joined: false,
    };
    let np = (1 << 20) / 12;
    let (h, b) = enc.payload(&vec![0u8; np * 12]);
    let app = [h, b].concat();
    let file = |k: usize| {
        let mut body = format!("<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"0\"><PointData>");
        for i in 0..k {
            body += &format!("<DataArray type=\"Float32\" Name=\"a{i}\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>");
        }
        body += "</PointData><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/></Points></Piece>";
        enc.file(&body, &app)
    };
    let m = xml::read_bytes(Path::new("amp.vtu"), &file(3), Format::XmlUnstructured).unwrap();
    assert_eq!(m.point_data.len(), 3);
    let big = file(100);
    assert!(big.len() < 40_000, "{}", big.len());
    let e = xml::read_bytes(Path::new("amp.vtu"), &big, Format::XmlUnstructured)
        .unwrap_err()
        .to_string();
    assert!(e.contains("amp.vtu") && e.contains("offsets reused"), "{e}");
}

// ---------------------------------------------------------------- hand-written files

fn read_str(name: &str, text: &str, format: Format) -> Result<Mesh, String> {
    xml::read_bytes(Path::new(name), text.as_bytes(), format).map_err(|e| e.to_string())
}

#[test]
fn image_data_as_hexahedra() {
    let m = read_str(
        "img.vti",
        r#"<VTKFile type="ImageData" version="1.0"><ImageData WholeExtent="0 2 0 1 0 1" Origin="1 2 3" Spacing="0.5 1 2">
        <Piece Extent="0 2 0 1 0 1"><PointData Scalars="s"><DataArray type="Float64" Name="s" format="ascii">0 1 2 3 4 5 6 7 8 9 10 11</DataArray></PointData>
        <CellData><DataArray type="Int32" Name="c" format="ascii">7 8</DataArray></CellData></Piece></ImageData></VTKFile>"#,
        Format::XmlImage,
    )
    .unwrap();
    check_mesh(&m);
    assert_eq!(m.cells.len(), 2);
    assert_eq!(m.cells.nodes(1), &[1, 2, 5, 4, 7, 8, 11, 10]);
    assert_eq!(m.points[11].to_array(), [2.0, 3.0, 5.0]);
    assert_eq!(m.bounds(), [1.0, 2.0, 2.0, 3.0, 3.0, 5.0]);
    assert_eq!(array(&m, "c").component(1, 0), 8.0);
    assert_eq!(by_type(&m, "hexahedron"), 2);
}

#[test]
fn rectilinear_and_structured_grids() {
    let m = read_str(
        "r.vtr",
        r#"<VTKFile type="RectilinearGrid"><RectilinearGrid WholeExtent="0 2 0 1 0 1"><Piece Extent="0 2 0 1 0 1">
        <Coordinates><DataArray type="Float32" format="ascii">0 1 3</DataArray><DataArray type="Float64" format="ascii">0 2</DataArray>
        <DataArray type="Float64" format="ascii">-1 1</DataArray></Coordinates></Piece></RectilinearGrid></VTKFile>"#,
        Format::XmlRectilinear,
    )
    .unwrap();
    check_mesh(&m);
    assert_eq!(m.cells.len(), 2);
    assert_eq!(m.points[5].to_array(), [3.0, 2.0, -1.0]);
    assert_eq!(m.bounds(), [0.0, 3.0, 0.0, 2.0, -1.0, 1.0]);

    let m = read_str(
        "s.vts",
        r#"<VTKFile type="StructuredGrid"><StructuredGrid WholeExtent="0 1 0 1 0 1"><Piece Extent="0 1 0 1 0 1">
        <Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0 1 1 0 0 0 1 1 0 1 0 1 1 1 1 1.5</DataArray></Points>
        </Piece></StructuredGrid></VTKFile>"#,
        Format::XmlStructured,
    )
    .unwrap();
    assert_eq!(m.cells.nodes(0), &[0, 1, 3, 2, 4, 5, 7, 6]);
    assert_eq!(m.points[7].z, 1.5);

    // A flat lattice has only 2D cells: none kept, all counted.
    let m = read_str(
        "flat.vti",
        r#"<VTKFile type="ImageData"><ImageData WholeExtent="0 3 0 2 0 0"><Piece Extent="0 3 0 2 0 0">
        <CellData><DataArray type="Float32" Name="c" format="ascii">1 2 3 4 5 6</DataArray></CellData></Piece></ImageData></VTKFile>"#,
        Format::XmlImage,
    )
    .unwrap();
    assert_eq!((m.cells.len(), m.source.ignored_cells), (0, 6));
    assert_eq!(array(&m, "c").tuples(), 0);
}

#[test]
fn polyhedron_from_faces() {
    let m = read_str("poly.vtu", POLY, Format::XmlUnstructured).unwrap();
    check_mesh(&m);
    assert_eq!(m.cells.kinds, vec![CellKind::Polyhedron, CellKind::Tetra]);
    assert_eq!(m.cells.face_count(0), 6);
    assert_eq!(m.cells.nodes(0), &[0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(m.cells.poly_faces[&0][2], vec![4, 5, 6, 7]);
    assert_eq!(by_type(&m, "polyhedron"), 1);
    // The VTK 9.4 layout: faces shared through face ids.
    let v94 = POLY
        .replace(
            r#"<DataArray type="Int64" Name="faces" format="ascii">6 4 0 3 2 1 4 0 4 7 3 4 4 5 6 7 4 5 1 2 6 4 0 1 5 4 4 2 3 7 6</DataArray>"#,
            r#"<DataArray type="Int32" Name="face_connectivity" format="ascii">0 3 2 1 0 4 7 3 4 5 6 7 5 1 2 6 0 1 5 4 2 3 7 6</DataArray>
            <DataArray type="Int32" Name="face_offsets" format="ascii">4 8 12 16 20 24</DataArray>
            <DataArray type="Int32" Name="polyhedron_to_faces" format="ascii">0 1 2 3 4 5</DataArray>"#,
        )
        .replace(
            r#"<DataArray type="Int64" Name="faceoffsets" format="ascii">31 -1</DataArray>"#,
            r#"<DataArray type="Int64" Name="polyhedron_offsets" format="ascii">0 6 6</DataArray>"#,
        );
    let m2 = read_str("poly94.vtu", &v94, Format::XmlUnstructured).unwrap();
    check_mesh(&m2);
    assert_eq!(m2.cells.poly_faces, m.cells.poly_faces);
    // A face stream pointing outside the points is refused.
    let bad = POLY.replace("4 4 5 6 7 4 5", "4 4 5 6 70 4 5");
    let e = read_str("poly.vtu", &bad, Format::XmlUnstructured).unwrap_err();
    assert!(e.contains("poly.vtu") && e.contains("faces"), "{e}");
}

#[test]
fn several_pieces_are_merged() {
    let piece = |x: f64| {
        format!(
            r#"<Piece NumberOfPoints="4" NumberOfCells="1"><PointData><DataArray type="Int32" Name="id" format="ascii">1 2 3 4</DataArray></PointData>
            <Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">{x} 0 0 {} 0 0 {x} 1 0 {x} 0 1</DataArray></Points>
            <Cells><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3</DataArray>
            <DataArray type="Int32" Name="offsets" format="ascii">4</DataArray><DataArray type="UInt8" Name="types" format="ascii">10</DataArray></Cells></Piece>"#,
            x + 1.0
        )
    };
    let text = format!(
        r#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid>{}{}</UnstructuredGrid></VTKFile>"#,
        piece(0.0),
        piece(5.0)
    );
    let m = read_str("two.vtu", &text, Format::XmlUnstructured).unwrap();
    check_mesh(&m);
    assert_eq!(m.cells.nodes(1), &[4, 5, 6, 7]);
    assert_eq!(m.points[4].x, 5.0);
    assert_eq!(array(&m, "id").tuples(), 8);
    assert_eq!(by_type(&m, "tetra"), 2);
}

// ---------------------------------------------------------------- collections

#[test]
fn pvd_and_series_resolve_sort_and_refuse() {
    let d = tmp();
    std::fs::create_dir(d.path().join("sub")).unwrap();
    write(&d.path().join("sub"), "a.vtu", POLY);
    write(d.path(), "b.vtu", POLY);
    let pvd = write(
        d.path(),
        "c.pvd",
        r#"<VTKFile type="Collection"><Collection>
        <DataSet timestep="2.5" part="0" file="b.vtu"/><DataSet timestep="2.5" part="1" file="nope.vtu"/>
        <DataSet timestep="1" part="0" file="sub/a.vtu"/></Collection></VTKFile>"#,
    );
    let steps = collection::read_pvd(&pvd).unwrap();
    assert_eq!(steps.len(), 2);
    assert_eq!(steps[0].time, 1.0);
    assert!(steps[0].path.ends_with("sub/a.vtu"));
    let m = io::read(&pvd, &ReadOptions::default()).unwrap();
    assert_eq!(m.cells.len(), 2);

    let series = write(
        d.path(),
        "c.vtu.series",
        r#"{"file-series-version": "1.0", "files": [{"name": "b.vtu", "time": 3}, {"name": "sub/a.vtu", "time": 0.5}]}"#,
    );
    let steps = io::read_series(&series).unwrap();
    assert_eq!(
        steps.iter().map(|s| s.time).collect::<Vec<_>>(),
        vec![0.5, 3.0]
    );

    let missing = write(
        d.path(),
        "m.series",
        r#"{"file-series-version": "1.0", "files": [{"name": "gone.vtu", "time": 0}]}"#,
    );
    let e = io::read_series(&missing).unwrap_err().to_string();
    assert!(
        e.contains("m.series") && e.contains("files[0]") && e.contains("gone.vtu"),
        "{e}"
    );
    let selfref = write(
        d.path(),
        "s.pvd",
        r#"<VTKFile type="Collection"><Collection><DataSet timestep="0" file="s.pvd"/></Collection></VTKFile>"#,
    );
    let e = io::read(&selfref, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("s.pvd") && e.contains("itself"), "{e}");
}

// ---------------------------------------------------------------- corrupt files

#[test]
fn every_corrupt_xml_file_fails_naming_the_file() {
    let dir = zoovr::testdata::mesh_file("corrupt");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if !name.starts_with("xml_") {
            continue;
        }
        let t = std::time::Instant::now();
        let r = io::read(&path, &ReadOptions::default());
        let e = match r {
            Ok(_) => panic!("{name} was read without error"),
            Err(e) => e.to_string(),
        };
        eprintln!("{e}");
        assert!(
            e.contains(&name),
            "{name}: error does not name the file: {e}"
        );
        // The place: a byte offset (XML), a line (.series JSON) or the
        // entry of a collection.
        let placed = ["byte ", "line "].iter().any(|k| {
            e.match_indices(k)
                .any(|(i, _)| e[i + k.len()..].starts_with(|c: char| c.is_ascii_digit()))
        }) || e.contains("files[");
        assert!(placed, "{name}: error does not say where: {e}");
        assert!(
            t.elapsed().as_secs_f64() < 2.0,
            "{name} took {:?}",
            t.elapsed()
        );
        n += 1;
    }
    assert!(n >= 8, "only {n} corrupt xml files");
}

#[test]
fn mutations_never_panic() {
    let seeds: Vec<Vec<u8>> = vec![
        write_sample(
            &Enc {
                fmt: Fmt::AppRaw,
                comp: Comp::Zlib,
                h64: true,
                be: false,
                block: 48,
                joined: false,
            },
            "Int64",
            "UInt8",
        ),
        write_sample(
            &Enc {
                fmt: Fmt::Binary,
                comp: Comp::Lz4,
                h64: false,
                be: true,
                block: 40,
                joined: false,
            },
            "Int32",
            "Int8",
        ),
        write_sample(
            &Enc {
                fmt: Fmt::AppRaw,
                comp: Comp::Lzma,
                h64: true,
                be: true,
                block: 56,
                joined: false,
            },
            "Int32",
            "UInt8",
        ),
        write_sample(
            &Enc {
                fmt: Fmt::AppB64,
                comp: Comp::None,
                h64: false,
                be: false,
                block: 64,
                joined: false,
            },
            "Int32",
            "UInt8",
        ),
        write_sample(
            &Enc {
                fmt: Fmt::Ascii,
                comp: Comp::None,
                h64: false,
                be: false,
                block: 64,
                joined: false,
            },
            "Int32",
            "UInt8",
        ),
        POLY.as_bytes().to_vec(),
    ];
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let start = std::time::Instant::now();
    let mut errors = 0;
    let total = 3000;
    for round in 0..total {
        let mut b = seeds[round % seeds.len()].clone();
        match rng.below(4) {
            0 => b.truncate(rng.below(b.len())),
            1 => {
                for _ in 0..1 + rng.below(4) {
                    let i = rng.below(b.len());
                    b[i] ^= 1 << rng.below(8);
                }
            }
            2 => {
                let i = rng.below(b.len());
                b[i] = b"0123456789-+e<>\"= _"[rng.below(19)];
            }
            _ => {
                let i = rng.below(b.len());
                let j = (i + rng.below(64)).min(b.len());
                b.drain(i..j);
            }
        }
        let r = std::panic::catch_unwind(|| {
            xml::read_bytes(Path::new("mut.vtu"), &b, Format::XmlUnstructured)
        });
        match r {
            Ok(Ok(m)) => check_mesh(&m),
            Ok(Err(e)) => {
                assert!(e.to_string().contains("mut.vtu"));
                errors += 1;
            }
            Err(_) => panic!(
                "round {round} panicked; input: {:?}",
                String::from_utf8_lossy(&b)
            ),
        }
    }
    assert!(errors > total / 4, "mutations should mostly fail: {errors}");
    assert!(start.elapsed().as_secs() < 30, "{:?}", start.elapsed());
}
