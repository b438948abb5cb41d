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

/// Projection (perspective): pieces are clipped at `near * NEAR_CLIP_SCALE`
/// rather than at the camera's near plane itself, so every clipped point lies
/// strictly in front of the near plane and projects to a finite pixel
/// position. `near` is 1e-9 of the camera distance: the clipped sliver is far
/// below any pixel.
pub const NEAR_CLIP_SCALE: f64 = 2.0;

/// Projection (perspective): region values are interpolated linearly in
/// screen space. Region edges whose interpolation error bound (screen-space
/// vs perspective-correct parameter: `|dz| / (4 min z)` per face, plus the
/// ray-length factor's curvature `|d(u, v)|^2 / 8`) exceeds this fraction of
/// the piece's scalar range (of its diameter, for the thickness `l`) are split
/// at their midpoint. 1e-3 keeps the error of the interpolated scalars and
/// thickness below ~1e-3 of the piece's range/diameter (measured: <= 1.2e-3
/// in close-up wide-angle views) while leaving ordinary views unrefined.
pub const PERSPECTIVE_INTERP_REL: f64 = 1e-3;
