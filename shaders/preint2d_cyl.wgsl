// The preint2d-cyl stage's lookup: the "cylindrical" re-mapping of the 3D
// table (Roettger, Ertl 2002, section 4): equation 10 takes the normalised
// (S_f, S_b, L = l / l_table) to (a, u, v); planes a_k = k / (nz - 1) are
// layers of a storage buffer over (u, v) (src/gpu/table.rs: u fastest, then v,
// then the plane); the lookup is bilinear in each of
// the two nearest planes and linear between them, in f32.
//
// Twin: render::modes::preint2d_cyl::table_rgba.

@group(0) @binding(1) var<storage, read> planes: array<vec4<f32>>;

// Texel (i, j) of plane k.
fn plane_texel(i: i32, j: i32, k: i32) -> vec4<f32> {
    let n = i32(pre.ns);
    return planes[(k * n + j) * n + i];
}

fn table_rgba(sf: f32, sb: f32, l: f32) -> vec4<f32> {
    let big_l = clamp(l / pre.l_table, 0.0, 1.0);
    let d = sf - sb;
    var a = 0.0;
    var u = 0.0;
    if d >= 0.0 {
        if big_l <= d {
            if d > 0.0 {
                a = big_l / (4.0 * d);
            }
            u = d;
        } else {
            a = 0.5 - d / (4.0 * big_l);
            u = big_l;
        }
    } else if big_l >= -d {
        a = 0.5 - d / (4.0 * big_l);
        u = big_l;
    } else {
        a = 1.0 + big_l / (4.0 * d);
        u = -d;
    }
    let p = axis(a, pre.nz);
    let x = axis(u, pre.ns);
    let y = axis(sb, pre.ns);
    let i = i32(x.x);
    let j = i32(y.x);
    let k = i32(p.x);
    var layer: array<vec4<f32>, 2>;
    for (var z = 0; z < 2; z++) {
        let r0 = lerp4(
            plane_texel(i, j, k + z),
            plane_texel(i + 1, j, k + z),
            x.y,
        );
        let r1 = lerp4(
            plane_texel(i, j + 1, k + z),
            plane_texel(i + 1, j + 1, k + z),
            x.y,
        );
        layer[z] = lerp4(r0, r1, y.y);
    }
    return lerp4(layer[0], layer[1], p.y);
}
