//! Time collections: `.pvd` and ParaView `.series` (issue 2).

use std::path::Path;

use super::{IoError, TimeStep};

/// Reads a `.pvd` collection.
pub fn read_pvd(path: &Path) -> Result<Vec<TimeStep>, IoError> {
    Err(IoError::parse(
        path,
        super::Location::None,
        "pvd reader pending",
    ))
}

/// Reads a `.series` JSON collection.
pub fn read_series_json(path: &Path) -> Result<Vec<TimeStep>, IoError> {
    Err(IoError::parse(
        path,
        super::Location::None,
        "series reader pending",
    ))
}
