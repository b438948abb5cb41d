// Isosurfaces on the segment payload, alone or mixed with the volume
// (Roettger, Kraus, Ertl 2000, sections 7-10, without extracted triangles;
// src/render/iso.rs states the rules). The fragment rebuilds its segment
// (s_f, s_b, l; shaders/segment.wgsl) and the gradients at its ends
// (shaders/iso_vertex.wgsl), finds the isovalues V with
// min(s_f, s_b) < V <= max(s_f, s_b) (`iso_window`), and composites front
// to back the volume up to the first crossing, the lit surface, the volume
// up to the next, ..., the volume after the last: `iso_segment`, defined
// by the file the stage puts next to this one (shaders/iso_split.wgsl,
// which calls the stage's `volume(l, s0, s1)` once per sub-segment: a
// table lookup, or nothing for `--mode iso`; shaders/iso_walk.wgsl, which
// walks the transfer function's nodes and the crossings in one loop for
// the closed-form integral). Only the values a segment crosses are
// visited, and none behind a surface that made the fragment opaque.
//
// Bindings 3 and 4 (after the volume's own 0-2). Twin: render::modes::iso.

// Keep in sync with `IsoParams` in src/render/modes/iso.rs.
struct IsoParams {
    // Number of surfaces.
    count: u32,
    // 0: no light, 1: flat, 2: smooth (the gradients differ, not the light).
    lighting: u32,
    ambient: f32,
    diffuse: f32,
    // 0: exact mixing, 1: RKE's blend (src/render/iso.rs `IsoMix`).
    mix: u32,
    // A table volume's lookups take the transfer function's normalised
    // scalar (first node 0, last 1); the fragment's are centred on the
    // isovalues (src/render/modes/segment.rs `ScalarMap::centred`): this
    // is the centre in the table's terms, 0 for the other volumes.
    table_offset: f32,
    _pad1: u32,
    _pad2: u32,
}

// Keep in sync with `IsoSurface` in src/render/modes/iso.rs.
struct IsoSurface {
    // x: the normalised isovalue (increasing with the index).
    value: vec4<f32>,
    // Straight colour and opacity of the front (rising, 0) and back (1)
    // sides (`front`, `back` in the Rust struct): indexed, so that a
    // fragment loads only the side it sees.
    sides: array<vec4<f32>, 2>,
}

@group(0) @binding(3) var<uniform> iso: IsoParams;
@group(0) @binding(4) var<storage, read> surfaces: array<IsoSurface>;

// The number of isovalues <= x, for an x between the values of surfaces
// first - 1 and end (every surface below `first` is at most x, every one
// from `end` on above it): a binary search among first ..< end.
fn count_at_most(x: f32, first: u32, end: u32) -> u32 {
    var lo = first;
    var hi = end;
    loop {
        if lo >= hi {
            break;
        }
        let mid = (lo + hi) / 2u;
        if surfaces[mid].value.x <= x {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The crossings of the segment from s_f to s_b: the surfaces a ..< b
// (returned as (a, b)), the values V with min < V <= max of its ends,
// among the part's candidates (`VertexIn::candidates`, flat: the values
// within its scalar range, so that a segment inside the triangle crosses
// no other, and a rasteriser's lanes outside it, shaded with extrapolated
// scalars, search and loop over no more). A part holding no value
// searches nothing.
fn iso_window(s_f: f32, s_b: f32, candidates: vec2<f32>) -> vec2<u32> {
    let first = u32(candidates.x);
    let end = u32(candidates.y);
    var a = first;
    var b = first;
    if first < end {
        a = count_at_most(min(s_f, s_b), first, end);
        b = max(count_at_most(max(s_f, s_b), first, end), a);
    }
    return vec2<u32>(a, b);
}

// The headlight's factor for gradient g (view space: the view direction is
// +z); 1 without light or without a gradient.
fn iso_light(g: vec3<f32>) -> f32 {
    if iso.lighting == 0u {
        return 1.0;
    }
    let n = length(g);
    if !(n > 0.0) || !finite(n) {
        return 1.0;
    }
    return iso.ambient + iso.diffuse * min(abs(g.z) / n, 1.0);
}

// Premultiplied colour and opacity of surface k crossed rising or falling,
// its opacity times w.
fn iso_surface(k: u32, rising: bool, g: vec3<f32>, w: f32) -> vec4<f32> {
    let c = surfaces[k].sides[select(1u, 0u, rising)];
    let a = clamp(c.w * w, 0.0, 1.0);
    return vec4<f32>(c.xyz * (iso_light(g) * a), a);
}

// `back` behind `front` (premultiplied).
fn iso_over(front: vec4<f32>, back: vec4<f32>) -> vec4<f32> {
    let t = 1.0 - front.w;
    return vec4<f32>(front.xyz + t * back.xyz, front.w + t * back.w);
}

// Whether the segment crosses level v: lo < v <= hi. Where a surface meets
// a face between two pieces, the centres next to the line where the face's
// scalar is the isovalue get the exact segment's values in both pieces (the
// driver's seams, src/render/ties), so the two cannot both miss it or both
// take it.
fn iso_crosses(v: f32, seg: Seg) -> bool {
    let lo = min(seg.s_f, seg.s_b);
    let hi = max(seg.s_f, seg.s_b);
    return v > lo && v <= hi;
}

@fragment
fn fs_iso(f: VertexOut) -> FragOut {
    let seg = segment_at(f, f.clip.xy);
    if !seg.ok {
        discard;
    }
    var gf = f.grad_front;
    var gb = f.grad_back;
    if view.ortho != 1u {
        gf = gf / f.front.y;
        gb = gb / f.back.y;
    }
    var out: FragOut;
    out.color = iso_segment(seg, gf, gb, f.candidates);
    out.depth = piece_depth(f.piece);
    return out;
}
