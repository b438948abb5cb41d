//! The error type shared by all readers: always names the file and the place.

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// Where in a file an error was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// 1-based line number (text formats).
    Line(usize),
    /// Byte offset from the start of the file.
    Byte(u64),
    /// A named element, e.g. `DataArray 'connectivity'` or `piece 2`.
    Element(String),
    /// Nowhere more precise than the file.
    None,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::Element(e) => write!(f, "{e}"),
            Location::None => write!(f, "file"),
        }
    }
}

/// A reader error.
#[derive(Debug, Error)]
pub enum IoError {
    #[error("{}: cannot open: {source}", path.display())]
    Open {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {location}: {msg}", path.display())]
    Parse {
        path: PathBuf,
        location: Location,
        msg: String,
    },
    #[error("{}: unknown file format (expected VTK legacy .vtk, VTK XML .vtu/.vts/.vtr/.vti/.pvtu/.pvts/.pvtr/.pvti/.vtm, .pvd, .series or a PLOT3D grid)", path.display())]
    UnknownFormat { path: PathBuf },
}

impl IoError {
    /// An [`IoError::Open`].
    pub fn open(path: &Path, source: std::io::Error) -> IoError {
        IoError::Open {
            path: path.to_path_buf(),
            source,
        }
    }

    /// An [`IoError::Parse`].
    pub fn parse(path: &Path, location: Location, msg: impl Into<String>) -> IoError {
        IoError::Parse {
            path: path.to_path_buf(),
            location,
            msg: msg.into(),
        }
    }
}
