//! Keeping part of a mesh: a subset of its cells, and the points they need.
//!
//! [`keep_cells`] removes the cells a mask leaves out, in place: the kept
//! cells stay in their order, each cell array keeps the tuples of the kept
//! cells (so cell data stays aligned with the cells), polyhedron faces are
//! re-keyed to the new cell ids, and the points that only removed cells used
//! are dropped with their point-data tuples (points that no cell used to
//! begin with stay). Points are renumbered in their order, so the
//! smallest-vertex rule picks the same diagonals as before. [`SourceInfo`]
//! (what the file held) is left as it was.
//!
//! [`remove_unused_points`] drops every point no cell uses.
//!
//! [`SourceInfo`]: super::SourceInfo

use std::collections::BTreeMap;

use super::data::{ArrayData, DataArray};

use super::{Cells, Mesh};

/// Keeps the cells `c` with `keep[c]` (cells past the end of `keep` are
/// kept) and the data that belongs to them (see the module docs). Returns
/// the number of cells removed.
pub fn keep_cells(mesh: &mut Mesh, keep: &[bool]) -> usize {
    let n = mesh.cells.len();
    let kept = |c: usize| keep.get(c).copied().unwrap_or(true);
    let removed = (0..n).filter(|&c| !kept(c)).count();
    if removed == 0 {
        return 0;
    }
    let np = mesh.points.len();
    // 0: used by no cell, 1: used by removed cells only, 2: used by a kept cell.
    let mut use_of = vec![0u8; np];
    for c in 0..n {
        let mark = if kept(c) { 2 } else { 1 };
        for &p in mesh.cells.nodes(c) {
            if let Some(u) = use_of.get_mut(p as usize) {
                *u = (*u).max(mark);
            }
        }
        if let Some(faces) = mesh.cells.poly_faces.get(&(c as u32)) {
            for &p in faces.iter().flatten() {
                if let Some(u) = use_of.get_mut(p as usize) {
                    *u = (*u).max(mark);
                }
            }
        }
    }
    let (cells, _) = cells_subset(&mesh.cells, kept);
    mesh.cells = cells;
    let cell_keep: Vec<bool> = (0..n).map(kept).collect();
    for a in &mut mesh.cell_data {
        keep_tuples(a, &cell_keep);
    }
    let point_keep: Vec<bool> = use_of.iter().map(|&u| u != 1).collect();
    if point_keep.contains(&false) {
        renumber_points(mesh, &point_keep);
    }
    removed
}

/// The cells `c` of `cells` with `keep(c)`, in their order, with their
/// point ids as they are (polyhedron faces re-keyed to the new cell ids),
/// and the old id of each kept cell.
pub fn cells_subset(cells: &Cells, keep: impl Fn(usize) -> bool) -> (Cells, Vec<u32>) {
    let mut out = Cells {
        offsets: vec![0],
        poly_faces: BTreeMap::new(),
        ..Default::default()
    };
    let mut old_id = Vec::new();
    for c in (0..cells.len()).filter(|&c| keep(c)) {
        if let Some(faces) = cells.poly_faces.get(&(c as u32)) {
            out.poly_faces.insert(out.len() as u32, faces.clone());
        }
        out.push(cells.kinds[c], cells.nodes(c));
        old_id.push(c as u32);
    }
    (out, old_id)
}

/// Removes points no cell uses (renumbering in order) and the matching
/// point-array tuples; returns how many were removed.
pub fn remove_unused_points(mesh: &mut Mesh) -> usize {
    let mut used = vec![false; mesh.points.len()];
    for &i in &mesh.cells.conn {
        if let Some(x) = used.get_mut(i as usize) {
            *x = true;
        }
    }
    let removed = used.iter().filter(|&&u| !u).count();
    if removed > 0 {
        renumber_points(mesh, &used);
    }
    removed
}

/// Keeps the points with `keep[p]`, renumbered in order, with their
/// point-data tuples; node ids of the cells (and polyhedron faces) follow.
/// Ids of removed points that cells still name are left unchanged.
fn renumber_points(mesh: &mut Mesh, keep: &[bool]) {
    let mut new_id = vec![u32::MAX; mesh.points.len()];
    let mut next = 0u32;
    for (i, x) in new_id.iter_mut().enumerate() {
        if keep.get(i).copied().unwrap_or(true) {
            *x = next;
            next += 1;
        }
    }
    let old = std::mem::take(&mut mesh.points);
    mesh.points = old
        .iter()
        .zip(&new_id)
        .filter(|(_, &id)| id != u32::MAX)
        .map(|(p, _)| *p)
        .collect();
    let point_keep: Vec<bool> = new_id.iter().map(|&id| id != u32::MAX).collect();
    for a in &mut mesh.point_data {
        keep_tuples(a, &point_keep);
    }
    let map = |i: &mut u32| {
        if let Some(&id) = new_id.get(*i as usize) {
            if id != u32::MAX {
                *i = id;
            }
        }
    };
    mesh.cells.conn.iter_mut().for_each(map);
    for faces in mesh.cells.poly_faces.values_mut() {
        faces.iter_mut().flatten().for_each(map);
    }
}

/// Keeps the tuples `t` of `a` with `keep[t]` (tuples past the end of
/// `keep` are dropped).
fn keep_tuples(a: &mut DataArray, keep: &[bool]) {
    let nc = a.components.max(1);
    fn pick<T: Copy>(v: &[T], nc: usize, keep: &[bool]) -> Vec<T> {
        v.chunks(nc)
            .zip(keep)
            .filter(|(_, &k)| k)
            .flat_map(|(t, _)| t.iter().copied())
            .collect()
    }
    a.data = match &a.data {
        ArrayData::F32(v) => ArrayData::F32(pick(v, nc, keep)),
        ArrayData::F64(v) => ArrayData::F64(pick(v, nc, keep)),
        ArrayData::Int(v) => ArrayData::Int(pick(v, nc, keep)),
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{single_cell, warped_hex_grid, Warp};
    use crate::mesh::CellKind;

    fn ids(n: usize) -> DataArray {
        DataArray {
            name: "id".into(),
            components: 2,
            data: ArrayData::Int((0..2 * n as i64).collect()),
            vtk_type: "Int64".into(),
        }
    }

    #[test]
    fn keeps_cells_their_data_and_the_points_they_need() {
        let mut m = warped_hex_grid(2, &Warp::default());
        m.cell_data.push(ids(8));
        // an unused point stays
        m.points.push(glam::DVec3::splat(9.0));
        if let Some(ArrayData::F32(v)) = m.point_data.first_mut().map(|a| &mut a.data) {
            v.push(7.0);
        }
        let before = m.clone();
        // keep cells 0 and 7 (opposite corners share only the centre point)
        let keep = [true, false, false, false, false, false, false, true];
        assert_eq!(keep_cells(&mut m, &keep), 6);
        m.sanity_check().unwrap();
        assert_eq!(m.cells.len(), 2);
        assert_eq!(m.points.len(), 8 + 8 - 1 + 1);
        assert_eq!(m.cell_data[0].data, ArrayData::Int(vec![0, 1, 14, 15]));
        // same positions and point values in the same order
        for c in [0usize, 1] {
            let oc = if c == 0 { 0 } else { 7 };
            for (a, b) in m.cells.nodes(c).iter().zip(before.cells.nodes(oc)) {
                assert_eq!(m.points[*a as usize], before.points[*b as usize]);
                let (pa, pb) = (&m.point_data[0], &before.point_data[0]);
                assert_eq!(pa.component(*a as usize, 0), pb.component(*b as usize, 0));
            }
        }
        assert_eq!(*m.points.last().unwrap(), glam::DVec3::splat(9.0));
        // nothing to remove: unchanged
        let again = m.clone();
        assert_eq!(keep_cells(&mut m, &[true, true]), 0);
        assert_eq!(m.points, again.points);
    }

    #[test]
    fn polyhedra_keep_their_faces() {
        let mut m = single_cell(CellKind::Hexahedron);
        let house = single_cell(CellKind::Polyhedron);
        let off = m.points.len() as u32;
        m.points.extend(&house.points);
        let faces: Vec<Vec<u32>> = house.cells.poly_faces[&0]
            .iter()
            .map(|f| f.iter().map(|&p| p + off).collect())
            .collect();
        m.cells.push_polyhedron(faces);
        m.point_data.clear();
        m.cell_data.clear();
        assert_eq!(keep_cells(&mut m, &[false, true]), 1);
        m.sanity_check().unwrap();
        assert_eq!(m.points, house.points);
        assert_eq!(m.cells.poly_faces[&0], house.cells.poly_faces[&0]);
        assert_eq!(remove_unused_points(&mut m), 0);
    }
}
