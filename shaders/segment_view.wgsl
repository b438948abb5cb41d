// The vertex format and view of the segment modes (exact-frag, preint3d,
// preint2d, preint2d-cyl): each region vertex carries what the fragment
// needs to rebuild its ray segment through the piece (front scalar s_f,
// back scalar s_b, length l), exactly in orthographic and perspective views.
//
// Per vertex (src/render/modes/segment.rs `SegmentVertex`, which says how the
// CPU fills it):
// - orthographic: front = (s_f, 1), back = (s_b, 1), thick = l;
// - perspective: front = (s_f q_f, q_f), back = (s_b q_b, q_b) with q = 1/z
//   (z the view depth where the vertex's ray enters and leaves the piece),
//   thick = q_f - q_b.
// The scalar on a boundary triangle is linear in space, so over a region (one
// front and one back triangle) s q and q are affine in screen position, and
// so is q_f - q_b: the rasteriser interpolates all of them exactly (w = 1,
// positions already divided), and the fragment divides:
//   s_f = front.x / front.y, s_b = back.x / back.y,
//   l = (z_b - z_f) * |ray| = thick / (q_f q_b) * sqrt(1 + |u|^2),
// with u the view-plane position of the fragment's pixel. q_f - q_b is
// interpolated as itself, so a thin piece far away loses nothing to
// cancellation. Scalars are normalised (segment.rs `ScalarMap`).
//
// This file holds what every segment stage shares whatever its vertex: the
// view, the fragment's output, the segment and `segment_of`, the arithmetic
// above. Binding 0 is the view (`SegmentView`); a stage's own bindings
// follow. A stage on region vertices puts shaders/segment_vertex.wgsl (or
// shaders/iso_vertex.wgsl: `VertexIn`, `VertexOut`, `vs_main`) and
// shaders/segment.wgsl (`segment_at`, `fs_count`) beside it; the whole-piece
// quads of exact-frag put shaders/piece_quad.wgsl there instead.

// Keep in sync with `SegmentView` in src/render/modes/segment.rs.
struct View {
    // 1 for an orthographic view.
    ortho: u32,
    _pad0: u32,
    // View-plane position of framebuffer position p: p * scale + offset.
    scale: vec2<f32>,
    offset: vec2<f32>,
    _pad1: vec2<f32>,
}

@group(0) @binding(0) var<uniform> view: View;

// What a fragment writes: its colour, and as its depth the piece's key (see
// `piece_depth`), so that the depth test lets each piece colour a pixel at
// most once.
struct FragOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// A fragment's ray segment through its piece.
struct Seg {
    s_f: f32,
    s_b: f32,
    l: f32,
    // False where the interpolated values are not finite (a rasteriser may
    // interpolate garbage on a sliver of almost zero area): the fragment is
    // then discarded, leaving the pixel to the piece's other triangle.
    ok: bool,
}

// The segment from interpolated `front = (s_f q_f, q_f)`, `back = (s_b q_b,
// q_b)` and `thick = q_f - q_b` (or `(s, 1)` and `l`, orthographic) at
// framebuffer position `p` (pixel centres at i + 0.5).
// Twin: render::modes::segment_view::segment_of.
fn segment_of(front: vec2<f32>, back: vec2<f32>, thick: f32, p: vec2<f32>) -> Seg {
    var out: Seg;
    out.s_f = front.x / front.y;
    out.s_b = back.x / back.y;
    if view.ortho == 1u {
        out.l = thick;
    } else {
        let u = p * view.scale + view.offset;
        out.l = thick / (front.y * back.y) * sqrt(1.0 + dot(u, u));
    }
    out.l = max(out.l, 0.0);
    out.ok = finite(out.s_f) && finite(out.s_b) && finite(out.l);
    return out;
}
