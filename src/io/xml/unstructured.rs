//! `UnstructuredGrid` pieces: points, the `<Cells>` arrays, point/cell data.
//!
//! `<Cells>` holds `connectivity` (node ids of all cells back to back),
//! `offsets` (the *end* of each cell in `connectivity`, one per cell) and
//! `types` (VTK cell type codes, any integer width). Polyhedra (type 42) add
//! `faces` (per polyhedron: face count, then per face its point count and
//! ids) and `faceoffsets` (end of each cell's stream in `faces`, -1 for cells
//! that are not polyhedra). VTK 9.4+ writes polyhedra as four arrays instead:
//! `face_connectivity`/`face_offsets` (the faces' point ids) and
//! `polyhedron_to_faces`/`polyhedron_offsets` (each cell's face ids); offsets
//! are accepted with or without a leading 0.
//!
//! Each cell is mapped as `mesh::cell` describes: 0D-2D cells are dropped and
//! counted (cell data is filtered to match), voxels are reordered to
//! hexahedron order, quadratic and higher-order cells keep their corner nodes
//! (VTK lists corners first), and a cell labelled linear but carrying the
//! node count of its quadratic sibling is read as that quadratic cell. When
//! every cell is already a linear 3D kind, the decoded connectivity becomes the
//! mesh's connectivity without a copy.

use std::collections::BTreeMap;

use super::arrays::{read_arrays, read_points, scalar_type};
use super::dom::Element;
use super::encoding::Source;
use crate::io::IoError;
use crate::mesh::cell::{vtk_type_is_lower_dim, vtk_type_name, VOXEL_TO_HEX};
use crate::mesh::{CellKind, Cells, Mesh};

/// Largest point or cell count of one piece (ids are `u32`, `u32::MAX` is a
/// sentinel).
pub const MAX_COUNT: u64 = u32::MAX as u64 - 1;

/// How a VTK cell type code is read.
struct Spec {
    kind: CellKind,
    /// Node counts accepted in the file; the first is the type's own.
    counts: &'static [usize],
    /// Higher-order (Lagrange/Bezier) cells: any count >= corners.
    at_least: bool,
}

fn spec(code: u8) -> Option<Spec> {
    use CellKind::*;
    let s = |kind, counts| Spec {
        kind,
        counts,
        at_least: false,
    };
    let hi = |kind, counts| Spec {
        kind,
        counts,
        at_least: true,
    };
    Some(match code {
        10 => s(Tetra, &[4, 10]),
        11 => s(Hexahedron, &[8]),
        12 => s(Hexahedron, &[8, 20, 27]),
        13 => s(Wedge, &[6, 15, 18]),
        14 => s(Pyramid, &[5, 13, 19]),
        15 => s(PentagonalPrism, &[10]),
        16 => s(HexagonalPrism, &[12]),
        24 => s(Tetra, &[10]),
        25 => s(Hexahedron, &[20]),
        26 => s(Wedge, &[15]),
        27 => s(Pyramid, &[13]),
        29 => s(Hexahedron, &[27]),
        31 => s(Wedge, &[12]),
        32 => s(Wedge, &[18]),
        33 => s(Hexahedron, &[24]),
        37 => s(Pyramid, &[19]),
        71 | 78 => hi(Tetra, &[4]),
        72 | 79 => hi(Hexahedron, &[8]),
        73 | 80 => hi(Wedge, &[6]),
        74 | 81 => hi(Pyramid, &[5]),
        _ => return None,
    })
}

/// The name counted in `cells_by_type` for a type code.
fn type_name(code: u8) -> &'static str {
    match code {
        78 => "bezier_tetra",
        79 => "bezier_hexahedron",
        80 => "bezier_wedge",
        81 => "bezier_pyramid",
        c => vtk_type_name(c),
    }
}

fn lower_dim(code: u8) -> bool {
    vtk_type_is_lower_dim(code) || (75..=77).contains(&code)
}

/// A count attribute such as `NumberOfPoints` (`+11047` is accepted).
pub fn count_attr(src: &Source, el: &Element, key: &str) -> Result<usize, IoError> {
    let raw = el.attr(key).unwrap_or("0").trim();
    let v: u64 = raw
        .strip_prefix('+')
        .unwrap_or(raw)
        .parse()
        .map_err(|_| IoError::parse(src.path, el.location(), format!("bad {key} '{raw}'")))?;
    if v > MAX_COUNT {
        return Err(IoError::parse(
            src.path,
            el.location(),
            format!("{key}={v} exceeds the supported maximum {MAX_COUNT}"),
        ));
    }
    Ok(v as usize)
}

/// Reads one `<Piece>` of an `UnstructuredGrid`.
pub fn read_piece(src: &Source, piece: &Element) -> Result<Mesh, IoError> {
    let np = count_attr(src, piece, "NumberOfPoints")?;
    let nc = count_attr(src, piece, "NumberOfCells")?;
    let points = read_points(src, piece, np)?;
    let mut mesh = Mesh {
        points,
        ..Mesh::default()
    };
    let keep = read_cells(src, piece, np, nc, &mut mesh)?;
    let mut notes = std::mem::take(&mut mesh.source.notes);
    let (pd, pa) = read_arrays(src, piece.child("PointData"), np, &mut notes)?;
    let (mut cd, ca) = read_arrays(src, piece.child("CellData"), nc, &mut notes)?;
    if let Some(keep) = keep {
        super::arrays::filter_tuples(&mut cd, &keep);
    }
    mesh.point_data = pd;
    mesh.cell_data = cd;
    mesh.active_point_scalars = pa;
    mesh.active_cell_scalars = ca;
    mesh.source.notes = notes;
    Ok(mesh)
}

fn cells_array<'e>(cells: &'e Element, name: &str) -> Option<&'e Element> {
    cells
        .children_named("DataArray")
        .find(|a| a.attr("Name") == Some(name))
}

/// Reads `<Cells>` into `mesh.cells`; returns the keep mask of the file's
/// cells when some were dropped.
fn read_cells(
    src: &Source,
    piece: &Element,
    np: usize,
    nc: usize,
    mesh: &mut Mesh,
) -> Result<Option<Vec<bool>>, IoError> {
    if nc == 0 {
        return Ok(None);
    }
    let cells_el = piece.child("Cells").ok_or_else(|| {
        IoError::parse(
            src.path,
            piece.location(),
            format!("{nc} cells declared but no <Cells>"),
        )
    })?;
    let need = |name: &str| {
        cells_array(cells_el, name).ok_or_else(|| {
            IoError::parse(
                src.path,
                cells_el.location(),
                format!("<Cells> has no '{name}' array"),
            )
        })
    };
    let (types_el, offsets_el, conn_el) = (need("types")?, need("offsets")?, need("connectivity")?);
    let types: Vec<u8> = src.decode(types_el, scalar_type(src, types_el)?, Some(nc))?;
    let offsets: Vec<u32> = src.decode(offsets_el, scalar_type(src, offsets_el)?, Some(nc))?;
    let bad = |el: &Element, msg: String| IoError::parse(src.path, el.location(), msg);
    let mut prev = 0u32;
    for (i, &o) in offsets.iter().enumerate() {
        if o == u32::MAX || o < prev {
            return Err(bad(
                offsets_el,
                format!("offset {o} of cell {i} is out of range or decreasing (previous {prev})"),
            ));
        }
        prev = o;
    }
    let conn: Vec<u32> = src.decode(conn_el, scalar_type(src, conn_el)?, Some(prev as usize))?;
    if let Some(i) = conn.iter().position(|&v| v as usize >= np) {
        let cell = offsets.partition_point(|&o| o as usize <= i);
        let id = match conn[i] {
            u32::MAX => "a negative or huge id".to_string(),
            v => format!("point {v}"),
        };
        return Err(bad(
            conn_el,
            format!("cell {cell} refers to {id} but there are {np} points"),
        ));
    }
    let linear = |t: u8| matches!(t, 10 | 12 | 13 | 14 | 15 | 16);
    if types.iter().all(|&t| linear(t)) {
        return fast_path(src, conn_el, types, offsets, conn, mesh).map(|_| None);
    }
    let polys = if !types.contains(&42) {
        None
    } else if cells_array(cells_el, "polyhedron_offsets").is_some() {
        Some(read_faces_vtk94(src, cells_el, nc, np)?)
    } else {
        Some(read_faces(src, cells_el, nc, np)?)
    };
    general_path(src, conn_el, &types, &offsets, &conn, polys, mesh)
}

/// Every cell is a linear 3D kind: reuse the connectivity as is.
fn fast_path(
    src: &Source,
    el: &Element,
    types: Vec<u8>,
    offsets: Vec<u32>,
    conn: Vec<u32>,
    mesh: &mut Mesh,
) -> Result<(), IoError> {
    let mut kinds = Vec::with_capacity(types.len());
    let mut counts = [0usize; 17];
    let mut start = 0u32;
    for (i, (&t, &end)) in types.iter().zip(&offsets).enumerate() {
        let kind = spec(t).map(|s| s.kind).unwrap_or(CellKind::Tetra);
        let n = (end - start) as usize;
        if Some(n) != kind.corner_count() {
            return Err(IoError::parse(
                src.path,
                el.location(),
                format!(
                    "cell {i} ({}) has {n} nodes, expected {}",
                    type_name(t),
                    kind.corner_count().unwrap_or(0)
                ),
            ));
        }
        kinds.push(kind);
        counts[t as usize] += 1;
        start = end;
    }
    let mut full = Vec::with_capacity(offsets.len() + 1);
    full.push(0);
    full.extend_from_slice(&offsets);
    mesh.cells = Cells {
        kinds,
        offsets: full,
        conn,
        poly_faces: BTreeMap::new(),
    };
    for (t, &c) in counts.iter().enumerate() {
        if c > 0 {
            *mesh
                .source
                .cells_by_type
                .entry(type_name(t as u8).to_string())
                .or_default() += c;
        }
    }
    Ok(())
}

/// Mixed, higher-order, voxel, lower-dimensional or polyhedral cells.
fn general_path(
    src: &Source,
    el: &Element,
    types: &[u8],
    offsets: &[u32],
    conn: &[u32],
    mut polys: Option<Vec<Option<Vec<Vec<u32>>>>>,
    mesh: &mut Mesh,
) -> Result<Option<Vec<bool>>, IoError> {
    let mut keep = vec![true; types.len()];
    let mut relabelled = BTreeMap::<u8, usize>::new();
    let mut start = 0usize;
    for (i, (&t, &end)) in types.iter().zip(offsets).enumerate() {
        let nodes = &conn[start..end as usize];
        start = end as usize;
        if lower_dim(t) {
            keep[i] = false;
            mesh.source.ignored_cells += 1;
            continue;
        }
        let err = |msg: String| IoError::parse(src.path, el.location(), format!("cell {i}: {msg}"));
        if t == 42 {
            let faces = polys
                .as_mut()
                .and_then(|p| p.get_mut(i))
                .and_then(Option::take)
                .ok_or_else(|| err("polyhedron without faces in 'faces'/'faceoffsets'".into()))?;
            mesh.cells.push_polyhedron(faces);
        } else {
            let s = spec(t).ok_or_else(|| err(format!("unsupported VTK cell type {t}")))?;
            let corners = s.kind.corner_count().unwrap_or(0);
            let ok = if s.at_least {
                nodes.len() >= corners
            } else {
                s.counts.contains(&nodes.len())
            };
            if !ok {
                return Err(err(format!(
                    "{} with {} nodes (expected {:?})",
                    type_name(t),
                    nodes.len(),
                    s.counts
                )));
            }
            if !s.at_least && nodes.len() != s.counts[0] {
                *relabelled.entry(t).or_default() += 1;
            }
            if t == 11 {
                let hex: [u32; 8] = std::array::from_fn(|k| nodes[VOXEL_TO_HEX[k]]);
                mesh.cells.push(s.kind, &hex);
            } else {
                mesh.cells.push(s.kind, &nodes[..corners]);
            }
        }
        *mesh
            .source
            .cells_by_type
            .entry(type_name(t).to_string())
            .or_default() += 1;
    }
    for (t, n) in relabelled {
        mesh.source.notes.push(format!(
            "{n} cells labelled {} carry the node count of the quadratic cell: read as quadratic, corners used",
            type_name(t)
        ));
    }
    Ok((mesh.source.ignored_cells > 0).then_some(keep))
}

/// The array `name` of `<Cells>`, which polyhedra need.
fn polyhedron_array<'e>(
    src: &Source,
    cells_el: &'e Element,
    name: &str,
) -> Result<&'e Element, IoError> {
    cells_array(cells_el, name).ok_or_else(|| {
        IoError::parse(
            src.path,
            cells_el.location(),
            format!("polyhedra need a '{name}' array"),
        )
    })
}

/// Reads `faces`/`faceoffsets` into per-cell face lists (`None` for cells
/// that are not polyhedra).
fn read_faces(
    src: &Source,
    cells_el: &Element,
    nc: usize,
    np: usize,
) -> Result<Vec<Option<Vec<Vec<u32>>>>, IoError> {
    let need = |name: &str| polyhedron_array(src, cells_el, name);
    let (faces_el, fo_el) = (need("faces")?, need("faceoffsets")?);
    let fo: Vec<i64> = src.decode(fo_el, scalar_type(src, fo_el)?, Some(nc))?;
    let faces: Vec<i64> = src.decode(faces_el, scalar_type(src, faces_el)?, None)?;
    let err = |i: usize, msg: &str| {
        IoError::parse(
            src.path,
            faces_el.location(),
            format!("polyhedron cell {i}: {msg}"),
        )
    };
    let mut out = Vec::with_capacity(nc);
    let mut start = 0usize;
    for (i, &end) in fo.iter().enumerate() {
        if end < 0 {
            out.push(None);
            continue;
        }
        let end = end as usize;
        let stream = faces
            .get(start..end)
            .ok_or_else(|| err(i, "face offsets out of range"))?;
        start = end;
        let mut it = stream.iter().copied();
        let nf = it.next().ok_or_else(|| err(i, "empty face stream"))?;
        if nf < 4 || nf as usize > stream.len() {
            return Err(err(i, "bad face count"));
        }
        let mut cell_faces = Vec::with_capacity(nf as usize);
        for _ in 0..nf {
            let n = it.next().ok_or_else(|| err(i, "truncated face stream"))?;
            if n < 3 || n as usize > stream.len() {
                return Err(err(i, "bad face size"));
            }
            let face = (0..n)
                .map(|_| match it.next() {
                    Some(p) if p >= 0 && (p as usize) < np => Ok(p as u32),
                    _ => Err(err(i, "face point id missing or out of range")),
                })
                .collect::<Result<Vec<u32>, _>>()?;
            cell_faces.push(face);
        }
        if it.next().is_some() {
            return Err(err(i, "face stream longer than its faces"));
        }
        out.push(Some(cell_faces));
    }
    Ok(out)
}

/// Offsets as `n + 1` starts (a leading 0 added when the file gives `n` ends).
fn with_leading_zero(v: Vec<i64>, n: usize) -> Vec<i64> {
    if v.len() == n + 1 {
        return v;
    }
    let mut out = Vec::with_capacity(n + 1);
    out.push(0);
    out.extend(v);
    out
}

/// Reads the VTK 9.4+ polyhedron arrays into per-cell face lists.
fn read_faces_vtk94(
    src: &Source,
    cells_el: &Element,
    nc: usize,
    np: usize,
) -> Result<Vec<Option<Vec<Vec<u32>>>>, IoError> {
    let need = |name: &str| polyhedron_array(src, cells_el, name);
    let dec =
        |el: &Element| -> Result<Vec<i64>, IoError> { src.decode(el, scalar_type(src, el)?, None) };
    let (fc_el, fo_el, p2f_el, po_el) = (
        need("face_connectivity")?,
        need("face_offsets")?,
        need("polyhedron_to_faces")?,
        need("polyhedron_offsets")?,
    );
    let fc = dec(fc_el)?;
    let fo = dec(fo_el)?;
    let p2f = dec(p2f_el)?;
    let po = dec(po_el)?;
    if po.len() != nc && po.len() != nc + 1 {
        return Err(IoError::parse(
            src.path,
            po_el.location(),
            format!("{} offsets for {nc} cells", po.len()),
        ));
    }
    let po = with_leading_zero(po, nc);
    let nfaces = if fo.first() == Some(&0) {
        fo.len().saturating_sub(1)
    } else {
        fo.len()
    };
    let fo = with_leading_zero(fo, nfaces);
    let bad = |el: &Element, i: usize, what: &str| {
        IoError::parse(
            src.path,
            el.location(),
            format!("polyhedron cell {i}: {what}"),
        )
    };
    let range = |v: &[i64], k: usize| -> Option<(usize, usize)> {
        let (a, b) = (*v.get(k)?, *v.get(k + 1)?);
        (0 <= a && a <= b).then_some((a as usize, b as usize))
    };
    let mut out = Vec::with_capacity(nc);
    for i in 0..nc {
        let (a, b) = range(&po, i).ok_or_else(|| bad(po_el, i, "bad polyhedron offsets"))?;
        let ids = p2f
            .get(a..b)
            .ok_or_else(|| bad(p2f_el, i, "face ids out of range"))?;
        if ids.is_empty() {
            out.push(None);
            continue;
        }
        let mut faces = Vec::with_capacity(ids.len());
        for &f in ids {
            let (fa, fb) = usize::try_from(f)
                .ok()
                .and_then(|f| range(&fo, f))
                .ok_or_else(|| bad(p2f_el, i, "face id out of range"))?;
            let pts = fc
                .get(fa..fb)
                .ok_or_else(|| bad(fo_el, i, "face offsets out of range"))?;
            if pts.len() < 3 || pts.iter().any(|&p| p < 0 || p as usize >= np) {
                return Err(bad(
                    fc_el,
                    i,
                    "face with fewer than 3 points or a point id out of range",
                ));
            }
            faces.push(pts.iter().map(|&p| p as u32).collect());
        }
        out.push(Some(faces));
    }
    Ok(out)
}
