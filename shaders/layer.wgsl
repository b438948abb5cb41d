// The layer stage of zoovr: premultiplied colours computed on the CPU (the
// per-pixel layers of cycle groups, src/render/group.rs), drawn as they are
// at their place in the drawing order, whatever the mode. Twin:
// gpu::layer::fs_main.

// Keep in sync with `LayerVertex` in src/gpu/layer.rs.
struct VertexIn {
    @location(0) pos: vec4<f32>,
    @location(1) rgba: vec4<f32>,
    @location(2) piece: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) rgba: vec4<f32>,
    @location(1) @interpolate(flat) piece: u32,
}

struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = v.pos;
    out.rgba = v.rgba;
    out.piece = v.piece;
    return out;
}

@fragment
fn fs_main(f: VertexOut) -> FragOut {
    var out: FragOut;
    out.color = f.rgba;
    out.depth = piece_depth(f.piece);
    return out;
}

// Coverage counting: every fragment adds 1 to red (see shaders/exact.wgsl).
@fragment
fn fs_count(f: VertexOut) -> FragOut {
    var out: FragOut;
    out.color = count_of(f.clip.z);
    out.depth = piece_depth(f.piece);
    return out;
}
