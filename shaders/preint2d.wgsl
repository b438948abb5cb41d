// The preint2d stage's lookup: the 2D table at the mean cell thickness
// l_table (Roettger, Kraus, Ertl 2000, section 4), texels (C, depth) at
// l_table, filtered bilinearly in f32 (a storage buffer,
// src/gpu/table.rs, x = s_f fastest). The optical depth is
// exactly linear in l (depth = l * mean extinction over [s_f, s_b]), so the
// opacity is exact up to interpolation; the colour is C scaled by
// alpha(l) / alpha(l_table), which is RKE's l / l_table for thin segments
// and exact for homogeneous ones.
//
// Twin: render::modes::preint2d::table_rgba.

@group(0) @binding(1) var<storage, read> table2d: array<vec4<f32>>;

// Texel (i, j), x fastest.
fn texel2d(i: i32, j: i32) -> vec4<f32> {
    return table2d[j * i32(pre.ns) + i];
}

fn table_rgba(sf: f32, sb: f32, l: f32) -> vec4<f32> {
    let a = axis(sf, pre.ns);
    let b = axis(sb, pre.ns);
    let i = i32(a.x);
    let j = i32(b.x);
    let r0 = lerp4(
        texel2d(i, j),
        texel2d(i + 1, j),
        a.y,
    );
    let r1 = lerp4(
        texel2d(i, j + 1),
        texel2d(i + 1, j + 1),
        a.y,
    );
    let t = lerp4(r0, r1, b.y);
    let r = l / pre.l_table;
    let depth_ref = max(t.w, 0.0);
    let depth = min(depth_ref * r, 1e30);
    let alpha = depth * one_minus_exp_over(depth);
    let scale = r * (one_minus_exp_over(depth) / one_minus_exp_over(depth_ref));
    return vec4<f32>(min(t.xyz * scale, vec3<f32>(1e30)), alpha);
}
