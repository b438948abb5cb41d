// The exact-frag stage: per fragment, the closed-form Williams-Max integral
// of the fragment's own ray segment (shaders/segment.wgsl rebuilds s_f, s_b
// and l; shaders/integral.wgsl integrates over every transfer-function piece
// between them). No table, no colour interpolation, no slicing at
// breakpoints. Output premultiplied, blended src + (1 - src.a) dst.
//
// Twin: render::modes::exact_frag::fs_main.

@fragment
fn fs_main(f: VertexOut) -> FragOut {
    let seg = segment_at(f, f.clip.xy);
    if !seg.ok {
        discard;
    }
    var out: FragOut;
    out.color = integrate_segment(seg.l, seg.s_f, seg.s_b);
    out.depth = piece_depth(f.piece);
    return out;
}
