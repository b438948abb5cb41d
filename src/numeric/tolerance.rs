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

/// Safety factor of the floating-point filter in front of the exact
/// ray/edge predicate (`raycast::geometry`): the 2D cross product of two
/// projected vertices is trusted when it exceeds `K eps |a - o| |b - o|`
/// (scaled by the ray's origin magnitude). A first-order error analysis
/// gives about 16 (projection, subtraction, product rounding and the
/// direction's own rounding); 64 leaves a margin. Larger only means more
/// exact evaluations, never a different answer.
pub const PLUCKER_FILTER_K: f64 = 64.0;

/// The ray caster stops a ray when its transmittance falls below this
/// (accumulated opacity `>= 1 - 1e-6`): the rest of the ray can change each
/// premultiplied channel by at most this times the brightest glow colour,
/// far below the 1/255 of a PNG value.
pub const RAY_TERMINATION_TRANSMITTANCE: f64 = 1e-6;

/// Re-entering the mesh through the boundary after leaving it: entries up to
/// this fraction of the bounds diagonal before the exit point still count
/// (coincident but unshared faces of touching parts, whose crossing depths
/// round differently).
pub const RAY_REENTRY_SLACK_REL: f64 = 1e-12;

/// Native field model: absolute tolerance (colour and optical depth, per
/// cell segment) of the adaptive Gauss-Legendre collocation that integrates
/// the ray through the iso-parametric field.
pub const NATIVE_INTEGRAL_TOL: f64 = 1e-9;

/// Native field model: Newton inversion of the iso-parametric map stops when
/// the parametric step is below this (parametric coordinates are O(1)).
pub const NATIVE_NEWTON_TOL: f64 = 1e-13;
