//! Point coordinates, `PointData`/`CellData` arrays, and merging pieces.
//!
//! Arrays keep the file's value type: `Float32` as `f32` and `Float64` as
//! `f64` bit for bit, every integer type widened to `i64`; `vtk_type` keeps
//! the name written in the file. A `Scalars="name"` attribute on
//! `PointData`/`CellData` marks the active scalars. Arrays of types zoovr does
//! not use (`String`, `Bit`) are skipped with a note.
//!
//! A dataset split into pieces (several `<Piece>` elements, or the files of a
//! parallel file) is read piece by piece into [`Mesh`]es and merged: points and
//! cells are concatenated with point ids offset per piece; arrays present in
//! every piece (same name and component count) are concatenated, others are
//! dropped with a note.

use std::collections::BTreeMap;

use glam::DVec3;

use super::dom::Element;
use super::encoding::{Scalar, Source};
use crate::field::{ArrayData, DataArray};
use crate::io::IoError;
use crate::mesh::Mesh;

/// Most components per tuple accepted (tensors have 9).
const MAX_COMPONENTS: usize = 4096;

/// The scalar type of a `<DataArray>`.
pub fn scalar_type(src: &Source, el: &Element) -> Result<Scalar, IoError> {
    let t = el.attr("type").unwrap_or("");
    Scalar::parse(t).ok_or_else(|| {
        IoError::parse(
            src.path,
            el.location(),
            format!("unsupported DataArray type '{t}'"),
        )
    })
}

/// `NumberOfComponents` (default 1).
pub fn components(src: &Source, el: &Element) -> Result<usize, IoError> {
    match el.attr("NumberOfComponents") {
        None => Ok(1),
        Some(s) => match s.trim().parse::<usize>() {
            Ok(n) if (1..=MAX_COMPONENTS).contains(&n) => Ok(n),
            _ => Err(IoError::parse(
                src.path,
                el.location(),
                format!("bad NumberOfComponents '{s}'"),
            )),
        },
    }
}

/// Reads the point coordinates of a piece (`<Points>` with one 3-component
/// array), rejecting non-finite values.
pub fn read_points(src: &Source, piece: &Element, np: usize) -> Result<Vec<DVec3>, IoError> {
    let Some(arr) = piece.child("Points").and_then(|p| p.child("DataArray")) else {
        if np == 0 {
            return Ok(Vec::new());
        }
        return Err(IoError::parse(
            src.path,
            piece.location(),
            format!("{np} points declared but no <Points> array"),
        ));
    };
    if components(src, arr)? != 3 {
        return Err(IoError::parse(
            src.path,
            arr.location(),
            "points must have 3 components",
        ));
    }
    let ty = scalar_type(src, arr)?;
    let want = np
        .checked_mul(3)
        .ok_or_else(|| IoError::parse(src.path, piece.location(), "point count overflows"))?;
    let xyz: Vec<f64> = src.decode(arr, ty, Some(want))?;
    let points = to_points(&xyz);
    check_finite(src, arr, &points)?;
    Ok(points)
}

/// Groups coordinates in threes.
pub fn to_points(xyz: &[f64]) -> Vec<DVec3> {
    xyz.chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect()
}

/// Errors on the first point with a NaN or infinite coordinate.
pub fn check_finite(src: &Source, el: &Element, points: &[DVec3]) -> Result<(), IoError> {
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(IoError::parse(
            src.path,
            el.location(),
            format!("point {i} has a non-finite coordinate {:?}", points[i]),
        ));
    }
    Ok(())
}

/// Reads the arrays of a `<PointData>`/`<CellData>` element with `ntuples`
/// tuples each; returns them with the active scalars' name.
pub fn read_arrays(
    src: &Source,
    el: Option<&Element>,
    ntuples: usize,
    notes: &mut Vec<String>,
) -> Result<(Vec<DataArray>, Option<String>), IoError> {
    let Some(el) = el else {
        return Ok((Vec::new(), None));
    };
    let mut out = Vec::new();
    for arr in el.children_named("DataArray") {
        let name = arr.attr("Name").unwrap_or("").to_string();
        let Some(ty) = Scalar::parse(arr.attr("type").unwrap_or("")) else {
            notes.push(format!(
                "array '{name}' of type '{}' skipped",
                arr.attr("type").unwrap_or("")
            ));
            continue;
        };
        let nc = components(src, arr)?;
        let want = ntuples
            .checked_mul(nc)
            .ok_or_else(|| IoError::parse(src.path, arr.location(), "array size overflows"))?;
        let data = match ty {
            Scalar::F32 => ArrayData::F32(src.decode(arr, ty, Some(want))?),
            Scalar::F64 => ArrayData::F64(src.decode(arr, ty, Some(want))?),
            _ => ArrayData::Int(src.decode(arr, ty, Some(want))?),
        };
        out.push(DataArray {
            name,
            components: nc,
            data,
            vtk_type: ty.name().to_string(),
        });
    }
    let active = el
        .attr("Scalars")
        .filter(|s| out.iter().any(|a| a.name == *s))
        .map(str::to_string);
    Ok((out, active))
}

/// Keeps the tuples of `arrays` where `keep` is true.
pub fn filter_tuples(arrays: &mut [DataArray], keep: &[bool]) {
    for a in arrays {
        let nc = a.components;
        let pick = |i: usize| keep.get(i / nc).copied().unwrap_or(false);
        a.data = match &a.data {
            ArrayData::F32(v) => ArrayData::F32(
                v.iter()
                    .enumerate()
                    .filter(|(i, _)| pick(*i))
                    .map(|(_, x)| *x)
                    .collect(),
            ),
            ArrayData::F64(v) => ArrayData::F64(
                v.iter()
                    .enumerate()
                    .filter(|(i, _)| pick(*i))
                    .map(|(_, x)| *x)
                    .collect(),
            ),
            ArrayData::Int(v) => ArrayData::Int(
                v.iter()
                    .enumerate()
                    .filter(|(i, _)| pick(*i))
                    .map(|(_, x)| *x)
                    .collect(),
            ),
        };
    }
}

/// Concatenates array data; mixed types become `f64` (integers as `i64`
/// when all parts are integers).
fn concat(parts: &[&ArrayData]) -> ArrayData {
    let all = |f: fn(&ArrayData) -> bool| parts.iter().all(|p| f(p));
    if all(|p| matches!(p, ArrayData::F32(_))) {
        ArrayData::F32(
            parts
                .iter()
                .flat_map(|p| match p {
                    ArrayData::F32(v) => v.as_slice(),
                    _ => &[],
                })
                .copied()
                .collect(),
        )
    } else if all(|p| matches!(p, ArrayData::Int(_))) {
        ArrayData::Int(
            parts
                .iter()
                .flat_map(|p| match p {
                    ArrayData::Int(v) => v.as_slice(),
                    _ => &[],
                })
                .copied()
                .collect(),
        )
    } else {
        ArrayData::F64(
            parts
                .iter()
                .flat_map(|p| (0..p.len()).map(move |i| p.get(i)))
                .collect(),
        )
    }
}

/// Merges the arrays named like those of the first piece.
fn merge_arrays(sets: &[&[DataArray]], what: &str, notes: &mut Vec<String>) -> Vec<DataArray> {
    let Some(first) = sets.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for a in first.iter() {
        let parts: Vec<&DataArray> = sets
            .iter()
            .filter_map(|s| {
                s.iter()
                    .find(|b| b.name == a.name && b.components == a.components)
            })
            .collect();
        if parts.len() != sets.len() {
            notes.push(format!(
                "{what} array '{}' is missing from some pieces: dropped",
                a.name
            ));
            continue;
        }
        let same_type = parts.iter().all(|p| p.vtk_type == a.vtk_type);
        let data = concat(&parts.iter().map(|p| &p.data).collect::<Vec<_>>());
        let vtk_type = if same_type {
            a.vtk_type.clone()
        } else if data.is_float() {
            "Float64".to_string()
        } else {
            "Int64".to_string()
        };
        out.push(DataArray {
            name: a.name.clone(),
            components: a.components,
            data,
            vtk_type,
        });
    }
    out
}

/// Merges pieces into one mesh (point ids offset per piece).
pub fn merge(mut pieces: Vec<Mesh>) -> Mesh {
    if pieces.len() == 1 {
        return pieces.pop().unwrap_or_default();
    }
    let mut m = Mesh::default();
    let mut notes = Vec::new();
    let mut by_type: BTreeMap<String, usize> = BTreeMap::new();
    for p in &pieces {
        let base = m.points.len() as u32;
        let cbase = m.cells.len() as u32;
        m.points.extend_from_slice(&p.points);
        for c in 0..p.cells.len() {
            let nodes: Vec<u32> = p.cells.nodes(c).iter().map(|&n| n + base).collect();
            m.cells.push(p.cells.kinds[c], &nodes);
        }
        for (&c, faces) in &p.cells.poly_faces {
            let shifted = faces
                .iter()
                .map(|f| f.iter().map(|&n| n + base).collect())
                .collect();
            m.cells.poly_faces.insert(c + cbase, shifted);
        }
        for (k, v) in &p.source.cells_by_type {
            *by_type.entry(k.clone()).or_default() += v;
        }
        m.source.ignored_cells += p.source.ignored_cells;
        for n in &p.source.notes {
            if !notes.contains(n) {
                notes.push(n.clone());
            }
        }
    }
    let pd: Vec<&[DataArray]> = pieces.iter().map(|p| p.point_data.as_slice()).collect();
    let cd: Vec<&[DataArray]> = pieces.iter().map(|p| p.cell_data.as_slice()).collect();
    m.point_data = merge_arrays(&pd, "point", &mut notes);
    m.cell_data = merge_arrays(&cd, "cell", &mut notes);
    m.active_point_scalars = pieces[0]
        .active_point_scalars
        .clone()
        .filter(|s| m.point_data.iter().any(|a| &a.name == s));
    m.active_cell_scalars = pieces[0]
        .active_cell_scalars
        .clone()
        .filter(|s| m.cell_data.iter().any(|a| &a.name == s));
    m.source.cells_by_type = by_type;
    m.source.notes = notes;
    m
}
