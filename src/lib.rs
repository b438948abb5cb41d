//! zoovr: exact volume rendering of unstructured and curvilinear grids made
//! of zoo cells (tetrahedra, pyramids, wedges, hexahedra, convex polyhedra).
//!
//! The pipeline, one module per step (see `ARCHITECTURE.md`):
//! [`io`] -> [`mesh`] -> [`field`] -> [`visibility`] -> [`projection`] ->
//! [`integrate`] -> [`gpu`], with [`raycast`] as the independent reference.

pub mod bench;
pub mod camera;
pub mod field;
#[doc(hidden)]
pub mod fuzzing;
pub mod generate;
pub mod gpu;
pub mod image;
pub mod integrate;
pub mod io;
pub mod legend;
pub mod mesh;
pub mod numeric;
pub mod projection;
pub mod raycast;
pub mod render;
#[doc(hidden)]
pub mod testdata;
pub mod tf;
pub mod video;
pub mod visibility;
