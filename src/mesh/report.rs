//! [`MeshReport`]: every structural and quality fact `zoovr info` prints,
//! computed once.
//!
//! Steps: topology ([`Topology::build`]) -> boundary / non-manifold face
//! counts and connected components -> signed cell volumes and their
//! classification ([`super::quality`]) -> nonplanar quad faces -> convex hull
//! of the boundary-face points ([`super::hull`]) for the convexity ratio ->
//! the consistent tetrahedra of every cell, each signed by the exact
//! predicate and multiplied by the orientation of its cell, so that
//! `inverted_tets` counts what remains inverted *after* orientation repair
//! (the mesh itself is not changed) -> coincident points a merge would join.

use rayon::prelude::*;

use super::components::connected_components;
use super::hull::convex_hull_volume;
use super::merge::coincident_representatives;
use super::quality::{cell_volumes, orientations, quality_counts, Orientation};
use super::tetra::tetrahedralize_cell;
use super::topology::Topology;
use super::{Mesh, NONE};
use crate::numeric::predicates::{orient3d, Side};

/// Structure and quality of a mesh (see the module docs for each step).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshReport {
    /// 3D cells.
    pub cells: usize,
    /// Points (including unused ones).
    pub points: usize,
    /// Unique faces.
    pub faces: usize,
    /// Faces with one cell.
    pub boundary_faces: usize,
    /// Faces listed by more than two cells (extras counted).
    pub nonmanifold_faces: usize,
    /// Connected components through shared faces.
    pub components: usize,
    /// Sum of `|cell volume|`.
    pub volume: f64,
    /// Volume of the convex hull of the boundary points (0 when flat).
    pub hull_volume: f64,
    /// `volume / hull_volume` (1 for a convex mesh); `None` when the hull is
    /// flat.
    pub convexity: Option<f64>,
    /// Cells with negative signed volume in the given node order.
    pub inverted_cells: usize,
    /// Cells with zero volume.
    pub degenerate_cells: usize,
    /// Cells that use a point id twice.
    pub repeated_index_cells: usize,
    /// Quad faces (per cell) leaving their plane by more than the report
    /// tolerance of the face's longer diagonal.
    pub nonplanar_faces: usize,
    /// Largest quad-face nonplanarity relative to the face's diagonal.
    pub max_nonplanarity: f64,
    /// Consistent tetrahedra of all cells.
    pub tets: usize,
    /// Consistent tetrahedra with negative volume after orientation repair.
    pub inverted_tets: usize,
    /// Consistent tetrahedra with exactly zero volume.
    pub flat_tets: usize,
    /// Points with the same coordinates as a smaller-index point.
    pub coincident_points: usize,
    /// 0D-2D cells the reader dropped.
    pub ignored_cells: usize,
}

impl MeshReport {
    /// Builds the topology and computes the report.
    pub fn compute(mesh: &Mesh) -> MeshReport {
        let topo = Topology::build(&mesh.cells);
        MeshReport::compute_with(mesh, &topo)
    }

    /// Computes the report with an existing topology of `mesh`.
    pub fn compute_with(mesh: &Mesh, topo: &Topology) -> MeshReport {
        let vols = cell_volumes(mesh);
        let orient = orientations(mesh, &vols);
        let q = quality_counts(mesh, &vols, &orient);
        let (tets, inverted_tets, flat_tets) = tet_signs(mesh, &orient);
        let hull_volume = convex_hull_volume(&mesh.points, Some(&boundary_points(topo)));
        let convexity = (hull_volume > 0.0).then(|| q.total_volume / hull_volume);
        let coincident_points = coincident_representatives(&mesh.points)
            .iter()
            .enumerate()
            .filter(|(i, &r)| *i != r as usize)
            .count();
        MeshReport {
            cells: mesh.cells.len(),
            points: mesh.points.len(),
            faces: topo.face_count(),
            boundary_faces: topo.boundary_face_count(),
            nonmanifold_faces: topo.nonmanifold_faces,
            components: connected_components(topo).count,
            volume: q.total_volume,
            hull_volume,
            convexity,
            inverted_cells: q.inverted,
            degenerate_cells: q.degenerate,
            repeated_index_cells: q.repeated_index,
            nonplanar_faces: q.nonplanar_faces,
            max_nonplanarity: q.max_nonplanarity,
            tets,
            inverted_tets,
            flat_tets,
            coincident_points,
            ignored_cells: mesh.source.ignored_cells,
        }
    }
}

/// Sorted, deduplicated point ids of the boundary faces.
pub fn boundary_points(topo: &Topology) -> Vec<u32> {
    let mut pts: Vec<u32> = (0..topo.face_count())
        .filter(|&f| topo.face_cells[f][1] == NONE)
        .flat_map(|f| topo.face(f).iter().copied())
        .collect();
    pts.par_sort_unstable();
    pts.dedup();
    pts
}

/// `(tets, inverted, flat)` over the consistent tetrahedra of all cells, each
/// tet's exact sign multiplied by its cell's orientation.
pub fn tet_signs(mesh: &Mesh, orient: &[Orientation]) -> (usize, usize, usize) {
    let p = |i: u32| mesh.points.get(i as usize).copied().unwrap_or_default();
    (0..mesh.cells.len())
        .into_par_iter()
        .map_init(Vec::new, |buf, c| {
            buf.clear();
            tetrahedralize_cell(&mesh.cells, c, buf);
            let flip = orient.get(c) == Some(&Orientation::Inverted);
            let (mut inv, mut flat) = (0, 0);
            for &[a, b, cc, d] in buf.iter() {
                match orient3d(p(a), p(b), p(cc), p(d)) {
                    Side::On => flat += 1,
                    Side::Positive if flip => inv += 1,
                    Side::Negative if !flip => inv += 1,
                    _ => {}
                }
            }
            (buf.len(), inv, flat)
        })
        .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2))
}
