//! PLOT3D reader (issue 2).

use std::path::Path;

use super::IoError;
use crate::mesh::Mesh;

/// Whether the first bytes look like a PLOT3D grid header.
pub fn looks_like_grid(_head: &[u8]) -> bool {
    false
}

/// Reads a PLOT3D grid (and optional Q solution).
pub fn read(path: &Path, _q: Option<&Path>) -> Result<Mesh, IoError> {
    Err(IoError::parse(
        path,
        super::Location::None,
        "plot3d reader pending",
    ))
}
