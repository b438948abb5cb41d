//! VTK legacy reader (issue 2).

use std::path::Path;

use super::IoError;
use crate::mesh::Mesh;

/// Reads a legacy `.vtk` file.
pub fn read(path: &Path) -> Result<Mesh, IoError> {
    Err(IoError::parse(
        path,
        super::Location::None,
        "legacy reader pending",
    ))
}
