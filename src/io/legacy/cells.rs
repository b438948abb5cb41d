//! Cell sections of legacy files and their conversion to [`Cells`].
//!
//! Two layouts exist. Before version 5 a `CELLS n size` section holds `size`
//! integers: for each cell its node count followed by the node ids. From 5.0
//! on, `CELLS n_offsets n_conn` is followed by an `OFFSETS <type>` array and
//! a `CONNECTIVITY <type>` array (any integer type). Both are read into one
//! [`CellArray`] (offsets plus ids), which remembers how to find each value in
//! the file again so that a bad id can be reported at its line or byte.
//!
//! [`convert`] then applies `CELL_TYPES`: 0D-2D cells are dropped (and
//! counted), voxels become hexahedra, quadratic and higher-order cells keep
//! their corner nodes (cells labelled hexahedron or wedge that carry 20/27 or
//! 15/18 nodes are read as the quadratic cell), and `VTK_POLYHEDRON` entries
//! are parsed as VTK's face stream `[n_faces, n0, ids.., n1, ids..]`.

use std::collections::BTreeMap;

use super::tokens::{Cursor, Span, ValueType};
use crate::field::ArrayData;
use crate::io::{IoError, Location};
use crate::mesh::cell::{vtk_type_is_lower_dim, vtk_type_name, VOXEL_TO_HEX};
use crate::mesh::{CellKind, Cells};

/// A cell section: `offsets[c]..offsets[c + 1]` indexes `ids` for cell `c`.
pub(crate) struct CellArray {
    pub(crate) offsets: Vec<usize>,
    pub(crate) ids: Vec<i64>,
    span: Span,
    /// Whether each cell's ids are preceded by a count in the file (pre-5.0).
    with_counts: bool,
}

impl CellArray {
    /// Number of cells.
    pub(crate) fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Location in the file of cell `c`'s entry (its count, or its first id).
    fn cell_location(&self, cur: &Cursor<'_>, c: usize) -> Location {
        let lo = self.offsets[c];
        let idx = if self.with_counts { lo + c } else { lo };
        cur.value_location(self.span, idx)
    }

    /// Location in the file of `ids[j]`, which belongs to cell `c`.
    fn location(&self, cur: &Cursor<'_>, c: usize, j: usize) -> Location {
        let idx = if self.with_counts { j + c + 1 } else { j };
        cur.value_location(self.span, idx)
    }
}

fn ints(data: ArrayData) -> Vec<i64> {
    match data {
        ArrayData::Int(v) => v,
        // Floating-point id arrays are refused by the callers' type check.
        ArrayData::F32(v) => v.into_iter().map(|x| x as i64).collect(),
        ArrayData::F64(v) => v.into_iter().map(|x| x as i64).collect(),
    }
}

fn int_type(cur: &mut Cursor<'_>, what: &str) -> Result<ValueType, IoError> {
    let ty = cur.value_type()?;
    if matches!(ty, ValueType::F32 | ValueType::F64 | ValueType::Bit) {
        return Err(cur.err(format!("{what} must have an integer type")));
    }
    Ok(ty)
}

/// Reads a cell section whose keyword (`CELLS`, `POLYGONS`, ...) was just
/// read; picks the layout from whether an `OFFSETS` array follows.
pub(crate) fn read_cell_array(cur: &mut Cursor<'_>, keyword: &str) -> Result<CellArray, IoError> {
    let a = cur.count(&format!("{keyword} count"))?;
    let b = cur.count(&format!("{keyword} size"))?;
    let section = cur.loc();
    if cur.accept_keyword("OFFSETS") {
        let ty = int_type(cur, "OFFSETS")?;
        let (off, _) = cur.read_values(a, ty, "OFFSETS")?;
        if !cur.accept_keyword("CONNECTIVITY") {
            cur.next_token();
            return Err(cur.err("expected CONNECTIVITY after the OFFSETS array"));
        }
        let ty = int_type(cur, "CONNECTIVITY")?;
        let (conn, span) = cur.read_values(b, ty, "CONNECTIVITY")?;
        let off = ints(off);
        let mut offsets = Vec::with_capacity(off.len().max(1));
        for (i, &o) in off.iter().enumerate() {
            let prev = offsets.last().copied().unwrap_or(0);
            let ok = usize::try_from(o)
                .ok()
                .filter(|&o| o <= b && o >= prev && (i > 0 || o == 0));
            match ok {
                Some(o) => offsets.push(o),
                None => {
                    return Err(cur.err_at(
                        section.clone(),
                        format!(
                            "{keyword}: offset {i} = {o} is not increasing from 0 within 0..={b}"
                        ),
                    ))
                }
            }
        }
        if offsets.is_empty() {
            offsets.push(0);
        }
        if offsets.last() != Some(&b) {
            return Err(cur.err_at(
                section,
                format!("{keyword}: the last offset must equal the connectivity size {b}"),
            ));
        }
        return Ok(CellArray {
            offsets,
            ids: ints(conn),
            span,
            with_counts: false,
        });
    }
    let (raw, span) = cur.read_values(b, ValueType::I32, keyword)?;
    let raw = ints(raw);
    let mut offsets = Vec::with_capacity(a.min(b) + 1);
    let mut ids = Vec::with_capacity(b.saturating_sub(a));
    offsets.push(0);
    let mut i = 0usize;
    for c in 0..a {
        let k = raw.get(i).copied().ok_or_else(|| {
            cur.err_at(
                section.clone(),
                format!("{keyword}: {a} cells claimed but the {b} values end at cell {c}"),
            )
        })?;
        let k = usize::try_from(k)
            .ok()
            .filter(|&k| k < b - i)
            .ok_or_else(|| {
                cur.err_at(
                    cur.value_location(span, i),
                    format!("{keyword}: cell {c} has an invalid node count {k}"),
                )
            })?;
        ids.extend_from_slice(&raw[i + 1..i + 1 + k]);
        offsets.push(ids.len());
        i += 1 + k;
    }
    if i != b {
        return Err(cur.err_at(
            section,
            format!("{keyword}: the {a} cells use {i} values but the section size is {b}"),
        ));
    }
    Ok(CellArray {
        offsets,
        ids,
        span,
        with_counts: true,
    })
}

/// Reads the `CELL_TYPES n` section (keyword already read).
pub(crate) fn read_cell_types(cur: &mut Cursor<'_>) -> Result<(Vec<i64>, Span), IoError> {
    let n = cur.count("CELL_TYPES count")?;
    let (t, span) = cur.read_values(n, ValueType::I32, "CELL_TYPES")?;
    Ok((ints(t), span))
}

/// How many nodes a cell type takes.
#[derive(Clone, Copy)]
enum Nodes {
    Exact(&'static [usize]),
    AtLeast(usize),
}

enum Class {
    Lower,
    Solid(CellKind, Nodes),
    Voxel,
    Polyhedron,
    Unsupported,
}

fn classify(t: u8) -> Class {
    use CellKind::*;
    use Nodes::*;
    match t {
        10 => Class::Solid(Tetra, Exact(&[4])),
        11 => Class::Voxel,
        12 => Class::Solid(Hexahedron, Exact(&[8, 20, 27])),
        13 => Class::Solid(Wedge, Exact(&[6, 15, 18])),
        14 => Class::Solid(Pyramid, Exact(&[5, 13])),
        15 => Class::Solid(PentagonalPrism, Exact(&[10])),
        16 => Class::Solid(HexagonalPrism, Exact(&[12])),
        24 => Class::Solid(Tetra, Exact(&[10])),
        25 => Class::Solid(Hexahedron, Exact(&[20])),
        26 => Class::Solid(Wedge, Exact(&[15])),
        27 => Class::Solid(Pyramid, Exact(&[13])),
        29 => Class::Solid(Hexahedron, Exact(&[27])),
        31 => Class::Solid(Wedge, Exact(&[12])),
        32 => Class::Solid(Wedge, Exact(&[18])),
        33 => Class::Solid(Hexahedron, Exact(&[24])),
        37 => Class::Solid(Pyramid, Exact(&[19])),
        71 | 78 => Class::Solid(Tetra, AtLeast(4)),
        72 | 79 => Class::Solid(Hexahedron, AtLeast(8)),
        73 | 80 => Class::Solid(Wedge, AtLeast(6)),
        74 | 81 => Class::Solid(Pyramid, AtLeast(5)),
        42 => Class::Polyhedron,
        75..=77 => Class::Lower,
        t if vtk_type_is_lower_dim(t) => Class::Lower,
        _ => Class::Unsupported,
    }
}

/// VTK's name of a cell type, including the Bézier types the mesh table lacks.
pub(crate) fn type_name(t: u8) -> &'static str {
    match t {
        75 => "bezier_curve",
        76 => "bezier_triangle",
        77 => "bezier_quadrilateral",
        78 => "bezier_tetra",
        79 => "bezier_hexahedron",
        80 => "bezier_wedge",
        81 => "bezier_pyramid",
        t => vtk_type_name(t),
    }
}

/// The 3D cells of a section, and which file cells they came from.
pub(crate) struct Converted {
    pub(crate) cells: Cells,
    /// `keep[c]`: whether file cell `c` became a mesh cell.
    pub(crate) keep: Vec<bool>,
    pub(crate) by_type: BTreeMap<String, usize>,
    pub(crate) ignored: usize,
}

/// Builds the mesh cells from a cell section and its types.
pub(crate) fn convert(
    cur: &Cursor<'_>,
    arr: &CellArray,
    types: &[i64],
    types_span: Span,
    n_points: usize,
) -> Result<Converted, IoError> {
    if types.len() != arr.len() {
        return Err(cur.err_at(
            cur.value_location(types_span, 0),
            format!(
                "CELL_TYPES lists {} types for {} cells",
                types.len(),
                arr.len()
            ),
        ));
    }
    if u32::try_from(arr.ids.len()).is_err() {
        return Err(cur.err_at(cur.loc_here(), "more than 2^32 cell node ids"));
    }
    let mut out = Converted {
        cells: Cells::default(),
        keep: vec![false; arr.len()],
        by_type: BTreeMap::new(),
        ignored: 0,
    };
    out.cells.kinds.reserve(arr.len());
    out.cells.offsets.reserve(arr.len() + 1);
    out.cells.conn.reserve(arr.ids.len());
    out.cells.offsets.push(0);
    let mut nodes_u32: Vec<u32> = Vec::with_capacity(32);
    let mut counts = [0usize; 256];
    for (c, &code) in types.iter().enumerate() {
        let t = u8::try_from(code).map_err(|_| {
            cur.err_at(
                cur.value_location(types_span, c),
                format!("cell {c} has an invalid cell type {code}"),
            )
        })?;
        let (lo, hi) = (arr.offsets[c], arr.offsets[c + 1]);
        let ids = &arr.ids[lo..hi];
        let (kind, rule, voxel) = match classify(t) {
            Class::Lower => {
                out.ignored += 1;
                continue;
            }
            Class::Unsupported => {
                return Err(cur.err_at(
                    cur.value_location(types_span, c),
                    format!("cell {c}: unsupported cell type {t} ({})", type_name(t)),
                ))
            }
            Class::Polyhedron => {
                let faces = face_stream(cur, arr, c, n_points)?;
                out.cells.push_polyhedron(faces);
                out.keep[c] = true;
                counts[t as usize] += 1;
                continue;
            }
            Class::Voxel => (CellKind::Hexahedron, Nodes::Exact(&[8]), true),
            Class::Solid(k, r) => (k, r, false),
        };
        let ok = match rule {
            Nodes::Exact(list) => list.contains(&ids.len()),
            Nodes::AtLeast(m) => ids.len() >= m,
        };
        if !ok {
            let want = match rule {
                Nodes::Exact(list) => format!("{list:?}"),
                Nodes::AtLeast(m) => format!("at least {m}"),
            };
            return Err(cur.err_at(
                arr.cell_location(cur, c),
                format!(
                    "cell {c} ({}, type {t}) needs {want} nodes, has {}",
                    type_name(t),
                    ids.len()
                ),
            ));
        }
        // Every id of a kept cell must name a point (mid-edge nodes included).
        nodes_u32.clear();
        for (j, &id) in ids.iter().enumerate() {
            let p = usize::try_from(id)
                .ok()
                .filter(|&i| i < n_points)
                .ok_or_else(|| {
                    cur.err_at(
                        arr.location(cur, c, lo + j),
                        format!(
                            "cell {c}: point id {id} out of range (the file has {n_points} points)"
                        ),
                    )
                })?;
            nodes_u32.push(p as u32);
        }
        if voxel {
            let v: [u32; 8] = std::array::from_fn(|i| nodes_u32[VOXEL_TO_HEX[i]]);
            out.cells.push(kind, &v);
        } else {
            let corners = kind.corner_count().unwrap_or(nodes_u32.len());
            out.cells.push(kind, &nodes_u32[..corners]);
        }
        out.keep[c] = true;
        counts[t as usize] += 1;
    }
    for (t, &n) in counts.iter().enumerate() {
        if n > 0 {
            out.by_type.insert(type_name(t as u8).to_string(), n);
        }
    }
    Ok(out)
}

/// Parses a polyhedron's face stream `[n_faces, (n, ids..)*]`.
fn face_stream(
    cur: &Cursor<'_>,
    arr: &CellArray,
    c: usize,
    n_points: usize,
) -> Result<Vec<Vec<u32>>, IoError> {
    let (lo, hi) = (arr.offsets[c], arr.offsets[c + 1]);
    let s = &arr.ids[lo..hi];
    let bad = |j: usize, msg: String| {
        cur.err_at(
            arr.location(cur, c, lo + j.min(s.len().saturating_sub(1))),
            format!("polyhedron cell {c}: {msg}"),
        )
    };
    let nf = s.first().copied().unwrap_or(0);
    if nf < 4 || nf as usize > s.len() {
        return Err(bad(
            0,
            format!("invalid face count {nf} in its face stream"),
        ));
    }
    let mut faces = Vec::with_capacity(nf as usize);
    let mut j = 1usize;
    for f in 0..nf as usize {
        let np = s
            .get(j)
            .copied()
            .ok_or_else(|| bad(j, format!("face stream ends at face {f}")))?;
        let np = usize::try_from(np)
            .ok()
            .filter(|&np| np >= 3 && np < s.len() - j)
            .ok_or_else(|| bad(j, format!("face {f} has an invalid point count {np}")))?;
        let mut face = Vec::with_capacity(np);
        for k in 0..np {
            let id = s[j + 1 + k];
            let p = usize::try_from(id)
                .ok()
                .filter(|&p| p < n_points)
                .ok_or_else(|| {
                    bad(
                        j + 1 + k,
                        format!("point id {id} out of range ({n_points} points)"),
                    )
                })?;
            face.push(p as u32);
        }
        faces.push(face);
        j += 1 + np;
    }
    if j != s.len() {
        return Err(bad(
            j,
            format!("face stream has {} values, the faces use {j}", s.len()),
        ));
    }
    Ok(faces)
}
