// The vertex stage of the isosurface stages: the segment vertex
// (shaders/segment_vertex.wgsl, the same fields) and the gradient at the
// entry and exit points of the vertex's ray, for the light. In place of
// shaders/segment_vertex.wgsl, in front of shaders/segment.wgsl.
//
// Per vertex (src/render/modes/iso.rs `IsoVertex`, which says how the CPU
// fills it): grad_front = g_f (orthographic) or g_f q_f (perspective), and
// grad_back likewise with q_b. The gradient is linear on each boundary
// triangle (smooth shading) or constant (flat), so, as s q, g q is affine in
// screen position and the fragment divides by the interpolated q.
// candidates (flat) are the surfaces the part can cross, as indices
// candidates.x ..< candidates.y (exact in f32): the only ones searched.

// Keep in sync with `IsoVertex` in src/render/modes/iso.rs.
struct VertexIn {
    @location(0) pos: vec4<f32>,
    @location(1) front: vec2<f32>,
    @location(2) back: vec2<f32>,
    @location(3) thick: f32,
    @location(4) piece: u32,
    @location(5) grad_front: vec3<f32>,
    @location(6) grad_back: vec3<f32>,
    @location(7) candidates: vec2<f32>,
}

// Default (perspective-correct, with w = 1 screen-linear) interpolation, as
// in shaders/segment_vertex.wgsl.
struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) front: vec2<f32>,
    @location(1) back: vec2<f32>,
    @location(2) thick: f32,
    @location(3) @interpolate(flat) piece: u32,
    @location(4) grad_front: vec3<f32>,
    @location(5) grad_back: vec3<f32>,
    @location(6) @interpolate(flat) candidates: vec2<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = v.pos;
    out.front = v.front;
    out.back = v.back;
    out.thick = v.thick;
    out.piece = v.piece;
    out.grad_front = v.grad_front;
    out.grad_back = v.grad_back;
    out.candidates = v.candidates;
    return out;
}
