// Isosurfaces on the segment payload, alone or mixed with the volume
// (Roettger, Kraus, Ertl 2000, sections 7-10, without extracted triangles;
// src/render/iso.rs states the rules). The fragment rebuilds its segment
// (s_f, s_b, l; shaders/segment.wgsl) and the gradients at its ends
// (shaders/iso_vertex.wgsl), finds by binary search the isovalues V with
// min(s_f, s_b) < V <= max(s_f, s_b), and composites front to back: the
// volume up to the first crossing, the lit surface, the volume up to the
// next, ..., the volume after the last. `volume(l, s0, s1)` is the stage's
// volume integral (the exact-frag integral, a table lookup, or nothing for
// `--mode iso`), defined by the stage next to this file. Only the values a
// segment crosses are visited, and none behind a surface that made the
// fragment opaque.
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
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Keep in sync with `IsoSurface` in src/render/modes/iso.rs.
struct IsoSurface {
    // x: the normalised isovalue (increasing with the index).
    value: vec4<f32>,
    // Straight colour and opacity of the front (rising) and back sides.
    front: vec4<f32>,
    back: vec4<f32>,
}

@group(0) @binding(3) var<uniform> iso: IsoParams;
@group(0) @binding(4) var<storage, read> surfaces: array<IsoSurface>;

// The number of isovalues <= x.
fn count_at_most(x: f32) -> u32 {
    var lo = 0u;
    var hi = iso.count;
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
    var c = surfaces[k].back;
    if rising {
        c = surfaces[k].front;
    }
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

// The segment with its surfaces, front to back. One loop, one call of
// `volume` (inlined once: the volume integral is the stage's largest
// function): step i < b ends the volume at crossing k and adds the surface,
// step b ends it at the segment's back. RKE's blend (iso.mix 1) instead
// draws every surface's front-face layer (opacity times 1 - u), the whole
// segment's volume at step b, then the back-face layers (times u).
fn iso_segment(seg: Seg, gf: vec3<f32>, gb: vec3<f32>, range: vec2<f32>) -> vec4<f32> {
    let lo = min(seg.s_f, seg.s_b);
    let hi = max(seg.s_f, seg.s_b);
    // The search window, within the part's scalar range (flat): a no-op
    // inside the triangle, a bound on the lanes a rasteriser shades
    // outside it with extrapolated scalars (whose loops would otherwise
    // run over every isovalue).
    let wlo = max(lo, range.x);
    let whi = min(hi, range.y);
    // Most segments cross nothing: two reads decide it before any search.
    var a = 0u;
    var b = 0u;
    if iso.count > 0u && whi >= surfaces[0].value.x
        && wlo <= surfaces[iso.count - 1u].value.x {
        a = count_at_most(wlo);
        b = max(count_at_most(whi), a);
    }
    let rising = seg.s_f <= seg.s_b;
    let blend = iso.mix == 1u;
    let d = seg.s_b - seg.s_f;
    var acc = vec4<f32>(0.0);
    var back = vec4<f32>(0.0);
    var u0 = 0.0;
    var s0 = seg.s_f;
    for (var i = a; i <= b; i++) {
        var u = 1.0;
        var sv = seg.s_b;
        var k = 0u;
        if i < b {
            k = i;
            if !rising {
                k = a + b - 1u - i;
            }
            let v = surfaces[k].value.x;
            if !iso_crosses(v, seg) {
                continue;
            }
            u = 0.0;
            if d != 0.0 {
                u = clamp((v - seg.s_f) / d, 0.0, 1.0);
            }
            sv = v;
        }
        if !blend || i == b {
            var from_u = u0;
            var from_s = s0;
            if blend {
                from_u = 0.0;
                from_s = seg.s_f;
            }
            acc = iso_over(acc, volume((u - from_u) * seg.l, from_s, sv));
        }
        if i < b {
            let g = mix(gf, gb, u);
            if blend {
                acc = iso_over(acc, iso_surface(k, rising, g, 1.0 - u));
                back = iso_over(back, iso_surface(k, rising, g, u));
            } else {
                acc = iso_over(acc, iso_surface(k, rising, g, 1.0));
                // Opaque now: nothing behind shows (each later step would
                // add t = 0 times itself), so the cost is one surface's,
                // however many the segment crosses.
                if acc.w >= 1.0 {
                    break;
                }
            }
        }
        u0 = u;
        s0 = sv;
    }
    return iso_over(acc, back);
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
    out.color = iso_segment(seg, gf, gb, f.range);
    out.depth = piece_depth(f.piece);
    return out;
}
