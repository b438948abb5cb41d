//! What a render draws, in two parts: the [`Geometry`] (points, cells, face
//! adjacency: fixed across the steps of a time series with fixed topology)
//! and the [`Shading`] (the scalar field, its range and the transfer
//! function: changing per step). A [`crate::render::Renderer`] is built once
//! from a geometry and renders any shading of it; a [`Scene`] is the two
//! together, a convenience for one-off renders and tests.
//!
//! [`Geometry::build`] and [`Shading::build`] (or [`Scene::build`], both at
//! once) apply the conventions of docs/conventions.md in one place, so every
//! mode renders the same thing:
//! - cells the file flags hidden or duplicate in its `vtkGhostType` cell
//!   array are left out first, with their cell-data values and the points
//!   only they used ([`crate::mesh::ghost`]), unless
//!   [`SceneSpec::show_hidden`]: the topology, the visibility order, the
//!   exact mode and the ray caster then see only the cells drawn, and cell
//!   data stays aligned with them. Point ghost flags remove nothing;
//! - coincident points are merged (a merged point keeps the smallest original
//!   index, so the smallest-vertex diagonals are unchanged where points were
//!   already shared) and face adjacency is built;
//! - the field is `--field`, else the TF file's `scalar` key, else the
//!   default-field rule ([`crate::field::select_field`]); `--cell-to-point`
//!   averages cell data to points;
//! - the range is `--range`, else the field's min..max over what is drawn
//!   (hidden and duplicate cells, and the points only they use, are gone
//!   by then, as ParaView computes ranges over non-ghost data);
//! - the TF is the file (absolute scalar values), else the preset normalised
//!   onto the range, else the default (viridis, opacity ramp, unit distance =
//!   bounds diagonal / 10, glow).

use std::path::PathBuf;
use std::sync::Arc;

use crate::field::{self, Association, FieldSpec, ScalarField};
use crate::mesh::ghost::remove_ghost_cells;
use crate::mesh::merge::merge_coincident_points;
use crate::mesh::topology::Topology;
use crate::mesh::Mesh;
use crate::tf::presets::Opacity;
use crate::tf::{presets, TransferFunction};

use super::RenderError;

/// How to pick the field and transfer function ([`SceneSpec::show_hidden`]:
/// which cells the geometry keeps).
#[derive(Clone, Debug, Default)]
pub struct SceneSpec {
    /// `--field`.
    pub field: Option<String>,
    /// `--tf FILE` (project JSON or ParaView colour map).
    pub tf_file: Option<PathBuf>,
    /// `--preset NAME`.
    pub preset: Option<String>,
    /// `--range LO,HI`.
    pub range: Option<(f64, f64)>,
    /// `--cell-to-point`.
    pub cell_to_point: bool,
    /// `--show-hidden`: draw the cells that `vtkGhostType` flags hidden or
    /// duplicate too.
    pub show_hidden: bool,
}

/// The scalar values a renderer integrates.
#[derive(Clone, Copy, Debug)]
pub enum ScalarsRef<'a> {
    Point(&'a [f64]),
    Cell(&'a [f64]),
    Constant(f64),
}

impl ScalarsRef<'_> {
    /// The scalars of `field` (`None`: constant scalar 0).
    pub fn of(field: Option<&ScalarField>) -> ScalarsRef<'_> {
        match field {
            Some(f) if f.association == Association::Point => ScalarsRef::Point(&f.values),
            Some(f) => ScalarsRef::Cell(&f.values),
            None => ScalarsRef::Constant(0.0),
        }
    }
}

/// The part of a scene that stays fixed across the steps of a time series
/// with fixed topology: the mesh (points, cells, and the data arrays read
/// with them) after hidden cells are left out and coincident points merged,
/// and its face adjacency. Cloning shares the mesh and topology.
#[derive(Clone, Debug)]
pub struct Geometry {
    pub mesh: Arc<Mesh>,
    pub topology: Arc<Topology>,
    /// Points merged when building the geometry.
    pub merged_points: usize,
    /// Cells left out because `vtkGhostType` flags them hidden or duplicate.
    pub ghost_cells: usize,
}

impl Geometry {
    /// Leaves out hidden and duplicate cells (unless `show_hidden`), merges
    /// coincident points and builds the face adjacency of a freshly read
    /// mesh.
    pub fn build(mesh: Mesh, show_hidden: bool) -> Result<Geometry, RenderError> {
        let (mesh, ghost_cells, merged_points) = Geometry::prepare(mesh, show_hidden)?;
        let topology = Topology::build(&mesh.cells);
        Ok(Geometry {
            mesh: Arc::new(mesh),
            topology: Arc::new(topology),
            merged_points,
            ghost_cells,
        })
    }

    /// The mesh as a geometry holds it: hidden and duplicate cells left out
    /// (unless `show_hidden`) and coincident points merged. Returns it with
    /// the number of cells left out and of points merged.
    pub fn prepare(mut mesh: Mesh, show_hidden: bool) -> Result<(Mesh, usize, usize), RenderError> {
        if mesh.cells.is_empty() {
            return Err(RenderError::NoCells);
        }
        let ghost_cells = if show_hidden {
            0
        } else {
            remove_ghost_cells(&mut mesh)?
        };
        if mesh.cells.is_empty() {
            return Err(RenderError::AllCellsHidden(ghost_cells));
        }
        let merged_points = merge_coincident_points(&mut mesh);
        Ok((mesh, ghost_cells, merged_points))
    }

    /// The default opacity unit distance: bounds diagonal / 10 (1 when the
    /// bounds are degenerate).
    pub fn default_unit(&self) -> f64 {
        default_unit_of(&self.mesh)
    }
}

/// Bounds diagonal / 10 of `mesh` (1 when the bounds are degenerate).
fn default_unit_of(mesh: &Mesh) -> f64 {
    let diagonal = mesh.diagonal();
    if diagonal.is_finite() && diagonal > 0.0 {
        diagonal / 10.0
    } else {
        1.0
    }
}

/// The part of a scene that changes per step of a time series: the field
/// integrated, its range and the transfer function. Cloning shares the
/// field's values.
#[derive(Clone, Debug)]
pub struct Shading {
    /// The field integrated (`None`: constant scalar 0); one value per
    /// point or per cell of the geometry it is rendered with.
    pub field: Option<Arc<ScalarField>>,
    /// Scalar range the TF was mapped onto.
    pub range: (f64, f64),
    pub tf: TransferFunction,
    /// Opacity unit distance in world units (length scale of the scene).
    pub unit_distance: f64,
}

impl Shading {
    /// Picks the field from the arrays of `geometry`'s mesh and the
    /// transfer function, as `spec` asks (module docs).
    pub fn build(geometry: &Geometry, spec: &SceneSpec) -> Result<Shading, RenderError> {
        Shading::build_for_mesh(&geometry.mesh, spec)
    }

    /// [`Shading::build`] from a mesh prepared as a geometry holds it
    /// ([`Geometry::prepare`]), without its topology: e.g. to find the
    /// range of every step of a series first.
    pub fn build_for_mesh(mesh: &Mesh, spec: &SceneSpec) -> Result<Shading, RenderError> {
        let default_unit = default_unit_of(mesh);
        let file_tf = match &spec.tf_file {
            Some(p) => Some(
                TransferFunction::from_json_file(p, default_unit).map_err(|e| RenderError::Tf {
                    path: p.display().to_string(),
                    msg: e.to_string(),
                })?,
            ),
            None => None,
        };
        let field_name = spec
            .field
            .clone()
            .or_else(|| file_tf.as_ref().and_then(|t| t.scalar.clone()));
        let field_spec = match &field_name {
            Some(s) => Some(FieldSpec::parse(s)?),
            None => None,
        };
        let mut field = field::select_field(mesh, field_spec.as_ref())?;
        if spec.cell_to_point {
            if let Some(f) = &field {
                if f.association == Association::Cell {
                    field = Some(field::cell_to_point(mesh, f));
                }
            }
        }
        let range = match spec.range {
            Some(r) => r,
            None => field.as_ref().map(|f| f.range).unwrap_or((0.0, 0.0)),
        };
        let tf = match (file_tf, &spec.preset) {
            (Some(tf), _) => tf,
            (None, Some(name)) => presets::preset(name, range, default_unit, Opacity::Ramp)
                .map_err(|e| RenderError::Tf {
                    path: format!("preset '{name}'"),
                    msg: e.to_string(),
                })?,
            (None, None) => TransferFunction::default_for(range, mesh.diagonal()),
        };
        let unit_distance = tf.unit_distance.unwrap_or(default_unit);
        Ok(Shading {
            field: field.map(Arc::new),
            range,
            tf,
            unit_distance,
        })
    }

    /// The scalars as the renderers take them.
    pub fn scalars(&self) -> ScalarsRef<'_> {
        ScalarsRef::of(self.field.as_deref())
    }

    /// Checks that the field has one value per point or per cell of
    /// `geometry`.
    pub fn check(&self, geometry: &Geometry) -> Result<(), RenderError> {
        let Some(f) = &self.field else {
            return Ok(());
        };
        let (want, per) = match f.association {
            Association::Point => (geometry.mesh.points.len(), "points"),
            Association::Cell => (geometry.mesh.cells.len(), "cells"),
        };
        if f.values.len() == want {
            Ok(())
        } else {
            Err(RenderError::FieldLength {
                name: f.name.clone(),
                got: f.values.len(),
                want,
                per,
            })
        }
    }
}

/// A geometry and one shading of it, flat: everything one render needs that
/// does not depend on the view.
#[derive(Debug)]
pub struct Scene {
    pub mesh: Arc<Mesh>,
    pub topology: Arc<Topology>,
    /// The field integrated (`None`: constant scalar 0).
    pub field: Option<Arc<ScalarField>>,
    /// Scalar range the TF was mapped onto.
    pub range: (f64, f64),
    pub tf: TransferFunction,
    /// Opacity unit distance in world units (length scale of the scene).
    pub unit_distance: f64,
    /// Points merged when building the scene.
    pub merged_points: usize,
    /// Cells left out because `vtkGhostType` flags them hidden or duplicate.
    pub ghost_cells: usize,
}

impl Scene {
    /// Builds the scene from a freshly read mesh ([`Geometry::build`], then
    /// [`Shading::build`]).
    pub fn build(mesh: Mesh, spec: &SceneSpec) -> Result<Scene, RenderError> {
        let geometry = Geometry::build(mesh, spec.show_hidden)?;
        let shading = Shading::build(&geometry, spec)?;
        Ok(Scene::new(geometry, shading))
    }

    /// The scene of `geometry` shaded by `shading`.
    pub fn new(geometry: Geometry, shading: Shading) -> Scene {
        Scene {
            mesh: geometry.mesh,
            topology: geometry.topology,
            field: shading.field,
            range: shading.range,
            tf: shading.tf,
            unit_distance: shading.unit_distance,
            merged_points: geometry.merged_points,
            ghost_cells: geometry.ghost_cells,
        }
    }

    /// Its geometry (shared, not copied).
    pub fn geometry(&self) -> Geometry {
        Geometry {
            mesh: self.mesh.clone(),
            topology: self.topology.clone(),
            merged_points: self.merged_points,
            ghost_cells: self.ghost_cells,
        }
    }

    /// Its shading (the field shared, not copied).
    pub fn shading(&self) -> Shading {
        Shading {
            field: self.field.clone(),
            range: self.range,
            tf: self.tf.clone(),
            unit_distance: self.unit_distance,
        }
    }

    /// The scalars as the renderers take them.
    pub fn scalars(&self) -> ScalarsRef<'_> {
        ScalarsRef::of(self.field.as_deref())
    }

    /// Min and max of every scalar integrated (computed with the field,
    /// not per call), or `None` where some value is not finite.
    pub fn field_span(&self) -> Option<(f64, f64)> {
        self.field
            .as_deref()
            .map_or(Some((0.0, 0.0)), ScalarField::span)
    }

    /// The scene as the reference ray caster takes it (mesh, topology and
    /// scalars).
    pub fn ray_scene(&self) -> crate::raycast::Scene<'_> {
        let scalars = match self.scalars() {
            ScalarsRef::Point(v) => crate::raycast::Scalars::Point(v),
            ScalarsRef::Cell(v) => crate::raycast::Scalars::Cell(v),
            ScalarsRef::Constant(c) => crate::raycast::Scalars::Constant(c),
        };
        crate::raycast::Scene {
            mesh: &self.mesh,
            topology: &self.topology,
            scalars,
        }
    }
}
