//! Errors of transfer-function construction and loading.

use thiserror::Error;

/// Why a transfer function could not be built or loaded.
#[derive(Debug, Error)]
pub enum TfError {
    #[error("transfer function has no points")]
    Empty,
    #[error("{what}: point {index}: scalar value is not finite")]
    NonFiniteScalar { what: &'static str, index: usize },
    #[error("{what}: points are not sorted by scalar (point {index}: {value} after {previous})")]
    Unsorted {
        what: &'static str,
        index: usize,
        value: f64,
        previous: f64,
    },
    #[error("{what}: more than two points at scalar {value} (a jump is exactly two points)")]
    TooManyAtOneScalar { what: &'static str, value: f64 },
    #[error("{what}: point {index}: {field} is not finite")]
    NonFinite {
        what: &'static str,
        index: usize,
        field: &'static str,
    },
    #[error("{what}: point {index}: {field} is negative ({value})")]
    Negative {
        what: &'static str,
        index: usize,
        field: &'static str,
        value: f64,
    },
    #[error("{what}: point {index}: {field} {value} is out of range (magnitude limit 1e100)")]
    OutOfRange {
        what: &'static str,
        index: usize,
        field: &'static str,
        value: f64,
    },
    #[error("{what}: point {index}: opacity {value} is outside [0, 1]")]
    OpacityRange {
        what: &'static str,
        index: usize,
        value: f64,
    },
    #[error("unit distance must be finite and positive, got {0}")]
    UnitDistance(f64),
    #[error("invalid JSON at line {line}, column {column}: {message}")]
    Json {
        line: usize,
        column: usize,
        message: String,
    },
    #[error("unsupported zoovr_tf version {0} (this build reads version 1)")]
    Version(u64),
    #[error("{0}")]
    Format(String),
    #[error("unknown preset {name:?}; available: {available}")]
    UnknownPreset { name: String, available: String },
    #[error("cannot read {path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
}

impl From<serde_json::Error> for TfError {
    fn from(e: serde_json::Error) -> Self {
        let full = e.to_string();
        // serde_json appends " at line L column C"; keep only the message.
        let message = match full.rfind(" at line ") {
            Some(i) => full[..i].to_string(),
            None => full,
        };
        TfError::Json {
            line: e.line(),
            column: e.column(),
            message,
        }
    }
}
