//! VTK legacy reader (`.vtk`, versions 1.0 to 5.1, ASCII and BINARY).
//!
//! The file is parsed in one pass by a [`tokens::Cursor`] that tracks line
//! numbers and byte offsets, so every error names the file and a line
//! (ASCII) or byte offset (binary). The header is the `# vtk DataFile
//! Version x.y` line, a title line, `ASCII` or `BINARY`, then
//! `DATASET <type>`; after that, sections come in any order, each introduced
//! by a keyword:
//!
//! - geometry: `POINTS`, `DIMENSIONS`, `ORIGIN`, `SPACING` (`ASPECT_RATIO`),
//!   `X/Y/Z_COORDINATES`;
//! - topology: `CELLS` + `CELL_TYPES` ([`cells`]), polydata
//!   `VERTICES`/`LINES`/`POLYGONS`/`TRIANGLE_STRIPS` (2D at most: counted as
//!   ignored);
//! - data: `POINT_DATA n` / `CELL_DATA n` followed by attributes
//!   ([`attributes`]); a `FIELD` block outside them is dataset field data:
//!   the first value of its `TIME` (VTK's writers) or `TimeValue` array is
//!   the step's time ([`SourceInfo::time_value`], what `animate` labels the
//!   frame with), the other arrays are read and dropped;
//! - `METADATA` blocks anywhere (skipped up to their closing blank line).
//!
//! Blank lines are whitespace like any other. At the end the pieces are
//! checked against each other (point and cell counts of every section) and
//! assembled into a [`Mesh`]: structured, rectilinear and image grids become
//! hexahedra ([`structured`]); cell data keeps only the tuples of cells that
//! became 3D mesh cells.
//!
//! `vtkio` is not used: it misreads blank header lines, a `FIELD` before
//! `POINTS` and prism cell types, and cannot say where a file went wrong.

mod attributes;
mod cells;
mod structured;
mod tokens;

use std::path::Path;

use glam::DVec3;

pub(crate) use structured::{hexahedra, vtk_cell_count};

use self::cells::CellArray;
use self::tokens::{Cursor, Span, ValueType};
use super::{IoError, Location};
use crate::field::DataArray;
use crate::mesh::{Mesh, SourceInfo};

/// Image and rectilinear grids get their points from the header alone, so
/// their point count is not bounded by the file size. They are limited to
/// this many points plus [`IMPLICIT_POINTS_PER_BYTE`] per byte of the file.
pub const MAX_IMPLICIT_POINTS_BASE: usize = 1 << 22;
/// See [`MAX_IMPLICIT_POINTS_BASE`].
pub const IMPLICIT_POINTS_PER_BYTE: usize = 16;

/// Reads a legacy `.vtk` file.
pub fn read(path: &Path) -> Result<Mesh, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::open(path, e))?;
    read_bytes(path, &bytes)
}

/// Reads a legacy file from memory; `path` only names it in error messages.
pub fn read_bytes(path: &Path, bytes: &[u8]) -> Result<Mesh, IoError> {
    let mut cur = Cursor::new(path, bytes);
    let dataset = header(&mut cur)?;
    let mut r = Reader {
        dataset,
        ..Reader::default()
    };
    r.sections(&mut cur)?;
    r.finish(&cur)
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Dataset {
    #[default]
    Unstructured,
    Structured,
    Rectilinear,
    Image,
    PolyData,
}

impl Dataset {
    fn name(self) -> &'static str {
        match self {
            Dataset::Unstructured => "UNSTRUCTURED_GRID",
            Dataset::Structured => "STRUCTURED_GRID",
            Dataset::Rectilinear => "RECTILINEAR_GRID",
            Dataset::Image => "STRUCTURED_POINTS",
            Dataset::PolyData => "POLYDATA",
        }
    }
}

/// Parses the four header items and returns the dataset type.
fn header(cur: &mut Cursor<'_>) -> Result<Dataset, IoError> {
    let first = cur.line_rest();
    let text = String::from_utf8_lossy(first).to_ascii_lowercase();
    let Some(ver) = text.trim().strip_prefix("# vtk datafile version") else {
        return Err(cur.err_at(
            Location::Line(1),
            "not a VTK legacy file (expected '# vtk DataFile Version x.y')",
        ));
    };
    let major = ver
        .trim()
        .split('.')
        .next()
        .and_then(|m| m.parse::<u32>().ok());
    match major {
        Some(1..=5) => {}
        _ => {
            return Err(cur.err_at(
                Location::Line(1),
                format!("unsupported legacy version '{}'", ver.trim()),
            ))
        }
    }
    let title = cur.line_rest();
    let title = String::from_utf8_lossy(title).trim().to_ascii_uppercase();
    let format = if title == "ASCII" || title == "BINARY" {
        title
    } else {
        let t = cur.token("ASCII or BINARY")?;
        String::from_utf8_lossy(t).to_ascii_uppercase()
    };
    match format.as_str() {
        "ASCII" => {}
        "BINARY" => cur.set_binary(true),
        other => {
            return Err(cur.err(format!(
                "expected ASCII or BINARY, got '{}'",
                tokens::show(other.as_bytes())
            )))
        }
    }
    let kw = cur.token("DATASET")?;
    if !kw.eq_ignore_ascii_case(b"DATASET") {
        return Err(cur.err(format!("expected DATASET, got '{}'", tokens::show(kw))));
    }
    let ty = cur.token("the dataset type")?;
    Ok(match ty.to_ascii_uppercase().as_slice() {
        b"UNSTRUCTURED_GRID" => Dataset::Unstructured,
        b"STRUCTURED_GRID" => Dataset::Structured,
        b"RECTILINEAR_GRID" => Dataset::Rectilinear,
        b"STRUCTURED_POINTS" => Dataset::Image,
        b"POLYDATA" => Dataset::PolyData,
        _ => return Err(cur.err(format!("unsupported dataset type '{}'", tokens::show(ty)))),
    })
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Section {
    Point,
    Cell,
}

/// Everything read so far, assembled by [`Reader::finish`].
#[derive(Default)]
struct Reader {
    dataset: Dataset,
    points: Option<Vec<DVec3>>,
    dims: Option<([usize; 3], Location)>,
    origin: [f64; 3],
    spacing: Option<[f64; 3]>,
    coords: [Option<Vec<f64>>; 3],
    cells: Option<(CellArray, Location)>,
    types: Option<(Vec<i64>, Span, Location)>,
    poly_cells: usize,
    section: Option<Section>,
    point_n: Option<(usize, Location)>,
    cell_n: Option<(usize, Location)>,
    point_data: Vec<DataArray>,
    cell_data: Vec<DataArray>,
    active_point: Option<String>,
    active_cell: Option<String>,
    time_value: Option<f64>,
    notes: Vec<String>,
}

impl Reader {
    fn sections(&mut self, cur: &mut Cursor<'_>) -> Result<(), IoError> {
        while let Some(tok) = cur.next_token() {
            let kw = String::from_utf8_lossy(tok).to_ascii_uppercase();
            let loc = cur.loc();
            let ds = self.dataset;
            match kw.as_str() {
                "METADATA" => cur.skip_metadata(),
                "FIELD" if self.section.is_none() => {
                    let mut arrays = attributes::read_field(cur, None)?;
                    if let Some(k) = arrays
                        .iter()
                        .position(|a| a.name == "TIME" || a.name == "TimeValue")
                    {
                        let a = arrays.remove(k);
                        let t = (a.tuples() > 0).then(|| a.component(0, 0));
                        match t {
                            Some(t) if t.is_finite() => self.time_value = Some(t),
                            _ => self.notes.push(format!(
                                "dataset field '{}' holds no finite time value: not used",
                                a.name
                            )),
                        }
                    }
                    let names: Vec<&str> = arrays.iter().map(|a| a.name.as_str()).collect();
                    if !names.is_empty() {
                        self.notes
                            .push(format!("dataset field data not used: {}", names.join(", ")));
                    }
                }
                "POINTS" if ds != Dataset::Rectilinear && ds != Dataset::Image => {
                    self.once(cur, self.points.is_some(), "POINTS")?;
                    self.points = Some(read_points(cur)?);
                }
                "CELLS" if ds == Dataset::Unstructured => {
                    self.once(cur, self.cells.is_some(), "CELLS")?;
                    self.cells = Some((cells::read_cell_array(cur, "CELLS")?, loc));
                }
                "CELL_TYPES" if ds == Dataset::Unstructured => {
                    self.once(cur, self.types.is_some(), "CELL_TYPES")?;
                    let (t, span) = cells::read_cell_types(cur)?;
                    self.types = Some((t, span, loc));
                }
                "VERTICES" | "LINES" | "POLYGONS" | "TRIANGLE_STRIPS"
                    if ds == Dataset::PolyData =>
                {
                    self.poly_cells += cells::read_cell_array(cur, &kw)?.len();
                }
                "DIMENSIONS" if ds != Dataset::Unstructured && ds != Dataset::PolyData => {
                    self.once(cur, self.dims.is_some(), "DIMENSIONS")?;
                    let mut d = [0usize; 3];
                    for v in &mut d {
                        *v = cur.count("a grid dimension")?;
                    }
                    self.dims = Some((d, loc));
                }
                "ORIGIN" if ds == Dataset::Image => {
                    for v in &mut self.origin {
                        *v = cur.real("an origin coordinate")?;
                    }
                }
                "SPACING" | "ASPECT_RATIO" if ds == Dataset::Image => {
                    let mut s = [0.0; 3];
                    for v in &mut s {
                        *v = cur.real("a spacing")?;
                    }
                    self.spacing = Some(s);
                }
                "X_COORDINATES" | "Y_COORDINATES" | "Z_COORDINATES"
                    if ds == Dataset::Rectilinear =>
                {
                    let axis = usize::from(kw.as_bytes()[0] - b'X');
                    self.once(cur, self.coords[axis].is_some(), &kw)?;
                    let n = cur.count("the coordinate count")?;
                    let ty = cur.value_type()?;
                    let (data, span) = cur.read_values(n, ty, &kw)?;
                    let v: Vec<f64> = (0..data.len()).map(|i| data.get(i)).collect();
                    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                        return Err(cur.err_at(
                            cur.value_location(span, i),
                            format!("{kw}: value {i} is not finite"),
                        ));
                    }
                    self.coords[axis] = Some(v);
                }
                "POINT_DATA" | "CELL_DATA" => {
                    let n = cur.count(&format!("the {kw} count"))?;
                    let (sec, known) = if kw == "POINT_DATA" {
                        self.point_n = Some((n, loc.clone()));
                        (Section::Point, self.known_points())
                    } else {
                        self.cell_n = Some((n, loc.clone()));
                        (Section::Cell, self.known_cells())
                    };
                    if let Some(m) = known.filter(|&m| m != n) {
                        return Err(cur.err_at(
                            loc,
                            format!(
                                "{kw} {n} does not match the {m} {} of the dataset",
                                if sec == Section::Point {
                                    "points"
                                } else {
                                    "cells"
                                }
                            ),
                        ));
                    }
                    self.section = Some(sec);
                }
                k if attributes::is_attribute(k) && self.section.is_some() => {
                    self.attribute(cur, k)?;
                }
                _ => {
                    return Err(cur.err(format!(
                        "unexpected keyword '{}' in a {} dataset",
                        tokens::show(tok),
                        ds.name()
                    )))
                }
            }
        }
        Ok(())
    }

    fn once(&self, cur: &Cursor<'_>, seen: bool, kw: &str) -> Result<(), IoError> {
        if seen {
            Err(cur.err(format!("a second {kw} section")))
        } else {
            Ok(())
        }
    }

    fn attribute(&mut self, cur: &mut Cursor<'_>, kw: &str) -> Result<(), IoError> {
        let (sec, n) = match self.section {
            Some(Section::Point) => (Section::Point, self.point_n.as_ref().map_or(0, |p| p.0)),
            _ => (Section::Cell, self.cell_n.as_ref().map_or(0, |p| p.0)),
        };
        let (list, active) = match sec {
            Section::Point => (&mut self.point_data, &mut self.active_point),
            Section::Cell => (&mut self.cell_data, &mut self.active_cell),
        };
        match attributes::read_attribute(cur, kw, n)? {
            attributes::Attribute::Scalars(a) => {
                if active.is_none() {
                    *active = Some(a.name.clone());
                }
                list.push(a);
            }
            attributes::Attribute::Arrays(v) => list.extend(v),
            attributes::Attribute::Skipped => {}
        }
        Ok(())
    }

    /// Point count implied by what was read so far.
    fn known_points(&self) -> Option<usize> {
        match self.dataset {
            Dataset::Image | Dataset::Rectilinear => self
                .dims
                .as_ref()
                .and_then(|(d, _)| d[0].checked_mul(d[1]).and_then(|x| x.checked_mul(d[2]))),
            _ => self.points.as_ref().map(Vec::len),
        }
    }

    /// File cell count implied by what was read so far.
    fn known_cells(&self) -> Option<usize> {
        match self.dataset {
            Dataset::Unstructured => self.cells.as_ref().map(|c| c.0.len()),
            Dataset::PolyData => Some(self.poly_cells),
            _ => self.dims.as_ref().map(|(d, _)| vtk_cell_count(*d)),
        }
    }

    /// Checks the pieces against each other and builds the mesh.
    fn finish(mut self, cur: &Cursor<'_>) -> Result<Mesh, IoError> {
        let end = cur.loc_here();
        let points = self.geometry(cur, &end)?;
        let n_points = points.len();
        let mut mesh = Mesh {
            points,
            ..Mesh::default()
        };
        // Cells, and which file cells they keep.
        let keep: Vec<bool> = match self.dataset {
            Dataset::Unstructured => match (self.cells.take(), self.types.take()) {
                (Some((arr, _)), Some((types, span, _))) => {
                    let conv = cells::convert(cur, &arr, &types, span, n_points)?;
                    mesh.cells = conv.cells;
                    mesh.source.cells_by_type = conv.by_type;
                    mesh.source.ignored_cells = conv.ignored;
                    conv.keep
                }
                (Some((_, loc)), None) => {
                    return Err(cur.err_at(loc, "CELLS without a CELL_TYPES section"))
                }
                (None, Some((_, _, loc))) => {
                    return Err(cur.err_at(loc, "CELL_TYPES without a CELLS section"))
                }
                (None, None) => Vec::new(),
            },
            Dataset::PolyData => {
                mesh.source.ignored_cells = self.poly_cells;
                vec![false; self.poly_cells]
            }
            _ => {
                let dims = self.dims.as_ref().map(|d| d.0).unwrap_or([0; 3]);
                let total = vtk_cell_count(dims);
                let is3d = structured::is_3d(dims);
                mesh.cells = hexahedra(dims);
                if is3d {
                    mesh.source
                        .cells_by_type
                        .insert("hexahedron".to_string(), total);
                } else {
                    mesh.source.ignored_cells = total;
                }
                vec![is3d; total]
            }
        };
        if let Some((n, loc)) = &self.point_n {
            if *n != n_points {
                return Err(cur.err_at(
                    loc.clone(),
                    format!("POINT_DATA {n} does not match the {n_points} points"),
                ));
            }
        }
        if let Some((n, loc)) = &self.cell_n {
            if *n != keep.len() {
                return Err(cur.err_at(
                    loc.clone(),
                    format!("CELL_DATA {n} does not match the {} cells", keep.len()),
                ));
            }
        }
        let all_kept = keep.iter().all(|&k| k);
        mesh.point_data = self.point_data;
        mesh.cell_data = if all_kept {
            self.cell_data
        } else {
            self.cell_data
                .into_iter()
                .map(|a| attributes::filter_tuples(a, &keep))
                .collect()
        };
        mesh.active_point_scalars = self.active_point;
        mesh.active_cell_scalars = self.active_cell;
        mesh.source = SourceInfo {
            notes: self.notes,
            time_value: self.time_value,
            ..mesh.source
        };
        Ok(mesh)
    }

    /// The points of the dataset, explicit or generated from the header.
    fn geometry(&mut self, cur: &Cursor<'_>, end: &Location) -> Result<Vec<DVec3>, IoError> {
        let implicit = matches!(self.dataset, Dataset::Image | Dataset::Rectilinear);
        let dims = match (&self.dims, self.dataset) {
            (Some((d, loc)), _) => {
                let n = d[0].checked_mul(d[1]).and_then(|x| x.checked_mul(d[2]));
                let limit = if implicit {
                    MAX_IMPLICIT_POINTS_BASE
                        .saturating_add(IMPLICIT_POINTS_PER_BYTE.saturating_mul(cur.len()))
                        .min(u32::MAX as usize)
                } else {
                    u32::MAX as usize
                };
                match n {
                    Some(n) if n <= limit => Some((*d, n, loc.clone())),
                    _ => {
                        return Err(cur.err_at(
                            loc.clone(),
                            format!("DIMENSIONS {d:?} give more points than the file can describe (limit {limit})"),
                        ))
                    }
                }
            }
            (None, Dataset::Unstructured | Dataset::PolyData) => None,
            (None, _) => return Err(cur.err_at(end.clone(), "missing DIMENSIONS section")),
        };
        match self.dataset {
            Dataset::Unstructured | Dataset::PolyData | Dataset::Structured => {
                let pts = self
                    .points
                    .take()
                    .ok_or_else(|| cur.err_at(end.clone(), "missing POINTS section"))?;
                if let Some((d, n, loc)) = dims {
                    if n != pts.len() {
                        return Err(cur.err_at(
                            loc,
                            format!("DIMENSIONS {d:?} need {n} points, POINTS has {}", pts.len()),
                        ));
                    }
                }
                Ok(pts)
            }
            Dataset::Image => {
                let (d, n, _) =
                    dims.ok_or_else(|| cur.err_at(end.clone(), "missing DIMENSIONS"))?;
                let o = DVec3::from(self.origin);
                let s = DVec3::from(self.spacing.unwrap_or([1.0; 3]));
                let mut pts = Vec::with_capacity(n);
                for k in 0..d[2] {
                    for j in 0..d[1] {
                        for i in 0..d[0] {
                            pts.push(o + s * DVec3::new(i as f64, j as f64, k as f64));
                        }
                    }
                }
                Ok(pts)
            }
            Dataset::Rectilinear => {
                let (d, n, loc) =
                    dims.ok_or_else(|| cur.err_at(end.clone(), "missing DIMENSIONS"))?;
                let mut axes: [&[f64]; 3] = [&[], &[], &[]];
                for (a, name) in ["X", "Y", "Z"].iter().enumerate() {
                    let c = self.coords[a].as_deref().ok_or_else(|| {
                        cur.err_at(end.clone(), format!("missing {name}_COORDINATES section"))
                    })?;
                    if c.len() != d[a] {
                        return Err(cur.err_at(
                            loc.clone(),
                            format!(
                                "{name}_COORDINATES has {} values, DIMENSIONS says {}",
                                c.len(),
                                d[a]
                            ),
                        ));
                    }
                    axes[a] = c;
                }
                let mut pts = Vec::with_capacity(n);
                for &z in axes[2] {
                    for &y in axes[1] {
                        for &x in axes[0] {
                            pts.push(DVec3::new(x, y, z));
                        }
                    }
                }
                Ok(pts)
            }
        }
    }
}

/// Reads `POINTS n type` (keyword already read); coordinates must be finite.
fn read_points(cur: &mut Cursor<'_>) -> Result<Vec<DVec3>, IoError> {
    let n = cur.count("the point count")?;
    if u32::try_from(n).is_err() {
        return Err(cur.err(format!("{n} points exceed the 2^32 limit")));
    }
    let ty: ValueType = cur.value_type()?;
    let nv = n
        .checked_mul(3)
        .ok_or_else(|| cur.err("point count overflows"))?;
    let (data, span) = cur.read_values(nv, ty, "POINTS")?;
    let mut pts = Vec::with_capacity(n);
    for p in 0..n {
        let v = DVec3::new(data.get(3 * p), data.get(3 * p + 1), data.get(3 * p + 2));
        if !v.is_finite() {
            let c = (0..3).find(|&c| !v[c].is_finite()).unwrap_or(0);
            return Err(cur.err_at(
                cur.value_location(span, 3 * p + c),
                format!(
                    "point {p} has a non-finite coordinate ({}, {}, {})",
                    v.x, v.y, v.z
                ),
            ));
        }
        pts.push(v);
    }
    Ok(pts)
}
