//! `StructuredGrid` (.vts), `RectilinearGrid` (.vtr) and `ImageData` (.vti).
//!
//! All three are `nx x ny x nz` point lattices given by a piece's `Extent`
//! (`x0 x1 y0 y1 z0 z1`, inclusive). Point `(i, j, k)` has id
//! `i + nx (j + ny k)`; cell `(i, j, k)` is the hexahedron with VTK node order
//! `(i,j,k) (i+1,j,k) (i+1,j+1,k) (i,j+1,k)` then the same at `k+1`, and id
//! `i + (nx-1) (j + (ny-1) k)`, which is also the order of the file's cell
//! data. The positions come from an explicit `<Points>` array (.vts), three
//! coordinate arrays (.vtr), or `Origin + Direction * (index * Spacing)`
//! (.vti). Every cell is counted as `hexahedron` (rectilinear and image cells
//! are VTK voxels, stored here directly in hexahedron order).
//!
//! A lattice that is flat in some direction (`n = 1`) has no 3D cells: its
//! VTK cells (quads, lines or a vertex) are counted as ignored.

use glam::{DMat3, DVec3};

use super::arrays::{check_finite, components, read_arrays, read_points, scalar_type};
use super::dom::Element;
use super::encoding::Source;
use crate::io::IoError;
use crate::mesh::{CellKind, Cells, Mesh};

/// Which lattice flavour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lattice {
    Structured,
    Rectilinear,
    Image,
}

/// Most points generated from an extent alone (.vti, .vtr): 2^26, about
/// 1.6 GB of coordinates. Explicit point arrays (.vts) are bounded by the
/// bytes present instead.
const MAX_GENERATED_POINTS: u64 = 1 << 26;

fn parse_numbers<const N: usize>(
    src: &Source,
    el: &Element,
    key: &str,
) -> Result<Option<[f64; N]>, IoError> {
    let Some(s) = el.attr(key) else {
        return Ok(None);
    };
    let v: Vec<f64> = s
        .split_ascii_whitespace()
        .filter_map(|t| t.parse().ok())
        .collect();
    if v.len() != N || v.iter().any(|x| !x.is_finite()) {
        return Err(IoError::parse(
            src.path,
            el.location(),
            format!("bad {key} '{s}': expected {N} numbers"),
        ));
    }
    Ok(Some(std::array::from_fn(|i| v[i])))
}

/// The piece's extent as point counts per axis and the first index.
fn extent(
    src: &Source,
    grid: &Element,
    piece: &Element,
) -> Result<([usize; 3], [i64; 3]), IoError> {
    let s = piece
        .attr("Extent")
        .or_else(|| grid.attr("WholeExtent"))
        .unwrap_or("");
    let v: Vec<i64> = s
        .split_ascii_whitespace()
        .filter_map(|t| t.parse().ok())
        .collect();
    let bad = || IoError::parse(src.path, piece.location(), format!("bad Extent '{s}'"));
    if v.len() != 6 {
        return Err(bad());
    }
    let mut dims = [0usize; 3];
    for a in 0..3 {
        let n = v[2 * a + 1]
            .checked_sub(v[2 * a])
            .and_then(|d| d.checked_add(1))
            .ok_or_else(bad)?;
        if n < 1 || n > u32::MAX as i64 {
            return Err(bad());
        }
        dims[a] = n as usize;
    }
    let np = dims
        .iter()
        .try_fold(1u64, |acc, &d| acc.checked_mul(d as u64));
    match np {
        Some(n) if n <= super::unstructured::MAX_COUNT => Ok((dims, [v[0], v[2], v[4]])),
        _ => Err(IoError::parse(
            src.path,
            piece.location(),
            format!("Extent '{s}' gives too many points"),
        )),
    }
}

/// Reads every piece of a lattice dataset.
pub fn read(src: &Source, grid: &Element, lattice: Lattice) -> Result<Vec<Mesh>, IoError> {
    grid.children_named("Piece")
        .map(|p| read_piece(src, grid, p, lattice))
        .collect()
}

fn read_piece(
    src: &Source,
    grid: &Element,
    piece: &Element,
    lattice: Lattice,
) -> Result<Mesh, IoError> {
    let (dims, first) = extent(src, grid, piece)?;
    let np = dims[0] * dims[1] * dims[2];
    if lattice != Lattice::Structured && np as u64 > MAX_GENERATED_POINTS {
        return Err(IoError::parse(
            src.path,
            piece.location(),
            format!(
                "extent gives {np} points, more than the {MAX_GENERATED_POINTS} zoovr generates"
            ),
        ));
    }
    let points = match lattice {
        Lattice::Structured => read_points(src, piece, np)?,
        Lattice::Rectilinear => rectilinear_points(src, piece, dims)?,
        Lattice::Image => image_points(src, grid, dims, first)?,
    };
    let file_cells: usize = dims.iter().map(|&d| (d - 1).max(1)).product();
    let solid = dims.iter().all(|&d| d >= 2);
    let mut mesh = Mesh {
        points,
        ..Mesh::default()
    };
    let mut notes = Vec::new();
    let (pd, pa) = read_arrays(src, piece.child("PointData"), np, &mut notes)?;
    let (mut cd, ca) = read_arrays(src, piece.child("CellData"), file_cells, &mut notes)?;
    if solid {
        mesh.cells = Cells::lattice(dims);
        mesh.source
            .cells_by_type
            .insert(CellKind::Hexahedron.vtk_name().to_string(), file_cells);
    } else {
        mesh.source.ignored_cells = file_cells;
        super::arrays::filter_tuples(&mut cd, &[]);
    }
    mesh.point_data = pd;
    mesh.cell_data = cd;
    mesh.active_point_scalars = pa;
    mesh.active_cell_scalars = ca;
    mesh.source.notes = notes;
    Ok(mesh)
}

fn rectilinear_points(
    src: &Source,
    piece: &Element,
    dims: [usize; 3],
) -> Result<Vec<DVec3>, IoError> {
    let coords = piece.child("Coordinates").ok_or_else(|| {
        IoError::parse(
            src.path,
            piece.location(),
            "RectilinearGrid piece without <Coordinates>",
        )
    })?;
    let arrays: Vec<&Element> = coords.children_named("DataArray").collect();
    if arrays.len() != 3 {
        return Err(IoError::parse(
            src.path,
            coords.location(),
            "<Coordinates> needs 3 arrays",
        ));
    }
    let mut axes: [Vec<f64>; 3] = Default::default();
    for a in 0..3 {
        if components(src, arrays[a])? != 1 {
            return Err(IoError::parse(
                src.path,
                arrays[a].location(),
                "coordinate arrays have 1 component",
            ));
        }
        axes[a] = src.decode(arrays[a], scalar_type(src, arrays[a])?, Some(dims[a]))?;
        if axes[a].iter().any(|v| !v.is_finite()) {
            return Err(IoError::parse(
                src.path,
                arrays[a].location(),
                "non-finite coordinate",
            ));
        }
    }
    let mut pts = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for &z in &axes[2] {
        for &y in &axes[1] {
            for &x in &axes[0] {
                pts.push(DVec3::new(x, y, z));
            }
        }
    }
    Ok(pts)
}

fn image_points(
    src: &Source,
    grid: &Element,
    dims: [usize; 3],
    first: [i64; 3],
) -> Result<Vec<DVec3>, IoError> {
    let origin = DVec3::from(parse_numbers::<3>(src, grid, "Origin")?.unwrap_or([0.0; 3]));
    let spacing = DVec3::from(parse_numbers::<3>(src, grid, "Spacing")?.unwrap_or([1.0; 3]));
    let dir = parse_numbers::<9>(src, grid, "Direction")?
        .map(|d| DMat3::from_cols_array(&d).transpose())
        .unwrap_or(DMat3::IDENTITY);
    let mut pts = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let idx = DVec3::new(
                    (first[0] + i as i64) as f64,
                    (first[1] + j as i64) as f64,
                    (first[2] + k as i64) as f64,
                );
                pts.push(origin + dir * (idx * spacing));
            }
        }
    }
    check_finite(src, grid, &pts)?;
    Ok(pts)
}
