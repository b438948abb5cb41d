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

/// Error bound factor (times `f64::EPSILON`) of the visibility sort's float
/// filter for plane-side tests: `|n . eye - d|` is trusted when it exceeds
/// `PLANE_FILTER_EPS * m * (|eye|_inf + |a|_inf)` (`m` bounds `|n|`), else the
/// exact predicate decides. Not a tolerance on the answer: a generous bound on
/// the rounding of a 3x3 determinant, so the filter never changes a sign.
pub const PLANE_FILTER_EPS: f64 = 256.0 * f64::EPSILON;

/// Margin in pixels of the non-convex rasteriser's float edge functions: a
/// pixel centre farther than this from every edge line of a projected
/// triangle is classified in floating point (projection rounding is about
/// 1e-12 pixel); closer ones go to the exact ray-triangle test.
pub const RASTER_FILTER_PX: f64 = 1e-6;

/// Relative depth (of the ray parameter) by which two consecutive pieces'
/// segments along a validation ray must overlap before the validator calls
/// them intersecting pieces (inverted cells) rather than neighbours whose
/// shared face depth differs by rounding (~1e-16 relative).
pub const VALIDATE_OVERLAP_REL: f64 = 1e-9;
