// The GPU build of the pre-integration tables (Roettger, Ertl 2002, step 1):
// one invocation per texel, every texel of every slice in one dispatch,
// each the exact integral `integrate_segment` of shaders/integral.wgsl
// (this file is put behind it) at the texel's (s_f, s_b, l):
// - kind 0, the 3D table: (i, j, k) -> (i / (ns - 1), j / (ns - 1), k / (nz - 1) l_table);
// - kind 1, the 2D table: (i, j) at l_table, alpha replaced by the optical
//   depth (`optical_depth`);
// - kind 2, the cylindrical planes: (u, v, plane) through equation 9 of the
//   paper (src/integrate/cylinder.rs `cyl_to_table`).
// Texels whose scalar interval misses [lo, hi] (a transfer-function edit
// confined there) are left as they are.
//
// Twin: render::modes::table_build (`build_main` per texel, `optical_depth`;
// `cyl_to_table` is integrate::cylinder::cyl_to_table).

// Keep in sync with `BuildParams` in src/render/modes/table_build.rs.
struct BuildParams {
    kind: u32,
    ns: u32,
    nz: u32,
    // Texels per output row (the row padded for the texture copy).
    row_texels: u32,
    l_table: f32,
    lo: f32,
    hi: f32,
    _pad: f32,
}

@group(0) @binding(0) var<uniform> build: BuildParams;
@group(0) @binding(3) var<storage, read_write> texels: array<vec4<f32>>;

// Equation 9: plane parameter a and in-plane (u, v) to (S_f, S_b, L).
fn cyl_to_table(a: f32, u: f32, v: f32) -> vec3<f32> {
    if a <= 0.25 {
        return vec3<f32>(v + u, v, 4.0 * a * u);
    }
    if a <= 0.5 {
        return vec3<f32>(v + 4.0 * (0.5 - a) * u, v, u);
    }
    if a <= 0.75 {
        return vec3<f32>(v - 4.0 * (a - 0.5) * u, v, u);
    }
    return vec3<f32>(v - u, v, 4.0 * (1.0 - a) * u);
}

// l times the mean extinction over [s_f, s_b] (the optical depth of the
// segment), piece by piece of the transfer function.
fn optical_depth(l: f32, sf: f32, sb: f32) -> f32 {
    let lo = min(sf, sb);
    let hi = max(sf, sb);
    if !(hi > lo) {
        return l * eval_piece(piece_index(lo), lo).tau;
    }
    var sum = 0.0;
    var s0 = lo;
    var i = piece_index(lo);
    loop {
        var next = hi;
        if i < tf.count {
            next = min(node_s(i), hi);
        }
        if next > s0 {
            let idx = piece_index(0.5 * (s0 + next));
            let t0 = eval_piece(idx, s0).tau;
            let t1 = eval_piece(idx, next).tau;
            sum += 0.5 * (t0 + t1) * (next - s0);
        }
        if next >= hi || i >= tf.count {
            break;
        }
        s0 = next;
        i++;
    }
    return l * (sum / (hi - lo));
}

@compute @workgroup_size(8, 8, 1)
fn build_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= build.ns || id.y >= build.ns || id.z >= build.nz {
        return;
    }
    let x = f32(id.x) / f32(build.ns - 1u);
    let y = f32(id.y) / f32(build.ns - 1u);
    var c = vec3<f32>(x, y, 1.0);
    if build.kind == 0u {
        c.z = f32(id.z) / f32(build.nz - 1u);
    } else if build.kind == 2u {
        c = cyl_to_table(f32(id.z) / f32(build.nz - 1u), x, y);
    }
    if max(c.x, c.y) < build.lo || min(c.x, c.y) > build.hi {
        return;
    }
    let l = c.z * build.l_table;
    var v = integrate_segment(l, c.x, c.y);
    if build.kind == 1u {
        v.w = optical_depth(l, c.x, c.y);
    }
    texels[(id.z * build.ns + id.y) * build.row_texels + id.x] = v;
}
