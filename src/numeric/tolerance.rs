//! Every tolerance in zoovr, in one place, each with its reason.
//!
//! Combinatorial decisions (which side of a plane, whether two projected edges
//! cross, which cell a ray enters) do not use tolerances: they go through
//! [`super::predicates`]. The values here bound *numerical* approximations
//! and classify data for reporting.

/// Relative deviation (of the face's longer diagonal) of a quad face's fourth vertex
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

/// Measured maximum absolute error of the exact mode's exponential table
/// (`gpu::exptable`, 1024^2 texels, log-warped axes, f32 bilinear filtering)
/// against the exact `1 - exp(-l tau)` over `l, tau` in `{0} + [1e-8, 1e6]`:
/// 9.5e-5 on 2000^2 log-spaced samples (5.7e-5 for l, tau in [1e-3, 1e3]),
/// rounded up for points between samples (test `exptable_error_is_bounded`). Used as the tolerance of
/// every comparison of compositor opacities with exact values.
pub const EXP_TABLE_MAX_ABS_ERROR: f64 = 1.2e-4;

/// Exact mode: a region edge is refined when (optical depth at its ends,
/// capped at 1) x (largest glow-colour difference between its ends) exceeds
/// this. Inside a region `C/alpha` is interpolated, which is exact only for
/// constant glow colour; math README 8.1 measures errors up to ~7e-3 for
/// depth <= 1 with colour spread 1. 0.02 left 0.06 on single pixels of
/// coarse tet meshes seen up close (`tetraMesh`, 128 px, oblique
/// orthographic view); 0.004 brings every pixel of the shared datasets
/// within 2/255 of the ray caster (0.01 does not), for 1.3 % more
/// triangles on the hex_shell benchmark scene but 7x the refined triangles
/// on meshes of few, large, optically thick cells (zoo_3x3x3 filling the
/// view: 31k -> 224k). A test of the interpolation error itself instead of
/// the end values would refine less.
pub const COLOR_REFINE_TOL: f64 = 0.004;

/// Exact mode: at most this many levels of midpoint refinement per region
/// triangle for colour accuracy (each level splits a triangle in up to 4).
pub const COLOR_REFINE_MAX_DEPTH: u32 = 6;
/// Integral-function table fills (`integrate::fast`): below this fraction of
/// the table's scalar range, `|s_b - s_f|` is too small for the difference
/// quotients `(T(s_b) - T(s_f)) / (s_b - s_f)` (they lose
/// `log10(|T| / |T_b - T_f|)` digits, math README 8.4) and the point values
/// at the midpoint scalar are used instead (error O(ds) there).
pub const INTEGRAL_FUNCTION_MIN_DS_REL: f64 = 1e-7;
/// Projection (perspective): pieces are clipped at `near * NEAR_CLIP_SCALE`
/// rather than at the camera's near plane itself, so every clipped point lies
/// strictly in front of the near plane and projects to a finite pixel
/// position. `near` is 1e-9 of the camera distance: the clipped sliver is far
/// below any pixel.
pub const NEAR_CLIP_SCALE: f64 = 2.0;
/// Projection (renderer, [`crate::projection::Projector::clip_to_image`]):
/// regions reaching beyond the image rectangle grown by this many pixels on
/// every side are clipped to it. Near-plane caps project to ~1e9 pixels
/// (`1 / NEAR_CLIP_SCALE` of the inverse near distance), where no bounded
/// midpoint refinement can make screen-space interpolation accurate on
/// screen; the rasteriser only samples pixel centres (`0.5 ..= W - 0.5`), so
/// any margin of at least half a pixel loses nothing. A few pixels keep the
/// window's own edges well away from every centre.
pub const IMAGE_CLIP_MARGIN_PX: f64 = 4.0;
/// Coverage culling ([`crate::projection::coverage`]): a region triangle is
/// dropped only when no pixel centre lies within this many pixels of it.
/// The GPU rasterises `f32` clip coordinates snapped to its sub-pixel grid:
/// with 8 bits of sub-pixel precision (D3D12 and Metal require it; Mesa's
/// lavapipe and llvmpipe and the desktop Vulkan/GL drivers have it) a vertex
/// moves by at most `sqrt(2) / 512 = 0.0028` px, and `f32` rounding of
/// positions adds at most ~1e-3 px up to 16384-pixel images. 1/64 px is
/// four times their sum; a device with only Vulkan's minimum of 4 bits
/// (0.044 px) could differ at centres within 0.03 px of a dropped sliver.
pub const COVERAGE_MARGIN_PX: f64 = 1.0 / 64.0;

/// Projection (perspective): region values are interpolated linearly in
/// screen space. Region edges whose interpolation error bound (screen-space
/// vs perspective-correct parameter: `|dz| / (4 min z)` per face, plus the
/// ray-length factor's curvature `|d(u, v)|^2 / 8`) exceeds this fraction of
/// the piece's scalar range (of its diameter, for the thickness `l`) are split
/// at their midpoint. 1e-3 keeps the error of the interpolated scalars and
/// thickness below ~1e-3 of the piece's range/diameter (measured: <= 1.2e-3
/// in close-up wide-angle views) while leaving ordinary views unrefined.
pub const PERSPECTIVE_INTERP_REL: f64 = 1e-3;
/// Safety factor of the floating-point filter in front of the exact
/// ray/edge predicate (`raycast::geometry`): the 2D cross product of two
/// projected vertices is trusted when it exceeds `K eps |a - o| |b - o|`
/// (scaled by the ray's origin magnitude). A first-order error analysis
/// gives about 16 (projection, subtraction, product rounding and the
/// direction's own rounding); 64 leaves a margin. Larger only means more
/// exact evaluations, never a different answer.
pub const PLUCKER_FILTER_K: f64 = 64.0;
/// A ray/triangle crossing's depth comes from barycentric weights, the
/// three edge values (`raycast::geometry`). When their sum is below this
/// factor times the sum of their certified error bounds, the weights may be
/// off by more than 1/K and the triangle is seen nearly edge-on: the depth
/// is then kept within the triangle's chord across from the ray (where the
/// exact crossing lies; on a triangle seen exactly edge-on, noise weights
/// put it anywhere on the triangle, past the cells' other faces, so the
/// walk clamped the next segments and a ray along a cube's face diagonal
/// came out 2% long). Clamping to the chord only moves the depth towards
/// the exact one, so K only trades speed (the chord costs two cross
/// products) against how far noisy weights may go before it is checked.
pub const EDGE_ON_CROSSING_K: f64 = 1048576.0;

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

/// Exact mode: an extinction node whose left and right slopes agree to this
/// relative difference is not a kink (nodes inserted where only the colour
/// changes carry slopes that differ by rounding only). Splitting there would
/// be exact too, only slower.
pub const TF_SLOPE_REL: f64 = 1e-9;

/// Projection refinement (`projection::refine`): a region triangle narrower
/// than this many pixels (twice its area over its longest edge) never asks
/// for a split itself; its edges are split only where a wider neighbour
/// asks. Faces seen exactly edge-on project, through rounded positions, to
/// slivers ~1e-14 px wide whose values are meaningless, and refining them
/// to the depth limit multiplied the triangle count (one prism -> 15k
/// triangles). Such a triangle can cover only pixel centres within this
/// distance of a line, which is below the f32 rounding of the vertex
/// positions the rasteriser receives (~1e-5 px for a 100 px image), so its
/// coverage is decided by rounding anyway; it still gets drawn, with its
/// vertices' (well-conditioned) values.
pub const SLIVER_WIDTH_PX: f64 = 1e-6;

/// Plane cuts of visibility cycles (`visibility::bsp`): a cut part whose
/// volume is below this fraction of its tet's volume is dropped. Cut points
/// are rounded to f64, so a cut through (or next to) an existing vertex can
/// leave a sliver of zero volume whose rounded corners straddle later
/// planes; such slivers hold ~1e-16 of the tet, cannot be ordered (they have
/// no interior), and are invisible at any image resolution.
pub const BSP_SLIVER_REL: f64 = 1e-12;

/// Plane cuts of visibility cycles (`visibility::bsp`): a vertex within this
/// fraction of the group's bounding-box diagonal (times the plane normal's
/// length) of a cutting plane counts as on it. Cut points carry rounding of
/// ~1e-16 of the group's size; without a band, a second plane through
/// (nearly) the same line would cut next to an earlier cut point and leave
/// near-duplicate vertices, slivers and caps whose order rounding decides.
/// Treating points 1e-10 of the size away as on the plane moves a cut by at
/// most that much: invisible at any image resolution.
pub const BSP_ON_PLANE_REL: f64 = 1e-10;

/// Brute-force ray traversal (`raycast::brute`): a segment that starts less
/// than this fraction of the bounds diagonal before the segments ahead of
/// it end is not counted as overlapping in its statistics. Two pieces that
/// meet at one point (a ray through an edge or vertex) cross it through
/// different triangles, whose depths round differently (~1e-16), so they
/// overlap by that much without overlapping in space. Only the count uses
/// this; the compositing splits every overlap exactly.
pub const BRUTE_OVERLAP_REPORT_REL: f64 = 1e-9;
