//! Every tolerance in zoovr, in one place, each with its reason.
//!
//! Combinatorial decisions (which side of a plane, whether two projected edges
//! cross, which cell a ray enters) do not use tolerances: they go through
//! [`super::predicates`]. The values here bound *numerical* approximations
//! and classify data for reporting.

/// Relative deviation (of the bounds diagonal) of a quad face's fourth vertex
/// from the plane of the other three above which `info` counts the face as
/// nonplanar. Matches the figure used in `../shared/data/README.md`.
pub const NONPLANAR_REPORT_REL: f64 = 1e-3;

/// Cells whose |signed volume| is below this fraction of (bounding box
/// diagonal of the cell)^3 are reported as degenerate (zero volume).
pub const DEGENERATE_VOLUME_REL: f64 = 1e-12;

/// Relative distance (of the bounds diagonal) under which two points are
/// merged by the optional coincident-point merge (exactly equal coordinates
/// are always merged; this allows for ASCII round-off).
pub const MERGE_POINTS_REL: f64 = 1e-12;

/// Integral-function table fills (`integrate::fast`): below this fraction of
/// the table's scalar range, `|s_b - s_f|` is too small for the difference
/// quotients `(T(s_b) - T(s_f)) / (s_b - s_f)` (they lose
/// `log10(|T| / |T_b - T_f|)` digits, math README 8.4) and the point values
/// at the midpoint scalar are used instead (error O(ds) there).
pub const INTEGRAL_FUNCTION_MIN_DS_REL: f64 = 1e-7;
