// The vertex stage and segment of exact-frag's whole-piece quads
// (src/render/modes/piece_quad.rs, which fills `VertexIn` and is the twin):
// a convex piece of at most 8 points and 12 boundary triangles is drawn as
// one screen polygon over its outline (its projected points' hull widened
// a little, or the quad over its pixel bounding box; see
// src/render/driver/whole.rs), every vertex carrying the
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

// Point i of the piece (view-space x, y, z and normalised scalar), chosen
// by selects: no indexed private array, which software rasterisers run
// through memory lane by lane (a version with arrays took 2.4 s for the
// hex_shell frame at 512^2 on lavapipe, this one 1.2 s).
// Twin: render::modes::piece_quad::point.
fn point(f: VertexOut, i: u32) -> vec4<f32> {
    let b0 = (i & 1u) != 0u;
    let b1 = (i & 2u) != 0u;
    let lo = select(select(f.p0, f.p1, b0), select(f.p2, f.p3, b0), b1);
    let hi = select(select(f.p4, f.p5, b0), select(f.p6, f.p7, b0), b1);
    return select(lo, hi, (i & 4u) != 0u);
}

// Point i's depth relative to point 0. Twin: render::modes::piece_quad::depth.
fn depth(f: VertexOut, i: u32) -> f32 {
    let d = select(f.depth0, f.depth1, (i & 4u) != 0u);
    let b0 = (i & 1u) != 0u;
    return select(select(d.x, d.y, b0), select(d.z, d.w, b0), (i & 2u) != 0u);
}

// The point sheared onto the ray through view-plane position `u`.
// Twin: render::modes::piece_quad::shear.
fn shear(c: vec4<f32>, u: vec2<f32>) -> vec2<f32> {
    if view.ortho == 1u {
        return c.xy - u;
    }
    return c.xy - u * c.z;
}

// The first of triangles [first, last) holding the ray through `u`: (depth,
// scalar, mask of the points with nonzero weight, 1), or 0 in w where none
// does. Every triangle is wound so that a ray through it has three edge
// functions of one sign, positive. Twin: render::modes::piece_quad::find.
fn find(f: VertexOut, u: vec2<f32>, first: u32, last: u32) -> vec4<f32> {
    for (var k = first; k < last; k++) {
        let t = corners(f.topo, k);
        let pa = point(f, t.x);
        let pb = point(f, t.y);
        let pc = point(f, t.z);
        let qa = shear(pa, u);
        let qb = shear(pb, u);
        let qc = shear(pc, u);
        let e = vec3<f32>(edge(qb, qc, t.y, t.z), edge(qc, qa, t.z, t.x), edge(qa, qb, t.x, t.y));
        let sum = e.x + e.y + e.z;
        if e.x >= 0.0 && e.y >= 0.0 && e.z >= 0.0 && sum > 0.0 {
            let w = e / sum;
            let mask = (select(0u, 1u, e.x != 0.0) << t.x) | (select(0u, 1u, e.y != 0.0) << t.y)
                | (select(0u, 1u, e.z != 0.0) << t.z);
            return vec4<f32>(
                dot(w, vec3<f32>(depth(f, t.x), depth(f, t.y), depth(f, t.z))),
                dot(w, vec3<f32>(pa.w, pb.w, pc.w)),
                f32(mask),
                1.0,
            );
        }
    }
    return vec4<f32>(0.0);
}

// The fragment's ray segment through its piece at framebuffer position `p`
// (a pixel centre): the nearest front triangle holding the ray (they come
// first), then the back one. Twin: render::modes::piece_quad::segment_at.
fn segment_at(f: VertexOut, p: vec2<f32>) -> Seg {
    let count = f.topo.x >> 27u;
    if count == 0u {
        return segment_of(f.seg.xy, f.seg.zw, f.thick, p);
    }
    let u = p * view.scale + view.offset;
    let front_count = f.topo.y >> 27u;
    var out: Seg;
    out.ok = false;
    let a = find(f, u, 0u, front_count);
    if a.w == 0.0 {
        return out;
    }
    let b = find(f, u, front_count, count);
    // The points each hit has a nonzero weight on are the same on both
    // sides where the ray only touches the piece (at a vertex, or along an
    // edge of its outline), which it then meets for no length.
    out.ok = b.w != 0.0 && a.z != b.z;
    var front = a;
    var back = b;
    if back.x < front.x {
        front = b;
        back = a;
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
