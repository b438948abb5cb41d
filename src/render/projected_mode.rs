//! The seam between the one projected-cell driver ([`super::driver`]) and
//! the modes: the [`ProjectedMode`] trait, what a mode supplies (split
//! policy, payload, vertex, stage, twin, and what it draws: isosurfaces,
//! the volume).

use glam::DVec3;

use crate::gpu::cpu::CpuStage;
use crate::gpu::{Context, GpuError, GpuVertex, Stage};
use crate::projection::{Polyhedron, Projected};
use crate::tf::TransferFunction;

use super::iso::IsoSet;
use super::pieces::PieceSource;

/// What a projected-cell mode adds to the shared driver: its split policy,
/// its per-vertex payload, its stage (shader) and the stage's CPU twin.
pub trait ProjectedMode: Sync {
    /// The Rust mirror of the stage's `VertexIn`.
    type Vertex: GpuVertex;
    /// Per-worker scratch holding the payload of the piece being drawn.
    type Payload: Default + Send;

    /// TF values at which pieces are sliced (empty: never sliced).
    fn split_points(&self, tf: &TransferFunction) -> Vec<f64>;

    /// Whether regions are refined in perspective views until linear
    /// interpolation in screen space is within
    /// [`crate::numeric::tolerance::PERSPECTIVE_INTERP_REL`] (a mode whose
    /// payload interpolates exactly in perspective says no).
    fn perspective_refine(&self) -> bool {
        true
    }

    /// Whether centres next to a part's outline are decided on the exact
    /// geometry ([`super::ties`]): on for every mode (a mode whose stage
    /// cannot draw a tie triangle may say no).
    fn decides_ties(&self) -> bool {
        true
    }

    /// The isosurfaces the mode draws ([`super::iso`]; none by default):
    /// pieces holding one are drawn even where the volume is dark.
    fn isosurfaces(&self) -> Option<&IsoSet> {
        None
    }

    /// The isovalues whose crossings the mode finds per fragment from the
    /// interpolated scalars (sorted; none by default): the driver decides
    /// exactly the sliver centres whose scalars come within the snap's
    /// shift of one ([`super::ties::PartTriangles::isovalues`]). The exact
    /// mode slices its pieces at the isovalues instead and says none.
    fn fragment_isovalues(&self) -> &[f64] {
        &[]
    }

    /// Of [`ProjectedMode::fragment_isovalues`], those the fragments of
    /// the part whose payload is `payload` can cross (all by default): the
    /// decisions about the others change nothing that part draws.
    fn part_isovalues(&self, _payload: &Self::Payload) -> &[f64] {
        self.fragment_isovalues()
    }

    /// The scalar of `src` that the stage finding
    /// [`ProjectedMode::fragment_isovalues`] maps to 0: its rounding is
    /// relative to the distance from it
    /// ([`super::ties::PartTriangles::iso_origin`]).
    fn fragment_iso_origin(&self, _src: &PieceSource) -> f64 {
        0.0
    }

    /// Whether the mode draws the volume (only `--mode iso` does not).
    fn draws_volume(&self) -> bool {
        true
    }

    /// World-space gradients per mesh point the parts should carry
    /// ([`Polyhedron::gradients`], smooth isosurface shading).
    fn point_gradients(&self) -> Option<&[DVec3]> {
        None
    }

    /// Binds the mode's stage for one frame (uniforms, tables) of `src`.
    /// The part of `tf` the mode's triangles (positions and payload) depend
    /// on, where that is not all of it: frames whose signatures are equal
    /// may draw the same triangles ([`super::driver::kept`]). `None` (the
    /// default): every change of the transfer function projects again.
    fn stream_signature(&self, _tf: &TransferFunction) -> Option<Vec<u64>> {
        None
    }

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError>;

    /// The CPU twin of the stage's fragment shader, for one frame of `src`.
    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<Self::Vertex>>;

    /// The vertex that draws `part` whole, as one polygon over its outline
    /// (the driver's `whole` module) whose fragments find their own
    /// segment through the part (`--piece-draw quads` of exact-frag and the
    /// table modes, [`super::modes::piece_quad`]), with the clip position
    /// left to the driver; `None` (the default, and for a part the mode
    /// cannot draw whole): the driver projects the part into regions.
    /// `rate` is the part's largest rate ([`PieceSource::max_rate`] on its range).
    fn whole_part(
        &self,
        _src: &PieceSource,
        _part: &Polyhedron,
        _payload: &mut Self::Payload,
        _rate: &dyn Fn() -> f64,
    ) -> Option<Self::Vertex> {
        None
    }

    /// Computes the payload of `part`'s projection at every vertex
    /// `used[i]` marks (a kept triangle uses it). `part` is the polyhedron
    /// whose triangles `proj`'s faces index: a part reaching the near plane
    /// comes clipped there ([`crate::projection::Projector::projected_piece`]),
    /// with its cap. It may refine
    /// `proj.triangles` (adding vertices, then marking them used) and must
    /// then cull them again when `src.cull`; `refined` counts the triangles
    /// it added.
    fn payload(
        &self,
        src: &PieceSource,
        part: &Polyhedron,
        proj: &mut Projected,
        used: &mut Vec<bool>,
        payload: &mut Self::Payload,
        refined: &mut usize,
    );

    /// Vertex `i` of `proj` at normalised device coordinates `ndc` (on the
    /// sub-pixel grid), in piece 0 (the driver numbers the pieces).
    fn vertex(
        &self,
        payload: &Self::Payload,
        proj: &Projected,
        i: usize,
        ndc: [f32; 2],
    ) -> Self::Vertex;
}
