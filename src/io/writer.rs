//! Writers for the formats zoovr produces: VTK XML `.vtu` (appended raw data,
//! optionally zlib-compressed), VTK legacy ASCII `.vtk`, and `.pvd` /
//! `.series` time collections.
//!
//! `.vtu` layout: every array is one block in `<AppendedData encoding="raw">`
//! with `header_type="UInt64"`. Uncompressed, a block is its byte count then
//! the bytes. With [`Compression::Zlib`] the data is cut into
//! [`ZLIB_BLOCK`]-byte pieces compressed independently (in parallel) and the
//! header is `[pieces, piece size, last piece size, compressed sizes...]`,
//! VTK's `vtkZLibDataCompressor` layout. Points are Float64 (lossless);
//! connectivity and offsets are Int32 when every value fits, else Int64;
//! types are UInt8 VTK codes of [`crate::mesh::CellKind`]; general
//! polyhedra add the `faces` / `faceoffsets` streams. Data arrays keep their
//! stored type (Float32, Float64, or the integer width their `vtk_type` names).
//!
//! The legacy writer emits version 4.2 ASCII with `SCALARS` (1 component),
//! `VECTORS` (3) or `FIELD` arrays; array names are percent-encoded as VTK
//! does; polyhedra are written as their face stream in `CELLS`, as VTK 4.2
//! does. Floats use Rust's shortest round-trip formatting, so a file read
//! back gives identical values.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use thiserror::Error;

use crate::field::{ArrayData, DataArray};
use crate::mesh::{CellKind, Mesh};

/// Size of the independently compressed zlib pieces (VTK's default is 32 KiB).
pub const ZLIB_BLOCK: usize = 1 << 16;

/// Compression of `.vtu` appended data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    None,
    Zlib,
}

/// A writer error (always names the file).
#[derive(Debug, Error)]
pub enum WriteError {
    #[error("{}: cannot write: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {msg}", path.display())]
    Invalid { path: PathBuf, msg: String },
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> WriteError + '_ {
    move |source| WriteError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// One array ready for the appended section.
struct Block {
    xml_type: &'static str,
    bytes: Vec<u8>,
}

fn le_bytes<T: Copy, const N: usize>(v: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    let mut out = Vec::with_capacity(v.len() * N);
    for &x in v {
        out.extend_from_slice(&f(x));
    }
    out
}

fn int_block(v: &[i64], ty: &str) -> Block {
    let (xml_type, bytes): (&'static str, Vec<u8>) = match ty {
        "Int8" => ("Int8", le_bytes(v, |x| (x as i8).to_le_bytes())),
        "UInt8" => ("UInt8", le_bytes(v, |x| (x as u8).to_le_bytes())),
        "Int16" => ("Int16", le_bytes(v, |x| (x as i16).to_le_bytes())),
        "UInt16" => ("UInt16", le_bytes(v, |x| (x as u16).to_le_bytes())),
        "Int32" => ("Int32", le_bytes(v, |x| (x as i32).to_le_bytes())),
        "UInt32" => ("UInt32", le_bytes(v, |x| (x as u32).to_le_bytes())),
        "UInt64" => ("UInt64", le_bytes(v, |x| (x as u64).to_le_bytes())),
        _ => ("Int64", le_bytes(v, i64::to_le_bytes)),
    };
    Block { xml_type, bytes }
}

fn array_block(a: &DataArray) -> Block {
    match &a.data {
        ArrayData::F32(v) => Block {
            xml_type: "Float32",
            bytes: le_bytes(v, f32::to_le_bytes),
        },
        ArrayData::F64(v) => Block {
            xml_type: "Float64",
            bytes: le_bytes(v, f64::to_le_bytes),
        },
        ArrayData::Int(v) => int_block(v, &a.vtk_type),
    }
}

/// Index array as Int32 when every value fits, else Int64.
fn index_block(v: &[u64]) -> Block {
    if v.iter().all(|&x| x <= i32::MAX as u64) {
        Block {
            xml_type: "Int32",
            bytes: le_bytes(v, |x| (x as i32).to_le_bytes()),
        }
    } else {
        Block {
            xml_type: "Int64",
            bytes: le_bytes(v, |x| (x as i64).to_le_bytes()),
        }
    }
}

/// The appended bytes of one block (header + payload).
fn encode(bytes: &[u8], compression: Compression) -> Vec<u8> {
    match compression {
        Compression::None => {
            let mut out = Vec::with_capacity(bytes.len() + 8);
            out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
            out.extend_from_slice(bytes);
            out
        }
        Compression::Zlib => {
            let pieces: Vec<Vec<u8>> = bytes
                .par_chunks(ZLIB_BLOCK)
                .map(|chunk| {
                    let mut e = flate2::write::ZlibEncoder::new(
                        Vec::with_capacity(chunk.len() / 2),
                        flate2::Compression::fast(),
                    );
                    // Writing to a Vec cannot fail.
                    let _ = e.write_all(chunk);
                    e.finish().unwrap_or_default()
                })
                .collect();
            let last = match bytes.len() % ZLIB_BLOCK {
                0 if !bytes.is_empty() => ZLIB_BLOCK,
                r => r,
            };
            let mut out = Vec::new();
            for h in [pieces.len(), ZLIB_BLOCK, last] {
                out.extend_from_slice(&(h as u64).to_le_bytes());
            }
            for p in &pieces {
                out.extend_from_slice(&(p.len() as u64).to_le_bytes());
            }
            for p in &pieces {
                out.extend_from_slice(p);
            }
            out
        }
    }
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes `mesh` as a `.vtu` file with appended raw data.
pub fn write_vtu(path: &Path, mesh: &Mesh, compression: Compression) -> Result<(), WriteError> {
    let cells = &mesh.cells;
    let points: Vec<f64> = mesh.points.iter().flat_map(|p| p.to_array()).collect();
    let conn: Vec<u64> = cells.conn.iter().map(|&i| i as u64).collect();
    let offsets: Vec<u64> = (1..=cells.len()).map(|c| cells.offsets[c] as u64).collect();
    let types: Vec<u8> = cells.kinds.iter().map(|&k| k as u8).collect();

    // (section, name, components, block)
    let mut arrays: Vec<(&str, Option<String>, usize, Block)> = Vec::new();
    for a in &mesh.point_data {
        arrays.push((
            "PointData",
            Some(a.name.clone()),
            a.components,
            array_block(a),
        ));
    }
    for a in &mesh.cell_data {
        arrays.push((
            "CellData",
            Some(a.name.clone()),
            a.components,
            array_block(a),
        ));
    }
    arrays.push((
        "Points",
        None,
        3,
        Block {
            xml_type: "Float64",
            bytes: le_bytes(&points, f64::to_le_bytes),
        },
    ));
    arrays.push(("Cells", Some("connectivity".into()), 1, index_block(&conn)));
    arrays.push(("Cells", Some("offsets".into()), 1, index_block(&offsets)));
    arrays.push((
        "Cells",
        Some("types".into()),
        1,
        Block {
            xml_type: "UInt8",
            bytes: types,
        },
    ));
    if !cells.poly_faces.is_empty() {
        let (faces, faceoffsets) = face_streams(mesh);
        arrays.push(("Cells", Some("faces".into()), 1, index_block(&faces)));
        let fo: Vec<i64> = faceoffsets;
        arrays.push((
            "Cells",
            Some("faceoffsets".into()),
            1,
            int_block(&fo, "Int64"),
        ));
    }

    let mut appended: Vec<u8> = Vec::new();
    let mut xml = String::new();
    let compressor = match compression {
        Compression::None => "",
        Compression::Zlib => " compressor=\"vtkZLibDataCompressor\"",
    };
    let _ = writeln!(xml, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        xml,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\"{compressor}>"
    );
    let _ = writeln!(xml, "  <UnstructuredGrid>");
    let _ = writeln!(
        xml,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.points.len(),
        cells.len()
    );
    let mut open: Option<&str> = None;
    for (section, name, comps, block) in &arrays {
        if open != Some(*section) {
            if let Some(s) = open {
                let _ = writeln!(xml, "      </{s}>");
            }
            let attr = match *section {
                "PointData" => mesh
                    .active_point_scalars
                    .as_ref()
                    .map(|s| format!(" Scalars=\"{}\"", xml_escape(s)))
                    .unwrap_or_default(),
                "CellData" => mesh
                    .active_cell_scalars
                    .as_ref()
                    .map(|s| format!(" Scalars=\"{}\"", xml_escape(s)))
                    .unwrap_or_default(),
                _ => String::new(),
            };
            let _ = writeln!(xml, "      <{section}{attr}>");
            open = Some(section);
        }
        let name_attr = name
            .as_ref()
            .map(|n| format!(" Name=\"{}\"", xml_escape(n)))
            .unwrap_or_default();
        let _ = writeln!(
            xml,
            "        <DataArray type=\"{}\"{name_attr} NumberOfComponents=\"{comps}\" format=\"appended\" offset=\"{}\"/>",
            block.xml_type,
            appended.len()
        );
        appended.extend_from_slice(&encode(&block.bytes, compression));
    }
    if let Some(s) = open {
        let _ = writeln!(xml, "      </{s}>");
    }
    let _ = writeln!(xml, "    </Piece>");
    let _ = writeln!(xml, "  </UnstructuredGrid>");
    let _ = write!(xml, "  <AppendedData encoding=\"raw\">\n   _");

    let file = std::fs::File::create(path).map_err(io_err(path))?;
    let mut w = std::io::BufWriter::new(file);
    w.write_all(xml.as_bytes()).map_err(io_err(path))?;
    w.write_all(&appended).map_err(io_err(path))?;
    w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
        .map_err(io_err(path))?;
    w.flush().map_err(io_err(path))
}

/// VTK's polyhedron streams: `faces` (per polyhedron: face count, then per
/// face its point count and ids) and `faceoffsets` (end of each cell's
/// stream in `faces`, -1 for other cells).
fn face_streams(mesh: &Mesh) -> (Vec<u64>, Vec<i64>) {
    let mut faces = Vec::new();
    let mut offs = Vec::with_capacity(mesh.cells.len());
    for c in 0..mesh.cells.len() {
        match mesh.cells.poly_faces.get(&(c as u32)) {
            Some(fs) if mesh.cells.kinds[c] == CellKind::Polyhedron => {
                faces.push(fs.len() as u64);
                for f in fs {
                    faces.push(f.len() as u64);
                    faces.extend(f.iter().map(|&i| i as u64));
                }
                offs.push(faces.len() as i64);
            }
            _ => offs.push(-1),
        }
    }
    (faces, offs)
}

/// Percent-encodes characters VTK legacy names cannot hold (space, `%`,
/// control and non-ASCII bytes).
pub fn legacy_encode_name(name: &str) -> String {
    let mut out = String::new();
    for b in name.bytes() {
        if b <= b' ' || b == b'%' || b >= 0x7f {
            let _ = write!(out, "%{b:02X}");
        } else {
            out.push(b as char);
        }
    }
    out
}

fn legacy_type(a: &DataArray) -> &'static str {
    match &a.data {
        ArrayData::F32(_) => "float",
        ArrayData::F64(_) => "double",
        ArrayData::Int(_) => match a.vtk_type.as_str() {
            "Int8" => "char",
            "UInt8" => "unsigned_char",
            "Int16" => "short",
            "UInt16" => "unsigned_short",
            "Int32" => "int",
            "UInt32" => "unsigned_int",
            "UInt64" => "vtktypeuint64",
            _ => "vtktypeint64",
        },
    }
}

fn push_values(s: &mut String, a: &DataArray) {
    let per_line = a.components.clamp(1, 9);
    for i in 0..a.data.len() {
        let _ = match &a.data {
            ArrayData::F32(v) => write!(s, "{}", v[i]),
            ArrayData::F64(v) => write!(s, "{}", v[i]),
            ArrayData::Int(v) => write!(s, "{}", v[i]),
        };
        s.push(if (i + 1) % per_line == 0 { '\n' } else { ' ' });
    }
    if !s.ends_with('\n') {
        s.push('\n');
    }
}

fn push_arrays(s: &mut String, arrays: &[DataArray], active: Option<&String>) {
    // The active scalars first as SCALARS, then VECTORS, the rest as FIELD.
    let mut field = Vec::new();
    let mut order: Vec<&DataArray> = arrays.iter().collect();
    order.sort_by_key(|a| Some(&a.name) != active);
    for a in order {
        let name = legacy_encode_name(&a.name);
        let ty = legacy_type(a);
        match a.components {
            1 => {
                let _ = writeln!(s, "SCALARS {name} {ty} 1\nLOOKUP_TABLE default");
                push_values(s, a);
            }
            3 => {
                let _ = writeln!(s, "VECTORS {name} {ty}");
                push_values(s, a);
            }
            _ => field.push(a),
        }
    }
    if !field.is_empty() {
        let _ = writeln!(s, "FIELD FieldData {}", field.len());
        for a in field {
            let name = legacy_encode_name(&a.name);
            let _ = writeln!(
                s,
                "{name} {} {} {}",
                a.components,
                a.tuples(),
                legacy_type(a)
            );
            push_values(s, a);
        }
    }
}

/// Writes `mesh` as a VTK legacy 4.2 ASCII unstructured grid.
pub fn write_legacy_ascii(path: &Path, mesh: &Mesh, title: &str) -> Result<(), WriteError> {
    let cells = &mesh.cells;
    let mut s = String::new();
    let title: String = title.chars().filter(|c| *c != '\n').take(255).collect();
    let _ = writeln!(
        s,
        "# vtk DataFile Version 4.2\n{title}\nASCII\nDATASET UNSTRUCTURED_GRID"
    );
    let _ = writeln!(s, "POINTS {} double", mesh.points.len());
    for p in &mesh.points {
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }
    let mut rows: Vec<Vec<u64>> = Vec::with_capacity(cells.len());
    for c in 0..cells.len() {
        match cells.poly_faces.get(&(c as u32)) {
            Some(fs) if cells.kinds[c] == CellKind::Polyhedron => {
                let mut r = vec![fs.len() as u64];
                for f in fs {
                    r.push(f.len() as u64);
                    r.extend(f.iter().map(|&i| i as u64));
                }
                rows.push(r);
            }
            _ => rows.push(cells.nodes(c).iter().map(|&i| i as u64).collect()),
        }
    }
    let size: usize = rows.iter().map(|r| r.len() + 1).sum();
    let _ = writeln!(s, "CELLS {} {size}", cells.len());
    for r in &rows {
        let _ = write!(s, "{}", r.len());
        for v in r {
            let _ = write!(s, " {v}");
        }
        s.push('\n');
    }
    let _ = writeln!(s, "CELL_TYPES {}", cells.len());
    for &k in &cells.kinds {
        let _ = writeln!(s, "{}", k as u8);
    }
    if !mesh.point_data.is_empty() {
        let _ = writeln!(s, "POINT_DATA {}", mesh.points.len());
        push_arrays(&mut s, &mesh.point_data, mesh.active_point_scalars.as_ref());
    }
    if !mesh.cell_data.is_empty() {
        let _ = writeln!(s, "CELL_DATA {}", cells.len());
        push_arrays(&mut s, &mesh.cell_data, mesh.active_cell_scalars.as_ref());
    }
    std::fs::write(path, s).map_err(io_err(path))
}

/// Writes a `.pvd` collection of `(time, file)` entries (file names relative
/// to the collection's folder).
pub fn write_pvd(path: &Path, steps: &[(f64, String)]) -> Result<(), WriteError> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, f) in steps {
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{}\"/>",
            xml_escape(f)
        );
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    std::fs::write(path, s).map_err(io_err(path))
}

/// Writes a ParaView `.series` JSON file of `(time, file)` entries.
pub fn write_series(path: &Path, steps: &[(f64, String)]) -> Result<(), WriteError> {
    let files: Vec<serde_json::Value> = steps
        .iter()
        .map(|(t, f)| serde_json::json!({ "name": f, "time": t }))
        .collect();
    let v = serde_json::json!({ "file-series-version": "1.0", "files": files });
    let text = serde_json::to_string_pretty(&v).map_err(|e| WriteError::Invalid {
        path: path.to_path_buf(),
        msg: e.to_string(),
    })?;
    std::fs::write(path, text + "\n").map_err(io_err(path))
}
