// What the pre-integrated table modes (preint3d, preint2d, preint2d-cyl)
// share: their parameters, the table axes, and the segment logic around the
// mode's own lookup `table_rgba(s_f, s_b, l)` (defined in the mode's file).
//
// A table covers the normalised scalar range [0, 1] (the transfer
// function's nodes, src/render/modes/segment.rs `ScalarMap`). Outside it the
// transfer function is constant, so the part of a segment below 0 or above
// 1 is homogeneous and integrated in closed form (`homogeneous`); only the
// part inside goes to the table. The 3D and cylindrical tables span lengths
// up to the largest cell diameter (with a margin, src/numeric/tolerance.rs
// TABLE_LENGTH_MARGIN), which bounds every segment through a piece, so one
// lookup serves every segment; a length beyond it (only from rounding) reads
// the last length sample.
//
// The three parts are evaluated unconditionally, with lengths l t_a,
// l (t_b - t_a) and l (1 - t_b), zero where a part is absent (every lookup
// and `homogeneous` give exactly 0 at length 0): software rasterisers run
// both sides of a branch anyway, and a loop around the lookup (steps for
// longer segments, as there were) cost one more lookup per fragment even
// where it never looped (hex_shell preint3d frame on lavapipe: 0.93 s with
// the loop, 0.77 s without).
//
// Twin: render::modes::preint, function for function.

// Keep in sync with `PreintParams` in src/render/modes/preint.rs.
struct PreintParams {
    // The constant extensions below 0 and above 1: (colour or emission, tau).
    below: vec4<f32>,
    above: vec4<f32>,
    // Samples along each scalar axis.
    ns: u32,
    // Samples along the length (3D) or planes (cylindrical); 1 for 2D.
    nz: u32,
    // 0: glow, 1: independent emission.
    model: u32,
    _pad0: u32,
    // The length the table's last length sample stands for (3D, cylinder),
    // or its reference length (2D).
    l_table: f32,
    _pad1: f32,
    _pad2: f32,
    _pad3: f32,
}

@group(0) @binding(2) var<uniform> pre: PreintParams;

// False where every scalar of the field lies inside the transfer function's
// node range (src/render/modes/preint.rs `field_inside`): the normalised
// scalars then leave [0, 1] only by the rounding of their interpolation,
// and each segment is one lookup at its clamped scalars, with no parts
// outside (two closed forms less per fragment: 5 % of the hex_shell
// preint3d frame on lavapipe, where both sides of a branch run, a uniform
// one included, so this is a pipeline constant).
override EXTENDED: bool = true;

// (1 - exp(-x)) / x, stable at 0 (x >= 0).
fn one_minus_exp_over(x: f32) -> f32 {
    if x < 1e-3 {
        return 1.0 - 0.5 * x + x * x / 6.0;
    }
    return (1.0 - exp(-x)) / x;
}

// A segment of length l in constant material m = (colour or emission, tau).
fn homogeneous(m: vec4<f32>, l: f32) -> vec4<f32> {
    let x = min(m.w * l, 1e30);
    let f = l * one_minus_exp_over(x);
    let alpha = x * one_minus_exp_over(x);
    if pre.model == 0u {
        return vec4<f32>(m.xyz * alpha, alpha);
    }
    return vec4<f32>(min(m.xyz * f, vec3<f32>(1e30)), alpha);
}

// `back` behind `front` (premultiplied).
fn over(front: vec4<f32>, back: vec4<f32>) -> vec4<f32> {
    let t = 1.0 - front.w;
    return vec4<f32>(front.xyz + t * back.xyz, front.w + t * back.w);
}

// Lower sample and weight of normalised coordinate x on an axis of n
// samples over [0, 1], clamped.
fn axis(x: f32, n: u32) -> vec2<f32> {
    let top = f32(n - 1u);
    let c = clamp(x * top, 0.0, top);
    let i = min(floor(c), top - 1.0);
    return vec2<f32>(i, c - i);
}

fn lerp4(a: vec4<f32>, b: vec4<f32>, w: f32) -> vec4<f32> {
    return a + (b - a) * w;
}

// The constant extension holding scalar s (outside [0, 1]).
fn extension(s: f32) -> vec4<f32> {
    if s < 0.5 {
        return pre.below;
    }
    return pre.above;
}

// Premultiplied colour and opacity of the segment (s_f, s_b, l): the part
// below 0 or above 1 in front (t < t_a), the table's part, the part behind
// (t > t_b).
fn preint_segment(sf: f32, sb: f32, l: f32) -> vec4<f32> {
    if !EXTENDED {
        return table_rgba(clamp(sf, 0.0, 1.0), clamp(sb, 0.0, 1.0), l);
    }
    let d = sb - sf;
    var ta = select(0.0, 1.0, sf < 0.0 || sf > 1.0);
    var tb = 1.0;
    if d != 0.0 {
        let t0 = (0.0 - sf) / d;
        let t1 = (1.0 - sf) / d;
        ta = clamp(min(t0, t1), 0.0, 1.0);
        tb = clamp(max(t0, t1), 0.0, 1.0);
    }
    tb = max(ta, tb);
    let s0 = clamp(sf + d * ta, 0.0, 1.0);
    let s1 = clamp(sf + d * tb, 0.0, 1.0);
    let front = homogeneous(extension(sf), l * ta);
    let inside = over(front, table_rgba(s0, s1, l * (tb - ta)));
    return over(inside, homogeneous(extension(sb), l * (1.0 - tb)));
}

@fragment
fn fs_main(f: VertexOut) -> FragOut {
    let seg = segment_at(f, f.clip.xy);
    if !seg.ok {
        discard;
    }
    var out: FragOut;
    out.color = preint_segment(seg.s_f, seg.s_b, seg.l);
    out.depth = piece_depth(f.piece);
    return out;
}
