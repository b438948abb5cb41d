//! Helpers shared by the XML reader tests: the structural invariants every
//! reader output must satisfy, and lookups by cell type and array name.
#![allow(dead_code)]

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
