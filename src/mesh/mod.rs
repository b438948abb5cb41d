//! The mesh model: points, 3D cells and the data arrays attached to them.
//!
//! Readers in [`crate::io`] produce one [`Mesh`]. Points are `f64` (the
//! readers convert `f32` coordinates exactly); cells are stored in a compact
//! CSR layout ([`Cells`]): one kind byte, an offset and the corner node ids.
//! Only 3D cells are kept; 0D-2D cells are dropped by the readers and counted
//! in [`SourceInfo::ignored_cells`], and cell arrays are filtered to match.
//!
//! Topology (unique faces, adjacency) lives in [`topology`]; consistent
//! tetrahedralisation in [`tetra`]; connected components in [`components`];
//! cell volumes, orientation, degeneracy and nonplanarity in [`quality`];
//! orientation repair in [`orient`]; coincident-point merging in [`merge`];
//! the convex hull in [`hull`]; everything `info` prints in [`report`];
//! keeping a subset of the cells (with their data) in [`subset`]; the cells
//! a file marks hidden or duplicate (VTK's `vtkGhostType`) in [`ghost`].

pub mod cell;
pub mod components;
pub mod data;
pub mod ghost;
pub mod hull;
pub mod merge;
pub mod orient;
pub mod quality;
pub mod report;
pub mod subset;
pub mod tetra;
pub mod topology;

use std::collections::BTreeMap;

use glam::DVec3;

pub use cell::CellKind;

use data::DataArray;

/// Sentinel for "no cell" / "no face".
pub const NONE: u32 = u32::MAX;

/// The point ids of cube `(i, j, k)` of a structured lattice with `nx x ny`
/// points per layer (point `(i, j, k)` is `i + nx (j + ny k)`), in VTK
/// hexahedron node order: the bottom face counter-clockwise seen from
/// above, then the top face.
#[inline]
pub fn lattice_hex(nx: usize, ny: usize, [i, j, k]: [usize; 3]) -> [u32; 8] {
    let id = |i: usize, j: usize, k: usize| (i + nx * (j + ny * k)) as u32;
    [
        id(i, j, k),
        id(i + 1, j, k),
        id(i + 1, j + 1, k),
        id(i, j + 1, k),
        id(i, j, k + 1),
        id(i + 1, j, k + 1),
        id(i + 1, j + 1, k + 1),
        id(i, j + 1, k + 1),
    ]
}

/// The 3D cells of a mesh in CSR layout.
#[derive(Clone, Debug, Default)]
pub struct Cells {
    /// Kind of each cell.
    pub kinds: Vec<CellKind>,
    /// `offsets[c]..offsets[c + 1]` indexes `conn` for cell `c`; `len = n + 1`.
    pub offsets: Vec<u32>,
    /// Corner node ids (point indices) in the kind's VTK node order.
    pub conn: Vec<u32>,
    /// Faces of [`CellKind::Polyhedron`] cells: cell id -> faces, each face a
    /// list of point ids ordered so the right-hand normal points outward.
    pub poly_faces: BTreeMap<u32, Vec<Vec<u32>>>,
}

impl Cells {
    /// The hexahedra of a structured lattice of `dims` points (every
    /// `dims[d] >= 2`; the point count must fit in `u32`), `i` fastest,
    /// each by [`lattice_hex`].
    pub fn lattice(dims: [usize; 3]) -> Cells {
        let [nx, ny, nz] = dims;
        let n = (nx - 1) * (ny - 1) * (nz - 1);
        let mut conn = Vec::with_capacity(8 * n);
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    conn.extend_from_slice(&lattice_hex(nx, ny, [i, j, k]));
                }
            }
        }
        Cells {
            kinds: vec![CellKind::Hexahedron; n],
            offsets: (0..=n as u32).map(|c| 8 * c).collect(),
            conn,
            poly_faces: Default::default(),
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.kinds.len()
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.kinds.is_empty()
    }

    /// Corner node ids of cell `c`.
    #[inline]
    pub fn nodes(&self, c: usize) -> &[u32] {
        &self.conn[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }

    /// Appends a cell (node ids in the kind's order).
    pub fn push(&mut self, kind: CellKind, nodes: &[u32]) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        self.kinds.push(kind);
        self.conn.extend_from_slice(nodes);
        self.offsets.push(self.conn.len() as u32);
    }

    /// Appends a general polyhedron given by its faces (point ids); its node
    /// list is the sorted set of the faces' point ids.
    pub fn push_polyhedron(&mut self, faces: Vec<Vec<u32>>) {
        let mut nodes: Vec<u32> = faces.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        let id = self.len() as u32;
        self.push(CellKind::Polyhedron, &nodes);
        self.poly_faces.insert(id, faces);
    }

    /// Calls `f` with each face of cell `c` as a list of point ids, in the
    /// cell's local face order.
    pub fn for_each_face(&self, c: usize, mut f: impl FnMut(usize, &[u32])) {
        let kind = self.kinds[c];
        if kind == CellKind::Polyhedron {
            if let Some(faces) = self.poly_faces.get(&(c as u32)) {
                for (i, face) in faces.iter().enumerate() {
                    f(i, face);
                }
            }
            return;
        }
        let nodes = self.nodes(c);
        let mut buf = [0u32; 6];
        for (i, lf) in kind.faces().iter().enumerate() {
            for (k, &ln) in lf.iter().enumerate() {
                buf[k] = nodes[ln as usize];
            }
            f(i, &buf[..lf.len()]);
        }
    }

    /// Number of faces of cell `c`.
    pub fn face_count(&self, c: usize) -> usize {
        match self.kinds[c] {
            CellKind::Polyhedron => self.poly_faces.get(&(c as u32)).map_or(0, |f| f.len()),
            k => k.faces().len(),
        }
    }
}

/// Facts about the source file that the mesh model itself does not keep.
#[derive(Clone, Debug, Default)]
pub struct SourceInfo {
    /// Counts of the 3D cells by their VTK type name as written in the file
    /// (e.g. `quadratic_tetra`, `voxel`), see [`cell::vtk_type_name`].
    pub cells_by_type: BTreeMap<String, usize>,
    /// 0D-2D cells in the file, which zoovr ignores.
    pub ignored_cells: usize,
    /// Human-readable notes about repairs the reader made.
    pub notes: Vec<String>,
    /// The time value the file itself records, if any: VTK XML, the first
    /// value of the `TimeValue` array of the dataset's `<FieldData>` (a
    /// `.pvtu`: its pieces'); legacy VTK, of the dataset `FIELD` array
    /// `TIME` or `TimeValue`.
    pub time_value: Option<f64>,
}

/// One dataset: points, 3D cells and attached arrays.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Point coordinates.
    pub points: Vec<DVec3>,
    /// The 3D cells.
    pub cells: Cells,
    /// Point data arrays (one tuple per point).
    pub point_data: Vec<DataArray>,
    /// Cell data arrays (one tuple per kept 3D cell).
    pub cell_data: Vec<DataArray>,
    /// Name of the active point scalars, when the file marks one.
    pub active_point_scalars: Option<String>,
    /// Name of the active cell scalars, when the file marks one.
    pub active_cell_scalars: Option<String>,
    /// What the reader saw.
    pub source: SourceInfo,
}

impl Mesh {
    /// Axis-aligned bounds `[xmin, xmax, ymin, ymax, zmin, zmax]` of the points
    /// used by cells (all points when there are no cells).
    pub fn bounds(&self) -> [f64; 6] {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        if self.cells.is_empty() {
            for p in &self.points {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        } else {
            // In parallel blocks (a time step's renders ask for it several
            // times); min and max are exact, so the result does not depend
            // on the blocks.
            use rayon::prelude::*;
            let points = &self.points;
            (lo, hi) = self
                .cells
                .conn
                .par_chunks(1 << 16)
                .map(|block| {
                    block.iter().fold((lo, hi), |(l, h), &n| {
                        let p = points[n as usize];
                        (l.min(p), h.max(p))
                    })
                })
                .reduce(|| (lo, hi), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        }
        if lo.x > hi.x {
            return [0.0; 6];
        }
        [lo.x, hi.x, lo.y, hi.y, lo.z, hi.z]
    }

    /// Length of the bounds diagonal.
    pub fn diagonal(&self) -> f64 {
        let b = self.bounds();
        DVec3::new(b[1] - b[0], b[3] - b[2], b[5] - b[4]).length()
    }

    /// Checks the structure every reader guarantees: CSR offsets start at 0,
    /// never decrease and end at the connectivity length; each cell has its
    /// kind's corner count (polyhedra: their faces, whose ids are in range);
    /// every node id names a point; every point is finite; every array has
    /// one tuple per point (cell) and a whole number of tuples. Run by the
    /// reader tests on every file they read.
    pub fn sanity_check(&self) -> Result<(), String> {
        let c = &self.cells;
        let n = c.len();
        if n == 0 {
            if !(c.offsets.is_empty() || c.offsets == [0]) || !c.conn.is_empty() {
                return Err("no cells but offsets or connectivity".into());
            }
        } else {
            if c.offsets.len() != n + 1 {
                return Err(format!("{} offsets for {n} cells", c.offsets.len()));
            }
            if c.offsets[0] != 0 || c.offsets[n] as usize != c.conn.len() {
                return Err(format!(
                    "offsets run {}..{} over {} node ids",
                    c.offsets[0],
                    c.offsets[n],
                    c.conn.len()
                ));
            }
            for (cell, w) in c.offsets.windows(2).enumerate() {
                if w[1] < w[0] {
                    return Err(format!("cell {cell}: offsets decrease"));
                }
                let k = (w[1] - w[0]) as usize;
                match c.kinds[cell].corner_count() {
                    Some(want) if want != k => {
                        return Err(format!(
                            "cell {cell} ({}) has {k} nodes, expected {want}",
                            c.kinds[cell].vtk_name()
                        ))
                    }
                    Some(_) => {}
                    None => {
                        let faces = c
                            .poly_faces
                            .get(&(cell as u32))
                            .ok_or_else(|| format!("polyhedron {cell} has no faces"))?;
                        if faces.len() < 4 || faces.iter().any(|f| f.len() < 3) {
                            return Err(format!("polyhedron {cell}: malformed faces"));
                        }
                        let np = self.points.len();
                        if faces.iter().flatten().any(|&p| p as usize >= np) {
                            return Err(format!("polyhedron {cell}: face id out of range"));
                        }
                    }
                }
            }
        }
        let np = self.points.len();
        if let Some(&bad) = c.conn.iter().find(|&&p| p as usize >= np) {
            return Err(format!("node id {bad} but {np} points"));
        }
        if let Some(i) = self.points.iter().position(|p| !p.is_finite()) {
            return Err(format!("point {i} is not finite"));
        }
        for (arrays, want, what) in [
            (&self.point_data, np, "point"),
            (&self.cell_data, n, "cell"),
        ] {
            for a in arrays {
                if a.components == 0 || a.data.len() % a.components != 0 {
                    return Err(format!(
                        "{what} array '{}': {} values in tuples of {}",
                        a.name,
                        a.data.len(),
                        a.components
                    ));
                }
                if a.tuples() != want {
                    return Err(format!(
                        "{what} array '{}' has {} tuples for {want} {what}s",
                        a.name,
                        a.tuples()
                    ));
                }
            }
        }
        Ok(())
    }
}
