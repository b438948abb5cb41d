//! From the visibility order's pieces to view-space polyhedra: the one place
//! that turns a [`Piece`] into what a mode projects or a cycle group clips.
//!
//! A [`PieceSource`] holds what a view needs for that (mesh, scalars, TF,
//! camera, the order's slab levels and fragments). Per piece:
//! - [`PieceSource::polyhedron`]: the whole piece (a slab: its tet clipped
//!   to its band; a fragment of a plane cut: its tetrahedra-free polyhedron),
//!   used by cycle groups, which integrate breakpoints exactly along rays;
//! - [`PieceSource::parts`]: the parts a projected-cell mode draws, in
//!   back-to-front order: the piece itself, or for a fragment holding
//!   breakpoints its slabs (back to front along the tet's gradient,
//!   [`tet_slabs`], the slab expansion the order uses too). Pieces whose scalar range maps to zero extinction
//!   everywhere are left out ([`PieceSource::invisible`]): they neither emit
//!   nor absorb in the glow model; so are tets, slabs and fragments with a
//!   missing (NaN) scalar at a corner, empty as the reference's segments
//!   with a NaN end are (a field holds no infinities: they are missing
//!   values too, `crate::field::ScalarField::new`). A whole cell with
//!   NaN corners keeps the rays between two of its boundary triangles
//!   without one: its NaN points become the part's holes
//!   ([`Polyhedron::holes`], finite stand-ins in their place), whose
//!   triangles the driver leaves out. The tet of consecutive slabs is built
//!   once ([`PartScratch`]).

use super::ties::TieRays;
use glam::DVec3;

use crate::camera::Camera;
use crate::integrate::segment;
use crate::integrate::{Material, RayMaterial, SegmentValue};
use crate::mesh::Mesh;
use crate::numeric::tolerance::{LEFT_LIMIT_FLOOR, LEFT_LIMIT_REL};
use crate::projection::coverage::PixelGrid;
use crate::projection::{ClipValue, Clipper, Polyhedron, ProjectionError};
use crate::tf::TransferFunction;
use crate::visibility::bsp::Fragment;
use crate::visibility::slabs::{band_values, tet_slabs, SlabScratch};
use crate::visibility::Piece;

use super::iso::IsoSet;
use super::scene::ScalarsRef;

/// A piece that cannot be made into a polyhedron.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PieceError {
    #[error("cell {cell}: {source}")]
    Projection {
        cell: u32,
        #[source]
        source: ProjectionError,
    },
    #[error("cell {cell}: the order has no fragment {fragment}")]
    NoFragment { cell: u32, fragment: u32 },
}

/// The smallest and largest of `values` (`(inf, -inf)` when empty).
pub fn value_range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// Marks the points of `poly` whose scalar is NaN as its holes
/// ([`Polyhedron::holes`]), with another point's scalar and a zero
/// gradient as their stand-ins (finite, so that projection and
/// payload run; the driver draws no region whose front or back triangle
/// holds a hole). False where no scalar is a number: nothing to draw.
fn mark_holes(poly: &mut Polyhedron) -> bool {
    poly.holes.clear();
    let mut stand_in = None;
    for (i, s) in poly.scalars.iter().enumerate() {
        if s.is_nan() {
            poly.holes.push(i as u32);
        } else {
            stand_in = stand_in.or(Some(*s));
        }
    }
    if poly.holes.is_empty() {
        return true;
    }
    let Some(stand_in) = stand_in else {
        return false;
    };
    for &h in &poly.holes {
        poly.scalars[h as usize] = stand_in;
        if let Some(g) = poly.gradients.get_mut(h as usize) {
            *g = DVec3::ZERO;
        }
    }
    true
}

/// What a view needs to turn pieces into polyhedra; see the module docs.
pub struct PieceSource<'a> {
    /// The cells drawn: the geometry's, or its visible subset
    /// ([`super::visible`]), over the same points.
    pub mesh: &'a Mesh,
    /// The geometry's whole mesh: scene-wide lengths (the pre-integrated
    /// tables' length range) come from it, so that they do not depend on
    /// which cells are sorted.
    pub whole: &'a Mesh,
    pub scalars: ScalarsRef<'a>,
    /// Min and max of every scalar of the field (the whole field's, also
    /// for a visible subset), `None` where some value is not finite
    /// ([`super::Scene::field_span`]).
    pub field_span: Option<(f64, f64)>,
    pub tf: &'a TransferFunction,
    pub camera: &'a Camera,
    /// TF values where extinction kinks or jumps, or colour jumps
    /// ([`super::breakpoints::split_points`]).
    pub breakpoints: &'a [f64],
    /// The order's slab bounds ([`crate::visibility::Order::levels`]).
    pub levels: &'a [f64],
    /// The order's fragments ([`crate::visibility::Order::fragments`]).
    pub fragments: &'a [Fragment],
    /// The frame's length unit (the scene's unit distance, in `f32`).
    pub length_unit: f64,
    /// Leave out triangles that colour no pixel centre of `grid`
    /// ([`crate::projection::coverage`]).
    pub cull: bool,
    /// Leave out pieces that draw nothing ([`PieceSource::invisible`]; on
    /// by default, off only to measure what it saves).
    pub skip_invisible: bool,
    pub grid: PixelGrid,
    /// The frame's pixel rays for the exact decisions next to outlines
    /// ([`super::ties`]).
    pub ties: TieRays,
    /// Whether the modes that decide ties do ([`super::ProjectedOptions::exact_ties`]).
    pub exact_ties: bool,
    /// Whether the frame composites colour (not a counting draw), so the
    /// tie decisions may leave an optically thin part's outline to the
    /// rasteriser ([`super::ties::PartTriangles::weighed`]).
    pub colour_draw: bool,
    /// The isosurfaces drawn ([`super::iso`]): a piece whose scalar range
    /// holds one is drawn even where the volume is dark; cycle groups
    /// composite them.
    pub iso: Option<&'a IsoSet>,
    /// Whether the volume is drawn (false for `--mode iso`: only pieces
    /// holding a surface are).
    pub volume: bool,
    /// World-space gradient per point for smooth isosurface shading: the
    /// parts get [`Polyhedron::gradients`] in view space.
    pub gradients: Option<&'a [DVec3]>,
}

/// Scratch of [`PieceSource::parts`], reused from piece to piece.
#[derive(Default)]
pub struct PartScratch {
    poly: Polyhedron,
    whole: Polyhedron,
    /// The (cell, tet) `whole` holds for slab pieces (fragments reuse
    /// `whole` and reset this).
    whole_of: Option<(u32, [u32; 4])>,
    clipper: Clipper,
    slabs: SlabScratch,
}

/// What [`PieceSource::parts`] did with a piece.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Parts {
    /// Left out: zero extinction over its scalar range, or a non-finite
    /// scalar at a node (drawn empty, as the reference's segments with a
    /// NaN end are).
    pub invisible: bool,
    /// Slab pieces drawn.
    pub slabs: usize,
}

impl PieceSource<'_> {
    /// The scalar of `point` in `cell`.
    #[inline]
    pub fn scalar(&self, cell: u32, point: u32) -> f64 {
        match self.scalars {
            ScalarsRef::Point(v) => v.get(point as usize).copied().unwrap_or(0.0),
            ScalarsRef::Cell(v) => v.get(cell as usize).copied().unwrap_or(0.0),
            ScalarsRef::Constant(c) => c,
        }
    }

    fn projection(cell: u32) -> impl Fn(ProjectionError) -> PieceError {
        move |source| PieceError::Projection { cell, source }
    }

    /// The view-space polyhedron of a piece (whole, not sliced into its
    /// bands); an empty one when a slab has no volume.
    pub fn polyhedron(&self, piece: &Piece, poly: &mut Polyhedron) -> Result<(), PieceError> {
        let cell = piece.cell();
        match *piece {
            Piece::Cell(c) => self.cell(c, poly),
            Piece::Tet { tet, .. } => {
                let (p, s) = self.tet_view(cell, tet);
                poly.set_tet(p, s);
                poly.world.extend_from_slice(&self.tet_world(tet));
                Ok(())
            }
            Piece::Slab { tet, lo, hi, .. } => {
                let mut whole = Polyhedron::default();
                let mut clipper = Clipper::default();
                let (p, s) = self.tet_view(cell, tet);
                whole.set_tet(p, s);
                whole.world.extend_from_slice(&self.tet_world(tet));
                if !self.clip_band(cell, lo, hi, &mut clipper, &whole, poly)? {
                    poly.clear();
                }
                Ok(())
            }
            Piece::Frag { tet, frag, .. } => self.fragment(cell, tet, frag, poly),
        }
    }

    /// Calls `draw` with each part of `piece` a projected-cell mode draws,
    /// back to front (see the module docs).
    pub fn parts(
        &self,
        piece: &Piece,
        scratch: &mut PartScratch,
        mut draw: impl FnMut(&Polyhedron) -> Result<(), PieceError>,
    ) -> Result<Parts, PieceError> {
        let cell = piece.cell();
        let mut done = Parts::default();
        // A tet with a missing (NaN) scalar at a corner is drawn empty.
        // The reference integrates a segment with a NaN end as nothing
        // (`integrate::segment`), and every ray through a tet with a NaN
        // corner enters or leaves it through a face holding that corner,
        // so such a tet is empty to the `tets` field exactly. The `faces`
        // field of a whole cell keeps the rays between two faces without
        // it: a whole cell with NaN corners is drawn with them as holes
        // ([`Polyhedron::holes`]). A field holds no infinities (they are
        // missing values too: `ScalarField::new`; README, "Bad values").
        // (Only looked at where the field has such a value: its span.)
        let finite = |n: &u32| self.scalar(cell, *n).is_finite();
        let all_finite = self.field_span.is_some()
            || match *piece {
                Piece::Cell(_) => true,
                Piece::Tet { tet, .. } | Piece::Slab { tet, .. } | Piece::Frag { tet, .. } => {
                    tet.iter().all(finite)
                }
            };
        if !all_finite {
            done.invisible = true;
            return Ok(done);
        }
        let PartScratch {
            poly,
            whole,
            whole_of,
            clipper,
            slabs,
        } = scratch;
        match *piece {
            Piece::Cell(c) => {
                let nodes = self.mesh.cells.nodes(c as usize);
                let (lo, hi) = value_range(nodes.iter().map(|&n| self.scalar(c, n)));
                if self.invisible(lo, hi) {
                    done.invisible = true;
                    return Ok(done);
                }
                self.cell(c, poly)?;
                self.point_gradients(nodes.iter().copied(), poly);
                if self.field_span.is_none() && !mark_holes(poly) {
                    done.invisible = true;
                    return Ok(done);
                }
                draw(poly)?;
            }
            Piece::Tet { tet, .. } => {
                let (p, s) = self.tet_view(cell, tet);
                let (lo, hi) = value_range(s);
                if self.invisible(lo, hi) {
                    done.invisible = true;
                    return Ok(done);
                }
                // A tet holding a breakpoint comes as its slabs
                // (`Piece::Slab`): the TF is linear on this one.
                poly.set_tet(p, s);
                poly.world.extend_from_slice(&self.tet_world(tet));
                self.point_gradients(tet.into_iter(), poly);
                draw(poly)?;
            }
            Piece::Frag { tet, frag, .. } => {
                *whole_of = None;
                self.fragment(cell, tet, frag, whole)?;
                if let (Some(g), Some(f)) = (self.gradients, self.fragments.get(frag as usize)) {
                    let corner = tet.map(|n| self.view_gradient(g, n));
                    whole.gradients = f.positions(&corner);
                }
                let (lo, hi) = value_range(whole.scalars.iter().copied());
                if self.invisible(lo, hi) {
                    done.invisible = true;
                    return Ok(done);
                }
                // Breakpoints inside: the fragment's slabs, back to front
                // along the tet's gradient (the one slab expansion).
                let (p, s) = self.tet_view(cell, tet);
                let order = tet_slabs(
                    &whole.scalars,
                    &s,
                    || p,
                    self.levels,
                    self.camera.ortho,
                    slabs,
                );
                if order.is_empty() {
                    draw(whole)?;
                }
                for &(lo, hi) in order {
                    let (blo, bhi) = band_values(self.levels, lo, hi);
                    if clipper
                        .clip(whole, ClipValue::Scalar, blo, bhi, poly)
                        .map_err(Self::projection(cell))?
                    {
                        draw(poly)?;
                    }
                }
            }
            Piece::Slab { tet, lo, hi, .. } => {
                let (blo, bhi) = self.band(lo, hi);
                let (smin, smax) = value_range(tet.map(|n| self.scalar(cell, n)));
                if self.invisible(smin.max(blo), smax.min(bhi)) {
                    done.invisible = true;
                    return Ok(done);
                }
                // The slabs of a tet come one after another: its view-space
                // piece is built once for them all.
                if *whole_of != Some((cell, tet)) {
                    let (p, s) = self.tet_view(cell, tet);
                    whole.set_tet(p, s);
                    whole.world.extend_from_slice(&self.tet_world(tet));
                    // The slab's cut points get them by interpolation
                    // (smooth isosurface light on the slices).
                    self.point_gradients(tet.into_iter(), whole);
                    *whole_of = Some((cell, tet));
                }
                if self.clip_band(cell, lo, hi, clipper, whole, poly)? {
                    done.slabs += 1;
                    draw(poly)?;
                }
            }
        }
        Ok(done)
    }

    /// Fills `poly.gradients` of [`Self::polyhedron`]'s `piece` (not of a
    /// slab, whose clipped points have none), when the source has
    /// gradients.
    pub fn piece_gradients(&self, piece: &Piece, poly: &mut Polyhedron) {
        let Some(g) = self.gradients else {
            return;
        };
        match *piece {
            Piece::Cell(c) => {
                self.point_gradients(self.mesh.cells.nodes(c as usize).iter().copied(), poly)
            }
            Piece::Tet { tet, .. } => self.point_gradients(tet.into_iter(), poly),
            Piece::Frag { tet, frag, .. } => {
                if let Some(f) = self.fragments.get(frag as usize) {
                    let corner = tet.map(|n| self.view_gradient(g, n));
                    poly.gradients = f.positions(&corner);
                }
            }
            Piece::Slab { .. } => {}
        }
    }

    /// Fills `poly.gradients` (view space) from the points `ids` of its
    /// points, in order, when the source has gradients.
    fn point_gradients(&self, ids: impl Iterator<Item = u32>, poly: &mut Polyhedron) {
        if let Some(g) = self.gradients {
            poly.gradients.clear();
            poly.gradients.extend(ids.map(|n| self.view_gradient(g, n)));
        }
    }

    /// The view-space gradient of point `n`.
    #[inline]
    fn view_gradient(&self, g: &[DVec3], n: u32) -> DVec3 {
        let c = self.camera;
        super::gradients::to_view(
            g.get(n as usize).copied().unwrap_or(DVec3::ZERO),
            c.right,
            c.up,
            c.forward,
        )
    }

    /// The view-space polyhedron of whole cell `c`.
    fn cell(&self, c: u32, poly: &mut Polyhedron) -> Result<(), PieceError> {
        poly.set_cell(
            &self.mesh.cells,
            c as usize,
            &self.mesh.points,
            |n| self.scalar(c, n),
            self.camera,
        )
        .map_err(Self::projection(c))
    }

    /// Clips `whole` (the view-space tet of `cell`) to band `lo..hi` of
    /// the order's levels; `Ok(false)` when nothing of positive volume is
    /// left.
    fn clip_band(
        &self,
        cell: u32,
        lo: u32,
        hi: u32,
        clipper: &mut Clipper,
        whole: &Polyhedron,
        poly: &mut Polyhedron,
    ) -> Result<bool, PieceError> {
        let (lo, hi) = self.band(lo, hi);
        clipper
            .clip(whole, ClipValue::Scalar, lo, hi, poly)
            .map_err(Self::projection(cell))
    }

    /// The view-space polyhedron of fragment `frag` of a tet.
    fn fragment(
        &self,
        cell: u32,
        tet: [u32; 4],
        frag: u32,
        poly: &mut Polyhedron,
    ) -> Result<(), PieceError> {
        let f = self
            .fragments
            .get(frag as usize)
            .ok_or(PieceError::NoFragment {
                cell,
                fragment: frag,
            })?;
        let (p, s) = self.tet_view(cell, tet);
        poly.clear();
        poly.points = f.positions(&p);
        poly.world = f.positions(&self.tet_world(tet));
        poly.scalars = f.values(&s);
        poly.triangles.extend_from_slice(&f.triangles);
        poly.orient_outward();
        Ok(())
    }

    /// World-space corners of a tet ([`Polyhedron::world`]).
    fn tet_world(&self, tet: [u32; 4]) -> [DVec3; 4] {
        tet.map(|n| self.mesh.points[n as usize])
    }

    /// View-space corners and scalars of a tet of cell `cell`.
    fn tet_view(&self, cell: u32, tet: [u32; 4]) -> ([DVec3; 4], [f64; 4]) {
        let pts = &self.mesh.points;
        (
            tet.map(|n| self.camera.to_view(pts[n as usize])),
            tet.map(|n| self.scalar(cell, n)),
        )
    }

    /// The scalar bounds of a slab ([`Piece::Slab`]).
    fn band(&self, lo: u32, hi: u32) -> (f64, f64) {
        band_values(self.levels, lo, hi)
    }

    /// The segment of length `l` from `s_f` to `s_b` of a piece: its volume
    /// (when drawn) split at the isosurfaces it crosses, whose gradients at
    /// its two ends `grads` gives (view space, called only for a segment
    /// that crosses one).
    pub fn segment_value(
        &self,
        l: f64,
        s_f: f64,
        s_b: f64,
        grads: impl FnOnce() -> [DVec3; 2],
    ) -> SegmentValue {
        let volume = |l: f64, a: f64, b: f64| {
            if self.volume {
                segment(self.tf, l, a, b)
            } else {
                SegmentValue::default()
            }
        };
        match self.iso {
            Some(set) if !set.crossed(s_f, s_b).is_empty() => {
                set.composite(l, s_f, s_b, grads(), DVec3::Z, volume)
            }
            _ => volume(l, s_f, s_b),
        }
    }

    /// The largest extinction or emission rate (per unit length) the
    /// transfer function takes on `[lo, hi]` (at its ends and on both sides
    /// of every node inside: the function is piecewise linear), `f64::MAX`
    /// when not finite: a bound on how fast a segment's optical depth and
    /// colour grow with its length ([`super::ties`] weighs slivers by it).
    pub fn max_rate(&self, lo: f64, hi: f64) -> f64 {
        let r = self.fold_nodes(lo, hi, 0.0, |r, m| {
            m.source.iter().fold(r.max(m.tau), |a, &c| a.max(c.abs()))
        });
        if r.is_finite() {
            r
        } else {
            f64::MAX
        }
    }

    /// The least extinction (per unit length) the transfer function takes
    /// on `[lo, hi]` (at its ends and on both sides of every node inside),
    /// 0 when not a number: what a segment with scalars in `[lo, hi]`
    /// absorbs at least per unit length ([`super::occlusion`]).
    pub fn min_extinction(&self, lo: f64, hi: f64) -> f64 {
        let t = self.fold_nodes(lo, hi, f64::INFINITY, |t, m| t.min(m.tau));
        if t.is_nan() {
            0.0
        } else {
            t
        }
    }

    /// The largest extinction (per unit length) the transfer function
    /// takes on `[lo, hi]` (at its ends and on both sides of every node
    /// inside), `f64::MAX` when not finite: a bound on the optical depth
    /// per unit length of any segment whose scalars lie in `[lo, hi]`.
    pub fn max_extinction(&self, lo: f64, hi: f64) -> f64 {
        let t = self.fold_nodes(lo, hi, 0.0, |t, m| t.max(m.tau));
        if t.is_finite() {
            t
        } else {
            f64::MAX
        }
    }

    /// Folds `f` over the materials at the ends of `[lo, hi]` and on both
    /// sides of every transfer-function node inside: where a piecewise
    /// linear function takes its extremes.
    fn fold_nodes(&self, lo: f64, hi: f64, init: f64, f: impl Fn(f64, Material) -> f64) -> f64 {
        let m = |s: f64| self.tf.material(s);
        let mut acc = f(init, m(lo));
        acc = f(acc, m(hi));
        // The breakpoints are sorted: only those in `[lo, hi]` (none for
        // NaN ends).
        let breaks = self.tf.breakpoints_slice();
        let first = breaks.partition_point(|&b| b < lo);
        for &b in breaks[first..].iter().take_while(|&&b| b <= hi) {
            if b >= lo {
                let left = b - b.abs().max(LEFT_LIMIT_FLOOR) * LEFT_LIMIT_REL;
                acc = f(acc, m(b));
                acc = f(acc, m(left));
            }
        }
        acc
    }

    /// Whether nothing of a piece with scalars in `[lo, hi]` is drawn: it
    /// holds no isosurface, and the volume is not drawn or the material is
    /// dark over the whole interval: zero
    /// extinction and (independent emission) zero emission at both ends and
    /// on both sides of every transfer-function node inside, so (the
    /// function being piecewise linear) everywhere. Every node is checked,
    /// not only the mode's split points: a mode that slices at none still
    /// skips only what is truly dark.
    pub fn invisible(&self, lo: f64, hi: f64) -> bool {
        self.skip_invisible && dark_range(self.tf, self.iso, self.volume, lo, hi)
    }
}

/// Whether nothing of a piece with scalars in `[lo, hi]` is drawn (see
/// [`PieceSource::invisible`], which asks this where skipping is on): no
/// isosurface of `iso` in it, and the volume not drawn or `tf` dark over
/// the whole interval. The visibility sort asks the same of whole cells
/// ([`crate::visibility::SplitPolicy::dark`]), so that a dark cell is not
/// split at breakpoints.
pub fn dark_range(
    tf: &TransferFunction,
    iso: Option<&IsoSet>,
    volume: bool,
    lo: f64,
    hi: f64,
) -> bool {
    if !(lo.is_finite() && hi.is_finite()) {
        return false;
    }
    if iso.is_some_and(|set| set.any_in(lo, hi)) {
        return false;
    }
    if !volume {
        return true;
    }
    let dark = |s: f64| {
        let m = tf.material(s);
        m.tau == 0.0 && m.source == [0.0; 3]
    };
    if !dark(lo) || !dark(hi) {
        return false;
    }
    for &b in tf.breakpoints_slice() {
        if b >= lo && b <= hi {
            let left = b - b.abs().max(LEFT_LIMIT_FLOOR) * LEFT_LIMIT_REL;
            if !dark(b) || !dark(left) {
                return false;
            }
        }
    }
    true
}

/// A 64-bit key of what [`dark_range`] answers with these inputs: the
/// transfer function's nodes and darkness on both sides of each and
/// beyond its ends (piecewise linear between them), the isosurface
/// levels, and whether the volume is drawn. Equal keys give equal
/// answers, but for a 2^-64 chance.
pub fn dark_key(tf: &TransferFunction, iso: Option<&IsoSet>, volume: bool) -> u64 {
    const K: u64 = 0x517c_c1b7_2722_0a95;
    let mut h = volume as u64;
    let mut mix = |x: u64| h = (h.rotate_left(5) ^ x).wrapping_mul(K);
    let dark = |s: f64| {
        let m = tf.material(s);
        (m.tau == 0.0 && m.source == [0.0; 3]) as u64
    };
    let nodes = tf.breakpoints_slice();
    for &b in nodes {
        let left = b - b.abs().max(LEFT_LIMIT_FLOOR) * LEFT_LIMIT_REL;
        mix(b.to_bits());
        mix(dark(b) << 1 | dark(left));
    }
    if let (Some(&first), Some(&last)) = (nodes.first(), nodes.last()) {
        mix(dark(first - first.abs().max(1.0)) << 1 | dark(last + last.abs().max(1.0)));
    } else {
        mix(dark(0.0));
    }
    for &v in iso.map(|s| &s.levels[..]).unwrap_or(&[]) {
        mix(v.to_bits());
    }
    h
}
