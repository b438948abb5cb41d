//! Helpers shared by the XML reader tests: the structural invariants every
//! reader output must satisfy, and lookups by cell type and array name.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use zoovr::mesh::Mesh;

/// Structural invariants every reader output must satisfy.
pub fn check_mesh(m: &Mesh) {
    let c = &m.cells;
    if !c.is_empty() {
        assert_eq!((c.offsets.len(), c.offsets[0]), (c.len() + 1, 0));
    }
    for i in 0..c.len() {
        let n = c.nodes(i);
        if let Some(k) = c.kinds[i].corner_count() {
            assert_eq!(n.len(), k, "cell {i}");
        }
        assert!(
            n.iter().all(|&p| (p as usize) < m.points.len()),
            "cell {i} ids"
        );
    }
    for a in &m.point_data {
        assert_eq!(a.tuples(), m.points.len(), "point array {}", a.name);
        assert_eq!(a.data.len() % a.components, 0);
    }
    for a in &m.cell_data {
        assert_eq!(a.tuples(), c.len(), "cell array {}", a.name);
    }
    assert_eq!(m.source.cells_by_type.values().sum::<usize>(), c.len());
    assert!(m.points.iter().all(|p| p.is_finite()));
}

pub fn by_type(m: &Mesh, name: &str) -> usize {
    m.source.cells_by_type.get(name).copied().unwrap_or(0)
}

pub fn array<'m>(m: &'m Mesh, name: &str) -> &'m zoovr::field::DataArray {
    m.point_data
        .iter()
        .chain(&m.cell_data)
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no array {name}"))
}

/// A polyhedron (a hexahedron given by its faces) and a tetrahedron on
/// its top face, in the pre-9.4 `faces` / `faceoffsets` layout.
pub const POLY: &str = r#"<VTKFile type="UnstructuredGrid" version="0.1"><UnstructuredGrid><Piece NumberOfPoints="9" NumberOfCells="2">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">
-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1  0 0 3</DataArray></Points>
<Cells>
<DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3 4 5 6 7  4 5 6 8</DataArray>
<DataArray type="Int64" Name="offsets" format="ascii">8 12</DataArray>
<DataArray type="UInt8" Name="types" format="ascii">42 10</DataArray>
<DataArray type="Int64" Name="faces" format="ascii">6 4 0 3 2 1 4 0 4 7 3 4 4 5 6 7 4 5 1 2 6 4 0 1 5 4 4 2 3 7 6</DataArray>
<DataArray type="Int64" Name="faceoffsets" format="ascii">31 -1</DataArray>
</Cells></Piece></UnstructuredGrid></VTKFile>"#;

pub fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Writes `text` to `dir/name`.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}
