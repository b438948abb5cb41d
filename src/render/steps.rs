//! The steps of a time series on one geometry: what changed from one step
//! to the next, and so what a [`super::Renderer`] may keep.
//!
//! [`Geometry::next_step`] takes a later step's freshly read mesh through
//! the same preparation as [`Geometry::build`] (hidden and duplicate cells
//! left out, coincident points merged), so its cells, points and arrays
//! line up with the geometry's exactly as step 0's did, and then compares
//! it with the geometry, exactly (bit for bit, no tolerance):
//! - [`StepChange::Values`]: the same cells and the same point coordinates;
//!   only the arrays differ. The renderer keeps everything: topology, the
//!   sorter with its planes and splits, the last sort of the view (a step
//!   only splices its values in), the GPU context.
//! - [`StepChange::Points`]: the same cells (connectivity, kinds, polyhedron
//!   faces) after the merge, new coordinates (a deforming mesh). The face
//!   adjacency ([`Topology`]) depends on the cells alone and is shared; the
//!   sorter's planes are rebuilt and the pieces re-sorted.
//! - [`StepChange::Cells`]: anything else; the topology is rebuilt (the
//!   render is still right, just without reuse).
//!
//! Comparing costs one pass over the connectivity and the points, far less
//! than reading the step.

use std::sync::Arc;

use serde::Serialize;

use crate::mesh::topology::Topology;
use crate::mesh::{Cells, Mesh};

use super::scene::Geometry;
use super::RenderError;

/// What changed between a geometry and the next step of its series.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepChange {
    /// Nothing: the geometry itself (the first step; or a camera move only).
    None,
    /// Same cells and points, new values: everything is kept.
    Values,
    /// Same cells, new point coordinates: the topology is kept, the
    /// visibility sort's geometry rebuilt.
    Points,
    /// Different cells: nothing geometric is kept.
    Cells,
}

impl StepChange {
    /// The lower-case name used in `--stats`.
    pub fn name(self) -> &'static str {
        match self {
            StepChange::None => "none",
            StepChange::Values => "values",
            StepChange::Points => "points",
            StepChange::Cells => "cells",
        }
    }
}

/// Whether two cell lists are the same cells, node for node.
pub fn same_cells(a: &Cells, b: &Cells) -> bool {
    a.kinds == b.kinds && a.offsets == b.offsets && a.conn == b.conn && a.poly_faces == b.poly_faces
}

/// Whether two point lists are bit for bit the same coordinates.
pub fn same_points(a: &[glam::DVec3], b: &[glam::DVec3]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            p.x.to_bits() == q.x.to_bits()
                && p.y.to_bits() == q.y.to_bits()
                && p.z.to_bits() == q.z.to_bits()
        })
}

impl Geometry {
    /// The geometry of a later step of this geometry's series, from its
    /// freshly read mesh, and what changed (module docs). The arrays are the
    /// step's own; the topology is shared when the cells are the same.
    pub fn next_step(
        &self,
        mesh: Mesh,
        show_hidden: bool,
    ) -> Result<(Geometry, StepChange), RenderError> {
        let (mesh, ghost_cells, merged_points) = Geometry::prepare(mesh, show_hidden)?;
        let (topology, change) = if same_cells(&self.mesh.cells, &mesh.cells) {
            let change = if same_points(&self.mesh.points, &mesh.points) {
                StepChange::Values
            } else {
                StepChange::Points
            };
            (self.topology.clone(), change)
        } else {
            (Arc::new(Topology::build(&mesh.cells)), StepChange::Cells)
        };
        let geometry = Geometry {
            mesh: Arc::new(mesh),
            topology,
            merged_points,
            ghost_cells,
        };
        Ok((geometry, change))
    }
}
