//! The exact mode with isosurfaces (`--mode exact --iso ...`): surfaces
//! mixed with the volume in each piece's place in the exact order, with the
//! exact mode's vertex integrals for the volume.
//!
//! The exact mode interpolates per-vertex integrals across a region, so it
//! cannot find a crossing inside a segment per fragment as the segment
//! modes do ([`super::iso`]). Instead it puts every surface on a piece's
//! boundary:
//! - **split policy**: pieces are sliced at the isovalues' levels
//!   ([`IsoSet::levels`]) as well as at the TF's breakpoints (cells holding
//!   one are drawn as their tets, as for a breakpoint). A slab's points on
//!   the slice carry the level exactly ([`crate::projection::Clipper`]);
//! - **where a surface is**: with the crossing rule of
//!   [`IsoSet::crossed`] (a segment crosses level `L` when its scalars go
//!   from below `L` to `L` or above), a segment through a part crosses a
//!   level only at one of its ends, and only where the part lies below the
//!   level: a part whose largest scalar is a level `L` holds surface `L` on
//!   every region whose entry (or exit) triangle has all its corners at
//!   `L`. Entered there, the ray falls from `L` (the surface's back style,
//!   then the volume); left there, it rises to `L` (the volume, then the
//!   front style). Parts above a level leave the surface to the part in
//!   front of or behind them, so each surface is drawn once;
//! - **payload** ([`ExactIsoMode::payload`]): the exact mode's payload,
//!   then each surface region's triangles get their own copies of their
//!   vertices (a vertex on the slice's edge is shared with regions that do
//!   not hold the surface), carrying the surface's straight colour and
//!   opacity, the field's gradient at the surface point (flat: the part's
//!   least-squares fit; smooth: the points' gradients interpolated on the
//!   slice triangle, [`crate::render::gradients`]) and the side;
//! - **seams**: the boundary of a surface region inside the part's outline
//!   separates pixels with and without the surface, and two parts whose
//!   slices meet there (neighbouring tets) must give a centre on it to
//!   exactly one of them. The rounding of region corners (and refinement
//!   midpoints on one side only) cannot promise that, so the edges are
//!   handed to the driver as seams ([`Projected::seams`]): the centres next
//!   to them are decided on the exact geometry like those next to the
//!   outline ([`crate::render::ties`]), and their quads hold the surface
//!   when the exact ray enters or leaves through a triangle on the level
//!   ([`Projected::tie_faces`]), the one rule every part applies;
//! - **stage** (`shaders/exptable.wgsl` + `shaders/exact_iso.wgsl`): the
//!   exact stage's volume, the surface lit by the headlight, composited in
//!   their order along the ray; [`fs_main`] is its twin.
//!
//! Within one part both mixes of [`crate::render::iso::IsoMix`] give this
//! image: a surface is at the very end of the part's segment, where RKE's
//! blend weights are 0 and 1.

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use crate::gpu::common::finite;
use crate::gpu::cpu::{lerp, CpuStage};
use crate::gpu::{Binding, Context, GpuError, GpuVertex, Resource, Stage, StageDesc};
use crate::projection::{Polyhedron, Projected};
use crate::render::driver::ProjectedMode;
use crate::render::gradients::{boundary_gradient, piece_gradient};
use crate::render::iso::{IsoSet, Lighting, AMBIENT, DIFFUSE};
use crate::render::pieces::PieceSource;
use crate::tf::TransferFunction;

use super::exact::{self, bind_table_stage, ExactMode, ExactPayload, ExactTwin, ExactVertex};
use super::iso::{face_gradient, view_point};

/// One vertex of the exact stage with isosurfaces. Keep in sync with
/// `VertexIn` in `shaders/exact_iso.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct ExactIsoVertex {
    /// The exact mode's vertex.
    pub exact: ExactVertex,
    /// The region's surface: straight colour and opacity (0: none).
    pub surface: [f32; 4],
    /// The field's view-space gradient at the surface point, scaled per
    /// part (only its direction lights).
    pub grad: [f32; 3],
    /// 1: the surface is at the segment's exit (behind the volume); 0: at
    /// its entry.
    pub at_back: f32,
}

impl ExactIsoVertex {
    /// Vertex attributes (`@location`s of `VertexIn`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 8] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Float32,
        2 => Float32,
        3 => Float32x3,
        4 => Uint32,
        5 => Float32x4,
        6 => Float32x3,
        7 => Float32,
    ];
}

impl GpuVertex for ExactIsoVertex {
    fn clip(&self) -> [f32; 4] {
        self.exact.pos
    }
    fn piece(&self) -> u32 {
        self.exact.piece
    }
    fn with_piece(self, piece: u32) -> Self {
        ExactIsoVertex {
            exact: self.exact.with_piece(piece),
            ..self
        }
    }
    fn is_finite(&self) -> bool {
        self.exact.is_finite()
            && self.surface.iter().all(|v| v.is_finite())
            && self.grad.iter().all(|v| v.is_finite())
            && self.at_back.is_finite()
    }
    fn with_clip(self, pos: [f32; 4]) -> Self {
        ExactIsoVertex {
            exact: self.exact.with_clip(pos),
            ..self
        }
    }
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self {
        ExactIsoVertex {
            exact: ExactVertex::lerp3(tri.map(|v| &v.exact), bary),
            surface: [0, 1, 2, 3].map(|k| lerp(tri, bary, |v| v.surface[k])),
            grad: [0, 1, 2].map(|k| lerp(tri, bary, |v| v.grad[k])),
            at_back: lerp(tri, bary, |v| v.at_back),
        }
    }
    fn transparent(self) -> Self {
        ExactIsoVertex {
            exact: self.exact.transparent(),
            surface: [0.0; 4],
            ..self
        }
    }
}

/// The light uniform. Keep in sync with `IsoLight` in
/// `shaders/exact_iso.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct ExactIsoParams {
    pub lighting: u32,
    pub ambient: f32,
    pub diffuse: f32,
    pub _pad: u32,
}

impl ExactIsoParams {
    fn of(set: &IsoSet) -> ExactIsoParams {
        ExactIsoParams {
            lighting: set.lighting.code(),
            ambient: AMBIENT as f32,
            diffuse: DIFFUSE as f32,
            _pad: 0,
        }
    }
}

/// The stage.
pub static EXACT_ISO_STAGE: StageDesc = StageDesc {
    name: "exact_iso.wgsl",
    fragment: "fs_main",
    wgsl: concat!(
        include_str!("../../../shaders/exptable.wgsl"),
        include_str!("../../../shaders/exact_iso.wgsl")
    ),
    vertex: wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<ExactIsoVertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &ExactIsoVertex::ATTRIBUTES,
    },
    bindings: &[Binding::Uniform, Binding::Table, Binding::Uniform],
    constants: &[],
};

/// The stage's bindings on the CPU, for its twin [`fs_main`].
pub struct ExactIsoTwin {
    exact: ExactTwin,
    light: ExactIsoParams,
}

/// Twin of `exact_iso_light`.
pub fn exact_iso_light(stage: &ExactIsoTwin, g: [f32; 3]) -> f32 {
    if stage.light.lighting == 0 {
        return 1.0;
    }
    let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if n.is_nan() || n <= 0.0 || !finite(n) {
        return 1.0;
    }
    stage.light.ambient + stage.light.diffuse * (g[2].abs() / n).min(1.0)
}

/// Twin of `fs_main` in `shaders/exact_iso.wgsl`: the exact stage's volume
/// ([`exact::fs_main`]) and the region's lit surface, in their order.
pub fn fs_main(
    stage: &ExactIsoTwin,
    tri: [&ExactIsoVertex; 3],
    bary: [f64; 3],
) -> Option<[f32; 4]> {
    let surface = [0, 1, 2, 3].map(|k| lerp(tri, bary, |v| v.surface[k]));
    let grad = [0, 1, 2].map(|k| lerp(tri, bary, |v| v.grad[k]));
    let at_back = lerp(tri, bary, |v| v.at_back);
    if !(surface.iter().all(|&c| finite(c)) && finite(at_back)) {
        return None;
    }
    let volume = exact::fs_main(&stage.exact, tri.map(|v| &v.exact), bary)?;
    let a = surface[3].clamp(0.0, 1.0);
    let i = exact_iso_light(stage, grad) * a;
    let surf = [surface[0] * i, surface[1] * i, surface[2] * i, a];
    let over = |f: [f32; 4], b: [f32; 4]| std::array::from_fn(|k| f[k] + (1.0 - f[3]) * b[k]);
    Some(if at_back > 0.5 {
        over(volume, surf)
    } else {
        over(surf, volume)
    })
}

impl CpuStage<ExactIsoVertex> for ExactIsoTwin {
    fn shade(&self, tri: [&ExactIsoVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_main(self, tri, bary)
    }

    fn describe(&self, tri: [&ExactIsoVertex; 3], bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let mut out = self.exact.describe(tri.map(|v| &v.exact), bary);
        out.push(("surface.a", lerp(tri, bary, |v| v.surface[3])));
        out.push(("at_back", lerp(tri, bary, |v| v.at_back)));
        out
    }
}

/// A surface on one side of a region or tie segment.
#[derive(Clone, Copy, Debug, Default)]
struct Surface {
    /// `[r, g, b, opacity]`, straight; opacity 0: none.
    color: [f64; 4],
    grad: DVec3,
    at_back: bool,
}

/// The payload of one part: the exact mode's, and the surface at each
/// vertex.
#[derive(Default)]
pub struct ExactIsoPayload {
    exact: ExactPayload,
    surfaces: Vec<Surface>,
    /// One scale for the part's gradients (only their direction lights):
    /// their largest component becomes 1, so that `f32` holds them
    /// whatever the field's units, and interpolation keeps directions.
    grad_scale: f64,
    /// Scratch: the copy of each vertex in the region being given its own.
    copy: Vec<u32>,
    /// Scratch: (region, triangle) of the triangles of surface regions.
    tris: Vec<(u32, u32)>,
    /// Scratch: a surface region's edges.
    edges: Vec<(u32, u32)>,
    /// Scratch: the side and triangle of each region holding the surface.
    sides: Vec<Option<(usize, u32)>>,
    /// Scratch: the vertices given a copy in the region being done.
    made: Vec<usize>,
}

/// The exact mode with isosurfaces on the projected-cell driver.
pub struct ExactIsoMode {
    exact: ExactMode,
    set: IsoSet,
    /// World-space point gradients (smooth light).
    gradients: Option<Vec<DVec3>>,
}

impl ExactIsoMode {
    /// The surfaces `set` over `exact`'s volume; `gradients` are the
    /// points' (smooth light).
    pub fn new(exact: ExactMode, set: IsoSet, gradients: Option<Vec<DVec3>>) -> ExactIsoMode {
        ExactIsoMode {
            exact,
            set,
            gradients,
        }
    }

    /// The index of the level that is the part's largest scalar, if any.
    fn top_level(&self, part: &Polyhedron) -> Option<usize> {
        let top = part
            .scalars
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        self.set.levels.iter().position(|&l| l == top)
    }

    /// Surface `k` seen from side `side` (0: the entry) with gradient `g`.
    fn surface(&self, k: usize, side: usize, g: DVec3) -> Surface {
        // At the entry the ray falls from the level: the back style.
        let c = self.set.sides[k][if side == 0 { 1 } else { 0 }];
        Surface {
            color: c,
            grad: g,
            at_back: side == 1,
        }
    }

    /// The gradient lighting region vertex `i` at its side `side`, on the
    /// part's boundary triangle `face` (`None`: search the boundary).
    fn gradient(
        &self,
        part: &Polyhedron,
        proj: &Projected,
        i: usize,
        side: usize,
        face: Option<u32>,
        flat: DVec3,
    ) -> DVec3 {
        if self.set.lighting != Lighting::Smooth || part.gradients.len() != part.points.len() {
            return flat;
        }
        let x = view_point(proj, i, side);
        match face {
            Some(t) => face_gradient(part, t, x).unwrap_or(flat),
            None => boundary_gradient(part, x, flat),
        }
    }
}

impl ProjectedMode for ExactIsoMode {
    type Vertex = ExactIsoVertex;
    type Payload = ExactIsoPayload;

    fn split_points(&self, tf: &TransferFunction) -> Vec<f64> {
        let mut points = self.exact.split_points(tf);
        points.extend(self.set.levels.iter().copied().filter(|l| l.is_finite()));
        points.sort_by(f64::total_cmp);
        points.dedup();
        points
    }

    fn isosurfaces(&self) -> Option<&IsoSet> {
        Some(&self.set)
    }

    fn point_gradients(&self) -> Option<&[DVec3]> {
        match self.set.lighting {
            Lighting::Smooth => self.gradients.as_deref(),
            _ => None,
        }
    }

    fn bind(&self, gpu: &Context, src: &PieceSource) -> Result<Stage, GpuError> {
        let light = ExactIsoParams::of(&self.set);
        bind_table_stage(
            gpu,
            &EXACT_ISO_STAGE,
            src.length_unit as f32,
            &[Resource::Uniform(bytemuck::bytes_of(&light))],
        )
    }

    fn twin(&self, src: &PieceSource) -> Box<dyn CpuStage<ExactIsoVertex>> {
        let exact = match ExactTwin::new(src.length_unit as f32) {
            Ok(t) => t,
            // The driver's unit is the scene's (positive, finite) unit.
            Err(_) => ExactTwin::new(1.0).expect("unit 1"),
        };
        Box::new(ExactIsoTwin {
            exact,
            light: ExactIsoParams::of(&self.set),
        })
    }

    fn payload(
        &self,
        src: &PieceSource,
        part: &Polyhedron,
        proj: &mut Projected,
        used: &mut Vec<bool>,
        payload: &mut ExactIsoPayload,
        refined: &mut usize,
    ) {
        self.exact
            .payload(src, part, proj, used, &mut payload.exact, refined);
        payload.grad_scale = 1.0;
        self.surfaces(part, proj, used, payload);
        let n = payload
            .surfaces
            .iter()
            .map(|s| s.grad.abs().max_element())
            .fold(0.0, f64::max);
        if n > 0.0 && n.is_finite() {
            payload.grad_scale = 1.0 / n;
        }
    }

    fn vertex(
        &self,
        payload: &ExactIsoPayload,
        proj: &Projected,
        i: usize,
        ndc: [f32; 2],
    ) -> ExactIsoVertex {
        let exact = self.exact.vertex(&payload.exact, proj, i, ndc);
        let s = payload.surfaces.get(i).copied().unwrap_or_default();
        let g = s.grad * payload.grad_scale;
        let g = [g.x as f32, g.y as f32, g.z as f32].map(|c| if c.is_finite() { c } else { 0.0 });
        ExactIsoVertex {
            exact,
            surface: s.color.map(|c| c as f32),
            grad: g,
            at_back: if s.at_back { 1.0 } else { 0.0 },
        }
    }
}

impl ExactIsoMode {
    /// The surface at every vertex of `proj` (see the module docs), giving
    /// each surface region's triangles their own vertices.
    fn surfaces(
        &self,
        part: &Polyhedron,
        proj: &mut Projected,
        used: &mut Vec<bool>,
        payload: &mut ExactIsoPayload,
    ) {
        let surfaces = &mut payload.surfaces;
        surfaces.clear();
        surfaces.resize(proj.vertices.len(), Surface::default());
        let Some(k) = self.top_level(part) else {
            return;
        };
        let level = self.set.levels[k];
        let flat = match self.set.lighting {
            Lighting::None => DVec3::ZERO,
            _ => piece_gradient(part),
        };
        // Whether the part's boundary triangle `t` lies on the level.
        let on_level = |t: u32| {
            part.triangles.get(t as usize).is_some_and(|tri| {
                tri.iter()
                    .all(|&i| part.scalars.get(i as usize) == Some(&level))
            })
        };
        if proj.regions.is_empty() {
            // Tie quads' segments: the triangles the exact crossings found.
            for (i, surface) in surfaces.iter_mut().enumerate() {
                let Some(&[f, b]) = proj.tie_faces.get(i) else {
                    continue;
                };
                let l = proj.vertices[i].l;
                if l.is_nan() || l <= 0.0 {
                    continue;
                }
                let (side, face) = if on_level(f) {
                    (0, f)
                } else if on_level(b) {
                    (1, b)
                } else {
                    continue;
                };
                let g = self.gradient(part, proj, i, side, Some(face), flat);
                *surface = self.surface(k, side, g);
            }
            return;
        }
        // The side of each region whose triangle lies on the level.
        let sides = &mut payload.sides;
        sides.clear();
        for r in 0..proj.regions.len() {
            let faces = proj.region_faces.get(r).copied();
            sides.push(faces.and_then(|[f, b]| {
                if on_level(f) {
                    Some((0usize, f))
                } else if on_level(b) {
                    Some((1, b))
                } else {
                    None
                }
            }));
        }
        if sides.iter().all(Option::is_none) {
            return;
        }
        // Each surface region's triangles get their own vertices.
        let tris = &mut payload.tris;
        tris.clear();
        for (t, &r) in proj.triangle_region.iter().enumerate() {
            if sides.get(r as usize).copied().flatten().is_some() {
                tris.push((r, t as u32));
            }
        }
        tris.sort_unstable();
        let edges = &mut payload.edges;
        let copy = &mut payload.copy;
        copy.clear();
        copy.resize(proj.vertices.len(), u32::MAX);
        let values = &mut payload.exact.values;
        let mut start = 0;
        while start < tris.len() {
            let r = tris[start].0;
            let mut end = start;
            while end < tris.len() && tris[end].0 == r {
                end += 1;
            }
            let Some((side, face)) = sides[r as usize] else {
                start = end;
                continue;
            };
            let made = &mut payload.made;
            made.clear();
            for &(_, t) in &tris[start..end] {
                for c in 0..3 {
                    let v = proj.triangles[t as usize][c] as usize;
                    if copy[v] == u32::MAX {
                        let n = proj.vertices.len();
                        copy[v] = n as u32;
                        made.push(v);
                        proj.vertices.push(proj.vertices[v]);
                        values.push(values.get(v).copied().unwrap_or_default());
                        used.push(true);
                        let g = self.gradient(part, proj, v, side, Some(face), flat);
                        surfaces.push(self.surface(k, side, g));
                    }
                    proj.triangles[t as usize][c] = copy[v];
                }
            }
            for &v in made.iter() {
                copy[v] = u32::MAX;
            }
            // The region's boundary: its edges used once.
            edges.clear();
            for &(_, t) in &tris[start..end] {
                let tri = proj.triangles[t as usize];
                for c in 0..3 {
                    let (a, b) = (tri[c], tri[(c + 1) % 3]);
                    edges.push(if a < b { (a, b) } else { (b, a) });
                }
            }
            edges.sort_unstable();
            let mut e = 0;
            while e < edges.len() {
                let mut n = 1;
                while e + n < edges.len() && edges[e + n] == edges[e] {
                    n += 1;
                }
                if n == 1 {
                    proj.seams.push(edges[e]);
                }
                e += n;
            }
            start = end;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_matches_struct() {
        assert_eq!(std::mem::size_of::<ExactIsoVertex>(), 72);
        let offs: Vec<u64> = ExactIsoVertex::ATTRIBUTES
            .iter()
            .map(|a| a.offset)
            .collect();
        assert_eq!(offs, vec![0, 16, 20, 24, 36, 40, 56, 68]);
        assert_eq!(std::mem::offset_of!(ExactIsoVertex, surface), 40);
        assert_eq!(std::mem::offset_of!(ExactIsoVertex, grad), 56);
        assert_eq!(std::mem::offset_of!(ExactIsoVertex, at_back), 68);
    }
}
