//! The layer stage: premultiplied colours made on the CPU, drawn as they
//! are (`shaders/layer.wgsl`), the same for every mode.
//!
//! A layer is a set of pixel quads ([`LayerVertex::pixel_quad`]), each
//! with one constant premultiplied RGBA: the per-pixel layers of cycle
//! groups are drawn this way at their place in the drawing order. The quad
//! of pixel `(i, j)` has its corners on the pixel's edges (exact on the
//! sub-pixel grid), so its centre lies strictly inside and is covered
//! exactly once; the colour is flat (no interpolation).

use bytemuck::{Pod, Zeroable};

use super::cpu::CpuStage;
use super::raster::{ClipMapper, GpuVertex};
use super::stage::StageDesc;

/// One vertex of the layer stage. Keep in sync with `VertexIn` in
/// `shaders/layer.wgsl`.
#[repr(C)]
#[derive(Pod, Zeroable, Clone, Copy, Debug, Default, PartialEq)]
pub struct LayerVertex {
    /// Clip-space position.
    pub pos: [f32; 4],
    /// Premultiplied colour and opacity (flat over the triangle).
    pub rgba: [f32; 4],
    /// The piece (layer) number in drawing order.
    pub piece: u32,
}

impl LayerVertex {
    /// Vertex attributes (`@location`s of `VertexIn`).
    pub const ATTRIBUTES: [wgpu::VertexAttribute; 3] = wgpu::vertex_attr_array![
        0 => Float32x4,
        1 => Float32x4,
        2 => Uint32,
    ];

    /// The four corners and two triangles of the quad of pixel `(i, j)`
    /// with colour `rgba`, appended to `vertices` and `indices`.
    pub fn pixel_quad(
        mapper: &ClipMapper,
        i: u32,
        j: u32,
        rgba: [f32; 4],
        piece: u32,
        vertices: &mut Vec<LayerVertex>,
        indices: &mut Vec<u32>,
    ) {
        let base = vertices.len() as u32;
        for (di, dj) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
            // Pixel corners are on the grid: always mapped.
            let ([x, y], _) = mapper
                .ndc((i + di) as f64, (j + dj) as f64)
                .unwrap_or(([0.0; 2], [0; 2]));
            vertices.push(LayerVertex {
                pos: [x, y, 0.5, 1.0],
                rgba,
                piece,
            });
        }
        indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
}

impl GpuVertex for LayerVertex {
    fn clip(&self) -> [f32; 4] {
        self.pos
    }
    fn piece(&self) -> u32 {
        self.piece
    }
    fn with_piece(self, piece: u32) -> Self {
        LayerVertex { piece, ..self }
    }
    fn is_finite(&self) -> bool {
        self.pos.iter().chain(&self.rgba).all(|v| v.is_finite())
    }
    fn with_clip(self, pos: [f32; 4]) -> Self {
        LayerVertex { pos, ..self }
    }
    fn lerp3(tri: [&Self; 3], bary: [f64; 3]) -> Self {
        LayerVertex {
            rgba: [0, 1, 2, 3].map(|k| super::cpu::lerp(tri, bary, |v| v.rgba[k])),
            ..*tri[0]
        }
    }
    fn transparent(self) -> Self {
        LayerVertex {
            rgba: [0.0; 4],
            ..self
        }
    }
}

/// The layer stage.
pub static LAYER_STAGE: StageDesc = StageDesc {
    name: "layer.wgsl",
    fragment: "fs_main",
    wgsl: include_str!("../../shaders/layer.wgsl"),
    vertex: wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<LayerVertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &LayerVertex::ATTRIBUTES,
    },
    bindings: &[],
    constants: &[],
};

/// Twin of `fs_main` in `shaders/layer.wgsl`: the quad's flat colour.
pub fn fs_main(tri: [&LayerVertex; 3], _bary: [f64; 3]) -> Option<[f32; 4]> {
    Some(tri[0].rgba)
}

/// The layer stage on the CPU (it binds nothing), drawing through its twin
/// [`fs_main`].
pub struct LayerTwin;

impl CpuStage<LayerVertex> for LayerTwin {
    fn shade(&self, tri: [&LayerVertex; 3], bary: [f64; 3]) -> Option<[f32; 4]> {
        fs_main(tri, bary)
    }
    fn describe(&self, tri: [&LayerVertex; 3], _bary: [f64; 3]) -> Vec<(&'static str, f32)> {
        let c = tri[0].rgba;
        vec![("r", c[0]), ("g", c[1]), ("b", c[2]), ("a", c[3])]
    }
}
