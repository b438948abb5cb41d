//! Every tolerance in zoovr, in one place, each with its reason.
//!
//! Combinatorial decisions (which side of a plane, whether two projected edges
//! cross, which cell a ray enters) do not use tolerances: they go through
//! [`super::predicates`]. The values here bound *numerical* approximations
//! and classify data for reporting.

/// Relative deviation (of the face's longer diagonal) of a quad face's fourth vertex
/// from the plane of the other three above which `info` counts the face as
/// nonplanar. The same threshold as the datasets' published nonplanar-face
/// counts (`mesh::quality` reproduces them).
pub const NONPLANAR_REPORT_REL: f64 = 1e-3;

/// Cells whose |signed volume| is below this fraction of (bounding box
/// diagonal of the cell)^3 are reported as degenerate (zero volume).
pub const DEGENERATE_VOLUME_REL: f64 = 1e-12;

/// Relative distance (of the bounds diagonal) under which two points are
/// merged by the optional coincident-point merge (exactly equal coordinates
/// are always merged; this allows for ASCII round-off).
pub const MERGE_POINTS_REL: f64 = 1e-12;

/// Measured maximum absolute error of the exact mode's exponential table
/// (`render::modes::exact::exptable`, 1024^2 texels, log-warped axes, f32 bilinear filtering)
/// against the exact `1 - exp(-l tau)` over `l, tau` in `{0} + [1e-8, 1e6]`:
/// 9.5e-5 on 2000^2 log-spaced samples (5.7e-5 for l, tau in [1e-3, 1e3]),
/// rounded up for points between samples (test `exptable_error_is_bounded`). Used as the tolerance of
/// every comparison of compositor opacities with exact values.
pub const EXP_TABLE_MAX_ABS_ERROR: f64 = 1.2e-4;

/// Exact mode: a region edge is refined when (a bound on the optical depth
/// along it: its ends' largest length times the transfer function's largest
/// extinction on the piece's scalar range, capped at 1) x (largest
/// glow-colour difference between its ends) exceeds this. (The depth at the
/// ends is no bound: an edge from a thick end where the field maps to
/// little extinction to a silhouette end, of no length, where it maps to
/// much is optically deep in between.) Inside a region `C/alpha` is
/// interpolated, which is exact only for constant glow colour; docs/math.md 8.1 measures errors up to ~7e-3 for
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
/// `log10(|T| / |T_b - T_f|)` digits, docs/math.md 8.4) and the point values
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
/// Frustum culling ([`crate::visibility::frustum`]): a cell is left out of
/// the order only when all its points lie beyond one side of the image's
/// view pyramid (perspective) or box (orthographic) grown by this many
/// pixels. The outermost pixel-centre rays are half a pixel inside the
/// image's edge, so the grown side is 1.5 px from every ray; the rounding
/// of a point's view coordinates (~1e-16 of its distance from the eye) is
/// far below that at any image size.
pub const FRUSTUM_MARGIN_PX: f64 = 1.0;
/// Occlusion culling ([`crate::render::occlusion`]): a piece is left out
/// when the optical depth in front of every pixel centre it may cover is
/// at least `ln(brightest colour / this)`, so what it would add changes no
/// premultiplied channel by more than this: ten times below the 1e-6 the
/// image tests allow, and below the ray caster's own
/// [`RAY_TERMINATION_TRANSMITTANCE`].
pub const OCCLUSION_TRANSMITTANCE: f64 = 1e-7;
/// Occlusion behind an opaque isosurface ([`crate::render::occlusion`]): a
/// cell hides what lies behind a pixel centre where the ray's entry and
/// exit scalars in it (the `faces` field's, on the triangles its chord
/// enters and leaves by) lie on opposite sides of an opaque surface's value
/// `V` by at least this fraction of `|V - lo| + span` (the transfer
/// function's node range `[lo, lo + span]`): ten times the `f32` stages'
/// level margin ([`ISO_LEVEL_F32`] of the normalised value), so the stages
/// draw that crossing in the cell too. Elsewhere the drawn scalars are on
/// the exact ones' side of `V`: next to the line where a face's scalar is
/// `V`, and in slivers near it, centres are decided on the exact segment
/// (whose ends are stored on the reference's side of each level); farther
/// from it the snap of a region's corners moves the scalar less than the
/// distance to the line does.
pub const OCCLUSION_ISO_REL: f64 = 1e-5;

/// How far outside a boundary triangle (in barycentric weight) the point
/// where a chord through a cell's kernel enters or leaves it may lie and
/// still be taken as on it (rounding of the plane intersection); beyond,
/// the kernel's face is not the cell's there and the centre is not
/// credited.
pub const OCCLUSION_ISO_BARY: f64 = 1e-9;

/// The least chord through a cell, relative to the mesh's diagonal, at
/// which its opaque surface hides what lies behind a pixel centre: a ray
/// through the cell for less is on its outline up to rounding, where the
/// exact tie decisions may give the centre to the pieces beside it.
pub const OCCLUSION_ISO_CHORD: f64 = 1e-9;

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

/// Parts drawn whole ([`crate::render::driver`]'s whole-part polygons): the
/// convex hull of a part's projected points is pushed outward by this many
/// pixels before its corners are snapped to the sub-pixel grid. Snapping
/// moves a corner by at most `sqrt(2) / 512 = 0.0028` px, so the drawn
/// polygon still holds every pixel centre within [`COVERAGE_MARGIN_PX`]
/// of the hull (the budget for the `f32` rounding of the fragment's own
/// inside test, as for coverage culling): 1/32 px is that margin plus
/// more than five times the snap.
pub const QUAD_HULL_MARGIN_PX: f64 = 1.0 / 32.0;

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

/// Camera: the near plane lies at this fraction of the eye's distance from
/// the focal point. Rays start at the eye, so the near plane only keeps
/// projected points finite; a slab this thin in front of the eye holds no
/// geometry visible at any image resolution.
pub const CAMERA_NEAR_REL: f64 = 1e-9;

/// Camera: when the view-up vector's component orthogonal to the view
/// direction has a squared length below this (length below 1e-12 for a unit
/// view-up), view-up is taken as parallel to the view direction and the
/// previous right axis defines the new view-up instead (normalising such a
/// remainder would amplify rounding into an arbitrary direction).
pub const CAMERA_UP_PARALLEL_SQ: f64 = 1e-24;

/// `(1 - exp(-x)) / x` (`integrate::fast`): below this `x` the two-term
/// series `1 - x / 2` is used. Its first omitted term, `x^2 / 6`, is then
/// below 2e-21, far under the rounding of 1, while `exp_m1(-x) / x` would
/// still be accurate but needlessly slow near 0 (and undefined at 0).
pub const ONE_MINUS_EXP_SERIES_X: f64 = 1e-10;

/// Power series of the segment weights (`integrate::weights`): summation
/// stops when the newest term is below this fraction of the partial sum (of
/// 1, the leading term, for the asymptotic series). 1e-18 is below half an
/// ulp of the sum, so further terms cannot change the rounded result.
pub const SERIES_TRUNCATION_REL: f64 = 1e-18;

/// Power series of the segment weights: floor of `|partial sum|` in the
/// relative stopping test of a series whose sum may be exactly zero, so the
/// test compares against a positive number instead of requiring a zero term.
pub const SERIES_SUM_FLOOR: f64 = 1e-300;

/// Below this optical depth `C / alpha` is replaced by its `l -> 0` limit
/// (`integrate::segment`): both are equal to ~1e-16 relative there, and the
/// quotient of two subnormal numbers would lose precision.
pub const GLOW_LIMIT_DEPTH: f64 = 1e-200;

/// Native field model: parametric tolerance of "inside the reference
/// element" and of "inside a face" for ray / face roots. Roots of the two
/// faces meeting at an edge carry rounding of ~1e-15 in parametric units;
/// accepting 1e-9 beyond `[0, 1]` lets both faces find a root at the edge
/// (a duplicate then gives an empty interval) instead of neither.
pub const NATIVE_PARAM_TOL: f64 = 1e-9;

/// Native field model: Newton's method for the Gauss-Legendre nodes stops
/// when its step is below this; nodes lie in `[-1, 1]`, so this is below an
/// ulp of every node and the iteration has converged to rounding.
pub const GAUSS_LEGENDRE_NODE_TOL: f64 = 1e-16;

/// Native field model: a Newton inversion of the iso-parametric map that
/// stops at its iteration limit (or with a step below
/// [`NATIVE_NEWTON_TOL`]) is accepted only when its last parametric step is
/// below this. A larger last step means the iteration did not converge
/// (point outside a curved cell's valid map, nearly singular Jacobian); the
/// evaluation then counts as failed.
pub const NATIVE_NEWTON_ACCEPT: f64 = 1e-8;

/// Native field model: a Newton iterate with a parametric coordinate beyond
/// this magnitude has diverged (the reference element is `[0, 1]^3`) and the
/// inversion is abandoned before it overflows.
pub const NATIVE_NEWTON_DIVERGED: f64 = 1e3;

/// Native field model, monotone-piece search: the slope of the cubic Hermite
/// interpolant, `c0 + c1 x + c2 x^2`, is treated as linear when `|c2|` is
/// below this fraction of `|c0| + |c1|` (its quadratic term is rounding
/// noise of the end slopes, and dividing by it would invent critical points).
pub const HERMITE_QUADRATIC_REL: f64 = 1e-14;

/// Native field model, monotone-piece search: an interval is accepted as
/// cubic when its Hermite interpolant predicts `s` and `s'` at the midpoint
/// to this fraction of the interval's range of `s` (of its slopes, for `s'`).
/// The stated accuracy assumption of the breakpoint search (see
/// `raycast::native`): tight enough that a cubic that matches this well
/// hides no pair of extrema, loose enough that smooth cells split rarely.
pub const NATIVE_HERMITE_REL: f64 = 1e-3;

/// Native field model, monotone-piece search: absolute part of the midpoint
/// test, relative to `1 + max |s|` at the interval ends, so an interval on
/// which `s` is constant up to rounding is accepted instead of halved to the
/// depth limit.
pub const NATIVE_HERMITE_ABS: f64 = 1e-12;

/// Ray / bilinear patch (`raycast::native`): the patch's quadratic in `u` is
/// solved as linear when its leading coefficient is below this fraction of
/// the largest coefficient (a planar or nearly planar patch, where the
/// second root would be a huge rounding artefact).
pub const BILINEAR_LINEAR_REL: f64 = 1e-13;

/// Ray / bilinear patch: a discriminant negative by less than this fraction
/// of `b^2` is rounding of a double root (a ray grazing the patch) and is
/// taken as zero.
pub const BILINEAR_DISC_REL: f64 = 1e-12;

/// Ray / bilinear patch: roots `(u, v)` up to this far outside `[0, 1]` are
/// kept as candidates for the Newton polish on the 3D system, which moves
/// them by up to the quadratic's rounding; only after the polish is the
/// root tested against [`NATIVE_PARAM_TOL`].
pub const BILINEAR_ROOT_WINDOW: f64 = 1e-3;

/// Perspective refinement (`projection::project`): a piece whose scalar
/// range is below this fraction of its largest `|scalar|` has constant
/// scalars up to rounding (cell data), hence no scalar interpolation error:
/// its rounding noise must not drive the refinement.
pub const CONSTANT_SCALAR_REL: f64 = 1e-12;

/// Arrangement check (`projection::arrangement`): the bounded regions'
/// areas must sum to the outer boundary's area to this fraction of it.
/// Crossing points are rounded to f64, so areas carry relative rounding of
/// ~1e-15 per region; a real gap or overlap is a whole region.
pub const ARRANGEMENT_AREA_REL: f64 = 1e-9;

/// Arrangement (`projection::arrangement`): a face cycle of negative area
/// counts as an outer boundary (of a second component) only when its area
/// exceeds this fraction of the largest outer area. Sliver regions whose
/// rounded crossing points make their area zero or slightly negative stay
/// bounded faces.
pub const OUTER_CYCLE_AREA_REL: f64 = 1e-9;

/// ParaView colour maps (`tf::paraview`): midpoints of opacity nodes are
/// clamped to `[this, 1 - this]`, as `vtkPiecewiseFunction` does, so the
/// midpoint/sharpness curve never divides by zero.
pub const PARAVIEW_MIDPOINT_CLAMP: f64 = 1e-5;

/// Visibility geometry (`visibility::geometry`): per-face float error
/// bounds are stored as f32 rounded up; when the cast rounds down the value
/// is raised by this relative amount (over 8 f32 ulps, 1.19e-7 each), so
/// the stored bound is never below the f64 one.
pub const F32_ROUND_UP_REL: f32 = 1e-6;

/// Floating-point filters of the exact predicates: below this bound the
/// filter's error estimate could itself be a rounded subnormal, so the
/// exact predicate decides instead.
pub const FILTER_UNDERFLOW_BOUND: f64 = 1e-250;

/// Error bound factor of the float filter in front of the exact
/// `((b - a) x (c - a)) . d` sign: the float value is trusted when it
/// exceeds this times the determinant's permanent. Shewchuk's orient3d bound
/// is 7.000001 eps times the permanent; 16 eps leaves ample room. Not a
/// tolerance on the answer: only a larger number of exact evaluations.
pub const ORIENT_DIR_FILTER_EPS: f64 = 16.0 * f64::EPSILON;

/// Bounding-volume hierarchies of the ray caster (the walk's boundary
/// triangles, the brute force's cells): every box is grown by this fraction
/// of the scene's size (bounding radius plus the largest coordinate of its
/// centre). A ray that grazes a box edge within rounding must still test
/// what is inside; whether it crosses is then decided exactly, so the
/// padding only costs a few extra tests, never a different answer.
pub const BVH_PAD_REL: f64 = 1e-9;

/// Ray tie basis (`raycast::geometry::tie_basis`): when the image's right
/// direction, with its component along the ray removed, has a squared
/// length below this (unit vectors: the right vector is within ~1e-6 rad of
/// the ray), it no longer defines a direction on the image and the basis is
/// taken from the ray's direction alone.
pub const TIE_BASIS_DEGENERATE_SQ: f64 = 1e-12;

/// Visibility rasterisation (`visibility::raster`): projected coordinates
/// of magnitude above this (pixels) are not trusted by the float
/// edge-function filter (points near the eye plane in perspective, whose
/// coordinates carry errors of many pixels); such triangles go to the
/// exact ray/triangle test at every pixel centre.
pub const RASTER_FILTER_MAX_COORD_PX: f64 = 1e7;

/// Culling of zero-extinction pieces (`render::pieces`): the transfer
/// function's left limit at a breakpoint `b` is taken at
/// `b - max(|b|, LEFT_LIMIT_FLOOR) * LEFT_LIMIT_REL`, a few ulps below `b`
/// (so inside the piece left of it, whose extinction may be positive while
/// the value at `b` is zero), and never at `b` itself when `b` is 0.
pub const LEFT_LIMIT_REL: f64 = 1e-15;
/// See [`LEFT_LIMIT_REL`].
pub const LEFT_LIMIT_FLOOR: f64 = 1e-300;

/// Segment integrals (`integrate::weights`): segments whose larger optical
/// depth `max(a, b)` is at most this use 12-point Gauss-Legendre over the
/// positive integrands, accurate to ~5e-16 up to this depth with no
/// cancellation at any depth down to subnormals (docs/math.md section 4.2);
/// deeper segments use the closed forms.
pub const GAUSS_LEGENDRE_MAX_DEPTH: f64 = 2.0;
/// Segment integrals: at or below this `max(a, b)` 8 Gauss-Legendre nodes
/// suffice: their error against 12 nodes is 1e-14 at depth 1 but falls like
/// `max(a, b)^16`, to rounding level (< 1e-15, tested) at 1/2; two thirds
/// of the cost of 12 nodes.
pub const GAUSS_LEGENDRE_8_MAX_DEPTH: f64 = 0.5;

/// Pre-integrated table modes: the longest tabulated length is the largest
/// cell diameter (which bounds every segment through a piece) grown by this
/// fraction, so that a segment of exactly that length, rounded to `f32` and
/// rebuilt per fragment, still falls inside the table instead of being cut
/// into two steps.
pub const TABLE_LENGTH_MARGIN: f64 = 1e-3;

/// A least-squares gradient fit ([`crate::render::gradients::fit_gradient`])
/// whose normal-equation determinant is below this times the cube of the
/// largest squared distance from the centroid comes from a flat (coplanar)
/// set of points: the gradient across it is undefined and taken as zero
/// (the determinant grows as the squared volume spanned: this flags pieces
/// thinner than about 1e-6 of their size).
pub const GRADIENT_FLAT_REL: f64 = 1e-12;

/// Isosurface level, `f64` (the reference, cycle groups, the exact mode's
/// slices): a scalar reaches the isovalue `V` when it is at least
/// `V - max(ISO_LEVEL_F64 * span, ISO_LEVEL_ULPS * eps * |V|)` (`span` the
/// transfer function's node range, `eps` the `f64` machine epsilon). A
/// surface through vertices with the value `V` (integer data, fields built
/// from levels) is then one surface: barycentric interpolation of equal
/// values rounds to a few ulps either side of `V`, and without the margin
/// the segments on both sides of such a face would both or neither cross
/// it. The margin is relative to the span, not to `|V|`: a field spanning
/// 1e-12 around 1 would otherwise lie wholly within it, and no segment
/// would cross any of its values.
pub const ISO_LEVEL_F64: f64 = 1e-12;

/// The `|V|`-relative floor of the `f64` isosurface level's margin, in
/// ulps of `V` (see [`ISO_LEVEL_F64`]): the rounding of a barycentric
/// interpolation of equal values, with room.
pub const ISO_LEVEL_ULPS: f64 = 4.0;

/// The same margin for the GPU stages and their twins, relative to the
/// normalised isovalue `|V|` (`f32`, about 16 ulps; normalised from the
/// middle of the isovalues where the stage allows,
/// `render::modes::segment::ScalarMap::centred`): the fragment's
/// `s = (s q) / q` is interpolated in `f32`, and where the corners all hold
/// `V` (the case the margin is for) it rounds to within a few ulps of `V`.
/// Relative to `V`, not to the normalised range: a margin of 1e-6 of the
/// range hid the dips of a nearly uniform field (bluntfin's free stream,
/// within 2e-7 of the range of a surface at 0.9999) from the stages.
pub const ISO_LEVEL_F32: f64 = 1e-6;

/// How far (in `f32` ulps of the level, with a floor of
/// [`ISO_DECIDE_FLOOR`]) a vertex's end scalar is put from a GPU level
/// when its `f32` value falls on the other side of that level than the
/// exact `f64` value falls of the reference's
/// (`render::modes::iso::decided_end`): the stage reads `(s q) / q`
/// interpolated from equal corners (a tie triangle), within a few ulps of the
/// stored quotient.
pub const ISO_DECIDE_ULPS: f64 = 16.0;

/// The absolute floor of [`ISO_DECIDE_ULPS`]' distance (normalised
/// scalar), for a level at or near 0, where ulps are denormal (flushed to
/// zero on GPUs).
pub const ISO_DECIDE_FLOOR: f64 = 1e-20;

/// How close (relative to the scalar) a sliver's interpolated entry or exit
/// scalar at a pixel centre must come to an isovalue, beyond the snap's
/// shift of it, for the centre to be decided on the exact geometry
/// (`render::ties::scan_triangles`): ten times [`ISO_LEVEL_F32`], above
/// the `f32` rounding of the stages' scalars.
pub const ISO_SLIVER_REL: f64 = 1e-5;

/// Relative rounding of the fragment's `f32` geometry: the shear and the
/// edge functions are a handful of operations on coordinates of magnitude
/// `|p|`, each within half an ulp (2^-24) of it; 2^-20 covers 16 of them.
pub const QUAD_F32_REL: f64 = 1.0 / 1048576.0;

/// The optical depth (or emitted colour) the `f32` geometry of a whole
/// piece may shift a segment by: the region path's sliver tolerance
/// ([`crate::render::ties::SLIVER_DEPTH_TOL`], a quarter of an 8-bit level),
/// for the same guarantee on both paths of exact-frag
/// ([`crate::render::modes::piece_quad`]).
pub const QUAD_DEPTH_TOL: f64 = 1e-3;

/// The least cosine between a whole piece's faces and the ray: a face
/// nearer edge-on leaves the barycentric weights ill-conditioned (its
/// sheared triangle is a sliver), whatever the rates; the region path and
/// its exact decisions take such pieces.
pub const QUAD_MIN_COS: f64 = 1e-3;

/// Occlusion culling over the min/max tree (`render::occlusion`): a node's
/// screen box, from the projections of its world box's corners, is grown
/// by this many pixels beyond a piece's margin, so that it holds the box
/// of every piece of its cells although its corners are not mesh points
/// and round differently (the rounding of a projection is ~1e-16 of the
/// coordinates; a millionth of a pixel is far above it at any image
/// size).
pub const OCCLUSION_NODE_MARGIN_PX: f64 = 1e-6;

/// How far from a part's outline (pixels) a centre whose side the tie
/// decisions could change may lie, for their thin-outline test
/// (`render::ties::thin_outline`): the band the decisions search
/// ([`crate::render::ties::TIE_BAND_PX`]), plus the snap (the GPU's value
/// at a centre its snapped triangle covers is the exact triangle's at a
/// point up to [`crate::render::ties::SNAP_PX`] away), doubled for the
/// exact thickness's departure from the interpolated one in perspective
/// (the refinement bounds it to a small part of the change along an edge;
/// the unit test checks the ray caster's thickness near the outline
/// against the bound).
pub const THIN_OUTLINE_PX: f64 =
    2.0 * (crate::render::ties::TIE_BAND_PX + crate::render::ties::SNAP_PX);

/// Boundary triangles narrower than this on screen (pixels: twice the area
/// over the longest edge) have the smooth gradients of the region vertices
/// on them interpolated in view space (`render::modes::iso::face_gradient`)
/// rather than from the vertices' pixel positions
/// (`render::modes::iso::face_gradient_at`): the screen weights of a face
/// seen nearly edge-on are moved by the rounding of the positions (by
/// about the rounding over this width: 1e-13 of the gradients' change
/// across the face, far below the `f32` stage's).
pub const GRADIENT_FACE_WIDTH_PX: f64 = 1e-3;
