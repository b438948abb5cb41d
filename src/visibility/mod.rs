//! Exact back-to-front visibility order of drawable pieces.
//!
//! # What it produces
//! [`Sorter::order`] lists the [`Piece`]s of a mesh back to front for one
//! [`Camera`]: whole cells, the consistent tetrahedra
//! ([`crate::mesh::tetra`]) of cells that must be split, and the slabs of
//! the tets whose nodal scalar range strictly holds a transfer-function
//! breakpoint (consecutive, back to front along the gradient: [`slabs`]).
//! A piece is drawn after every piece it occludes at the image's pixel
//! centres. Cells no pixel-centre ray meets (outside the view frustum,
//! [`frustum`]) are left out; cells the renderer draws nothing of
//! ([`SplitPolicy::dark`]) are not split at breakpoints.
//!
//! # How it works
//! 1. **Per geometry** ([`Sorter::new`]): every unique face is split into its
//!    smallest-vertex triangles (`tetra::triangulate_face`) and each
//!    triangle's plane equation is stored with a floating-point error bound;
//!    each cell's orientation (sign of its volume) tells which side of a face
//!    it lies on; the boundary surface is checked for convexity (every
//!    boundary edge's dihedral angle tested with exact `orient3d`; a single
//!    closed manifold component).
//! 2. **Per view, MPVO**: the side of every face triangle's plane the eye is
//!    on (perspective: the eye position; orthographic: the sign of
//!    `n . forward`), by the float filter with exact fallback
//!    (`numeric::predicates::orient3d` / [`orient_dir`](crate::numeric::predicates::orient_dir)). An interior
//!    face whose triangles agree directs the adjacency edge between its two
//!    cells (the cell on the eye's side is drawn later). A quad whose two
//!    triangles disagree is a **problem face** (MWS section V); both its cells
//!    become **problem cells** and are split into consistent tets. A
//!    boundary quad is a problem face when its triangles disagree and the
//!    cell is concave along the diagonal (a ray can leave and re-enter it).
//!    Cells that are non-convex beyond their face diagonals (a vertex outside
//!    the plane of another face's triangle: badly distorted cells) are split
//!    in every view. The neighbour of a split cell keeps its geometry: its edges across the
//!    face are per triangle, to the tet owning that triangle.
//! 3. **Non-convex meshes** (boundary not convex): XMPVO sampled at image
//!    resolution ([`raster`]). Every boundary triangle is rasterised at the
//!    pixel-centre rays of [`Camera::pixel_ray`] (a float edge-function filter
//!    with a margin, exact [`ray_triangle`](crate::numeric::predicates::ray_triangle) inside the margin). Per
//!    pixel the boundary crossings are sorted by depth; every exit from piece
//!    `X` followed directly by an entry into piece `Y` adds the constraint "`Y`
//!    before `X`". Along every pixel ray, consecutive pieces are then related
//!    by an adjacency edge or such a constraint, which makes the order exact
//!    at image resolution.
//! 4. **Topological sort** (Kahn) back to front.
//! 5. **Cycles**: pieces Kahn cannot emit are grouped into strongly connected
//!    components (Tarjan, [`scc`]). The whole cells on cycles are split
//!    into consistent tets and everything is re-sorted (at most
//!    [`MAX_SPLIT_ROUNDS`] rounds): one depth-first search per component
//!    finds vertex-disjoint cycles and only their members are split (a
//!    large component held together by a few cycles: on the generated
//!    1M-hex grid 49k cells rather than 444k), and in the last round every
//!    whole cell of a component is. A cycle of tets that remains is cut by
//!    planes through faces of its members ([`bsp`], an auto-partition
//!    restricted to the cycle): the far side of a plane is drawn before the
//!    near side, so the fragments ([`Piece::Frag`], [`Order::fragments`])
//!    come out in an exact order (tested on interlocked tets,
//!    `generate::interlocked_tets`). A cycle the cuts cannot order (its
//!    pieces overlap in space, as in self-intersecting meshes such as a
//!    crushed can, or it is too large, [`bsp::MAX_GROUP`]) is emitted as one
//!    **group**: a range of [`Order::pieces`] listed in [`Order::groups`]
//!    (inside, by centroid depth). The order between a group and every
//!    other piece is still exact, so the renderer composites each group
//!    **per pixel** into one layer drawn at the group's place
//!    (`render::group`: every pixel-centre ray clipped against the group's
//!    pieces, segments sorted along the ray, exact segment integrals), exact
//!    at pixel centres for pieces that do not overlap; overlapping pieces,
//!    for which no order exists even along one ray, are ordered by segment
//!    midpoint. The sort always terminates.
//!
//! 6. **The values, spliced in** ([`Sorter::splice`]): steps 2 to 5 make
//!    the view's order from the geometry alone ([`Sorter::base_order`]);
//!    then each whole cell whose nodal range strictly holds a breakpoint is
//!    replaced, at its place, by its consistent tets sorted among
//!    themselves, and each tet holding breakpoints by its slabs. A cell
//!    drawn whole is convex, so a ray meets it in one interval its tets
//!    tile, and every piece before (after) it lies behind (in front of)
//!    that interval. A time step with new values, or a transfer function
//!    with new breakpoints, keeps the sort and only splices.
//!
//! Subdivisions persist between views inside the [`Sorter`] (a pool of split
//! cells); cells that stop needing a split are restored. [`Sorter::sanity_check`]
//! verifies that bookkeeping.
//!
//! # Tie rule at pixel centres
//! A pixel-centre ray through a triangle's edge or vertex (exactly, by exact
//! predicates) counts as crossing *every* triangle it touches when constraints
//! are generated (conservative: constraints for all interpretations); the
//! validator ([`validate`]) skips such rays and counts them as degenerate.
//!
//! # Validation
//! [`validate`] is a brute-force check for tests: for sampled pixel-centre
//! rays it intersects the ray exactly with every piece's triangles, orders the
//! pieces met by depth and checks that they are drawn back to front.

pub mod bsp;
pub mod frustum;
mod geometry;
mod input;
mod raster;
mod sanity;
pub mod scc;
pub mod slabs;
mod sorter;
mod split;
#[doc(hidden)]
pub mod synth;
mod validate;

use std::ops::Range;
use std::time::Duration;

pub use sorter::{NonConvex, Sorter};
pub use validate::{sample_pixels, validate, Violation, Violations};

/// Rounds of "split the whole cells on cycles, then sort again" before
/// the remaining cycles are emitted as groups (composited per pixel).
pub const MAX_SPLIT_ROUNDS: usize = 4;

/// One drawable piece.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Piece {
    /// A whole cell (quad faces are their two smallest-vertex triangles).
    Cell(u32),
    /// One consistent tetrahedron of a split cell (global point ids, in the
    /// orientation `tetra::tetrahedralize_cell` gives).
    Tet { cell: u32, tet: [u32; 4] },
    /// The part of a consistent tet (as in [`Piece::Tet`]) where
    /// `levels[lo] <= s <= levels[hi]`, `levels` being [`Order::levels`] and
    /// [`NO_LEVEL`] an open end: one slab of a tet whose nodal scalar range
    /// strictly holds transfer-function breakpoints. A tet's slabs are
    /// consecutive in the order, back to front ([`slabs`]).
    Slab {
        cell: u32,
        tet: [u32; 4],
        lo: u32,
        hi: u32,
    },
    /// A convex part of a consistent tet, cut off by planes through members
    /// of a visibility cycle ([`bsp`]): `Order::fragments[frag]` (vertices
    /// as barycentric weights of `tet`'s corners).
    Frag { cell: u32, tet: [u32; 4], frag: u32 },
}

/// An open end of a [`Piece::Slab`].
pub const NO_LEVEL: u32 = u32::MAX;

impl Piece {
    /// The cell the piece belongs to.
    pub fn cell(&self) -> u32 {
        match *self {
            Piece::Cell(c) => c,
            Piece::Tet { cell, .. } | Piece::Slab { cell, .. } | Piece::Frag { cell, .. } => cell,
        }
    }

    /// The tetrahedron of a tet or slab piece.
    pub fn tet(&self) -> Option<[u32; 4]> {
        match *self {
            Piece::Cell(_) => None,
            Piece::Tet { tet, .. } | Piece::Slab { tet, .. } | Piece::Frag { tet, .. } => Some(tet),
        }
    }
}

/// Which cells to split beyond the problem cells of the view.
#[derive(Clone, Copy, Debug, Default)]
pub struct SplitPolicy<'a> {
    /// `--split all`: every cell is drawn as its consistent tets.
    pub all: bool,
    /// Transfer-function breakpoints.
    pub breakpoints: &'a [f64],
    /// Nodal scalars; cells whose nodal range strictly contains a breakpoint
    /// are split into tets, and those tets whose range strictly contains
    /// one are listed as slabs ([`Piece::Slab`]).
    pub point_scalars: Option<&'a [f64]>,
    /// Scalar ranges nothing is drawn for (the renderer's dark pieces):
    /// a cell whose nodal range is one is not split at breakpoints. Whole
    /// or as its tets it carries the same constraints between the pieces
    /// drawn, and it is drawn by neither.
    pub dark: Option<DarkRanges<'a>>,
}

/// Which nodal ranges `[lo, hi]` are drawn by no piece ([`SplitPolicy::dark`]).
#[derive(Clone, Copy)]
pub struct DarkRanges<'a> {
    /// Whether nothing is drawn for a piece with scalars in `[lo, hi]`.
    pub test: &'a (dyn Fn(f64, f64) -> bool + Sync),
    /// Equal for two tests that answer alike: orders are reused on it
    /// (`render::order_cache`).
    pub key: u64,
}

impl std::fmt::Debug for DarkRanges<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DarkRanges")
            .field("key", &self.key)
            .finish()
    }
}

/// What one call of [`Sorter::order`] did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct OrderStats {
    /// Cells of the mesh.
    pub cells: usize,
    /// Pieces in the order.
    pub pieces: usize,
    /// Cells left out as outside the view frustum ([`frustum`]).
    pub frustum_culled: usize,
    /// Cells drawn as tets in this view (all reasons).
    pub split_cells: usize,
    /// Tets emitted (whole or as slabs).
    pub tets: usize,
    /// Tets drawn as slabs because their nodal range strictly holds
    /// breakpoints, and the slab pieces they became.
    pub sliced_tets: usize,
    pub slabs: usize,
    /// Problem faces (interior and boundary) in this view.
    pub problem_faces: usize,
    /// Cells split because of a problem face.
    pub problem_cells: usize,
    /// Cells split because their scalar range holds a breakpoint.
    pub breakpoint_cells: usize,
    /// Of those, the cells split by [`Sorter::splice`] (not in the
    /// sorter's own split cells, [`Sorter::split_count`]); 0 when the
    /// order was sorted in one step.
    pub spliced_cells: usize,
    /// Cells whose scalar range holds a breakpoint but is dark
    /// ([`SplitPolicy::dark`]): left whole.
    pub dark_unsplit: usize,
    /// Cells split because they are non-convex beyond their face diagonals
    /// (distorted cells; split in every view).
    pub nonconvex_cells: usize,
    /// Cells split by `--split all`.
    pub all_split_cells: usize,
    /// Cells split to break a cycle.
    pub cycle_split_cells: usize,
    /// Whole cells in the strongly connected components met (all rounds):
    /// what splitting every member of a component would split.
    pub cycle_component_cells: usize,
    /// Cells newly split in this view (not split in the previous one).
    pub newly_split: usize,
    /// Cells restored to whole cells (split in the previous view only).
    pub restored: usize,
    /// Nontrivial strongly connected components met (all rounds).
    pub cycles_found: usize,
    /// Of those, the ones resolved by splitting cells into tets.
    pub cycles_resolved_by_split: usize,
    /// Of those, the ones ordered by cutting their tets with planes through
    /// members ([`bsp`]), and the fragments they became.
    pub cycles_resolved_by_planes: usize,
    pub fragments: usize,
    /// Cycles left as per-pixel groups ([`Order::groups`]).
    pub cycle_groups: usize,
    /// Pieces inside those groups.
    pub pieces_in_groups: usize,
    /// Sort rounds (1 without cycles).
    pub rounds: usize,
    /// Whether the boundary is convex (no non-convex constraints needed).
    pub convex_boundary: bool,
    /// Boundary crossings found by the pixel rasteriser.
    pub boundary_crossings: usize,
    /// Distinct non-convex constraints added (last round).
    pub nonconvex_constraints: usize,
    /// Plane tests the float filter could not decide (exact fallback).
    pub exact_fallbacks: usize,
    /// Time to classify faces (plane tests, problem faces).
    pub time_classify: Duration,
    /// Time to split / restore cells and build the split-cell edges.
    pub time_split: Duration,
    /// Time for the non-convex constraints (rasterisation included).
    pub time_nonconvex: Duration,
    /// Time for the topological sorts and cycle handling.
    pub time_sort: Duration,
    /// Time to splice the values' splits into the geometry's order
    /// ([`Sorter::splice`]).
    pub time_splice: Duration,
    /// Total time of the call.
    pub time_total: Duration,
}

/// A back-to-front order for one view.
#[derive(Clone, Debug, Default)]
pub struct Order {
    /// Pieces back to front (draw in this order with "over").
    pub pieces: Vec<Piece>,
    /// The fragments of [`Piece::Frag`] pieces.
    pub fragments: Vec<bsp::Fragment>,
    /// The breakpoints the slabs are cut at (sorted, distinct, finite): the
    /// bounds of every [`Piece::Slab`].
    pub levels: Vec<f64>,
    /// Ranges of `pieces` that form unresolved visibility cycles: the pieces
    /// of one range must be composited together with per-pixel depth sorting.
    /// Every piece outside a range is correctly ordered against the range.
    pub groups: Vec<Range<usize>>,
    /// What the sort did.
    pub stats: OrderStats,
}

/// Errors of the visibility sort (bad input; the sort itself cannot fail).
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum VisibilityError {
    /// A cell references a point that does not exist.
    #[error("cell {cell} references point {point}, but the mesh has {points} points")]
    PointOutOfRange {
        cell: usize,
        point: u32,
        points: usize,
    },
    /// The topology does not belong to the mesh.
    #[error("the topology has {topo} cells but the mesh has {mesh}")]
    TopologyMismatch { topo: usize, mesh: usize },
    /// A point coordinate is NaN or infinite.
    #[error("point {0} has a non-finite coordinate")]
    NonFinitePoint(usize),
    /// The camera has a non-finite position or direction, or an empty image.
    #[error("invalid camera: {0}")]
    BadCamera(&'static str),
    /// The nodal scalars do not cover every point.
    #[error("{got} nodal scalars given for {points} points")]
    ScalarCount { got: usize, points: usize },
    /// The mesh has more pieces than 32-bit ids can address.
    #[error("too many pieces ({0}) for 32-bit ids")]
    TooManyPieces(usize),
}
