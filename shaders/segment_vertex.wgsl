// The vertex stage of the segment modes (exact-frag, preint3d, preint2d,
// preint2d-cyl): `VertexIn` mirrors `SegmentVertex`
// (src/render/modes/segment.rs), and the varyings `shaders/segment.wgsl`
// rebuilds the fragment's segment from. A stage that carries more per vertex
// (shaders/iso_vertex.wgsl) replaces this file, keeping these fields.

// Keep in sync with `SegmentVertex` in src/render/modes/segment.rs.
struct VertexIn {
    @location(0) pos: vec4<f32>,
    @location(1) front: vec2<f32>,
    @location(2) back: vec2<f32>,
    @location(3) thick: f32,
    @location(4) piece: u32,
}

// Varyings use the default perspective-correct interpolation, which with
// w = 1 is linear in screen space; never @interpolate(linear) (Mesa gives
// NaN with it on triangles crossing the viewport edge).
struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) front: vec2<f32>,
    @location(1) back: vec2<f32>,
    @location(2) thick: f32,
    @location(3) @interpolate(flat) piece: u32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = v.pos;
    out.front = v.front;
    out.back = v.back;
    out.thick = v.thick;
    out.piece = v.piece;
    return out;
}
