// The vertex stage and segment of exact-frag's whole-piece quads
// (src/render/modes/piece_quad.rs, which fills `VertexIn` and is the twin):
// a convex piece of at most 8 points and 12 boundary triangles is drawn as
// one screen quad over its pixel bounding box, every vertex carrying the
// whole piece, and each fragment finds where its own ray enters and leaves
// the piece (view-independent cell projection, Weiler, Kraus, Merz and
// Ertl 2003): no region subdivision on the CPU.
//
// Per fragment, in view coordinates (x right, y up, z depth; the eye at the
// origin in perspective), the ray through the pixel's view-plane position u
// is sheared onto the origin: each point p goes to
//   q = p.xy - u p.z (perspective) or q = p.xy - u (orthographic),
// and a boundary triangle (a, b, c) holds the ray where the three edge
// functions E(b, c), E(c, a), E(a, b), E(i, j) = q_i x q_j, have one sign
// (Woop, Benthin and Wald 2013, watertight ray/triangle intersection). Their
// ratios are the hit's barycentric weights, which give its depth and scalar
// on the triangle's plane. A convex piece has one such triangle of each sign
// on a ray that meets it; the nearer is the entry. An edge is always
// evaluated from its lower-numbered point (the CPU numbers the points in one
// order for every piece, by view position), so two pieces sharing an edge
// compute the same value with opposite signs and a pixel centre on it
// belongs to both or neither of their faces: no gaps, no double coverage.
// Depths are taken relative to the piece's point 0 from f64 (`depth`), so
// a thin piece far from the eye keeps its thickness.
//
// A vertex whose `topo` holds no triangles is a region vertex of a piece the
// CPU projected instead (the near plane, faces seen nearly edge-on, more
// points, optically thick): `seg` and `thick` then carry the segment payload
// of shaders/segment_view.wgsl, interpolated.

// Keep in sync with `QuadVertex` in src/render/modes/piece_quad.rs.
struct VertexIn {
    @location(0) pos: vec4<f32>,
    @location(1) p0: vec4<f32>,
    @location(2) p1: vec4<f32>,
    @location(3) p2: vec4<f32>,
    @location(4) p3: vec4<f32>,
    @location(5) p4: vec4<f32>,
    @location(6) p5: vec4<f32>,
    @location(7) p6: vec4<f32>,
    @location(8) p7: vec4<f32>,
    @location(9) depth0: vec4<f32>,
    @location(10) depth1: vec4<f32>,
    @location(11) topo: vec4<u32>,
    @location(12) seg: vec4<f32>,
    @location(13) thick: f32,
    @location(14) piece: u32,
}

// The piece is flat (the same on every vertex; flat keeps it bit-exact);
// the region payload is interpolated (w = 1: linear in screen space).
struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) p0: vec4<f32>,
    @location(1) @interpolate(flat) p1: vec4<f32>,
    @location(2) @interpolate(flat) p2: vec4<f32>,
    @location(3) @interpolate(flat) p3: vec4<f32>,
    @location(4) @interpolate(flat) p4: vec4<f32>,
    @location(5) @interpolate(flat) p5: vec4<f32>,
    @location(6) @interpolate(flat) p6: vec4<f32>,
    @location(7) @interpolate(flat) p7: vec4<f32>,
    @location(8) @interpolate(flat) depth0: vec4<f32>,
    @location(9) @interpolate(flat) depth1: vec4<f32>,
    @location(10) @interpolate(flat) topo: vec4<u32>,
    @location(11) seg: vec4<f32>,
    @location(12) thick: f32,
    @location(13) @interpolate(flat) piece: u32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = v.pos;
    out.p0 = v.p0;
    out.p1 = v.p1;
    out.p2 = v.p2;
    out.p3 = v.p3;
    out.p4 = v.p4;
    out.p5 = v.p5;
    out.p6 = v.p6;
    out.p7 = v.p7;
    out.depth0 = v.depth0;
    out.depth1 = v.depth1;
    out.topo = v.topo;
    out.seg = v.seg;
    out.thick = v.thick;
    out.piece = v.piece;
    return out;
}

// The corners of triangle k of `topo`: three per word, 9 bits each (3 bits
// per corner). Bits 27 to 31 of words 0, 1 and 2 hold the number of
// triangles, of front triangles (they come first) and of points.
// Twin: render::modes::piece_quad::corners.
fn corners(topo: vec4<u32>, k: u32) -> vec3<u32> {
    let w = topo[k / 3u] >> (9u * (k % 3u));
    return vec3<u32>(w & 7u, (w >> 3u) & 7u, (w >> 6u) & 7u);
}

// The edge function of the sheared points `a` (point i) and `b` (point j),
// evaluated from the lower-numbered point. Twin: piece_quad::edge.
fn edge(a: vec2<f32>, b: vec2<f32>, i: u32, j: u32) -> f32 {
    if i < j {
        return a.x * b.y - a.y * b.x;
    }
    return -(b.x * a.y - b.y * a.x);
}

// The fragment's ray segment through its piece at framebuffer position `p`
// (a pixel centre). Twin: render::modes::piece_quad::segment_at.
fn segment_at(f: VertexOut, p: vec2<f32>) -> Seg {
    let count = f.topo.x >> 27u;
    if count == 0u {
        return segment_of(f.seg.xy, f.seg.zw, f.thick, p);
    }
    let u = p * view.scale + view.offset;
    var pts = array<vec4<f32>, 8>(f.p0, f.p1, f.p2, f.p3, f.p4, f.p5, f.p6, f.p7);
    var zs = array<f32, 8>(
        f.depth0.x, f.depth0.y, f.depth0.z, f.depth0.w,
        f.depth1.x, f.depth1.y, f.depth1.z, f.depth1.w,
    );
    let front_count = f.topo.y >> 27u;
    let point_count = f.topo.z >> 27u;
    var q: array<vec2<f32>, 8>;
    for (var i = 0u; i < point_count; i++) {
        let c = pts[i];
        if view.ortho == 1u {
            q[i] = c.xy - u;
        } else {
            q[i] = c.xy - u * c.z;
        }
    }
    // (depth, scalar) where the ray meets a front triangle (side 0; they
    // come first) and a back one (side 1). Every triangle is wound so that
    // a ray through it has three edge functions of one sign, positive.
    var hit = array<vec2<f32>, 2>(vec2<f32>(0.0), vec2<f32>(0.0));
    var found = array<bool, 2>(false, false);
    // The points each hit has a nonzero weight on: equal for both sides
    // where the ray only touches the piece (at a vertex, or along an edge
    // of its outline), which it then meets for no length.
    var mask = array<u32, 2>(0u, 0u);
    var side = 0u;
    var k = 0u;
    loop {
        // No front triangle holds the ray: it misses the piece.
        if (side == 0u && k == front_count) || k >= count {
            break;
        }
        let t = corners(f.topo, k);
        let e = vec3<f32>(
            edge(q[t.y], q[t.z], t.y, t.z),
            edge(q[t.z], q[t.x], t.z, t.x),
            edge(q[t.x], q[t.y], t.x, t.y),
        );
        let sum = e.x + e.y + e.z;
        if e.x >= 0.0 && e.y >= 0.0 && e.z >= 0.0 && sum > 0.0 {
            let w = e / sum;
            found[side] = true;
            mask[side] = (select(0u, 1u, e.x != 0.0) << t.x) | (select(0u, 1u, e.y != 0.0) << t.y)
                | (select(0u, 1u, e.z != 0.0) << t.z);
            hit[side] = vec2<f32>(
                dot(w, vec3<f32>(zs[t.x], zs[t.y], zs[t.z])),
                dot(w, vec3<f32>(pts[t.x].w, pts[t.y].w, pts[t.z].w)),
            );
            if side == 1u {
                break;
            }
            side = 1u;
            k = front_count;
            continue;
        }
        k = k + 1u;
    }
    var out: Seg;
    out.ok = found[0] && found[1] && mask[0] != mask[1];
    var front = hit[0];
    var back = hit[1];
    if back.x < front.x {
        front = hit[1];
        back = hit[0];
    }
    out.s_f = front.y;
    out.s_b = back.y;
    out.l = back.x - front.x;
    if view.ortho == 0u {
        out.l = out.l * sqrt(1.0 + dot(u, u));
    }
    out.l = max(out.l, 0.0);
    out.ok = out.ok && finite(out.s_f) && finite(out.s_b) && finite(out.l);
    return out;
}

// Coverage counting (tests and diagnostics): 1 to red where the fragment's
// ray meets its piece.
@fragment
fn fs_count(f: VertexOut) -> FragOut {
    let seg = segment_at(f, f.clip.xy);
    if !seg.ok {
        discard;
    }
    var out: FragOut;
    out.color = count_of(f.clip.z);
    out.depth = piece_depth(f.piece);
    return out;
}
