// The GPU build of the pre-integration tables (Roettger, Ertl 2002, step 1),
// every texel of every slice in one dispatch, each the exact integral of
// shaders/integral.wgsl (this file is put behind it) at the texel's
// (s_f, s_b, l):
// - kind 0, the 3D table: (i, j, k) -> (i / (ns - 1), j / (ns - 1), k / (nz - 1) l_table),
//   one invocation per column (i, j) of all its lengths (`column_main`,
//   `build_column`);
// - kind 1, the 2D table: (i, j) at l_table, alpha replaced by the optical
//   depth (`optical_depth`), one invocation per texel (`build_main`);
// - kind 2, the cylindrical planes: (u, v, plane) through equation 9 of the
//   paper (src/integrate/cylinder.rs `cyl_to_table`), one invocation per
//   texel.
// Texels whose scalar interval misses [lo, hi] (a transfer-function edit
// confined there) are left as they are.
//
// A column shares everything but the length. Its segments cross the same
// transfer-function spans at the same fractions of their length, and every
// optical depth is the length index k times its value at k = 1, so each
// Gauss-Legendre node's exponential exp(-k c) is the k-th power of
// exp(-c): the column integrates each span once per CHUNK lengths with
// exact exponentials at the chunk's first length and one multiplication per
// node and length after that (`column_subspan`; the factor exp(-c) from its
// series, `exp_small`, since the rounding of a library exp is raised to
// the power too). The 6-node rule is exact to 6e-9 only up to GAUSS_MAX,
// so a span is cut into equal sub-spans (`subspans`: the extinction is
// linear along it, so each is again a linear piece) thin enough at the
// longest length. Where the cut would need more than MAX_SUBSPANS (a span
// with extinction times length above 16), only the lengths it serves thin
// are integrated by the recurrences, and if those are fewer than
// MIN_RECURRENCE the whole column texel by texel (`integrate_segment`,
// whose closed form covers any thickness).
//
// Measured on llvmpipe (2 cores): 128^3 in about 39 ms against 213 ms texel
// by texel, and within 1.1e-6 of the f64 table against 2.5e-6. The shape
// is what the software rasteriser needs: the chunk's composites are named
// registers (`Chunk`, written out), since an array indexed by the length
// cost a memory access per length, and the texels are stored one by one
// (`store_texel`), since a loop over a dynamically indexed array cost
// about as much as the integration.
//
// Twin: render::modes::table_build (`build_main`, `column_main`, `build_column`,
// `store_texel`, `column_subspan`, `column_step`, `next_powers`,
// `exp_small`, `subspans`, `optical_depth`; `cyl_to_table` is
// integrate::cylinder::cyl_to_table).

// Keep in sync with `BuildParams` in src/render/modes/table_build.rs.
struct BuildParams {
    kind: u32,
    ns: u32,
    nz: u32,
    _pad0: u32,
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

// Lengths per chunk of a column (the fields of `Chunk`): every exponential
// is exact at a chunk's first length and a product of at most CHUNK - 1
// factors after it (relative rounding below 16 f32 ulps). 8 lengths cost
// 63 ms for 128^3 on llvmpipe, 16 and 32 36 ms (more registers spill).
const CHUNK: u32 = 16u;
// At most this many sub-spans per transfer-function span of a column.
const MAX_SUBSPANS: u32 = 8u;
// A column whose recurrences would serve fewer lengths is integrated texel
// by texel, so every exponent at k = 1 is at most
// GAUSS_MAX / MIN_RECURRENCE = 1 / 8 (`exp_small`).
const MIN_RECURRENCE: u32 = 16u;

// The composites of a chunk's lengths k0 + t, t < CHUNK: colour (rgb) and
// the transmittance in front of it (w).
struct Chunk {
    v0: vec4<f32>,
    v1: vec4<f32>,
    v2: vec4<f32>,
    v3: vec4<f32>,
    v4: vec4<f32>,
    v5: vec4<f32>,
    v6: vec4<f32>,
    v7: vec4<f32>,
    v8: vec4<f32>,
    v9: vec4<f32>,
    v10: vec4<f32>,
    v11: vec4<f32>,
    v12: vec4<f32>,
    v13: vec4<f32>,
    v14: vec4<f32>,
    v15: vec4<f32>,
}

// The exponentials of one sub-span at one length: the six Gauss-Legendre
// nodes' (a: nodes 0, 2, 4; b: nodes 1, 3, 5) and the whole sub-span's.
struct Powers {
    a: vec3<f32>,
    b: vec3<f32>,
    t: f32,
}

// The sub-span's weights of colour per node (`ga`, `gb`, one column per
// node) at length k behind composite v, with its exponentials q.
fn column_step(v: vec4<f32>, k: f32, ga: mat3x3<f32>, gb: mat3x3<f32>, q: Powers) -> vec4<f32> {
    let c = k * (ga * q.a + gb * q.b);
    return vec4<f32>(v.xyz + v.w * c, v.w * q.t);
}

// exp(-c) for 0 <= c <= 1 / 8 (a sub-span's exponents at k = 1 where the
// recurrences serve at least MIN_RECURRENCE lengths): seven terms of its
// series, within 1e-10 relative there, so as exact as f32 allows where
// the library exp of a software rasteriser is a few ulps off (the
// recurrence raises its error to the power of up to CHUNK - 1).
fn exp_small(c: vec3<f32>) -> vec3<f32> {
    return 1.0 - c * (1.0 - c * (1.0 / 2.0) * (1.0 - c * (1.0 / 3.0) * (1.0 - c * (1.0 / 4.0) * (1.0 - c * (1.0 / 5.0) * (1.0 - c * (1.0 / 6.0))))));
}

// The exponentials at the next length: each times its value at k = 1.
fn next_powers(q: Powers, r: Powers) -> Powers {
    return Powers(q.a * r.a, q.b * r.b, q.t * r.t);
}

// Sub-spans a span is cut into: each at most GAUSS_MAX thick at the
// column's longest length (`len`: the span's share of l_table), at most
// MAX_SUBSPANS.
fn subspans(t0: f32, t1: f32, len: f32) -> u32 {
    let d = max(t0, t1) * len;
    return u32(clamp(ceil(d / GAUSS_MAX), 1.0, f32(MAX_SUBSPANS)));
}

// Adds the linear piece from m0 to m1 of length k ls behind the chunk's
// composites (k = k0 + t, t < CHUNK): the 6-node rule of `gauss` with each
// node's exponential a power.
fn column_subspan(acc: ptr<function, Chunk>, k0: u32, ls: f32, m0: Material, m1: Material) {
    let a = m0.tau * ls;
    let b = m1.tau * ls;
    let e0 = consts[GL6_BASE];
    let e1 = consts[GL6_BASE + 1u];
    let e2 = consts[GL6_BASE + 2u];
    // Nodes 0, 2, 4 (xa) and 1, 3, 5 (xb) and their exponents at k = 1.
    let xa = vec3<f32>(e0.x, e1.x, e2.x);
    let xb = vec3<f32>(e0.z, e1.z, e2.z);
    let ca = xa * (a * (1.0 - 0.5 * xa) + b * (0.5 * xa));
    let cb = xb * (a * (1.0 - 0.5 * xb) + b * (0.5 * xb));
    // Each node's colour weight over k: glow w (a y + b x) (the extinction
    // there), independent emission w ls.
    var fa = vec3<f32>(e0.y, e1.y, e2.y) * ls;
    var fb = vec3<f32>(e0.w, e1.w, e2.w) * ls;
    if tf.model == 0u {
        fa = vec3<f32>(e0.y, e1.y, e2.y) * (a * (1.0 - xa) + b * xa);
        fb = vec3<f32>(e0.w, e1.w, e2.w) * (a * (1.0 - xb) + b * xb);
    }
    let ga = mat3x3<f32>(
        (m0.col * (1.0 - xa.x) + m1.col * xa.x) * fa.x,
        (m0.col * (1.0 - xa.y) + m1.col * xa.y) * fa.y,
        (m0.col * (1.0 - xa.z) + m1.col * xa.z) * fa.z,
    );
    let gb = mat3x3<f32>(
        (m0.col * (1.0 - xb.x) + m1.col * xb.x) * fb.x,
        (m0.col * (1.0 - xb.y) + m1.col * xb.y) * fb.y,
        (m0.col * (1.0 - xb.z) + m1.col * xb.z) * fb.z,
    );
    let d = 0.5 * (a + b);
    let r = Powers(exp_small(ca), exp_small(cb), exp_small(vec3<f32>(d)).x);
    let k = f32(k0);
    var q = Powers(exp(-k * ca), exp(-k * cb), exp(-k * d));
    (*acc).v0 = column_step((*acc).v0, k, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v1 = column_step((*acc).v1, k + 1.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v2 = column_step((*acc).v2, k + 2.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v3 = column_step((*acc).v3, k + 3.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v4 = column_step((*acc).v4, k + 4.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v5 = column_step((*acc).v5, k + 5.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v6 = column_step((*acc).v6, k + 6.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v7 = column_step((*acc).v7, k + 7.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v8 = column_step((*acc).v8, k + 8.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v9 = column_step((*acc).v9, k + 9.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v10 = column_step((*acc).v10, k + 10.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v11 = column_step((*acc).v11, k + 11.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v12 = column_step((*acc).v12, k + 12.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v13 = column_step((*acc).v13, k + 13.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v14 = column_step((*acc).v14, k + 14.0, ga, gb, q);
    q = next_powers(q, r);
    (*acc).v15 = column_step((*acc).v15, k + 15.0, ga, gb, q);
}

// Texel k of a column (at: its offset in slice 0, row: the slice's
// texels) from its composite v, if the recurrences serve it (k <= kmax).
fn store_texel(k: u32, kmax: u32, depth: f32, v: vec4<f32>, row: u32, at: u32) {
    if k > kmax {
        return;
    }
    var out = vec4<f32>(0.0);
    if k > 0u {
        out = vec4<f32>(min(v.xyz, vec3<f32>(MAX_THICKNESS)), neg_expm1(f32(k) * depth));
    }
    texels[k * row + at] = out;
}

// Column (ix, iy) of the 3D table: every length k of the segment from
// s_f = ix / (ns - 1) to s_b = iy / (ns - 1).
fn build_column(ix: u32, iy: u32) {
    let n1 = f32(build.ns - 1u);
    let sf = f32(ix) / n1;
    let sb = f32(iy) / n1;
    if max(sf, sb) < build.lo || min(sf, sb) > build.hi {
        return;
    }
    var dl = 0.0;
    if build.nz > 1u {
        dl = build.l_table / f32(build.nz - 1u);
    }
    // The spans, as integrate_segment walks them.
    let sp = segment_spans(sf, sb);
    // The thickest sub-span and the whole segment's optical depth at k = 1.
    var dmax = 0.0;
    var depth = 0.0;
    var m_prev = sp.m_first;
    var x_prev = 0.0;
    for (var n = 0u; n <= sp.count; n++) {
        let e = span_end(sp, n, sf);
        if e.x > x_prev {
            let f = e.x - x_prev;
            let q = f32(subspans(m_prev.tau, e.m.tau, build.l_table * f));
            dmax = max(dmax, max(m_prev.tau, e.m.tau) * dl * f / q);
            depth += 0.5 * (m_prev.tau + e.m.tau) * dl * f;
        }
        m_prev = e.m;
        x_prev = e.x;
    }
    // Lengths 0 ..= kmax by the recurrences, the rest texel by texel.
    var kmax = build.nz - 1u;
    if dmax * f32(kmax) > GAUSS_MAX {
        kmax = u32(GAUSS_MAX / dmax);
        if kmax < MIN_RECURRENCE {
            kmax = 0u;
        }
    }
    let row = build.ns * build.ns;
    let at = iy * build.ns + ix;
    for (var k0 = 0u; k0 <= kmax; k0 += CHUNK) {
        let e = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        var acc = Chunk(e, e, e, e, e, e, e, e, e, e, e, e, e, e, e, e);
        m_prev = sp.m_first;
        x_prev = 0.0;
        for (var n = 0u; n <= sp.count; n++) {
            let e = span_end(sp, n, sf);
            if e.x > x_prev {
                let f = e.x - x_prev;
                let q = subspans(m_prev.tau, e.m.tau, build.l_table * f);
                let qf = f32(q);
                for (var j = 0u; j < q; j++) {
                    var s0 = m_prev;
                    var s1 = e.m;
                    if j > 0u {
                        let u = f32(j) / qf;
                        s0 = Material(mix(m_prev.tau, e.m.tau, u), mix(m_prev.col, e.m.col, u));
                    }
                    if j + 1u < q {
                        let u = f32(j + 1u) / qf;
                        s1 = Material(mix(m_prev.tau, e.m.tau, u), mix(m_prev.col, e.m.col, u));
                    }
                    column_subspan(&acc, k0, dl * f / qf, s0, s1);
                }
            }
            m_prev = e.m;
            x_prev = e.x;
        }
        store_texel(k0, kmax, depth, acc.v0, row, at);
        store_texel(k0 + 1u, kmax, depth, acc.v1, row, at);
        store_texel(k0 + 2u, kmax, depth, acc.v2, row, at);
        store_texel(k0 + 3u, kmax, depth, acc.v3, row, at);
        store_texel(k0 + 4u, kmax, depth, acc.v4, row, at);
        store_texel(k0 + 5u, kmax, depth, acc.v5, row, at);
        store_texel(k0 + 6u, kmax, depth, acc.v6, row, at);
        store_texel(k0 + 7u, kmax, depth, acc.v7, row, at);
        store_texel(k0 + 8u, kmax, depth, acc.v8, row, at);
        store_texel(k0 + 9u, kmax, depth, acc.v9, row, at);
        store_texel(k0 + 10u, kmax, depth, acc.v10, row, at);
        store_texel(k0 + 11u, kmax, depth, acc.v11, row, at);
        store_texel(k0 + 12u, kmax, depth, acc.v12, row, at);
        store_texel(k0 + 13u, kmax, depth, acc.v13, row, at);
        store_texel(k0 + 14u, kmax, depth, acc.v14, row, at);
        store_texel(k0 + 15u, kmax, depth, acc.v15, row, at);
    }
    for (var k = kmax + 1u; k < build.nz; k++) {
        texels[k * row + at] = integrate_segment(f32(k) * dl, sf, sb);
    }
}

// One invocation per column of the 3D table (kind 0). Its own entry point:
// llvmpipe runs both sides of a branch on the kind, masked, so one entry
// for both shapes made the per-texel tables 2.6 times slower.
@compute @workgroup_size(8, 8, 1)
fn column_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < build.ns && id.y < build.ns {
        build_column(id.x, id.y);
    }
}

// One invocation per texel (kinds 1 and 2; kind 0 too, texel by texel).
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
    texels[(id.z * build.ns + id.y) * build.ns + id.x] = v;
}
