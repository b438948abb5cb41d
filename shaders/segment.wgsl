// The segment of a region vertex stage (shaders/segment_vertex.wgsl or
// shaders/iso_vertex.wgsl in front, shaders/segment_view.wgsl beside it):
// each region vertex carries s_f, s_b and l as shaders/segment_view.wgsl
// describes, interpolated by the rasteriser.

// The segment at framebuffer position `p` (pixel centres at i + 0.5).
// Twin: render::modes::segment::segment_at.
fn segment_at(f: VertexOut, p: vec2<f32>) -> Seg {
    return segment_of(f.front, f.back, f.thick, p);
}

// Coverage counting (tests and diagnostics): every fragment adds 1 to red.
@fragment
fn fs_count(f: VertexOut) -> FragOut {
    var out: FragOut;
    out.color = count_of(f.clip.z);
    out.depth = piece_depth(f.piece);
    return out;
}
