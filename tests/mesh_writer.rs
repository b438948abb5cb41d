//! The `.vtu` and legacy writers, checked by an independent minimal parser
//! of what they write (XML attributes, appended raw blocks with UInt64
//! headers, zlib pieces) — not by zoovr's own readers.

use std::io::Read;

use zoovr::field::ArrayData;
use zoovr::generate::{single_cell, zoo_grid, Warp};
use zoovr::io::writer::{
    legacy_encode_name, write_legacy_ascii, write_pvd, write_series, write_vtu, Compression,
    ZLIB_BLOCK,
};
use zoovr::mesh::CellKind;

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(&tag[start..end])
}

/// (type, name, components, decoded bytes) for every DataArray.
fn parse_vtu(bytes: &[u8]) -> Vec<(String, String, usize, Vec<u8>)> {
    let marker = b"<AppendedData encoding=\"raw\">";
    let pos = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .expect("appended data");
    let xml = std::str::from_utf8(&bytes[..pos]).unwrap();
    let underscore = pos + bytes[pos..].iter().position(|&b| b == b'_').unwrap();
    let data = &bytes[underscore + 1..];
    let compressed = xml.contains("vtkZLibDataCompressor");
    assert!(xml.contains("header_type=\"UInt64\""));
    let u64_at = |o: usize| u64::from_le_bytes(data[o..o + 8].try_into().unwrap()) as usize;
    let mut out = Vec::new();
    for tag in xml.split("<DataArray").skip(1) {
        let ty = attr(tag, "type").unwrap().to_string();
        let name = attr(tag, "Name").unwrap_or("").to_string();
        let comps: usize = attr(tag, "NumberOfComponents").unwrap().parse().unwrap();
        let off: usize = attr(tag, "offset").unwrap().parse().unwrap();
        let decoded = if compressed {
            let (n, size, last) = (u64_at(off), u64_at(off + 8), u64_at(off + 16));
            assert!(size >= 32 * 1024);
            let sizes: Vec<usize> = (0..n).map(|k| u64_at(off + 24 + 8 * k)).collect();
            let mut p = off + 24 + 8 * n;
            let mut v = Vec::new();
            for (k, &s) in sizes.iter().enumerate() {
                let mut piece = Vec::new();
                flate2::read::ZlibDecoder::new(&data[p..p + s])
                    .read_to_end(&mut piece)
                    .unwrap();
                assert_eq!(piece.len(), if k + 1 == n { last } else { size });
                v.extend(piece);
                p += s;
            }
            v
        } else {
            let n = u64_at(off);
            data[off + 8..off + 8 + n].to_vec()
        };
        out.push((ty, name, comps, decoded));
    }
    out
}

fn ints(ty: &str, b: &[u8]) -> Vec<i64> {
    match ty {
        "Int32" => b
            .chunks(4)
            .map(|c| i32::from_le_bytes(c.try_into().unwrap()) as i64)
            .collect(),
        "Int64" => b
            .chunks(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        "UInt8" => b.iter().map(|&x| x as i64).collect(),
        t => panic!("type {t}"),
    }
}

#[test]
fn vtu_round_trips_through_an_independent_parser() {
    let mut mesh = zoo_grid(4, &Warp::default());
    mesh.cell_data.push(zoovr::field::DataArray {
        name: "id & <name>".into(),
        components: 1,
        data: ArrayData::Int((0..mesh.cells.len() as i64).collect()),
        vtk_type: "Int32".into(),
    });
    let dir = tempfile::tempdir().unwrap();
    for comp in [Compression::None, Compression::Zlib] {
        let path = dir.path().join(format!("zoo_{comp:?}.vtu"));
        write_vtu(&path, &mesh, comp).unwrap();
        let arrays = parse_vtu(&std::fs::read(&path).unwrap());
        let get = |n: &str| arrays.iter().find(|a| a.1 == n).unwrap();
        // points: the unnamed Float64 array
        let pts = arrays.iter().find(|a| a.1.is_empty()).unwrap();
        assert_eq!((pts.0.as_str(), pts.2), ("Float64", 3));
        let xyz: Vec<f64> = pts
            .3
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let want: Vec<f64> = mesh.points.iter().flat_map(|p| p.to_array()).collect();
        assert_eq!(xyz, want);
        let conn = get("connectivity");
        let conn: Vec<u32> = ints(&conn.0, &conn.3).iter().map(|&x| x as u32).collect();
        assert_eq!(conn, mesh.cells.conn);
        let offs = get("offsets");
        let offs = ints(&offs.0, &offs.3);
        assert_eq!(offs.len(), mesh.cells.len());
        assert_eq!(offs.last().copied(), Some(mesh.cells.conn.len() as i64));
        let types = ints("UInt8", &get("types").3);
        let want: Vec<i64> = mesh.cells.kinds.iter().map(|&k| k as u8 as i64).collect();
        assert_eq!(types, want);
        let f = get("f");
        assert_eq!(f.0, "Float32");
        let ArrayData::F32(fv) = &mesh.point_data[0].data else {
            panic!()
        };
        let got: Vec<f32> =
            f.3.chunks(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect();
        assert_eq!(&got, fv);
        let id = get("id &amp; &lt;name&gt;"); // XML-escaped in the file
        assert_eq!(
            ints(&id.0, &id.3),
            (0..mesh.cells.len() as i64).collect::<Vec<_>>()
        );
    }
}

#[test]
fn zlib_pieces_split_large_arrays() {
    // 21^3 points = 222 KB of coordinates: 4 pieces of 64 KiB
    let mesh = hex_grid(20);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.vtu");
    write_vtu(&path, &mesh, Compression::Zlib).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let arrays = parse_vtu(&bytes);
    let pts = arrays.iter().find(|a| a.1.is_empty()).unwrap();
    assert_eq!(pts.3.len(), mesh.points.len() * 24);
    assert!(pts.3.len() > 2 * ZLIB_BLOCK);
    assert!(bytes.len() < mesh.points.len() * 24 + mesh.cells.conn.len() * 4);
}

fn hex_grid(n: usize) -> zoovr::mesh::Mesh {
    zoovr::generate::warped_hex_grid(n, &Warp::default())
}

#[test]
fn polyhedron_streams_are_written() {
    let mesh = single_cell(CellKind::Polyhedron);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("poly.vtu");
    write_vtu(&path, &mesh, Compression::None).unwrap();
    let arrays = parse_vtu(&std::fs::read(&path).unwrap());
    let faces = arrays.iter().find(|a| a.1 == "faces").unwrap();
    let faces = ints(&faces.0, &faces.3);
    // 9 faces: 5 quads and 4 triangles
    assert_eq!(faces[0], 9);
    assert_eq!(faces.len(), 1 + 5 * 5 + 4 * 4);
    let fo = arrays.iter().find(|a| a.1 == "faceoffsets").unwrap();
    assert_eq!(ints(&fo.0, &fo.3), vec![faces.len() as i64]);
}

#[test]
fn legacy_ascii_layout() {
    let mut mesh = single_cell(CellKind::Wedge);
    mesh.point_data[0].name = "Nodal Stress%".into();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("w.vtk");
    write_legacy_ascii(&path, &mesh, "wedge").unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "# vtk DataFile Version 4.2");
    assert_eq!(lines[2], "ASCII");
    assert_eq!(lines[3], "DATASET UNSTRUCTURED_GRID");
    assert_eq!(lines[4], "POINTS 6 double");
    assert_eq!(lines[11], "CELLS 1 7");
    assert_eq!(lines[12], "6 0 1 2 3 4 5");
    assert_eq!(lines[13], "CELL_TYPES 1");
    assert_eq!(lines[14], "13");
    assert_eq!(lines[15], "POINT_DATA 6");
    assert_eq!(lines[16], "SCALARS Nodal%20Stress%25 float 1");
    // shortest round-trip floats parse back exactly
    for (i, p) in mesh.points.iter().enumerate() {
        let v: Vec<f64> = lines[5 + i]
            .split(' ')
            .map(|s| s.parse().unwrap())
            .collect();
        assert_eq!(v, p.to_array());
    }
    assert_eq!(legacy_encode_name("a b"), "a%20b");
}

#[test]
fn collections() {
    let dir = tempfile::tempdir().unwrap();
    let steps = vec![(0.0, "s_0.vtu".to_string()), (0.5, "s_1.vtu".to_string())];
    let pvd = dir.path().join("s.pvd");
    write_pvd(&pvd, &steps).unwrap();
    let text = std::fs::read_to_string(&pvd).unwrap();
    assert!(text.contains("<DataSet timestep=\"0.5\" group=\"\" part=\"0\" file=\"s_1.vtu\"/>"));
    let series = dir.path().join("s.vtu.series");
    write_series(&series, &steps).unwrap();
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&series).unwrap()).unwrap();
    assert_eq!(v["files"][1]["name"], "s_1.vtu");
    assert_eq!(v["files"][1]["time"], 0.5);
}
