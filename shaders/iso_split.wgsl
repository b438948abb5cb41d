// `iso_segment` over the stage's `volume(l, s0, s1)` (a table lookup, or
// nothing for `--mode iso`): the segment split at its crossings, each
// sub-segment's volume looked up on its own (shaders/iso.wgsl says how the
// surfaces are found and lit).
//
// Twin: render::modes::iso_split.

// The segment with its surfaces, front to back. One loop, one call of
// `volume` (inlined once): step i < b ends the volume at crossing k and
// adds the surface, step b ends it at the segment's back. RKE's blend
// (iso.mix 1) instead draws every surface's front-face layer (opacity
// times 1 - u), the whole segment's volume at step b, then the back-face
// layers (times u).
fn iso_segment(seg: Seg, gf: vec3<f32>, gb: vec3<f32>, candidates: vec2<f32>) -> vec4<f32> {
    let w = iso_window(seg.s_f, seg.s_b, candidates);
    let a = w.x;
    let b = w.y;
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
