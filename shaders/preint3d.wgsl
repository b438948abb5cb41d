// The preint3d stage's lookup: the 3D pre-integrated table (Roettger, Kraus,
// Ertl 2000, section 3) over (s_f, s_b, l), RGBA = premultiplied colour and
// opacity, filtered trilinearly in f32 (a storage buffer, src/gpu/table.rs).
// Axes: s_f along x, s_b along y over [0, 1] (ns texels each); l along z
// over [0, l_table] (nz texels).
//
// Twin: render::modes::preint3d::table_rgba.

@group(0) @binding(1) var<storage, read> table3d: array<vec4<f32>>;

// Texel (i, j, k), x fastest.
fn texel3d(i: i32, j: i32, k: i32) -> vec4<f32> {
    let n = i32(pre.ns);
    return table3d[(k * n + j) * n + i];
}

fn table_rgba(sf: f32, sb: f32, l: f32) -> vec4<f32> {
    let a = axis(sf, pre.ns);
    let b = axis(sb, pre.ns);
    let c = axis(l / pre.l_table, pre.nz);
    let i = i32(a.x);
    let j = i32(b.x);
    let k = i32(c.x);
    var plane: array<vec4<f32>, 2>;
    for (var z = 0; z < 2; z++) {
        let r0 = lerp4(
            texel3d(i, j, k + z),
            texel3d(i + 1, j, k + z),
            a.y,
        );
        let r1 = lerp4(
            texel3d(i, j + 1, k + z),
            texel3d(i + 1, j + 1, k + z),
            a.y,
        );
        plane[z] = lerp4(r0, r1, b.y);
    }
    return lerp4(plane[0], plane[1], c.y);
}
