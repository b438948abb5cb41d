//! VTK XML readers: `.vtu`, `.vts`, `.vtr`, `.vti`, the parallel `.pvtu`,
//! `.pvts`, `.pvtr` and `.pvti`, and multiblock `.vtm` ([`multiblock`]).
//!
//! How a file is read:
//! 1. [`dom::parse`] pulls the element tree out of the file with quick-xml
//!    (no entity expansion) and locates the `<AppendedData>` block by byte
//!    offset, without parsing it.
//! 2. The `<VTKFile>` attributes give the [`encoding::Codec`]: `byte_order`,
//!    `header_type` (UInt32 default, UInt64) and `compressor` (zlib, LZ4,
//!    LZMA).
//! 3. Each `<Piece>` is read by [`unstructured`] or [`structured`]: its
//!    `<DataArray>`s are decoded by [`encoding::Source::decode`] straight into
//!    typed vectors (ascii, inline base64, appended raw or base64, compressed
//!    or not), checked against the declared counts before anything large is
//!    allocated.
//! 4. Pieces (several `<Piece>`s in one file, or the files of a parallel
//!    file, see [`parallel`]) are merged by [`arrays::merge`].
//!
//! vtkio is not used for XML: it cannot read appended raw data, Int8 cell
//! types or pentagonal prisms (vtkio 0.7.0-rc2 fails on all three, measured
//! on the real datasets the tests read), and its errors
//! do not say where a file is broken. Every error here names the file and the
//! element (with its `Name` and byte offset) or the byte where reading failed.

mod arrays;

/// Merges meshes as the pieces of a file are merged (point ids offset per
/// piece; an array missing from some piece dropped, with a note).
pub(crate) use arrays::merge as merge_pieces;
pub(crate) mod dom;
mod encoding;
mod multiblock;
mod parallel;
mod scalar;
mod structured;
mod unstructured;

use std::path::Path;

use super::{Format, IoError, Location};
use crate::mesh::Mesh;
use encoding::{Codec, Compressor, Source};
use structured::Lattice;

/// Reads a VTK XML dataset from a file.
pub fn read(path: &Path, format: Format) -> Result<Mesh, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::open(path, e))?;
    read_bytes(path, &bytes, format)
}

/// Reads a VTK XML dataset from memory; `path` names the file in errors and
/// locates the pieces of a parallel file. The dataset type comes from the file's
/// `<VTKFile type=...>`; `format` is only checked against it when the file
/// does not say.
pub fn read_bytes(path: &Path, bytes: &[u8], format: Format) -> Result<Mesh, IoError> {
    read_nested(path, bytes, format, 0)
}

/// [`read_bytes`], `depth` levels of parallel files deep.
fn read_nested(path: &Path, bytes: &[u8], format: Format, depth: usize) -> Result<Mesh, IoError> {
    let doc = dom::parse(path, bytes)?;
    let root = &doc.root;
    let kind = root.attr("type").map(str::to_string).unwrap_or_else(|| {
        match format {
            Format::XmlStructured => "StructuredGrid",
            Format::XmlRectilinear => "RectilinearGrid",
            Format::XmlImage => "ImageData",
            Format::XmlParallelUnstructured => "PUnstructuredGrid",
            Format::XmlParallelStructured => "PStructuredGrid",
            Format::XmlParallelRectilinear => "PRectilinearGrid",
            Format::XmlParallelImage => "PImageData",
            Format::XmlMultiBlock => "vtkMultiBlockDataSet",
            _ => "UnstructuredGrid",
        }
        .to_string()
    });
    let src = Source::new(path, bytes, codec(path, root)?, doc.appended);
    let grid = root.child(&kind).ok_or_else(|| {
        IoError::parse(
            path,
            root.location(),
            format!("<VTKFile type=\"{kind}\"> has no <{kind}> element"),
        )
    })?;
    let pieces = match kind.as_str() {
        "UnstructuredGrid" => grid
            .children_named("Piece")
            .map(|p| unstructured::read_piece(&src, p))
            .collect::<Result<Vec<_>, _>>()?,
        "StructuredGrid" => structured::read(&src, grid, Lattice::Structured)?,
        "RectilinearGrid" => structured::read(&src, grid, Lattice::Rectilinear)?,
        "ImageData" => structured::read(&src, grid, Lattice::Image)?,
        "PUnstructuredGrid" => {
            return parallel::read(path, grid, depth, Format::XmlUnstructured)
        }
        "PStructuredGrid" => return parallel::read(path, grid, depth, Format::XmlStructured),
        "PRectilinearGrid" => return parallel::read(path, grid, depth, Format::XmlRectilinear),
        "PImageData" => return parallel::read(path, grid, depth, Format::XmlImage),
        "vtkMultiBlockDataSet" => return multiblock::read(path, grid),
        other => {
            return Err(IoError::parse(
                path,
                root.location(),
                format!("unsupported VTK XML dataset type '{other}' (expected UnstructuredGrid, StructuredGrid, RectilinearGrid, ImageData, one of their parallel forms PUnstructuredGrid, PStructuredGrid, PRectilinearGrid, PImageData, or vtkMultiBlockDataSet)"),
            ))
        }
    };
    if pieces.is_empty() {
        return Err(IoError::parse(path, grid.location(), "no <Piece> element"));
    }
    let mut mesh = merge_checked(path, grid, pieces)?;
    mesh.source.time_value = time_value(&src, grid);
    Ok(mesh)
}

/// The first value of the `TimeValue` array in the dataset's
/// `<FieldData>` (as ParaView writes the time of a step), if there is one
/// and it decodes to a finite number. A bad time never stops the dataset
/// from being read: it is only a label.
fn time_value(src: &Source, grid: &dom::Element) -> Option<f64> {
    let arr = grid.child("FieldData").and_then(|fd| {
        fd.children_named("DataArray")
            .find(|a| a.attr("Name") == Some("TimeValue"))
    })?;
    let ty = scalar::Scalar::parse(arr.attr("type").unwrap_or(""))?;
    let values: Vec<f64> = src.decode(arr, ty, None).ok()?;
    values.first().copied().filter(|t| t.is_finite())
}

/// Checks a file that a parallel or multiblock file `path` names (`what`:
/// "piece" or "block"; `at` the place of the reference): it opens, is a
/// regular file, and is not `path` itself (`me`, canonical).
fn referenced_file(
    path: &Path,
    me: Option<&Path>,
    file: &Path,
    what: &str,
    at: impl Fn() -> Location,
) -> Result<(), IoError> {
    let fail = |msg: String| IoError::parse(path, at(), msg);
    let canon = std::fs::canonicalize(file).map_err(|e| {
        fail(format!(
            "{what} file {} cannot be opened: {e}",
            file.display()
        ))
    })?;
    if Some(canon.as_path()) == me {
        return Err(fail(format!("the {what} is the file itself")));
    }
    if !canon.is_file() {
        return Err(fail(format!(
            "{what} {} is not a regular file",
            file.display()
        )));
    }
    Ok(())
}

/// Merges the parts (pieces or blocks, `what`) of a parallel or multiblock
/// file, with the `TimeValue` they agree on (ParaView writes the step's
/// time into every part); parts that disagree leave it unset, with a note.
fn merge_parts(
    path: &Path,
    grid: &dom::Element,
    parts: Vec<Mesh>,
    what: &str,
) -> Result<Mesh, IoError> {
    let times: Vec<f64> = parts.iter().filter_map(|m| m.source.time_value).collect();
    let mut mesh = merge_checked(path, grid, parts)?;
    match times.first() {
        Some(&t) if times.iter().all(|&u| u == t) => mesh.source.time_value = Some(t),
        Some(_) => mesh
            .source
            .notes
            .push(format!("the {what}' TimeValues differ: no time value")),
        None => {}
    }
    Ok(mesh)
}

/// Merges pieces after checking the total point count fits `u32` ids.
fn merge_checked(path: &Path, grid: &dom::Element, pieces: Vec<Mesh>) -> Result<Mesh, IoError> {
    let total: u64 = pieces.iter().map(|p| p.points.len() as u64).sum();
    if total > unstructured::MAX_COUNT {
        return Err(IoError::parse(
            path,
            grid.location(),
            format!("{total} points in all pieces: too many"),
        ));
    }
    Ok(arrays::merge(pieces))
}

/// The encoding settings of `<VTKFile>`.
fn codec(path: &Path, root: &dom::Element) -> Result<Codec, IoError> {
    let bad = |key: &str, v: &str| {
        IoError::parse(path, root.location(), format!("unsupported {key} '{v}'"))
    };
    let big_endian = match root.attr("byte_order").unwrap_or("LittleEndian") {
        "LittleEndian" => false,
        "BigEndian" => true,
        v => return Err(bad("byte_order", v)),
    };
    let header64 = match root.attr("header_type").unwrap_or("UInt32") {
        "UInt32" => false,
        "UInt64" => true,
        v => return Err(bad("header_type", v)),
    };
    let compressor = match root.attr("compressor").unwrap_or("") {
        "" => Compressor::None,
        "vtkZLibDataCompressor" => Compressor::Zlib,
        "vtkLZ4DataCompressor" => Compressor::Lz4,
        "vtkLZMADataCompressor" => Compressor::Lzma,
        v => return Err(bad("compressor", v)),
    };
    Ok(Codec {
        header64,
        big_endian,
        compressor,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_dataset_type_names_file() {
        let e = read_bytes(
            Path::new("x.vtp"),
            b"<VTKFile type=\"PolyData\"><PolyData/></VTKFile>",
            Format::XmlUnstructured,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("x.vtp") && e.contains("PolyData"), "{e}");
    }
}
