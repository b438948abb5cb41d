//! Readers: every supported file format produces one [`Mesh`].
//!
//! [`read`] picks the reader from the extension, falling back to the file's
//! first bytes, so callers never know which reader (or which library) read a
//! file. Time collections (`.pvd`, `.series`) are read with [`read_series`],
//! which lists the steps; each step is then read with [`read`].
//!
//! Hostile input: every reader checks counts against the bytes actually
//! present before allocating, so a header that claims 10^12 points is refused
//! with a [`IoError::Parse`] naming the file and the place.

pub mod collection;
pub mod error;
pub mod legacy;
pub mod plot3d;
pub mod sequence;
pub mod writer;
pub mod xml;

use std::path::{Path, PathBuf};

pub use error::{IoError, Location};

use crate::mesh::Mesh;

/// Options for [`read`].
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    /// PLOT3D solution (`--q FILE`) to attach to a PLOT3D grid.
    pub q_file: Option<PathBuf>,
}

/// One time step of a collection.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeStep {
    /// Time value of the step.
    pub time: f64,
    /// File of the step (resolved relative to the collection file).
    pub path: PathBuf,
}

/// The formats zoovr reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Legacy,
    XmlUnstructured,
    XmlStructured,
    XmlRectilinear,
    XmlImage,
    XmlParallelUnstructured,
    /// `.pvts`: structured pieces.
    XmlParallelStructured,
    /// `.pvtr`: rectilinear pieces.
    XmlParallelRectilinear,
    /// `.pvti`: image-data pieces.
    XmlParallelImage,
    /// `.vtm`: blocks in files of their own.
    XmlMultiBlock,
    Pvd,
    Series,
    Plot3d,
}

/// Detects the format from the extension, then from the first bytes.
pub fn detect_format(path: &Path) -> Result<Format, IoError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let by_ext = match ext.as_str() {
        "vtk" => Some(Format::Legacy),
        "vtu" => Some(Format::XmlUnstructured),
        "vts" => Some(Format::XmlStructured),
        "vtr" => Some(Format::XmlRectilinear),
        "vti" => Some(Format::XmlImage),
        "pvtu" => Some(Format::XmlParallelUnstructured),
        "pvts" => Some(Format::XmlParallelStructured),
        "pvtr" => Some(Format::XmlParallelRectilinear),
        "pvti" => Some(Format::XmlParallelImage),
        "vtm" => Some(Format::XmlMultiBlock),
        "pvd" => Some(Format::Pvd),
        "series" => Some(Format::Series),
        "xyz" | "p3d" | "x" | "g" => Some(Format::Plot3d),
        _ if name.ends_with(".vtu.series") || name.ends_with(".vtk.series") => Some(Format::Series),
        _ if name.contains("xyz") && ext == "bin" => Some(Format::Plot3d),
        _ => None,
    };
    if let Some(f) = by_ext {
        return Ok(f);
    }
    sniff(path)
}

fn sniff(path: &Path) -> Result<Format, IoError> {
    use std::io::Read;
    let mut head = [0u8; 512];
    let mut f = std::fs::File::open(path).map_err(|e| IoError::open(path, e))?;
    let n = f.read(&mut head).map_err(|e| IoError::open(path, e))?;
    let text = String::from_utf8_lossy(&head[..n]);
    if text.starts_with("# vtk DataFile") {
        return Ok(Format::Legacy);
    }
    for (tag, fmt) in [
        ("\"UnstructuredGrid\"", Format::XmlUnstructured),
        ("\"StructuredGrid\"", Format::XmlStructured),
        ("\"RectilinearGrid\"", Format::XmlRectilinear),
        ("\"ImageData\"", Format::XmlImage),
        ("\"PUnstructuredGrid\"", Format::XmlParallelUnstructured),
        ("\"PStructuredGrid\"", Format::XmlParallelStructured),
        ("\"PRectilinearGrid\"", Format::XmlParallelRectilinear),
        ("\"PImageData\"", Format::XmlParallelImage),
        ("\"vtkMultiBlockDataSet\"", Format::XmlMultiBlock),
        ("\"Collection\"", Format::Pvd),
    ] {
        if text.contains("<VTKFile") && text.contains(tag) {
            return Ok(fmt);
        }
    }
    if text.trim_start().starts_with('{') && text.contains("\"files\"") {
        return Ok(Format::Series);
    }
    if plot3d::looks_like_grid(&head[..n]) {
        return Ok(Format::Plot3d);
    }
    if let Some(why) = not_read(path, &text) {
        return Err(IoError::parse(path, Location::None, why));
    }
    Err(IoError::UnknownFormat {
        path: path.to_path_buf(),
    })
}

/// Why a file of a kind zoovr knows but does not read is refused, with what
/// to do instead: polygonal data holds no volume, and the binary formats of
/// some solvers need converting first.
fn not_read(path: &Path, head: &str) -> Option<&'static str> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if matches!(ext.as_str(), "vtp" | "pvtp") || head.contains("\"PolyData\"") {
        return Some(
            "VTK PolyData holds surfaces, not 3D cells: there is no volume to render \
             (a volume mesh is a .vtu, .vts, .vtr, .vti, their parallel forms, a .vtm or a legacy .vtk)",
        );
    }
    if matches!(
        ext.as_str(),
        "e" | "exo" | "ex2" | "cgns" | "h5" | "hdf5" | "cas" | "msh"
    ) {
        return Some(
            "Exodus II, CGNS, HDF5, Fluent and Gmsh files are not read: save the volume as VTK \
             (.vtu, .vts or .vtm; in ParaView: File > Save Data) and render that",
        );
    }
    None
}

/// Reads one dataset (not a collection: see [`read_series`]).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Mesh, IoError> {
    let format = detect_format(path)?;
    // A solution file only means something for a PLOT3D grid (a collection
    // passes it on to its steps): refuse it elsewhere rather than ignore it.
    if let Some(q) = &opts.q_file {
        if !matches!(format, Format::Plot3d | Format::Pvd | Format::Series) {
            return Err(IoError::parse(
                path,
                Location::None,
                format!(
                    "--q {} is a PLOT3D solution, but this is not a PLOT3D grid",
                    q.display()
                ),
            ));
        }
    }
    match format {
        Format::Legacy => legacy::read(path),
        Format::XmlUnstructured
        | Format::XmlStructured
        | Format::XmlRectilinear
        | Format::XmlImage
        | Format::XmlParallelUnstructured
        | Format::XmlParallelStructured
        | Format::XmlParallelRectilinear
        | Format::XmlParallelImage
        | Format::XmlMultiBlock => xml::read(path, format),
        Format::Plot3d => plot3d::read(path, opts.q_file.as_deref()),
        Format::Pvd | Format::Series => {
            // A collection given where one dataset is expected: its first step.
            let steps = read_series(path)?;
            let first = steps.first().ok_or_else(|| IoError::Parse {
                path: path.to_path_buf(),
                location: Location::None,
                msg: "the collection lists no time steps".into(),
            })?;
            read(&first.path, opts)
        }
    }
}

/// Lists the steps of a time collection (`.pvd`, `.series`); a plain dataset
/// is one step at time 0.
pub fn read_series(path: &Path) -> Result<Vec<TimeStep>, IoError> {
    match detect_format(path)? {
        Format::Pvd => collection::read_pvd(path),
        Format::Series => collection::read_series_json(path),
        _ => Ok(vec![TimeStep {
            time: 0.0,
            path: path.to_path_buf(),
        }]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kinds zoovr knows but does not read get a reason and what to do;
    /// anything else is an unknown format.
    #[test]
    fn known_unread_kinds_say_why() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, text: &str| {
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let surface = write("skin.vtp", "<VTKFile type=\"PolyData\"></VTKFile>");
        let e = read(&surface, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("skin.vtp") && e.contains("PolyData"), "{e}");
        let by_content = write("skin.xml", "<VTKFile type=\"PolyData\"></VTKFile>");
        let e = read(&by_content, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("skin.xml") && e.contains("surfaces"), "{e}");
        let exodus = write("case.exo", "CDF\u{1}");
        let e = read(&exodus, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("case.exo") && e.contains("Save Data"), "{e}");
        let other = write("notes.txt", "hello");
        assert!(matches!(
            read(&other, &ReadOptions::default()),
            Err(IoError::UnknownFormat { .. })
        ));
    }
}
