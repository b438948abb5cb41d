//! Regions kept across frames whose scalars change and nothing else (the
//! steps of a time series with the same points and cells, seen by the same
//! camera): [`KeptRegions`].
//!
//! **What depends on the scalars.** Steps 2-6 of the [`super::Projector`]
//! (pixel positions, facing, the regions and their front and back
//! triangles, the fan triangles) read only the piece's points; the scalars
//! enter step 6 only through the values of each region vertex, and those
//! come from one of three sources ([`ValueSource`]): a point's own data, a
//! boundary triangle's plane evaluated at the vertex ([`FaceTri::eval`]),
//! or the boundary along an edge. Step 6 records each vertex's sources
//! (which triangle is the widest, what a fast-path vertex is: all decided
//! on positions), so that the same regions can take other scalars through
//! the very function calls step 6 made with the first ones:
//! [`KeptRegions::restore`] gives the bits a fresh projection gives. The
//! profile flags and [`Projected::outline_profile`] are recomputed with the
//! values (a NaN can move a vertex's depth to a corner's). The steps after
//! 6 (the window clip, the perspective refinement, the coverage culling)
//! run again as always: their new vertices and the refinement depend on the
//! values.
//!
//! **Which piece.** A kept projection is only valid for the piece's own
//! geometry, the camera and the projector's settings it was made with.
//! [`KeptRegions::holds`] compares the piece's points and triangles, bit
//! for bit, so a caller that keys kept regions by cell can never draw a
//! cell with another's regions; the camera and settings are the caller's
//! to keep fixed (`render::driver::regions`). A piece that reaches the
//! near plane is clipped again, with its new scalars, before its kept
//! regions take them.

use glam::{DVec2, DVec3};

use super::project::source_value;
use super::{FaceTri, Polyhedron, Projected, RegionList, RegionVertex};

/// Where a region vertex's front or back depth and scalar come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ValueSource {
    /// The piece's point (its own depth and scalar).
    Own(u32),
    /// A boundary triangle's plane, evaluated at the vertex.
    Face(u32),
    /// The boundary along the edge between two points, at the vertex.
    Edge([u32; 2]),
}

/// The sources of one region vertex's front and back values, and whether
/// it lies on the outline (for its profile).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct VertexSource {
    pub sources: [ValueSource; 2],
    pub on_hull: bool,
}

/// The regions of one piece (steps 2-6 of the [`super::Projector`]), kept
/// for frames in which only its scalars change (module docs): what step 6
/// wrote less the values, which [`KeptRegions::restore`] evaluates again,
/// and the fan triangles, which it makes again from the regions.
#[derive(Clone, Debug)]
pub struct KeptRegions {
    /// The piece's view-space points and boundary triangles (before any
    /// near-plane clip), to check that a piece is this one.
    points: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Pixel positions of the projected piece's points (its faces' corners
    /// and the edge sources' ends).
    pix: Vec<DVec2>,
    /// Region vertices: positions and value sources.
    pos: Vec<DVec2>,
    sources: Vec<VertexSource>,
    regions: RegionList,
    region_faces: Vec<[u32; 2]>,
    outline_inputs: [bool; 2],
    fast_path: bool,
}

impl KeptRegions {
    /// The regions steps 2-6 made of `poly` (its part beyond the near
    /// plane projected at pixel positions `pix`), written in `out`.
    pub(super) fn new(
        poly: &Polyhedron,
        pix: &[DVec2],
        out: &Projected,
        fast_path: bool,
    ) -> KeptRegions {
        KeptRegions {
            points: poly.points.clone(),
            triangles: poly.triangles.clone(),
            pix: pix.to_vec(),
            pos: out.vertices.iter().map(RegionVertex::pos).collect(),
            sources: out.sources.clone(),
            regions: out.regions.clone(),
            region_faces: out.region_faces.clone(),
            outline_inputs: out.outline_inputs,
            fast_path,
        }
    }

    /// Whether `poly` has the geometry these regions were made for: the
    /// same points and boundary triangles, bit for bit.
    pub fn holds(&self, poly: &Polyhedron) -> bool {
        self.points == poly.points && self.triangles == poly.triangles
    }

    /// About how many bytes this holds.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        size_of::<Self>()
            + self.points.len() * size_of::<DVec3>()
            + self.triangles.len() * size_of::<[u32; 3]>()
            + (self.pix.len() + self.pos.len()) * size_of::<DVec2>()
            + self.sources.len() * size_of::<VertexSource>()
            + (self.regions.verts.len() + self.regions.start.len()) * size_of::<u32>()
            + self.region_faces.len() * size_of::<[u32; 2]>()
    }

    pub(super) fn fast_path(&self) -> bool {
        self.fast_path
    }

    /// Writes the kept regions into `out` (cleared, its view set) with the
    /// scalars of `piece` (the piece these were made for, or its part
    /// beyond the near plane, now with new scalars): the faces and the
    /// vertices' values are evaluated again as step 6 did.
    pub(super) fn restore(&self, piece: &Polyhedron, out: &mut Projected) {
        out.faces
            .extend((0..piece.triangles.len() as u32).map(|t| FaceTri::new(piece, &self.pix, t)));
        let view = out.view;
        let mut profile_hull = true;
        for (&q, src) in self.pos.iter().zip(&self.sources) {
            let value = |s| source_value(piece, &self.pix, &view, &out.faces, s, q);
            let v = RegionVertex::from_values(
                &view,
                value(src.sources[0]),
                value(src.sources[1]),
                q,
                src.on_hull,
            );
            profile_hull &= !src.on_hull || v.profile;
            out.vertices.push(v);
        }
        out.sources.extend_from_slice(&self.sources);
        out.regions.verts.clone_from(&self.regions.verts);
        out.regions.start.clone_from(&self.regions.start);
        // The fan triangles again (exact orientations of the same
        // positions: the same triangles).
        out.triangulate_regions();
        out.region_faces.extend_from_slice(&self.region_faces);
        out.outline_inputs = self.outline_inputs;
        let [fast, complete] = self.outline_inputs;
        out.outline_profile = fast && profile_hull && complete;
    }
}
